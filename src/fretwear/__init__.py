"""fretwear: coupled vibration and fretting wear of frictional contact interfaces.

Implements the "DLFT with wear" method of Salles, Blanc, Thouverez and Gousskov (2011),
Int. J. Solids Struct. 48, 1513-1524, and goes beyond it (3D contact, continuation, adaptive
slow-time steps, time-domain reference solvers).

The public API, stage by stage (data flows one way; each stage returns a plain data object)::

    model = fretwear.rectangle(...) / fretwear.from_mesh(...) / fretwear.from_matrices(...)
    cond  = fretwear.exact_condenser(model)                       # Condenser: built once
    red   = fretwear.condense(model, frequency, basis.orders, condenser=cond)  # Reduced (Z_r)
    sol   = fretwear.solve_periodic(model, basis, frequency, condenser=cond)   # PeriodicSolution
    frf   = fretwear.sweep(model, basis, f_min, f_max, n, condenser=cond)     # SweepResult
    fam   = fretwear.load_levels(model, basis, f_min, f_max, n, levels)  # FRFs over the level
    hill  = fretwear.sweep_stability(model, frf, condenser=cond)         # SweepStability
    nm    = fretwear.nonlinear_mode(model, basis, amplitudes)           # Backbone (EPMC)
    syn   = fretwear.mode_frf(model, nm)                  # ModalFRF (single-mode theory)
    wear  = fretwear.simulate_wear(model, basis, frequency, condenser=cond)   # WearResult
    worn  = fretwear.frf_worn(model, basis, wear.final_wear, f_min, f_max, n)  # SweepResult
    run   = fretwear.integrate(model, frequency, n_periods=...)   # TransientResult
    out   = fretwear.run_case("case.toml", "out/")                # a case file end to end
    out   = fretwear.run(model, "sweep", "out/", f_min=..., ...)  # a Python model, the same way
    path  = fretwear.write_results(frf, "out/", model, basis)     # results.nc of a Python result
    files = fretwear.plot(frf, "out/", model, basis)              # its figures (and ParaView)
    ds    = fretwear.read_results("out/results.nc")               # an xarray Dataset
    st    = fretwear.run_study("study.toml", "out/")              # members on Dask (study.nc)

The condensation of a model is an object its caller owns (``exact_condenser``, the
Craig-Bampton ``modal_condenser`` for large interfaces, or ``condenser(model, method, f_max=,
max_order=)``: ``"exact"``, ``"modal"`` or ``"auto"``, the modal one where it is cheaper, with
modes raised until its error check passes): build it once and pass it as ``condenser=`` to
every driver that condenses the same model; without it each call builds its own exact one.

One vocabulary and argument order at every entry point (:mod:`fretwear.api`): ``model, basis``
first, then the frequency or the band; the stick anchors are ``anchor``, the initial wear
``wear0``, the Archard coefficient ``wear_coefficient``; ``frequency`` is required wherever it
matters (a quasi-static solve can do without). Every frequency argument is in Hz
(``frequency``, ``f_min``, ``f_max``); objects also keep the circular frequency
``omega = 2 pi frequency`` [rad/s] where the equations use it. Every
result has ``success`` (bool) and ``message`` (str), as :class:`scipy.optimize.OptimizeResult`.

Names are loaded on first use, so ``import fretwear`` stays light. The drivers run with one
BLAS thread, from Python as from the command line (:mod:`fretwear.threads`; change it with
``fretwear.set_blas_threads(n)`` or the environment variable ``FRETWEAR_THREADS``).
``docs/api.md`` has runnable examples.
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
    "ContactDofs": "fretwear.model.matrices",
    # harmonic balance
    "FourierBasis": "fretwear.hb.fourier", "condense": "fretwear.hb.reduce",
    "exact_condenser": "fretwear.hb.reduce", "modal_condenser": "fretwear.hb.modal",
    "condenser": "fretwear.hb.condensers",
    "Reduced": "fretwear.hb.reduce", "solve_periodic": "fretwear.api",
    "PeriodicSolution": "fretwear.hb.solution", "SweepResult": "fretwear.hb.sweep_result",
    "sweep": "fretwear.api", "SolveOptions": "fretwear.hb.options",
    "SweepOptions": "fretwear.hb.options",
    "nonlinear_mode": "fretwear.api", "sweep_stability": "fretwear.hb.sweep_stability",
    "mode_frf": "fretwear.api",
    # linear
    "modes": "fretwear.linear", "frf": "fretwear.linear",
    # one sector of a tuned bladed disk (cyclic symmetry)
    "cyclic_sector": "fretwear.model.cyclic", "neighbour_contact": "fretwear.model.cyclic",
    "whole_disk": "fretwear.model.cyclic", "cyclic_condenser": "fretwear.hb.cyclic",
    "cyclic_modes": "fretwear.hb.cyclic", "cyclic_frf": "fretwear.hb.cyclic",
    "centrifugal_load": "fretwear.model.rotation",
    # a mistuned disk: the N sectors made to differ
    "mistuning": "fretwear.model.mistuning", "random_mistuning": "fretwear.model.mistuning",
    "mistuned_disk": "fretwear.model.mistuning", "whitehead_bound": "fretwear.model.mistuning",
    "blade_amplitudes": "fretwear.model.mistuning",
    "amplification_factor": "fretwear.model.mistuning",
    "sector_responses": "fretwear.model.mistuning", "lumped_blisk": "fretwear.examples.blisk",
    # wear
    "simulate_wear": "fretwear.api", "frf_worn": "fretwear.api",
    "worn_state": "fretwear.api", "WornStateOptions": "fretwear.wear.worn_state",
    "WearOptions": "fretwear.wear", "WearResult": "fretwear.wear",
    "BalanceSetup": "fretwear.wear", "RunControl": "fretwear.wear",
    # time domain
    "integrate": "fretwear.api", "steady_state": "fretwear.api",
    "incremental_wear": "fretwear.api",
    "check_periodic": "fretwear.timedomain.stability",
    "IntegrationOptions": "fretwear.timedomain.options",
    "InitialState": "fretwear.timedomain.options",
    "SteadyStateOptions": "fretwear.timedomain.options",
    "IncrementalWearOptions": "fretwear.timedomain.options",
    # case files and results
    "run_case": "fretwear.analyses.run", "load_case": "fretwear.analyses.run",
    "read_results": "fretwear.io.results",
    "load_levels": "fretwear.levels", "LoadLevels": "fretwear.levels",
    "run": "fretwear.analyses.python_run", "write_results": "fretwear.analyses.python_run",
    "plot": "fretwear.analyses.python_run",
    "run_study": "fretwear.study.run", "read_study": "fretwear.study.spec",
    # BLAS threads of the drivers
    "blas_threads": "fretwear.threads", "set_blas_threads": "fretwear.threads",
    # errors
    "FretwearError": "fretwear.errors", "InputError": "fretwear.errors",
    "ConvergenceError": "fretwear.errors",
}

__all__ = ["__version__", *_API]


#: the subpackages, reachable as attributes (``fw.model.join``, ``fw.hb``, ``fw.linear``) as
#: after ``import fretwear.model``, loaded on first use like the names above
_SUBPACKAGES = ("model", "hb", "linear", "wear", "timedomain", "io", "analyses", "study",
                "paper", "examples", "api", "errors", "limits", "files", "threads")


def __getattr__(name: str):
    if name in _SUBPACKAGES:
        value = importlib.import_module(f"fretwear.{name}")
        globals()[name] = value
        return value
    module = _API.get(name)
    if module is None:
        raise AttributeError(f"module 'fretwear' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_API) | set(_SUBPACKAGES))
