"""Cost of the periodic solve, the condensation, sweeps and wear runs on large 3D interfaces.

The model: a steel pad 10 x 10 x 1.25 mm (hexahedra of about 0.3 mm) pressed on a rigid flat
with springs on its top face (1e7 N/m along x and y), the contact face with n x n nodes (3
DOFs each), 7 harmonics, 128 samples per period. Two loads (``--load``):

* ``slip`` (default): the fretting case. 10 MPa, mu = 0.3, a harmonic tangential traction of
  0.95 mu P at 30 degrees to x at 1 kHz, the modal condensation with 10 fixed-interface modes:
  the interface is in partial slip, 6-7 % of the contact area x period slipping along both
  tangential directions (printed: the area-weighted slip fraction, the share of the slip
  path along each tangent and the nodes that slip along both). ``--ratio`` sets the
  traction (0.8 mu P leaves 1 % of area x period slipping at 256 nodes; 0.95: 6.7 %).
  ``--damped`` adds Rayleigh stiffness damping (2 % at 100 kHz: complex ``Z_r`` blocks).
* ``stuck``: the earlier load, 1 MPa, mu = 0.5, 0.8 mu P along x at 5 kHz, the default modal
  condensation: 99.5 % of area x period sticks and the full balance needs no iteration after
  the one-harmonic start (docs/theory.md, "Large interfaces").

For each size, in a fresh process (so that the peak memory is that size's), it prints:
unknowns ``3 n^2 (2 H + 1)``, the condensation (the modal representation of
fretwear.hb.modal with its error check against the exact condensation, and the exact
condensation itself where it runs in minutes), the periodic solve (fretwear's
solve_periodic: static preload, harmonic continuation start, Powell with the Newton step of
fretwear.hb.krylov), its Powell iterations, Newton steps and GMRES iterations, the contact
states, the peak resident memory, and, with ``--dense-lu`` where a dense matrix of the
Jacobian's size fits in 4 GiB, one dense LU of that size timed in the same process (what the
dense path pays per iteration). CPU seconds of the process are printed beside wall seconds:
the machine is shared.

eps: the default rule of each driver (``"auto"`` for the periodic solve and the wear run,
``"top"`` for the sweep; fretwear.hb.penalty: a power-iteration estimate of the spectral radius
above 256 rows), its cost included in the times.

Optionally (``--sweep N`` / ``--wear N``) it times a sweep of N points over 0.8-1.2 times the
load's frequency (default options) and a wear run of N slow steps (explicit Euler with the
adaptive jump: the linearly implicit default needs one solve per contact node for its slow
Jacobian, see docs/theory.md "Large interfaces") at the size given to ``--extras-size``, each
writing its checkpoint (sweep-checkpoint.npz, wear-checkpoint.npz, sizes printed) into a
temporary folder.

Sizes: 8, 16, 32 and 64 nodes a side (64 to 4096 contact nodes). A size whose estimated peak
memory (:func:`estimate_gib`, checked against the measured peak of the sizes that run) is
above ``LIMIT_GIB`` = 12 GiB is not run: the estimate and its parts are printed instead.
4096 nodes are estimated at 9.6 GiB (fretwear.hb.modal builds the blocked condenser there:
no ``Psi``, no dense block per harmonic; with dense blocks it was 39 GiB), so ``--sizes 64``
runs; benchmarks/scale_4096.py times that size alone and prints its parts. Every size runs
under that address-space limit.

The last lines read ``solve_1024_slip_s=`` (``solve_1024_s=`` with ``--load stuck``),
``condense_1024_s=`` and ``peak_rss_1024_gib=`` (CPU seconds and GiB of the 32 x 32 size,
when it was run).

With ``--alternate N`` it also times the 256- and 1024-node solves alternately in one
process, N times each, and prints the growth of their medians: the machine's speed drifts
(30 % within an hour was measured), and two sizes run minutes apart carry that drift into
their ratio.

Run: ``python benchmarks/scale_3d.py [--load slip|stuck] [--sizes 8,16,32,64] [--sweep 50
--wear 20 --extras-size 32] [--alternate 4]``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass

import numpy as np

A, H = 0.01, 7


@dataclass(frozen=True)
class Load:
    """A load case of the pad: pressure [Pa], friction coefficient, tangential traction
    amplitude (ratio of mu P) and its angle to x [degrees], frequency [Hz], fixed-interface
    modes of the modal condensation (None: its default selection), Rayleigh stiffness damping
    (2 % at 100 kHz) or none, and the attempts of the periodic solve."""

    name: str
    pressure: float
    mu: float
    ratio: float
    angle_deg: float
    freq: float
    modes: int | None
    damped: bool = False
    strategy: str = ""  # attempts of the periodic solve ("": solve_periodic's default)


LOADS = {"slip": Load("slip", 10e6, 0.3, 0.95, 30.0, 1000.0, 10),
         "stuck": Load("stuck", 1e6, 0.5, 0.8, 0.0, 5000.0, None)}
#: no size is run whose estimated peak memory (:func:`estimate_gib`) is above this, and
#: every size runs under this address-space limit (the machine is shared)
LIMIT_GIB = 12.0


def layers(n: int) -> int:
    """Element layers through the thickness of the pad with n x n contact nodes."""
    return max(1, round((n - 1) / 8))


def estimate_gib(n: int, damped: bool = False) -> dict:
    """Peak memory [GiB] of one size, estimated from the arrays that grow with it (the sizes
    measured at 32 x 32 check it, docs/theory.md).

    Where fretwear.hb.modal.modal_condenser builds the dense condenser (up to 1024 nodes):
    the reduced model ``Z_r`` (H + 1 real m x m blocks when the pad is undamped, as
    fretwear.hb.modal stores them; complex when ``damped``), the static constraint modes
    ``Psi`` (n_i x m reals) with one product of their size while they are projected, and work
    arrays: ten real m x m (the projected stiffness and mass in both frames, a harmonic's
    condensation, the kept harmonic 0, the active sub-blocks and the preconditioner's
    factors; calibrated on the 2.2 GiB measured at 1024 nodes) and 0.4 GiB of Python, NumPy,
    SciPy and numba. An upper bound since that condenser returns ``Z_r`` as an operator above
    3000 real unknowns (fretwear.hb.modal.OPERATOR_MIN_UNKNOWNS: 2 m x m instead of H + 1;
    1024 nodes, partial slip: 1.90 GiB peak against 2.37 GiB with the dense blocks).

    Where it builds the blocked one (fretwear.hb.modal, 4096 nodes; not yet
    measured at that size): the shared ``K^cc, M^cc`` (two real m x m; four complex-sized
    when ``damped``), the sparse LU of ``K_ii`` (8.9e6 non-zeros measured at 1024 nodes, 12
    bytes each, grown as n_i^(4/3)), work arrays: the active sub-blocks (two m x m at most),
    one formed block and the preconditioner's factors (at most 2 GiB), and the same base."""
    m = 3 * n * n
    ni = 3 * n * n * (layers(n) + 1) - m
    w = 16 if damped else 8
    if 8.0 * (ni * m + (H + 5) * m * m) / 2**30 <= 6.0:  # modal.DENSE_STORAGE_GIB
        parts = {"Z_r": (H + 1) * m * m * w, "Psi": 2 * ni * m * 8, "work": 10 * m * m * w,
                 "base": 0.4 * 2**30}
    else:
        parts = {"K^cc, M^cc": 2 * m * m * w, "LU K_ii": 12 * 8.9e6 * (ni / 12288) ** (4 / 3),
                 "work": 3 * m * m * w + 2 * 2**30, "base": 0.4 * 2**30}
    parts = {k: v / 2**30 for k, v in parts.items()}
    parts["total"] = sum(parts.values())
    return parts


