"""A hierarchical low-rank (H-matrix) compression of a real ``m x m`` matrix given with the
positions of the contact nodes its rows and columns belong to: products ``A X`` and
``A^T X`` below ``m^2`` operations (docs/theory.md, "Compressed interface operator").

The condensed contact stiffness ``K^cc`` and mass ``M^cc`` of an elastic body couple every
pair of contact nodes, but smoothly away from the diagonal: the block of two groups of nodes
that are far apart against their size has a low numerical rank. The compression is the
textbook one (Hackbusch, *Hierarchical Matrices*, 2015, ch. 5-6; Bebendorf 2008):

1. A cluster tree of the nodes by geometric bisection: a cluster of more than ``leaf``
   nodes is split at the median of its bounding box's longest side; a node's ``d`` DOFs
   stay together (rows ``d p .. d p + d - 1`` of node ``p``).
2. A block tree of pairs of clusters ``(s, t)`` from ``(root, root)``: a pair is
   *admissible* when ``max(diam s, diam t) <= eta dist(s, t)`` (bounding boxes), and its
   block is stored as ``U V^T`` of the lowest rank within the block's share of the error
   budget; a pair that is not admissible is split into its children's pairs until one of
   them is a leaf, where the block is stored dense.
3. The rank of an admissible block ``B`` (``b_r x b_c``): a randomised range finder
   (Halko, Martinsson and Tropp 2011, alg. 4.2, blocks of :data:`SAMPLES` columns) gives
   an orthonormal ``Q`` with ``||B - Q Q^T B||_F`` computed exactly (not estimated) below
   the block's budget, then the SVD of ``Q^T B`` truncates to the fewest singular values
   that keep ``||B - U V^T||_F^2 = ||B - Q Q^T B||_F^2 + sum_{i > k} s_i^2`` within it (the
   two parts are orthogonal). A block whose factors would not be smaller than the block is
   stored dense.

**Error bound.** Block ``b`` of ``|b|`` entries gets the budget
``e_b = tol ||A||_F sqrt(|b| / m^2)``; the blocks partition ``A``, so
``||A - A_H||_F^2 = sum_b ||B_b - U_b V_b^T||_F^2 <= tol^2 ||A||_F^2``: the relative
Frobenius error of the whole matrix is at most ``tol``. The achieved error is kept
(:attr:`HMatrix.error`, relative, exact up to rounding) and is what callers quote. For a
symmetric ``A`` only the blocks on and above the diagonal are compressed; the mirrored
block is the transpose, sharing the arrays (an asymmetry of rounding's size is added to the
stated error: then a bound, by the triangle inequality).

:meth:`HMatrix.astype` keeps the blocks in float32 (half the bytes a product reads), the
stored entries' rounding added to the stated error: GMRES's compressed twin of the condensed
operator (:meth:`fretwear.hb.modal_operator.ReducedOperator.single`).

A product ``A X`` (``X`` of ``r`` columns) costs ``sum_b k_b (b_r + b_c) r`` for the
low-rank blocks plus the dense leaves: ``O(m log m)`` per column for a fixed rank, against
``m^2`` dense. It is made by compiled kernels (:func:`_apply`) over the packed stacks: one
BLAS ``gemm`` per stack (SciPy's, called by symbol so that the kernels are cached), the
gathers and scatters between them compiled, in the blocks' order (the same sums in every
run). Its rounding is that of any product in the blocks' precision: every entry of the
result within ``g_N |A_H| |X|`` of the exact one (``|U| |V|^T`` for a low-rank block,
``g_N = N u / (1 - N u)``, ``N`` the terms and partial sums of a row; Higham 2002, sec. 3.5);
the near field's diagonal blocks and its mirrored ones are summed apart (shorter sums).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from llvmlite import binding as _llvm
from numba import njit, types
from numba.extending import get_cython_function_address

from fretwear.errors import InputError

#: nodes in a leaf cluster
LEAF = 32
#: admissibility ``max(diam s, diam t) <= ETA dist(s, t)``
ETA = 2.0
#: columns of the random sample per step of the range finder
SAMPLES = 16


@dataclass
class Cluster:
    """Nodes ``order[start:stop]`` of the cluster tree, with their bounding box and
    children (none for a leaf)."""

    start: int
    stop: int
    lo: np.ndarray
    hi: np.ndarray
    children: tuple = ()

    @property
    def diam(self) -> float:
        return float(np.linalg.norm(self.hi - self.lo))


def cluster_tree(coords: np.ndarray, leaf: int = LEAF) -> tuple[np.ndarray, Cluster]:
    """``(order, root)``: the nodes (rows of ``coords``, (n, dim)) reordered so that every
    cluster is a contiguous range, and the tree (module docstring, step 1)."""
    coords = np.asarray(coords, dtype=float)
    order = np.arange(coords.shape[0])

    def build(start, stop):
        pts = coords[order[start:stop]]
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        c = Cluster(start, stop, lo, hi)
        if stop - start <= leaf or not np.any(hi > lo):
            return c
        axis = int(np.argmax(hi - lo))
        idx = np.argsort(pts[:, axis], kind="stable")
        order[start:stop] = order[start:stop][idx]
        mid = start + (stop - start) // 2
        c.children = (build(start, mid), build(mid, stop))
        return c

    return order, build(0, coords.shape[0])


def _distance(s: Cluster, t: Cluster) -> float:
    gap = np.maximum(0.0, np.maximum(s.lo - t.hi, t.lo - s.hi))
    return float(np.linalg.norm(gap))


def block_tree(root: Cluster, eta: float = ETA) -> list[tuple[Cluster, Cluster, bool]]:
    """The leaves ``(s, t, admissible)`` of the block tree of ``(root, root)`` (module
    docstring, step 2): a partition of the matrix."""
    out = []

    def visit(s, t):
        if max(s.diam, t.diam) <= eta * _distance(s, t):
            out.append((s, t, True))
        elif not s.children or not t.children:
            out.append((s, t, False))
        else:
            for a in s.children:
                for b in t.children:
                    visit(a, b)

    visit(root, root)
    return out


def low_rank(B: np.ndarray, budget: float, rng: np.random.Generator):
    """``(U, V, err)`` with ``||B - U V^T||_F = err <= budget`` of the lowest rank the
    range finder's basis allows (module docstring, step 3), or None when the factors would
    hold as many numbers as ``B``."""
    br, bc = B.shape
    top = br * bc // (br + bc)  # the rank at which the factors are as large as B
    Q = np.zeros((br, 0))
    R = B
    while True:
        if Q.shape[1] >= top:
            return None
        G = rng.standard_normal((bc, min(SAMPLES, top - Q.shape[1])))
        Y = R @ G  # the part of B's range not yet in Q
        Y -= Q @ (Q.T @ Y)
        Qn, _ = np.linalg.qr(Y)
        Qn -= Q @ (Q.T @ Qn)  # re-orthogonalise (one more pass)
        Qn, _ = np.linalg.qr(Qn)
        Q = np.hstack([Q, Qn])
        C = Q.T @ B
        R = B - Q @ C
        rest = float(np.linalg.norm(R))
        if rest <= budget:
            break
    W, s, Vt = np.linalg.svd(C, full_matrices=False)
    tail = np.sqrt(np.cumsum((s**2)[::-1])[::-1])  # tail[k] = ||s[k:]||
    tail = np.append(tail, 0.0)
    err = np.sqrt(rest**2 + tail**2)
    k = int(np.argmax(err <= budget))
    if k >= top:
        return None
    return (np.ascontiguousarray((Q @ W[:, :k]) * s[:k]), np.ascontiguousarray(Vt[:k].T),
            float(err[k]))


@dataclass
class Block:
    """Rows ``r0:r1`` and columns ``c0:c1`` of the reordered matrix: ``D`` dense, or
    ``U V^T`` (``D`` None). ``of``: for the mirror of a block of a symmetric matrix, that
    block (the arrays are shared: the mirror is its transpose)."""

    r0: int
    r1: int
    c0: int
    c1: int
    D: np.ndarray | None = None
    U: np.ndarray | None = None
    V: np.ndarray | None = None
    of: Block | None = None

    def mirror(self) -> Block:
        """The transpose of this block, sharing its arrays."""
        if self.D is not None:
            return Block(self.c0, self.c1, self.r0, self.r1, D=self.D.T, of=self)
        return Block(self.c0, self.c1, self.r0, self.r1, U=self.V, V=self.U, of=self)

    @property
    def rank(self) -> int:
        return -1 if self.D is not None else self.U.shape[1]


class HMatrix:
    """A compressed real matrix (module docstring): ``A @ X``, ``A.T @ X`` for ``X`` (n,)
    or (n, r), real or complex; :meth:`sub` restricts it to rows and columns.

    The blocks are stored in stacks that make a product one BLAS call per stack, not one
    per block, all stacks packed in one array and multiplied by a compiled loop
    (:class:`_Plan`): the dense blocks of a block row side by side, the low-rank factors of
    every block on a cluster side by side (one stack per cluster when the matrix is
    symmetric: the ``U`` of block ``(s, t)`` is the ``V`` of its mirror ``(t, s)``).

    Attributes
    ----------
    rows, cols : the original row (column) of each row (column) of the reordered matrix.
    blocks : the :class:`Block` partition of the reordered matrix (views into the stacks).
    error : achieved ``||A - A_H||_F / ||A||_F`` (exact up to rounding).
    tol : the bound it was compressed to.
    """

    ndim = 2

    def __init__(self, rows, cols, blocks, error: float = 0.0, tol: float = 0.0):
        self.rows, self.cols = np.asarray(rows), np.asarray(cols)
        self.blocks = list(blocks)
        self.error, self.tol = float(error), float(tol)
        self._plan = _Plan(self.blocks)
        self.dtype = self._plan.dtype
        self._transposed = False

    @property
    def shape(self) -> tuple[int, int]:
        return (self.cols.size, self.rows.size) if self._transposed else (self.rows.size,
                                                                           self.cols.size)

    @property
    def nbytes(self) -> int:
        """Bytes held (the stacks and the orderings)."""
        return self._plan.nbytes + self.rows.nbytes + self.cols.nbytes

    @property
    def T(self) -> HMatrix:
        out = object.__new__(HMatrix)
        out.__dict__.update(self.__dict__)
        out._transposed = not self._transposed
        return out

    def ranks(self) -> np.ndarray:
        """Rank of every low-rank block."""
        return np.array([b.rank for b in self.blocks if b.D is None], dtype=np.int64)

    def __matmul__(self, X):
        """``A X`` in the blocks' precision (:attr:`dtype`: float64, or float32 for
        :meth:`astype`'s copy); a complex ``X`` as its real and imaginary parts side by side
        (one pass over the blocks)."""
        X = np.asarray(X)
        one = X.ndim == 1
        X2 = X.reshape(X.shape[0], -1)
        if np.iscomplexobj(X2):
            r = X2.shape[1]
            Y = self @ np.hstack([X2.real, X2.imag])
            out = Y[:, :r] + 1j * Y[:, r:]
            return out[:, 0] if one else out
        rows, cols = (self.cols, self.rows) if self._transposed else (self.rows, self.cols)
        Xp = np.ascontiguousarray(X2[cols], dtype=self.dtype)
        Yp = self._plan.apply(Xp, rows.size, self._transposed)
        Y = np.empty_like(Yp)
        Y[rows] = Yp
        return Y[:, 0] if one else Y

    def astype(self, dtype) -> HMatrix:
        """A copy with every block in the real ``dtype`` (float32: half the bytes a product
        reads, products in float32 arithmetic). The stated :attr:`error` adds the
        rounding of the stored entries: an entry moves by at most ``u |a|`` (``u`` the unit
        roundoff, ``2^-24`` for float32), so a dense block ``D`` by ``u ||D||_F`` and a
        low-rank block ``U V^T`` by at most ``u (2 + u) || |U| |V|^T ||_F`` (Higham,
        *Accuracy and Stability of Numerical Algorithms*, 2002, sec. 3.5); the blocks
        partition the matrix, so the squares add, relative to ``||A_H||_F`` (that of
        ``A`` to within the stated error). The products' own rounding (``k u`` per entry
        of a length-``k`` sum) is that of any product in that precision, not counted."""
        dtype = np.dtype(dtype)
        u = float(np.finfo(dtype).eps) / 2
        mirrored = {id(b.of) for b in self.blocks if b.of is not None}
        new, out, err2, norm2 = {}, [], 0.0, 0.0
        for b in sorted(self.blocks, key=lambda b: b.of is not None):  # originals first
            w = 2.0 if id(b) in mirrored else 1.0  # it and its mirror
            if b.of is not None:
                nb = new[id(b.of)].mirror()
            elif b.D is not None:
                nb = Block(b.r0, b.r1, b.c0, b.c1, D=np.array(b.D, dtype=dtype))
                err2 += w * (u * float(np.linalg.norm(b.D))) ** 2
                norm2 += w * float(np.linalg.norm(b.D)) ** 2
            else:
                nb = Block(b.r0, b.r1, b.c0, b.c1, U=np.array(b.U, dtype=dtype),
                           V=np.array(b.V, dtype=dtype))
                bound = float(np.linalg.norm(np.abs(b.U) @ np.abs(b.V).T))
                err2 += w * (u * (2 + u) * bound) ** 2
                norm2 += w * float(np.linalg.norm(b.U @ b.V.T)) ** 2
            new[id(b)] = nb
            out.append(nb)
        rounding = np.sqrt(err2 / norm2) if norm2 else 0.0
        return HMatrix(self.rows, self.cols, out, self.error + rounding, self.tol)

    def toarray(self) -> np.ndarray:
        """The matrix ``A_H`` formed (for checks)."""
        Ap = np.zeros((self.rows.size, self.cols.size))
        for b in self.blocks:
            Ap[b.r0 : b.r1, b.c0 : b.c1] = b.D if b.D is not None else b.U @ b.V.T
        out = np.empty_like(Ap)
        out[np.ix_(self.rows, self.cols)] = Ap
        return out.T if self._transposed else out

    def sub(self, rows: np.ndarray, cols: np.ndarray | None = None) -> HMatrix:
        """The matrix restricted to the rows ``rows`` and columns ``cols`` (None: ``rows``),
        in that order; the same blocks, cut (its error is at most this one's in absolute
        terms)."""
        if self._transposed:
            return self.T.sub(rows if cols is None else cols, rows).T
        rows = np.asarray(rows, dtype=np.int64)
        cols = rows if cols is None else np.asarray(cols, dtype=np.int64)
        same = np.array_equal(rows, cols)  # then a block and its mirror stay so
        rp, rsel = _restrict(self.rows, rows)
        cp, csel = _restrict(self.cols, cols)
        cut = {}  # a factor shared by a block and its mirror is cut once

        def take(a, idx, key):
            k = (id(a), *key)
            if k not in cut:
                cut[k] = np.ascontiguousarray(a[idx])
            return cut[k]

        out, new = [], {}
        order = sorted(self.blocks, key=lambda b: b.of is not None)  # originals first
        for b in order:
            i0, i1 = np.searchsorted(rp, [b.r0, b.r1])
            j0, j1 = np.searchsorted(cp, [b.c0, b.c1])
            if i0 == i1 or j0 == j1:
                continue
            ri, ci = rp[i0:i1] - b.r0, cp[j0:j1] - b.c0
            if same and b.of is not None and id(b.of) in new:
                nb = new[id(b.of)].mirror()
            elif b.D is not None:
                nb = Block(i0, i1, j0, j1, D=np.ascontiguousarray(b.D[np.ix_(ri, ci)]))
            else:
                tr, tc = ("", "") if same else ("r", "c")
                nb = Block(i0, i1, j0, j1, U=take(b.U, ri, (tr, b.r0, i0, i1)),
                           V=take(b.V, ci, (tc, b.c0, j0, j1)))
            new[id(b)] = nb
            out.append(nb)
        return HMatrix(rsel, csel, out, self.error, self.tol)


class _Plan:
    """The packed storage of an :class:`HMatrix`'s blocks and their product by compiled
    kernels (:func:`_apply`): every stack in one array ``vals`` of the blocks' precision, with
    integer tables of where each stack sits and which rows and columns it touches.

    Far field: the low-rank factors of the blocks on one cluster side by side (a *stack*
    ``W``, ``(a1 - a0, k)``), each block ``b`` owning coefficient rows ``o_b .. o_b + k_b`` of
    ``C``; ``cols`` lists per column range its ``V`` stack (``C[idx] = V_s^T x_s``), ``rows``
    per row range its ``U`` stack (``y_s += U_s C[idx]``); the transpose swaps the two. A
    symmetric matrix shares one stack per cluster between the two tables. Near field: per row
    range the dense blocks side by side in two arrays, ``D1`` those that are not mirrored and
    ``D2`` those whose mirror is a block below the diagonal (applied transposed too: a
    symmetric near field is stored once). Table rows are ``(a0, a1, offset, k, index
    offset)`` and ``(r0, r1, offset of D1, j0, offset of D2, w, index offset)``, ``D1`` of
    ``j0`` and ``D2`` of ``w - j0`` columns. The blocks' arrays are replaced by views into
    ``vals`` (nothing is held twice).

    Each stack's product is one BLAS ``gemm`` on contiguous operands, called from the
    compiled loop with the gathers and scatters beside it (no Python per cluster); the
    tables are in the blocks' order, so the sums are made in the same order in every run
    (an order by memory address changed their rounding from run to run)."""

    def __init__(self, blocks: list[Block]):
        self._parts, self._size = [], 0  # the arrays of vals, in order, and its length
        mirrored = {id(b.of) for b in blocks if b.D is not None and b.of is not None}
        self.near, self.gidx = self._pack_near(blocks, mirrored)
        far = [b for b in blocks if b.D is None and b.U.shape[1]]
        self.k = int(sum(b.U.shape[1] for b in far))
        self.rows, self.cols, self.fidx, views = self._pack_far(far)
        # one precision for every stored entry (the kernels' gemm is chosen by it): a block
        # of another precision is cast, as NumPy's products would have promoted it
        self.dtype = (np.result_type(*self._parts) if self._parts else np.dtype(float))
        self.vals = (np.concatenate([a.ravel() for a in self._parts]).astype(self.dtype,
                                                                              copy=False)
                     if self._parts else np.zeros(0))
        del self._parts
        self._point(blocks, far, views)
        self.width = int(max([1, *(self.near[:, 1] - self.near[:, 0]), *self.near[:, 5],
                              *(self.rows[:, 1] - self.rows[:, 0]), *self.rows[:, 3],
                              *(self.cols[:, 1] - self.cols[:, 0]), *self.cols[:, 3]]))
        self.nbytes = int(self.vals.nbytes + self.near.nbytes + self.gidx.nbytes
                          + self.rows.nbytes + self.cols.nbytes + self.fidx.nbytes)

    def _put(self, a: np.ndarray) -> int:
        """Append ``a`` (C order) to ``vals``; its offset."""
        off = self._size
        self._parts.append(np.ascontiguousarray(a))
        self._size += a.size
        return off

    def _pack_near(self, blocks, mirrored):
        """The near field's table and column indices (class docstring); each dense block's
        array becomes a view into its group's ``D1`` or ``D2`` (set by :meth:`_point`)."""
        groups = {}  # row range -> its dense blocks, the mirrors' originals last
        for b in blocks:
            if b.D is not None and b.of is None:
                groups.setdefault((b.r0, b.r1), []).append(b)
        table, gidx, go = [], [], 0
        self._near_views = {}
        for (r0, r1), group in groups.items():
            group.sort(key=lambda b: id(b) in mirrored)
            plain = [b for b in group if id(b) not in mirrored]
            mirr = [b for b in group if id(b) in mirrored]
            j0, w = sum(b.c1 - b.c0 for b in plain), sum(b.c1 - b.c0 for b in group)
            offs = []
            for part in (plain, mirr):
                D = np.hstack([b.D for b in part]) if part else np.zeros((r1 - r0, 0))
                offs.append(self._put(D.astype(group[0].D.dtype, copy=False)))
                o = 0
                for b in part:
                    self._near_views[id(b)] = (offs[-1], D.shape[1], o, b.c1 - b.c0)
                    o += b.c1 - b.c0
            table.append((r0, r1, offs[0], j0, offs[1], w, go))
            gidx.append(np.concatenate([np.arange(b.c0, b.c1) for b in group]))
            go += w
        return (np.array(table, dtype=np.int64).reshape(-1, 7),
                np.concatenate(gidx).astype(np.int64) if gidx else np.zeros(0, np.int64))

    def _pack_far(self, far):
        """The far field's tables (rows, cols), coefficient indices and, per factor, where
        its view lies in ``vals`` (offset, stack width, first column)."""
        off = np.cumsum([0] + [b.U.shape[1] for b in far])
        rowg, colg = {}, {}
        # each factor's rank in the blocks' order: the stacks' order, the same in every run
        rank = {}
        for b in far:
            for a in (b.U, b.V):
                rank.setdefault(id(a), len(rank))
        for b, o in zip(far, off[:-1], strict=True):
            idx = np.arange(o, o + b.U.shape[1])
            rowg.setdefault((b.r0, b.r1), []).append((b.U, idx))
            colg.setdefault((b.c0, b.c1), []).append((b.V, idx))
        stacks, views, fidx, fo = {}, {}, [], 0

        def table(groups):
            nonlocal fo
            out = []
            for (a0, a1), entries in groups.items():
                entries = sorted(entries, key=lambda e: rank[id(e[0])])
                key = tuple(id(a) for a, _ in entries)
                if key not in stacks:  # the same factors in the same order: one stack
                    W = np.hstack([a for a, _ in entries])
                    stacks[key] = self._put(W)
                    o = 0
                    for a, _ in entries:
                        views[id(a)] = (stacks[key], W.shape[1], o, a.shape[1])
                        o += a.shape[1]
                idx = np.concatenate([i for _, i in entries])
                out.append((a0, a1, stacks[key], idx.size, fo))
                fidx.append(idx)
                fo += idx.size
            return np.array(out, dtype=np.int64).reshape(-1, 5)

        rows, cols = table(rowg), table(colg)
        fidx = np.concatenate(fidx).astype(np.int64) if fidx else np.zeros(0, np.int64)
        return rows, cols, fidx, views

    def _point(self, blocks, far, views):
        """Replace the blocks' arrays by their views into ``vals``."""
        def view(spec, nrows):
            off, width, o, w = spec
            return self.vals[off : off + nrows * width].reshape(nrows, width)[:, o : o + w]

        for b in blocks:
            if b.D is not None and b.of is None:
                b.D = view(self._near_views[id(b)], b.r1 - b.r0)
        for b in blocks:
            if b.D is not None and b.of is not None:
                b.D = b.of.D.T
        for b in far:
            b.U, b.V = view(views[id(b.U)], b.r1 - b.r0), view(views[id(b.V)], b.c1 - b.c0)
        del self._near_views

    def apply(self, Xp: np.ndarray, nout: int, transposed: bool) -> np.ndarray:
        """``A_p Xp`` (or ``A_p^T Xp``) on the reordered rows and columns (``Xp``
        made C-contiguous in :attr:`dtype`: the kernels read it raw)."""
        Xp = np.ascontiguousarray(Xp, dtype=self.dtype)
        Y = np.zeros((nout, Xp.shape[1]), dtype=self.dtype)
        if Xp.shape[1] == 0 or Xp.shape[0] == 0:
            return Y
        src, dst = (self.rows, self.cols) if transposed else (self.cols, self.rows)
        r = Xp.shape[1]
        work = (np.zeros((self.k, r), dtype=self.dtype),  # the far field's coefficients
                np.empty((self.width, r), dtype=self.dtype),  # one stack's product
                np.empty((self.width, r), dtype=self.dtype))  # gathered rows
        _apply(self.vals, src, dst, self.fidx, self.near, self.gidx, Xp, Y, transposed,
               *work)
        return Y


