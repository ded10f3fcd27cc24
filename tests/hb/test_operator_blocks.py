"""fretwear.hb.operator_blocks: the products, transposed products, column norms and Newton
steps of a Jacobian whose harmonic blocks are a ReducedOperator, against the same blocks
stored dense (fretwear.hb.krylov.HarmonicBlocks), the formed dense Jacobian and central finite
differences (tolerances in each test; the blocked and dense condensations agree to rounding:
tests/hb/test_modal_blocked.py)."""

import dataclasses

import numpy as np
import pytest
from helpers.operator_models import F_MAX, ORDERS, block, rel

from fretwear.hb import krylov
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.krylov import HarmonicBlocks, KrylovJacobian
from fretwear.hb.modal import BlockedModalCondenser
from fretwear.hb.operator_blocks import OperatorBlocks
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.preload import static_anchor
from fretwear.hb.problem import DLFTProblem
from fretwear.model import Damping


@pytest.mark.parametrize("damping", [None, Damping(loss_factor=0.02)])
def test_operator_blocks_products_equal_stored_blocks(damping):
    """Every product of OperatorBlocks equals HarmonicBlocks' on the formed blocks (the dense
    path), to rounding (measured <= 7e-16)."""
    model = block(damping)
    red = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2).reduced(2 * np.pi * 15e3, ORDERS)
    ob = OperatorBlocks(red.Z)
    hb = HarmonicBlocks(np.stack(list(red.Z)))
    rng = np.random.default_rng(2)
    U = rng.standard_normal((ob.m, ob.H))
    assert rel(ob.apply(U), hb.apply(U)) < 1e-13
    assert rel(ob.apply_T(U), hb.apply_T(U)) < 1e-13
    rows, cols = np.arange(5, 20), np.arange(3, 30)
    X = rng.standard_normal((cols.size, ob.H, 2))
    assert rel(ob.apply_sub(rows, cols, X), hb.apply_sub(rows, cols, X)) < 1e-13
    V = rng.standard_normal((ob.m // 3, 3 * ob.H))
    assert rel(ob.node_rows(V), hb.node_rows(V)) < 1e-13
    assert rel(ob.sub(rows).dense(), hb.sub(rows).dense()) < 1e-13
    assert rel(ob.leading(2).dense(), hb.leading(2).dense()) < 1e-13
    # the rows the column norms read (kept per set of rows) and the node diagonals, for
    # two sets of rows in turn and the first again: the kept rows follow the set
    for r in (rows, cols, rows):
        for b in range(ob.nb):
            A, ra = ob.row_block(b, r)
            B, rb = hb.row_block(b, r)
            assert rel(A[ra], B[rb]) < 1e-13, b
            assert rel(ob.node_diagonal(b, 3), hb.node_diagonal(b, 3)) < 1e-13, b
    # the panels the column norms form into one buffer: consecutive rows (views of the
    # stored matrices' rows), rows with gaps (formed from the first to the last) and rows too
    # far apart (taken): the same entries as row_block's to rounding (the gemm of the modal
    # term on another number of rows may round differently: measured <= 5e-18 of the
    # largest entry)
    buf = np.empty((12, ob.m), dtype=ob.op.dtype)
    for r in (np.arange(6, 18), np.array([0, 1, 2, 9, 10, 11]), np.array([0, 1, 2, 30, 31, 32]),
              np.arange(ob.m - 3, ob.m)):
        for b in range(ob.nb):
            A, ra = ob.row_panel(b, r, buf)
            B, rb = ob.row_block(b, r)
            assert np.abs(A[ra] - B[rb]).max() <= 1e-15 * np.abs(B[rb]).max(), b
            if b and r[-1] - r[0] < buf.shape[0]:
                assert np.shares_memory(A, buf)  # formed into the buffer, no new array


@pytest.mark.parametrize("damping", [None, Damping(loss_factor=0.02)])
def test_block_products_equal_the_formed_blocks(damping):
    """``block_products`` (the preconditioner's sharing test multiplies by the blocks without
    forming them) of OperatorBlocks, of HarmonicBlocks and of the active view on a subset of
    DOFs: column ``j`` equals the formed block ``blocks[j]`` (its real part for block 0, as
    ``Z0``) times ``V[:, j]`` by numpy, for real and complex ``V`` and blocks repeated and out
    of order, to rounding (a sum of the same terms in another order: 1e-13)."""
    model = block(damping)
    red = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2).reduced(2 * np.pi * 15e3, ORDERS)
    ob = OperatorBlocks(red.Z)
    formed = np.stack(list(red.Z))
    hb = HarmonicBlocks(formed)
    rng = np.random.default_rng(5)
    blocks = [3, 0, 1, 3, 2, 0]
    dofs = np.flatnonzero(rng.random(ob.m) < 0.8)
    for V in (rng.standard_normal((ob.m, 6)),
              rng.standard_normal((ob.m, 6)) + 1j * rng.standard_normal((ob.m, 6))):
        ref = np.stack([(formed[b].real if b == 0 else formed[b]) @ V[:, j]
                        for j, b in enumerate(blocks)], axis=1)
        for Z in (ob, hb):
            assert rel(Z.block_products(blocks, V), ref) < 1e-13
        sub = np.stack([(formed[b].real if b == 0 else formed[b])[np.ix_(dofs, dofs)]
                        @ V[dofs, j] for j, b in enumerate(blocks)], axis=1)
        view = krylov._ActiveView(ob, dofs)
        assert rel(view.block_products(blocks, V[dofs]), sub) < 1e-13


@pytest.mark.parametrize("damping", [None, Damping(loss_factor=0.02)])
def test_preconditioner_on_operator_blocks_equals_the_formed_blocks(damping):
    """The mean-gain preconditioner's sharing test multiplies by the operator's blocks
    (block_products) instead of formed blocks: on OperatorBlocks, on the active view of a
    subset of DOFs and on the same blocks stored formed (HarmonicBlocks: the products by
    numpy's matrix product, the former path), the same harmonics share factors and the
    factors are equal to rounding (1e-12 of their largest entry: the same LU of blocks
    formed by the same operations), with gains that make some harmonics share and others
    not (asserted)."""
    model = block(damping)
    red = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2).reduced(2 * np.pi * 15e3, ORDERS)
    ob = OperatorBlocks(red.Z)
    formed = np.stack(list(red.Z))
    nc = ob.m // 3
    rng = np.random.default_rng(6)
    gbar = np.tile(0.6 * np.eye(3), (nc, 1, 1)) + 0.05 * rng.standard_normal((nc, 3, 3))
    gosc = np.tile(0.3 * np.eye(3), (nc, 1, 1))
    eps = 0.5 * np.abs(np.diagonal(formed[0])).max()
    keep = np.flatnonzero(rng.random(nc) < 0.8)
    dofs = (keep[:, None] * 3 + np.arange(3)).reshape(-1)
    cases = [(ob, HarmonicBlocks(formed), gbar, gosc),
             (krylov._ActiveView(ob, dofs), HarmonicBlocks(formed).sub(dofs), gbar[keep],
              gosc[keep])]
    for Zo, Zh, g0, g1 in cases:
        po = krylov.MeanGainPreconditioner(g0, Zo, eps, gosc=g1)
        ph = krylov.MeanGainPreconditioner(g0, Zh, eps, gosc=g1)
        assert [h for _, h in po.groups] == [h for _, h in ph.groups]
        assert 0 < po.shared < ob.nb - 1, [h for _, h in po.groups]
        for (a, _), (b, _) in zip(po.groups, ph.groups, strict=True):
            assert np.array_equal(a[1], b[1])
            assert np.abs(a[0] - b[0]).max() <= 1e-12 * np.abs(b[0]).max()