def pad(n: int, load: Load):
    """The pad with n x n contact nodes under ``load``."""
    from fretwear.model import (
        ContactSpec,
        Damping,
        Material,
        Spring,
        Traction,
        box,
        from_mesh,
    )

    ne = n - 1
    q = load.ratio * load.mu * load.pressure
    t = np.radians(load.angle_deg)
    damping = Damping(rayleigh_stiffness=0.02 / (2 * np.pi * 1e5)) if load.damped else None
    return from_mesh(box(A, A, A / 8, ne, ne, layers(n)), Material(210e9, 0.3, 7800.0),
                     supports=[Spring("zmax", "x", 1e7), Spring("zmax", "y", 1e7)],
                     damping=damping,
                     loads=[Traction("zmax", pressure=load.pressure),
                            Traction("zmax", traction=(q * np.cos(t), q * np.sin(t), 0.0),
                                     waveform="cos")],
                     contact=ContactSpec("zmin", mu=load.mu, wear_coefficient=1e-15))


def condenser(model, load: Load):
    """The modal condensation of the load case (fretwear.hb.modal.modal_condenser), passed
    to every call below."""
    from fretwear.hb.modal import modal_condenser

    extra = {} if load.modes is None else {"modes": load.modes}
    return modal_condenser(model, load.freq * 1.2, H, **extra)


