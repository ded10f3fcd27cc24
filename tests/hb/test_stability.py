"""Hill's method on the DLFT linearisation (:mod:`fretwear.hb.stability`); the structure's
dynamic stiffness at complex arguments (:mod:`fretwear.hb.dynamics`) is tested in
test_dynamics.py.

Independent references (none calls the code under test):

* the law's own time recursion (:func:`fretwear.hb.contact.dlft_time`) run over many periods
  with a perturbation ``e^{s t} q(t)``: its response divided by ``e^{s t}`` is the
  Floquet-periodic part that ``G(s)`` predicts;
* the solve's Jacobian (:meth:`DLFTProblem.residual`) for ``T(0)``;
* the eigenvalues of the linear structure's state matrix where the contact never touches;
* shooting with SciPy's integrators on the equations of motion written here (a unilateral
  spring, a Jenkins element as a clipped spring force), Floquet multipliers from the
  monodromy matrix by central differences.
"""

import numpy as np
import pytest
from helpers.models import C2, K2, oscillator, two_dof
from scipy.integrate import solve_ivp
from scipy.optimize import root

from fretwear.hb import contact as law
from fretwear.hb import stability as hill_module
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.stability import (
    COPY_EXACT,
    EDGE_TOL,
    HillProblem,
    QuadraticReduction,
    _backward_error,
    _block_mats,
    _companion_eigen,
    _components,
    _copy,
    _det_sign,
    _families,
    _inverse_iteration,
    _inverse_iteration_py,
    _member,
    _pair,
    _pair_lapack,
    _shifted_copy,
    _state_summary,
    centroid,
    jacobian_form,
    problem_of,
    quadratic_eigen,
    reduce_quadratic,
    shifted_gain,
    stability,
)
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices


# --- models --------------------------------------------------------------------------------
def jenkins(force, m=1.0, k=1.0, c=0.02, kt=0.5, slip=0.5):
    """A mass on a spring ``k`` and a Jenkins element (``kt`` in series with a slider of
    threshold ``slip`` = mu N, N prescribed)."""
    return from_matrices([[k]], [[m]],
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=slip,
                                             normal_load=1.0, kt=kt),
                         damping=Damping(C=[[c]]), loads=[Load(np.array([force]), "cos")],
                         observed={"x": 0})


def continued(model, basis, omegas):
    """Solutions along ``omegas`` [rad/s], each from the previous one (a branch)."""
    U0, out = None, []
    for w in omegas:
        sol = solve_periodic(model, basis, frequency=w / (2 * np.pi), time_domain=None, U0=U0)
        assert sol.success
        out.append(sol)
        U0 = sol.U
    return out


def start_state(sol, obs, omega):
    """Displacements and velocities at t = 0 of the observed points of ``sol``."""
    k = sol.basis.k
    n = np.arange(1, k + 1)
    u = [sol.observed[o][0] for o in obs]
    return (np.array([c[0] + c[1:1 + k].sum() for c in u]),
            np.array([omega * (n * c[1 + k:]).sum() for c in u]))


def multipliers_by_shooting(flow, y0):
    """Fixed point of the period map ``flow`` from ``y0`` and the eigenvalues of its monodromy
    matrix (central differences), by decreasing modulus."""
    sol = root(lambda y: flow(y) - y, y0, method="hybr", options={"xtol": 1e-12})
    y = sol.x
    n = y.size
    M = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = 1e-6
        M[:, j] = (flow(y + e) - flow(y - e)) / 2e-6
    mu = np.linalg.eigvals(M)
    return mu[np.argsort(-np.abs(mu))]


def two_dof_flow(omega, kn=10.0, gap=0.5, force=0.1):
    def rhs(t, y):
        x, v = y[:2], y[2:]
        fc = np.array([kn * max(x[0] - gap, 0.0), 0.0])
        return np.concatenate([v, np.array([0.0, force]) * np.cos(omega * t) - K2 @ x
                               - C2 @ v - fc])

    def flow(y):
        return solve_ivp(rhs, (0.0, 2 * np.pi / omega), y, rtol=1e-11, atol=1e-12,
                         method="DOP853").y[:, -1]

    return flow


def jenkins_flow(omega, force, m=1.0, k=1.0, c=0.02, kt=0.5, slip=0.5, n=1000):
    """Period map of ``(u, v, f)``: RK4 on the mass with the element's force ``f`` advanced by
    the return map of a spring in series with a slider (clip of ``f + kt du``)."""
    h = 2 * np.pi / omega / n

    def acc(t, u, v, f):
        return (force * np.cos(omega * t) - c * v - k * u - f) / m

    def flow(y):
        u, v, f = y
        t = 0.0
        for _ in range(n):
            a1 = acc(t, u, v, f)
            a2 = acc(t + h / 2, u + h / 2 * v, v + h / 2 * a1,
                     np.clip(f + kt * h / 2 * v, -slip, slip))
            v2 = v + h / 2 * a1
            a3 = acc(t + h / 2, u + h / 2 * v2, v + h / 2 * a2,
                     np.clip(f + kt * h / 2 * v2, -slip, slip))
            v3 = v + h / 2 * a2
            a4 = acc(t + h, u + h * v3, v + h * a3, np.clip(f + kt * h * v3, -slip, slip))
            v4 = v + h * a3
            du = h * (v + 2 * v2 + 2 * v3 + v4) / 6
            v = v + h * (a1 + 2 * a2 + 2 * a3 + a4) / 6
            f = np.clip(f + kt * du, -slip, slip)
            u += du
            t += h
        return np.array([u, v, f])

    return flow


# --- the law's derivative with its memory ----------------------------------------------------
def _samples(rng, nc, d, N):
    """Smooth random lambda_u samples that stick, slip (and in 3D turn) within a period."""
    t = 2 * np.pi * np.arange(N) / N
    lu = np.empty((nc, d, N))
    for p in range(nc):
        lu[p, 0] = 2.0 + 0.3 * np.cos(t + rng.uniform(0, 6))
        for c in range(1, d):
            lu[p, c] = (1.5 * np.cos(t + rng.uniform(0, 6)) + 0.4 * np.sin(2 * t)
                        + 0.1 * rng.standard_normal())
    return lu


