"""Sensitivity of a periodic solution to the stick-anchor rule (docs/theory.md, "Full stick").

Solves the paper's section 4.2 beam at a few frequencies with the documented rule (anchors
from the static preload) and with the alternatives: the usual DLFT convention (anchors at the
undeformed position, 0) and the preload anchors shifted by +-1 um and +-5 um. Prints, for
each, whether the solve converged, the harmonic-1 amplitude of u_x at P_e, the friction energy
per cycle, the mean x position of P_e and the fraction of nodes stuck all period, and the
relative change against the documented rule.

Run: ``python studies/anchor_sensitivity.py [freq_hz ...]`` (default 10e3 70e3 79e3).
"""

from __future__ import annotations

import sys

import numpy as np

from fretwear.examples.builders import paper_beam
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.preload import static_anchor
from fretwear.hb.reduce import condense, exact_condenser


def describe(sol):
    c = sol.observed["Pe"][0]
    amp = float(np.hypot(c[1], c[1 + sol.basis.k]))
    stuck = float(np.mean((sol.state == 1).all(axis=1)))
    return amp, float(sol.friction_energy().sum()), float(c[0]), stuck


def main():
    freqs = [float(f) for f in sys.argv[1:]] or [10e3, 70e3, 79e3]
    model = paper_beam()
    basis = FourierBasis.up_to(7, 128)
    cond = exact_condenser(model)  # one condensation of the beam for every frequency
    a0 = static_anchor(model, condenser=cond)
    rules = {"preload (default)": a0, "zero (usual DLFT)": np.zeros_like(a0),
             "preload + 1 um": a0 + 1e-6, "preload - 1 um": a0 - 1e-6,
             "preload + 5 um": a0 + 5e-6, "preload - 5 um": a0 - 5e-6}
    for f in freqs:
        red = condense(model, f, [0, *basis.harmonics], condenser=cond)
        ref = None
        print(f"\nf = {f:g} Hz")
        print(f"{'anchors':20s} {'conv':>5s} {'|u_x1(Pe)| [m]':>15s} {'E_fric [J]':>11s} "
              f"{'mean x(Pe) [m]':>15s} {'stuck':>6s} {'d_amp':>8s} {'d_E':>8s}")
        for name, anc in rules.items():
            sol = solve_periodic(model, basis, frequency=f, reduced=red,
                                 anchor=anc, options=SolveOptions(solver="newton", max_iter=300))
            st = sol.stats
            if not sol.success:
                print(f"{name:20s} {'no':>5s}   ({st.message}, residual {st.residual:.1e})")
                continue
            amp, e, mean, stuck = describe(sol)
            if ref is None:
                ref = (amp, e)
            print(f"{name:20s} {'yes':>5s} {amp:15.4e} {e:11.4e} {mean:15.4e} {stuck:6.2f} "
                  f"{(amp - ref[0]) / ref[0]:8.1e} {(e - ref[1]) / ref[1]:8.1e}")


if __name__ == "__main__":
    main()
