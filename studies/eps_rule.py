"""How the DLFT answer moves with the penalty eps at finite H, and which rule to use.

Written up in docs/studies/eps-rule.md. Run from the repository root:

    PYTHONPATH=src python studies/eps_rule.py [--quick]

Part 1, the issue's two oscillators (benchmarks/reference_oscillators.py: event-driven
integration with exact stick/slip switching plus Newton shooting, independent of fretwear):
for H = 7 and 15 and eps over five decades plus the rules "stiff" (the sweeps' default),
"top", "static", "auto", a sweep of
121 (a) / 137 (b) frequencies over w = 0.7-1.3 (a) / 1.0-1.8 (b) rad/s at that eps, and the
peak of the first harmonic amplitude of mass 1 (largest point refined by a parabola) against
the reference. Prints converged points and peak amplitude / frequency errors.

Part 2, the paper's beam (default model, 7 harmonics, 128 samples): at 10, 30, 70 and 79 kHz,
a solve from the contact-closed start with the solver alone (``strategy=("start",)``) at each
eps: converged or not and A1 of P_e, to see both the accuracy trend and the convergence.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import reference_oscillators as ref  # noqa: E402
from peers import curve_peak  # noqa: E402

import fretwear  # noqa: E402
from fretwear.examples.builders import paper_beam  # noqa: E402
from fretwear.hb.fourier import FourierBasis  # noqa: E402
from fretwear.hb.options import SolveOptions, SweepOptions  # noqa: E402
from fretwear.hb.periodic import solve_periodic  # noqa: E402
from fretwear.model.build import Damping  # noqa: E402
from fretwear.model.core import Load  # noqa: E402
from fretwear.model.matrices import ContactDofs, from_matrices  # noqa: E402


def oscillator(prob: str):
    if prob == "a":
        return from_matrices([[1.0]], [[1.0]],
                             contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=0.5,
                                                 normal_load=1.0, kt=0.5),
                             damping=Damping(C=[[0.02]]), loads=[Load(np.array([0.2]), "cos")],
                             observed={"x": 0})
    return from_matrices(np.array([[2.0, -1.0], [-1.0, 1.0]]), np.eye(2),
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[1], mu=0.5,
                                             normal_load=1.0),
                         damping=Damping(C=0.02 * np.eye(2)),
                         loads=[Load(np.array([0.2, 0.0]), "cos")], observed={"x": 0})


def part1(harmonics, eps_list):
    refs = {"a": ref.peak(ref.Jenkins(), 1.1, 1.3), "b": ref.peak(ref.Chain(), 1.4, 1.6)}
    print("# part 1: peak of A1 (mass 1) vs the event-driven reference")
    print(f"{'prob':4s} {'H':>3s} {'eps':>10s} {'eps_N/m':>10s} {'conv':>8s} {'peak_err':>10s} "
          f"{'freq_err':>10s} {'time_s':>7s}")
    for prob, n, band in (("a", 121, (0.7, 1.3)), ("b", 137, (1.0, 1.8))):
        model = oscillator(prob)
        w_ref, a_ref = refs[prob]
        for H in harmonics:
            basis = FourierBasis.up_to(H, 128)
            for eps in eps_list:
                t0 = time.perf_counter()
                res = fretwear.sweep(model, basis, band[0] / (2 * np.pi),
                                     band[1] / (2 * np.pi), n,
                                     options=SweepOptions(spacing="linear", eps=eps),
                                     time_domain=False)
                grid = [p for p in res.points if p.on_grid]
                ok = [p for p in grid if p.success]
                w = [2 * np.pi * p.frequency_hz for p in ok]
                a = [p.solution.observed_amplitude("x")[0][0] for p in ok]
                wp, ap = curve_peak(w, a)
                e = ok[0].solution.eps if ok else float("nan")
                print(f"{prob:4s} {H:3d} {str(eps):>10s} {e:10.3g} {len(ok):4d}/{len(grid):3d} "
                      f"{ap / a_ref - 1:+10.2e} {wp / w_ref - 1:+10.2e} "
                      f"{time.perf_counter() - t0:7.1f}", flush=True)


def part2(eps_list, freqs):
    model = paper_beam()
    basis = FourierBasis.up_to(7, 128)
    print("# part 2: the paper's beam, solver alone from the contact-closed start")
    print(f"{'f_kHz':>6s} {'eps':>10s} {'eps_N/m':>10s} {'conv':>5s} {'residual':>9s} "
          f"{'A1_Pe_m':>11s} {'time_s':>7s}")
    for f in freqs:
        for eps in eps_list:
            t0 = time.perf_counter()
            s = solve_periodic(model, basis, frequency=f, eps=eps,
                               options=SolveOptions(strategy=("start",)))
            print(f"{f / 1e3:6.0f} {str(eps):>10s} {s.eps:10.3g} {str(s.success):>5s} "
                  f"{s.stats.residual:9.1e} {s.observed_amplitude('Pe')[0][0]:11.4e} "
                  f"{time.perf_counter() - t0:7.1f}", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="H = 7 only, fewer eps")
    args = ap.parse_args(argv)
    eps1 = ["stiff", "top", "static", "auto", 0.1, 0.3, 1.0, 3.0, 10.0, 100.0, 1000.0, 3000.0,
            1e4]
    eps2 = ["stiff", "top", "static", "auto", 1e9, 1e10, 1e11]
    if args.quick:
        eps1 = ["stiff", "top", "static", 1.0, 100.0, 1000.0]
        eps2 = ["stiff", "top", 1e10]
    part1([7] if args.quick else [7, 15], eps1)
    part2(eps2, [1e4, 3e4, 7e4, 7.9e4])


if __name__ == "__main__":
    main()
