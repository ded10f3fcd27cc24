"""Cost of the DLFT harmonic balance on the paper's section 4.2 beam.

Prints, on this machine and in this run:
- the JIT warm-up time of the numba kernels (first call, with and without the on-disk cache);
- the time of one Newton iteration at 79 kHz (31 contact nodes x 2 DOF x 15 coefficients = 930
  unknowns, 128 samples): residual + analytic Jacobian + LU solve, as a ratio to one dense LU
  factorisation of a 930 x 930 matrix timed in the same run (target: at most 2);
- the wall time of the periodic solve at 79 kHz from the default start, Powell and Newton;
- the wall time of a 200-point FRF sweep from 1 Hz to 100 kHz and how many grid points
  converged (``sweep_converged=<k>/<n>``), with the flagged points and their reasons (where a
  point fails, a time integration says what the structure does there).
The last line reads ``newton_over_lu=<ratio>``.

Run: ``python benchmarks/newton_vs_lu.py [--points 200] [--quick]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.linalg as sla

from fretwear.examples.builders import paper_beam
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions, SweepOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.hb.sweep import sweep
from fretwear.timedomain.fallback import FALLBACK


def _best(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times), float(np.median(times))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=200, help="points of the FRF sweep")
    ap.add_argument("--quick", action="store_true", help="skip the full sweep")
    args = ap.parse_args()

    t0 = time.perf_counter()
    model = paper_beam()
    basis = FourierBasis.up_to(7, 128)
    orders = np.array([0, *basis.harmonics])
    t_build = time.perf_counter() - t0

    # JIT warm-up: first call of the kernels on a tiny problem
    t0 = time.perf_counter()
    from fretwear.hb import contact as law

    lu = np.random.default_rng(0).normal(size=(2, 2, 8))
    lx, st, _ = law.dlft_time(lu, np.full(2, 0.3), np.zeros((2, 1)), 1e-12, 10)
    fb = FourierBasis.up_to(2, 8)
    law.dlft_jacobian(lu, lx, st, np.full(2, 0.3), fb.forward_matrix(), fb.inverse_matrix())
    t_jit = time.perf_counter() - t0
    print(f"model_build_s={t_build:.3f}")
    print(f"jit_warmup_s={t_jit:.3f}  (first call in this process; numba cache on disk)")

    # reference: one dense LU of the same size
    f = 79e3  # [Hz]
    red = condense(model, f, orders)
    prob = DLFTProblem(red, model.contact, basis)
    n = prob.m * prob.H
    A = np.random.default_rng(1).normal(size=(n, n)) + n * np.eye(n)
    t_lu, t_lu_med = _best(lambda: sla.lu_factor(A, check_finite=False), 15)
    print(f"unknowns={n}")
    print(f"dense_lu_s={t_lu:.5f} (best of 15; median {t_lu_med:.5f})")

    # the periodic solve at 79 kHz from the default start (paper's eps: spectral radius of Z_r)
    sol = None
    for solver in ("powell", "newton"):
        s_ = solve_periodic(model, basis, frequency=f, reduced=red,
                            options=SolveOptions(solver=solver, max_iter=400))
        st = s_.stats
        print(f"periodic_79khz_{solver}_s={st.wall_time:.3f} iterations={st.iterations} "
              f"converged={st.success} residual={st.residual:.2e}")
        sol = sol or (s_ if s_.success else None)
    if sol is not None:
        prob = DLFTProblem(red, model.contact, basis, anchor=sol.anchor)
        U = sol.U.reshape(prob.m, prob.H)
        print(f"stops_per_period_Pe_x_79khz={sol.stops_per_period('Pe', 0)}")
    else:
        U = prob.initial_guess()

    def one_iteration():
        f, J = prob.residual(U)
        lu_ = sla.lu_factor(J, check_finite=False)
        sla.lu_solve(lu_, f, check_finite=False)

    t_it, t_it_med = _best(one_iteration, 15)
    t_res, _ = _best(lambda: prob.residual(U, False), 15)
    print(f"residual_only_s={t_res:.5f}")
    print(f"newton_iteration_s={t_it:.5f} (best of 15; median {t_it_med:.5f})")

    if not args.quick:
        t0 = time.perf_counter()
        res = sweep(model, basis, 1.0, 1e5, args.points, options=SweepOptions(time_domain=FALLBACK))
        t_sweep = time.perf_counter() - t0
        print(f"sweep_{args.points}pts_s={t_sweep:.1f} (computed points incl. substeps: "
              f"{len(res.points)})")
        print(res.summary())  # first line: sweep_converged=<k>/<n> over the grid
    print(f"newton_over_lu={t_it / t_lu:.3f}")


if __name__ == "__main__":
    main()
