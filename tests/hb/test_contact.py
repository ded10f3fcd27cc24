"""Validation of the DLFT contact law in time (paper eq. 24-28) and of its Jacobian.

Code under test: :func:`fretwear.hb.contact.dlft_time`, :func:`fretwear.hb.contact.dlft_jacobian`
and :meth:`fretwear.hb.problem.DLFTProblem.residual`.

Independent references used here (none of them calls the code under test):

* ``ref_sweep`` / ``ref_law``: a direct pure-Python transcription of the paper's
  prediction / correction (eq. 24-28) in this project's sign convention (``lambda_N >= 0`` in
  compression, so the paper's "separation when lambda_pre,N >= 0" reads ``pre_N <= 0`` here),
  made periodic by sweeping until the start state repeats. It uses the plain stick test
  ``|pre_T| < mu pN``; the kernel adds a rounding margin (contact.ROUND = 1e-13 relative) so
  that a state sitting on the cone stays "slip": the two differ only within 1e-13 of the
  cone, which the regular test signals avoid (asserted margins) and where the shakedown
  tests compare corrections, not states;
* ``trig_matrices``: the real Fourier basis ``[1, cos h tau, sin h tau]`` written with
  numpy cos/sin (not :mod:`fretwear.hb.fourier`);
* central finite differences of the time law / of the residual for the Jacobians;
* closed forms where the derivative is known by hand (separation: ``G = I``; stick for the
  whole period: ``G = 0``; 2D slip at every instant: ``lambda_x,T = lambda_u,T - mu pN s``).

The test signals are small trigonometric polynomials built to visit the three states
(separation ``-``, stick ``|``, slip ``/``) in known patterns; every test asserts its own
*margin* (distance of every instant from a switching threshold) so that a finite-difference
step never crosses a kink of this piecewise-smooth map.
"""

import numpy as np
import pytest
from helpers.contact_law import (
    ATOL_LAW,
    CASES,
    EXPECTED,
    FD_RTOL,
    FD_STEP,
    HARM,
    MIN_MARGIN,
    NS,
    P_REF,
    Q_REF,
    SWEEPS,
    TOL_LAW,
    case,
    coeffs,
    margins,
    pattern,
    ref_law,
    ref_sweep,
    run_law,
)

from fretwear.hb import contact as law


# --------------------------------------------------------------------------------------------
# 1. the time law against the direct transcription of eq. 24-28
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("key", list(CASES), ids=[f"{d}D-{n}" for d, n in CASES])
def test_time_law_matches_reference(key):
    """dlft_time vs ``ref_law`` (eq. 24-28 in pure Python): same corrections lambda_x and same
    states at every instant. Tolerance ATOL_LAW (see its comment): rounding only."""
    c, mu, xs = case(key)
    lu, lx, state, sweeps = run_law(c, mu, xs)
    lx_ref, state_ref = ref_law(lu, mu, xs)
    scale = np.abs(lu).max()
    assert margins(lu, lx_ref, mu).min() > MIN_MARGIN  # no instant sits on a threshold
    exp = EXPECTED[key[1]]
    assert pattern(state_ref[0]) == (exp[key[0]] if isinstance(exp, dict) else exp)
    np.testing.assert_array_equal(state, state_ref)
    np.testing.assert_allclose(lx, lx_ref, rtol=0, atol=ATOL_LAW * scale)
    assert sweeps[0] <= SWEEPS


