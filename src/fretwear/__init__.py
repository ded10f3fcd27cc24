"""fretwear: coupled vibration and fretting wear of frictional contact interfaces.

Implements the "DLFT with wear" method of Salles, Blanc, Thouverez and Gousskov (2011),
Int. J. Solids Struct. 48, 1513-1524, and goes beyond it (3D contact, continuation, adaptive
slow-time steps, time-domain reference solvers).

The public API, stage by stage (data flows one way; each stage returns a plain data object)::

    model = fretwear.rectangle(...) / fretwear.from_mesh(...) / fretwear.from_matrices(...)
    red   = fretwear.condense(model, frequency, basis.orders)     # Reduced: Z_r per harmonic
    sol   = fretwear.solve_periodic(model, basis, frequency=...)  # PeriodicSolution
    frf   = fretwear.sweep(model, basis, f_min, f_max, n)         # SweepResult
    wear  = fretwear.simulate_wear(model, basis, frequency=...)   # WearResult
    run   = fretwear.integrate(model, frequency, n_periods=...)   # TransientResult
    out   = fretwear.run_case("case.toml", "out/")                # a case file end to end
    ds    = fretwear.read_results("out/results.nc")               # an xarray Dataset
    st    = fretwear.run_study("study.toml", "out/")              # members on Dask (study.nc)

Every frequency argument is in Hz (``frequency``, ``f_min``, ``f_max``); objects also keep
the circular frequency ``omega = 2 pi frequency`` [rad/s] where the equations use it. Every
result has ``success`` (bool) and ``message`` (str), as :class:`scipy.optimize.OptimizeResult`.

Names are loaded on first use, so ``import fretwear`` stays light (the command line sets its
BLAS threads before numpy loads). ``docs/api.md`` has runnable examples.
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

#: public name -> module that defines it
_API = {
    # models
    "Model": "fretwear.model.core", "ContactInterface": "fretwear.model.core",
    "Load": "fretwear.model.core", "Mesh": "fretwear.model.core",
    "ObservedPoint": "fretwear.model.core",
    "rectangle": "fretwear.model.mesh", "box": "fretwear.model.mesh",
    "read_mesh": "fretwear.model", "from_mesh": "fretwear.model.build",
    "ContactSpec": "fretwear.model.build", "Material": "fretwear.model.build",
    "Damping": "fretwear.model.build", "Spring": "fretwear.model.build",
    "Traction": "fretwear.model.build", "NodalForce": "fretwear.model.build",
    "from_matrices": "fretwear.model.matrices", "read_matrix_market": "fretwear.model.matrices",
    # harmonic balance
    "FourierBasis": "fretwear.hb.fourier", "condense": "fretwear.hb.reduce",
    "Reduced": "fretwear.hb.reduce", "solve_periodic": "fretwear.api",
    "PeriodicSolution": "fretwear.hb.solution", "SweepResult": "fretwear.hb.sweep_result",
    "sweep": "fretwear.api", "SolveOptions": "fretwear.hb.options",
    "SweepOptions": "fretwear.hb.options",
    # linear
    "modes": "fretwear.linear", "frf": "fretwear.linear",
    # wear
    "simulate_wear": "fretwear.api", "frf_worn": "fretwear.api",
    "WearOptions": "fretwear.wear", "WearResult": "fretwear.wear",
    # time domain
    "integrate": "fretwear.timedomain.integrate", "steady_state": "fretwear.timedomain.steady",
    "incremental_wear": "fretwear.timedomain.quasistatic",
    "check_periodic": "fretwear.timedomain.stability",
    # case files and results
    "run_case": "fretwear.analyses.run", "load_case": "fretwear.analyses.run",
    "read_results": "fretwear.io.results",
    "run_study": "fretwear.study.run", "read_study": "fretwear.study.spec",
    # errors
    "FretwearError": "fretwear.errors", "InputError": "fretwear.errors",
    "ConvergenceError": "fretwear.errors",
}

__all__ = ["__version__", *_API]


def __getattr__(name: str):
    module = _API.get(name)
    if module is None:
        raise AttributeError(f"module 'fretwear' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_API))
