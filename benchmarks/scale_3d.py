"""Cost of the periodic solve, the condensation, sweeps and wear runs on large 3D interfaces.

The model: a steel pad 10 x 10 x 1.25 mm (hexahedra of about 0.3 mm) pressed by 1 MPa on a
rigid flat (mu = 0.5) with springs on its top face, under a harmonic tangential traction of
0.8 mu P at 5 kHz; the contact face has n x n nodes (3 DOFs each), 7 harmonics, 128 samples
per period. For each size, in a fresh process (so that the peak memory is that size's), it
prints: unknowns ``3 n^2 (2 H + 1)``, the condensation (the modal representation of
fretwear.hb.modal with its error check against the exact condensation, and the exact
condensation itself where it runs in minutes), the periodic solve (fretwear's
solve_periodic: static preload, harmonic continuation start, Powell with the Newton step of
fretwear.hb.krylov), its iterations and contact states, the peak resident memory, and, where
a dense matrix of the Jacobian's size fits in 4 GiB, one dense LU of that size timed in the
same process (what the dense path pays per iteration). CPU seconds of the process are
printed beside wall seconds: the machine is shared.

eps: the default rule of each driver (``"auto"`` for the periodic solve and the wear run,
``"top"`` for the sweep; fretwear.hb.penalty: a power-iteration estimate of the spectral radius
above 256 rows), its cost included in the times.

Optionally (``--sweep N`` / ``--wear N``) it times a sweep of N points from 4 to 6 kHz (default
options) and a wear run of N slow steps (explicit Euler with the adaptive jump: the
linearly implicit default needs one solve per contact node for its slow Jacobian, see
docs/theory.md "Large interfaces") at the size given to ``--extras-size``, each writing its
checkpoint (sweep-checkpoint.npz, wear-checkpoint.npz, sizes printed) into a temporary folder.

Sizes: 8, 16, 32 and 64 nodes a side (64 to 4096 contact nodes). A size whose estimated peak
memory (:func:`estimate_gib`, checked against the measured peak of the sizes that run) is
above ``LIMIT_GIB`` = 12 GiB is not run: the estimate and its parts are printed instead
(4096 nodes: about 39 GiB). Every size runs under that address-space limit.

The last lines read ``solve_1024_s=``, ``condense_1024_s=`` and ``peak_rss_1024_gib=`` (CPU
seconds and GiB of the 32 x 32 size, when it was run).

With ``--alternate N`` it also times the 256- and 1024-node solves alternately in one
process, N times each, and prints the growth of their medians: the machine's speed drifts
(30 % within an hour was measured), and two sizes run minutes apart carry that drift into
their ratio.

Run: ``python benchmarks/scale_3d.py [--sizes 8,16,32,64] [--sweep 50 --wear 20
--extras-size 32] [--alternate 4]``.
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

import numpy as np

A, P0, MU, FREQ, H = 0.01, 1e6, 0.5, 5000.0, 7
#: no size is run whose estimated peak memory (:func:`estimate_gib`) is above this, and
#: every size runs under this address-space limit (the machine is shared)
LIMIT_GIB = 12.0


def layers(n: int) -> int:
    """Element layers through the thickness of the pad with n x n contact nodes."""
    return max(1, round((n - 1) / 8))


def estimate_gib(n: int) -> dict:
    """Peak memory [GiB] of one size, estimated from the arrays that grow with it (the sizes
    measured at 32 x 32 check it, docs/theory.md).

    Where fretwear.hb.modal.modal_condenser builds the dense condenser (up to 1024 nodes):
    the reduced model ``Z_r`` (H + 1 real m x m blocks: the pad is undamped, and
    fretwear.hb.modal stores such blocks real), the static constraint modes ``Psi`` (n_i x m
    reals) with one product of their size while they are projected, and work arrays: ten
    real m x m (the projected stiffness and mass in both frames, a harmonic's condensation,
    the kept harmonic 0, the active sub-blocks and the preconditioner's factors; calibrated
    on the 2.2 GiB measured at 1024 nodes) and 0.4 GiB of Python, NumPy, SciPy and numba.

    Where it builds the blocked one (fretwear.hb.modal, 4096 nodes; not yet
    measured at that size): the shared ``K^cc, M^cc`` (two real m x m), the sparse LU of
    ``K_ii`` (8.9e6 non-zeros measured at 1024 nodes, 12 bytes each, grown as n_i^(4/3)),
    work arrays: the active sub-blocks (two m x m at most), one formed block and the
    preconditioner's factors (at most 2 GiB), and the same base."""
    m = 3 * n * n
    ni = 3 * n * n * (layers(n) + 1) - m
    if 8.0 * (ni * m + (H + 5) * m * m) / 2**30 <= 6.0:  # modal.DENSE_STORAGE_GIB
        parts = {"Z_r": (H + 1) * m * m * 8, "Psi": 2 * ni * m * 8, "work": 10 * m * m * 8,
                 "base": 0.4 * 2**30}
    else:
        parts = {"K^cc, M^cc": 2 * m * m * 8, "LU K_ii": 12 * 8.9e6 * (ni / 12288) ** (4 / 3),
                 "work": 3 * m * m * 8 + 2 * 2**30, "base": 0.4 * 2**30}
    parts = {k: v / 2**30 for k, v in parts.items()}
    parts["total"] = sum(parts.values())
    return parts