@pytest.mark.parametrize("d", [2, 3])
def test_shifted_gain_is_the_floquet_response_of_the_law(d):
    """``G(s)`` at a real ``s`` against the law's own recursion: the converged periodic
    state, then 12 periods of ``lambda_u + eps e^{s t} q(t)``; the change of ``lambda_x`` in
    the last period times ``e^{-s t}``, projected on the kept harmonics, is ``G(s) q~`` (the
    start's transient has decayed by ``e^{-12 s T}``: 4e-13 at ``s T = 2.4``). The finite
    difference ``eps = 1e-7`` of a piecewise-linear map (no state changes: asserted) leaves
    rounding only: 1e-6."""
    rng = np.random.default_rng(3)
    basis = FourierBasis.up_to(3, 48)
    P, Q = basis.matrices()
    N, H = basis.n_samples, basis.size
    nc = 2
    lu = _samples(rng, nc, d, N)
    mu = np.array([0.5, 0.7])
    lx, state, _ = law.dlft_time(lu, mu, np.zeros((nc, d - 1)), 1e-14, 200)
    assert np.any(state == law.STICK) and np.any(state == law.SLIP)
    s = 0.4  # s / w, real: the perturbation grows
    z = np.exp(-2 * np.pi * s / N)
    G = shifted_gain(lu, lx, state, mu, P, Q, z)
    M = 12
    tt = 2 * np.pi * np.arange(M * N) / N
    q = rng.standard_normal((nc, d, H))
    ref_t = tt[-N]  # the perturbation is of order 1 in the last period
    pert = np.exp(s * (tt - ref_t)) * np.tile(q @ Q.T, M)
    eps = 1e-7
    start = lx[:, 1:, -1].copy()
    base, st0, _ = law.dlft_time(np.tile(lu, M), mu, start, 1e-14, 0)
    moved, st1, _ = law.dlft_time(np.tile(lu, M) + eps * pert, mu, start, 1e-14, 0)
    assert np.array_equal(st0, st1)
    r = (moved - base)[:, :, -N:] / eps * np.exp(-s * (tt[-N:] - ref_t))
    ref = r @ P.T  # (nc, d, H)
    got = np.einsum("pij,pj->pi", G.real, q.reshape(nc, d * H)).reshape(nc, d, H)
    assert np.abs(G.imag).max() < 1e-12
    assert np.abs(got - ref).max() <= 1e-6 * np.abs(ref).max()


def test_shifted_gain_at_zero_is_the_solve_s_gain():
    """``z = 1`` (``s = 0``) gives :func:`fretwear.hb.contact.dlft_jacobian` (the same
    recursion without the factor) to rounding, in 3D with stick and slip."""
    rng = np.random.default_rng(5)
    basis = FourierBasis.up_to(3, 40)
    P, Q = basis.matrices()
    lu = _samples(rng, 3, 3, basis.n_samples)
    mu = np.array([0.4, 0.6, 0.8])
    lx, state, _ = law.dlft_time(lu, mu, np.zeros((3, 2)), 1e-14, 200)
    ref = law.dlft_jacobian(lu, lx, state, mu, P, Q)
    G = shifted_gain(lu, lx, state, mu, P, Q, 1.0)
    assert np.abs(G - ref).max() <= 1e-12 * np.abs(ref).max()


@pytest.mark.parametrize("d", [2, 3])
def test_shifted_gain_with_a_prescribed_normal_force(d):
    """With a prescribed normal force (the normal row of every sample is the inverse
    transform's, which ``_shifted_gain`` takes as ``P Q`` without the samples' product):
    ``z = 1`` gives :func:`fretwear.hb.contact.dlft_jacobian` with the same ``normal`` (the
    solve's recursion, every row by the samples) to rounding (1e-12), with stick and slip;
    at ``z != 1`` the normal rows are ``z``-free (``P Q`` and zeros: no memory)."""
    rng = np.random.default_rng(9)
    basis = FourierBasis.up_to(3, 40)
    P, Q = basis.matrices()
    H = basis.size
    lu = _samples(rng, 2, d, basis.n_samples)
    mu = np.array([0.4, 0.6])
    normal = 1.0 + 0.5 * np.cos(2 * np.pi * np.arange(basis.n_samples) / basis.n_samples)
    normal = np.vstack([normal, 2.0 * normal])
    lx, state, _ = law.dlft_time(lu, mu, np.zeros((2, d - 1)), 1e-14, 200, normal)
    assert np.any(state == law.STICK) and np.any(state == law.SLIP)
    ref = law.dlft_jacobian(lu, lx, state, mu, P, Q, normal=normal)
    G = shifted_gain(lu, lx, state, mu, P, Q, 1.0, normal)
    assert np.abs(G - ref).max() <= 1e-12 * np.abs(ref).max()
    Gz = shifted_gain(lu, lx, state, mu, P, Q, np.exp(-0.3j), normal)
    assert np.abs(Gz[:, :H, :H] - P @ Q).max() <= 1e-14 and np.all(Gz[:, :H, H:] == 0)


# --- Hill's matrix and the exponents --------------------------------------------------------
def _jenkins_hysteretic():
    """A Jenkins oscillator (m = k = 1, kt 0.5, mu N 0.5) with viscous and hysteretic
    damping, forced by 0.2 cos."""
    return from_matrices([[1.0]], [[1.0]],
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=0.5,
                                             normal_load=1.0, kt=0.5),
                         damping=Damping(C=[[0.02]], D=[[0.03]]),
                         loads=[Load(np.array([0.2]), "cos")], observed={"x": 0})


