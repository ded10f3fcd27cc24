"""The large-interface Newton step (fretwear.hb.krylov) against the dense path of
fretwear.hb.periodic.

References: the formed Jacobian of the dense path (``J = eps (I - G) + G Z`` built by
DLFTProblem.residual with jacobian="dense", LAPACK LU), which is independent of the operator
products, the active-node reduction and GMRES tested here. Small 2D and 3D blocks are loaded
so that separation, stick and slip all occur during the period (asserted).

Tolerances: the operator products are the same sums in another order (1e-12 relative to the
largest entry); the converged solutions are compared at a residual tolerance of 1e-12, where
two exact-step solvers agree to ~1e-13 (measured 2e-13 to 5e-12 on these cases): 1e-8 is the
acceptance of the issue and a wrong Jacobian product or step would not converge or would
stop at a different point.
"""

import numpy as np
import pytest
from helpers.blocks import block

from fretwear.hb import contact as law
from fretwear.hb import krylov
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.krylov import KrylovJacobian
from fretwear.hb.options import KRYLOV, KrylovOptions
from fretwear.hb.preload import static_anchor
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.hb.solvers import solve


def problem(model, jacobian, nh=3):
    basis = FourierBasis.up_to(nh, 32)
    red = condense(model, 2000.0, basis.orders)
    return DLFTProblem(red, model.contact, basis, eps="auto", anchor=static_anchor(model),
                       jacobian=jacobian)


def run(prob, tol=1e-12, x0=None):
    def fun(x, jac=True):
        return prob.residual(x.reshape(prob.m, prob.H), jac)

    x0 = prob.initial_guess().reshape(-1) if x0 is None else x0
    x, _, st = solve(fun, x0,
                     lambda x: prob.scale(x.reshape(prob.m, prob.H)), tol=tol)
    assert st.success, st.message
    return x


@pytest.fixture(scope="module", params=[(2, 0.0), (3, 0.0), (2, 0.05), (3, 0.05)],
                ids=["2", "3", "2-damped", "3-damped"])
def case(request):
    """Undamped blocks (real Z_r blocks: the operator's real-arithmetic path) and damped ones
    (complex blocks: the complex path), each with every contact state."""
    dim, eta = request.param
    model = block(dim, eta)
    dense = problem(model, "dense")
    x = run(dense)
    _, _, state, _ = dense.time_law(x.reshape(dense.m, dense.H))
    for s in (law.SEPARATION, law.STICK, law.SLIP):
        assert np.any(state == s), f"no {law.STATE_NAMES[s]} in the {request.param} case"
    assert problem(model, "krylov").blocks.real == (eta == 0.0)
    return model, x


def test_operator_products_equal_the_formed_jacobian(case):
    """J @ x, J.T @ x and the column norms of the operator equal those of the dense path's
    formed Jacobian at the solution (every contact state present in G)."""
    model, x = case
    dense = problem(model, "dense")
    op = problem(model, "krylov")
    _, J = dense.residual(x.reshape(dense.m, dense.H), True)
    _, Jo = op.residual(x.reshape(op.m, op.H), True)
    assert isinstance(Jo, KrylovJacobian)
    v = np.random.default_rng(1).standard_normal(J.shape[0])
    scale = np.abs(J).max() * np.abs(v).sum()
    assert np.abs(Jo @ v - J @ v).max() < 1e-12 * scale
    assert np.abs(Jo.T @ v - J.T @ v).max() < 1e-12 * scale
    np.testing.assert_allclose(Jo.column_norms(chunk=5), np.linalg.norm(J, axis=0),
                               rtol=1e-12)
    np.testing.assert_allclose(Jo.toarray(), J, rtol=0, atol=1e-13 * np.abs(J).max())


@pytest.mark.parametrize("step", ["active", "gmres"])
def test_converged_answer_equals_dense_path(case, step, monkeypatch):
    """The periodic solution with the operator Jacobian (step reduced to the active nodes and
    solved by LU, or by preconditioned GMRES) equals the dense path's to 1e-8 relative. In 3D
    the GMRES variant starts from 0.9 times the solution (from rest Powell takes ~50
    iterations there, each with ~100 GMRES iterations: 35 s)."""
    model, x_ref = case
    x0 = None
    if step == "gmres":
        monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
        x0 = 0.9 * x_ref if model.dim == 3 else None
    x = run(problem(model, "krylov"), x0=x0)
    assert np.abs(x - x_ref).max() <= 1e-8 * np.abs(x_ref).max()