@pytest.mark.parametrize("key", list(CASES), ids=[f"{d}D-{n}" for d, n in CASES])
def test_time_law_satisfies_contact_conditions(key):
    """The forces ``lambda = lambda_u - lambda_x`` (eq. 25 corrected) obey the contact law at
    every instant: zero in separation; lambda_N >= 0 and |lambda_T| <= mu lambda_N in contact;
    on the cone ``|lambda_T| = mu lambda_N`` in slip with lambda_T along pre_T (isotropic
    Coulomb: vector norm in 3D); no tangential correction change in stick. Checked on the
    kernel's output alone, with ``pre_T`` recomputed here. Relative tolerance 1e-12: the cone
    projection is one division, so only rounding separates |lambda_T| from mu lambda_N."""
    c, mu, xs = case(key)
    lu, lx, state, _ = run_law(c, mu, xs)
    lam = lu - lx
    st = state[0]
    scale = np.abs(lu).max()
    sep, stick, slip = (st == law.SEPARATION), (st == law.STICK), (st == law.SLIP)
    np.testing.assert_array_equal(lam[0][:, sep], 0.0)
    ln = lam[0, 0]
    lt = np.linalg.norm(lam[0, 1:], axis=0)
    assert np.all(ln[~sep] > 0.0)
    assert np.all(lt[~sep] <= mu[0] * ln[~sep] * (1 + 1e-12))
    np.testing.assert_allclose(lt[slip], mu[0] * ln[slip], rtol=1e-12, atol=0)
    pre = (lu[0, 1:] - np.roll(lx[0, 1:], 1, axis=1))[:, slip]
    cosang = np.einsum("cn,cn->n", lam[0, 1:][:, slip], pre) / (
        lt[slip] * np.linalg.norm(pre, axis=0))
    np.testing.assert_allclose(cosang, 1.0, rtol=0, atol=1e-12)
    # stick copies the previous correction; across the wrap-around the start of the period
    # equals its end only to the periodicity tolerance (1e-14 of the scale)
    np.testing.assert_allclose(lx[0, 1:][:, stick], np.roll(lx[0, 1:], 1, axis=1)[:, stick],
                               rtol=0, atol=ATOL_LAW * scale)
    np.testing.assert_array_equal(lx[0, 0][~sep], 0.0)  # no normal correction in contact


@pytest.mark.parametrize("key", list(CASES), ids=[f"{d}D-{n}" for d, n in CASES])
def test_time_law_is_periodic(key):
    """The start state repeats: one more reference pass started from the last correction of
    the kernel's period reproduces the whole period (the output is a periodic orbit of the
    recursion, including across the wrap-around). Tolerance ATOL_LAW: rounding plus the
    periodicity tolerance 1e-14 given to the kernel."""
    c, mu, xs = case(key)
    lu, lx, _, _ = run_law(c, mu, xs)
    again, _, end = ref_sweep(lu[0], mu[0], lx[0, 1:, -1])
    scale = np.abs(lu).max()
    np.testing.assert_allclose(again, lx[0], rtol=0, atol=ATOL_LAW * scale)
    np.testing.assert_allclose(end, lx[0, 1:, -1], rtol=0, atol=ATOL_LAW * scale)


@pytest.mark.parametrize("d", [2, 3])
def test_node_sticking_all_period_keeps_its_anchor(d):
    """A node that sticks for the whole period keeps exactly the start state it was given
    (its stick anchor eps X_a): the mean tangential position of a stuck node is not decided by
    the periodic recursion. Several nodes with different anchors in one call, to check that
    the anchors are not mixed up. Exact equality: the kernel only copies the anchor."""
    nodes = []
    anchors = []
    for j in range(3):
        c, mu, xs = case((d, "stick"))
        nodes.append(c[0])
        anchors.append(xs[0] * (j + 1) * (-1) ** j)
    c = np.array(nodes)
    xs = np.array(anchors)
    mu = np.full(3, 0.3)
    lu, lx, state, sweeps = run_law(c, mu, xs)
    assert np.all(state == law.STICK)
    np.testing.assert_array_equal(lx[:, 1:, :], np.repeat(xs[:, :, None], NS, axis=2))
    np.testing.assert_array_equal(sweeps, 1)


def test_many_nodes_at_once_are_independent():
    """All cases of one dimension in a single call give the same result as one node at a time
    (no state leaks from one node to the next)."""
    for d in (2, 3):
        keys = [k for k in CASES if k[0] == d]
        c = np.concatenate([case(k)[0] for k in keys])
        mu = np.concatenate([case(k)[1] for k in keys])
        xs = np.concatenate([case(k)[2] for k in keys])
        lu, lx, state, _ = run_law(c, mu, xs)
        for i, k in enumerate(keys):
            _, lx1, st1, _ = run_law(*case(k))
            np.testing.assert_array_equal(lx[i], lx1[0])
            np.testing.assert_array_equal(state[i], st1[0])


def test_non_repeating_start_is_flagged():
    """With max_sweeps = 1 a 3D node whose start state needs several passes to repeat (the
    cone projection contracts the start state only geometrically) is flagged by
    ``sweeps > max_sweeps`` (kernel docstring)."""
    c, mu, xs = case((3, "wrap"))
    lu = np.ascontiguousarray(c @ Q_REF.T)
    _, _, sweeps = law.dlft_time(lu, mu, xs, TOL_LAW, 1)
    assert sweeps[0] > 1
    _, _, sweeps = law.dlft_time(lu, mu, xs, TOL_LAW, SWEEPS)
    assert 2 < sweeps[0] <= SWEEPS


