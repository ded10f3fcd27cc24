"""Contact stiffness in series with the contact law (:mod:`fretwear.hb.connectors`) and friction
under a prescribed normal load, end to end through :func:`fretwear.hb.periodic.solve_periodic`.

Independent references:

* the same springs written as real massless DOFs in user matrices, with a rigid contact on the
  massless DOFs: the condensation of :mod:`fretwear.hb.reduce` then eliminates the structure
  instead of :func:`fretwear.hb.connectors.connect` (a different code path to the same exact
  model), solved with the same eps and tolerance;
* the analytic response of a stuck Jenkins element (linear: the slider holds, the spring kt
  acts in parallel with k);
* the condensation formula of the issue, ``Z_x = Kc - Kc (Z_r + Kc)^-1 Kc``, evaluated with
  numpy on one harmonic.
"""

import numpy as np
import pytest

from fretwear.hb.connectors import Connected, connect
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.reduce import condense
from fretwear.hb.solution import initial_state
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

BASIS = FourierBasis.up_to(3, 32)
TOL = 1e-11  # solver tolerance: both models converged far below the comparison tolerance
# Two exact condensations of the same model differ by rounding (~1e-14 relative) and by the
# solver tolerance TOL (relative residual); 1e-8 leaves a wide margin over both while a wrong
# spring (e.g. kt applied twice, or a missing Kc term) changes the amplitude by > 1e-2.
RTOL = 1e-8


def jenkins(kt, *, explicit, mu=0.5, normal=1.0, force=0.2):
    """One-DOF oscillator (m = 1, k = 1, c = 0.02) with a Jenkins element (kt in series with a
    Coulomb slider, threshold mu N): the issue's problem (a). ``explicit``: the spring as a
    massless DOF 1 of the matrices, the slider on it; otherwise ``kt`` on the interface."""
    load = Load(np.array([force] + [0.0] * explicit), "cos")
    if explicit:
        K = np.array([[1.0 + kt, -kt], [-kt, kt]])
        return from_matrices(K, np.diag([1.0, 0.0]),
                             contact=ContactDofs(normal_dofs=None, tangential_dofs=[1], mu=mu,
                                                 normal_load=normal),
                             damping=Damping(C=np.diag([0.02, 0.0])), loads=[load],
                             observed={"u": 0})
    return from_matrices([[1.0]], [[1.0]],
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=mu,
                                             normal_load=normal, kt=kt),
                         damping=Damping(C=[[0.02]]), loads=[load], observed={"u": 0})


@pytest.mark.parametrize("w", [1.18, 1.24, 1.3])
def test_jenkins_matches_explicit_spring_dof(w):
    """Jenkins element as interface stiffness kt = 0.5 vs the same spring as a massless DOF:
    same displacement of the mass (observed rows of the connected model), and the contact
    point of the connected model moves as the explicit massless DOF. Frequencies below, at and
    above the frictional resonance (stick-slip at all three: asserted)."""
    f = w / (2 * np.pi)
    a = solve_periodic(jenkins(0.5, explicit=False), BASIS, frequency=f, eps=1.0,
                       options=SolveOptions(tol=TOL))
    b = solve_periodic(jenkins(0.5, explicit=True), BASIS, frequency=f, eps=1.0,
                       options=SolveOptions(tol=TOL))
    assert a.success and b.success
    assert set(np.unique(a.state)) >= {1, 2}
    np.testing.assert_allclose(a.observed["u"], b.observed["u"], rtol=0,
                               atol=RTOL * np.abs(b.observed["u"]).max())
    # tangential motion of the slider: contact point (connected) = massless DOF (explicit)
    np.testing.assert_allclose(a.X[:, 1], b.X[:, 1], rtol=0, atol=RTOL * np.abs(b.X).max())
    # the structure node of the connected model is the mass
    np.testing.assert_allclose(a.U_node[0, 1], a.observed["u"][0], rtol=0,
                               atol=RTOL * np.abs(b.observed["u"]).max())
    # the normal force is the prescribed one at every instant
    np.testing.assert_allclose(a.lam_t[0, 0], 1.0, rtol=1e-12)


def test_stuck_jenkins_is_linear_with_springs_in_parallel():
    """A slider that never slips (mu N = 1e3 >> the spring force): the mass sees k + kt, so its
    amplitude is F / |k + kt - w^2 m + i c w| (analytic) and all harmonics above the first
    vanish. Tolerance 1e-9 relative: a linear solve, only the solver tolerance remains."""
    w = 1.1
    s = solve_periodic(jenkins(0.5, explicit=False, mu=1.0, normal=1e3), BASIS,
                       frequency=w / (2 * np.pi), eps=1.0, options=SolveOptions(tol=TOL))
    assert s.success and np.all(s.state == 1)
    amp = s.observed_amplitude("u")[0]
    ref = 0.2 / abs(1.5 - w * w + 1j * 0.02 * w)
    assert amp[0] == pytest.approx(ref, rel=1e-9)
    assert np.all(amp[1:] <= 1e-9 * ref)