def options(load: Load):
    """The SolveOptions of the periodic solve for ``load`` (PERIODIC with the load's
    ``strategy`` when it names one)."""
    from fretwear.hb.options import PERIODIC

    if not load.strategy:
        return PERIODIC
    return PERIODIC.replace(strategy=tuple(load.strategy.split(",")))


def slip_report(sol) -> dict:
    """The interface state of a solution: fractions of the contact area x period that
    separate, stick and slip (area-weighted), the same per node (unweighted mean), the share
    of the slip path (sum over slip instants of |dX| per tangent, contact-local) along each
    tangent, and the nodes whose slip path along each tangent is at least a tenth of the
    other's (slipping along both directions)."""
    frac = sol.state_fractions()
    area = np.asarray(sol.area, float)
    w = frac.T @ area / area.sum()
    dx = np.abs(sol.x_t[:, 1:, :] - np.roll(sol.x_t[:, 1:, :], 1, axis=2))
    dx[np.broadcast_to((sol.state != 2)[:, None, :], dx.shape)] = 0.0
    path = dx.sum(axis=2)  # (nc, 2)
    total = max(float(path.sum()), 1e-300)
    both = int(np.sum((path[:, 0] >= 0.1 * path[:, 1]) & (path[:, 1] >= 0.1 * path[:, 0])
                      & (path.sum(axis=1) > 0)))
    return {"sep": w[0], "stick": w[1], "slip": w[2], "slip_nodes": frac[:, 2].mean(),
            "slip_share_t1": float(path[:, 0].sum()) / total,
            "slip_share_t2": float(path[:, 1].sum()) / total, "slip_both_nodes": both,
            "slipping_nodes": int(np.sum(path.sum(axis=1) > 0))}


class Counts:
    """Newton steps and GMRES iterations of the solves run inside it (benchmark only: wraps
    fretwear.hb.solvers._lu_step and fretwear.hb.krylov.KrylovJacobian.solve)."""

    def __enter__(self):
        from fretwear.hb import krylov, solvers

        self.steps, self.gmres = 0, []
        self._lu, self._solve = solvers._lu_step, krylov.KrylovJacobian.solve

        def lu_step(J, f, *a):
            self.steps += 1
            return self._lu(J, f, *a)

        def solve(J, b, *a, **k):
            n0 = J.gmres_iterations
            out = self._solve(J, b, *a, **k)
            self.gmres.append(J.gmres_iterations - n0)
            return out

        solvers._lu_step, krylov.KrylovJacobian.solve = lu_step, solve
        return self

    def __exit__(self, *exc):
        from fretwear.hb import krylov, solvers

        solvers._lu_step, krylov.KrylovJacobian.solve = self._lu, self._solve


class Clock:
    """CPU seconds of the process (``cpu``) and wall seconds (``wall``) of a ``with`` block."""

    def __enter__(self):
        self.c, self.w = time.process_time(), time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.cpu, self.wall = time.process_time() - self.c, time.perf_counter() - self.w

    def __str__(self):
        return f"{self.cpu:.1f} s CPU, {self.wall:.1f} s wall"


def peak_gib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20