def test_operator_jacobian_against_dense_and_finite_differences():
    """In partial slip: the operator Jacobian's products, transposed products, column norms
    and Newton step on the ReducedOperator equal the formed dense Jacobian of the same
    problem (to 1e-10: GMRES_RTOL is 1e-10 for the step); one product against central finite
    differences of the residual (step 1e-7 of |U|: truncation and rounding leave ~1e-6)."""
    model = block(traction=4.5e5)
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    basis = FourierBasis.up_to(3, 64)
    anchor = static_anchor(model, condenser=bc)
    sol = solve_periodic(model, basis, frequency=12e3, anchor=anchor, condenser=bc)
    assert sol.success
    red = bc.reduced(2 * np.pi * 12e3, basis.orders)
    kw = dict(eps=sol.eps, anchor=sol.anchor)
    pk = DLFTProblem(red, model.contact, basis, jacobian="krylov", **kw)
    pd = DLFTProblem(red, model.contact, basis, jacobian="dense", **kw)
    U = sol.U.reshape(pk.m, pk.H)  # near the solution, off it (a residual to compare)
    U = U * (1.0 + 1e-3 * np.random.default_rng(4).standard_normal(U.shape))
    fk, J = pk.residual(U)
    fd, Jd = pd.residual(U)
    norms = J.column_norms()
    assert isinstance(J, KrylovJacobian) and isinstance(J.Z, OperatorBlocks)
    assert J.active_nodes().size > 0  # partial slip: the step is not trivial
    assert rel(fk, fd) < 1e-10
    v = np.random.default_rng(3).standard_normal(pk.m * pk.H)
    assert rel(J @ v, Jd @ v) < 1e-12
    assert rel(J.T @ v, Jd.T @ v) < 1e-12
    assert rel(J.column_norms(), np.linalg.norm(Jd, axis=0)) < 1e-12
    # the active rows in panels of one and of two nodes (several panels per block, the
    # sums in the same node order): the same norms (bit for bit with this BLAS; the modal
    # term's gemm on fewer rows may round otherwise, 1e-14 bounds that)
    for panel in (3, 6):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(krylov, "COLUMN_NORM_PANEL", panel)
            assert rel(J.column_norms(), norms) < 1e-14
    assert rel(J.solve(v), np.linalg.solve(Jd, v)) < 1e-8
    h = 1e-7 * np.linalg.norm(U) / np.linalg.norm(v)
    fp, _ = pk.residual(U + h * v.reshape(U.shape), False)
    fm, _ = pk.residual(U - h * v.reshape(U.shape), False)
    assert rel(J @ v, (fp - fm) / (2 * h)) < 1e-5


