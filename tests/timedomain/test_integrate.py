"""Tests of the time-domain reference solvers (:mod:`fretwear.timedomain.integrate`).

Every test compares with something independent of the code under test (a closed-form
solution, an event-driven integration written here with ``scipy.integrate.solve_ivp``, a
direct sparse solve, an energy identity with its terms computed independently, or synthetic
sequences with a known answer) and says why its tolerance is what it is.

The models are built by hand from scipy.sparse matrices and ``fretwear.model.core`` objects.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from helpers.models import chain
from helpers.oscillators import event_driven, hz, slider
from helpers.pads import F_PAD, MU_PAD, P_PAD, dlft_friction_energy, pad_3d

from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.solution import initial_state
from fretwear.model.core import ContactInterface, Load, Model, ObservedPoint
from fretwear.timedomain import integrate as tr
from fretwear.timedomain import quasistatic, steady
from fretwear.timedomain.options import (
    IncrementalWearOptions,
    InitialState,
    IntegrationOptions,
)


# --------------------------------------------------------------------------------------------
# models
# --------------------------------------------------------------------------------------------
def slider3d(*, m=1.0, k=1.0, N=1.0, F0=1.0, mu=0.3):
    """3D node: normal DOF 0 pressed by N, tangential DOFs 1, 2 with isotropic spring k and a
    rotating force ``F0 (cos wt, sin wt)``."""
    K = sp.csr_matrix(np.diag([0.0, k, k]))
    M = sp.csr_matrix(np.diag([1.0, m, m]))
    contact = ContactInterface(dofs=np.array([[0, 1, 2]]), frame=np.eye(3)[None],
                               gap=np.zeros(1), area=np.ones(1), mu=mu, coords=np.zeros((1, 3)))
    loads = [Load(np.array([N, 0.0, 0.0]), "constant"), Load(np.array([0.0, F0, 0.0]), "cos"),
             Load(np.array([0.0, 0.0, F0]), "sin")]
    return Model(K=K, M=M, contact=contact, loads=loads, dim=3,
                 observed=[ObservedPoint("x", np.array([1, 2]), np.zeros(3))])


# --------------------------------------------------------------------------------------------
# references
# --------------------------------------------------------------------------------------------
def den_hartog(t, *, m, k, Ff, F0, w):
    """Den Hartog's (1931) exact continuous-slip steady state of
    ``m x'' + k x + Ff sgn(x') = F0 cos(w t)``.

    Derivation: let t' = 0 be a reversal at x = -X with x' = 0, and write the forcing
    ``F0 cos(w t' + phi)``. On the half period 0 < t' < T/2 (x' > 0)
    ``x = -Ff/k + P cos(w t' + phi) + C1 cos(w0 t') + C2 sin(w0 t')`` with
    ``P = F0 / (k (1 - r^2))``, ``r = w / w0``. Symmetry requires ``x(T/2) = X``,
    ``x'(T/2) = 0``; with ``theta = pi / r`` the four conditions give ``C2 = P r sin(phi)``,
    ``C1 = Ff / k = P r sin(phi) cot(theta/2)``, ``X = -P cos(phi)``, hence
    ``sin(phi) = (Ff/F0) (1 - r^2) tan(theta/2) / r`` and
    ``X = (F0/k) sqrt(1/(1 - r^2)^2 - (Ff/F0)^2 U^2)``, ``U = tan(pi/(2r)) / r``
    (Den Hartog's U = sin(pi/r) / (r (1 + cos(pi/r)))). The second half period is ``-x``.

    Returns x(t), x'(t) and X.
    """
    w0 = np.sqrt(k / m)
    r = w / w0
    P = F0 / (k * (1 - r * r))
    s = Ff * (1 - r * r) * np.tan(np.pi / (2 * r)) / (F0 * r)
    phi = np.pi - np.arcsin(s) if P > 0 else np.arcsin(s)
    X = -P * np.cos(phi)
    T = 2 * np.pi / w

    def half(tp):
        return (-Ff / k + P * np.cos(w * tp + phi) + Ff / k * np.cos(w0 * tp)
                + P * r * np.sin(phi) * np.sin(w0 * tp))

    def half_v(tp):
        return (-P * w * np.sin(w * tp + phi) - Ff / k * w0 * np.sin(w0 * tp)
                + P * r * np.sin(phi) * w0 * np.cos(w0 * tp))

    tp = np.mod(np.asarray(t) - phi / w, T)
    second = tp >= T / 2
    x = np.where(second, -half(tp - T / 2), half(tp))
    v = np.where(second, -half_v(tp - T / 2), half_v(tp))
    return x, v, X


# --------------------------------------------------------------------------------------------
# the 1-DOF friction oscillator
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("r", [0.7, 1.5])
def test_den_hartog_continuous_slip(r):
    """Steady state from rest vs Den Hartog's exact continuous-slip solution.

    Tolerance: in continuous slip the friction force jumps by 2 Ff at each velocity reversal;
    an event-capturing fixed-step scheme places the jump within one step h, so each reversal
    carries an impulse error up to 2 Ff h, i.e. a velocity error 2 Ff h / m and a displacement
    error ~ 2 Ff h / (m w). Allowing two such errors: ``4 Ff h / (m w X)`` relative to X
    (first order in h; measured 1.2e-3 and 2.2e-3 against 8.0e-3 and 4.5e-3).
    """
    m = k = F0 = 1.0
    Ff = 0.3
    w = r
    N = 1024
    model = slider(mu=Ff, N=1.0)
    res = tr.integrate(model, hz(w), options=IntegrationOptions(steps_per_period=N), n_periods=200)
    xa, va, X = den_hartog(res.t, m=m, k=k, Ff=Ff, F0=F0, w=w)
    # the analytic solution has no stops: the velocity changes sign twice per period only
    tt = np.linspace(0, 2 * np.pi / w, 4001)[:-1]
    _, vv, _ = den_hartog(tt, m=m, k=k, Ff=Ff, F0=F0, w=w)
    assert np.count_nonzero(np.diff(np.sign(vv)) != 0) <= 2
    h = 2 * np.pi / (w * N)
    tol = 4 * Ff * h / (m * w * X)
    x = res.observed["x"][:, 0]
    assert np.max(np.abs(x - xa)) / X < tol
    # friction dissipation per period: Ff times the sliding distance 4 X (same bound)
    assert abs(res.energy["friction"][-1] / (4 * Ff * X) - 1) < tol
    # the normal DOF stays pressed with lam_N = N exactly (constant load, closed contact)
    np.testing.assert_allclose(res.lam[:, 0, 0], 1.0, rtol=1e-12)
    assert np.all(res.state[:, 0] > 0)


@pytest.mark.parametrize("Ff", [0.5, 0.7])
def test_stick_slip_with_stops_vs_event_driven(Ff):
    """Oscillator that stops twice per period vs an event-driven solve_ivp integration.

    Tolerance: at a stop (slip -> stick) the velocity is continuous and at a start (stick ->
    slip) the force is continuous, so an event placed up to one step h late or early gives a
    local error ``a h^2 / 2`` with ``|a| <= (F0 + Ff + k max|x|) / m``; relative to the
    amplitude this is the bound used (measured errors are 10 times smaller).
    """
    m = k = F0 = 1.0
    w = 0.5
    N = 1024
    n = 25
    T = 2 * np.pi / w
    h = T / N
    res = tr.integrate(slider(mu=Ff), hz(w), options=IntegrationOptions(steps_per_period=N),
                       n_periods=n)
    ref, sticks = event_driven(m=m, k=k, Ff=Ff, F0=F0, w=w, t_end=n * T + 1e-9, t_eval=res.t)
    last = [s for s in sticks if s[0] > (n - 1) * T]
    assert len(last) == 2  # two stops per period: a genuine stick-slip case
    amp = 0.5 * (ref.max() - ref.min())
    a_max = (F0 + Ff + k * np.abs(ref).max()) / m
    err = np.max(np.abs(res.observed["x"][:, 0] - ref)) / amp
    assert err < a_max * h * h / (2 * amp)
    # the scheme reports stick steps where the reference sticks
    stuck = np.zeros(res.t.size, dtype=bool)
    for a, b in last:
        stuck |= (res.t > a + h) & (res.t < b - h)
    assert np.all(res.state[stuck, 0] == 1)


def test_3d_rotating_force_circular_slip():
    """3D node under a rotating tangential force: exact steady state is a circle of radius
    ``X = sqrt(F0^2 - mu^2 N^2) / |k - m w^2|`` slipping at constant speed.

    Tolerance: the friction force at t_n takes the direction of the slip over the next step
    (direction of the velocity at t_n + h/2), a lag of ``delta = w h / 2``; the steady
    radius then satisfies ``(k - m w^2) X = sqrt(F0^2 - mu^2 N^2 cos^2 d) + mu N sin d``, an
    error ``mu N delta / sqrt(F0^2 - mu^2 N^2)`` (first order). We check the error against
    1.5 times this estimate and that halving h halves the error.
    """
    mu, w, N, F0, k, m = 0.3, 0.7, 1.0, 1.0, 1.0, 1.0
    X = np.sqrt(F0**2 - (mu * N) ** 2) / abs(k - m * w * w)
    errs = []
    for steps in (128, 256):
        res = tr.integrate(slider3d(mu=mu), hz(w),
                           options=IntegrationOptions(steps_per_period=steps), n_periods=150)
        rad = np.hypot(*res.observed["x"].T)
        err = np.max(np.abs(rad / X - 1))
        lag = mu * N * (w * 2 * np.pi / (w * steps) / 2) / np.sqrt(F0**2 - (mu * N) ** 2)
        assert err < 1.5 * lag
        assert np.all(res.state[:, 0] == 2)  # slips all the time
        # friction dissipation per period: mu N times the circumference 2 pi X
        assert abs(res.energy["friction"][-1] / (mu * N * 2 * np.pi * X) - 1) < lag
        errs.append(err)
    assert 0.4 < errs[1] / errs[0] < 0.6


def check_cone(res, mu, tol=1e-9):
    """Coulomb's law on the isotropic cone at every recorded step, checked on the recorded
    forces and positions: no tension, inside the cone, on it when slipping, no motion at all
    when sticking; the slip of each step points along its force to 5e-5 rad (cosine
    1 - 1e-9: the contact solve meets its force tolerance ``tol fs``, which fixes the
    direction of a slip ``xi`` only to ``~ tol fs / (k_T |xi|)``; the pad's slips per step are
    down to 1e-5 of ``fs / k_T``; measured angles below 1e-7 rad); and the friction work
    equals mu times the slip work to 1e-9 (Archard's and Coulomb's laws together)."""
    lam, x, st = res.lam, res.u_loc, res.state[:-1]
    fs = np.abs(lam).max()
    ln, lt = lam[:-1, :, 0], lam[:-1, :, 1:]
    xi = np.diff(x[:, :, 1:], axis=0)  # slip over the step of each force
    assert np.all(ln >= -tol * fs)
    nlt = np.linalg.norm(lt, axis=-1)
    assert np.all(nlt <= mu * ln + tol * fs)
    assert np.all(xi[st == 1] == 0.0)
    slip = st == 2
    nxi = np.linalg.norm(xi[slip], axis=-1)
    np.testing.assert_allclose(nlt[slip], mu * ln[slip], rtol=0, atol=tol * fs)
    cos = np.sum(lt[slip] * xi[slip], axis=-1) / (nlt[slip] * nxi)
    assert np.all(cos >= 1.0 - 1e-9)
    work = np.sum(lt[slip] * xi[slip])
    assert work == pytest.approx(mu * np.sum(ln[slip] * nxi), rel=1e-9)
    return slip.sum()


@pytest.fixture(scope="module")
def pad_dlft():
    """The 16-node pad's DLFT solutions with H = 6 and 2H = 12 harmonics (16 samples per
    harmonic)."""
    model = pad_3d()
    sols = {}
    for H in (6, 12):
        sols[H] = solve_periodic(model, FourierBasis.up_to(H, 16 * H), frequency=F_PAD,
                                 options=SolveOptions(tol=1e-10))
        assert sols[H].success, sols[H].message
    return model, sols


def test_3d_pad_agrees_with_the_dlft(pad_dlft):
    """A 3D pad with 16 contact nodes (4 x 4, hexahedra on a flat, 10 MPa, tangential traction
    0.8 mu P at 30 deg, 1 kHz: partial slip, the two corners across the load slip a third of
    the period) integrated in time from the 12-harmonic DLFT state: every contact solve
    settles and the settled period agrees with the DLFT, a different method, in the
    amplitude of the top's first harmonic and in the friction energy per cycle.

    Tolerance: the sum of the two methods' discretisation errors, each estimated by halving
    its resolution: ``|DLFT(12) - DLFT(6)|`` (measured 8.6e-12 m on the amplitude, 3.2 % on
    the energy) and ``|TD(8192 steps) - TD(4096 steps)|`` (1.7e-11 m, 1.2 %). Measured gaps:
    5.6e-12 m and 0.02 %. The step must resolve the contact's highest retained mode
    (``steps_per_highest_period``, 6.7 with 8192 steps): with 512 steps (0.44) the friction
    energy is 32 % off (docs/transient.md)."""
    model, sols = pad_dlft

    def dlft(H):
        o = sols[H].observed["top"]
        return np.hypot(o[:, 1], o[:, 1 + H]), dlft_friction_energy(sols[H])

    U0, V0 = initial_state(model, sols[12])
    td = {}
    for steps, periods in ((4096, 8), (8192, 6)):
        res = tr.integrate(model, F_PAD, options=IntegrationOptions(steps_per_period=steps),
                           start=InitialState(U0=U0, V0=V0), n_periods=periods, record=1)
        assert res.success and res.info["failed_steps"] == 0, res.message
        assert check_cone(res, MU_PAD) > 0
        c = np.fft.rfft(res.observed["top"], axis=0)[1] * 2 / steps
        td[steps] = np.abs(c), res.energy["friction"][-1] - res.energy["friction"][0]
    (a6, e6), (a12, e12), (a_td, e_td), (a_half, e_half) = dlft(6), dlft(12), td[8192], td[4096]
    assert e12 > 0
    assert np.all(np.abs(a_td - a12) <= np.abs(a12 - a6) + np.abs(a_td - a_half))
    assert abs(e_td - e12) <= abs(e12 - e6) + abs(e_td - e_half)
    assert abs(e_td - e12) < 0.01 * e12


def test_3d_pad_from_rest_settles_and_stays_held(pad_dlft):
    """The same pad started from rest with the loads applied at once (the default step,
    256 per period): every contact solve settles, and the pad stays where friction can hold
    it: its mean tangential offset is at most what the springs (1e7 N/m along x and y) can
    carry beside the load in the friction cone, ``sqrt((mu P A)^2 - Q0^2) / k`` = 18 um (an
    equilibrium bound, independent of the integrator; a contact solve that does not settle
    let it slide 25-53 um). Its peak-to-peak motion is the DLFT's to 1 % (the start selects
    another member of the family of stuck positions, which moves the mean, not the
    motion)."""
    model, sols = pad_dlft
    res = tr.integrate(model, F_PAD, n_periods=20)
    assert res.success and res.info["failed_steps"] == 0, res.message
    check_cone(res, MU_PAD)
    top = res.observed["top"]
    area, k = 1e-4, 1e7
    bound = np.sqrt((MU_PAD * P_PAD * area) ** 2 - (0.8 * MU_PAD * P_PAD * area) ** 2) / k
    assert np.hypot(*top[:, :2].mean(axis=0)) <= bound
    ptp_hb = np.ptp(sols[12].observed_time("top")[0], axis=-1)
    np.testing.assert_allclose(np.ptp(top, axis=0)[:2], ptp_hb[:2], rtol=0.01)


# --------------------------------------------------------------------------------------------
# energy
# --------------------------------------------------------------------------------------------
def test_energy_conserved_without_friction_and_damping():
    """Undamped chain, no loads, initial velocity.

    (a) contact open all the time: the discrete energy ``E_{n+1/2}`` of the trapezoidal rule
    is an exact invariant, so it is constant to round-off (1e-12 relative) over 200 periods,
    with and without the Craig-Bampton reduction.
    (b) frictionless impacts on the obstacle: energy never increases (the normal work of each
    step is >= 0, a perfectly inelastic impact of the contact node), is constant between
    impacts, and the identity ``dE = -W_normal`` holds to round-off.
    """
    for cut in (None, "all"):
        model = chain(mu=0.0, gap=1.0, N=0.0, F=0.0)
        V0 = np.zeros(model.ndof)
        V0[5] = 1e-3
        res = tr.integrate(model, hz(1.0),
                           options=IntegrationOptions(steps_per_period=64, modal_cutoff=cut),
                           start=InitialState(V0=V0), n_periods=200, record=200)
        E = res.energy["mechanical"]
        assert np.all(res.state == 0)
        assert np.ptp(E) / E[0] < 1e-12
    model = chain(mu=0.0, gap=2e-4, N=0.0, F=0.0)
    V0 = np.zeros(model.ndof)
    V0[1:4] = 1e-3
    V0[0] = 1e-3  # the contact node moves towards the obstacle
    res = tr.integrate(model, hz(1.0), options=IntegrationOptions(steps_per_period=64),
                       start=InitialState(V0=V0), n_periods=50, record=50)
    E = res.energy["mechanical"]
    wn = np.diff(res.energy["normal"])
    assert np.any(res.state > 0)  # it hits
    assert np.all(wn >= -1e-15 * E[0])
    dE = np.diff(E)
    assert np.all(dE <= 1e-13 * E[0])
    assert np.max(np.abs(dE + wn)) < 1e-12 * E[0]
    assert E[-1] < E[0]


def test_energy_balance_with_friction_and_damping():
    """Forced chain with friction, Rayleigh damping and an undamped spring to ground (the
    low-rank damping path): over one period of the steady state
    ``external work = friction + damping + normal work + change of mechanical energy``.

    The identity is exact for the scheme, so its residual is round-off (1e-9 of the external
    work). Independently, the damping dissipation is recomputed from the recorded velocities
    of all DOFs with the model's own (full) ``C``, ``sum_n h v_n^T C v_n`` (the scheme's
    damping work per step is ``h v_n^T C v_n`` with ``v_n = (U_{n+1} - U_{n-1}) / 2h``): this
    checks the reduced damping (diagonal + low rank) and its accumulation, to round-off.
    Friction work is > 0, the work of the normal contact force is 0 (closed contact, the
    normal position does not move), and the mechanical energy repeats after a period.
    """
    model = chain(mu=0.3, N=1.0, F=1.5, c_a=1e-2, c_b=2e-2)
    steps = 256
    res = tr.integrate(model, hz(0.5), options=IntegrationOptions(steps_per_period=steps),
                       n_periods=300, record=2)
    assert res.info["diagonal"] and res.info["damping"]["low_rank"] == 1
    assert np.any(res.state[:, 0] == 1) and np.any(res.state[:, 0] == 2)  # stick and slip
    e = {key: val[steps] - val[0] for key, val in res.energy.items()}  # over one period
    ext = e["external"]
    assert ext > 0
    assert res.energy_residual() < 1e-9 * ext
    assert abs(e["numerical"]) < 1e-9 * ext
    assert e["friction"] > 0
    assert abs(e["normal"]) < 1e-12 * ext
    assert abs(e["mechanical"]) < 1e-6 * ext  # steady: the period repeats
    assert abs(ext - e["friction"] - e["damping"]) < 1e-6 * ext
    v = res.velocities["all"][1:steps + 1]
    d_indep = res.info["h"] * np.einsum("ni,ij,nj->", v, model.C.toarray(), v)
    assert abs(e["damping"] / d_indep - 1) < 1e-9


def test_low_rank_damping_step_matches_dense():
    """The Woodbury form of the step (modal damping ``diag + U R U^T``) against a dense solve
    of ``S = M + gamma h C + beta h^2 K`` in the same coordinates (round-off)."""
    model = chain(mu=0.3, c_a=2e-3, c_b=1e-3)
    integ = tr.Integrator(model, 1.2, IntegrationOptions(steps_per_period=64, gamma=0.5,
                                                         contact_tol=1e-10))
    red, h = integ.red, integ.h
    C = np.diag(red.C) + red.U @ red.R @ red.U.T
    S = np.eye(integ.r) + 0.5 * h * C + 0.25 * h * h * np.diag(red.K)
    G = h * h * np.linalg.solve(S, red.Tx.T)
    np.testing.assert_allclose(integ.G, G, rtol=1e-10, atol=1e-12 * np.abs(G).max())


# --------------------------------------------------------------------------------------------
# reduction
# --------------------------------------------------------------------------------------------
def test_linear_limit_against_frequency_domain():
    """Frictionless, permanently closed contact makes the problem linear (the normal DOF is
    held, the tangential one is free). For ``F e^{i w t}`` the two-step trapezoidal rule has
    the exact periodic solution ``Z(w~)^-1 F`` with the warped frequency
    ``w~ = (2/h) tan(w h / 2)`` (mass, damping and stiffness terms all warp the same way;
    classical). So the steady first harmonic at the chain end must match a direct complex
    solve of the full model at ``w~`` to round-off (1e-9) without reduction, and, with the
    default Craig-Bampton cutoff ``w_c = 8 w`` (64 steps), to the dynamic amplification lost
    with the truncated modes, at most ``(w / w_c)^2 = 1/64``. Done twice: with Rayleigh
    damping (diagonal modal step) and with a damping of no such structure (dense step).
    """
    model = chain(mu=0.0, N=5.0, F=1.0, c_b=0.05)
    _check_linear_limit(model)
    # a damping with no Rayleigh-plus-low-rank structure: the dense step
    rng = np.random.default_rng(3)
    model.C = sp.diags(rng.uniform(0.02, 0.1, model.ndof)).tocsr()
    assert not _check_linear_limit(model)


def _check_linear_limit(model):
    w, steps = 1.1, 64
    h = 2 * np.pi / (w * steps)
    wt = 2 / h * np.tan(w * h / 2)
    K, M, C = model.K.toarray(), model.M.toarray(), model.C.toarray()
    keep = np.arange(1, model.ndof)
    Z = K - wt * wt * M + 1j * wt * C
    f = np.zeros(model.ndof)
    f[-1] = 1.0
    u = np.linalg.solve(Z[np.ix_(keep, keep)], f[keep])[-1]
    for cut, tol in (("all", 1e-9), (None, 1.0 / 64)):
        res = tr.integrate(model, hz(w),
                           options=IntegrationOptions(steps_per_period=steps, modal_cutoff=cut),
                           n_periods=400)
        c = steady.fourier_coefficients(res.observed["end"][:, 0], 3)
        assert abs((c[1] - 1j * c[4]) / u - 1) < tol
    assert res.info["r"] < model.ndof  # the default did truncate
    return res.info["diagonal"]


def test_restart_is_exact():
    """Two runs of 15 periods chained through ``U, V`` equal one run of 30 periods to
    round-off (the final state encodes the two-step history exactly)."""
    model = chain(mu=0.3, N=2.0, F=1.5, c_a=2e-3)
    a = tr.integrate(model, hz(1.2), options=IntegrationOptions(steps_per_period=64), n_periods=30)
    b = tr.integrate(model, hz(1.2), options=IntegrationOptions(steps_per_period=64), n_periods=15)
    b = tr.integrate(model, hz(1.2), options=IntegrationOptions(steps_per_period=64),
                     start=InitialState(U0=b.U, V0=b.V), n_periods=15)
    scale = np.abs(a.U).max()
    np.testing.assert_allclose(b.U, a.U, atol=1e-9 * scale)
    np.testing.assert_allclose(b.observed["end"], a.observed["end"], atol=1e-9 * scale)


# --------------------------------------------------------------------------------------------
# quasi-static incremental wear
# --------------------------------------------------------------------------------------------
def punch(*, p=(1e6, 1e6, 1e6, 4e6), k=1e6, mu=0.5, Q0=120.0, kw=1e-12, area=1e-4):
    """Contact nodes each held tangentially by a spring k, pressed with pressure p and pulled
    by ``Q0 sin(tau)``: three slide (Q0 > mu p A), the fourth (higher pressure) sticks."""
    nc = len(p)
    p = np.asarray(p, dtype=float)
    Kd = np.zeros(2 * nc)
    Kd[1::2] = k
    contact = ContactInterface(dofs=np.arange(2 * nc).reshape(nc, 2),
                               frame=np.tile(np.eye(2), (nc, 1, 1)), gap=np.zeros(nc),
                               area=np.full(nc, area), mu=mu, coords=np.zeros((nc, 2)),
                               wear_coefficient=kw)
    vN = np.zeros(2 * nc)
    vN[0::2] = p * area
    vT = np.zeros(2 * nc)
    vT[1::2] = Q0
    return Model(K=sp.csr_matrix(np.diag(Kd)), M=sp.identity(2 * nc, format="csr"),
                 contact=contact, loads=[Load(vN, "constant"), Load(vT, "sin")])


def test_incremental_wear_flat_punch():
    """Uniform sliding under constant pressure wears at Archard's rate, exactly.

    Analytic: once the first cycle is over, a sliding node goes between +-X,
    ``X = (Q0 - mu p A) / k``, so it slides ``4 X`` per cycle and wears ``k_w p 4 X`` per
    cycle; the sticking node (``Q0 < mu p A``) does not wear. Quasi-static load steps that
    include the turning points (steps_per_cycle divisible by 4) reproduce this exactly
    (round-off). The worn volume per cycle equals ``k_w / mu`` times the friction
    dissipation (Archard with Coulomb slip), and a cycle jump J counts a computed cycle J
    times, which for a constant wear rate gives the same wear.
    """
    p = np.array([1e6, 1e6, 1e6, 4e6])
    model = punch(p=p)
    c = model.contact
    k, mu, Q0, kw = 1e6, c.mu, 120.0, c.wear_coefficient
    res = quasistatic.incremental_wear(model, options=IncrementalWearOptions(steps_per_cycle=16),
                                       n_cycles=10)
    X = (Q0 - mu * p * c.area) / k
    rate = np.diff(res.wear, axis=0)[1:]
    expected = np.broadcast_to(kw * p[:3] * 4 * X[:3], rate[:, :3].shape)
    np.testing.assert_allclose(rate[:, :3], expected, rtol=1e-10)
    assert np.all(res.wear[:, 3] == 0.0)
    np.testing.assert_allclose(res.slip[-1, :3], 4 * X[:3], rtol=1e-10)
    np.testing.assert_allclose(res.pressure[-1], p, rtol=1e-10)
    np.testing.assert_allclose(np.diff(res.worn_volume)[1:], kw / mu * res.dissipation[2:],
                               rtol=1e-10)
    jumped = quasistatic.incremental_wear(
        model, options=IncrementalWearOptions(steps_per_cycle=16, cycle_jump=3), n_cycles=10)
    assert jumped.computed_cycles == 4 and jumped.cycles[-1] == 10
    np.testing.assert_allclose(jumped.wear[-1], res.wear[-1], rtol=1e-10, atol=1e-20)


def test_incremental_wear_gap_grows_with_wear():
    """Wear opens the gap as it goes: a sliding node's normal DOF (no stiffness, pressed by a
    constant load) sits exactly at the wear of the step before the last (the last step's
    wear is added after its solve), and the normal force stays the applied load."""
    steps = 8
    res = quasistatic.incremental_wear(punch(p=[1e6]),
                                       options=IncrementalWearOptions(steps_per_cycle=steps),
                                       n_cycles=5)
    w_last, w_prev = res.wear[-1, 0], res.wear[-2, 0]
    assert w_prev < res.U[0] < w_last
    # one step's wear at most: the slip per step is at most the cycle's slip over 2
    assert w_last - res.U[0] <= 0.5 * (w_last - w_prev)
    assert res.lam[0, 0] == pytest.approx(1e6 * 1e-4, rel=1e-12)


# --------------------------------------------------------------------------------------------
# inputs
# --------------------------------------------------------------------------------------------
def test_bad_inputs_are_reported():
    model = slider()
    with pytest.raises(InputError, match="record"):
        tr.integrate(model, 1.0, n_periods=2, record=3)
    with pytest.raises(InputError, match="modal_cutoff"):
        tr.integrate(model, 1.0, options=IntegrationOptions(modal_cutoff="some"), n_periods=1)
    with pytest.raises(InputError, match="frequency"):
        tr.integrate(model, -1.0, n_periods=1)
    with pytest.raises(InputError, match="wear"):
        tr.integrate(model, 1.0, start=InitialState(wear=[0.0, 1.0]), n_periods=1)
    fixed = slider()
    fixed.fixed_dofs = np.array([1])
    with pytest.raises(InputError, match="fixed"):
        tr.integrate(fixed, 1.0, n_periods=1)


def test_energy_is_cumulative_across_kernel_chunks(monkeypatch):
    """The recorded energy terms are cumulative from the first recorded sample, whatever the
    number of kernel calls the integration is cut into (CHUNK_STEPS: progress and Ctrl-C).
    Reference: the same integration in one kernel call; the terms must be equal bit for bit
    (the same additions in the same order), and the balance must hold over a window that
    crosses a chunk boundary (round-off, 1e-9 of the external work as above)."""
    model = chain(mu=0.3, N=1.0, F=1.5, c_a=1e-2, c_b=2e-2)
    steps = 64
    whole = tr.integrate(model, hz(0.5), options=IntegrationOptions(steps_per_period=steps),
                         n_periods=40, record=6)
    monkeypatch.setattr(tr, "CHUNK_STEPS", steps)  # one period per kernel call
    cut = tr.integrate(model, hz(0.5), options=IntegrationOptions(steps_per_period=steps),
                       n_periods=40, record=6)
    for key in whole.energy:
        np.testing.assert_array_equal(cut.energy[key], whole.energy[key], err_msg=key)
    e = {key: val[-1] - val[0] for key, val in cut.energy.items()}  # five chunk boundaries
    assert e["external"] > 0 and e["friction"] > 0
    assert cut.energy_residual() < 1e-9 * e["external"]


def test_kept_periods_that_cannot_fit_are_refused_before_allocation():
    """A fixed-length run keeps the once-per-period samples of every period: 1e9 periods of a
    one-DOF slider need 3 x 1e9 x 2 x 8 bytes = 48 GB, more than this machine's memory (24
    GiB); the run is refused in one line naming what would not fit, before numpy is asked
    for the arrays (it raised numpy's ArrayMemoryError, a traceback in a case file)."""
    from fretwear.resources import machine_memory

    n = 10**9
    assert 3 * n * 2 * 8 > machine_memory()
    with pytest.raises(InputError, match="once-per-period samples of 1000000000 periods"):
        tr.integrate(slider(m=1.0, k=1.0, N=1.0, F0=1.0, mu=0.3), hz(1.0), n_periods=n,
                     keep_poincare=n)