def pad(n: int):
    """The pad with n x n contact nodes."""
    from fretwear.model import ContactSpec, Material, Spring, Traction, box, from_mesh

    ne = n - 1
    return from_mesh(box(A, A, A / 8, ne, ne, layers(n)), Material(210e9, 0.3, 7800.0),
                     supports=[Spring("zmax", "x", 1e7), Spring("zmax", "y", 1e7)],
                     loads=[Traction("zmax", pressure=P0),
                            Traction("zmax", traction=(0.8 * MU * P0, 0.0, 0.0),
                                     waveform="cos")],
                     contact=ContactSpec("zmin", mu=MU, wear_coefficient=1e-15))


class Clock:
    def __enter__(self):
        self.c, self.w = time.process_time(), time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.cpu, self.wall = time.process_time() - self.c, time.perf_counter() - self.w


def peak_gib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20


def warm_up():
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

    small, basis = pad(4), FourierBasis.up_to(H, 128)
    anchor = static_anchor(small)
    sol = solve_periodic(small, basis, frequency=FREQ, anchor=anchor)
    prob = DLFTProblem(condense(small, FREQ, basis.orders), small.contact, basis, eps=sol.eps,
                       anchor=anchor, jacobian="krylov")
    _, J = prob.residual(sol.U.reshape(prob.m, prob.H), True)
    J.column_norms()


