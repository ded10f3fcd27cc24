"""Pseudo-arclength continuation (:mod:`fretwear.hb.arclength`): the Newton step of the bordered
system, the branch from two converged points past a target frequency, and the test of a fold
ahead of the last converged points (against a circle's turning point).

References: the bordered system multiplied out by hand (the step is whatever solves it), and a
fresh DLFT problem condensed at each returned frequency by :func:`fretwear.hb.reduce.condense`
(not the sweep's cache), whose residual at the returned harmonics must meet the corrector's
tolerance."""

import numpy as np
from helpers.blocks import closed_block

from fretwear.hb.arclength import arclength, bordered_step, fold_ahead
from fretwear.hb.attempts import solve_at
from fretwear.hb.branch import Problems
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense, exact_condenser

BASIS = FourierBasis.up_to(3, 32)
EPS = 1e9  # N/m: one penalty at every frequency


def test_bordered_step_solves_the_bordered_system():
    """``[[J sx, fw sw], [t]] dy = -[f, g]`` multiplied out: 1e-12 of the right-hand side
    (an LU of a well-conditioned 9 x 9 system)."""
    rng = np.random.default_rng(2)
    n, sx, sw = 8, 2.0, 5.0
    J = rng.standard_normal((n, n)) + 4 * np.eye(n)
    f, fw, t = rng.standard_normal(n), rng.standard_normal(n), rng.standard_normal(n + 1)
    dy = bordered_step(J, f, fw, 0.3, t, sx, sw)
    lhs = np.concatenate([J @ dy[:n] * sx + fw * sw * dy[n], [t @ dy]])
    np.testing.assert_allclose(lhs, -np.concatenate([f, [0.3]]), rtol=0, atol=1e-12 * 10)


def test_branch_passes_the_target_with_balanced_points():
    """A frictionless block held closed (a linear response): from two converged points at
    1000 and 1100 Hz towards 1300 Hz, the branch reaches past the target and every point on
    it is a balance of its own frequency (relative residual of a freshly condensed problem
    below 1e-8, the corrector's 1e-10 plus the rounding of omega -> Hz -> omega)."""
    model, branch = _closed_block_branch(1000.0, 1100.0, 1300.0)
    target = 2 * np.pi * 1300.0
    assert branch and branch[-1][1] >= target
    assert all(b[1] > 2 * np.pi * 1100.0 for b in branch)
    for _, _, st, _ in branch:
        assert st.success and st.solver == "arclength"
    _assert_balances(model, branch)


def test_branch_never_steps_below_zero_frequency():
    """Marching down from 1100 and 300 Hz towards 100 Hz on the closed block (a linear
    response), the first predictor lands at -500 Hz: the step is shortened until it is at a
    positive frequency (before, the condensation at a negative frequency raised an
    InputError: a sweep point of the paper's beam whose neighbour lay 9 times lower in
    frequency). Every point returned lies at a positive frequency and is a balance there
    (relative residual of a freshly condensed problem below 1e-8, as above)."""
    model, branch = _closed_block_branch(1100.0, 300.0, 100.0)
    assert branch and branch[-1][1] <= 2 * np.pi * 100.0
    assert all(w > 0 for _, w, _, _ in branch)
    _assert_balances(model, branch)


def _closed_block_branch(f0, f1, f_target):
    """The closed block (a linear response) converged at ``f0`` and ``f1`` [Hz], and the
    arclength branch from those two points towards ``f_target``: ``(model, branch)``."""
    model = closed_block()
    probs = Problems(model, BASIS, None, EPS, exact_condenser(model))
    anchor = np.zeros((model.contact.n_nodes, 1))
    opts = SolveOptions(tol=1e-10)
    w0, w1, target = (2 * np.pi * f for f in (f0, f1, f_target))
    _, U0, s0 = solve_at(probs, w0, anchor, None, opts)
    _, U1, s1 = solve_at(probs, w1, anchor, U0, opts)
    assert s0.success and s1.success
    return model, arclength(probs, anchor, (U0.reshape(-1), w0), (U1.reshape(-1), w1), target,
                            1e-10)


def _assert_balances(model, branch):
    """Every point of ``branch`` is a balance of its own frequency: the relative residual of a
    freshly condensed problem (zero anchor) below 1e-8."""
    anchor = np.zeros((model.contact.n_nodes, 1))
    for U, w, _, _ in branch:
        red = condense(model, w / (2 * np.pi), BASIS.orders)
        prob = DLFTProblem(red, model.contact, BASIS, eps=EPS, anchor=anchor)
        Ux = U.reshape(prob.m, prob.H)
        f, _ = prob.residual(Ux, jacobian=False)
        assert np.linalg.norm(f) <= 1e-8 * prob.scale(Ux)

def _arc(degrees, R=0.1):
    """Points ``(omega, U)`` on the circle ``omega = 1 + R cos a``, ``U = 1 + R sin a`` at the
    angles ``degrees``: a branch whose frequency turns back at ``a = 0`` (``omega = 1 + R``)."""
    a = np.radians(degrees)
    return [(1.0 + R * np.cos(t), np.array([1.0 + R * np.sin(t)])) for t in a]


def test_fold_ahead_finds_the_turning_point_of_a_circle():
    """Three points 20 degrees apart before the turning point of a circle: the parabola of the
    frequency along the arclength puts the turn within 5 % of the radius of the circle's
    (measured 0.9 %, and 3.9 % on the mirror image: the scaling by the last point's frequency
    makes the circle a slight ellipse): a target past it has a fold ahead, one before it has
    none, marching up or down (the mirror image);
    a straight branch, one past the turn marching down (omega(s) accelerating along the
    march: the tangent turning towards the frequency axis) and fewer than three points have
    none."""
    R = 0.1
    up = _arc((-60, -40, -20))
    assert fold_ahead(up, 1.0 + 1.05 * R)
    assert not fold_ahead(up, 1.0 + 0.95 * R)
    down = [(2.0 - w, U) for w, U in up]  # the mirror image, marching down
    assert fold_ahead(down, 1.0 - 1.05 * R)
    assert not fold_ahead(down, 1.0 - 0.95 * R)
    line = [(w, np.array([2.0 * w])) for w in (1.0, 1.05, 1.1)]
    assert not fold_ahead(line, 2.0)
    away = _arc((10, 30, 50))  # past the turn: the frequency falls ever faster along s
    assert away[2][0] < away[1][0] < away[0][0]
    assert not fold_ahead(away, 0.5)
    assert not fold_ahead(up[1:], 2.0)
    # a step halved to its smallest without converging: a fold wherever the branch
    # decelerates, never where it does not
    assert fold_ahead(up, 1.0 + 0.95 * R, halved_out=True)
    assert not fold_ahead(line, 2.0, halved_out=True)
    assert not fold_ahead(away, 0.5, halved_out=True)