def test_bounded_preconditioner_factors_give_the_same_step(monkeypatch):
    """The GMRES step on operator blocks with the preconditioner's factors bounded to one
    factorisation (every harmonic shares it) equals the dense solve of the formed Jacobian
    (GMRES_RTOL 1e-10: asserted 1e-8), in partial slip."""
    from fretwear.hb import krylov, operator_blocks

    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", 0)  # GMRES whatever the size
    monkeypatch.setattr(operator_blocks.OperatorBlocks, "factor_budget", 1)  # one LU
    model = block(traction=4.5e5)
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    basis = FourierBasis.up_to(3, 64)
    sol = solve_periodic(model, basis, frequency=12e3, condenser=bc,
                         anchor=static_anchor(model, condenser=bc))
    red = bc.reduced(2 * np.pi * 12e3, basis.orders)
    kw = dict(eps=sol.eps, anchor=sol.anchor)
    pk = DLFTProblem(red, model.contact, basis, jacobian="krylov", **kw)
    pd = DLFTProblem(red, model.contact, basis, jacobian="dense", **kw)
    U = sol.U.reshape(pk.m, pk.H)
    _, J = pk.residual(U)
    _, Jd = pd.residual(U)
    v = np.random.default_rng(5).standard_normal(pk.m * pk.H)
    assert rel(J.solve(v), np.linalg.solve(Jd, v)) < 1e-8
    # the active blocks as a view of the operator (no copies of its matrices: what a large
    # share of active DOFs takes) give the same step, to the GMRES tolerance as well
    monkeypatch.setattr(krylov, "VIEW_FRACTION", 0.0)
    J.owner._precond = J.owner._active_Z = None
    assert rel(J.solve(v), np.linalg.solve(Jd, v)) < 1e-8
    assert isinstance(J.owner._active_Z[2], krylov._ActiveView)
    # without sharing by closeness, only the bound makes the harmonics share one LU
    act = J.active_nodes()
    dofs = (act[:, None] * 3 + np.arange(3)).reshape(-1)
    gbar = J.G[act].reshape(act.size, 3, basis.size, 3, basis.size)[:, :, 0, :, 0]
    Za = J.Z.sub(dofs)
    formed = []
    monkeypatch.setattr(Za, "block", lambda b: formed.append(b) or Za.op.block(b))
    pc = krylov.MeanGainPreconditioner(np.ascontiguousarray(gbar), Za, J.eps, share=False)
    assert len(pc.factors) == basis.k + 1 and len({id(f) for f in pc.factors}) == 1
    assert formed == []  # the harmonics that share by the bound form no block
    monkeypatch.undo()
    pc = krylov.MeanGainPreconditioner(np.ascontiguousarray(gbar), J.Z.sub(dofs), J.eps,
                                       share=False)
    assert len({id(f) for f in pc.factors}) == basis.k + 1