def _hill_problem(model, basis, f):
    """``(prob, HillProblem)`` of the periodic solution of ``model`` at ``f`` [Hz]."""
    sol = solve_periodic(model, basis, frequency=f, time_domain=None)
    assert sol.success
    prob = problem_of(model, sol)
    return prob, HillProblem(prob, sol.U.reshape(prob.m, prob.H), structure_dynamics(model))


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("case", ["jenkins-hysteretic", "unilateral-two-dof"])
def test_compiled_hill_matrix_is_its_parts(case, compiled, monkeypatch):
    """``HillProblem.matrix`` (compiled: ``Z_r`` by elimination on the held structure, then
    ``G Z`` over the nonzero entries of ``Z``) equals ``jacobian_form(gain, stiffness)``
    (numpy and LAPACK: tested against the law's recursion, the solve's Jacobian and the dense
    Schur complement in this module and test_dynamics.py) to 1e-13 of its largest entry:
    the same terms summed in another order and a ``q x q`` elimination instead of LAPACK's
    (measured within 1e-15; the margin is for the conditioning of the held structure). At
    ``s = 0``, on the imaginary axis and in both half-planes, on a Jenkins solution with
    viscous and hysteretic damping (``Im s`` signs the hysteretic term of every harmonic,
    the static one included) and on the unilateral two-DOF oscillator (contact springs:
    three interior coordinates, a Schur complement per argument). ``compiled`` False: the
    interior held above ``CONDENSED_COMPILED_MAX`` (set to -1), ``Z_r`` by LAPACK's
    solve, the same comparison."""
    if not compiled:
        monkeypatch.setattr(hill_module, "CONDENSED_COMPILED_MAX", -1)
    if case == "jenkins-hysteretic":
        model = _jenkins_hysteretic()
        basis, w = FourierBasis.up_to(5, 64), 1.18
    else:
        model, basis, w = two_dof(), FourierBasis.up_to(5, 64), 0.7
    prob, hp = _hill_problem(model, basis, w / (2 * np.pi))
    for sigma in (0.0, 0.3j, -0.02 + 0.47j, 0.1 - 0.2j):
        ref = jacobian_form(hp.gain(sigma), hp.stiffness(sigma), prob.eps)
        assert np.abs(hp.matrix(sigma) - ref).max() <= 1e-13 * np.abs(ref).max()


@pytest.mark.parametrize("case", ["jenkins-hysteretic", "unilateral-two-dof"])
def test_refinement_step_is_its_parts(case):
    """``HillProblem.evaluate`` (``T(s)``, the compiled pair and the compiled residuals)
    against ``matrix`` and ``_pair_lapack`` (LAPACK's LU, two solves) with the residuals by
    numpy's norms: the eigenvalue estimate and the residuals to 1e-11 (the same two solves
    in another elimination order, amplified by the conditioning of ``T - mu0 I``, as the
    compiled pair's test), ``T`` bit for bit (the same kernels), at points of both
    half-planes and a shift."""
    if case == "jenkins-hysteretic":
        model, basis, w = _jenkins_hysteretic(), FourierBasis.up_to(5, 64), 1.18
    else:
        model, basis, w = two_dof(), FourierBasis.up_to(5, 64), 0.7
    prob, hp = _hill_problem(model, basis, w / (2 * np.pi))
    rng = np.random.default_rng(4)
    for sigma, mu0 in ((0.3j, 0.0), (-0.02 + 0.47j, 0.01 - 0.02j), (0.1 - 0.2j, 0.0)):
        v = rng.standard_normal(prob.m * prob.H) + 1j * rng.standard_normal(prob.m * prob.H)
        count = hp.evaluations
        T, mu, y, lu, res, pair = hp.evaluate(sigma, v, mu0)
        assert lu is None and hp.evaluations == count + 1
        T_ref = hp.matrix(sigma)
        assert np.array_equal(T, T_ref)
        mu_ref, y_ref, _ = _pair_lapack(T_ref, v, mu0)
        scale = np.linalg.norm(T_ref, 1)
        pair_ref = np.linalg.norm(T_ref @ y_ref - mu_ref * y_ref) / scale
        assert abs(mu - mu_ref) <= 1e-11 * abs(mu_ref)
        assert abs(pair - pair_ref) <= 1e-11 * max(pair_ref, 1e-3)
        assert abs(res - max(abs(mu_ref) / scale, pair_ref)) <= 1e-11 * max(res, 1e-3)


@pytest.mark.parametrize("case", ["jenkins-hysteretic", "unilateral-two-dof", "oscillator-2d"])
def test_pencil_condensed_is_the_frozen_memory_hill_matrix(case):
    """``HillProblem.pencil`` (compiled) with its interior coordinates ``q`` eliminated (the
    Schur complement of ``A0 + sigma A1 + sigma^2 A2`` onto the contact coordinates, done
    here densely) is ``T(s)`` with the law's memory frozen: ``jacobian_form(G(0), Z(s))``,
    ``Z(s)`` from the structure's condensation at complex arguments
    (:meth:`HillProblem.stiffness`, tested against the dense Schur complement in
    test_dynamics.py). Equal to 1e-12 of the largest entry: the same terms eliminated in
    another order, through ``Z^qq`` (conditioned 1e2-1e3 here). On a Jenkins solution with
    viscous and hysteretic damping (real ``s`` only: the pencil signs the hysteretic term by
    the harmonic, as ``Z(s)`` does where ``Im s`` is below ``w``, with none on the static
    coefficient as at ``Im s = 0``), on the unilateral two-DOF oscillator (three interior
    coordinates) and on a two-dimensional contact node (``d = 2``: the law's ``G`` couples
    the normal and tangential coefficients)."""
    if case == "jenkins-hysteretic":
        model = _jenkins_hysteretic()
        basis, f, sigmas = FourierBasis.up_to(5, 64), 1.18 / (2 * np.pi), (0.0, -0.05, 0.2)
    elif case == "unilateral-two-dof":
        model, basis, f = two_dof(), FourierBasis.up_to(5, 64), 0.7 / (2 * np.pi)
        sigmas = (0.0, 0.3j, -0.02 + 0.47j, 0.1 - 0.2j)
    else:
        model, basis, f = oscillator(), FourierBasis.up_to(3, 32), 15.0
        sigmas = (0.0, 0.3j, -0.02 + 0.47j, 0.1 - 0.2j)
    prob, hp = _hill_problem(model, basis, f)
    A = hp.pencil()
    nx = prob.m * prob.H
    assert case != "oscillator-2d" or prob.d == 2
    for sigma in sigmas:
        P = A[0] + sigma * A[1] + sigma**2 * A[2]
        S = P[:nx, :nx] - P[:nx, nx:] @ np.linalg.solve(P[nx:, nx:], P[nx:, :nx])
        ref = jacobian_form(hp.G0, hp.stiffness(sigma), prob.eps)
        assert np.abs(S - ref).max() <= 1e-12 * np.abs(ref).max()