def warm_up(load: Load):
    """Untimed: a 16-node solve and one Jacobian of it on the operator path (the column norms'
    kernel), which load the compiled kernels from numba's cache (about 0.7 s, the same at
    every size), so that the solve times and their growth with the size are those of the
    solve. The 256-node solve takes the dense path, the 1024-node one the operator path:
    without the second part only the latter would pay for loading its kernel."""
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.periodic import solve_periodic
    from fretwear.hb.preload import static_anchor
    from fretwear.hb.problem import DLFTProblem
    from fretwear.hb.reduce import condense

    small, basis = pad(4, load), FourierBasis.up_to(H, 128)
    anchor = static_anchor(small)
    sol = solve_periodic(small, basis, frequency=load.freq, anchor=anchor)
    prob = DLFTProblem(condense(small, load.freq, basis.orders), small.contact, basis,
                       eps=sol.eps, anchor=anchor, jacobian="krylov")
    _, J = prob.residual(sol.U.reshape(prob.m, prob.H), True)
    J.column_norms()


def one(n: int, extras: dict, load: Load) -> dict:
    """Everything for one size (run in its own process)."""
    import scipy.linalg as sla

    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.periodic import solve_periodic
    from fretwear.hb.preload import static_anchor
    from fretwear.hb.reduce import exact_condenser

    out = {"n": n, "nodes": n * n, "load": load.name, "load_before": os.getloadavg()[0]}
    with Clock() as c:
        warm_up(load)
    out["warmup_cpu"] = c.cpu
    with Clock() as c:
        model = pad(n, load)
    out.update(ndof=model.ndof, build_cpu=c.cpu, build_wall=c.wall)
    basis = FourierBasis.up_to(H, 128)
    out["unknowns"] = 3 * n * n * basis.size
    with Clock() as c:
        mc = condenser(model, load)
        red = mc.reduced(2 * np.pi * load.freq, basis.orders, frequency=load.freq)
    out.update(condense_cpu=c.cpu, condense_wall=c.wall, modes=mc.n_modes, q=mc.q,
               modal_error=mc.error)
    if n * n <= 256:  # the exact condensation, for comparison
        with Clock() as c:
            ex = exact_condenser(model).reduced(2 * np.pi * load.freq, basis.orders)
        out.update(exact_cpu=c.cpu, exact_wall=c.wall,
                   modal_vs_exact=float(max(np.abs(red.Z[b] - ex.Z[b]).max()
                                            / np.abs(ex.Z[b]).max() for b in range(H + 1))))
        del ex
    with Counts() as counts, Clock() as c:
        anchor = static_anchor(model, condenser=mc)  # the static preload state (default eps)
        sol = solve_periodic(model, basis, frequency=load.freq, options=options(load),
                             reduced=red, anchor=anchor, condenser=mc)
    out["eps"] = sol.eps
    out["attempts"] = [f"{a.method} ({a.iterations} iterations, {a.message})"
                       for a in sol.attempts]
    st = sol.stats
    out.update(solve_cpu=c.cpu, solve_wall=c.wall, success=sol.success, iterations=st.iterations,
               residual=st.residual, newton_steps=counts.steps, gmres=counts.gmres,
               active_nodes=int(np.sum(np.any(sol.state != 1, axis=1))), **slip_report(sol),
               load_after=os.getloadavg()[0])
    out["peak_gib"] = peak_gib()  # condensation + solve
    print("PARTIAL " + json.dumps(out, default=float), flush=True)
    tmp = tempfile.mkdtemp(prefix="scale3d-")
    if extras.get("wear"):
        from fretwear.wear.options import WearOptions
        from fretwear.wear.simulate import BalanceSetup, RunControl, simulate_wear

        ck = os.path.join(tmp, "wear-checkpoint.npz")
        with Clock() as c:
            wr = simulate_wear(model, basis, frequency=load.freq,
                               balance=BalanceSetup(reduced=red, anchor=sol.anchor, U0=sol.U,
                                                    condenser=mc),
                               run=RunControl(checkpoint=ck),
                               options=WearOptions(max_steps=extras["wear"],
                                                   scheme="explicit", checkpoint_every_s=0.0))
        out.update(wear_steps=len(wr.history.cycles) - 1, wear_cpu=c.cpu, wear_wall=c.wall,
                   wear_success=bool(wr.success), wear_message=wr.message,
                   wear_ckpt_mib=os.path.getsize(ck) / 2**20, peak_wear_gib=peak_gib())
        del wr
    print("PARTIAL " + json.dumps(out, default=float), flush=True)
    anchor = sol.anchor
    del red, sol  # the sweep condenses each of its frequencies itself (with mc)
    if extras.get("sweep"):
        from fretwear.hb.options import SweepOptions
        from fretwear.hb.sweep import sweep

        ck = os.path.join(tmp, "sweep-checkpoint.npz")
        with Clock() as c:
            res = sweep(model, basis, 0.8 * load.freq, 1.2 * load.freq, extras["sweep"],
                        options=SweepOptions(spacing="linear", checkpoint=ck), anchor=anchor,
                        condenser=mc)
        out.update(sweep_points=extras["sweep"], sweep_cpu=c.cpu, sweep_wall=c.wall,
                   sweep_converged=int(sum(p.success for p in res.points)),
                   sweep_ckpt_mib=os.path.getsize(ck) / 2**20,
                   peak_sweep_gib=peak_gib())
    out["peak_extras_gib"] = peak_gib()
    shutil.rmtree(tmp, ignore_errors=True)
    nu = out["unknowns"]
    if extras.get("dense_lu") and 8.0 * nu * nu <= 4 * 2**30:  # last: not the solve's memory
        M = np.random.default_rng(0).standard_normal((nu, nu)) + nu * np.eye(nu)
        with Clock() as c:
            sla.lu_factor(M, overwrite_a=True, check_finite=False)
        out.update(dense_lu_cpu=c.cpu, dense_lu_wall=c.wall)
    return out