def test_every_dof_active_shares_the_stored_matrices():
    """The active sub-operator and the rows of every contact DOF are the operator itself (no
    copy of its m x m matrices: 2.25 GiB each at 4096 contact nodes), and give the products,
    blocks and preconditioner of a copied operator (the former behaviour) exactly: the same
    arithmetic on the same numbers. Most but not all of them: the view (krylov._ActiveView)
    against the copied sub-operator."""
    from fretwear.hb.krylov import MeanGainPreconditioner
    from fretwear.hb.modal_operator import ReducedOperator

    model = block(Damping(loss_factor=0.02))
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    op = bc.reduced(2 * np.pi * 12e3, ORDERS[:3]).Z
    Z = OperatorBlocks(op)
    every = np.arange(Z.m)
    assert Z.sub(every).op is op and Z.sub(every[::-1]).op is not op
    copy = OperatorBlocks(ReducedOperator([A.copy() for A in op.mats], op.coef,
                                          [None if u is None else u.copy() for u in op.U],
                                          [None if y is None else y.copy() for y in op.Y],
                                          op.symmetric))
    A, rows = Z.row_block(2, every)
    assert np.array_equal(rows, every) and np.array_equal(A, copy.block(2))
    x = np.random.default_rng(2).standard_normal(Z.m * Z.H)
    assert np.array_equal(Z.sub(every).apply(x), copy.apply(x))
    g = np.tile(0.5 * np.eye(3), (Z.m // 3, 1, 1))
    pa = MeanGainPreconditioner(g, Z.sub(every), 1e8)
    pb = MeanGainPreconditioner(g, copy, 1e8)
    assert np.array_equal(pa.apply(x), pb.apply(x))
    # most but not all DOFs: the view's products and blocks against the copied sub-operator
    # (the same sums with zeros more: to rounding, 1e-13)
    from fretwear.hb.krylov import _ActiveView

    dofs = every[every % 7 != 3]
    view, sub = _ActiveView(Z, dofs), Z.sub(dofs)
    y = x[:dofs.size * Z.H]
    assert rel(view.apply(y), sub.apply(y)) < 1e-13
    assert np.array_equal(view.Z0, sub.Z0) and rel(view.block(2), sub.block(2)) < 1e-13


@pytest.mark.parametrize("damping", [None, Damping(loss_factor=0.02)])
def test_single_precision_products_and_the_loose_steps_that_take_them(damping, monkeypatch):
    """OperatorBlocks.single() (made once, then kept) multiplies as the double operator does to
    single precision (1e-6 relative: float32's 6e-8 times the rounding of sums over a few
    hundred terms; measured 1e-7), and the same for the view of active DOFs. GMRES takes it
    (KrylovOptions.single_products) on a Newton step solved to rtol 1e-3 (asserted: its
    products go through the single blocks), whose residual with the double Jacobian is then
    within 1.01 x rtol (the single products' 1e-7 error added to GMRES's own); a step solved
    to 1e-9, below single_products_rtol, takes the double blocks only and equals the dense
    solve of the formed Jacobian to 1e-7 (as test_bounded_preconditioner_factors_give_the_
    same_step's 1e-8 with GMRES at 1e-9 instead of 1e-10). Off (on by default), the loose
    step takes the double blocks too."""
    from fretwear.hb.options import KrylovOptions

    model = block(damping, traction=4.5e5)
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    basis = FourierBasis.up_to(3, 32)
    red = bc.reduced(2 * np.pi * 12e3, basis.orders)
    ob = OperatorBlocks(red.Z)
    tw = ob.single()
    assert tw is ob.single() and tw.op.mats[0].dtype == np.float32
    x = np.random.default_rng(4).standard_normal((ob.m, ob.H))
    assert rel(tw.apply(x), ob.apply(x)) < 1e-6
    dofs = np.arange(ob.m)[np.arange(ob.m) % 5 != 1]
    view = krylov._ActiveView(ob, dofs)
    assert rel(view.single().apply(x[dofs]), view.apply(x[dofs])) < 1e-6
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", 0)  # GMRES whatever the size
    prob = DLFTProblem(red, model.contact, basis, eps="auto",
                       anchor=static_anchor(model, condenser=bc), jacobian="krylov")
    dense = DLFTProblem(red, model.contact, basis, eps=prob.eps, anchor=prob.anchor,
                        jacobian="dense")
    U = 0.5 * prob.initial_guess()
    f, J = prob.residual(U)
    _, Jd = dense.residual(U)
    assert J.active_nodes().size
    used = []
    single_apply = OperatorBlocks.apply

    def spy(self, V):
        used.append(self.op.mats[0].dtype == np.float32)
        return single_apply(self, V)

    monkeypatch.setattr(OperatorBlocks, "apply", spy)
    assert prob.krylov.single_products  # (on by default)
    prob.krylov = KrylovOptions(single_products=True)
    s = J.solve(f, rtol=1e-3)
    assert used and all(used)
    assert np.linalg.norm(Jd @ s - f) <= 1.01e-3 * np.linalg.norm(f)
    used[:] = []
    s = J.solve(f, rtol=1e-9)
    assert used and not any(used)
    assert rel(s, np.linalg.solve(Jd, f)) < 1e-7
    prob.krylov = KrylovOptions(single_products=False)
    used[:] = []
    J.solve(f, rtol=1e-3)
    assert used and not any(used)


@pytest.mark.parametrize("damping", [None, Damping(loss_factor=0.02)])
def test_compressed_twin_within_its_stated_bound(damping, monkeypatch):
    """OperatorBlocks.single(compress) (a face of 13 x 13 nodes, leaves of 8 nodes, so that
    the matrices have low-rank blocks at 1e-7, asserted): each compressed matrix formed
    (float32 blocks, in float64)
    differs from the stored X^cc by at most its stated relative error (the compression's
    plus float32's rounding, hb/hmatrix.py; tol 1e-7), and that error is within the bound
    plus a few float32 roundoffs; the twin's products equal those of the operator on the
    formed compressed matrices (the same sums in float32: 1e-5, measured 1e-7) and differ
    from the double operator's by less than the single twin's 1e-6 (test above) allows.
    The compression is made once per condensation: an operator of the same condenser at
    another frequency takes the same compressed matrices. An active sub-operator's twin is
    the cut of the whole one's, against the double sub-operator the same way."""
    from fretwear.hb import hmatrix
    from fretwear.hb.modal_operator import ReducedOperator

    monkeypatch.setattr(hmatrix, "LEAF", 8)
    model = block(damping, traction=4.5e5, cells=12)
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    basis = FourierBasis.up_to(3, 32)
    ob = OperatorBlocks(bc.reduced(2 * np.pi * 12e3, basis.orders).Z)
    tw = ob.single(1e-7)
    assert tw is ob.single(1e-7) and tw is not ob.single()
    assert all(isinstance(A, hmatrix.HMatrix) and A.dtype == np.float32
               for A in tw.op.mats)
    assert all(A.ranks().size and A.ranks().min() > 0 for A in tw.op.mats)
    other = OperatorBlocks(bc.reduced(2 * np.pi * 9e3, basis.orders).Z).single(1e-7)
    assert all(a is b for a, b in zip(other.op.mats, tw.op.mats, strict=True))
    rng = np.random.default_rng(6)

    def check(Z, T, mats):
        formed = [A.toarray().astype(float) for A in T.op.mats]
        for F, D, A in zip(formed, mats, T.op.mats, strict=True):
            assert np.linalg.norm(F - D) <= A.error * np.linalg.norm(D)
            assert A.error <= 1e-7 + 5 * 2.0**-24
        on_formed = OperatorBlocks(ReducedOperator(formed, Z.op.coef, Z.op.U, Z.op.Y,
                                                   Z.op.symmetric))
        x = rng.standard_normal((Z.m, Z.H))
        assert rel(T.apply(x), on_formed.apply(x)) < 1e-5
        assert rel(T.apply(x), Z.apply(x)) < 1e-6

    check(ob, tw, ob.op.mats)
    dofs = np.arange(ob.m)[np.arange(ob.m) % 5 != 1]
    sub = ob.sub(dofs)
    check(sub, sub.single(1e-7), [A[np.ix_(dofs, dofs)] for A in ob.op.mats])
    view = krylov._ActiveView(ob, dofs)
    x = rng.standard_normal((dofs.size, ob.H))
    assert rel(view.single(1e-7).apply(x), view.apply(x)) < 1e-6


def test_solve_with_the_compressed_twin_has_the_dense_root(monkeypatch):
    """solve_periodic on GMRES steps (every size) whose loose products go through the
    compressed twin (KrylovOptions.compressed_products_min_dofs = 1; a face of 13 x 13
    nodes, leaves of 8: low-rank blocks; asserted to be used) converges to the root of the
    solve with the dense single twin:
    the residual is the dense operator's in both, so the roots differ by about the solve's
    tolerance times the Jacobian's amplification (1e-10 relative residual; measured 4.6e-9
    between the two: 1e-7 bounds it; a residual through the twin's float32 compressed
    matrices cannot reach 1e-10 at all: the solve did not converge in 10 min)."""
    from fretwear.hb import hmatrix
    from fretwear.hb.options import PERIODIC, KrylovOptions

    monkeypatch.setattr(hmatrix, "LEAF", 8)
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", 0)  # GMRES whatever the size
    model = block(traction=4.5e5, cells=12)
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    basis = FourierBasis.up_to(3, 64)
    anchor = static_anchor(model, condenser=bc)
    used = []
    single = OperatorBlocks.single

    def spy(self, compress=None):
        used.append(compress)
        return single(self, compress)

    monkeypatch.setattr(OperatorBlocks, "single", spy)
    out = {}
    for least in (None, 1):
        used[:] = []
        opts = dataclasses.replace(PERIODIC, tol=1e-10,
                                   krylov=KrylovOptions(compressed_products_min_dofs=least))
        sol = solve_periodic(model, basis, frequency=12e3, anchor=anchor, condenser=bc,
                             options=opts)
        assert sol.success
        assert used and all((c is None) == (least is None) for c in used), used
        out[least] = sol.U
    assert rel(out[1], out[None]) < 1e-7
