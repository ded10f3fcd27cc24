"""Direct tests of the contact solves of the time-domain solvers
(fretwear.timedomain.contact_solve).

* ``_gauss_solve`` (Gaussian elimination with partial pivoting, in place) against
  ``numpy.linalg.solve`` (LAPACK): random systems of condition ~10 agree to 1e-12 relative
  (both backward stable: error ~ cond x n x 1e-16); a singular system is reported.
* ``solve_contact`` on one 2D node with a diagonal condensed stiffness, where the frictional
  contact problem has a closed-form answer: open (``x = xref + A^-1 b``, no force), stick
  (``x_T`` = previous, ``lam_T = b_T - k_t x_T``) and slip (``lam_T = mu lam_N sign``). The
  answers are a division or two, so 1e-12 relative.
* ``solve_contact`` on one 3D node with ``A = diag(kN, kT, kT)``: the closed-form answer of the
  isotropic cone (open; stick; slip along the trial force ``b_T - kT x_prev,T`` with
  ``|lam_T| = mu lam_N``, the radial return), from every warm-start status, to 1e-12.
* ``solve_contact`` on many 3D nodes (16, the Delassus operator of a hexahedral pad), where
  there is no closed form: every answer satisfies Signorini and Coulomb's law on the isotropic
  cone, checked directly on ``lam = b - A (x - xref)`` (an independent evaluation of the laws,
  not the solver's residual), sticking nodes do not move by one rounding unit, and starts from
  different statuses reach the same answer (the problem has one solution).
"""

import numpy as np
import pytest
from helpers.pads import F_PAD, pad_3d