# BLAS gemm of the SciPy build NumPy's arrays are multiplied with elsewhere in the package,
# called from the compiled kernels by name (a symbol, not a pointer held by the function:
# the kernels stay cacheable)
for _name in ("sgemm", "dgemm"):
    _llvm.add_symbol(f"fretwear_{_name}",
                     get_cython_function_address("scipy.linalg.cython_blas", _name))
_SGEMM = types.ExternalFunction("fretwear_sgemm", types.void(*[types.voidptr] * 13))
_DGEMM = types.ExternalFunction("fretwear_dgemm", types.void(*[types.voidptr] * 13))


@njit(cache=True)
def _gemm(A, B, C, trans_a, beta):
    """``C = op(A) B + beta C`` (``beta`` 0 or 1) on C-ordered contiguous arrays of one real
    precision, ``op(A)`` = ``A`` or ``A^T`` (``trans_a``): one BLAS ``gemm`` on the
    column-major views, ``C^T = B^T op(A)^T``."""
    p, r = C.shape
    q = B.shape[0]
    if p == 0 or r == 0:
        return
    if q == 0:
        if beta == 0:
            for i in range(p):
                for c in range(r):
                    C[i, c] = 0
        return
    ints = np.empty(6, np.int32)  # m, n, k, ldb, lda, ldc of the column-major call
    ints[0], ints[1], ints[2], ints[3], ints[4], ints[5] = r, p, q, r, p if trans_a else q, r
    chars = np.empty(2, np.uint8)
    chars[0], chars[1] = 78, 84 if trans_a else 78  # 'N', 'T' or 'N'
    scal = np.empty(2, C.dtype)
    scal[0], scal[1] = 1, beta
    args = (chars[0:].ctypes, chars[1:].ctypes, ints[0:].ctypes, ints[1:].ctypes,
            ints[2:].ctypes, scal[0:].ctypes, B.ctypes, ints[3:].ctypes, A.ctypes,
            ints[4:].ctypes, scal[1:].ctypes, C.ctypes, ints[5:].ctypes)
    if C.itemsize == 4:
        _SGEMM(*args)
    else:
        _DGEMM(*args)


