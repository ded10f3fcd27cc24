"""Tests of the exact per-harmonic condensation on the contact DOFs (fretwear.hb.reduce).

The model is a hand-assembled 2D truss (independent of the FE layer). Every reference is a
*dense* solve of the full model written from the equation of motion in core.py,

    Z_n U + T^T lambda = F_n   on the free DOFs,   u_loc = T U,

with numpy.linalg (not the sparse LU used by reduce), for arbitrary contact forces lambda, so
that the condensed relation ``Z_r u_loc + lambda = F_r`` is checked for every contact state.
Tolerances: relative errors of a well-conditioned dense solve are ~ cond * 1e-16; near a
resonance (0.999 f) the amplification is ~1e3, so 1e-9 relative leaves a wide margin while any
formula error (a missing term, a wrong sign or frame) gives O(1) errors.
"""

import numpy as np
import pytest
import scipy.linalg as sla
from helpers.models import RNG, oscillator, sliders, truss

from fretwear.errors import InputError
from fretwear.hb import reduce
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.reduce import (
    condense,
    condense_static,
    exact_condenser,
    loads_to_real,
    recover,
    to_real_blocks,
)

RTOL = 1e-9


@pytest.fixture(autouse=True, params=["batched", "dense", "sparse"])
def condensation_path(request, monkeypatch):
    """Every test runs on the three paths of the condensation: every harmonic in one batched
    LAPACK solve (tiny models, reduce.BATCH_MAX), LAPACK per harmonic on dense blocks (small
    models, reduce.DENSE_MAX) and SuperLU with blocked multi-right-hand-side solves (BLOCK = 5
    columns, so the 12 contact DOFs of the truss take three blocks)."""
    monkeypatch.setattr(reduce, "DENSE_MAX", -1 if request.param == "sparse" else 10**9)
    monkeypatch.setattr(reduce, "BATCH_MAX", 10**9 if request.param == "batched" else -1)
    monkeypatch.setattr(reduce, "BLOCK", 5)
    return request.param


def dense_Z(model, omega, n):
    """Z_n written from the docstring of core.Model (independent of reduce.dynamic_stiffness)."""
    K = model.K.toarray()
    if n == 0:
        return K.astype(complex)
    w = n * omega
    Z = K - w**2 * model.M.toarray() + 0j
    if model.D is not None:
        Z += 1j * model.D.toarray()
    if model.C is not None:
        Z += 1j * w * model.C.toarray()
    return Z


def full_solve(model, Z, F, lam):
    """Dense solve of Z U + T^T lam = F with the fixed DOFs held; returns all DOFs."""
    T = model.contact.local_transform(model.ndof).toarray()
    free = model.free_dofs()
    U = np.zeros(model.ndof, dtype=complex)
    U[free] = np.linalg.solve(Z[np.ix_(free, free)], (F - T.T @ lam)[free])
    return U


def free_eigenfrequencies(model):
    """Undamped eigenfrequencies [rad/s] of the structure with a free interface (dense)."""
    free = model.free_dofs()
    lam = sla.eigh(model.K.toarray()[np.ix_(free, free)], model.M.toarray()[np.ix_(free, free)],
                   eigvals_only=True)
    return np.sqrt(lam)


