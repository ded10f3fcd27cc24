"""The sparse direct solvers of the condensations (fretwear.hb.sparse_lu): every backend, and
the fallback to SuperLU when the optional extra (kvxopt) is missing, against dense LAPACK."""

import numpy as np
import pytest
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.hb import reduce, sparse_lu


def _spd(n=60, seed=0):
    """A sparse SPD matrix with the pattern of a 1D stiffness plus random couplings, of
    condition number about 1e3 (a 1D Laplacian shifted by 1e-2 of its largest entry)."""
    rng = np.random.default_rng(seed)
    L = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    R = sp.random(n, n, density=0.05, random_state=seed)
    R = 1e-2 * (R + R.T)
    A = (L + R + sp.diags(np.full(n, 0.02 + abs(R).sum(axis=1).A1))).tocsc()
    B = rng.standard_normal((n, 7))
    return A, B


def _dense(A, B):
    return np.linalg.solve(A.toarray(), B)


# the factorisations are backward stable: with a condition number ~1e3 the solution agrees
# with LAPACK's to ~1e-13; 1e-10 leaves room for any ordering, and a wrong solve is O(1) off
TOL = 1e-10


@pytest.mark.parametrize("backend", sparse_lu.available())
def test_backends_match_dense_solve(backend):
    """Each available backend solves an SPD matrix (real and complex right-hand sides, one or
    several) and a complex symmetric one as LAPACK's dense solve does (independent)."""
    A, B = _spd()
    f = sparse_lu.factor(A, "spd", backend=backend)
    assert f.name == backend
    X = _dense(A, B)
    assert np.abs(f.solve(B) - X).max() <= TOL * np.abs(X).max()
    assert np.abs(f.solve(B[:, 0]) - X[:, 0]).max() <= TOL * np.abs(X).max()
    Bc = B + 1j * B[:, ::-1]
    Xc = _dense(A, Bc)
    assert np.abs(f.solve(Bc) - Xc).max() <= TOL * np.abs(Xc).max()
    Z = (A - 0.3 * sp.eye(A.shape[0]) + 0.05j * A).tocsc()  # complex symmetric Z_ii
    fz = sparse_lu.factor(Z, "general", backend=backend)
    assert fz.name == "superlu"  # every complex matrix goes to SuperLU
    Xz = _dense(Z, Bc)
    assert np.abs(fz.solve(Bc) - Xz).max() <= TOL * np.abs(Xz).max()


def test_cholmod_many_right_hand_sides():
    """From MANY right-hand sides on, a CHOLMOD factorisation solves through its supernodes
    with NumPy's BLAS (fretwear.hb.supernodal): on a 3D grid Laplacian (supernodes wider than
    a column), dense and sparse right-hand sides (real and complex) agree with LAPACK's solve
    to TOL, and with CHOLMOD's own solve of the same columns (few at a time) to TOL."""
    pytest.importorskip("kvxopt")
    n = 7
    one = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    eye = sp.eye(n)
    A = (sp.kron(sp.kron(one, eye), eye) + sp.kron(sp.kron(eye, one), eye)
         + sp.kron(sp.kron(eye, eye), one) + 0.05 * sp.eye(n**3)).tocsc()
    f = sparse_lu.factor(A, "spd", backend="cholmod")
    rng = np.random.default_rng(4)
    B = rng.standard_normal((n**3, sparse_lu.MANY + 3))
    B[:, 2:5] = 0.0
    B[100:, 5:] = 0.0  # sparse columns: a block of rows only
    B[:, -1] = 0.0
    B[::11, -1] = 1.0  # scattered rows: blocks of a supernode partly zero
    for rhs in (B, B + 1j * B[:, ::-1]):
        X = _dense(A, rhs)
        got = f.solve(rhs)
        assert np.abs(got - X).max() <= TOL * np.abs(X).max()
        few = np.column_stack([f.solve(rhs[:, j]) for j in range(rhs.shape[1])])
        assert np.abs(got - few).max() <= TOL * np.abs(X).max()
    assert f._sn is not None and f._sn.supernodes < n**3
    # release() drops the panels; the next solve of many columns makes them again, the same
    # arithmetic in the same order: equal to the last solve to the last bit
    before = f.solve(B)
    f.release()
    assert f._sn is None
    assert np.array_equal(f.solve(B), before) and f._sn is not None


@pytest.mark.parametrize("backend", ["cholmod", "superlu"])
def test_solve_few_columns(backend):
    """``solve_few`` (the few-column products of the condensation by partial factorisations)
    gives LAPACK's solution to TOL for real and complex right-hand sides of more than MANY
    columns, and for CHOLMOD without making the supernodal panels of the many-column solves."""
    if backend == "cholmod":
        pytest.importorskip("kvxopt")
    A, _ = _spd(seed=2)
    f = sparse_lu.factor(A, "spd", backend=backend)
    assert f.name == backend
    B = np.random.default_rng(5).standard_normal((A.shape[0], sparse_lu.MANY + 4))
    for rhs in (B, B + 1j * B[:, ::-1], B[:, 0]):
        X = _dense(A, rhs)
        assert np.abs(f.solve_few(rhs) - X).max() <= TOL * np.abs(X).max()
    assert getattr(f, "_sn", None) is None