@njit(cache=True)
def _block(vals, off, nrows, ncols):
    """The C-ordered ``(nrows, ncols)`` array at ``vals[off]``."""
    return vals[off : off + nrows * ncols].reshape((nrows, ncols))


@njit(cache=True)
def _gather(src, idx, out):
    """``out[j] = src[idx[j]]`` (rows)."""
    for j in range(idx.size):
        i = idx[j]
        for c in range(out.shape[1]):
            out[j, c] = src[i, c]


@njit(cache=True)
def _scatter(rows, idx, dst):
    """``dst[idx[j]] += rows[j]`` (rows)."""
    for j in range(idx.size):
        i = idx[j]
        for c in range(rows.shape[1]):
            dst[i, c] += rows[j, c]


@njit(cache=True)
def _apply(vals, src, dst, fidx, near, gidx, X, Y, transposed, C, T, G):
    """``Y += A_p X`` of :class:`_Plan`'s packed blocks (``src``, ``dst``: the far field's
    tables in the order of the product: ``cols, rows``, or ``rows, cols`` transposed; ``C``
    the far field's coefficients, zero, each row set once: ``0 + t = t``; ``T``, ``G`` work
    rows; made by the caller: an allocation compiled costs a second of compile time)."""
    for e in range(src.shape[0]):  # C[idx] = W^T x[a0:a1]
        a0, a1, off, kk, io = src[e]
        _gemm(_block(vals, off, a1 - a0, kk), X[a0:a1], T[:kk], True, 0)
        _scatter(T[:kk], fidx[io : io + kk], C)
    for e in range(dst.shape[0]):  # y[a0:a1] += W C[idx]
        a0, a1, off, kk, io = dst[e]
        _gather(C, fidx[io : io + kk], G[:kk])
        _gemm(_block(vals, off, a1 - a0, kk), G[:kk], Y[a0:a1], False, 1)
    for e in range(near.shape[0]):
        r0, r1, o1, j0, o2, w, go = near[e]
        _near(_block(vals, o1, r1 - r0, j0), _block(vals, o2, r1 - r0, w - j0),
              gidx[go : go + j0], gidx[go + j0 : go + w], X, Y[r0:r1], X[r0:r1], Y, T, G,
              transposed)