# A 3D node slipping a little at both ends of a tangential load on a line (amplitude 0.302
# against mu pN = 0.3, 2 slip instants of 24), with a small load across it: plain passes
# contract its start state across the slip direction by ~0.97 per pass (951 passes to
# repeat within TOL_LAW; after the 200 that DLFTProblem allows by default it still changes by
# 4e-6 of the scale); the kernel's Newton step on the start state (contact._newton_start)
# reaches the same fixed point in 10.
SLOW_3D = ({(0, "0"): 1.0, (1, "c1"): 0.302, (2, "0"): 0.02, (2, "s1"): 0.01}, 0.3,
           [0.0, 0.1])


def slow_case():
    spec, mu, xs = SLOW_3D
    return coeffs(3, spec)[None], np.array([mu]), np.array([xs], dtype=float)


def test_slowly_contracting_start_state_reaches_the_periodic_state():
    """The SLOW_3D node: ``ref_law`` (plain passes in pure Python, eq. 24-28) needs more than
    200 passes for its start state to repeat; the kernel with its default-size budget (200)
    takes at most 12 and gives the reference's corrections and states (tolerance ATOL_LAW:
    rounding and the periodicity tolerance). Instants at least MIN_MARGIN from a switch."""
    c, mu, xs = slow_case()
    lu = np.ascontiguousarray(c @ Q_REF.T)
    lx, state, sweeps = law.dlft_time(lu, mu, xs, TOL_LAW, 200)
    start, passes = xs[0].copy(), 0
    while passes < 100000:
        passes += 1
        _, _, end = ref_sweep(lu[0], mu[0], start)
        if np.abs(end - start).max() <= TOL_LAW * np.abs(lu).max():
            break
        start = end
    assert passes > 200
    lx_ref, state_ref = ref_law(lu, mu, xs, max_sweeps=100000)
    assert margins(lu, lx_ref, mu).min() > MIN_MARGIN
    assert 0 < np.count_nonzero(state_ref == law.SLIP) < NS // 2
    np.testing.assert_array_equal(state, state_ref)
    np.testing.assert_allclose(lx, lx_ref, rtol=0, atol=ATOL_LAW * np.abs(lu).max())
    assert sweeps[0] <= 12


def test_pass_derivative_with_respect_to_start_state():
    """The derivative ``S = d end / d start`` of one pass that :func:`contact._sweep`
    returns (what the Newton step on the start state uses) against central differences of
    ``ref_sweep`` (step 1e-7 of the scale: the pass is smooth there, every instant
    MIN_MARGIN from a switch; tolerance 1e-6 of max |S|, as FD_RTOL), on the SLOW_3D node,
    the 3D wrap case and a pass through separation (S = 0)."""
    for c, mu, xs in (slow_case(), case((3, "wrap")), case((3, "mixed"))):
        lu = np.ascontiguousarray(c @ Q_REF.T)
        lx, _, _ = law.dlft_time(lu, mu, xs, TOL_LAW, SWEEPS)
        x0 = lx[0, 1:, -1] + np.array([0.003, -0.002])  # near the periodic state
        S = np.eye(2)
        law._sweep(lu[0], mu[0], x0.copy(), np.empty((3, NS)), np.empty(NS, np.int8),
                   np.full(NS, np.nan), S)
        h = 1e-7 * np.abs(lu).max()
        S_fd = np.zeros((2, 2))
        for j in range(2):
            e = np.zeros(2)
            e[j] = h
            S_fd[:, j] = (ref_sweep(lu[0], mu[0], x0 + e)[2]
                          - ref_sweep(lu[0], mu[0], x0 - e)[2]) / (2 * h)
        np.testing.assert_allclose(S, S_fd, rtol=0, atol=1e-6 * max(np.abs(S_fd).max(), 1.0))
        if np.any(law.dlft_time(lu, mu, xs, TOL_LAW, SWEEPS)[1] == law.SEPARATION):
            np.testing.assert_array_equal(S, 0.0)