@pytest.mark.parametrize("limit", [10**9, -1], ids=["active-lu", "active-gmres"])
def test_step_equals_lu_step(case, limit, monkeypatch):
    """One Newton step: the active-node reduction solved by LU or by GMRES gives the LU
    solution of the formed Jacobian (to 1e-9 relative at 0.9 times the solution: GMRES stops
    at 1e-10 of the residual; the LU is exact to rounding), for one and several right-hand
    sides (the wear rate's dU/dW). Near the solution of the 2D case some nodes stick all
    period, so the stuck unknowns are eliminated: the step's residual with the formed
    Jacobian is then at most 1e-9 of the right-hand side (GMRES's 1e-10 on the active rows,
    the stuck rows exact)."""
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", limit)
    model, x = case
    dense, op = problem(model, "dense"), problem(model, "krylov")
    x1 = 0.9 * x  # off the solution: a non-trivial step with every state present
    f, J = dense.residual(x1.reshape(dense.m, dense.H), True)
    _, Jo = op.residual(x1.reshape(op.m, op.H), True)
    ref = np.linalg.solve(J, f)
    assert np.abs(Jo.solve(f) - ref).max() <= 1e-9 * np.abs(ref).max()
    B = np.random.default_rng(3).standard_normal((f.size, 3))
    ref = np.linalg.solve(J, B)
    assert np.abs(Jo.solve(B) - ref).max() <= 1e-9 * np.abs(ref).max()
    if model.dim == 2:
        x2 = x * (1.0 + 1e-3 * np.random.default_rng(5).standard_normal(x.size))
        f, J = dense.residual(x2.reshape(dense.m, dense.H), True)
        _, Jo = op.residual(x2.reshape(op.m, op.H), True)
        assert 0 < Jo.active_nodes().size < Jo.nc
        for rhs in (f, B):
            s = Jo.solve(rhs)
            assert np.linalg.norm(J @ s - rhs) <= 1e-9 * np.linalg.norm(rhs)


@pytest.mark.parametrize("real", [False, True, "float"], ids=["complex", "real", "float"])
@pytest.mark.parametrize("symmetric", [True, False])
def test_harmonic_blocks_products_equal_real_blocks(symmetric, real):
    """Z~ U, Z~^T U, the products on a subset of rows and columns and the node rows by
    harmonic blocks equal the products with the formed real operator (reduce.to_real_blocks,
    independent code) for complex symmetric blocks (the shortcut Z^H = conj(Z)) and general
    ones (the transposed copy), complex and real-valued (the real-arithmetic path of
    undamped structures); rounding only: 1e-13 of the largest term."""
    rng = np.random.default_rng(2)
    Zc = rng.standard_normal((4, 6, 6)) + 1j * rng.standard_normal((4, 6, 6)) * (not real)
    Zc[0] = Zc[0].real
    if symmetric:
        Zc = Zc + np.transpose(Zc, (0, 2, 1))
    if real == "float":  # stored real (an undamped modal reduced model): used without copy
        Zc = Zc.real.copy()
    hb = krylov.HarmonicBlocks(Zc)
    assert hb.real == bool(real)
    if real == "float":
        assert hb.Zr is hb.Zc
    Zd = hb.dense()
    U = rng.standard_normal((6, 7))
    assert hb.symmetric() == symmetric
    np.testing.assert_allclose(hb.apply(U).reshape(-1), Zd @ U.reshape(-1), rtol=0, atol=1e-13 * 50)
    np.testing.assert_allclose(hb.apply_T(U).reshape(-1), Zd.T @ U.reshape(-1), rtol=0,
                               atol=1e-13 * 50)
    rows, cols = np.array([0, 2, 5]), np.array([1, 2, 4])
    Us = rng.standard_normal((3, 7, 2))
    Ufull = np.zeros((6, 7, 2))
    Ufull[cols] = Us
    ref = (Zd @ Ufull.reshape(42, 2)).reshape(6, 7, 2)[rows]
    np.testing.assert_allclose(hb.apply_sub(rows, cols, Us), ref, rtol=0, atol=1e-13 * 50)
    V = rng.standard_normal((2, 21))  # 2 nodes of 3 DOFs, node-major (DOF, coefficient)
    ref = np.stack([V[p] @ Zd[p * 21 : (p + 1) * 21] for p in range(2)])
    np.testing.assert_allclose(hb.node_rows(V), ref, rtol=0, atol=1e-13 * 50)


def test_arclength_step_with_the_operator_equals_the_bordered_lu(case):
    """The arclength Newton step of a sweep with the operator Jacobian (block elimination, two
    solves) equals the LU of the formed bordered matrix (numpy.linalg.solve on the dense
    path's Jacobian): 1e-9 relative, the accuracy of the step (test above)."""
    from fretwear.hb.arclength import bordered_step

    model, x = case
    dense, op = problem(model, "dense"), problem(model, "krylov")
    x1 = 0.9 * x
    f, J = dense.residual(x1.reshape(dense.m, dense.H), True)
    _, Jo = op.residual(x1.reshape(op.m, op.H), True)
    rng = np.random.default_rng(4)
    fw, t = rng.standard_normal(f.size), rng.standard_normal(f.size + 1)
    ref = bordered_step(J, f, fw, 0.3, t, 2.0, 5.0)
    got = bordered_step(Jo, f, fw, 0.3, t, 2.0, 5.0)
    assert np.abs(got - ref).max() <= 1e-9 * np.abs(ref).max()


@pytest.mark.parametrize("limit", [10**9, -1], ids=["active-lu", "active-gmres"])
def test_real_storage_gives_the_same_answer(limit, monkeypatch):
    """An undamped reduced model stored real (as fretwear.hb.modal stores it) solved by the
    operator path (active LU, or GMRES with its shared real factors) against the same blocks
    stored complex solved by the dense path (the formed Jacobian, reduce.to_real_blocks,
    independent of the operator): both converge to 1e-12, so the answers agree to the 1e-8 of
    the module docstring; a wrong real-storage path (a block dropped, a sign) would not
    converge or would converge elsewhere. The GMRES variant starts from 0.9 times the
    reference, as test_converged_answer_equals_dense_path (from rest: 12 s)."""
    import dataclasses

    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", limit)
    model = block(3, 0.0)
    basis = FourierBasis.up_to(3, 32)
    red = condense(model, 2000.0, basis.orders)
    assert np.iscomplexobj(red.Z) and not np.any(red.Z.imag)
    anchor = static_anchor(model)
    ref = run(DLFTProblem(red, model.contact, basis, eps="auto", anchor=anchor,
                          jacobian="dense"))
    real = dataclasses.replace(red, Z=red.Z.real.copy())
    prob = DLFTProblem(real, model.contact, basis, eps="auto", anchor=anchor,
                       jacobian="krylov")
    assert prob.blocks.Zr is prob.blocks.Zc  # used as stored, no copy
    x = run(prob, x0=0.9 * ref if limit < 0 else None)
    assert np.abs(x - ref).max() <= 1e-8 * np.abs(ref).max()