@njit(cache=True)
def _near(D1, D2, g1, g2, X, Yr, Xr, Y, T, G, transposed):
    """One near-field row range ``r`` (:class:`_Plan`; ``Yr``, ``Xr`` its rows of ``Y`` and
    ``X``): ``D1`` on the columns ``g1``, ``D2`` on ``g2`` and, mirrored, ``D2^T`` on the
    rows ``g2`` and the columns ``r``; ``Y += A_p X`` (or ``A_p^T X``) of these blocks."""
    j0, w2 = g1.size, g2.size
    if transposed:
        _gemm(D1, Xr, T[:j0], True, 0)
        _scatter(T[:j0], g1, Y)
    else:
        _gather(X, g1, G[:j0])
        _gemm(D1, G[:j0], Yr, False, 1)
    if w2:
        _gather(X, g2, G[:w2])
        _gemm(D2, G[:w2], Yr, False, 1)  # the blocks (and, transposed, their mirrors)
        _gemm(D2, Xr, T[:w2], True, 0)  # their mirrors (and, transposed, the blocks)
        _scatter(T[:w2], g2, Y)


def _restrict(perm: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For the original indices ``idx``: their positions in the reordering ``perm``,
    sorted, and the position in ``idx`` of each of them (the sub-matrix's reordering)."""
    inv = np.empty_like(perm)
    inv[perm] = np.arange(perm.size)
    pos = inv[idx]
    o = np.argsort(pos, kind="stable")
    return pos[o], o


def compress(A: np.ndarray, coords: np.ndarray, tol: float, *, symmetric: bool | None = None,
             leaf: int = LEAF, eta: float = ETA, seed: int = 0) -> HMatrix:
    """The :class:`HMatrix` of ``A`` (m, m), real, with ``||A - A_H||_F <= tol ||A||_F``
    (module docstring). ``coords`` (n, dim): the position of each node, whose ``d = m / n``
    DOFs are rows ``d p .. d p + d - 1``; ``symmetric``: compress the upper blocks only, the
    lower ones their transposes (None: when ``||A - A^T||_F / sqrt 2 <= tol ||A||_F / 100``;
    that asymmetry is then taken from the budget and counted in the stated error);
    ``seed``: the range finder's random samples (the result is reproducible)."""
    A = np.asarray(A)
    coords = np.asarray(coords, dtype=float)
    if A.ndim != 2 or A.shape[0] != A.shape[1] or np.iscomplexobj(A):
        raise InputError(f"A of shape {A.shape}: expected a real square matrix")
    if coords.ndim != 2 or coords.shape[0] == 0 or A.shape[0] % coords.shape[0]:
        raise InputError(f"coords of shape {coords.shape}: expected (n, dim) node positions, "
                         f"n dividing the {A.shape[0]} rows of A")
    if not np.all(np.isfinite(coords)) or not np.any(np.ptp(coords, axis=0) > 0):
        raise InputError("coords: expected finite, distinct node positions (the compression "
                         "groups nodes by position)")
    if not (isinstance(tol, int | float) and 0 < tol < 1):
        raise InputError(f"tol = {tol!r}: expected a relative error in (0, 1)")
    m, n = A.shape[0], coords.shape[0]
    d = m // n
    norm = float(np.linalg.norm(A))
    # stored symmetric, the blocks below the diagonal are the upper ones transposed: their
    # asymmetry (the lower triangle of A - A^T) adds to the error
    asym = float(np.linalg.norm(A - A.T)) / np.sqrt(2.0)
    if symmetric is None:
        symmetric = asym <= 0.01 * tol * norm
    asym = asym if symmetric else 0.0
    order, root = cluster_tree(coords, leaf)
    perm = (order[:, None] * d + np.arange(d)).reshape(-1)
    scale2 = (max(tol * norm - asym, 0.0)) ** 2 / (m * m)
    rng = np.random.default_rng(seed)
    blocks, err2 = [], 0.0
    for s, t, adm in block_tree(root, eta):
        if symmetric and s.start > t.start:
            continue  # the mirror of a block above the diagonal
        r0, r1, c0, c1 = d * s.start, d * s.stop, d * t.start, d * t.stop
        B = A[np.ix_(perm[r0:r1], perm[c0:c1])]
        lr = low_rank(B, np.sqrt(scale2 * B.size), rng) if adm else None
        if lr is None:
            blk = Block(r0, r1, c0, c1, D=np.ascontiguousarray(B))
        else:
            blk = Block(r0, r1, c0, c1, U=lr[0], V=lr[1])
            err2 += lr[2] ** 2 * (2 if symmetric and s.start != t.start else 1)
        blocks.append(blk)
        if symmetric and s.start != t.start:
            blocks.append(blk.mirror())
    return HMatrix(perm, perm, blocks, (np.sqrt(err2) + asym) / norm if norm else 0.0, tol)