def test_cholmod_when_installed():
    """With the extra installed, a real SPD matrix gets CHOLMOD by default."""
    pytest.importorskip("kvxopt")
    A, B = _spd(seed=1)
    assert sparse_lu.default_backend() == "cholmod"
    f = sparse_lu.factor(A, "spd")
    assert f.name == "cholmod"
    X = _dense(A, B)
    assert np.abs(f.solve(B) - X).max() <= TOL * np.abs(X).max()


def test_fallback_without_the_extra(monkeypatch):
    """With kvxopt hidden (its import fails), SuperLU runs and gives the dense solution."""
    import importlib

    real_import = importlib.import_module

    def hidden(name, *a, **k):
        if name.startswith("kvxopt"):
            raise ImportError(f"No module named {name!r}")
        return real_import(name, *a, **k)

    monkeypatch.setattr(sparse_lu.importlib, "import_module", hidden)
    assert sparse_lu.available() == ["superlu"]
    assert sparse_lu.default_backend() == "superlu"
    A, B = _spd(seed=2)
    f = reduce._factor(A, 0, 0.0)
    assert f.name == "superlu"
    X = _dense(A, B)
    assert np.abs(reduce._solve(f, B) - X).max() <= TOL * np.abs(X).max()
    with pytest.raises(InputError, match="FRETWEAR_SPARSE_LU"):
        monkeypatch.setenv(sparse_lu.ENV, "cholmod")
        sparse_lu.default_backend()


def test_forced_backend_and_bad_input(monkeypatch):
    monkeypatch.setenv(sparse_lu.ENV, "superlu")
    A, _ = _spd(seed=3)
    assert sparse_lu.factor(A, "spd").name == "superlu"
    monkeypatch.setenv(sparse_lu.ENV, "nonesuch")
    with pytest.raises(InputError, match="nonesuch"):
        sparse_lu.factor(A, "spd")
    monkeypatch.delenv(sparse_lu.ENV)
    with pytest.raises(InputError, match="kind"):
        sparse_lu.factor(A, "hermitian")


@pytest.mark.parametrize("backend", sparse_lu.available())
def test_singular_and_nearly_singular(backend):
    """A zero row and column (nothing holds that DOF) is singular; a pivot 1e-15 of the others
    nearly singular: both raise, whatever the backend, and reduce names the cause."""
    A, _ = _spd(seed=4)
    S = A.tolil()
    S[0, :] = 0.0
    S[:, 0] = 0.0
    with pytest.raises(sparse_lu.SingularError):
        sparse_lu.factor(S.tocsc(), "spd", backend=backend)
    N = A.tolil()
    N[0, 1:] = 0.0
    N[1:, 0] = 0.0
    N[0, 0] = 1e-15 * A[0, 0]
    with pytest.raises(sparse_lu.SingularError) as info:
        sparse_lu.factor(N.tocsc(), "spd", backend=backend)
    assert info.value.near
    with pytest.raises(InputError, match="nearly"):
        reduce._factor(N.tocsc(), 0, 0.0)


def test_nonsymmetric_real_matrix_is_not_given_to_cholesky():
    """A real matrix that is not symmetric goes to SuperLU (a Cholesky factorisation reads
    one triangle and would solve another matrix)."""
    A, B = _spd(seed=5)
    U = (A + 0.1 * sp.triu(A, 1)).tocsc()
    assert not reduce._real_symmetric(U)
    f = reduce._factor(U, 0, 0.0)
    assert f.name == "superlu"
    X = _dense(U, B)
    assert np.abs(f.solve(B) - X).max() <= TOL * np.abs(X).max()


def test_undamped_condensation_in_real_arithmetic(monkeypatch):
    """An undamped structure's ``Z_ii = K_ii - (n w)^2 M_ii`` is real: the sparse path
    factorises it in real arithmetic (the backend recorded on the condenser) and its ``Z_r``
    equals eq. 19 written densely with numpy's complex solve (independent) to 1e-9, the
    tolerance of tests/hb/test_reduce.py (conditioning up to ~1e3)."""
    import scipy.linalg as sla
    from helpers.models import truss

    monkeypatch.setattr(reduce, "DENSE_MAX", -1)  # the sparse path on a small model
    model = truss(damping="none")
    cond = reduce.exact_condenser(model)
    cd = model.contact.dofs.reshape(-1)
    idofs = np.setdiff1d(model.free_dofs(), cd)
    R = sla.block_diag(*model.contact.frame)
    K, M = model.K.toarray(), model.M.toarray()
    f, orders = 37.0, np.array([0, 1, 2])
    red = reduce.condense(model, f, orders, condenser=cond)
    w = 2 * np.pi * f
    for b, n in enumerate(orders):
        Z = (K - (n * w) ** 2 * M).astype(complex)
        S = Z[np.ix_(cd, cd)] - Z[np.ix_(cd, idofs)] @ np.linalg.solve(
            Z[np.ix_(idofs, idofs)], Z[np.ix_(idofs, cd)])
        ref = R @ S @ R.T
        assert np.abs(red.Z[b] - ref).max() <= 1e-9 * np.abs(ref).max()
    lu = cond.factor(w, 2)
    assert not lu.complex  # real arithmetic
    assert cond.lu_backends <= {"cholmod", "superlu"} and cond.lu_backends