def test_preconditioner_shares_factors_only_between_close_harmonics():
    """A harmonic uses the LU of the last factored one when ``E = P_b^-1 gbar (Z_n - Z_b)``
    is small (MeanGainPreconditioner._close, a two-step power estimate). Reference: the
    2-norm of E formed densely with numpy. Blocks ``K - (n w)^2 M`` of a chain (harmonic 1
    damped): between harmonics on one side of its first resonance |E| is 0.005-0.01
    (shared), across it 3.0 (not shared: GMRES would need many iterations); a harmonic that
    is not shared is factored itself, and the next one compares with it."""
    nc, d = 40, 2
    m = nc * d
    rng = np.random.default_rng(4)
    K = 2 * np.eye(m) - np.eye(m, k=1) - np.eye(m, k=-1)
    K[0, 0] += 1.0  # grounded chain: smallest eigenvalue ~1e-3
    M = np.eye(m)
    lam1 = np.linalg.eigvalsh(K)[0]
    # every node sliding in both directions over the whole period (gbar = I): P_n = Z_n, the
    # case where a resonance of Z_n shows in P_n (a smaller gain adds eps (1 - g) I)
    gbar = np.tile(np.eye(d), (nc, 1, 1))
    eps = 4.0
    w2 = np.array([0.0, 0.01, 3.0, 3.005]) * lam1  # (n w)^2 of harmonics 0..3
    Zc = np.stack([K - x * M for x in w2]).astype(complex)
    Zc[1] += 1e-3j * K  # damped: a complex harmonic may take the real factors of harmonic 0
    pc = krylov.MeanGainPreconditioner(gbar, krylov.HarmonicBlocks(Zc), eps)

    def size_E(a, b):  # the dense reference
        P = krylov.MeanGainPreconditioner._block(gbar, Zc[a].real, eps)
        G = np.zeros((m, m))
        for p in range(nc):
            G[p * d:(p + 1) * d, p * d:(p + 1) * d] = gbar[p]
        return np.linalg.norm(np.linalg.solve(P, G @ (Zc[b] - Zc[a])), 2)

    assert size_E(0, 1) < 0.1 * krylov.SHARE_BELOW and size_E(1, 2) > 4 * krylov.SHARE_BELOW
    assert size_E(2, 3) < 0.1 * krylov.SHARE_BELOW
    f = pc.factors
    assert f[1] is f[0] and f[2] is not f[0] and f[3] is f[2] and pc.shared == 2
    # the shared factors applied: P_0^-1 on harmonic 1's coefficients (U_1 = a_1 - i b_1),
    # to rounding of a solve with condition number 2.6e3 (1e-12)
    r = rng.standard_normal((m, 7))
    P0 = krylov.MeanGainPreconditioner._block(gbar, Zc[0].real, eps)
    out = pc.apply(r).reshape(m, 7)
    y = np.linalg.solve(P0.astype(complex), r[:, 1] - 1j * r[:, 4])
    np.testing.assert_allclose(out[:, 1], y.real, rtol=1e-12, atol=0)
    np.testing.assert_allclose(out[:, 4], -y.imag, rtol=1e-12, atol=0)
    # harmonics 2 and 3 share the complex factors of P_2 (the blocks are complex here), solved
    # together: each equals the dense complex solve (condition number of P_2 2.6e3, as P_0's:
    # 1e-11 leaves a margin over the 1e-12 of harmonic 1)
    P2 = krylov.MeanGainPreconditioner._block(gbar, Zc[2], eps)
    for b in (2, 3):
        y = np.linalg.solve(P2, r[:, b] - 1j * r[:, 3 + b])
        np.testing.assert_allclose(out[:, b], y.real, rtol=1e-11, atol=0)
        np.testing.assert_allclose(out[:, 3 + b], -y.imag, rtol=1e-11, atol=0)
    unshared = krylov.MeanGainPreconditioner(gbar, krylov.HarmonicBlocks(Zc), eps, share=False)
    assert unshared.shared == 0 and len({id(x) for x in unshared.factors}) == 4