# --------------------------------------------------------------------------------------------
# 2. the quasi-analytic Jacobian of the law against finite differences
# --------------------------------------------------------------------------------------------
def fd_jacobian(c, mu, xs):
    """Central differences of ``lambda_x~ = P lambda_x(Q lambda_u~)`` with respect to the real
    Fourier coefficients of lambda_u, for a single node, rows/columns ``comp*H + h``."""
    d, H = c.shape[1:]
    h = FD_STEP * np.abs(c @ Q_REF.T).max()
    G = np.zeros((d * H, d * H))
    for j in range(d * H):
        e = np.zeros(d * H)
        e[j] = h
        out = []
        for s in (1.0, -1.0):
            _, lx, _, _ = run_law(c + s * e.reshape(1, d, H), mu, xs)
            out.append((lx[0] @ P_REF.T).reshape(-1))
        G[:, j] = (out[0] - out[1]) / (2 * h)
    return G


@pytest.mark.parametrize("key", list(CASES), ids=[f"{d}D-{n}" for d, n in CASES])
def test_jacobian_matches_finite_differences(key):
    """dlft_jacobian vs central differences of the time law, one state pattern at a time
    (all separation, all stick, all slip, mixed stick-slip-separation, stick across the end of
    the period which carries the state of the previous period's last slip). Tolerance FD_RTOL
    relative to max |G| (see its comment); the margin of every instant from a switch is
    asserted first."""
    c, mu, xs = case(key)
    lu, lx, state, _ = run_law(c, mu, xs)
    assert margins(lu, lx, mu).min() > MIN_MARGIN
    G = law.dlft_jacobian(lu, lx, state, mu, P_REF, Q_REF)[0]
    G_fd = fd_jacobian(c, mu, xs)
    scale = max(np.abs(G_fd).max(), 1.0)
    np.testing.assert_allclose(G, G_fd, rtol=0, atol=FD_RTOL * scale)


@pytest.mark.parametrize("d", [2, 3])
def test_jacobian_closed_forms(d):
    """Derivatives known by hand. Separation all period: lambda_x = lambda_u, so G = I (the
    DFT of the inverse DFT). Stick all period: lambda_x,T = anchor, lambda_x,N = 0, so G = 0.
    2D slip at every instant: lambda_x,T(n) = lambda_u,T(n) - mu pN(n) s(n) (no memory), so
    G_TT = I, G_TN = -mu P diag(s) Q, G_N. = 0. Tolerance 1e-12: sums of N = 24 products of
    O(1) numbers."""
    H = 1 + 2 * len(HARM)
    c, mu, xs = case((d, "separation"))
    lu, lx, state, _ = run_law(c, mu, xs)
    G = law.dlft_jacobian(lu, lx, state, mu, P_REF, Q_REF)[0]
    np.testing.assert_allclose(G, np.eye(d * H), rtol=0, atol=1e-12)
    c, mu, xs = case((d, "stick"))
    lu, lx, state, _ = run_law(c, mu, xs)
    G = law.dlft_jacobian(lu, lx, state, mu, P_REF, Q_REF)[0]
    np.testing.assert_array_equal(G, 0.0)
    if d == 2:
        c, mu, xs = case((2, "slip"))
        lu, lx, state, _ = run_law(c, mu, xs)
        G = law.dlft_jacobian(lu, lx, state, mu, P_REF, Q_REF)[0]
        s = np.sign(lu[0, 1] - lx[0, 1])  # direction of lambda_T
        ref = np.zeros((2 * H, 2 * H))
        ref[H:, H:] = np.eye(H)
        ref[H:, :H] = -mu[0] * P_REF @ np.diag(s) @ Q_REF
        np.testing.assert_allclose(G, ref, rtol=0, atol=1e-12)


def test_jacobian_of_several_nodes_is_per_node():
    """All 2D (then 3D) cases in one call: each block equals the single-node Jacobian."""
    for d in (2, 3):
        keys = [k for k in CASES if k[0] == d]
        c = np.concatenate([case(k)[0] for k in keys])
        mu = np.concatenate([case(k)[1] for k in keys])
        xs = np.concatenate([case(k)[2] for k in keys])
        lu, lx, state, _ = run_law(c, mu, xs)
        G = law.dlft_jacobian(lu, lx, state, mu, P_REF, Q_REF)
        for i, k in enumerate(keys):
            lu1, lx1, st1, _ = run_law(*case(k))
            G1 = law.dlft_jacobian(lu1, lx1, st1, case(k)[1], P_REF, Q_REF)[0]
            np.testing.assert_allclose(G[i], G1, rtol=0, atol=1e-14)


