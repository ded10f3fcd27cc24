"""Direct tests of the numba kernels of the time-domain solvers (fretwear.timedomain.kernels).

* ``_gauss_solve`` (Gaussian elimination with partial pivoting, in place) against
  ``numpy.linalg.solve`` (LAPACK): random systems of condition ~10 agree to 1e-12 relative
  (both backward stable: error ~ cond x n x 1e-16); a singular system is reported.
* ``solve_contact`` on one 2D node with a diagonal condensed stiffness, where the frictional
  contact problem has a closed-form answer: open (``x = xref + A^-1 b``, no force), stick
  (``x_T`` = previous, ``lam_T = b_T - k_t x_T``) and slip (``lam_T = mu lam_N sign``). The
  answers are a division or two, so 1e-12 relative.
"""

import numpy as np
import pytest

from fretwear.timedomain.kernels import OPEN, SLIP, STICK, _gauss_solve, solve_contact

RNG = np.random.default_rng(11)


@pytest.mark.parametrize("n", [1, 3, 8])
def test_gauss_solve_against_lapack(n):
    a = RNG.standard_normal((n, n)) + 3 * np.eye(n)
    b = RNG.standard_normal(n)
    ref = np.linalg.solve(a, b)
    work, rhs = a.copy(), np.r_[b, 7.0]  # an extra entry beyond n is left alone
    assert _gauss_solve(work, rhs, n)
    np.testing.assert_allclose(rhs[:n], ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    assert rhs[n] == 7.0


def test_gauss_solve_reports_a_singular_system():
    a = np.array([[1.0, 2.0], [2.0, 4.0]])
    assert not _gauss_solve(a.copy(), np.ones(2), 2)
    assert not _gauss_solve(np.zeros((2, 2)), np.ones(2), 2)


KN, KT, MU = 1e8, 5e7, 0.3


def one_node(bn, bt, xprev_t, guess=STICK):
    """Solve one node (components N, T) with ``A = diag(KN, KT)``, ``xref = 0``, gap 0."""
    A = np.diag([KN, KT])
    b = np.array([bn, bt])
    status = np.array([guess], dtype=np.int8)
    tdir = np.ones((1, 1))
    x, lam = np.zeros(2), np.zeros(2)
    its = solve_contact(A, b, np.zeros(2), np.zeros(1), np.array([0.0, xprev_t]), MU, 2,
                        status, tdir, x, lam, 1e-12, abs(bn) + abs(bt), 50,
                        np.zeros(2, np.int64), np.zeros(2, np.int64), np.zeros(2, np.int64),
                        np.zeros((2, 2)), np.zeros(2))
    assert its >= 0
    return int(status[0]), x, lam


def test_open_node_carries_no_force():
    """Pulled away (b_N < 0): free, x = A^-1 b below the gap."""
    st, x, lam = one_node(-100.0, 10.0, 0.0)
    assert st == OPEN
    np.testing.assert_allclose(x, [-100.0 / KN, 10.0 / KT], rtol=1e-12)
    np.testing.assert_allclose(lam, 0.0, atol=1e-9)


def test_sticking_node_keeps_its_tangential_position():
    """Pressed (b_N = 100 N) with |b_T - KT x_prev| = 10 N < mu x 100 N: stick."""
    xp = 1e-7
    st, x, lam = one_node(100.0, 10.0 + KT * xp, xp)
    assert st == STICK
    np.testing.assert_allclose(x, [0.0, xp], atol=1e-18)
    np.testing.assert_allclose(lam, [100.0, 10.0], rtol=1e-12)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_slipping_node_carries_mu_times_the_normal_force(sign):
    """Pressed by 100 N, tangential load 50 N > 30 N: slip along the load,
    lam_T = mu lam_N, x_T = (b_T - lam_T) / KT."""
    st, x, lam = one_node(100.0, sign * 50.0, 0.0)
    assert st == SLIP
    np.testing.assert_allclose(lam, [100.0, sign * MU * 100.0], rtol=1e-12)
    np.testing.assert_allclose(x[1], sign * (50.0 - 30.0) / KT, rtol=1e-12)
    assert abs(x[0]) <= 1e-12 * 100.0 / KN
