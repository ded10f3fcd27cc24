"""Direct tests of the integration loops of the time-domain solvers
(fretwear.timedomain.kernels), on records written by hand.

* ``run_dynamic`` on two undamped modal oscillators whose contact never closes: the loop is
  then the trapezoidal rule, whose discrete free vibration is known in closed form,
  ``q_n = q_0 cos(n theta)`` with ``cos theta = (1 - a) / (1 + a)``, ``a = (omega h)^2 / 4``
  (the start ``dq_0 = q_0 (1 - cos theta)`` puts ``q_-1`` on that cosine); and its discrete
  energy ``E_{n+1/2}`` is conserved (the identity of the scheme, docs/transient.md). Both to
  rounding over 64 steps (1e-12 relative).
* ``run_quasistatic`` on one 2D node pressed by a constant normal force ``P`` and pulled by a
  tangential spring load ``Q cos(2 pi k / N)`` (a Jenkins element, ``Q > mu P``): the node
  slides ``2 (Q - mu P) / kT`` each half cycle (``(Q - mu P) / kT`` more at the first step,
  from rest), the friction force does ``mu P`` times the slip, and Archard's law wears
  ``kw P / area`` times the slip, counted ``jump`` times per computed cycle. Sums of a few
  exact increments: 1e-12 relative.
"""

import numpy as np
import pytest

from fretwear.timedomain.contact_solve import OPEN, STICK, Contact, ContactState, Settings
from fretwear.timedomain.kernels import (
    DynamicState,
    EnergyTerms,
    LoadCycle,
    Records,
    StepOperator,
    WearRecords,
    WearState,
    run_dynamic,
    run_quasistatic,
)


def test_dynamic_loop_is_the_trapezoidal_rule():
    """Two modes (omega 1 and 2.5 rad/s, h = 0.1 s, 32 steps per period, two periods), each
    the local displacement of one component of a contact node 10 m from its obstacle."""
    w = np.array([1.0, 2.5])
    h, N, periods = 0.1, 32, 2
    r = m = 2
    a = (w * h) ** 2 / 4
    theta = np.arccos((1 - a) / (1 + a))
    q0 = np.array([1.0, 0.5])
    ds = 1.0 + a  # m + g h c + b h^2 k with m = 1, c = 0, g = 1/2, b = 1/4
    z = np.zeros((r, 0))
    G = np.diag(h * h / ds)
    op = StepOperator(True, ds.copy(), -h * h * w**2, ds.copy(), np.full(r, 0.5 * h), z.copy(),
                      np.zeros((0, 0)), z.copy(), np.zeros((0, r)), np.zeros((0, 0)),
                      np.zeros((0, 0)), np.zeros((N, r)), G, np.eye(m), np.eye(r))
    en = EnergyTerms(h, np.zeros((N, r)), np.ones(r), w**2, np.zeros(r), np.zeros((0, 0)),
                     np.zeros((0, 0)), np.zeros((0, 0)))
    con = Contact(np.linalg.inv(G), np.array([10.0]), np.array([0.3]), 2)
    dq = q0 * (1 - np.cos(theta))
    st = DynamicState(q0.copy(), dq.copy(), q0.copy(), q0 - dq,
                      ContactState(np.array([OPEN], dtype=np.int8), np.ones((1, 1))))
    ns = periods * N
    rec = Records(0, np.zeros((periods, 4)), np.zeros((periods, 4)), np.zeros((periods, 4)), 0,
                  np.zeros((ns, r)), np.zeros((ns, r)), np.zeros((ns, m)), np.zeros((ns, m)),
                  np.zeros((ns, 1), dtype=np.int8), np.zeros((ns, 6)))
    n_fail, _, first = run_dynamic(op, en, con, Settings(1e-10, 1.0, 60), st, rec, periods, 0)
    assert n_fail == 0 and first == -1
    n = np.arange(ns)[:, None]
    np.testing.assert_allclose(rec.obs, q0 * np.cos(n * theta), rtol=0, atol=1e-12)
    assert np.all(rec.lam == 0.0) and np.all(rec.state == OPEN)
    e = rec.energy[:, 4]  # E_{n+1/2}: the same at every step
    assert np.abs(e - e[0]).max() <= 1e-12 * e[0]
    np.testing.assert_array_equal(rec.mon_start[:, :r], rec.obs[::N])


@pytest.mark.parametrize("jump", [1, 3])
def test_quasistatic_loop_on_a_jenkins_element(jump):
    """P = 10 N, mu = 0.3, Q = 8 N, kT = 1e4 N/m, area 1e-4 m^2, kw = 1e-13 1/Pa, 16 steps
    per cycle (the extremes +-Q are steps), 4 computed cycles; the normal row of A is zero, so
    the normal force stays P whatever the wear."""
    P, mu, Q, kT, area, kw, N = 10.0, 0.3, 8.0, 1e4, 1e-4, 1e-13, 16
    tau = 2 * np.pi * np.arange(N) / N
    btab = np.column_stack([np.full(N, P), Q * np.cos(tau)])
    jumps = np.array([1] + [jump] * 3, dtype=np.int64)
    x = np.zeros(2)
    wear = np.zeros(1)
    rec = WearRecords(1, np.zeros((4, 1)), np.zeros((4, 1)), np.zeros((4, 1)), np.zeros(4),
                      np.zeros(4, dtype=np.int64))
    con = Contact(np.diag([0.0, kT]), np.zeros(1), np.array([mu]), 2)
    nrec, n_fail, _ = run_quasistatic(
        con, LoadCycle(btab, np.array([area]), kw, jumps), Settings(1e-12, Q, 60),
        WearState(x, wear, ContactState(np.array([STICK], dtype=np.int8), np.ones((1, 1)))),
        rec)
    assert nrec == 4 and n_fail == 0
    travel = 2 * (Q - mu * P) / kT
    slip = np.array([2.5, 2, 2, 2]) * travel  # the first cycle starts from rest
    np.testing.assert_allclose(rec.slip[:, 0], slip, rtol=1e-12)
    np.testing.assert_allclose(rec.diss, mu * P * slip, rtol=1e-12)
    np.testing.assert_allclose(rec.press[:, 0], P / area, rtol=1e-12)
    np.testing.assert_allclose(rec.wear[:, 0], np.cumsum(jumps * kw * P / area * slip),
                               rtol=1e-12)
    assert rec.cycle.tolist() == np.cumsum(jumps).tolist()
