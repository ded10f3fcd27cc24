"""The independent references of the DLFT contact law used by tests/hb/test_contact.py (the
law and its Jacobian) and tests/hb/test_problem.py (the DLFT residual): a direct pure-Python
transcription of the paper's prediction / correction (eq. 24-28), the real Fourier basis by
direct evaluation of cos/sin, and test signals that visit the three contact states in known
patterns (see the docstring of tests/hb/test_contact.py for what each reference is and why
its tolerance is what it is). None of them calls the code under test except ``run_law``.
"""

import numpy as np

from fretwear.hb import contact as law

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