def test_failed_shared_preconditioner_is_rebuilt_unshared(case, monkeypatch):
    """When GMRES fails with a preconditioner that shares factors between harmonics (forced
    here: every harmonic shares, and GMRES reports a failure whenever the preconditioner
    shares), it is rebuilt without sharing and the step still equals the LU solution of the
    formed Jacobian (1e-9, as test_step_equals_lu_step)."""
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    monkeypatch.setattr(krylov.MeanGainPreconditioner, "_close",
                        classmethod(lambda cls, *a: True))
    used = []
    pick, gmres = krylov.KrylovJacobian._preconditioner, krylov.spla.gmres

    def pick_spy(self, *a, **k):
        pc = pick(self, *a, **k)
        used.append(pc.shared)
        return pc

    def failing(A, b, **k):
        if used[-1]:
            return np.zeros_like(b), 1
        return gmres(A, b, **k)

    monkeypatch.setattr(krylov.KrylovJacobian, "_preconditioner", pick_spy)
    monkeypatch.setattr(krylov.spla, "gmres", failing)
    model, x = case
    dense, op = problem(model, "dense"), problem(model, "krylov")
    x1 = 0.9 * x
    f, J = dense.residual(x1.reshape(dense.m, dense.H), True)
    _, Jo = op.residual(x1.reshape(op.m, op.H), True)
    ref = np.linalg.solve(J, f)
    assert np.abs(Jo.solve(f) - ref).max() <= 1e-9 * np.abs(ref).max()
    assert used[0] > 0 and used[-1] == 0  # shared first, then rebuilt unshared


def test_single_factors_fall_back_to_double(case, monkeypatch):
    """The mean-gain preconditioner's factors are float32 (complex64 when damped) with
    ``KrylovOptions.single_factors``, the default, and the Newton step equals the LU solution of
    the formed Jacobian (1e-9, as test_step_equals_lu_step, which runs with them: GMRES
    multiplies by the operator in double and stops at 1e-10 of the residual whatever the
    preconditioner's precision). When GMRES fails with single factors (forced here: a failure
    reported whenever the preconditioner is single), one factored in double follows and the step
    is the same. The 2D cases only (real and complex factors; the 3D ones cost 5 s more)."""
    model, x = case
    if model.dim == 3:
        pytest.skip("the 2D cases cover real and complex factors")
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    assert KRYLOV.single_factors and problem(model, "krylov").krylov is KRYLOV
    used = []
    pick, gmres = krylov.KrylovJacobian._preconditioner, krylov.spla.gmres

    def pick_spy(self, *a, **k):
        pc = pick(self, *a, **k)
        used.append((pc.single, {lu[0].dtype.name for lu in pc.factors}))
        return pc

    def failing(A, b, **k):
        if used[-1][0]:
            return np.zeros_like(b), 1
        return gmres(A, b, **k)

    monkeypatch.setattr(krylov.KrylovJacobian, "_preconditioner", pick_spy)
    dense, op = problem(model, "dense"), problem(model, "krylov")
    f, J = dense.residual((0.9 * x).reshape(dense.m, dense.H), True)
    _, Jo = op.residual((0.9 * x).reshape(op.m, op.H), True)
    ref = np.linalg.solve(J, f)
    assert np.abs(Jo.solve(f) - ref).max() <= 1e-9 * np.abs(ref).max()
    assert used[0][0] and used[0][1] <= {"float32", "complex64"}
    monkeypatch.setattr(krylov.spla, "gmres", failing)
    op, used[:] = problem(model, "krylov"), []
    _, Jo = op.residual((0.9 * x).reshape(op.m, op.H), True)
    assert np.abs(Jo.solve(f) - ref).max() <= 1e-9 * np.abs(ref).max()
    assert used[0][0] and not used[-1][0]
    assert used[-1][1] <= {"float64", "complex128"}


def test_slow_single_factors_are_rebuilt_in_double(case, monkeypatch):
    """A GMRES run with single-precision factors that converges in more than
    ``KrylovOptions.single_max_iterations`` iterations (a bound of 1 here: every run of these
    cases takes more, asserted) has the preconditioner rebuilt in double at the next solve,
    and in double from then on; with ``single_factors=False`` every factorisation is double
    from the start, and with a bound no run reaches the factors stay single. Every step equals
    the LU solution of the formed Jacobian (1e-9, as test_step_equals_lu_step: GMRES
    multiplies by the operator in double whatever the factors). The 2D cases only (real and
    complex factors)."""
    model, x = case
    if model.dim == 3:
        pytest.skip("the 2D cases cover real and complex factors")
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    used, runs = [], []
    pick, gmres = krylov.KrylovJacobian._preconditioner, krylov.spla.gmres

    def pick_spy(self, *a, **k):
        pc = pick(self, *a, **k)
        used.append({lu[0].dtype.name for lu in pc.factors})
        return pc

    def counting(A, b, **k):
        n0 = len(runs)
        runs.append(0)
        cb = k.pop("callback")

        def count(r):
            runs[n0] += 1
            cb(r)

        return gmres(A, b, callback=count, **k)

    monkeypatch.setattr(krylov.KrylovJacobian, "_preconditioner", pick_spy)
    monkeypatch.setattr(krylov.spla, "gmres", counting)
    dense = problem(model, "dense")
    points = [(0.9 + 0.02 * i) * x for i in range(3)]
    single, double = {"float32", "complex64"}, {"float64", "complex128"}
    for opts, first, later in ((KrylovOptions(single_max_iterations=1), single, double),
                               (KrylovOptions(single_factors=False), double, double),
                               (KrylovOptions(single_max_iterations=10**6), single, single)):
        op = problem(model, "krylov")
        op.krylov = opts
        used[:], runs[:] = [], []
        for xi in points:
            f, J = dense.residual(xi.reshape(dense.m, dense.H), True)
            _, Jo = op.residual(xi.reshape(op.m, op.H), True)
            op._precond = None  # a fresh preconditioner at every point
            ref = np.linalg.solve(J, f)
            assert np.abs(Jo.solve(f) - ref).max() <= 1e-9 * np.abs(ref).max()
        assert min(runs) > 1 and len(used) == len(points)
        assert used[0] <= first and all(u <= later for u in used[1:]), (opts, used)


