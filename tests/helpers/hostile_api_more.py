"""The hostile calls of every public name of :mod:`fretwear` that tests/helpers/hostile_api.py
does not already cover: each argument of a small valid call replaced by a few wrong values
(:data:`FEW`), one at a time.

A record that fretwear returns or takes (``Model``, ``Mesh``, ``SweepResult``...) is called
by building it with the wrong value and handing it to the function that takes it (the
``use`` of its target), since that is where a wrong record has its effect. The objects the
valid calls need (a three-DOF model with a contact, its periodic solution, sweep, backbone,
wear run, a lumped bladed-disk sector) are built once per :func:`targets` call, small enough
that the survey stays a few seconds of CPU per target.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import fretwear as fw

#: the wrong values tried for each argument of these targets
FEW = ("1", None, math.nan, -1, 10**30, [], object())

#: public names that are not functions or records to call: what each is, and the check the
#: survey makes of it instead of hostile calls
NOT_CALLED = {
    "__version__": "the version string (checked: a non-empty str)",
    "FretwearError": "the base exception of fretwear (checked: an Exception subclass)",
    "InputError": "the exception of a wrong input (checked: a FretwearError subclass)",
    "ConvergenceError": "the exception of a failed solve (checked: a FretwearError subclass)",
}


#: the public names the targets of :func:`targets` call (kept beside them: a test checks that
#: these with hostile_api.COVERS and :data:`NOT_CALLED` are every name of fretwear.__all__)
TARGET_NAMES = ("Mesh", "Model", "ContactInterface", "Load", "ObservedPoint", "Spring", "Traction",
                "NodalForce", "read_matrix_market", "condense", "exact_condenser",
                "modal_condenser", "condenser", "Reduced", "solve_periodic", "PeriodicSolution",
                "sweep", "SweepResult", "nonlinear_mode", "sweep_stability", "mode_frf",
                "cyclic_sector", "neighbour_contact", "whole_disk", "cyclic_condenser",
                "cyclic_modes", "cyclic_frf", "centrifugal_load", "mistuning", "random_mistuning",
                "mistuned_disk", "whitehead_bound", "blade_amplitudes", "amplification_factor",
                "sector_responses", "lumped_blisk", "simulate_wear", "frf_worn", "worn_state",
                "WornStateOptions", "WearResult", "BalanceSetup", "RunControl", "integrate",
                "steady_state", "incremental_wear", "check_periodic", "IntegrationOptions",
                "InitialState", "SteadyStateOptions", "IncrementalWearOptions", "run_case",
                "load_case", "read_results", "load_levels", "LoadLevels", "run", "write_results",
                "plot", "run_study", "read_study", "blas_threads", "set_blas_threads")


def check_not_called() -> list[str]:
    """The failed checks of :data:`NOT_CALLED` (empty when all hold)."""
    bad = []
    if not (isinstance(fw.__version__, str) and fw.__version__):
        bad.append("__version__")
    if not issubclass(fw.FretwearError, Exception):
        bad.append("FretwearError")
    for name in ("InputError", "ConvergenceError"):
        if not issubclass(getattr(fw, name), fw.FretwearError):
            bad.append(name)
    return bad


def _K():
    return np.array([[3e6, -1e6, 0.0], [-1e6, 2e6, -5e5], [0.0, -5e5, 1e6]])


def _chain():
    """Three DOFs, a contact node (normal DOF 1 pressed by a constant load, tangential DOF 2)
    and a harmonic force on DOF 0."""
    return fw.from_matrices(
        _K(), np.diag([0.3, 0.1, 0.05]), damping=fw.Damping(loss_factor=0.01),
        contact=fw.ContactDofs(normal_dofs=[1], tangential_dofs=[2], mu=0.3, area=1e-4,
                               wear_coefficient=1e-13),
        loads=[fw.Load(np.array([0.0, -10.0, 0.0]), "constant", name="N"),
               fw.Load(np.array([5.0, 0.0, 0.0]), "cos", name="F")],
        observed={"tip": [0]})


class Objects:
    """The valid objects the calls need, built once."""

    def __init__(self, folder: Path):
        self.folder = Path(folder)
        self.model = _chain()
        self.basis = fw.FourierBasis.up_to(1, 16)
        self.sol = fw.solve_periodic(self.model, self.basis, 500.0, time_domain=False)
        self.sweep = fw.sweep(self.model, self.basis, 400.0, 600.0, 2, time_domain=False)
        self.backbone = fw.nonlinear_mode(self.model, self.basis, [1e-7, 1e-6])
        self.wear = fw.simulate_wear(self.model, self.basis, quasi_static=True,
                                     time_domain=False, options=fw.WearOptions(max_steps=1))
        self.sector = fw.lumped_blisk(4)
        self.mesh = fw.rectangle(0.02, 0.01, 4, 2)
        self.case = self.folder / "case.toml"
        self.case.write_text(CASE)
        self.results = self.folder / "made" / "results.nc"
        fw.write_results(self.sol, self.results.parent, self.model, self.basis)
        self.study = self.folder / "study.toml"
        self.study.write_text(f'base = "{self.case.name}"\n[grid]\n"contact.mu" = [0.2, 0.3]\n')


#: a small valid case file (the three DOFs of :func:`_chain` as user matrices, a modes run)
CASE = """
[model]
type = "matrices"
K = [[3e6, -1e6, 0.0], [-1e6, 2e6, -5e5], [0.0, -5e5, 1e6]]
M = [[0.3, 0, 0], [0, 0.1, 0], [0, 0, 0.05]]
[contact]
normal_dofs = [1]
tangential_dofs = [2]
mu = 0.3
[analysis]
type = "modes"
n_modes = 2
[output]
figures = false
"""


def targets(o: Objects) -> list[tuple[str, str, object, dict]]:
    """(label, the public name covered, function of keyword arguments, the valid keyword
    arguments) of every call."""
    m, b, sec = o.model, o.basis, o.sector
    c = m.contact
    out = o.folder / "out"

    def model_with(**kw):
        args = dict(K=sp.csr_matrix(_K()), M=sp.csr_matrix(np.diag([0.3, 0.1, 0.05])),
                    contact=c, loads=list(m.loads), observed=list(m.observed))
        args.update(kw)
        return fw.modes(fw.Model(**args), 2)

    def interface_with(**kw):
        args = {f: getattr(c, f) for f in ("dofs", "frame", "gap", "area", "mu", "coords")}
        args.update(kw)
        return model_with(contact=fw.ContactInterface(**args))

    def mesh_with(**kw):
        args = dict(points=o.mesh.points, cells=o.mesh.cells, cell_type=o.mesh.cell_type,
                    boundaries=o.mesh.boundaries)
        args.update(kw)
        return fw.from_mesh(fw.Mesh(**args), fw.Material(210e9, 0.3, 7800.0), thickness=0.01,
                            supports=[fw.Spring("top_left", "x", 1e7)],
                            contact=fw.ContactSpec("bottom", mu=0.3))

    def sweep_with(**kw):
        args = dict(points=o.sweep.points)
        args.update(kw)
        return fw.write_results(fw.SweepResult(**args), out, m, b)

    return [
        ("Mesh", "Mesh", mesh_with, dict(points=o.mesh.points, cells=o.mesh.cells,
                                         cell_type=o.mesh.cell_type)),
        ("Model", "Model", model_with, dict(K=sp.csr_matrix(_K()), contact=c)),
        ("ContactInterface", "ContactInterface", interface_with,
         dict(dofs=c.dofs, gap=c.gap, area=c.area, mu=c.mu)),
        ("Load", "Load", lambda **k: model_with(loads=[fw.Load(**k)]),
         dict(vector=np.array([1.0, 0.0, 0.0]), waveform="cos", name="F")),
        ("ObservedPoint", "ObservedPoint", lambda **k: model_with(observed=[
            fw.ObservedPoint(**k)]), dict(name="p", dofs=np.array([0]), coords=np.zeros(1))),
        ("Spring", "Spring", lambda **k: fw.from_mesh(
            o.mesh, fw.Material(210e9, 0.3, 7800.0), thickness=0.01,
            supports=[fw.Spring(**k)], contact=fw.ContactSpec("bottom", mu=0.3)),
         dict(at="top_left", direction="x", stiffness=1e7)),
        ("Traction", "Traction", lambda **k: fw.from_mesh(
            o.mesh, fw.Material(210e9, 0.3, 7800.0), thickness=0.01,
            supports=[fw.Spring("top_left", "x", 1e7)], loads=[fw.Traction(**k)],
            contact=fw.ContactSpec("bottom", mu=0.3)),
         dict(boundary="right", pressure=1e5, waveform="cos")),
        ("NodalForce", "NodalForce", lambda **k: fw.from_mesh(
            o.mesh, fw.Material(210e9, 0.3, 7800.0), thickness=0.01,
            supports=[fw.Spring("top_left", "x", 1e7)], loads=[fw.NodalForce(**k)],
            contact=fw.ContactSpec("bottom", mu=0.3)),
         dict(at="top_right", force=(0.0, 1.0), waveform="cos")),
        ("read_matrix_market", "read_matrix_market", fw.read_matrix_market,
         dict(path=o.folder / "missing.mtx")),
        ("condense", "condense", fw.condense, dict(model=m, frequency=500.0, orders=[0, 1])),
        ("exact_condenser", "exact_condenser", fw.exact_condenser, dict(model=m)),
        ("modal_condenser", "modal_condenser", fw.modal_condenser,
         dict(model=m, f_max=1e3, max_order=1, modes=2)),
        ("condenser", "condenser", fw.condenser, dict(model=m, method="exact")),
        ("Reduced", "Reduced", lambda **k: fw.solve_periodic(
            m, b, 500.0, reduced=fw.Reduced(**k), time_domain=False),
         dict(omega=2 * np.pi * 500.0, orders=np.array([0, 1]), Z=None, F=None, obs_A=None,
              obs_b=None, obs_dofs=np.array([0]))),
        ("solve_periodic", "solve_periodic", fw.solve_periodic,
         dict(model=m, basis=b, frequency=500.0, time_domain=False)),
        ("PeriodicSolution", "PeriodicSolution", lambda **k: fw.check_periodic(m, **k),
         dict(sol=o.sol)),
        ("sweep", "sweep", fw.sweep, dict(model=m, basis=b, f_min=400.0, f_max=600.0,
                                          n_points=2, time_domain=False)),
        ("SweepResult", "SweepResult", sweep_with, dict(points=o.sweep.points)),
        ("nonlinear_mode", "nonlinear_mode", fw.nonlinear_mode,
         dict(model=m, basis=b, amplitudes=[1e-7], mode=1)),
        ("sweep_stability", "sweep_stability", fw.sweep_stability, dict(model=m,
                                                                         result=o.sweep)),
        ("mode_frf", "mode_frf", fw.mode_frf, dict(model=m, backbone=o.backbone)),
        ("cyclic_sector", "cyclic_sector", fw.cyclic_sector,
         dict(model=sec.model, n_sectors=4, left="left", right="right")),
        ("neighbour_contact", "neighbour_contact", fw.neighbour_contact,
         dict(sector=sec, spec=fw.ContactSpec("bottom", mu=0.3, partner="top"))),
        ("whole_disk", "whole_disk", fw.whole_disk, dict(sector=sec, engine_order=0)),
        ("cyclic_condenser", "cyclic_condenser", fw.cyclic_condenser,
         dict(sector=sec, engine_order=1)),
        ("cyclic_modes", "cyclic_modes", fw.cyclic_modes, dict(sector=sec, k=1, n_modes=2)),
        ("cyclic_frf", "cyclic_frf", fw.cyclic_frf, dict(sector=sec, engine_order=1,
                                                         frequencies=[400.0])),
        ("centrifugal_load", "centrifugal_load", fw.centrifugal_load,
         dict(model=fw.from_mesh(o.mesh, fw.Material(210e9, 0.3, 7800.0), thickness=0.01,
                                 supports=[fw.Spring("top_left", "x", 1e7)],
                                 contact=fw.ContactSpec("bottom", mu=0.3)), speed=100.0)),
        ("mistuning", "mistuning", fw.mistuning, dict(n_sectors=4, young=[1.0, 1.01, 0.99, 1.0])),
        ("random_mistuning", "random_mistuning", fw.random_mistuning,
         dict(n_sectors=4, std=0.01, seed=1)),
        ("mistuned_disk", "mistuned_disk", fw.mistuned_disk,
         dict(sector=sec, engine_order=1, mistuned=fw.mistuning(4, young=[1.0, 1.01, 0.99,
                                                                         1.0]))),
        ("whitehead_bound", "whitehead_bound", fw.whitehead_bound, dict(n_sectors=4)),
        ("blade_amplitudes", "blade_amplitudes", fw.blade_amplitudes,
         dict(amplitude=np.ones(4))),
        ("amplification_factor", "amplification_factor", fw.amplification_factor,
         dict(mistuned=np.ones(4), tuned=np.ones(4))),
        ("sector_responses", "sector_responses", fw.sector_responses,
         dict(sector=sec, U=np.zeros(4 * sec.model.ndof))),
        ("lumped_blisk", "lumped_blisk", fw.lumped_blisk, dict(n_sectors=4, mu=0.3)),
        ("simulate_wear", "simulate_wear", fw.simulate_wear,
         dict(model=m, basis=b, quasi_static=True, time_domain=False,
              options=fw.WearOptions(max_steps=1))),
        ("frf_worn", "frf_worn", fw.frf_worn,
         dict(model=m, basis=b, wear=np.zeros(1), f_min=400.0, f_max=600.0, n_points=2,
              time_domain=False)),
        ("worn_state", "worn_state", fw.worn_state,
         dict(model=m, basis=b, quasi_static=True, time_domain=False,
              options=fw.WornStateOptions(max_steps=1))),
        ("WornStateOptions", "WornStateOptions", fw.WornStateOptions,
         dict(tolerance=1e-6, max_steps=10, max_growth=100.0)),
        ("WearResult", "WearResult", lambda **k: fw.write_results(
            fw.WearResult(**k), out, m, b),
         dict(history=o.wear.history, initial=o.wear.initial, final=o.wear.final,
              stop_reason="max_steps", message="", success=True, wall_time=0.0)),
        ("BalanceSetup", "BalanceSetup", lambda **k: fw.simulate_wear(
            m, b, quasi_static=True, time_domain=False, options=fw.WearOptions(max_steps=1),
            balance=fw.BalanceSetup(**k)), dict(eps="auto")),
        ("RunControl", "RunControl", lambda **k: fw.simulate_wear(
            m, b, quasi_static=True, time_domain=False, options=fw.WearOptions(max_steps=1),
            run=fw.RunControl(**k)), dict(checkpoint=o.folder / "w.npz", resume=False)),
        ("integrate", "integrate", fw.integrate, dict(model=m, frequency=500.0, n_periods=2)),
        ("steady_state", "steady_state", fw.steady_state,
         dict(model=m, frequency=500.0, options=fw.SteadyStateOptions(max_periods=200))),
        ("incremental_wear", "incremental_wear", fw.incremental_wear,
         dict(model=m, wear_coefficient=1e-13, n_cycles=1)),
        ("check_periodic", "check_periodic", fw.check_periodic,
         dict(model=m, sol=o.sol, max_periods=50)),
        ("IntegrationOptions", "IntegrationOptions", fw.IntegrationOptions,
         dict(steps_per_period=64, gamma=0.5, contact_tol=1e-10)),
        ("InitialState", "InitialState", lambda **k: fw.integrate(
            m, 500.0, n_periods=1, start=fw.InitialState(**k)),
         dict(U0=np.zeros(3), V0=np.zeros(3))),
        ("SteadyStateOptions", "SteadyStateOptions", fw.SteadyStateOptions,
         dict(max_periods=100, tol=1e-6, harmonics=3)),
        ("IncrementalWearOptions", "IncrementalWearOptions", fw.IncrementalWearOptions,
         dict(steps_per_cycle=32, cycle_jump=1, record_every=1)),
        ("run_case", "run_case", fw.run_case, dict(path=o.case, outdir=out, progress=False,
                                                   echo=False)),
        ("load_case", "load_case", fw.load_case, dict(path=o.case)),
        ("read_results", "read_results", fw.read_results, dict(path=o.results)),
        ("load_levels", "load_levels", fw.load_levels,
         dict(model=m, basis=b, f_min=400.0, f_max=600.0, n_points=2, levels=[1.0])),
        ("LoadLevels", "LoadLevels", lambda **k: fw.write_results(fw.LoadLevels(**k), out, m,
                                                                  b),
         dict(levels=[1.0], results=[o.sweep])),
        ("run", "run", fw.run, dict(model=m, analysis={"type": "modes", "n_modes": 2},
                                    output=out)),
        ("write_results", "write_results", fw.write_results,
         dict(result=o.sol, output=out, model=m, basis=b)),
        ("plot", "plot", fw.plot, dict(result=o.sol, output=out, model=m, basis=b,
                                       vtu=False)),
        ("run_study", "run_study", fw.run_study,
         dict(path=o.study, outdir=o.folder / "study-out", collect=True, echo=False,
              progress=False)),
        ("read_study", "read_study", fw.read_study, dict(path=o.study)),
        ("blas_threads", "blas_threads", lambda **k: fw.blas_threads(**k), {}),
        ("set_blas_threads", "set_blas_threads", fw.set_blas_threads, dict(n=None)),
    ]