def alternate(sizes: tuple[int, int], reps: int, load: Load) -> dict:
    """The solves of two sizes timed alternately in one process, ``reps`` times each (the
    machine's speed drifts between separate runs; alternating exposes both sizes to the
    same drift). Each timing is what ``one`` times: the static preload solve and the
    periodic solve on the condensation of the frequency (condensed once per size)."""
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.periodic import solve_periodic
    from fretwear.hb.preload import static_anchor

    basis = FourierBasis.up_to(H, 128)
    warm_up(load)  # untimed, as in one()
    cases = {}
    for n in sizes:
        model = pad(n, load)
        mc = condenser(model, load)
        cases[n] = model, mc, mc.reduced(2 * np.pi * load.freq, basis.orders,
                                         frequency=load.freq)
    times = {n: [] for n in sizes}
    for _ in range(reps):
        for n in sizes:
            model, mc, red = cases[n]
            with Clock() as c:
                sol = solve_periodic(model, basis, frequency=load.freq, options=options(load),
                                     reduced=red, anchor=static_anchor(model, condenser=mc),
                                     condenser=mc)
            if not sol.success:
                raise RuntimeError(f"{n * n} nodes: the periodic solve did not converge")
            times[n].append(c.cpu)
    return {"sizes": list(sizes), "times": {str(n): t for n, t in times.items()}}


def case_file(n: int, load: Load) -> str:
    """The TOML case file of :func:`pad` with ``n`` x ``n`` contact nodes under ``load``: a
    periodic analysis at the load's frequency with every other key at its default (as a
    user's first run; the condensation is the case file's default). One observed point,
    the centre of the top face (a periodic run without an ``[observed]`` point fails on
    main at d8665f3 while writing its results: ``displacement_coefficients`` of no point)."""
    q = load.ratio * load.mu * load.pressure
    t = np.radians(load.angle_deg)
    damping = (f"\n[damping]\nrayleigh_stiffness = {float(0.02 / (2 * np.pi * 1e5))!r}\n"
               if load.damped else "")
    return f"""title = "Steel pad on a rigid flat, {n * n} contact nodes, load {load.name}"

[model]
type = "box"
lx = {A!r}
ly = {A!r}
lz = {A / 8!r}
nx = {n - 1}
ny = {n - 1}
nz = {layers(n)}

[material]
E = 210e9
nu = 0.3
rho = 7800.0
{damping}
[[springs]]
at = "zmax"
direction = "x"
stiffness = 1e7

[[springs]]
at = "zmax"
direction = "y"
stiffness = 1e7

[[loads]]
name = "pressure"
boundary = "zmax"
pressure = {load.pressure!r}

[[loads]]
name = "fretting"
boundary = "zmax"
traction = [{float(q * np.cos(t))!r}, {float(q * np.sin(t))!r}, 0.0]
waveform = "cos"

[[contact]]
boundary = "zmin"
mu = {load.mu!r}
wear_coefficient = 1e-15

[observed]
top_centre = [{A / 2!r}, {A / 2!r}, {A / 8!r}]

[analysis]
type = "periodic"
frequency = {load.freq!r}
"""