def test_compiled_pair_is_lapacks():
    """``_pair`` up to ``PAIR_COMPILED_MAX`` unknowns (compiled LU with partial pivoting) is
    ``_pair_lapack`` (LAPACK's ``zgetrf``/``zgetrs``) on random complex matrices of 5, 30
    and 48 unknowns and random shifts: the eigenvalue estimate and the vector to 1e-11
    (the same elimination in another order, amplified by the conditioning of ``T - mu0 I``
    through two solves: measured within 3e-14). At a zero pivot (``mu0`` an eigenvalue of a
    triangular ``T``) it takes LAPACK's path, which returns its LU."""
    rng = np.random.default_rng(3)
    for n in (5, 30, 48):
        for _ in range(5):
            T = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
            v = rng.standard_normal(n) + 1j * rng.standard_normal(n)
            mu0 = complex(rng.standard_normal(), rng.standard_normal())
            mu, y, lu = _pair(T, v, mu0)
            mu_ref, y_ref, _ = _pair_lapack(T, v, mu0)
            assert lu is None
            assert abs(mu - mu_ref) <= 1e-11 * abs(mu_ref)
            np.testing.assert_allclose(y, y_ref, rtol=0, atol=1e-11)
    T = np.triu(rng.standard_normal((6, 6))) + 0j
    T[np.diag_indices(6)] = np.arange(1.0, 7.0)
    with np.errstate(all="ignore"):
        assert _pair(T, np.ones(6, dtype=complex), 0.0)[2] is None  # no zero pivot at 0
        assert _pair(T, np.ones(6, dtype=complex), 1.0)[2] is not None


def test_compiled_inverse_iteration_finds_the_dense_eigenvalue(monkeypatch):
    """``_inverse_iteration`` on a block of at most ``PAIR_COMPILED_MAX`` unknowns (compiled,
    its own LU) converges, from 1e-3 off an eigenvalue of a random quadratic problem of 20
    coordinates with its eigenvector perturbed, to that eigenvalue of the companion
    eigensolve (``_companion_eigen``, LAPACK) and to LAPACK's path (``PAIR_COMPILED_MAX``
    set to 0), within 1e-12 of ``max(1, |s|)``: both stop at a Newton step below 1e-14 of
    it, and the dense eigenvalues are backward stable to rounding (the eigenvalues here are
    simple and O(1) apart)."""
    from fretwear.hb import stability as hs

    B0, B1, B2, starts = _quadratic_starts(7, 20)
    for value, start, y0 in starts:
        s1, _, ok = _inverse_iteration(B0, B1, B2, start, y0)
        assert ok and abs(s1 - value) <= 1e-12 * max(1.0, abs(value))
        monkeypatch.setattr(hs, "PAIR_COMPILED_MAX", 0)
        s2, _, ok2 = _inverse_iteration(B0, B1, B2, start, y0)
        monkeypatch.undo()
        assert ok2 and abs(s1 - s2) <= 1e-12 * max(1.0, abs(s2))


def test_lapack_kernel_inverse_iteration_is_the_python_steps():
    """``_inverse_iteration`` above ``PAIR_COMPILED_MAX`` unknowns (compiled, LAPACK's solve
    called from the kernel) against the same steps from Python (``_inverse_iteration_py``,
    ``zgetrf``/``zgetrs``) and the companion eigensolve, on a random quadratic problem of 60
    coordinates from 1e-3 off three of its eigenvalues: the same eigenvalue within 1e-12 of
    ``max(1, |s|)`` (both stop at a Newton step below 1e-14 of it; the eigenvalues are simple
    and O(1) apart, so the rounding of the two LU orders stays at that level). At a singular
    ``P(s)`` (``s`` an eigenvalue of a diagonal problem) it falls back on the Python steps,
    which report no convergence instead of raising."""
    n = 60
    B0, B1, B2, starts = _quadratic_starts(11, n)
    for value, start, y0 in starts:
        s1, x1, ok = _inverse_iteration(B0, B1, B2, start, y0)
        s2, x2, ok2 = _inverse_iteration_py(B0 + 0j, B1 + 0j, B2 + 0j, start, y0 + 0j)
        assert ok and ok2
        assert abs(s1 - value) <= 1e-12 * max(1.0, abs(value))
        assert abs(s1 - s2) <= 1e-12 * max(1.0, abs(s2))
        assert abs(abs(np.vdot(x1, x2)) - 1.0) <= 1e-10
    D = np.diag(np.arange(1.0, n + 1.0))  # P(0) = D - D singular: the Python steps' answer
    s, _, ok = _inverse_iteration(-D, np.zeros((n, n)), D, 1.0, np.ones(n))
    assert not ok and s == 1.0


