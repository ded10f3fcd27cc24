"""A folded frictional FRF: the stable upper branch and the unstable middle branch classified
the same way by Hill's method (:mod:`fretwear.hb.stability`) and by the exact time integration
(:mod:`fretwear.timedomain.monodromy`, :func:`fretwear.timedomain.stability.check_periodic`).

The model (:func:`helpers.folded.inclined`): two masses (springs 1, 1 N/m from the wall to the
second mass, 0.1 N forcing on it) and the first mass striking a rigid wall inclined at 30
degrees, with friction ``mu = 0.3``, through a light contact node (1 g) held by a normal spring
``kn`` and a tangential spring ``kt`` (10 N/m each) along the wall. When the first mass moves
more than ``gap / cos 30`` towards the wall the node touches it: its normal load grows with the
motion (``kn (x1 cos 30 - gap)``) and, since ``mu < tan 30``, the node slides along the wall
for as long as it touches it, dissipating ``mu N`` times the slip. Why the FRF folds: touching
the wall adds the normal spring (and the tangential one, up to the slip limit) over part of the
period, a piecewise-linear hardening spring whose resonance rises with the amplitude, and the
friction's dissipation is too small to keep the bent resonance single-valued: between 0.68 and
0.76 rad/s there are three periodic states (an upper branch in contact, a middle one in
contact, a lower one that does not touch the wall).
"""

import numpy as np
from helpers.folded import inclined

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SweepOptions
from fretwear.hb.reduce import exact_condenser
from fretwear.hb.solution import initial_state
from fretwear.hb.stability import HillOptions
from fretwear.hb.sweep import sweep
from fretwear.hb.sweep_stability import sweep_stability
from fretwear.timedomain.monodromy import SHOOTING, monodromy
from fretwear.timedomain.options import InitialState
from fretwear.timedomain.stability import check_periodic


def _near(candidates, target):
    """The multiplier of ``candidates`` nearest ``target`` and its distance."""
    i = int(np.argmin(np.abs(candidates - target)))
    return candidates[i], float(abs(candidates[i] - target))


def test_folded_frictional_frf_hill_and_time_integration_agree():
    """The sweep (15 harmonics, 1024 samples, 0.60 to 0.78 rad/s on 19 points, arclength
    through the fold) has a middle branch (``det J < 0``) between stable stretches. Hill's
    method (4 exponents refined) finds on it a real multiplier above 1 (2.52 at 0.699 rad/s, the
    largest on the branch) and on the upper branch next to it (0.70 rad/s, the node touching
    the wall and sliding) every multiplier inside the unit circle (largest 0.85). Independent
    checks, by the exact time integration of the same model:

    * the monodromy of one period (1024 steps; shooting from the balance's state) has Hill's
      multipliers within 0.05 (measured 0.010 on the middle branch, 2.51 against 2.52, and
      4.4e-3 on the upper one; the difference is the balance's sampling of the friction's
      memory, h = T / N: at 256 samples it was 0.07 at 0.72 rad/s, at 1024 below 0.01) and the
      same verdict;
    * the integration started from the balance's state with its velocity perturbed by 1e-3
      (1024 steps a period, resolving the node's own dynamics) returns to the upper-branch state
      (distance 0.0028: the harmonic truncation of the contact's kink; 0.01 allowed) and leaves
      the middle-branch one (distance 0.18 after 241 periods: it settles on another periodic
      state; 0.1 required), with the tolerance of "the same state" at 0.05."""
    model = inclined()
    cond = exact_condenser(model)
    res = sweep(model, FourierBasis.up_to(15, 1024), 0.60 / (2 * np.pi), 0.78 / (2 * np.pi), 19,
                options=SweepOptions(spacing="linear"), condenser=cond)
    st = sweep_stability(model, res, condenser=cond, options=HillOptions(refine=4))
    rows = [(p, fl) for p, fl in zip(res.points, st.floquet, strict=True) if fl is not None]
    middle = [(p, fl) for p, fl in rows if fl.det_sign < 0]
    assert len(middle) >= 2  # the continuation traced the fold
    assert any(e.kind == "fold" for e in st.events)
    p_mid, fl_mid = max(middle, key=lambda r: r[1].max_multiplier)
    amp = {id(p): float(np.abs(p.solution.observed["x1"][0, 1:]).max()) for p, _ in rows}
    upper = [(p, fl) for p, fl in rows if fl.det_sign > 0 and fl.stable and fl.reliable
             and amp[id(p)] > amp[id(p_mid)] and p.frequency_hz > p_mid.frequency_hz]
    assert upper
    p_up, fl_up = min(upper, key=lambda r: r[0].frequency_hz - p_mid.frequency_hz)
    assert 0.0 < p_up.solution.state_fractions()[0, 2]  # the node slides on the upper branch
    for p, fl, unstable in ((p_mid, fl_mid, True), (p_up, fl_up, False)):
        U0, V0 = initial_state(model, p.solution, cond)
        mono = monodromy(model, p.frequency_hz, start=InitialState(U0=U0, V0=V0),
                         integration=SHOOTING.replace(steps_per_period=1024))
        assert mono.success
        main = fl.multipliers[np.abs(fl.multipliers) > 0.1]
        assert main.size >= 2
        for r in main:
            assert _near(mono.multipliers, r)[1] < 0.05, (p.frequency_hz, r, mono.multipliers)
        assert (fl.max_multiplier > 1) == (mono.max_multiplier > 1) == unstable
        if unstable:  # a real multiplier above 1: the fold's middle branch
            top = fl.critical(1)[0]
            assert abs(top.imag) < 1e-9 and top.real > 1.5
        chk = check_periodic(model, p.solution, max_periods=400, steps_per_period=1024,
                             tolerance=0.05, condenser=cond)
        assert (chk.verdict == "stable") == (not unstable), (p.frequency_hz, chk)
        if unstable:
            assert chk.verdict == "settles elsewhere" and chk.distance > 0.1
        else:
            assert chk.distance < 0.01