# 3D nodes whose periodic orbit touches the cone without slipping (elastic shakedown: the
# node slips in the first pass from its anchor, then only reaches |pre_T| = mu pN with a zero
# slip increment). The periodic fixed point is then not isolated (any direction on the cone
# edge is a fixed point), the wrap-around system (I - S_T) seed = A0_T of dlft_jacobian is
# singular, and the result of dlft_time depends on the passes made from the anchor.
SHAKEDOWN = {
    # a tangential load oscillating on a line, offset outside the cone of the anchor
    "line-offset": ({(0, "0"): 1.0, (1, "0"): 0.5, (1, "c1"): 0.2, (2, "0"): 0.2,
                     (2, "c1"): 0.05}, 0.3, [0.0, 0.0]),
    # a tangential load with two harmonics and a varying normal load: slips over several
    # instants in the first pass, then touches the cone once per period
    "two-harmonics": ({(0, "0"): 1.0, (0, "c1"): 0.2, (1, "0"): -0.4, (1, "s1"): 0.12,
                       (1, "c2"): 0.03, (2, "0"): 0.35, (2, "c1"): 0.05, (2, "s2"): 0.02},
                      0.3, [0.05, 0.0]),
}


def shakedown_case(name):
    spec, mu, xs = SHAKEDOWN[name]
    return coeffs(3, spec)[None], np.array([mu]), np.array([xs], dtype=float)


@pytest.mark.parametrize("name", list(SHAKEDOWN))
def test_time_law_3d_shakedown_node(name):
    """The shakedown cases are what they claim and the time law handles them: the first pass
    from the anchor slips (every instant >= MIN_MARGIN from a switch, so that finite
    differences are valid), the periodic pass only touches the cone (zero slip increment,
    |pre_T| = mu pN to rounding), the node ends away from its anchor, and dlft_time agrees
    with the reference (tolerance ATOL_LAW)."""
    c, mu, xs = shakedown_case(name)
    lu, lx, state, _ = run_law(c, mu, xs)
    lx_ref, _ = ref_law(lu, mu, xs)
    np.testing.assert_allclose(lx, lx_ref, rtol=0, atol=ATOL_LAW * np.abs(lu).max())
    lx1, st1, _ = ref_sweep(lu[0], mu[0], xs[0])  # first pass from the anchor
    assert np.count_nonzero(st1 == law.SLIP) >= 1
    assert np.all(lu[0, 0] > MIN_MARGIN * np.abs(lu).max())  # always in contact
    pre1 = lu[0, 1:] - np.concatenate([xs[0][:, None], lx1[1:, :-1]], axis=1)
    gap1 = np.abs(np.linalg.norm(pre1, axis=0) - mu[0] * lu[0, 0])
    assert gap1.min() > MIN_MARGIN * np.abs(lu).max()
    assert np.abs(lx[0, 1:, 0] - xs[0]).max() > 0.1
    slip = state[0] == law.SLIP
    pre = lu[0, 1:] - np.roll(lx[0, 1:], 1, axis=1)
    np.testing.assert_allclose(np.linalg.norm(pre, axis=0)[slip], mu[0] * lu[0, 0][slip],
                               rtol=1e-12)  # touches: no slip increment


@pytest.mark.parametrize("name", list(SHAKEDOWN))
def test_jacobian_3d_shakedown_node(name):
    """dlft_jacobian vs central differences (as above, tolerance FD_RTOL) on the 3D shakedown
    nodes validated by test_time_law_3d_shakedown_node. Their periodic fixed point is not
    isolated (they touch the cone without slipping), so the start state depends on the passes
    made from the anchor, and the kernel differentiates those passes. Before that, the errors
    were O(1) (0.86 and 1.10 of max |G|); now ~1e-10."""
    c, mu, xs = shakedown_case(name)
    lu, lx, state, _ = run_law(c, mu, xs)
    G_fd = fd_jacobian(c, mu, xs)
    G = law.dlft_jacobian(lu, lx, state, mu, P_REF, Q_REF, xs, TOL_LAW, SWEEPS)[0]
    np.testing.assert_allclose(G, G_fd, rtol=0, atol=FD_RTOL * max(np.abs(G_fd).max(), 1.0))