def test_hill_matrix_at_zero_is_the_solve_jacobian():
    """``T(0)`` is the Jacobian the solve used (``J = eps I - G (eps I - Z)``), to rounding,
    on a Jenkins solution that sticks and slips; so is :meth:`HillProblem.jacobian` (from the
    solve's ``G`` and the problem's ``Z~``: what ``det J`` is read from), which must be real."""
    model = jenkins(0.2)
    basis = FourierBasis.up_to(5, 64)
    sol = solve_periodic(model, basis, frequency=1.18 / (2 * np.pi), time_domain=None)
    prob = problem_of(model, sol)
    U = sol.U.reshape(prob.m, prob.H)
    hp = HillProblem(prob, U, structure_dynamics(model))
    _, J = prob.residual(U, True)
    T = hp.matrix(0.0)
    assert np.abs(T - J).max() <= 1e-10 * np.abs(J).max()
    J0 = hp.jacobian()
    assert J0.dtype == float and np.abs(J0 - J).max() <= 1e-10 * np.abs(J).max()
    assert hp.det_sign() == int(np.sign(np.linalg.slogdet(J)[0])) != 0


def test_det_sign_is_lapack_s():
    """The compiled sign of ``det(eps I - G (eps I - Z))`` (:func:`_det_sign`) against
    LAPACK's ``slogdet`` of :func:`jacobian_form` on random block-diagonal ``G`` (two nodes)
    and ``Z`` of both signs (well conditioned: the sign cannot hinge on rounding), and 0
    where a row of ``J`` is zero."""
    rng = np.random.default_rng(4)
    n, dH = 12, 6
    signs = set()
    for _ in range(20):
        G = rng.standard_normal((2, dH, dH))
        Z = rng.standard_normal((n, n))
        J = jacobian_form(G, Z, 0.7)
        ref = int(np.sign(np.linalg.slogdet(J)[0]))
        signs.add(ref)
        assert _det_sign(G, Z, 0.7) == ref
    assert signs == {-1, 1}
    G = np.zeros((2, dH, dH))
    assert _det_sign(G, rng.standard_normal((n, n)), 0.0) == 0


def test_gain_without_stick_from_the_split_is_the_recursion():
    """On the unilateral two-DOF oscillator (contact and separation, no stick: the law has
    no memory) ``G(0)`` is taken from the split (:func:`fretwear.hb.memory_gain.memory_gain`,
    nothing but its constant part there) instead of the solve's recursion: the same terms
    summed in another order, so equal to rounding (1e-14 of the largest entry; measured
    1.1e-16), with no stick interval kept for the refinement, and the same ``det J`` sign.
    At 0.6 rad/s the contact closes for some samples and is open for the others (at 0.65
    and above it stays open all period, where the split has only separated rows)."""
    from fretwear.hb.memory_gain import memory_gain

    model, basis = two_dof(), FourierBasis.up_to(5, 64)
    prob, hp = _hill_problem(model, basis, 0.6 / (2 * np.pi))
    assert hp.memoryless() and hp._memory is None
    assert len(np.unique(hp.state)) == 2 and law.SEPARATION in hp.state  # closes and opens
    split = memory_gain(hp.lu, hp.lx, hp.state, *hp._law)
    assert split is not None and np.array_equal(hp.G0, split.at(1.0).real)  # G(0): the split
    ref = law.dlft_jacobian(hp.lu, hp.lx, hp.state, prob.mu, prob.P, prob.Q,
                            prob.eps * prob.anchor, prob.tol, prob.max_sweeps, prob.normal)
    assert np.abs(split.at(1.0).real - ref).max() <= 1e-14 * np.abs(ref).max()
    J = jacobian_form(ref, prob.Z, prob.eps)
    assert hp.det_sign() == int(np.sign(np.linalg.slogdet(J)[0])) != 0


def _families_numpy(sig, kaps, res):
    """The result's families as :func:`hill_stability` assembled them with numpy before
    :func:`_families` (kept here as the reference)."""
    edge = np.abs(np.abs(sig.imag) - 0.5) <= EDGE_TOL
    cplx = (np.abs(sig.imag) > 1e-9 * np.maximum(np.abs(sig), 1.0)) & ~edge
    allsig = np.concatenate([sig, np.conj(sig[cplx])])
    allkap = np.concatenate([kaps, -kaps[cplx]])
    allres = np.concatenate([res, res[cplx]])
    src = np.concatenate([np.arange(sig.size), np.flatnonzero(cplx)])
    mult = np.exp(2.0 * np.pi * allsig)
    redge = np.concatenate([edge, np.zeros(int(cplx.sum()), dtype=bool)])
    mult[redge] = -np.exp(2.0 * np.pi * allsig[redge].real)
    chosen = np.argsort(-allsig.real, kind="stable")
    return allsig[chosen], mult[chosen], allkap[chosen], allres[chosen], src[chosen]


def test_compiled_families_are_numpy_s():
    """:func:`_families` (the result's conjugates, period-doubling members and order in one
    compiled call) against the numpy assembly it replaced, on exponents that are real,
    complex, on the period-doubling line (within ``EDGE_TOL``), with equal real parts (the
    stable order) and NaN residuals: the same order and sources exactly, the same exponents,
    centroids and residuals bit for bit, multipliers to 1e-15 (numba's and numpy's complex
    ``exp`` may differ in the last bit; measured equal), and none at all for no exponent."""
    rng = np.random.default_rng(8)
    for _ in range(20):
        n = int(rng.integers(1, 9))
        re = np.round(rng.uniform(-0.3, 0.1, n), 1)  # ties between real parts
        im = rng.choice([0.0, 0.5, 0.5 + 0.5 * EDGE_TOL, 0.2, 0.37, 1e-12], n)
        sig = re + 1j * im
        kaps = rng.uniform(-0.5, 0.5, n)
        res = np.where(rng.uniform(size=n) < 0.3, np.nan, rng.uniform(0, 1e-10, n))
        got, ref = _families(sig, kaps, res, EDGE_TOL), _families_numpy(sig, kaps, res)
        assert np.array_equal(got[4], ref[4])
        for a, b in zip(got[:4:2], ref[:4:2], strict=True):
            assert np.array_equal(a, b)
        assert np.array_equal(got[3], ref[3], equal_nan=True)
        assert np.abs(got[1] - ref[1]).max() <= 1e-15 * np.abs(ref[1]).max()
    empty = np.zeros(0)
    assert _families(empty.astype(complex), empty, empty, EDGE_TOL)[0].size == 0