def one(n: int, extras: dict) -> dict:
    """Everything for one size (run in its own process)."""
    import scipy.linalg as sla

    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.modal import modal_condenser
    from fretwear.hb.periodic import solve_periodic
    from fretwear.hb.preload import static_anchor
    from fretwear.hb.reduce import exact_condenser

    out = {"n": n, "nodes": n * n}
    with Clock() as c:
        warm_up()
    out["warmup_cpu"] = c.cpu
    with Clock() as c:
        model = pad(n)
    out.update(ndof=model.ndof, build_cpu=c.cpu, build_wall=c.wall)
    basis = FourierBasis.up_to(H, 128)
    out["unknowns"] = 3 * n * n * basis.size
    with Clock() as c:
        mc = modal_condenser(model, FREQ * 1.2, H)  # passed to every call below
        red = mc.reduced(2 * np.pi * FREQ, basis.orders, frequency=FREQ)
    out.update(condense_cpu=c.cpu, condense_wall=c.wall, modes=mc.n_modes, q=mc.q,
               modal_error=mc.error)
    if n * n <= 256:  # the exact condensation, for comparison
        with Clock() as c:
            ex = exact_condenser(model).reduced(2 * np.pi * FREQ, basis.orders)
        out.update(exact_cpu=c.cpu, exact_wall=c.wall,
                   modal_vs_exact=float(max(np.abs(red.Z[b] - ex.Z[b]).max()
                                            / np.abs(ex.Z[b]).max() for b in range(H + 1))))
        del ex
    with Clock() as c:
        anchor = static_anchor(model, condenser=mc)  # the static preload state (default eps)
        sol = solve_periodic(model, basis, frequency=FREQ, reduced=red, anchor=anchor,
                             condenser=mc)
    out["eps"] = sol.eps
    st = sol.stats
    frac = sol.state_fractions().mean(axis=0)
    out.update(solve_cpu=c.cpu, solve_wall=c.wall, success=sol.success, iterations=st.iterations,
               residual=st.residual, sep=frac[0], stick=frac[1], slip=frac[2],
               active_nodes=int(np.sum(np.any(sol.state != 1, axis=1))))
    out["peak_gib"] = peak_gib()  # condensation + solve
    print("PARTIAL " + json.dumps(out, default=float), flush=True)
    tmp = tempfile.mkdtemp(prefix="scale3d-")
    if extras.get("wear"):
        from fretwear.wear.options import WearOptions
        from fretwear.wear.simulate import BalanceSetup, RunControl, simulate_wear

        ck = os.path.join(tmp, "wear-checkpoint.npz")
        with Clock() as c:
            wr = simulate_wear(model, basis, frequency=FREQ,
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
            res = sweep(model, basis, 4000.0, 6000.0, extras["sweep"],
                        options=SweepOptions(spacing="linear", checkpoint=ck), anchor=anchor,
                        condenser=mc)
        out.update(sweep_points=extras["sweep"], sweep_cpu=c.cpu, sweep_wall=c.wall,
                   sweep_converged=int(sum(p.success for p in res.points)),
                   sweep_ckpt_mib=os.path.getsize(ck) / 2**20,
                   peak_sweep_gib=peak_gib())
    out["peak_extras_gib"] = peak_gib()
    shutil.rmtree(tmp, ignore_errors=True)
    nu = out["unknowns"]
    if 8.0 * nu * nu <= 4 * 2**30:  # last: its memory is not the solve's
        M = np.random.default_rng(0).standard_normal((nu, nu)) + nu * np.eye(nu)
        with Clock() as c:
            sla.lu_factor(M, overwrite_a=True, check_finite=False)
        out.update(dense_lu_cpu=c.cpu, dense_lu_wall=c.wall)
    return out


def alternate(sizes: tuple[int, int], reps: int) -> dict:
    """The solves of two sizes timed alternately in one process, ``reps`` times each (the
    machine's speed drifts between separate runs; alternating exposes both sizes to the
    same drift). Each timing is what ``one`` times: the static preload solve and the
    periodic solve on the condensation of the frequency (condensed once per size)."""
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.modal import modal_condenser
    from fretwear.hb.periodic import solve_periodic
    from fretwear.hb.preload import static_anchor

    basis = FourierBasis.up_to(H, 128)
    warm_up()  # untimed, as in one()
    cases = {}
    for n in sizes:
        model = pad(n)
        mc = modal_condenser(model, FREQ * 1.2, H)
        cases[n] = model, mc, mc.reduced(2 * np.pi * FREQ, basis.orders, frequency=FREQ)
    times = {n: [] for n in sizes}
    for _ in range(reps):
        for n in sizes:
            model, mc, red = cases[n]
            with Clock() as c:
                sol = solve_periodic(model, basis, frequency=FREQ, reduced=red,
                                     anchor=static_anchor(model, condenser=mc), condenser=mc)
            if not sol.success:
                raise RuntimeError(f"{n * n} nodes: the periodic solve did not converge")
            times[n].append(c.cpu)
    return {"sizes": list(sizes), "times": {str(n): t for n, t in times.items()}}


def _limit_memory():
    """The address-space limit of a size's process (``ulimit -v``)."""
    cap = int(LIMIT_GIB * 2**30)
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="8,16,32,64", help="nodes per side of the contact face")
    ap.add_argument("--sweep", type=int, default=0, help="points of the sweep (0: none)")
    ap.add_argument("--wear", type=int, default=0, help="slow steps of the wear run (0: none)")
    ap.add_argument("--extras-size", type=int, default=32, help="size of the sweep/wear run")
    ap.add_argument("--alternate", type=int, default=0,
                    help="also time the 256- and 1024-node solves alternately in one process, "
                         "this many times each, and print the growth of their medians")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--extras", default="{}", help=argparse.SUPPRESS)
    ap.add_argument("--alternate-in", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        print("RESULT " + json.dumps(one(args.one, json.loads(args.extras)), default=float))
        return
    if args.alternate_in:
        print("RESULT " + json.dumps(alternate((16, 32), args.alternate_in)))
        return
    print(f"load: {os.getloadavg()}; OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    rows = {}
    for n in (int(s) for s in args.sizes.split(",")):
        est = estimate_gib(n)
        if est["total"] > LIMIT_GIB:
            print(f"\n{n * n} contact nodes, H = {H}: {3 * n * n * (2 * H + 1)} unknowns: not "
                  f"run: estimated peak memory {est['total']:.1f} GiB > {LIMIT_GIB:g} GiB ("
                  + ", ".join(f"{k} {v:.1f}" for k, v in est.items() if k != "total")
                  + " GiB)")
            continue
        extras = ({"sweep": args.sweep, "wear": args.wear} if n == args.extras_size else {})
        proc = subprocess.run([sys.executable, __file__, "--one", str(n), "--extras",
                               json.dumps(extras)], capture_output=True, text=True,
                              preexec_fn=_limit_memory)
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
        print(f"  periodic solve: {r['solve_cpu']:.2f} s CPU, {r['solve_wall']:.1f} s wall, "
              f"success {r['success']}, {r['iterations']} iterations (after the 1-harmonic "
              f"start), residual {r['residual']:.2g}, eps {r['eps']:.3g} N/m (default rule); "
              "states sep/stick/slip "
              f"{r['sep']:.3f}/{r['stick']:.3f}/{r['slip']:.3f}, {r['active_nodes']} nodes "
              "slip or separate")
        if "dense_lu_cpu" in r:
            print(f"  one dense LU of {r['unknowns']}: {r['dense_lu_cpu']:.1f} s CPU, "
                  f"{r['dense_lu_wall']:.1f} s wall")
        else:
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
    if 16 in rows and 32 in rows:
        g = np.log(rows[32]["solve_cpu"] / rows[16]["solve_cpu"]) / np.log(
            rows[32]["unknowns"] / rows[16]["unknowns"])
        print(f"\nsolve time ~ unknowns^{g:.2f} from 256 to 1024 nodes")
    if args.alternate:
        proc = subprocess.run([sys.executable, __file__, "--alternate-in",
                               str(args.alternate)], capture_output=True, text=True,
                              preexec_fn=_limit_memory)
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
    print(f"load: {os.getloadavg()}")
    r = rows.get(32, {})
    print(f"solve_1024_s={r.get('solve_cpu', float('nan')):.1f}")
    print(f"condense_1024_s={r.get('condense_cpu', float('nan')):.1f}")
    print(f"peak_rss_1024_gib={r.get('peak_gib', float('nan')):.2f}")


if __name__ == "__main__":
    main()