def run_case(path: str, out: str) -> dict:
    """``fretwear run path -o out`` in this process (a child of the benchmark): exit status,
    CPU and wall seconds, peak memory and the run's summary lines."""
    import contextlib
    import io

    from fretwear.cli import main as cli

    buf = io.StringIO()
    with Clock() as c, contextlib.redirect_stdout(buf):
        status = cli(["run", path, "-o", out, "--no-progress"])
    return {"status": status, "cpu": c.cpu, "wall": c.wall, "peak_gib": peak_gib(),
            "summary": [x for x in buf.getvalue().splitlines()
                        if x.startswith(("periodic at", "interface", "condensation"))]}


def _limit_memory():
    """The address-space limit of a size's process (``ulimit -v``; a lower limit of the
    caller's shell is kept)."""
    cap = int(LIMIT_GIB * 2**30)
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--load", choices=sorted(LOADS), default="slip",
                    help="slip: partial slip (default); stuck: the earlier, 99.5 %% stuck load")
    ap.add_argument("--ratio", type=float, help="tangential traction / (mu P) (default: the "
                    "load's, 0.95 for slip)")
    ap.add_argument("--damped", action="store_true",
                    help="Rayleigh stiffness damping, 2 %% at 100 kHz (complex Z_r blocks)")
    ap.add_argument("--sizes", default="8,16,32,64", help="nodes per side of the contact face")
    ap.add_argument("--strategy", default="",
                    help="attempts of the periodic solve, comma-separated (default: "
                         "solve_periodic's; e.g. 'start' for the first Powell run alone)")
    ap.add_argument("--dense-lu", action="store_true",
                    help="time one dense LU of the Jacobian's size where it fits in 4 GiB")
    ap.add_argument("--sweep", type=int, default=0, help="points of the sweep (0: none)")
    ap.add_argument("--wear", type=int, default=0, help="slow steps of the wear run (0: none)")
    ap.add_argument("--extras-size", type=int, default=32, help="size of the sweep/wear run")
    ap.add_argument("--alternate", type=int, default=0,
                    help="also time the 256- and 1024-node solves alternately in one process, "
                         "this many times each, and print the growth of their medians")
    ap.add_argument("--case-file", type=int, default=0, metavar="N",
                    help="also run the load from a generated case file (`fretwear run`, every "
                         "other key at its default) with N x N contact nodes (0: not)")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--extras", default="{}", help=argparse.SUPPRESS)
    ap.add_argument("--case", help=argparse.SUPPRESS)
    ap.add_argument("--alternate-in", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--run-case", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.run_case:
        print("RESULT " + json.dumps(run_case(*args.run_case)))
        return
    if args.case:  # a child process: the load case as the parent built it
        load = Load(**json.loads(args.case))
        if args.one:
            print("RESULT " + json.dumps(one(args.one, json.loads(args.extras), load),
                                         default=float))
        elif args.alternate_in:
            print("RESULT " + json.dumps(alternate((16, 32), args.alternate_in, load)))
        return
    load = LOADS[args.load]
    if args.ratio is not None:
        load = Load(**{**asdict(load), "ratio": args.ratio})
    if args.damped:
        load = Load(**{**asdict(load), "damped": True})
    if args.strategy:
        load = Load(**{**asdict(load), "strategy": args.strategy})
    case = json.dumps(asdict(load))
    print(f"load: {os.getloadavg()}; OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    print(f"load case {load.name}: P = {load.pressure / 1e6:g} MPa, mu = {load.mu:g}, traction "
          f"{load.ratio:g} mu P at {load.angle_deg:g} degrees to x, {load.freq:g} Hz, modal "
          f"condensation with {'its default' if load.modes is None else load.modes} modes"
          + (", Rayleigh damping" if load.damped else ", undamped")
          + (f", attempts {load.strategy}" if load.strategy else ""))
    rows = {}
    for n in (int(s) for s in args.sizes.split(",")):
        est = estimate_gib(n, load.damped)
        if est["total"] > LIMIT_GIB:
            print(f"\n{n * n} contact nodes, H = {H}: {3 * n * n * (2 * H + 1)} unknowns: not "
                  f"run: estimated peak memory {est['total']:.1f} GiB > {LIMIT_GIB:g} GiB ("
                  + ", ".join(f"{k} {v:.1f}" for k, v in est.items() if k != "total")
                  + " GiB)")
            continue
        extras = {"dense_lu": args.dense_lu,
                  **({"sweep": args.sweep, "wear": args.wear} if n == args.extras_size else {})}
        proc = subprocess.run([sys.executable, __file__, "--one", str(n), "--extras",
                               json.dumps(extras), "--case", case], capture_output=True,
                              text=True, preexec_fn=_limit_memory)
        line = [x for x in proc.stdout.splitlines() if x.startswith("RESULT ")]
        if proc.returncode or not line:
            print(f"n = {n}: failed\n{proc.stderr[-2000:]}")
            continue
        r = rows[n] = json.loads(line[0][7:])
        print(f"\n{r['nodes']} contact nodes ({r['ndof']} DOFs), H = {H}: "
              f"{r['unknowns']} unknowns (model built in {r['build_cpu']:.1f} s CPU)")
        print(f"  condensation (modal, {r['modes']} modes + loads, checked error "
              f"{r['modal_error']:.2g}): {r['condense_cpu']:.1f} s CPU, "
              f"{r['condense_wall']:.1f} s wall")
        if "exact_cpu" in r:
            print(f"  exact condensation: {r['exact_cpu']:.1f} s CPU, {r['exact_wall']:.1f} s "
                  f"wall; modal vs exact max rel. difference {r['modal_vs_exact']:.2g}")
        print(f"  (untimed warm-up: a 16-node solve and Jacobian loading the compiled "
              f"kernels, {r['warmup_cpu']:.1f} s CPU)")
        g = r["gmres"]
        print(f"  periodic solve: {r['solve_cpu']:.2f} s CPU, {r['solve_wall']:.1f} s wall "
              f"(load average {r['load_before']:.1f} before, {r['load_after']:.1f} after), "
              f"success {r['success']}, {r['iterations']} Powell iterations of the last "
              f"attempt, {r['newton_steps']} Newton steps in all (static, one-harmonic start "
              f"where used, full), GMRES iterations per step "
              + (f"{min(g)}-{max(g)} (median {int(np.median(g))}, {sum(g)} in all)" if g
                 else "none (dense steps)")
              + f", residual {r['residual']:.2g}, eps {r['eps']:.3g} N/m (default rule)")
        print(f"  attempts: {'; '.join(r['attempts'])}")
        print(f"  interface: area x period separated/stuck/slipping {r['sep']:.3f}/"
              f"{r['stick']:.3f}/{r['slip']:.3f} (per node {r['slip_nodes']:.3f} slipping); "
              f"{r['slipping_nodes']} nodes slip, {r['slip_both_nodes']} along both tangents; "
              f"slip path along T1/T2 {r['slip_share_t1']:.2f}/{r['slip_share_t2']:.2f}; "
              f"{r['active_nodes']} nodes slip or separate at some instant")
        if "dense_lu_cpu" in r:
            print(f"  one dense LU of {r['unknowns']}: {r['dense_lu_cpu']:.1f} s CPU, "
                  f"{r['dense_lu_wall']:.1f} s wall")
        elif args.dense_lu:
            print(f"  dense LU of {r['unknowns']}: does not fit in 4 GiB "
                  f"({8 * r['unknowns'] ** 2 / 2**30:.0f} GiB)")
        if "sweep_cpu" in r:
            print(f"  sweep of {r['sweep_points']} points: {r['sweep_cpu']:.1f} s CPU, "
                  f"{r['sweep_wall']:.1f} s wall, {r['sweep_converged']} converged, "
                  f"peak {r['peak_sweep_gib']:.2f} GiB, sweep-checkpoint.npz "
                  f"{r['sweep_ckpt_mib']:.1f} MiB")
        if "wear_cpu" in r:
            print(f"  wear run ({r['wear_steps']} slow steps, explicit): {r['wear_cpu']:.1f} s "
                  f"CPU, {r['wear_wall']:.1f} s wall, success {r['wear_success']} "
                  f"({r['wear_message']}), peak {r['peak_wear_gib']:.2f} GiB, "
                  f"wear-checkpoint.npz {r['wear_ckpt_mib']:.1f} MiB")
        print(f"  peak memory {r['peak_gib']:.2f} GiB (condensation + solve), "
              f"{r['peak_extras_gib']:.2f} GiB with the sweep and wear run; estimated "
              f"{est['total']:.2f} GiB")
    for a, b in ((16, 24), (16, 32)):
        if a in rows and b in rows:
            g = np.log(rows[b]["solve_cpu"] / rows[a]["solve_cpu"]) / np.log(
                rows[b]["unknowns"] / rows[a]["unknowns"])
            print(f"\nsolve time ~ unknowns^{g:.2f} from {a * a} to {b * b} nodes")
    if args.alternate:
        proc = subprocess.run([sys.executable, __file__, "--alternate-in",
                               str(args.alternate), "--case", case], capture_output=True,
                              text=True, preexec_fn=_limit_memory)
        line = [x for x in proc.stdout.splitlines() if x.startswith("RESULT ")]
        if proc.returncode or not line:
            print(f"alternating solves: failed\n{proc.stderr[-2000:]}")
        else:
            t = json.loads(line[0][7:])["times"]
            a, b = np.asarray(t["16"]), np.asarray(t["32"])
            g = np.log(b / a) / np.log(4.0)  # unknowns grow 4 times
            print(f"\nalternating in one process ({args.alternate} times each): solve "
                  f"256 nodes {' '.join(f'{x:.2f}' for x in a)} s, 1024 nodes "
                  f"{' '.join(f'{x:.2f}' for x in b)} s; medians {np.median(a):.3f} s and "
                  f"{np.median(b):.3f} s: unknowns^"
                  f"{np.log(np.median(b) / np.median(a)) / np.log(4.0):.2f} (single pairs "
                  f"^{g.min():.2f} to ^{g.max():.2f})")
    if args.case_file:
        n = args.case_file
        tmp = tempfile.mkdtemp(prefix="scale3d-case-")
        path = os.path.join(tmp, f"pad-{n * n}.toml")
        with open(path, "w") as fh:
            fh.write(case_file(n, load))
        before = os.getloadavg()[0]
        proc = subprocess.run([sys.executable, __file__, "--run-case", path,
                               os.path.join(tmp, "out")], capture_output=True, text=True,
                              preexec_fn=_limit_memory)
        line = [x for x in proc.stdout.splitlines() if x.startswith("RESULT ")]
        if proc.returncode or not line:
            print(f"\ncase file, {n * n} nodes: failed\n{proc.stderr[-2000:]}")
        else:
            r = json.loads(line[0][7:])
            print(f"\ncase file ({n * n} contact nodes, `fretwear run` with every other key "
                  f"at its default): exit status {r['status']}, {r['cpu']:.1f} s CPU, "
                  f"{r['wall']:.1f} s wall (load average {before:.1f} before, "
                  f"{os.getloadavg()[0]:.1f} after), peak memory {r['peak_gib']:.2f} GiB")
            for x in r["summary"]:
                print(f"  {x}")
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"load: {os.getloadavg()}")
    r = rows.get(32, {})
    key = "solve_1024_slip_s" if load.name == "slip" else "solve_1024_s"
    print(f"{key}={r.get('solve_cpu', float('nan')):.1f}")
    print(f"condense_1024_s={r.get('condense_cpu', float('nan')):.1f}")
    print(f"peak_rss_1024_gib={r.get('peak_gib', float('nan')):.2f}")


if __name__ == "__main__":
    main()