def test_state_summary_is_numpy_s():
    """The states per node and their changes over the period (:func:`_state_summary`, one
    compiled pass) against numpy's ``np.unique`` and ``np.roll`` on random runs of the three
    states, with a node that sticks all period and one that changes at the period's end."""
    rng = np.random.default_rng(6)
    state = np.repeat(rng.integers(0, 3, (5, 8)), 6, axis=1).astype(np.int8)
    state[0] = law.STICK
    state[1, -1] = (state[1, 0] + 1) % 3
    present, changes = _state_summary(state)
    for p in range(state.shape[0]):
        assert np.flatnonzero(present[p]).tolist() == np.unique(state[p]).tolist()
        assert changes[p] == np.count_nonzero(state[p] != np.roll(state[p], 1))
    assert changes[0] == 0 and changes[1] >= 2


def test_exponents_of_a_linear_response_are_the_structure_s_eigenvalues():
    """A contact that never closes: ``T(s) = Z(s)``, and the multipliers are ``e^{lambda T}``
    for the eigenvalues ``lambda`` of the structure's state matrix (the two masses and the
    separate tangential DOF), to rounding; every eigenvector is centred."""
    model = two_dof(gap=50.0)
    w = 0.7
    sol = solve_periodic(model, FourierBasis.up_to(7, 64), frequency=w / (2 * np.pi),
                         time_domain=None)
    res = stability(model, sol)
    K, C = np.diag([0.0, 0.0, 1.0]), np.diag([0.0, 0.0, 1.0])
    K[:2, :2], C[:2, :2] = K2, C2
    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-K, -C]])
    ref = np.exp(np.linalg.eigvals(A) * 2 * np.pi / w)
    got = res.multipliers
    assert got.size == ref.size
    for r in ref:
        assert np.min(np.abs(got - r)) < 1e-9
    assert np.all(np.abs(res.centroid) < 1e-9) and res.stable and res.reliable


def test_unilateral_two_dof_agrees_with_shooting_stable_and_period_doubled():
    """The two-DOF oscillator with a unilateral spring on its upper branch (contact during
    ~10 % of the period): at 0.60 rad/s the four multipliers of the two masses agree with
    shooting to 2e-3 (measured 1.3e-3 at 15 harmonics: the truncation of the kink of the
    contact force); at 0.76 rad/s one real multiplier is below -1 (period doubling, the
    exponent at ``Im s = w/2``), counted once, as shooting finds it (-1.55 and -1.47 at 15
    harmonics: the multiplier converges slowly with the harmonics there, 0.1 allowed)."""
    model = two_dof()
    basis = FourierBasis.up_to(15, 256)
    ws = np.arange(0.56, 0.765, 0.02)
    sols = continued(model, basis, ws)
    dyn = structure_dynamics(model)
    for w, sol, tol in ((ws[2], sols[2], 2e-3), (ws[-1], sols[-1], 0.1)):
        res = stability(model, sol, dyn=dyn)
        u, v = start_state(sol, ("x1", "x2"), w)
        ref = multipliers_by_shooting(two_dof_flow(w), np.concatenate([u, v]))
        # the separate tangential DOF is linear: e^{(-1/2 +- i sqrt(3)/2) T}
        main = res.multipliers[np.abs(np.abs(res.multipliers)
                                      - np.exp(-np.pi / w)) > 1e-6]
        assert main.size == 4
        main = main[np.argsort(-np.abs(main))]
        for r in ref:
            assert np.min(np.abs(main - r)) < tol * max(1.0, abs(r))
        assert res.stable == (np.abs(ref[0]) < 1)
    assert not res.stable and res.multipliers[0].real < -1 and res.multipliers[0].imag == 0


@pytest.mark.parametrize("w, force", [(1.18, 0.2), (1.1, 0.5)])
def test_jenkins_agrees_with_shooting(w, force):
    """A Jenkins oscillator that sticks 40-65 % of the period: the law's memory matters
    (``G(s)`` carries ``e^{-s h}`` through stick), the exponents are refined on the exact
    ``T(s)``, and the multipliers agree with shooting on ``(u, v, f)`` (whose third multiplier
    is 0: a slip resets the element's force) to 1e-2 (measured 6e-3 and 4e-3 at 15
    harmonics and 512 samples; 7 harmonics: 1.2e-2)."""
    model = jenkins(force)
    basis = FourierBasis.up_to(15, 512)
    sol = solve_periodic(model, basis, frequency=w / (2 * np.pi), time_domain=None)
    res = stability(model, sol)
    assert set(res.kind) == {"refined"} and res.multipliers.size == 2
    u, v = start_state(sol, ("x",), w)
    ref = multipliers_by_shooting(jenkins_flow(w, force), np.array([u[0], v[0],
                                                                    sol.lam_t[0, 1, 0]]))
    assert abs(ref[2]) < 1e-6
    for r in ref[:2]:
        assert np.min(np.abs(res.multipliers - r)) < 1e-2
    assert res.stable


def test_centroid_of_shifted_eigenvectors():
    """The centroid of ``p e^{i j w t}`` is that of ``p`` plus ``j`` (for content that stays
    in the kept harmonics): the sorting's invariant, on a hand-made vector."""
    k = 6
    rng = np.random.default_rng(1)
    c = np.zeros((2, 2 * k + 1), dtype=complex)  # complex-exponential coefficients -k..k
    c[:, k - 2:k + 3] = rng.standard_normal((2, 5)) + 1j * rng.standard_normal((2, 5))

    def real_layout(c):
        a0 = c[:, k]
        cp, cm = c[:, k + 1:], c[:, :k][:, ::-1]
        return np.concatenate([a0[:, None], cp + cm, 1j * (cp - cm)], axis=1)

    base = centroid(real_layout(c), k)
    assert centroid(real_layout(np.roll(c, 2, axis=1)), k) == pytest.approx(base + 2, abs=1e-12)
    assert centroid(real_layout(np.roll(c, -3, axis=1)), k) == pytest.approx(base - 3, abs=1e-12)