def rel(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


@pytest.mark.parametrize("damping", ["hysteretic", "rayleigh", "both"])
def test_condensed_response_equals_full_solve(damping):
    """For random contact forces lambda, the reduced equation Z_r u + lambda = F_r gives the
    contact-local displacements of the full dense solve, and obs_A u + obs_b the observed DOFs,
    at several frequencies including 0.999 x an eigenfrequency, harmonics 0..3 (static, cos,
    sin and 'fourier' loads), with tilted contact frames."""
    model = truss(damping=damping)
    T = model.contact.local_transform(model.ndof).toarray()
    wn = free_eigenfrequencies(model)
    orders = np.array([0, 1, 2, 3])
    obs = np.concatenate([p.dofs for p in model.observed])
    for f in np.array([0.31 * wn[0], 0.999 * wn[2], 1.7 * wn[4]]) / (2 * np.pi):
        red = condense(model, f, orders)
        omega = red.omega
        F_all = model.load_harmonics(3)
        for b, n in enumerate(orders):
            lam = RNG.standard_normal(red.m) + 1j * RNG.standard_normal(red.m) * (n > 0)
            U = full_solve(model, dense_Z(model, omega, n), F_all[n], lam)
            u_ref = T @ U
            u = np.linalg.solve(red.Z[b], red.F[b] - lam)
            assert rel(u, u_ref) < RTOL
            np.testing.assert_allclose(red.obs_A[b] @ u + red.obs_b[b], U[obs], rtol=0,
                                       atol=RTOL * np.abs(U).max())
        np.testing.assert_array_equal(red.obs_dofs, obs)


def test_recover_equals_full_solve():
    """recover() from the contact solution gives every DOF of the full dense solve (fixed DOFs
    exactly zero), here with a stuck-like state lambda != 0 and a tilted frame."""
    model = truss(damping="both")
    T = model.contact.local_transform(model.ndof).toarray()
    f = 0.8 * free_eigenfrequencies(model)[1] / (2 * np.pi)
    omega = 2 * np.pi * f
    orders = np.array([0, 1, 3])
    F_all = model.load_harmonics(3)
    lams = RNG.standard_normal((orders.size, 2 * 6))
    U_ref = np.array([full_solve(model, dense_Z(model, omega, n), F_all[n], lam)
                      for n, lam in zip(orders, lams, strict=True)])
    U = recover(model, f, orders, U_ref @ T.T)
    assert rel(U, U_ref) < RTOL
    assert np.all(U[:, model.fixed_dofs] == 0)


def test_quasi_static_equals_static_solve_for_every_harmonic():
    """quasi_static=True drops inertia and damping: for every harmonic the reduced equation
    must reproduce the static solve K U + T^T lambda = F_n (dense), and Z_r be the same for all
    harmonics (the static condensation of K)."""
    model = truss(damping="both")
    T = model.contact.local_transform(model.ndof).toarray()
    orders = np.array([0, 1, 2, 3])
    red = condense(model, 1234.0, orders, quasi_static=True)
    assert red.quasi_static
    K = model.K.toarray().astype(complex)
    F_all = model.load_harmonics(3)
    obs = np.concatenate([p.dofs for p in model.observed])
    for b, n in enumerate(orders):
        np.testing.assert_allclose(red.Z[b], red.Z[0], rtol=0, atol=0)
        lam = RNG.standard_normal(red.m) + 1j * RNG.standard_normal(red.m)
        U = full_solve(model, K, F_all[n], lam)
        u = np.linalg.solve(red.Z[b], red.F[b] - lam)
        assert rel(u, T @ U) < RTOL
        assert rel(red.obs_A[b] @ u + red.obs_b[b], U[obs]) < RTOL
    # the static reduced stiffness is real and symmetric
    assert np.abs(red.Z[0].imag).max() == 0
    np.testing.assert_allclose(red.Z[0], red.Z[0].T, rtol=1e-12, atol=0)


def test_spectral_radius_against_flexibility():
    """Largest |eig Z_r| computed independently: Z_r^-1 is the contact block of the full
    dense flexibility Z^-1 in local frames (inverse of a Schur complement = block of the
    inverse), so rho(Z_r) = 1 / min |eig(T Z^-1 T^T)|."""
    model = truss(damping="hysteretic")
    orders = np.array([0, 1, 2])
    red = condense(model, 0.5 * free_eigenfrequencies(model)[0] / (2 * np.pi), orders)
    omega = red.omega
    T = model.contact.local_transform(model.ndof).toarray()
    free = model.free_dofs()
    Tf = T[:, free]
    rho = 0.0
    for n in orders:
        Z = dense_Z(model, omega, n)[np.ix_(free, free)]
        G = Tf @ np.linalg.solve(Z, Tf.T)
        rho = max(rho, 1.0 / np.min(np.abs(np.linalg.eigvals(G))))
    assert red.spectral_radius() == pytest.approx(rho, rel=1e-9)


def test_singular_interior_raises_input_error():
    """A node hanging on one bar from a contact node has a transverse mechanism the contact
    does not hold: its static (n = 0, or quasi-static) interior stiffness is singular."""
    model = truss(dangling=True)
    with pytest.raises(InputError, match="singular"):
        condense(model, 100.0, [0, 1])
    with pytest.raises(InputError, match="singular"):
        condense(model, 100.0, [1], quasi_static=True)
    # with inertia (n >= 1, omega > 0) the mass holds it: no error
    condense(model, 100.0, [1])


def test_contact_dof_cannot_be_fixed():
    """A contact DOF that is also a Dirichlet DOF is contradictory input: InputError."""
    model = truss()
    model.fixed_dofs = np.append(model.fixed_dofs, 0)
    with pytest.raises(InputError, match="fixed"):
        condense(model, 10.0, [0])


def test_real_blocks_match_time_domain_operator():
    """to_real_blocks/loads_to_real vs the time-domain operator K u + C u' + M u'' applied to
    the real Fourier coefficients with the derivative matrix of fretwear.hb.fourier (tested on its
    own in test_fourier): the sign convention of eq. (18) for viscous damping."""
    model = truss(nx=3, ny=2, damping="rayleigh")
    omega = 900.0
    basis = FourierBasis((1, 2, 3), 16)
    orders = basis.orders
    Zc = np.array([dense_Z(model, omega, n) for n in orders])
    R = to_real_blocks(Zc, orders)
    nd, H = model.ndof, basis.size
    c = RNG.standard_normal((nd, H))  # coefficients per DOF, [0, cos.., sin..]
    D = basis.derivative_matrix(omega)
    K, C, M = (A.toarray() for A in (model.K, model.C, model.M))
    ref = K @ c + C @ c @ D.T + M @ c @ (D @ D).T
    np.testing.assert_allclose((R @ c.reshape(-1)).reshape(nd, H), ref, rtol=0,
                               atol=1e-12 * np.abs(ref).max())
    F = model.load_harmonics(3)
    samples = model.load_time(basis.tau)  # exact load samples (N, ndof)
    np.testing.assert_allclose(loads_to_real(F), basis.to_freq(samples.T), rtol=0, atol=1e-12)


def test_a_condenser_refuses_another_model_or_an_edited_one():
    """A condenser belongs to the model it was built for: handed another model (here a truss of
    other damping, the same shape), or its own model after a matrix was replaced or edited in
    place, every entry point refuses it with one line naming ``condenser`` instead of
    condensing the wrong structure. A new condenser of the edited model gives the condensation
    of a fresh model with the same matrix (exact comparison: the same operations)."""
    model = truss(damping="both")
    cond = exact_condenser(model)
    condense(model, 10.0, [0, 1], condenser=cond)  # its own model: accepted
    other = truss(damping="hysteretic")
    u_loc = np.zeros((2, 12))
    for call in (lambda m: condense(m, 10.0, [0, 1], condenser=cond),
                 lambda m: recover(m, 10.0, [0, 1], u_loc, condenser=cond),
                 lambda m: condense_static(m, condenser=cond)):
        with pytest.raises(InputError, match="condenser: built for another model") as err:
            call(other)
        assert "\n" not in str(err.value)
    model.K.data[0] *= 1.5  # in place: seen by the fingerprint
    with pytest.raises(InputError, match="condenser"):
        condense(model, 10.0, [0, 1], condenser=cond)
    edited = exact_condenser(model)
    model.K = model.K.tocsr(copy=True)  # the same values in another matrix: another model
    with pytest.raises(InputError, match="condenser"):
        edited.check(model)
    with pytest.raises(InputError, match="condenser = int object"):
        condense(model, 10.0, [0, 1], condenser=42)
    red = condense(model, 10.0, [0, 1], condenser=exact_condenser(model))
    fresh = truss(damping="both")
    fresh.K, fresh.loads = model.K.copy(), model.loads  # (truss() gives these loads too)
    ref = condense(fresh, 10.0, [0, 1])
    np.testing.assert_array_equal(red.Z, ref.Z)
    np.testing.assert_array_equal(red.F, ref.F)


def test_exact_condenser_equals_a_dense_schur_complement():
    """The condensation of one condenser reused across frequencies, harmonics and calls on
    other models equals eq. 19 written densely from the model's matrices (numpy solves, not
    the sparse or batched LU of reduce): ``Z_r = R (Z_cc - Z_ci Z_ii^-1 Z_ic) R^T``,
    ``F_r = R (F_c - Z_ci Z_ii^-1 F_i)``. Tolerance RTOL (module docstring: conditioning up to
    ~1e3 near a resonance). And a condenser reused is bit for bit a new one per call (the
    behaviour of the module cache it replaces): the same operations on the same arrays."""
    model = truss(damping="both")
    cond = exact_condenser(model)
    cd = model.contact.dofs.reshape(-1)
    idofs = np.setdiff1d(model.free_dofs(), cd)
    R = sla.block_diag(*model.contact.frame)
    orders = np.array([0, 1, 2, 3])
    F_all = model.load_harmonics(3)
    wn = free_eigenfrequencies(model)
    for f in np.array([0.31 * wn[0], 0.999 * wn[2], 1.7 * wn[4]]) / (2 * np.pi):
        condense(truss(nx=4, damping="rayleigh"), f, orders)  # another model in between
        red = condense(model, f, orders, condenser=cond)
        for b, n in enumerate(orders):
            Z = dense_Z(model, red.omega, n)
            X = np.linalg.solve(Z[np.ix_(idofs, idofs)],
                                np.column_stack([Z[np.ix_(idofs, cd)], F_all[n][idofs]]))
            S = Z[np.ix_(cd, cd)] - Z[np.ix_(cd, idofs)] @ X[:, :-1]
            Fr = F_all[n][cd] - Z[np.ix_(cd, idofs)] @ X[:, -1]
            assert rel(red.Z[b], R @ S @ R.T) < RTOL
            assert rel(red.F[b], R @ Fr) < RTOL
        new = condense(model, f, orders)  # a new condenser for this call alone
        for name in ("Z", "F", "obs_A", "obs_b"):
            np.testing.assert_array_equal(getattr(red, name), getattr(new, name))


def test_loads_are_read_at_each_call():
    """The loads may change between calls while the structure does not: a condenser reads the
    model's loads at each call (``F_r`` then equals a new condenser's exactly), and keeps its
    structure (the same ``Z_r``)."""
    model = truss(damping="both")
    cond = exact_condenser(model)
    before = condense(model, 40.0, [0, 1, 2], condenser=cond)
    model.loads[1].vector *= 3.0  # the "cos" load, in place
    model.loads = model.loads[:2]  # and the "sin" and "fourier" loads dropped
    after = condense(model, 40.0, [0, 1, 2], condenser=cond)
    ref = condense(model, 40.0, [0, 1, 2])
    np.testing.assert_array_equal(after.F, ref.F)
    np.testing.assert_array_equal(after.Z, before.Z)
    assert rel(after.F[1], before.F[1]) > 0.1


@pytest.fixture
def constructions(monkeypatch):
    """The number of condensers built (exact or modal) while the test runs."""
    count = [0]
    init = reduce.Condenser.__init__

    def counting(self, *args, **kwargs):
        count[0] += 1
        init(self, *args, **kwargs)

    monkeypatch.setattr(reduce.Condenser, "__init__", counting)
    return count


def test_one_driver_call_builds_one_condenser(constructions):
    """Every driver call that condenses builds one condenser for all its condensations (the
    periodic solve's condensation, its penalty and its static preload; a sweep's penalty
    samples, points and preload; a wear run's condensation and preload; a condensed FRF's
    frequencies), and none when one is passed. Counted by a wrapper of Condenser.__init__:
    with every condensation building its own, the first three build 4, 4 and 3 (measured)."""
    from fretwear.hb.periodic import solve_periodic
    from fretwear.hb.sweep import sweep
    from fretwear.linear import frf
    from fretwear.wear import BalanceSetup, WearOptions, simulate_wear

    model = oscillator()
    basis = FourierBasis.up_to(3, 64)
    wear_model = sliders()
    wear_opts = WearOptions(max_cycles=2e4, initial_jump=1e4, adaptive=False)
    runs = {
        "solve_periodic": lambda c: solve_periodic(model, basis, frequency=10.0, eps="static",
                                                   condenser=c),
        "sweep": lambda c: sweep(model, basis, 8.0, 12.0, 3, condenser=c),
        "simulate_wear": lambda c: simulate_wear(wear_model, basis, quasi_static=True,
                                                 options=wear_opts,
                                                 balance=BalanceSetup(condenser=c)),
        "frf": lambda c: frf(truss(), [10.0, 20.0, 30.0], method="condensed", condenser=c),
    }
    for name, run in runs.items():
        constructions[0] = 0
        out = run(None)
        assert getattr(out, "success", True), name
        assert constructions[0] == 1, name
    for name, m in (("solve_periodic", model), ("sweep", model),
                    ("simulate_wear", wear_model)):
        cond = exact_condenser(m)
        constructions[0] = 0
        runs[name](cond)
        assert constructions[0] == 0, name


def test_a_condensation_that_cannot_fit_is_refused_before_it_allocates(monkeypatch):
    """Harmonics 10000 (the issue's case, with 20001 samples): the condensation of the truss
    is refused in one line with its estimate and the machine's memory before any block is
    formed, here on a machine said to hold 4 GiB: the Fourier basis it needs alone is
    8 x 20002 x 20001 x 4 bytes = 12.8 GB, written out by hand. The paper's 7 harmonics on
    the same machine condense as before (the check does not refuse what fits)."""
    from fretwear import resources

    monkeypatch.setattr(resources, "machine_memory", lambda: 4 * 2**30)
    model = truss()
    cond = reduce.exact_condenser(model)
    with pytest.raises(InputError) as err:
        cond.reduced(2 * np.pi * 100.0, np.arange(10001))
    msg = str(err.value)
    assert "10001 harmonic orders (up to 10000)" in msg and "this machine has 4 GiB" in msg
    assert "\n" not in msg
    est = float(msg.split("needs about ")[1].split(" GiB")[0]) * 2**30
    assert est >= 8.0 * 20002 * 20001 * 4
    red = cond.reduced(2 * np.pi * 100.0, np.arange(8))
    assert red.Z.shape[0] == 8