def test_solve_periodic_passes_the_krylov_options(monkeypatch):
    """``SolveOptions.krylov`` reaches the Newton steps of solve_periodic on the operator path
    (the 2D block of the module's cases, 3 harmonics, GMRES forced): with
    ``single_factors=False`` every preconditioner is factored in double, by default the first
    in single precision; both converge to the dense path's answer (1e-8 relative, as
    test_converged_answer_equals_dense_path)."""
    from fretwear.hb.options import PERIODIC
    from fretwear.hb.periodic import solve_periodic

    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    used = []
    pick = krylov.KrylovJacobian._preconditioner

    def pick_spy(self, *a, **k):
        pc = pick(self, *a, **k)
        used.append(pc.single)
        return pc

    monkeypatch.setattr(krylov.KrylovJacobian, "_preconditioner", pick_spy)
    model = block(2)
    basis = FourierBasis.up_to(3, 32)
    anchor = static_anchor(model)
    sols = {}
    for name, opts in (("dense", PERIODIC.replace(jacobian="dense", tol=1e-12)),
                       ("single", PERIODIC.replace(jacobian="krylov", tol=1e-12)),
                       ("double", PERIODIC.replace(jacobian="krylov", tol=1e-12,
                                                   krylov=KrylovOptions(single_factors=False)))):
        used[:] = []
        sols[name] = solve_periodic(model, basis, frequency=2000.0, options=opts,
                                    anchor=anchor, raise_on_failure=True).U
        if name == "single":
            assert used and used[0]
        elif name == "double":
            assert used and not any(used)
    ref = sols["dense"]
    for name in ("single", "double"):
        assert np.abs(sols[name] - ref).max() <= 1e-8 * np.abs(ref).max()


def test_single_factor_solves_keep_what_is_complex():
    """``_lu_solve`` with single-precision factors, for every pairing of real and complex
    factors and right-hand sides: the result is that of ``numpy.linalg.solve`` in double on
    the same matrix (complex where either the matrix or ``b`` is, never an imaginary part
    dropped) to single precision: 1e-5 relative, the bound ``n u cond`` with ``u = 6e-8``,
    ``n = 6`` and a diagonally dominant matrix (condition number below 10)."""
    rng = np.random.default_rng(1)
    A = rng.standard_normal((6, 6)) + 6 * np.eye(6)
    Ac = A + 0.3j * rng.standard_normal((6, 6))
    b = rng.standard_normal(6)
    bc = b + 1j * rng.standard_normal(6)
    for mat, rhs in ((A, b), (Ac, bc), (Ac, b), (A, bc)):
        lu = krylov.sla.lu_factor(mat.astype(np.complex64 if np.iscomplexobj(mat)
                                             else np.float32))
        ref = np.linalg.solve(mat, rhs)
        got = krylov._lu_solve(lu, rhs)
        assert np.iscomplexobj(got) == np.iscomplexobj(ref)
        assert np.abs(got - ref).max() <= 1e-5 * np.abs(ref).max()


def test_oscillating_gains_of_a_constant_gain_are_the_gain():
    """A node whose gain does not vary over the period has ``G_p = g (x) I_H`` (every
    harmonic maps to itself by ``g``): both gains of ``harmonic_gains`` are ``g`` exactly."""
    rng = np.random.default_rng(7)
    nc, d, H = 5, 3, 7
    g = rng.standard_normal((nc, d, d))
    G = np.stack([np.kron(gp, np.eye(H)) for gp in g])
    gbar, gosc = krylov.harmonic_gains(G, d)
    np.testing.assert_array_equal(gbar, g)
    np.testing.assert_allclose(gosc, g, rtol=0, atol=1e-15 * np.abs(g).max())
    same, same2 = krylov.harmonic_gains(G, d, oscillating=False)
    assert same2 is same