def test_compiled_centroid_equals_the_numpy_formula():
    """:func:`centroid` (compiled) against its formula written with numpy here
    (``sum_n n (|c_n|^2 - |c_-n|^2) / sum |c|^2`` on the real layout), on random vectors
    one at a time and in a batch of shape (2, 3, r, H): equal to rounding (1e-14 absolute
    on centroids of order 1: the two differ only in the order of the sums)."""
    k, r = 5, 3
    rng = np.random.default_rng(7)
    p = rng.standard_normal((2, 3, r, 2 * k + 1)) + 1j * rng.standard_normal((2, 3, r, 2 * k + 1))
    p[0, 0, :, 1:] *= 0.01  # mostly static content
    p[1, 2, :, 1 + k:] = 1j * p[1, 2, :, 1:1 + k]  # one-sided content: |kappa| large

    def numpy_centroid(p):
        a, b = p[..., 1:1 + k], p[..., 1 + k:]
        wp = np.sum(np.abs(a - 1j * b) ** 2, axis=-2) / 4.0
        wm = np.sum(np.abs(a + 1j * b) ** 2, axis=-2) / 4.0
        total = np.sum(np.abs(p[..., 0]) ** 2, axis=-1) + wp.sum(-1) + wm.sum(-1)
        return np.sum(np.arange(1, k + 1) * (wp - wm), axis=-1) / total

    ref = numpy_centroid(p)
    got = centroid(p, k)
    assert got.shape == (2, 3)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-14)
    assert abs(ref[1, 2]) > 1.0  # the one-sided vector is far off centre
    one = centroid(p[1, 1], k)
    assert isinstance(one, float) and abs(one - ref[1, 1]) <= 1e-14
    assert centroid(np.zeros((r, 2 * k + 1)), k) == 0.0


def test_shifted_copy_moves_the_coefficients_by_one_harmonic():
    """The start of the neighbouring copy's inverse iteration (:func:`_shifted_copy`): the
    eigenvector of ``s + i side`` is ``p e^{-i side w t}``, whose complex-exponential
    coefficient ``n`` is ``p``'s ``n + side``; the reference is that shift done on the
    hand-made coefficients (``np.roll``) and written in the real layout as in the test
    above, both normalised: equal to rounding (1e-14), and the centroid moved by ``-side``."""
    k = 6
    H = 2 * k + 1
    rng = np.random.default_rng(2)
    c = np.zeros((2, H), dtype=complex)
    c[:, k - 2:k + 3] = rng.standard_normal((2, 5)) + 1j * rng.standard_normal((2, 5))

    def real_layout(c):
        cp, cm = c[:, k + 1:], c[:, :k][:, ::-1]
        return np.concatenate([c[:, k:k + 1], cp + cm, 1j * (cp - cm)], axis=1)

    n = 2 * H
    red = QuadraticReduction(n, np.arange(n), np.zeros(0, dtype=int), None, *(
        np.zeros((n, n)) for _ in range(3)), [np.arange(n)])
    y = real_layout(c).reshape(-1)
    for side in (1, -1):
        got = _shifted_copy(red, 0, y, (2, H, k), side)
        ref = real_layout(np.roll(c, -side, axis=1)).reshape(-1)
        np.testing.assert_allclose(got, ref / np.linalg.norm(ref), rtol=0, atol=1e-14)
        assert centroid(got.reshape(2, H), k) == pytest.approx(
            centroid(y.reshape(2, H), k) - side, abs=1e-12)


def test_certified_copies_are_the_iterated_copies():
    """A tracked member's neighbouring copy ``s + i side`` (:func:`_copy`) is taken without
    its inverse iteration where the shifted eigenvector's backward error is below
    ``COPY_EXACT`` (the copy exact to rounding: a block whose law does not vary over the
    period, here the two-DOF oscillator's frictionless tangential DOF); the reference is the
    copy found by the inverse iteration from the same start (:func:`_member`, not folded).
    On the members of a point of the unilateral oscillator's resonance: some copies certified
    and some not (the contact block's, truncated), so both paths are
    covered; a certified copy's eigenvalue equal to the iterated one within 1e-13 of
    ``max(1, |s|)`` and its centroid within 1e-12 (both pairs are exact for pencils within
    rounding of the problem's, and the copies are simple eigenvalues far from the others);
    an iterated one the same within 1e-12 (the same steps). The backward error is
    checked against Tisseur's formula with the matrices' 2-norms: never below it (the column
    norms are lower bounds of the 2-norm), within a factor ``sqrt(n)`` above it."""
    model = two_dof()
    basis = FourierBasis.up_to(5, 64)
    sol = solve_periodic(model, basis, frequency=0.6 / (2 * np.pi), time_domain=None)
    prob = problem_of(model, sol)
    hp = HillProblem(prob, sol.U.reshape(prob.m, prob.H), structure_dynamics(model))
    assert hp.regime()[0][1] > 0  # the contact closes and opens: its block is truncated
    red = reduce_quadratic(*hp.pencil())
    res = hill_module.hill_stability(prob, sol.U.reshape(prob.m, prob.H),
                                     structure_dynamics(model))
    track = res.track
    assert track is not None and track.sigma.size >= 3
    k = len(basis.harmonics)
    shape = (prob.m + hp.dyn.q, prob.H, k)
    mats: dict = {}
    certified = 0
    for j, (s, b) in enumerate(zip(track.sigma, track.block, strict=True)):
        y = track.Y[red.blocks[b], j]
        kp = centroid(red.full(track.Y[:, j:j + 1])[:, 0].reshape(-1, prob.H), k)
        side = 1 if kp >= 0 else -1
        s2, y2, k2, cert = _copy(red, b, complex(s), y, shape, mats, side)
        start = _shifted_copy(red, b, y, shape, side)
        ref = _member(red, b, complex(s) + 1j * side, start, shape, mats, fold=False)
        assert ref is not None
        B0, B1, B2 = _block_mats(red, b, shape, mats)[0]
        sigma = complex(s) + 1j * side
        eta = _backward_error(B0, B1, B2, sigma, start, _block_mats(red, b, shape, mats)[5])
        tis = np.linalg.norm((B0 + sigma * B1 + sigma ** 2 * B2) @ start) / (
            np.linalg.norm(B0, 2) + abs(sigma) * np.linalg.norm(B1, 2)
            + abs(sigma) ** 2 * np.linalg.norm(B2, 2)) / np.linalg.norm(start)
        assert tis * (1 - 1e-12) <= eta <= np.sqrt(B0.shape[0]) * tis * (1 + 1e-12)
        assert cert == (eta <= COPY_EXACT)
        certified += cert
        tol = 1e-13 if cert else 1e-12
        assert abs(s2 - ref[0]) <= tol * max(1.0, abs(s2))
        assert abs(k2 - ref[2]) <= 1e-12
    assert 0 < certified < track.sigma.size


