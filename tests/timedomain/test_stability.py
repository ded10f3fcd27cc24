"""The time-domain check of periodic solutions (fretwear.timedomain.stability).

Compared with: an independent method, the exact time integration of fretwear.timedomain.integrate,
on
a single friction oscillator whose steady state is known to be unique and attracting (viscous
damping, continuous slip: Den Hartog's regime), so the check must answer "stable"; and the
time-domain start must hand back harmonics that make the DLFT converge at once; and on the
16-node 3D pad (tests/helpers/pads.py), whose partial-slip periodic state the time integration
reproduces (test_integrate.py), the check must answer "stable" when its step resolves the
contact's dynamics and say that the step is too coarse when it does not.
"""

import numpy as np
from helpers.models import K_, M_, oscillator
from helpers.pads import F_PAD, pad_3d

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.solution import initial_state
from fretwear.timedomain.stability import RESOLVED_STEPS, check_periodic, time_domain_start

F_HZ = 0.7 * np.sqrt(K_ / M_) / (2 * np.pi)  # forcing frequency [Hz], below the resonance


def test_initial_state_reproduces_the_periodic_solution():
    """The full-field state at t = 0 equals the sum of the harmonics (and the derivative
    operator for the velocity): exact up to rounding."""
    model = oscillator()
    basis = FourierBasis.up_to(7, 64)
    sol = solve_periodic(model, basis, frequency=F_HZ)
    st = sol.stats
    assert st.success
    U0, V0 = initial_state(model, sol)
    u, v = sol.observed_time("x")
    assert abs(U0[1] - u[0, 0]) <= 1e-12 * np.abs(u).max()
    assert abs(V0[1] - v[0, 0]) <= 1e-9 * np.abs(v).max()


def test_attracting_steady_state_is_reported_stable():
    """Continuous slip with 5 % damping: the time integration from the (perturbed) DLFT
    solution settles back to it. The distance allowed (0.2 of the peak-to-peak, the default)
    is far above the 7-harmonic truncation error of this oscillator (~3 %, docs/verification.md
    Den Hartog table), and far below what another state would give."""
    model = oscillator()
    basis = FourierBasis.up_to(7, 64)
    sol = solve_periodic(model, basis, frequency=F_HZ)
    st = sol.stats
    assert st.success
    chk = check_periodic(model, sol, max_periods=2000, steps_per_period=512)
    assert chk.verdict == "stable", chk
    assert chk.distance < 0.1
    assert chk.flags() == []


def test_time_domain_start_gives_a_converging_start():
    """The harmonics of the settled time response start the DLFT next to its solution: it
    converges in a few iterations (measured: 1; the two methods differ by the truncation
    error, ~3 %, which Newton removes in one step on this smooth-in-slip problem)."""
    model = oscillator()
    basis = FourierBasis.up_to(7, 64)
    msg, U0, anchor = time_domain_start(model, F_HZ, basis, max_periods=2000)
    assert msg.startswith("time integration: periodic"), msg
    sol = solve_periodic(model, basis, frequency=F_HZ, U0=U0, anchor=anchor)
    st = sol.stats
    assert st.success and st.iterations <= 3


def test_3d_pad_is_reported_stable_when_the_step_resolves_the_contact():
    """The 16-node pad (partial slip) from its 6-harmonic DLFT solution: with 4096 steps per
    period (3.4 per period of the reduced model's highest mode, 1.2 MHz) the time integration
    settles back to it (measured distance 0.08 of the peak-to-peak: the 6-harmonic truncation
    and the step; the default bound 0.2). With 1024 steps (0.88 per highest period) the
    contact nodes' dynamics are not resolved, the pad settles at another stuck position
    (distance 9.7: it slid by ~3 um during the start), and the message gives the step that
    resolves them: more than 1024 x 3 (fewer than one step per highest period at 1024) and
    fewer than 4096 (3.4 steps at 4096); measured 3489."""
    model = pad_3d()
    sol = solve_periodic(model, FourierBasis.up_to(6, 96), frequency=F_PAD,
                         options=SolveOptions(tol=1e-10))
    assert sol.success
    chk = check_periodic(model, sol, max_periods=200, steps_per_period=4096)
    assert chk.verdict == "stable", chk
    assert chk.distance < 0.15
    coarse = check_periodic(model, sol, max_periods=200, steps_per_period=1024)
    assert coarse.verdict != "stable"
    need = int(coarse.message.rsplit(">= ", 1)[1])
    assert 1024 * RESOLVED_STEPS < need < 4096


def test_settles_elsewhere_says_why_whatever_the_distance():
    """A subharmonic response (twice the period) can lie within the distance tolerance of
    the periodic solution over one period and still be another state: the verdict's message
    then says the distance is within the tolerance but the period is not the solution's,
    never "distance 0.18 > 0.2" (which a run on the platform damper printed); beyond the
    tolerance it says so as before."""
    from fretwear.timedomain.stability import _verdict

    near = _verdict("subharmonic", 0.18, 12, 1.0, 0.2, None)
    assert near.verdict == "settles elsewhere"
    assert "0.18 <= 0.2" in near.message and "> 0.2" not in near.message
    far = _verdict("periodic", 0.5, 12, 1.0, 0.2, None)
    assert "distance 0.5 > 0.2" in far.message