def test_normal_and_tangential_stiffness_match_explicit_dofs():
    """A 2D node (mass 1 on springs 1 in both directions, preloaded into a rigid plane, pushed
    tangentially) with contact stiffness kn = 2, kt = 0.7 vs the same springs as two massless
    DOFs carrying a rigid unilateral contact: same motion of the mass and of the contact
    point, with separation, stick and slip in the period (asserted)."""
    F = [Load(np.array([0.3, 0.0, 0.0, 0.0]), "constant"),
         Load(np.array([0.4, 0.5, 0.0, 0.0]), "cos")]
    kn, kt = 2.0, 0.7
    K = np.zeros((4, 4))
    K[:2, :2] = np.eye(2)
    for i, k in ((0, kn), (1, kt)):
        K[np.ix_([i, 2 + i], [i, 2 + i])] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    M = np.diag([1.0, 1.0, 0.0, 0.0])
    C = np.diag([0.05, 0.05, 0.0, 0.0])
    explicit = from_matrices(K, M,
                             contact=ContactDofs(normal_dofs=[2], tangential_dofs=[3], mu=0.4),
                             damping=Damping(C=C), loads=F, observed={"m": [0, 1]})
    K2 = np.eye(2)
    # the connected model: the mass is the contact node; the springs are the interface's
    connected = from_matrices(K2, M[:2, :2],
                              contact=ContactDofs(normal_dofs=[0], tangential_dofs=[1], mu=0.4,
                                                  kn=kn, kt=kt),
                              damping=Damping(C=C[:2, :2]),
                              loads=[Load(ld.vector[:2], ld.waveform) for ld in F],
                              observed={"m": [0, 1]})
    f = 0.9 / (2 * np.pi)
    b = solve_periodic(explicit, BASIS, frequency=f, eps=1.0, options=SolveOptions(tol=TOL))
    a = solve_periodic(connected, BASIS, frequency=f, eps=1.0, options=SolveOptions(tol=TOL))
    assert a.success and b.success
    assert set(np.unique(b.state)) == {0, 1, 2}
    scale = np.abs(b.observed["m"]).max()
    np.testing.assert_allclose(a.observed["m"], b.observed["m"], rtol=0, atol=RTOL * scale)
    np.testing.assert_allclose(a.X, b.X, rtol=0, atol=RTOL * scale)
    np.testing.assert_allclose(a.lam, b.lam, rtol=0, atol=RTOL * np.abs(b.lam).max())
    # full-field state at t = 0 recovered from the structure's node, not the contact point
    u0, _ = initial_state(connected, a)
    np.testing.assert_allclose(u0, BASIS.to_time(a.observed["m"])[:, 0], rtol=0,
                               atol=RTOL * scale)


def test_connect_matches_closed_form_and_rigid_limit():
    """``connect`` vs ``Z_x = Kc - Kc (Z_r + Kc)^-1 Kc`` and ``F_x = Kc (Z_r + Kc)^-1 F_r``
    (numpy, finite springs), and with ``kn = inf`` vs the hand condensation of the tangential
    spring alone (``u_N = x_N``; unknowns ``u_T, x_N, x_T``, ``u_T`` eliminated). Tolerance
    1e-12: 2 x 2 inverses of well-conditioned matrices."""
    K = np.array([[3.0, 0.5], [0.5, 2.0]])
    M = np.diag([1.0, 2.0])

    def model(kn, kt):
        return from_matrices(K, M, contact=ContactDofs(normal_dofs=[0], tangential_dofs=[1],
                                                       mu=0.3, kn=kn, kt=kt),
                             loads=[Load(np.array([1.0, 0.5]), "cos")])

    red = condense(model(None, None), 0.2, [0, 1, 2])
    kn, kt = 2.0, 0.7
    con = connect(red, model(kn, kt).contact)
    assert isinstance(con, Connected)
    Kc = np.diag([kn, kt])
    for b in range(3):
        inv = np.linalg.inv(red.Z[b] + Kc)
        np.testing.assert_allclose(con.Z[b], Kc - Kc @ inv @ Kc, rtol=0, atol=1e-12)
        np.testing.assert_allclose(con.F[b], Kc @ inv @ red.F[b], rtol=0, atol=1e-12)
    con = connect(red, model(np.inf, kt).contact)
    for b in range(3):
        Z, F = red.Z[b], red.F[b]
        g = 1.0 / (Z[1, 1] + kt)  # u_T = g (F_T - Z_TN x_N + kt x_T)
        ref = np.array([[Z[0, 0] - Z[0, 1] * g * Z[1, 0], Z[0, 1] * g * kt],
                        [kt * g * Z[1, 0], kt - kt * g * kt]])
        np.testing.assert_allclose(con.Z[b], ref, rtol=0, atol=1e-12)
        np.testing.assert_allclose(con.F[b], [F[0] - Z[0, 1] * g * F[1], kt * g * F[1]],
                                   rtol=0, atol=1e-12)
    assert connect(red, model(None, None).contact) is red  # rigid: unchanged