@pytest.mark.parametrize("diagonal", [True, False])
def test_algebraic_coordinates_eliminated_by_the_schur_complement(diagonal):
    """``reduce_quadratic`` on 30 coordinates of which 12 (scattered) have no mass nor
    damping: ``B0`` is the Schur complement ``A0[d, d] - A0[d, a] A0[a, a]^-1 A0[a, d]``
    formed by numpy's solve and product, ``back`` its ``-A0[a, a]^-1 A0[a, d]``, to 1e-13
    (the compiled elimination over the nonzero terms when ``A0[a, a]`` is diagonal,
    LAPACK's solve when not: the same terms summed in another order; the pivots are O(1)
    apart from zero), and ``B1``, ``B2`` the rows and columns of ``d`` exactly."""
    rng = np.random.default_rng(8)
    n = 30
    alg = np.sort(rng.choice(n, 12, replace=False))
    dyn = np.setdiff1d(np.arange(n), alg)
    A0 = rng.standard_normal((n, n))
    A0[np.ix_(alg, alg)] = np.diag(2.0 + rng.random(12)) if diagonal else (
        3.0 * np.eye(12) + 0.3 * rng.standard_normal((12, 12)))
    A0[np.ix_(dyn, alg)] *= rng.random((dyn.size, 12)) < 0.3  # sparse couplings
    A1, A2 = np.zeros((n, n)), np.zeros((n, n))
    A1[np.ix_(dyn, dyn)] = rng.standard_normal((dyn.size, dyn.size))
    A2[np.ix_(dyn, dyn)] = np.eye(dyn.size)
    red = reduce_quadratic(A0, A1, A2)
    assert np.array_equal(red.dyn, dyn) and np.array_equal(red.alg, alg)
    back = -np.linalg.solve(A0[np.ix_(alg, alg)], A0[np.ix_(alg, dyn)])
    ref = A0[np.ix_(dyn, dyn)] + A0[np.ix_(dyn, alg)] @ back
    assert np.abs(red.back - back).max() <= 1e-13 * np.abs(back).max()
    assert np.abs(red.B0 - ref).max() <= 1e-13 * np.abs(ref).max()
    assert np.array_equal(red.B1, A1[np.ix_(dyn, dyn)])
    assert np.array_equal(red.B2, A2[np.ix_(dyn, dyn)])


def test_quadratic_problem_split_into_its_blocks_keeps_every_eigenpair():
    """A quadratic problem that decouples into a 60-unknown block and 40 single unknowns
    (scattered by a permutation, with rounding-size couplings of 1e-17 between them, as the
    law's ``P Q = I`` leaves) against the dense companion eigensolve of the whole: the same
    eigenvalues (1e-10 relative, the conditioning of a random companion matrix: rounding is
    1e-14) and every eigenvector a null vector of its ``A0 + s A1 + s^2 A2`` (1e-9)."""
    rng = np.random.default_rng(3)
    n = 100
    mats = [np.zeros((n, n)) for _ in range(3)]
    for X, scale in zip(mats, (10.0, 0.1, 1.0), strict=True):
        X[:60, :60] = scale * rng.standard_normal((60, 60))
        X[60:, 60:] = np.diag(scale * (1.0 + rng.random(40)))
        X += 1e-17 * rng.standard_normal((n, n))
    mats[2][:60, :60] += 10 * np.eye(60)
    perm = rng.permutation(n)
    A0, A1, A2 = (X[np.ix_(perm, perm)] for X in mats)
    assert sorted(map(len, _components(A0, A1, A2))) == [40, 60]
    vals, vecs = quadratic_eigen(A0, A1, A2)
    ref, _ = _companion_eigen(A0, A1, A2)
    assert vals.size == ref.size == 2 * n
    a = vals[np.lexsort((vals.imag, vals.real))]
    b = ref[np.lexsort((ref.imag, ref.real))]
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10 * np.abs(b).max())
    for s, y in zip(vals, vecs.T, strict=True):
        r = (A0 + s * A1 + s * s * A2) @ y
        scale = (np.linalg.norm(A0) + abs(s) * np.linalg.norm(A1)
                 + abs(s) ** 2 * np.linalg.norm(A2)) * np.linalg.norm(y)
        assert np.linalg.norm(r) < 1e-9 * scale


def _quadratic_starts(seed: int, n: int):
    """A random quadratic problem ``B0 + s B1 + s^2 I`` of ``n`` coordinates and three starts
    ``(eigenvalue, start, y0)`` of an inverse iteration: 1e-3 off three of its eigenvalues
    (every other one by decreasing imaginary part, from the companion eigensolve), the
    eigenvector perturbed by 1e-3."""
    rng = np.random.default_rng(seed)
    B0, B1 = rng.standard_normal((2, n, n))
    B2 = np.eye(n)
    vals, Y = _companion_eigen(B0, B1, B2)
    starts = [(vals[i], vals[i] + 1e-3 * (1 + 1j), Y[:, i] + 1e-3 * rng.standard_normal(n))
              for i in np.argsort(-np.abs(vals.imag))[:6:2]]
    return B0, B1, B2, starts
