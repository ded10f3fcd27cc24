"""Direct tests of the pieces shared by the time-domain solvers, the DLFT and the wear laws.

* Archard's integrand ``lambda_N |dx_T|`` (paper eq. 12, 29), written once
  (:func:`fretwear.wear.kernels.archard_integrand`) and summed by the DLFT slip work, the
  time-averaged rate and the quasi-static load steps: compared with hand computations on a few
  samples whose slips are exact in binary or Pythagorean triples, so the only error is the
  rounding of one square root and a product (a few ulp: 1e-15 relative).
* The exact static condensation onto the contact DOFs (:func:`fretwear.hb.reduce.condense_static`,
  the same code as the per-harmonic :func:`fretwear.hb.reduce.condense`): compared with a dense
  Schur complement written here with numpy (``numpy.linalg.solve``, not the sparse LU of the
  code) on the hand-assembled truss of tests/helpers/models.py (tilted contact frames, fixed DOFs).
  Relative errors of a dense solve are ~ cond * 1e-16; the truss' interior stiffness has a
  condition number of about 20 (measured 2e-16 between the two), so 1e-9 relative leaves a
  wide margin while a missing term, a wrong sign or a wrong frame gives O(1) errors.
"""

import numpy as np
import pytest
from helpers.models import truss

from fretwear.hb.contact import SEPARATION, SLIP, STICK
from fretwear.hb.reduce import condense, condense_static
from fretwear.wear.kernels import archard_integrand, slip_work, slip_work_samples

ULP = 1e-15  # a square root and a product: a few units of the last place
RTOL = 1e-9  # dense vs sparse solves of the truss (see the module docstring)


# --------------------------------------------------------------------------------------------
# Archard's integrand
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("lam_n", "now", "before", "slip"), [
    (2.0, [0.1, 3e-6, -4e-6], [0.5, 0.0, 0.0], 5e-6),  # 3D: a 3-4-5 triangle
    (0.5, [7.0, 1.5e-6], [-3.0, -0.5e-6], 2e-6),  # 2D, the normal component ignored
    (4.0, [0.0, 1.0, 2.0], [0.0, 1.0, 2.0], 0.0),  # no motion, no work
])
def test_archard_integrand_by_hand(lam_n, now, before, slip):
    """One node, one step: the slip length is the tangential distance moved (the normal
    component is not part of it) and the work is the normal force times it."""
    s, w = archard_integrand(lam_n, np.array(now), np.array(before))
    assert s == pytest.approx(slip, rel=ULP, abs=0.0)
    assert w == pytest.approx(lam_n * slip, rel=ULP, abs=0.0)


def test_slip_work_samples_by_hand():
    """A periodic sequence of 5 instants of one 2D node: the step ending at instant n goes
    from n - 1 to n (instant 0 from instant 4) and counts only when its state is slip.
    Tangential positions [um] 0, 1, 3, 2, -2 and states stick, slip, slip, separation, slip:
    slips 0, 1, 2, 0, 4 (the last one from 2 to -2) and works lam_N times these. The second
    node (3D) moves by 3-4-5 triangles."""
    um = 1e-6
    x = np.zeros((2, 3, 5))
    x[0, 1] = np.array([0.0, 1.0, 3.0, 2.0, -2.0]) * um
    x[0, 2] = 99.0  # node 0 is 2D in spirit: its T2 never moves
    x[1, 1] = np.array([0.0, 3.0, 3.0, 0.0, 0.0]) * um
    x[1, 2] = np.array([0.0, 4.0, 0.0, 0.0, 0.0]) * um
    lam_n = np.array([[5.0, 6.0, 7.0, 8.0, 9.0], [1.0, 2.0, 3.0, 4.0, 5.0]])
    state = np.array([[STICK, SLIP, SLIP, SEPARATION, SLIP], [SLIP, SLIP, SLIP, SLIP, STICK]],
                     dtype=np.int8)
    slip, work = slip_work_samples(lam_n, x, state)
    slip_ref = np.array([[0.0, 1.0, 2.0, 0.0, 4.0], [0.0, 5.0, 4.0, 3.0, 0.0]]) * um
    np.testing.assert_allclose(slip, slip_ref, rtol=ULP, atol=0.0)
    np.testing.assert_allclose(work, lam_n * slip_ref, rtol=ULP, atol=0.0)