@pytest.mark.parametrize("real", [True, False], ids=["real", "complex"])
def test_preconditioner_with_two_gains_equals_dense_solves(real):
    """``MeanGainPreconditioner(gbar, Z, eps, gosc=...)`` applies ``P_0^-1`` with
    ``P_0 = eps I + gbar (Z_0 - eps I)`` and ``P_n^-1`` with ``P_n = eps I + gosc (Z_n - eps
    I)`` (n >= 1) to the coefficients ``a_n - i b_n``; reference: numpy's dense solves of
    those matrices formed with the node gains as a block-diagonal matrix (tolerance 1e-11:
    condition numbers below 1e3). The harmonics n >= 1 share one LU where their blocks are
    close (a chain far below resonance), and harmonic 1 does not take harmonic 0's factors,
    whose gain differs (|E| = |P_0^-1 (P_1 - P_0)| of order 1)."""
    rng = np.random.default_rng(8)
    nc, d, k = 30, 2, 3
    m = nc * d
    K = 2 * np.eye(m) - np.eye(m, k=1) - np.eye(m, k=-1)
    K[0, 0] += 1.0
    w2 = 1e-4 * np.arange(k + 1) ** 2
    Zc = np.stack([K - x * np.eye(m) for x in w2]).astype(complex)
    if not real:
        Zc[1:] += 1e-3j * K
    eps = 4.0
    gbar = np.tile(np.eye(d), (nc, 1, 1)) * 0.9
    gosc = 0.2 * rng.random((nc, d, d)) + 0.1 * np.eye(d)
    blocks = krylov.HarmonicBlocks(Zc if not real else Zc.real.copy())
    pc = krylov.MeanGainPreconditioner(gbar, blocks, eps, gosc=gosc)
    assert pc.factors[1] is not pc.factors[0] and pc.factors[3] is pc.factors[1]

    def dense_P(g, Z):
        Gd = np.zeros((m, m))
        for p in range(nc):
            Gd[p * d:(p + 1) * d, p * d:(p + 1) * d] = g[p]
        return eps * np.eye(m) + Gd @ (Z - eps * np.eye(m))

    H = 2 * k + 1
    r = rng.standard_normal((m, H))
    out = pc.apply(r).reshape(m, H)
    np.testing.assert_allclose(out[:, 0], np.linalg.solve(dense_P(gbar, Zc[0].real), r[:, 0]),
                               rtol=1e-11, atol=0)
    P1 = dense_P(gosc, Zc[1])  # the factors harmonics 1..k share
    for b in range(1, k + 1):
        y = np.linalg.solve(P1, r[:, b] - 1j * r[:, k + b])
        np.testing.assert_allclose(out[:, b], y.real, rtol=1e-11, atol=1e-14)
        np.testing.assert_allclose(out[:, k + b], -y.imag, rtol=1e-11, atol=1e-14)


def pad_in_partial_slip():
    """A 16-node damped pad (tests/helpers/pads.py: 10 MPa, mu 0.3, 0.8 mu P at 30 degrees,
    1 kHz) solved with 3 harmonics: 9 % of the nodes x period slip, in both tangential
    directions, every other instant sticks (asserted)."""
    from helpers.pads import pad_3d

    model = pad_3d(3, ratio=0.8)
    basis = FourierBasis.up_to(3, 32)
    red = condense(model, 1e3, basis.orders)
    prob = DLFTProblem(red, model.contact, basis, eps="auto", anchor=static_anchor(model),
                       jacobian="krylov")
    x = run(prob, tol=1e-10)
    state = prob.time_law(x.reshape(prob.m, prob.H))[2]
    assert 0.05 < np.mean(state == law.SLIP) < 0.15 and np.mean(state == law.STICK) > 0.85
    return prob, x


def test_oscillating_gains_precondition_partial_slip(monkeypatch):
    """On a Jacobian in partial slip the step by GMRES with the oscillating gains equals the
    LU solution of the formed Jacobian (1e-9, as test_step_equals_lu_step) in less than half
    the GMRES iterations the mean gain alone needs (21 against 51 measured: the mean gain
    treats the oscillating harmonics of nodes that stick most of the period as if they
    slipped; krylov.harmonic_gains)."""
    def mean_gain(prob, mean):
        prob._mean_gain = mean

    its = {}
    for mean, (J, pc) in _partial_slip_steps(monkeypatch, (False, True), mean_gain).items():
        its[mean] = J.gmres_iterations
        assert pc.oscillating is not mean
    assert its[False] < 0.5 * its[True]


def _partial_slip_steps(monkeypatch, variants, configure) -> dict:
    """The step by GMRES on the Jacobian in partial slip of pad_in_partial_slip for each of
    ``variants`` (``configure(prob, variant)`` sets it; a fresh preconditioner each), each
    checked against the LU solution of the formed Jacobian (1e-9, as
    test_step_equals_lu_step): ``{variant: (its KrylovJacobian, the preconditioner the step
    used)}``."""
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    prob, x = pad_in_partial_slip()
    f, J = prob.residual(x.reshape(prob.m, prob.H), True)
    ref = np.linalg.solve(J.toarray(), f)
    out = {}
    for v in variants:
        prob._precond = None
        configure(prob, v)
        _, J = prob.residual(x.reshape(prob.m, prob.H), True)
        s = J.solve(f)
        assert np.abs(s - ref).max() <= 1e-9 * np.abs(ref).max()
        out[v] = (J, prob._precond)
    return out


def test_failed_oscillating_gains_fall_back_to_the_mean_gain(case, monkeypatch):
    """When GMRES fails with a fresh unshared preconditioner of oscillating gains (forced: it
    reports a failure whenever the preconditioner has them), the owner takes the mean gain
    from then on, and the step equals the LU solution of the formed Jacobian (1e-9)."""
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    used = []
    pick, gmres = krylov.KrylovJacobian._preconditioner, krylov.spla.gmres

    def pick_spy(self, *a, **k):
        pc = pick(self, *a, **k)
        used.append(pc.oscillating)
        return pc

    def failing(A, b, **k):
        if used[-1]:
            return np.zeros_like(b), 1
        return gmres(A, b, **k)

    monkeypatch.setattr(krylov.KrylovJacobian, "_preconditioner", pick_spy)
    monkeypatch.setattr(krylov.spla, "gmres", failing)
    model, x = case
    dense, op = problem(model, "dense"), problem(model, "krylov")
    x1 = 0.9 * x
    f, J = dense.residual(x1.reshape(dense.m, dense.H), True)
    _, Jo = op.residual(x1.reshape(op.m, op.H), True)
    ref = np.linalg.solve(J, f)
    assert np.abs(Jo.solve(f) - ref).max() <= 1e-9 * np.abs(ref).max()
    assert used[0] and not used[-1] and op._mean_gain


