"""Validation of the DLFT contact law in time (paper eq. 24-28) and of its Jacobian.

Code under test: :func:`fretwear.hb.contact.dlft_time`, :func:`fretwear.hb.contact.dlft_jacobian`
and :meth:`fretwear.hb.periodic.DLFTProblem.residual`.

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
import scipy.sparse as sp

from fretwear.hb import contact as law
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.periodic import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.model.core import ContactInterface, Load, Model

HARM = (1, 2, 3)
NS = 24  # samples per period (> 2 * 3)
TOL_LAW = 1e-14  # periodicity tolerance passed to both implementations
SWEEPS = 2000
# Two implementations of the same recursion differ by rounding only (~1e-16 per operation,
# amplified by at most a few hundred operations per instant): 1e-10 of the signal scale is a
# wide margin, while any wrong branch or sign gives errors of order mu * pN ~ 0.1 of the scale.
ATOL_LAW = 1e-10
# Central differences with h = 1e-6 x scale: truncation ~ h^2 |f'''| ~ 1e-12 (the map is
# smooth between switches; every instant is >= MIN_MARGIN from a switch), rounding
# ~ 1e-16 / 1e-6 = 1e-10 relative, plus the periodicity tolerance 1e-14 / 1e-6 = 1e-8 in 3D.
# A missing term of the Jacobian (wrap-around seed, cone projection, mu t dpN, ...) gives
# errors of order 1e-2..1, so 1e-6 is discriminating with a 100x margin on the noise.
FD_STEP = 1e-6
FD_RTOL = 1e-6
MIN_MARGIN = 1e-3  # relative distance to a switch; >> FD_STEP x (sum of |G| entries ~ 10)


# --------------------------------------------------------------------------------------------
# independent references
# --------------------------------------------------------------------------------------------
def trig_matrices(harmonics, n):
    """``P`` (H, N) and ``Q`` (N, H) of the real basis, by direct evaluation of cos/sin."""
    tau = 2.0 * np.pi * np.arange(n) / n
    h = np.asarray(harmonics, dtype=float)
    q = np.hstack([np.ones((n, 1)), np.cos(np.outer(tau, h)), np.sin(np.outer(tau, h))])
    p = q.T * (2.0 / n)
    p[0] *= 0.5
    return p, q


P_REF, Q_REF = trig_matrices(HARM, NS)


def ref_sweep(lu, mu, xprev):
    """One pass of eq. 24-28 over a period for one node. ``lu`` (d, N); ``xprev`` the
    tangential correction lambda_x,T before the first instant. Returns (lx, state, end)."""
    d, n_t = lu.shape
    lx = np.zeros((d, n_t))
    state = np.zeros(n_t, dtype=int)
    xp = np.array(xprev, dtype=float)
    for n in range(n_t):
        pre_n = lu[0, n]  # eq. 24, normal
        pre_t = lu[1:, n] - xp  # eq. 24, tangential
        if pre_n <= 0.0:  # separation (paper: pre_N >= 0 with its opposite sign)
            lx[:, n] = lu[:, n]  # eq. 26
            state[n] = law.SEPARATION
        elif np.linalg.norm(pre_t) < mu * pre_n:  # stick
            lx[0, n] = 0.0  # eq. 27
            lx[1:, n] = xp
            state[n] = law.STICK
        else:  # slip
            lx[0, n] = 0.0  # eq. 28
            lx[1:, n] = xp + pre_t * (1.0 - mu * pre_n / np.linalg.norm(pre_t))
            state[n] = law.SLIP
        xp = lx[1:, n].copy()
    return lx, state, xp


def ref_law(lu, mu, x_start, tol=TOL_LAW, max_sweeps=SWEEPS):
    """Periodic solution of the recursion for every node: sweep the period, each pass starting
    where the previous one ended, until the start state repeats."""
    nc, d, n_t = lu.shape
    lx = np.zeros_like(lu)
    state = np.zeros((nc, n_t), dtype=int)
    for p in range(nc):
        start = np.array(x_start[p], dtype=float)
        thr = tol * np.abs(lu[p]).max()
        for _ in range(max_sweeps):
            lx[p], state[p], end = ref_sweep(lu[p], mu[p], start)
            done = np.abs(end - start).max() <= thr
            start = end
            if done:
                break
    return lx, state


def margins(lu, lx, mu):
    """Smallest distance of any instant from a switching threshold, relative to the node's
    scale: ``|pN|`` (separation/contact) and ``| |pre_T| - mu pN |`` (stick/slip)."""
    out = []
    for p in range(lu.shape[0]):
        pn = lu[p, 0]
        pre = lu[p, 1:] - np.roll(lx[p, 1:], 1, axis=1)
        m = np.where(pn <= 0.0, -pn,
                     np.minimum(pn, np.abs(np.linalg.norm(pre, axis=0) - mu[p] * pn)))
        out.append(m.min() / np.abs(lu[p]).max())
    return np.array(out)


def coeffs(d, spec):
    """Real Fourier coefficients (d, H) from {(component, "0" | "cH" | "sH"): value}."""
    k = len(HARM)
    c = np.zeros((d, 1 + 2 * k))
    for (comp, term), v in spec.items():
        if term == "0":
            c[comp, 0] = v
        else:
            i = HARM.index(int(term[1:]))
            c[comp, 1 + i if term[0] == "c" else 1 + k + i] = v
    return c


PH = 0.8  # phase putting the maximum of cos(tau + PH) near the end of the period
# name -> (coefficients, mu, stick anchor x_start); expected state pattern in the comment
# ("-" separation, "|" stick, "/" slip; 24 instants).
CASES = {
    # ------------------------
    (2, "separation"): ({(0, "0"): -1.0, (0, "c1"): 0.3, (1, "0"): 0.2, (1, "s1"): 0.5},
                        0.3, [0.1]),
    # ||||||||||||||||||||||||
    (2, "stick"): ({(0, "0"): 2.0, (0, "c1"): 0.2, (1, "s1"): 0.1, (1, "c2"): 0.05},
                   0.3, [0.05]),
    # //////////////////////// (a sample-to-sample drop > 2 mu pN reverses the slip)
    (2, "slip"): ({(0, "0"): 1.0, (0, "c1"): 0.2, (1, "s1"): 20.0, (1, "c3"): 2.0},
                  0.3, [0.0]),
    # /////////-------//||||||
    (2, "mixed"): ({(0, "0"): 1.0, (0, "c1"): 1.5, (1, "s1"): 0.8, (1, "c2"): 0.2},
                   0.3, [0.0]),
    # ||////////||||////////|| (stick across the end of the period)
    (2, "wrap"): ({(0, "0"): 1.0, (0, "s2"): 0.1, (1, "c1"): np.cos(PH),
                   (1, "s1"): -np.sin(PH)}, 0.3, [0.0]),
    (3, "separation"): ({(0, "0"): -1.0, (0, "c1"): 0.3, (1, "0"): 0.2, (1, "s1"): 0.5,
                         (2, "c2"): 0.3}, 0.3, [0.1, -0.1]),
    (3, "stick"): ({(0, "0"): 2.0, (0, "c1"): 0.2, (1, "s1"): 0.1, (2, "c2"): 0.05},
                   0.3, [0.05, -0.02]),
    # //////////////////////// (the tangential prediction turns on a circle)
    (3, "slip"): ({(0, "0"): 1.0, (0, "c2"): 0.2, (1, "c1"): 2.0, (2, "s1"): 2.0},
                  0.3, [0.0, 0.0]),
    # /////////-------/|||||||
    (3, "mixed"): ({(0, "0"): 1.0, (0, "c1"): 1.5, (1, "s1"): 0.8, (2, "c1"): 0.5,
                    (2, "s2"): 0.3}, 0.3, [0.0, 0.0]),
    # ||////////||||////////||
    (3, "wrap"): ({(0, "0"): 1.0, (0, "s2"): 0.1, (1, "c1"): 0.8 * np.cos(PH),
                   (1, "s1"): -0.8 * np.sin(PH), (2, "c1"): 0.6 * np.cos(PH),
                   (2, "s1"): -0.6 * np.sin(PH), (2, "c2"): 0.05}, 0.3, [0.0, 0.0]),
}
EXPECTED = {
    "separation": "-" * 24,
    "stick": "|" * 24,
    "slip": "/" * 24,
    "mixed": {2: "/////////-------//||||||", 3: "/////////-------/|||||||"},
    "wrap": "||////////||||////////||",
}


def case(key):
    spec, mu, xs = CASES[key]
    c = coeffs(key[0], spec)[None]  # (1, d, H)
    return c, np.array([mu]), np.array([xs], dtype=float)


def run_law(c, mu, xs):
    lu = np.ascontiguousarray(c @ Q_REF.T)
    lx, state, sweeps = law.dlft_time(lu, mu, xs, TOL_LAW, SWEEPS)
    return lu, lx, state, sweeps


def pattern(state):
    return "".join("-|/"[s] for s in state)


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
# 3. the DLFT residual and its full Jacobian on hand-built models
# --------------------------------------------------------------------------------------------
def chain_model(d, nc):
    """``nc`` contact nodes (d DOFs each, frames rotated so that no axis is special) tied by
    springs to each other and, through an interior mass, to ground; viscous and hysteretic
    damping so that every harmonic block of Z_r is complex and non-symmetric in real form."""
    rng = np.random.default_rng(3)
    nd = nc * d + d  # contact DOFs then d interior DOFs
    A = rng.standard_normal((nd, nd))
    K = A @ A.T + nd * np.eye(nd)
    M = np.diag(rng.uniform(0.5, 1.5, nd))
    C = 0.01 * K
    D = 0.02 * K
    frames = []
    for _ in range(nc):
        q, _ = np.linalg.qr(rng.standard_normal((d, d)))
        frames.append(q)
    contact = ContactInterface(
        dofs=np.arange(nc * d).reshape(nc, d), frame=np.array(frames), gap=np.zeros(nc),
        area=np.ones(nc), mu=0.3, coords=np.zeros((nc, d)))
    F = np.zeros(nd)
    F[:nc * d] = 1.0
    model = Model(K=sp.csr_matrix(K), M=sp.csr_matrix(M), C=sp.csr_matrix(C),
                  D=sp.csr_matrix(D), contact=contact,
                  loads=[Load(F, "constant"), Load(0.5 * F, "cos"), Load(0.2 * F, "sin")],
                  dim=d)
    return model


def real_blocks(Zc, k):
    """Real operator on [a0, a_h.., b_h..] per DOF from complex blocks, written from
    ``u = Re(U e^{i h tau})`` with U = a - i b (independent of reduce.to_real_blocks)."""
    m = Zc.shape[1]
    H = 1 + 2 * k
    out = np.zeros((m, H, m, H))
    out[:, 0, :, 0] = Zc[0].real
    for i in range(1, k + 1):
        # Z (a - i b) = (Zr a + Zi b) - i (Zr b - Zi a):  new a = Zr a + Zi b, new b = Zr b - Zi a
        zr, zi = Zc[i].real, Zc[i].imag
        out[:, i, :, i] = zr
        out[:, i, :, k + i] = zi
        out[:, k + i, :, i] = -zi
        out[:, k + i, :, k + i] = zr
    return out.reshape(m * H, m * H)


def problem_at(d, keys, frequency=3.0 / (2 * np.pi)):
    """A DLFTProblem on ``chain_model`` and a point U at which lambda_u of node p equals the
    test signal ``keys[p]`` (U from (eps I - Z) U = lambda_u - F + eps W, eps = 2 x spectral
    radius so that eps I - Z is invertible)."""
    nc = len(keys)
    model = chain_model(d, nc)
    basis = FourierBasis(HARM, NS)
    red = condense(model, frequency, [0, *HARM])
    eps = 2.0 * red.spectral_radius()
    scale = 1e3  # forces of order 1e3 N
    anchors = np.array([case(k)[2][0] for k in keys]) * scale / eps  # eps X_a = x_start
    prob = DLFTProblem(red, model.contact, basis, eps=eps, anchor=anchors,
                       periodicity_tol=TOL_LAW, max_sweeps=SWEEPS)
    target = scale * np.concatenate([case(k)[0][0] for k in keys])  # (nc*d, H): lambda_u
    n = prob.m * prob.H
    Z = real_blocks(red.Z, len(HARM))
    F = np.hstack([red.F[0].real[:, None], red.F[1:].real.T, -red.F[1:].imag.T])
    rhs = (target - F + eps * prob.W).reshape(-1)
    U = np.linalg.solve(eps * np.eye(n) - Z, rhs).reshape(prob.m, prob.H)
    return prob, U, Z, F, target


@pytest.mark.parametrize("d, keys", [
    (2, [(2, "mixed"), (2, "wrap"), (2, "slip"), (2, "stick"), (2, "separation")]),
    (3, [(3, "mixed"), (3, "wrap"), (3, "slip"), (3, "stick"), (3, "separation")]),
], ids=["2D", "3D"])
def test_residual_matches_reference(d, keys):
    """DLFTProblem.residual vs an independent assembly: lambda_u~ = F~ - Z U~ + eps (U~ - W~)
    from the complex reduced blocks through ``real_blocks`` (own real form), lambda_u in time
    with ``trig_matrices``, lambda_x by ``ref_law``, f = eps (U~ - W~) - P lambda_x (eq. 22).
    Tolerance 1e-10 of eps |U|: rounding of dense products of size ~ 100."""
    prob, U, Z, F, target = problem_at(d, keys)
    lu = (F - (Z @ U.reshape(-1)).reshape(prob.m, prob.H) + prob.eps * (U - prob.W))
    np.testing.assert_allclose(lu, target, rtol=0, atol=1e-9 * np.abs(target).max())
    lu_t = (lu @ Q_REF.T).reshape(prob.nc, d, NS)
    lx_ref, state_ref = ref_law(lu_t, prob.mu, prob.eps * prob.anchor)
    f_ref = prob.eps * (U - prob.W) - (lx_ref.reshape(prob.m, NS) @ P_REF.T)
    f, _ = prob.residual(U, jacobian=False)
    np.testing.assert_allclose(f, f_ref.reshape(-1), rtol=0,
                               atol=1e-10 * prob.eps * np.abs(U).max())
    _, _, state, _ = prob.time_law(U)
    np.testing.assert_array_equal(state, state_ref)


@pytest.mark.parametrize("d, keys", [
    (2, [(2, "mixed"), (2, "wrap"), (2, "slip"), (2, "stick"), (2, "separation")]),
    (3, [(3, "mixed"), (3, "wrap"), (3, "slip"), (3, "stick"), (3, "separation")]),
], ids=["2D", "3D"])
def test_residual_jacobian_matches_finite_differences(d, keys):
    """Full Jacobian ``J = eps I - G (eps I - Z)`` of DLFTProblem.residual vs central
    differences in U (step 1e-6 x max |U|), on coupled nodes in all state patterns (the
    coupling through Z mixes the nodes, so an error in the ordering of G's rows/columns or in
    the chain rule shows). Tolerance FD_RTOL relative to eps (the size of J's entries)."""
    prob, U, _, _, _ = problem_at(d, keys)
    lu, lx, _, _ = prob.time_law(U)
    assert margins(lu, lx, prob.mu).min() > MIN_MARGIN
    f0, J = prob.residual(U)
    h = FD_STEP * np.abs(U).max()
    n = U.size
    J_fd = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        fp, _ = prob.residual(U + e.reshape(U.shape), jacobian=False)
        fm, _ = prob.residual(U - e.reshape(U.shape), jacobian=False)
        J_fd[:, j] = (fp - fm) / (2 * h)
    np.testing.assert_allclose(J, J_fd, rtol=0, atol=FD_RTOL * prob.eps)
    # the nonlinear part is not negligible: the test would see an error in G
    assert np.abs(J - prob.eps * np.eye(n)).max() > 0.1 * prob.eps


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