from fretwear.timedomain.contact_solve import OPEN, SLIP, STICK, _gauss_solve, solve_contact

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
    its = solve_contact(A, b, np.zeros(2), np.zeros(1), np.array([0.0, xprev_t]),
                        np.full(1, MU), 2,
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


# --------------------------------------------------------------------------------------------
# 3D: the isotropic Coulomb cone
# --------------------------------------------------------------------------------------------
def solve3(A, b, xref, gap, xprev, status, tol=1e-12):
    """``solve_contact`` in 3D with fresh work arrays; returns (iterations, status, x, lam)."""
    m = b.size
    nc = m // 3
    status = np.array(status, dtype=np.int8)
    tdir = np.zeros((nc, 2))
    tdir[:, 0] = 1.0
    x, lam = np.zeros(m), np.zeros(m)
    its = solve_contact(A, b, xref, gap, xprev, np.full(nc, MU), 3, status, tdir, x, lam, tol,
                        float(np.abs(b).max()), 60 + 4 * nc, np.zeros(m, np.int64),
                        np.zeros(m, np.int64), np.zeros(m, np.int64), np.zeros((m, m)),
                        np.zeros(m))
    return its, status, x, lam


GUESSES = [OPEN, STICK, SLIP]


@pytest.mark.parametrize("guess", GUESSES)
def test_3d_node_open(guess):
    """Pulled away (b_N < 0): free, x = A^-1 b, no force."""
    A = np.diag([KN, KT, KT])
    b = np.array([-100.0, 10.0, -20.0])
    its, st, x, lam = solve3(A, b, np.zeros(3), np.zeros(1), np.zeros(3), [guess])
    assert its >= 0 and st[0] == OPEN
    np.testing.assert_allclose(x, b / np.diag(A), rtol=1e-12)
    np.testing.assert_allclose(lam, 0.0, atol=1e-12 * 100.0)


@pytest.mark.parametrize("guess", GUESSES)
def test_3d_node_stick(guess):
    """Pressed by 100 N, trial tangential force of 25 N < mu x 100 N at 40 deg: stick; the
    tangential position is the previous one to the last bit."""
    xp = np.array([0.0, 1e-7, -3e-8])
    trial = 25.0 * np.array([np.cos(0.7), np.sin(0.7)])
    A = np.diag([KN, KT, KT])
    b = np.r_[100.0, trial + KT * xp[1:]]
    its, st, x, lam = solve3(A, b, np.zeros(3), np.zeros(1), xp, [guess])
    assert its >= 0 and st[0] == STICK
    assert np.all(x[1:] == xp[1:])
    np.testing.assert_allclose(lam, np.r_[100.0, trial], rtol=1e-12)


@pytest.mark.parametrize("guess", GUESSES)
@pytest.mark.parametrize("angle", [0.0, 0.7, 2.0, -2.9])
def test_3d_node_slip_is_the_radial_return(guess, angle):
    """Pressed by 100 N, trial tangential force of 50 N > 30 N: slip along the trial force
    (isotropic cone and isotropic tangential stiffness: the radial return),
    lam_T = mu lam_N e, x_T = x_prev,T + (50 - 30) / kT e, whatever the direction (a
    component-wise or polygonal cone would bend it)."""
    xp = np.array([0.0, 2e-7, 1e-7])
    e = np.array([np.cos(angle), np.sin(angle)])
    A = np.diag([KN, KT, KT])
    b = np.r_[100.0, 50.0 * e + KT * xp[1:]]
    its, st, x, lam = solve3(A, b, np.zeros(3), np.zeros(1), xp, [guess])
    assert its >= 0 and st[0] == SLIP
    np.testing.assert_allclose(lam, np.r_[100.0, MU * 100.0 * e], rtol=1e-12, atol=1e-12 * 100)
    np.testing.assert_allclose(x[1:], xp[1:] + (50.0 - MU * 100.0) / KT * e, rtol=1e-12,
                               atol=1e-12 * 20.0 / KT)
    assert abs(x[0]) <= 1e-12 * 100.0 / KN


def check_laws(A, b, xref, gap, xprev, x, status, tol):
    """Signorini and incremental Coulomb on the isotropic cone at ``x``, with the forces
    recomputed here (``lam = b - A (x - xref)``); errors relative to the largest force (and to
    the displacement it causes through the stiffest diagonal term)."""
    nc = gap.size
    lam = (b - A @ (x - xref)).reshape(nc, 3)
    X = x.reshape(nc, 3)
    xi = X[:, 1:] - xprev.reshape(nc, 3)[:, 1:]
    fs = np.abs(lam).max()
    xs = fs / np.diag(A).max()
    ln, lt = lam[:, 0], np.linalg.norm(lam[:, 1:], axis=1)
    nxi = np.linalg.norm(xi, axis=1)
    closed = status != OPEN
    assert np.all(X[:, 0] - gap <= tol * xs)
    assert np.all(ln >= -tol * fs)
    assert np.all(np.abs(ln[~closed]) <= tol * fs)  # open: no force
    assert np.all(X[closed, 0] == gap[closed])  # closed: exactly at the gap
    assert np.all(lt <= MU * ln + tol * fs)  # inside the cone
    stick = status == STICK
    assert np.all(xi[stick] == 0.0)  # sticking nodes do not move at all
    slip = status == SLIP
    assert np.all(nxi[slip] > 0.0)
    # slip: the force is on the cone and points along the slip
    err = lam[slip, 1:] - MU * ln[slip, None] * xi[slip] / nxi[slip, None]
    assert np.all(np.abs(err) <= tol * fs)
    return lam


@pytest.fixture(scope="module")
def pad_delassus():
    """The step's Delassus operator of the 16-node pad (``A = W^-1``, 48 x 48, SPD, with
    strong coupling between the nodes), as the time integrator builds it."""
    from fretwear.timedomain.integrate import Integrator
    from fretwear.timedomain.options import IntegrationOptions

    integ = Integrator(pad_3d(), 2 * np.pi * F_PAD,
                       IntegrationOptions(steps_per_period=256, gamma=0.5, contact_tol=1e-10))
    return integ.A


def test_3d_many_nodes_satisfy_the_laws_from_any_start(pad_delassus):
    """40 random contact problems on the pad (free positions pressing or lifting nodes,
    tangential motions of the whole pad and of single nodes from 0.1 nm to 0.1 um, some
    initial gaps; mu = 0.3): each is solved (a few Newton iterations: the semismooth Newton
    method converges quadratically once the statuses are right), satisfies the laws to the
    tolerance asked (1e-12, tested at 1e-10: the forces are recomputed here in another order),
    and three starts (all open, all stick, all slip) give the same answer to 1e-9 of the
    largest force (one solution; the starts differ by the solver's tolerance)."""
    A = pad_delassus
    nc = A.shape[0] // 3
    rng = np.random.default_rng(3)
    n_states = np.zeros(3, dtype=int)
    for _ in range(40):
        s = 10.0 ** rng.uniform(-10, -7)  # size of the tangential motions [m]
        xref = np.zeros(3 * nc)
        xref[0::3] = rng.normal(0.5, 1.0, nc) * 1e-7
        xref[1::3] = rng.normal(0, 0.1 * s, nc) + rng.normal() * s
        xref[2::3] = rng.normal(0, 0.1 * s, nc) + rng.normal() * s
        xprev = xref.copy()
        xprev[1::3] += rng.normal(0, 0.1 * s, nc)
        xprev[2::3] += rng.normal(0, 0.1 * s, nc)
        gap = np.abs(rng.normal(size=nc)) * 1e-8 * rng.integers(0, 2)
        b = np.zeros(3 * nc)
        answers = []
        for guess in GUESSES:
            its, st, x, lam = solve3(A, b, xref, gap, xprev, [guess] * nc)
            assert 0 <= its <= 20
            lam_here = check_laws(A, b, xref, gap, xprev, x, st, 1e-10)
            np.testing.assert_allclose(lam, lam_here.ravel(), rtol=0,
                                       atol=1e-10 * np.abs(lam_here).max())
            answers.append((st, lam))
        for st, lam in answers[1:]:
            assert np.array_equal(st, answers[0][0])
            np.testing.assert_allclose(lam, answers[0][1], rtol=0,
                                       atol=1e-9 * np.abs(lam).max())
        n_states += np.bincount(answers[0][0], minlength=3)
    assert np.all(n_states > 20)  # every status occurs often