def test_jacobian_of_slowly_contracting_node():
    """dlft_jacobian vs central differences of the time law (tolerance FD_RTOL, as above) on
    the SLOW_3D node, whose periodic state the kernel now reaches by Newton's step on the
    start state: the Jacobian (the derivative of the periodic fixed point, wrap-around seed
    solved exactly) is that of the law the residual evaluates, with the 200 passes that
    DLFTProblem allows by default. Before, the kernel stopped after those 200 plain passes
    short of the fixed point, and the two disagreed (by ~0.97^200 = 2e-3 of the start
    state's sensitivity: above FD_RTOL)."""
    c, mu, xs = slow_case()
    d, H = c.shape[1:]

    def law_coeffs(cc):
        lu = np.ascontiguousarray(cc @ Q_REF.T)
        lx, state, _ = law.dlft_time(lu, mu, xs, TOL_LAW, 200)
        return lu, lx, state

    lu, lx, state = law_coeffs(c)
    assert margins(lu, lx, mu).min() > MIN_MARGIN
    G = law.dlft_jacobian(lu, lx, state, mu, P_REF, Q_REF, xs, TOL_LAW, 200)[0]
    h = FD_STEP * np.abs(lu).max()
    G_fd = np.zeros((d * H, d * H))
    for j in range(d * H):
        e = np.zeros(d * H)
        e[j] = h
        plus = law_coeffs(c + e.reshape(1, d, H))[1][0] @ P_REF.T
        minus = law_coeffs(c - e.reshape(1, d, H))[1][0] @ P_REF.T
        G_fd[:, j] = (plus - minus).reshape(-1) / (2 * h)
    np.testing.assert_allclose(G, G_fd, rtol=0, atol=FD_RTOL * max(np.abs(G_fd).max(), 1.0))


def test_jacobian_3d_static_slip():
    """One instant per period (N = 1, the static problem solved by hbm.static_anchor): a 3D
    node pressed with pN = 1 and a tangential prediction (0.5, 0.2) outside the cone
    (mu = 0.3) from its anchor 0 slips onto the cone along (0.5, 0.2). The exact derivative of
    this return mapping is d lambda_x,T = (I - g (I - t t^T)) d lambda_u,T - mu t dpN with
    g = mu pN / |lambda_u,T - anchor| < 1, t the unit slip direction (closed form, tol 1e-12)."""
    lu = np.array([[[1.0], [0.5], [0.2]]])
    mu = np.array([0.3])
    xs = np.zeros((1, 2))
    lx, state, _ = law.dlft_time(lu, mu, xs, TOL_LAW, SWEEPS)
    ut = lu[0, 1:, 0]
    t = ut / np.linalg.norm(ut)
    g = mu[0] * lu[0, 0, 0] / np.linalg.norm(ut)
    np.testing.assert_allclose(lx[0, 1:, 0], ut - mu[0] * lu[0, 0, 0] * t, rtol=1e-14)
    ref = np.zeros((3, 3))
    ref[1:, 1:] = np.eye(2) - g * (np.eye(2) - np.outer(t, t))
    ref[1:, 0] = -mu[0] * t
    G = law.dlft_jacobian(lu, lx, state, mu, np.ones((1, 1)), np.ones((1, 1)))[0]
    np.testing.assert_allclose(G, ref, rtol=0, atol=1e-12)


# --------------------------------------------------------------------------------------------
# 3. friction under a prescribed normal load N(t) (no normal DOF in the law)
# --------------------------------------------------------------------------------------------
def ref_sweep_prescribed(lu, mu, xprev, nfix):
    """One pass of the tangential law with the threshold ``mu N(n)`` of a prescribed normal
    force ``nfix`` (N,), written independently of the kernel: ``lambda_N = N(n)`` always;
    ``N(n) <= 0`` frees the tangential force (``lambda_T = 0``); otherwise stick/slip as eq.
    27-28 with ``pre_N`` replaced by ``N(n)``. Returns (lx, state, end)."""
    d, n_t = lu.shape
    lx = np.zeros((d, n_t))
    state = np.zeros(n_t, dtype=int)
    xp = np.array(xprev, dtype=float)
    for n in range(n_t):
        lx[0, n] = lu[0, n] - nfix[n]
        pre_t = lu[1:, n] - xp
        if nfix[n] <= 0.0:
            lx[1:, n] = lu[1:, n]
            state[n] = law.SEPARATION
        elif np.linalg.norm(pre_t) < mu * nfix[n]:
            lx[1:, n] = xp
            state[n] = law.STICK
        else:
            lx[1:, n] = xp + pre_t * (1.0 - mu * nfix[n] / np.linalg.norm(pre_t))
            state[n] = law.SLIP
        xp = lx[1:, n].copy()
    return lx, state, xp