def test_tiled_symmetry_check_equals_allclose():
    """The tiled symmetry test of the harmonic blocks (krylov._symmetric) answers as NumPy's
    allclose(z, z.T, rtol=0, atol=1e-13 max|z|) (independent code) on blocks larger than a
    tile, real and complex, with an asymmetry above or below the bound in an off-diagonal
    tile, and says no for a NaN or an infinity anywhere."""
    from fretwear.hb.krylov import TILE, _symmetric

    rng = np.random.default_rng(8)
    m = TILE + 70
    A = rng.standard_normal((m, m))
    A = A + A.T
    for z in (A, A + 0.5j * A):
        for i, j, e in ((3, m - 2, 0.0), (3, m - 2, 1e-10), (m - 1, 4, 1e-15),
                        (TILE + 1, TILE + 5, 1e-9)):
            w = z.copy()
            w[i, j] += e
            ref = np.allclose(w, w.T, rtol=0.0, atol=1e-13 * np.abs(w).max())
            assert _symmetric(w) == ref
        for bad in (np.nan, np.inf):
            w = z.copy()
            w[m - 1, m - 1] = bad
            assert not _symmetric(w)


def test_node_local_inverse_equals_the_dense_node_blocks(case):
    """``krylov.node_local_inverse``: the inverse of every node's diagonal block of the
    Jacobian formed with ``Z~`` cut to its node-diagonal blocks, ``eps I + G (Z~_D - eps I)``,
    the reference formed from the dense real matrix of the blocks (HarmonicBlocks.dense,
    fretwear.hb.reduce.to_real_blocks: independent of the function's own layout of
    ``(a_n, b_n)`` and of the imaginary parts' signs, which the damped cases exercise) and
    inverted by numpy; to 1e-10 of the largest entry (inverses of blocks of condition number
    below 1e4 measured: a few 1e-15)."""
    model, x = case
    op = problem(model, "krylov")
    _, J = op.residual((0.9 * x).reshape(op.m, op.H), True)
    nc, dH = J.nc, J.dH
    act = np.arange(nc)
    Qi = krylov.node_local_inverse(J.G, J._node_diagonals(act), J.eps)
    Zd = J.Z.dense()
    for p in range(nc):
        sl = slice(p * dH, (p + 1) * dH)
        Q = J.eps * np.eye(dH) + J.G[p] @ (Zd[sl, sl] - J.eps * np.eye(dH))
        ref = np.linalg.inv(Q)
        assert np.abs(Qi[p] - ref).max() <= 1e-10 * np.abs(ref).max(), p


def test_node_correction_halves_gmres_and_keeps_the_step(monkeypatch):
    """On the Jacobian in partial slip of test_oscillating_gains_precondition_partial_slip,
    with the node-local correction forced on (``node_correction_min_dofs=0``), the step by
    GMRES equals the LU solution of the formed Jacobian (1e-9, as test_step_equals_lu_step) in fewer
    than two thirds of the GMRES iterations of the mean-gain preconditioner alone (measured
    9 against 32; 6-19 against 8-33 per Newton step on the 1024-node pad of
    benchmarks/scale_3d.py), and without the option the same step with that preconditioner
    alone."""
    def correction(prob, on):
        prob.krylov = KrylovOptions(node_correction=on, node_correction_min_dofs=0)

    its = {}
    for on, (J, _) in _partial_slip_steps(monkeypatch, (True, False), correction).items():
        assert J.node_corrected is on
        its[on] = J.gmres_iterations
    assert its[True] < 2 / 3 * its[False], its


@pytest.mark.parametrize("d", [2, 3])
def test_gain_block_equals_the_numpy_form(d):
    """``krylov._gain_block`` (the compiled one-pass form of the preconditioner's block from
    a whole block and the active rows) against ``MeanGainPreconditioner._block`` (NumPy's
    batched product, then the eps terms) on the gathered block ``Zb[rows][:, rows]``: the
    previous code path. In double to ``4 d`` roundings of the largest term (both sum ``d``
    products; on the machine of docs/studies/large-interface-solve.md they are equal bit for
    bit, which the solves there show), in single as that double block cast (one rounding of
    float32). A fault in the gather (rows or columns), the eps terms or the gain's index
    moves entries by O(1)."""
    rng = np.random.default_rng(11)
    nc_all, eps = 30, 3.0
    M = nc_all * d
    Zb = rng.standard_normal((M, M))
    nodes = np.sort(rng.choice(nc_all, size=22, replace=False))
    rows = (nodes[:, None] * d + np.arange(d)).reshape(-1)
    gbar = rng.standard_normal((nodes.size, d, d))
    ref = krylov.MeanGainPreconditioner._block(gbar, Zb[np.ix_(rows, rows)], eps)
    scale = np.abs(gbar).max() * np.abs(Zb).max() * d + eps * (1 + np.abs(gbar).max())
    for order in ("C", "F"):  # (the preconditioner's is F: factored in place)
        out = krylov._gain_block(Zb, rows, gbar, eps, np.empty(ref.shape, order=order))
        assert np.abs(out - ref).max() <= 4 * d * np.finfo(float).eps * scale
        out32 = krylov._gain_block(Zb, rows, gbar, eps,
                                   np.empty(ref.shape, np.float32, order=order))
        assert out32.dtype == np.float32
        np.testing.assert_allclose(out32, ref.astype(np.float32),
                                   rtol=2 * np.finfo(np.float32).eps,
                                   atol=4 * d * np.finfo(float).eps * scale)


