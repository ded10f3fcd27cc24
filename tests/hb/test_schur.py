"""The projected contact blocks by partial Cholesky factorisations (fretwear.hb.schur) and the
modal condenser built on them (fretwear.hb.modal.SchurModalCondenser), against the
projections through the static modes Psi (ModalCondenser, itself checked against the exact
condensation in test_modal.py), dense NumPy algebra and the exact condensation.

Tolerances: ``K^cc`` is the Schur complement itself (no difference): rounding of a
factorisation, measured 1e-15 relative, asserted 1e-12. The other ``X^cc`` come from a central
difference whose estimated error (truncation plus rounding, ``schur.Difference.error``) is
3e-10 on this block; measured 1e-10 to 4e-10; asserted 1e-7 and below ten times the estimate
(the estimate is an order of magnitude, not a bound). Everything else is the same algebra as
the dense condenser in another order (1e-12, as test_modal_blocked.py; 1e-10 for ``X^cq``:
the stiffness-proportional damping's ``C^cq, D^cq`` hold ``K^cq``, which vanishes, so they
are differences of terms up to 1e3 larger, measured 1.2e-12), but ``Z_r`` and what
is made from it carry ``M^cc``'s error scaled by ``(n w)^2 |M^cc| / |Z_r|``: asserted 1e-8.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from helpers.operator_models import (
    F_MAX,
    block,
    rel,
    same_partial_slip_solution,
    same_reductions,
)

from fretwear.errors import InputError
from fretwear.hb import modal, schur
from fretwear.hb.modal import ModalCondenser, SchurModalCondenser, modal_condenser
from fretwear.hb.reduce import _Blocks
from fretwear.hb.sparse_lu import factor
from fretwear.model import Damping

pytest.importorskip("kvxopt")

DAMPED = Damping(loss_factor=0.02, rayleigh_mass=100.0, rayleigh_stiffness=1e-7)


@pytest.mark.parametrize("damping", [None, DAMPED], ids=["undamped", "damped"])
def test_partial_factorisations_equal_the_static_modes(damping):
    """Every projected block, Z_r at every harmonic, the loads, the observed rows, the
    recovery and the error check of the condenser by partial factorisations against the dense
    condenser through Psi (tolerances: module docstring); harmonic 0 against the exact
    condensation (the static part is exact on both paths)."""
    model = block(damping)
    mc = ModalCondenser(model, F_MAX, 7, tol=1e-2)
    sc = SchurModalCondenser(model, F_MAX, 7, tol=1e-2)
    assert sc.n_modes == mc.n_modes and abs(sc.error - mc.error) <= 1e-6 * mc.error
    assert set(sc.proj_local) == set(mc.proj_local)
    assert set(sc.contact.differences) == set(mc.proj_local) - {"K"}
    assert sc.contact.factorisations == 1 + 2 * len(sc.contact.differences)
    assert rel(sc.proj_local["K"][0], mc.proj_local["K"][0]) < 1e-12
    for nm, d in sc.contact.differences.items():
        err = rel(sc.proj_local[nm][0], mc.proj_local[nm][0])
        assert err < 1e-7 and err < 10 * d.error, (nm, err, d)
        for i in (1, 2, 3):
            assert rel(sc.proj_local[nm][i], mc.proj_local[nm][i]) < 1e-10, (nm, i)
    same_reductions(model, mc, sc, 1e-8)


def _blocks(A, c):
    """The contact/interior blocks of the dense ``A`` (contact DOFs ``c`` last)."""
    i = np.setdiff1d(np.arange(A.shape[0]), c)
    S = sp.csr_matrix
    return _Blocks(A[np.ix_(c, c)], S(A[np.ix_(c, i)]), S(A[np.ix_(i, c)]).tocsc(),
                   S(A[np.ix_(i, i)]).tocsc())


def test_schur_complement_and_its_derivative_against_dense_algebra():
    """On a random sparse chain (a semi-definite K with a rigid motion, as a structure
    carried by its interface): the partial factorisation gives K_cc - K_ci K_ii^-1 K_ic of
    NumPy's dense solve to 1e-12 (rounding); the central difference of the Schur complements
    of K -/+ h X gives T^T X T, T = [I; Psi] (contact DOFs first), to 1e-7 (its estimated
    error, 1e-9 here, with margin), for a mass-like X and an indefinite one (dS/dsigma =
    -X^cc holds for any symmetric X)."""
    rng = np.random.default_rng(3)
    n, c = 40, np.arange(30, 40)
    # a chain of springs (one rigid translation) plus random symmetric coupling of neighbours
    k = 1e8 * (1 + rng.random(n - 1))
    K = np.zeros((n, n))
    for j, kj in enumerate(k):
        K[np.ix_([j, j + 1], [j, j + 1])] += kj * np.array([[1, -1], [-1, 1]])
    M = np.diag(1e-3 * (1 + rng.random(n))) + 1e-4 * (np.eye(n, k=1) + np.eye(n, k=-1))
    X2 = 1e-4 * (np.eye(n, k=2) + np.eye(n, k=-2)) - 2e-4 * np.eye(n)
    Kb = _blocks(K, c)
    i = np.setdiff1d(np.arange(n), c)
    Psi = -np.linalg.solve(K[np.ix_(i, i)], K[np.ix_(i, c)])
    pf = schur.PartialFactor(Kb)
    S = pf.schur(Kb.ii, Kb.ic, Kb.ci, Kb.cc)
    ref = K[np.ix_(c, c)] + K[np.ix_(c, i)] @ Psi
    assert rel(S, ref) < 1e-12
    assert np.linalg.eigvalsh(ref)[0] < 1e-6 * np.abs(ref).max()  # semi-definite
    from fretwear.hb.sparse_lu import factor

    lu = factor(Kb.ii, "spd")
    out = schur.contact_blocks(Kb, {"M": _blocks(M, c), "X": _blocks(X2, c)}, lu)
    for name, X in (("M", M), ("X", X2)):
        T = np.vstack([np.eye(c.size), Psi])  # rows: contact, then interior
        order = np.concatenate([c, i])
        Xcc = T.T @ X[np.ix_(order, order)] @ T
        assert rel(out.cc[name], Xcc) < 1e-7, name
        assert out.differences[name].error < 1e-7
    assert rel(out.cc["K"], ref) < 1e-12


def _chain(stiffness):
    """A chain of 40 springs of about ``stiffness`` [N/m] (one rigid translation, its last 10
    DOFs the contact ``c``): ``K``, its blocks, the static modes ``Psi`` (NumPy's dense
    solve), ``c`` and the interior DOFs ``i``."""
    n, c = 40, np.arange(30, 40)
    rng = np.random.default_rng(3)
    K = np.zeros((n, n))
    for j, kj in enumerate(stiffness * (1 + rng.random(n - 1))):
        K[np.ix_([j, j + 1], [j, j + 1])] += kj * np.array([[1, -1], [-1, 1]])
    i = np.setdiff1d(np.arange(n), c)
    return K, _blocks(K, c), -np.linalg.solve(K[np.ix_(i, i)], K[np.ix_(i, c)]), c, i


@pytest.mark.parametrize("stiffness", [1e6, 1e8])
def test_derivative_of_a_matrix_on_the_contact_dofs_alone(stiffness):
    """A damping matrix on the contact DOFs alone (dashpots at the interface and between a
    contact and an interior DOF: ``X_ii = 0``, indefinite): ``S(sigma)`` is then quadratic
    and its central difference exact, so ``X^cc = T^T X T`` of dense algebra is met to the
    rounding (estimated 1e-10; asserted 1e-9 and below ten times the estimate, as above).
    The step once came from the interior block alone: a relative error of 1.0 at 1e6 N/m
    (a step of 1e201), 2e-6 at 1e8 (a step not scaled to K / X)."""
    K, Kb, Psi, c, i = _chain(stiffness)
    X = np.zeros(K.shape)
    X[c, c] = 5.0 * (1 + np.random.default_rng(4).random(c.size))
    X[c[0], i[-1]] = X[i[-1], c[0]] = 2.0
    out = schur.contact_blocks(Kb, {"C": _blocks(X, c)}, factor(Kb.ii, "spd"))
    T = np.vstack([np.eye(c.size), Psi])  # rows: contact, then interior
    order = np.concatenate([c, i])
    err = rel(out.cc["C"], T.T @ X[np.ix_(order, order)] @ T)
    d = out.differences["C"]
    assert err < 1e-9 and err < 10 * d.error, (err, d)


@pytest.mark.parametrize("dense", [True, False], ids=["front", "scattered"])
def test_lower_product(dense):
    """``L L^T`` of a lower triangle given by compressed columns, against NumPy's product
    (rounding: 1e-13): a dense front (CHOLMOD's) and a pattern with holes."""
    rng = np.random.default_rng(0)
    m = 70
    L = np.tril(rng.standard_normal((m, m)))
    if not dense:
        L[rng.random((m, m)) < 0.3] = 0.0
        np.fill_diagonal(L, 1.0 + rng.random(m))
    if dense:  # every entry of the triangle stored, as a dense front
        rows = np.concatenate([np.arange(j, m) for j in range(m)])
        ptr = np.concatenate([[0], np.cumsum(m - np.arange(m))])
        vals = np.concatenate([L[j:, j] for j in range(m)])
    else:
        C = sp.csc_matrix(L)
        rows, ptr, vals = C.indices.astype(np.int64), C.indptr.astype(np.int64), C.data
    assert rel(schur._lower_product(ptr, rows, vals, m), L @ L.T) < 1e-13


def test_modal_condenser_chooses_the_path(monkeypatch):
    """``modal_condenser`` takes the partial factorisations from SCHUR_MIN_CONTACT contact
    DOFs on (lowered here to the block's), not with residual vectors, and says which path
    ran; without CHOLMOD (forced off) it keeps the static modes, and the class refuses in
    one line."""
    model = block()
    monkeypatch.setattr(modal, "SCHUR_MIN_CONTACT", 1)
    sc = modal_condenser(model, F_MAX, 7, tol=1e-2)
    assert isinstance(sc, SchurModalCondenser) and sc.path.startswith("partial")
    mc = modal_condenser(model, F_MAX, 7, tol=1e-2, residual=True)
    assert type(mc) is ModalCondenser and mc.path.startswith("static modes")
    monkeypatch.setattr(modal, "SCHUR_MIN_CONTACT", 10**9)
    assert type(modal_condenser(model, F_MAX, 7, tol=1e-2)) is ModalCondenser
    monkeypatch.setattr(modal, "SCHUR_MIN_CONTACT", 1)
    monkeypatch.setenv("FRETWEAR_SPARSE_LU", "superlu")
    assert not schur.available()
    assert type(modal_condenser(model, F_MAX, 7, tol=1e-2)) is ModalCondenser
    with pytest.raises(InputError, match="needs CHOLMOD"):
        SchurModalCondenser(model, F_MAX, 7, tol=1e-2)


def test_modes_raised_as_the_dense_condenser():
    """With ``raise_modes`` from two modes (the check fails there, test_modal.py), the
    condenser by partial factorisations raises them as the dense one does and passes with
    the same number of modes and the same error (to the difference's 1e-6 relative)."""
    model = block()
    a = ModalCondenser(model, F_MAX, 7, modes=2, tol=1e-2, raise_modes=True)
    b = SchurModalCondenser(model, F_MAX, 7, modes=2, tol=1e-2, raise_modes=True)
    assert a.n_modes == b.n_modes > 2
    assert abs(a.error - b.error) <= 1e-6 * a.error <= 1e-2


def test_periodic_solve_in_partial_slip_equals_the_static_modes_path():
    """A periodic solve in partial slip through the condenser by partial factorisations
    reaches the dense modal condenser's solution (1e-8: both stop at the solver's tolerance,
    1e-9 of |Z U|, and Z_r differs by less than 1e-8)."""
    same_partial_slip_solution(lambda m: ModalCondenser(m, F_MAX, 7, tol=1e-2),
                               lambda m: SchurModalCondenser(m, F_MAX, 7, tol=1e-2))


@pytest.mark.parametrize("cls", [modal.BlockedModalCondenser, SchurModalCondenser])
@pytest.mark.parametrize("name, value", [("cutoff", -1.0), ("tol", float("nan")),
                                         ("tol", 0.0)])
def test_bad_cutoff_or_tol_is_one_input_error(cls, name, value):
    """The large-interface condensers check ``cutoff`` and ``tol`` as
    :class:`ModalCondenser` does (one InputError naming the argument, before any solve):
    they once built with a NaN ``tol`` (no error ever exceeds it) and a negative ``cutoff``."""
    with pytest.raises(InputError, match=f"{name} = {value!r}: expected a positive number"):
        cls(None, F_MAX, 7, **{name: value})  # refused before the model is read


def test_indefinite_interior_stiffness_keeps_the_static_modes(monkeypatch):
    """A symmetric ``K_ii`` that is not positive definite (one interior diagonal entry
    negated; the static modes handle it, SuperLU factorising ``K_ii``): the condenser by
    partial factorisations refuses it in one InputError that says why, and
    ``modal_condenser`` (its threshold lowered to the block's) keeps the static modes. It
    once raised a RuntimeError blaming CHOLMOD's ordering (the probe of an incomplete
    factor)."""
    import dataclasses

    model = block()
    K = sp.lil_matrix(model.K)
    taken = set(np.asarray(model.contact.dofs).ravel()) | set(np.asarray(model.fixed_dofs))
    j = next(i for i in range(K.shape[0]) if i not in taken)
    K[j, j] = -0.5 * K[j, j]
    model = dataclasses.replace(model, K=sp.csr_matrix(K))
    with pytest.raises(InputError, match="positive definite K_ii"):
        SchurModalCondenser(model, F_MAX, 7, tol=1e-2)
    monkeypatch.setattr(modal, "SCHUR_MIN_CONTACT", 1)
    assert type(modal_condenser(model, F_MAX, 7, tol=1e-2)) is ModalCondenser


def test_nonsymmetric_matrices_keep_the_static_modes(monkeypatch):
    """A nonsymmetric damping matrix (one off-diagonal entry of a Rayleigh ``C`` doubled):
    the condenser by partial factorisations refuses it in one InputError (CHOLMOD factorises
    symmetric matrices), and ``modal_condenser`` (its threshold lowered to the block's)
    catches that refusal and keeps the static modes, which project any ``C``; the symmetric
    model next to it takes the partial factorisations."""
    import dataclasses

    model = block()
    C = sp.lil_matrix(1e-5 * model.K)
    rows, cols = sp.triu(model.K, 1).nonzero()
    i, j = int(rows[0]), int(cols[0])
    C[i, j] = 2 * C[i, j]
    assert C[i, j] != C[j, i]
    unsym = dataclasses.replace(model, C=sp.csr_matrix(C))
    with pytest.raises(InputError, match="needs symmetric"):
        SchurModalCondenser(unsym, F_MAX, 7, tol=1e-2)
    monkeypatch.setattr(modal, "SCHUR_MIN_CONTACT", 1)
    assert type(modal_condenser(unsym, F_MAX, 7, tol=1e-2)) is ModalCondenser
    sym = dataclasses.replace(model, C=sp.csr_matrix(1e-5 * model.K))
    assert type(modal_condenser(sym, F_MAX, 7, tol=1e-2)) is SchurModalCondenser


def test_memory_estimate_counts_the_factor_of_k():
    """The memory the condenser by partial factorisations checks before it runs counts the
    factor of ``K`` (contact rows and front, CHOLMOD's and kvxopt's copies), not only its
    ``m x m`` blocks: at 4096 contact nodes of the pad of benchmarks/scale_3d.py (n_i =
    98,304, m = 12,288, K and M) it is within 10 % of the 16.7 GiB peak measured there
    (docs/studies/large-interface-solve.md; the blocks alone counted 5.6 GiB, and the
    condensation would have started on a 16 GiB machine and run out). On the test
    block, a machine that holds the blocks but not the factor refuses it in one InputError."""
    from helpers.hostile_sizes import machine_of

    assert abs(modal.schur_bytes(98_304, 12_288, 2) / 2**30 - 16.7) <= 0.1 * 16.7
    model = block()
    probe = SchurModalCondenser(model, F_MAX, 7, tol=1e-2)
    k = sum(getattr(probe, nm) is not None for nm in modal.NAMES)
    blocks = 8.0 * (k + 3) * probe.m**2
    full = modal.schur_bytes(probe.ni, probe.m, k)
    with machine_of(int((blocks + full) / 2 / 0.9)), \
            pytest.raises(InputError, match="partial factorisations .* needs about"):
        SchurModalCondenser(model, F_MAX, 7, tol=1e-2)


def test_cholmod_options_are_restored_when_threads_factorise_at_once(monkeypatch):
    """Two threads make partial factorisations at once, the first held inside CHOLMOD's
    symbolic analysis until the second enters it too (or 0.5 s have passed: with the lock it
    cannot), the second then until the first is done: kvxopt's options, one dict for the
    process, end as they began, and both Schur complements equal the one made alone
    (bitwise: the same ordering, the same arithmetic). Without the lock the second thread
    saved the first's changed options and restored them: every later CHOLMOD factorisation
    of the process ran with one ordering method and no postordering."""
    import threading

    cholmod = pytest.importorskip("kvxopt.cholmod")
    _, Kb, _, _, _ = _chain(1e8)
    ref = schur.PartialFactor(Kb).schur(Kb.ii, Kb.ic, Kb.ci, Kb.cc)
    before = dict(cholmod.options)
    real, calls = cholmod.symbolic, []
    second, first_done = threading.Event(), threading.Event()

    def symbolic(*args, **kwargs):
        calls.append(threading.current_thread().name)
        if len(calls) == 1:
            second.wait(0.5)  # the first thread in waits for the second
        else:
            second.set()
            first_done.wait(0.5)  # which then finishes after the first
        return real(*args, **kwargs)

    monkeypatch.setattr(cholmod, "symbolic", symbolic)
    out = {}

    def work(name):
        out[name] = schur.PartialFactor(Kb).schur(Kb.ii, Kb.ic, Kb.ci, Kb.cc)
        if name == "a":
            first_done.set()

    threads = [threading.Thread(target=work, args=(name,), name=name) for name in "ab"]
    threads[0].start()
    while not calls:  # the first is inside the symbolic analysis
        second.wait(0.001)
    threads[1].start()
    for t in threads:
        t.join()
    assert dict(cholmod.options) == before
    assert np.array_equal(out["a"], ref) and np.array_equal(out["b"], ref)