def test_dlft_slip_work_is_the_same_integrand():
    """The DLFT slip work of a node is the sum of the integrand over its slip instants, on
    ``X = lambda_x / eps`` (eq. 29): the hand sequence above, scaled by eps, divided back."""
    eps = 2.5e7
    um = 1e-6
    lam_x = np.zeros((1, 2, 5))
    lam_x[0, 1] = eps * np.array([0.0, 1.0, 3.0, 2.0, -2.0]) * um
    lam_u = np.zeros((1, 2, 5))
    lam_u[0, 0] = [5.0, 6.0, 7.0, 8.0, 9.0]
    state = np.array([[STICK, SLIP, SLIP, SEPARATION, SLIP]], dtype=np.int8)
    expected = (6.0 * 1.0 + 7.0 * 2.0 + 9.0 * 4.0) * um
    assert slip_work(lam_u, lam_x, state, eps)[0] == pytest.approx(expected, rel=ULP)


# --------------------------------------------------------------------------------------------
# static condensation
# --------------------------------------------------------------------------------------------
def _dense_reference(model):
    """Dense Schur complement of the free structure onto the contact DOFs, in the local
    frames: ``K_r = R (K_cc - K_ci K_ii^-1 K_ic) R^T`` with ``R`` block-diagonal of the
    frames; returns it with the index sets and R."""
    K = model.K.toarray()
    c = model.contact.dofs.reshape(-1)
    free = np.setdiff1d(np.arange(model.ndof), model.fixed_dofs)
    i = np.setdiff1d(free, c)
    nc, d = model.contact.dofs.shape
    R = np.zeros((nc * d, nc * d))
    for p in range(nc):
        R[p * d:(p + 1) * d, p * d:(p + 1) * d] = model.contact.frame[p]
    S = K[np.ix_(c, c)] - K[np.ix_(c, i)] @ np.linalg.solve(K[np.ix_(i, i)], K[np.ix_(i, c)])
    return R @ S @ R.T, K, c, i, R


def test_static_condensation_is_the_dense_schur_complement():
    """Stiffness, condensed loads of several load vectors at once, and the recovery of every
    DOF, against the dense reference; the per-harmonic condensation with ``quasi_static``
    gives the same stiffness for every harmonic (one implementation)."""
    model = truss(damping="rayleigh")
    Kr_ref, K, c, i, R = _dense_reference(model)
    cond = condense_static(model)
    scale = np.abs(Kr_ref).max()
    np.testing.assert_allclose(cond.K, Kr_ref, rtol=RTOL, atol=RTOL * scale)
    np.testing.assert_array_equal(cond.K, cond.K.T)
    # condensed loads: F_r = R (F_c - K_ci K_ii^-1 F_i), three load vectors at once
    rng = np.random.default_rng(3)
    F = rng.standard_normal((3, model.ndof))
    F[:, model.fixed_dofs] = 0.0
    Fr_ref = (R @ (F[:, c].T - K[np.ix_(c, i)] @ np.linalg.solve(K[np.ix_(i, i)], F[:, i].T))).T
    np.testing.assert_allclose(cond.loads(F), Fr_ref, rtol=RTOL,
                               atol=RTOL * np.abs(Fr_ref).max())
    # recovery: U_c = R^T u_loc, U_i = K_ii^-1 (F_i - K_ic U_c), fixed DOFs zero
    u_loc = rng.standard_normal(c.size) * 1e-6
    U = cond.recover(u_loc, F[0])
    U_ref = np.zeros(model.ndof)
    U_ref[c] = R.T @ u_loc
    U_ref[i] = np.linalg.solve(K[np.ix_(i, i)], F[0, i] - K[np.ix_(i, c)] @ U_ref[c])
    np.testing.assert_allclose(U, U_ref, rtol=RTOL, atol=RTOL * np.abs(U_ref).max())
    # the equilibrium it stands for: K U + T^T lambda = F with lambda = F_r - K_r u_loc
    lam = cond.loads(F[0]) - cond.K @ u_loc
    T = model.contact.local_transform(model.ndof).toarray()
    free = np.setdiff1d(np.arange(model.ndof), model.fixed_dofs)
    resid = (K @ U + T.T @ lam - F[0])[free]
    assert np.abs(resid).max() < RTOL * np.abs(F[0]).max()
    # the per-harmonic condensation, quasi-static: the same K_r for every harmonic
    red = condense(model, 1e3, [0, 1, 3], quasi_static=True)
    for z in red.Z:
        np.testing.assert_allclose(z.real, cond.K, rtol=RTOL, atol=RTOL * scale)
        assert not np.any(z.imag)