def test_preconditioner_on_an_active_view_equals_the_copied_blocks():
    """The preconditioner built on an active view of an operator's blocks (``_ActiveView``:
    ``P_b`` formed from the whole block and the active DOFs by ``block_source``) has the
    factors of the one built on the copied active blocks (``HarmonicBlocks.sub``), bit for
    bit in single and double: the same entries formed from the same numbers; and its
    applies equal the dense solves of ``P_n`` formed by ``_block`` from the copied blocks
    (1e-10: condition numbers below 1e3). A wrong row or column of the view moves the
    factors."""
    rng = np.random.default_rng(5)
    nc, d, nb = 24, 3, 3
    m = nc * d
    A = rng.standard_normal((m, m))
    K = A @ A.T / m + 3 * np.eye(m)
    Zr = np.stack([K - 0.2 * b * np.eye(m) for b in range(nb)])
    Z = krylov.HarmonicBlocks(Zr)
    act = np.array([0, 2, 3, 5, 7, 8, 11, 13, 14, 17, 19, 20, 21, 23])
    dofs = (act[:, None] * d + np.arange(d)).reshape(-1)
    view, sub = krylov._ActiveView(Z, dofs), Z.sub(dofs)
    gbar = rng.uniform(0.2, 1.0, (act.size, 1, 1)) * np.eye(d)
    eps = 2.0
    for single in (False, True):  # (_gain_block casts to the factors' type)
        pv = krylov.MeanGainPreconditioner(gbar, view, eps, share=False, single=single)
        ps = krylov.MeanGainPreconditioner(gbar, sub, eps, share=False, single=single)
        for a, b in zip(pv.factors, ps.factors, strict=True):
            assert a[0].dtype == (np.float32 if single else np.float64)
            assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    r = rng.standard_normal((dofs.size, sub.H))
    pd = krylov.MeanGainPreconditioner(gbar, view, eps, share=False)
    out = pd.apply(r).reshape(-1, sub.H)
    for b, cols in ((0, [0]), (1, [1, 3]), (2, [2, 4])):
        P = krylov.MeanGainPreconditioner._block(gbar, Zr[b][np.ix_(dofs, dofs)], eps)
        ref = np.linalg.solve(P, r[:, cols])
        np.testing.assert_allclose(out[:, cols], ref, rtol=0, atol=1e-10 * np.abs(ref).max())


@pytest.mark.parametrize("same_gain", [True, False])
def test_probe_sizes_equal_the_dense_power_estimate(same_gain):
    """``MeanGainPreconditioner._probe_sizes`` (the sharing test's two power steps for
    several harmonics at once, their products in one call and their solves in one) against
    the same two steps with ``E = P_b^-1 (P_n - P_b)`` formed densely (numpy's solve of the
    blocks formed by ``_block``), from the same start vector: to 1e-10 (condition numbers
    below 1e2: rounding of a few 1e-15); and the batch equals the harmonics probed one at a
    time (``_close``'s call) to 1e-12. With one gain for both or the mean gain on ``P_b``
    and another on ``P_n`` (harmonic 0 against 1). A column of another harmonic, a product
    with the wrong block or a stale iterate changes the sizes by O(1)."""
    rng = np.random.default_rng(7)
    nc, d = 20, 2
    m = nc * d
    A = rng.standard_normal((m, m))
    K = A @ A.T / m + 2 * np.eye(m)
    Mm = np.eye(m) + 0.1 * np.diag(rng.uniform(size=m))
    w2 = np.array([0.0, 0.05, 0.1, 1.2, 1.3])
    Zr = np.stack([K - x * Mm for x in w2])
    Z = krylov.HarmonicBlocks(Zr)
    eps = 3.0
    gbar = rng.uniform(0.3, 1.0, (nc, 1, 1)) * np.eye(d)
    gosc = gbar if same_gain else rng.uniform(0.1, 0.9, (nc, 1, 1)) * np.eye(d)
    b = 0 if not same_gain else 1
    gb = gbar if b == 0 else gosc
    Pb = krylov.MeanGainPreconditioner._block(gb, Zr[b], eps)
    lu = krylov.sla.lu_factor(Pb)
    ns = [2, 3, 4] if same_gain else [1, 2, 3, 4]
    sizes = krylov.MeanGainPreconditioner._probe_sizes(gosc, ns, (b, gb, lu), eps, Z, {})
    v0 = np.random.default_rng(0).standard_normal(m)  # the probe's start
    for n in ns:
        E = np.linalg.solve(Pb, krylov.MeanGainPreconditioner._block(gosc, Zr[n], eps) - Pb)
        w1 = E @ v0
        ref = np.linalg.norm(E @ w1) / np.linalg.norm(w1)
        assert krylov.SHARE_PROBES == 2
        assert abs(sizes[n] - ref) <= 1e-10 * ref, (n, sizes[n], ref)
        one = krylov.MeanGainPreconditioner._probe_sizes(gosc, [n], (b, gb, lu), eps, Z, {})
        assert abs(one[n] - sizes[n]) <= 1e-12 * ref
    # both sides of the threshold occur (the test would not see a wrong decision otherwise)
    assert min(sizes.values()) < krylov.SHARE_BELOW < max(sizes.values())