TAU = 2.0 * np.pi * np.arange(NS) / NS
# prescribed normal forces: constant, periodic and positive, periodic and lifting off
NFIX = {"constant": np.full(NS, 1.0), "periodic": 1.0 + 0.5 * np.cos(TAU + 0.3),
        "lift-off": 0.4 + np.cos(TAU + 0.3)}
# tangential lambda_u that slips (amplitude > mu N) and sticks near its turning points; the
# normal component of lambda_u is arbitrary (it does not enter the law)
LU_T = {2: {(0, "0"): 0.7, (0, "s1"): 0.3, (1, "c1"): 0.9, (1, "s2"): 0.1},
        3: {(0, "0"): 0.7, (0, "s1"): 0.3, (1, "c1"): 0.9, (1, "s2"): 0.1, (2, "c1"): 0.3,
            (2, "s2"): 0.05}}


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("load", list(NFIX))
def test_prescribed_normal_law_and_jacobian(d, load):
    """dlft_time with a prescribed normal force vs ``ref_sweep_prescribed`` (made periodic by
    repeated passes): same corrections (tolerance ATOL_LAW: rounding only) and
    ``lambda_N = N(t)`` exactly at every instant; then dlft_jacobian vs central differences of
    the time law (tolerance FD_RTOL, see its comment; margins from the switches asserted
    first). A Jacobian that kept the ``- mu t e_N`` term of the unilateral law, or dropped the
    identity on the normal component, is off by O(mu) = 0.3."""
    c = coeffs(d, LU_T[d])[None]
    mu = np.array([0.3])
    xs = np.zeros((1, d - 1))
    nfix = NFIX[load][None]
    lu = np.ascontiguousarray(c @ Q_REF.T)
    lx, state, _ = law.dlft_time(lu, mu, xs, TOL_LAW, SWEEPS, nfix)
    start = xs[0].copy()
    for _ in range(SWEEPS):
        lx_ref, st_ref, end = ref_sweep_prescribed(lu[0], 0.3, start, nfix[0])
        done = np.abs(end - start).max() <= TOL_LAW * np.abs(lu).max()
        start = end
        if done:
            break
    scale = np.abs(lu).max()
    np.testing.assert_array_equal(state[0], st_ref)
    assert {law.STICK, law.SLIP} <= set(st_ref.tolist())  # both regimes visited
    if load == "lift-off":
        assert law.SEPARATION in st_ref
    np.testing.assert_allclose(lx[0], lx_ref, rtol=0, atol=ATOL_LAW * scale)
    np.testing.assert_allclose((lu - lx)[0, 0], nfix[0], rtol=0, atol=ATOL_LAW * scale)
    # margins from the stick/slip threshold mu N and from N = 0
    pre = lu[0, 1:] - np.roll(lx[0, 1:], 1, axis=1)
    marg = np.where(nfix[0] <= 0, -nfix[0],
                    np.abs(np.linalg.norm(pre, axis=0) - 0.3 * nfix[0]))
    assert marg.min() / scale > MIN_MARGIN
    G = law.dlft_jacobian(lu, lx, state, mu, P_REF, Q_REF, xs, TOL_LAW, SWEEPS, nfix)[0]
    H = c.shape[2]
    h = FD_STEP * scale
    G_fd = np.zeros((d * H, d * H))
    for j in range(d * H):
        e = np.zeros(d * H)
        e[j] = h
        out = []
        for s in (1.0, -1.0):
            lu_s = np.ascontiguousarray((c + s * e.reshape(1, d, H)) @ Q_REF.T)
            lx_s, _, _ = law.dlft_time(lu_s, mu, xs, TOL_LAW, SWEEPS, nfix)
            out.append((lx_s[0] @ P_REF.T).reshape(-1))
        G_fd[:, j] = (out[0] - out[1]) / (2 * h)
    np.testing.assert_allclose(G, G_fd, rtol=0, atol=FD_RTOL * max(np.abs(G_fd).max(), 1.0))
