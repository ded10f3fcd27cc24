"""Mortar pairing of non-matching interface meshes with dual shape functions.

The relative displacement of contact node ``s`` (slave face: the contact boundary) is the
weighted average ``r_s = (1 / D_s) int Phi_s (u_slave - u_master) dA`` over the slave face,
with the *dual* shape functions ``Phi_s`` (biorthogonal to the slave's ``N_t``: ``int Phi_s
N_t dA = delta_st D_s``, Wohlmuth 2000; ``Phi = 2 N_1 - N_2`` on a segment, ``4 N_i - 1`` on a
triangle, the tensor product of the segment's on a quadrilateral). Then
``r_s = u_s - sum_m w_sm u_m`` with ``w_sm = M_sm / D_s``, ``M_sm = int Phi_s N_m dA``: the
form of a node-to-node or node-to-segment pair (:mod:`fretwear.model.interfaces`), with the
weights of all the master nodes under node ``s``'s facets. The master nodes receive
``sum_s w_sm lambda_s``, which for ``lambda_s = p D_s`` is ``p int N_m dA``: the consistent
nodal forces of a uniform pressure on both faces, so a uniform pressure and a uniform slip
pass across any pair of meshes exactly (the patch test that a node-to-segment pairing fails
when the meshes are not nested).

The integrals are computed on the intersection of each slave facet with each master facet
projected on the slave facet's line or plane (intervals in 2D, convex polygons clipped by
Sutherland-Hodgman in 3D), by Gauss rules exact for the products of shape functions on
straight segments, triangles and parallelograms. ``D_s`` is the integral of ``Phi_s`` over the
covered part, so the weights add up to 1; the fraction of ``int N_s`` covered is returned so
that a node off the master face is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fretwear.model.projection import snapped

_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(3)
_A1, _B1, _A2, _B2 = 0.059715871789770, 0.470142064105115, 0.797426985353087, 0.101286507323456
#: degree-5 rule on a triangle: barycentric points and weights (adding up to 1)
_TRI_P = np.array([[1 / 3, 1 / 3, 1 / 3], [_A1, _B1, _B1], [_B1, _A1, _B1], [_B1, _B1, _A1],
                   [_A2, _B2, _B2], [_B2, _A2, _B2], [_B2, _B2, _A2]])
_TRI_W = np.array([0.225] + [0.132394152788506] * 3 + [0.125939180544827] * 3)


@dataclass
class Mortar:
    """nodes (ns, k) master node numbers (``-1`` padding), weights (ns, k) ``w_sm`` (adding
    up to 1 per slave node), coverage (ns,) the covered fraction of each slave node's area,
    and point (ns, d) ``sum_m w_sm x_m`` (where the node meets the master face)."""

    nodes: np.ndarray
    weights: np.ndarray
    coverage: np.ndarray
    point: np.ndarray


def mortar(points: np.ndarray, slaves: np.ndarray, slave_facets: np.ndarray,
           master_facets: np.ndarray) -> Mortar:
    """The mortar weights of the nodes ``slaves`` of ``slave_facets`` against
    ``master_facets`` (module docstring); ``points`` (nn, d) are the mesh coordinates.

    Every (slave facet, master facet) pair near each other is clipped and integrated at once
    (arrays over the pairs; the loops run over the vertices of a facet, not over facets)."""
    from scipy.spatial import cKDTree  # lazy: scipy.spatial is slow to import

    sf = np.asarray(slave_facets, dtype=np.int64)
    mf = np.asarray(master_facets, dtype=np.int64)
    slaves = np.asarray(slaves, dtype=np.int64)
    order = np.argsort(slaves)
    rows = order[np.searchsorted(slaves[order], sf)]  # (F, ks) slave row of each facet node
    xs, xm = points[sf], points[mf]
    origin, axes = _planes(xs)
    ps = np.einsum("fkd,fed->fke", xs - origin[:, None], axes)
    # int N_s over each slave facet itself
    q, w = _rules(ps, np.full(sf.shape[0], sf.shape[1]))
    N = _shape_functions(xs, origin[:, None] + np.einsum("fqe,fed->fqd", q, axes))
    area = np.bincount(rows.ravel(), np.einsum("fq,fqk->fk", w, N).ravel(),
                       minlength=slaves.size)
    # candidate pairs: master facets within reach of each slave facet, boxes overlapping
    centre = xm.mean(axis=1)
    rm = float(np.linalg.norm(xm - centre[:, None], axis=2).max())
    c = xs.mean(axis=1)
    rs = np.linalg.norm(xs - c[:, None], axis=2).max(axis=1)
    near = cKDTree(centre).query_ball_point(c, rs + rm + 1e-9 * (rs + rm))
    f = np.repeat(np.arange(sf.shape[0]), [len(x) for x in near])
    m = np.fromiter((j for x in near for j in x), dtype=np.int64, count=f.size)
    pm = np.einsum("pkd,ped->pke", xm[m] - origin[f][:, None], axes[f])
    lo, hi = ps[f].min(axis=1), ps[f].max(axis=1)
    keep = ~(np.any(pm.max(axis=1) <= lo, axis=1) | np.any(pm.min(axis=1) >= hi, axis=1))
    f, m, pm = f[keep], m[keep], pm[keep]
    poly, count = _clip_all(ps[f], pm)
    f, m, poly, count = f[count > 0], m[count > 0], poly[count > 0], count[count > 0]
    q, w = _rules(poly, count)
    x = origin[f][:, None] + np.einsum("pqe,ped->pqd", q, axes[f])
    phi = _dual_batch(_shape_functions(xs[f], x), sf.shape[1])  # (P, nq, ks)
    M = np.einsum("pq,pqa,pqb->pab", w, phi, _shape_functions(xm[m], x))  # (P, ks, km)
    cover = np.bincount(rows[f].ravel(), np.einsum("pq,pqa->pa", w, phi).ravel(),
                        minlength=slaves.size)
    r = np.broadcast_to(rows[f][:, :, None], M.shape)
    n = np.broadcast_to(mf[m][:, None, :], M.shape)
    nz = M != 0.0
    coupling = sp.csr_matrix((M[nz], (r[nz], n[nz])), shape=(slaves.size, points.shape[0]))
    coupling.sum_duplicates()
    return _weights(coupling, cover, area, points)


def _weights(coupling, cover, area, points) -> Mortar:
    """The padded weights ``M_sm / D_s`` of each slave row of ``coupling``."""
    ns = coupling.shape[0]
    k = max(1, int(np.diff(coupling.indptr).max(initial=0)))
    nodes = np.full((ns, k), -1, dtype=np.int64)
    weights = np.zeros((ns, k))
    point = np.zeros((ns, points.shape[1]))
    for i in range(ns):  # a loop over the slave nodes: snapping is per node
        lo, hi = coupling.indptr[i], coupling.indptr[i + 1]
        if hi == lo or cover[i] == 0.0:
            continue
        ids = coupling.indices[lo:hi].astype(np.int64)
        w = snapped(coupling.data[lo:hi] / cover[i])
        keep = w != 0.0
        nodes[i, :keep.sum()] = ids[keep]
        weights[i, :keep.sum()] = w[keep]
        point[i] = w[keep] @ points[ids[keep]]
    with np.errstate(invalid="ignore", divide="ignore"):
        coverage = np.where(area > 0, cover / area, 0.0)
    return Mortar(nodes, weights, coverage, point)


def _planes(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_plane` of every facet ``x`` (F, k, d): origins (F, d), axes (F, d-1, d)."""
    origin = x.mean(axis=1)
    e1 = x[:, 1] - x[:, 0]
    e1 = e1 / np.linalg.norm(e1, axis=1, keepdims=True)
    if x.shape[2] == 2:
        return origin, e1[:, None]
    n = (np.cross(x[:, 2] - x[:, 0], x[:, -1] - x[:, 1]) if x.shape[1] == 4
         else np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]))
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    e1 = e1 - np.einsum("fd,fd->f", e1, n)[:, None] * n
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return origin, np.stack([e1, np.cross(n, e1)], axis=1)


def _clip_all(ps: np.ndarray, pm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_clip` of every pair: the regions (P, V, d-1) and their vertex counts (P,)
    (0: empty; 2 for an interval)."""
    P = ps.shape[0]
    if ps.shape[2] == 1:
        lo = np.maximum(ps.min(axis=(1, 2)), pm.min(axis=(1, 2)))
        hi = np.minimum(ps.max(axis=(1, 2)), pm.max(axis=(1, 2)))
        return np.stack([lo, hi], axis=1)[:, :, None], np.where(hi > lo, 2, 0)
    poly = _ccw_all(ps)
    count = np.full(P, ps.shape[1])
    mm = _ccw_all(pm)
    km = mm.shape[1]
    for e in range(km):
        poly, count = _cut_all(poly, count, mm[:, e], mm[:, (e + 1) % km])
        count = np.where(count < 3, 0, count)
    area0 = np.abs(_signed_areas(_ccw_all(ps), np.full(P, ps.shape[1])))
    small = np.abs(_signed_areas(poly, count)) <= 1e-14 * area0
    return poly, np.where(small, 0, count)


def _ccw_all(p: np.ndarray) -> np.ndarray:
    flip = _signed_areas(p, np.full(p.shape[0], p.shape[1])) <= 0
    out = p.copy()
    out[flip] = p[flip, ::-1]
    return out


def _signed_areas(p: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Signed areas of polygons ``p`` (P, V, 2) of ``count`` (P,) vertices (0 if none)."""
    total = np.zeros(p.shape[0])
    rows = np.arange(p.shape[0])
    for i in range(p.shape[1]):
        nxt = np.where(i + 1 < count, i + 1, 0)
        a, b = p[:, i], p[rows, nxt]
        total += np.where(i < count, a[:, 0] * b[:, 1] - b[:, 0] * a[:, 1], 0.0)
    return 0.5 * total


def _cut_all(poly, count, a, b):
    """:func:`_cut` of every polygon (P, V, 2) of ``count`` vertices by its edge ``a -> b``
    (P, 2): the polygons (P, V + 1, 2) and their counts."""
    P, V = poly.shape[:2]
    rows = np.arange(P)
    e = b - a

    def side(p):
        return e[:, 0] * (p[:, 1] - a[:, 1]) - e[:, 1] * (p[:, 0] - a[:, 0])

    cand = np.zeros((P, 2 * V, 2))
    ok = np.zeros((P, 2 * V), dtype=bool)
    for i in range(V):
        p, q = poly[:, i], poly[rows, np.where(i + 1 < count, i + 1, 0)]
        sp_, sq = side(p), side(q)
        active = i < count
        cand[:, 2 * i] = p
        ok[:, 2 * i] = active & (sp_ >= 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            cand[:, 2 * i + 1] = p + (q - p) * (sp_ / (sp_ - sq))[:, None]
        ok[:, 2 * i + 1] = active & ((sp_ >= 0) != (sq >= 0))
    cand[~ok] = 0.0  # the unused slots (some are 0 / 0) padded with zeros
    order = np.argsort(~ok, axis=1, kind="stable")[:, :V + 1]
    return cand[rows[:, None], order], ok.sum(axis=1)


def _rules(region: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_rule` of every region (P, V, d-1) of ``count`` vertices: points (P, nq, d-1)
    and weights (P, nq), zero weights on the triangles a smaller polygon does not have."""
    if region.shape[2] == 1:
        lo, hi = region[:, 0, 0], region[:, 1, 0]
        lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
        half = 0.5 * (hi - lo)
        q = (0.5 * (lo + hi))[:, None] + half[:, None] * _GAUSS_X
        return q[:, :, None], half[:, None] * _GAUSS_W
    p0 = region[:, 0]
    pts, wts = [], []
    for t in range(region.shape[1] - 2):
        p1, p2 = region[:, t + 1], region[:, t + 2]
        a = 0.5 * np.abs((p1[:, 0] - p0[:, 0]) * (p2[:, 1] - p0[:, 1])
                         - (p1[:, 1] - p0[:, 1]) * (p2[:, 0] - p0[:, 0]))
        a = np.where(t + 2 < count, a, 0.0)
        pts.append(np.einsum("qk,pke->pqe", _TRI_P, np.stack([p0, p1, p2], axis=1)))
        wts.append(_TRI_W * a[:, None])
    return np.concatenate(pts, axis=1), np.concatenate(wts, axis=1)


def _shape_functions(x: np.ndarray, p: np.ndarray) -> np.ndarray:
    """:func:`shape_functions` of every facet ``x`` (P, k, d) at its points ``p`` (P, n, d):
    (P, n, k)."""
    k = x.shape[1]
    if k == 2:
        ab = x[:, 1] - x[:, 0]
        t = np.einsum("pnd,pd->pn", p - x[:, None, 0], ab) / np.einsum("pd,pd->p", ab, ab)[
            :, None]
        t = np.clip(t, 0.0, 1.0)
        return np.stack([1.0 - t, t], axis=2)
    if k == 3:
        e1, e2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
        g11, g12 = np.einsum("pd,pd->p", e1, e1), np.einsum("pd,pd->p", e1, e2)
        g22 = np.einsum("pd,pd->p", e2, e2)
        r = p - x[:, None, 0]
        b1, b2 = np.einsum("pnd,pd->pn", r, e1), np.einsum("pnd,pd->pn", r, e2)
        G = np.stack([np.stack([g11, g12], -1), np.stack([g12, g22], -1)], -2)
        st = np.linalg.solve(G[:, None], np.stack([b1, b2], axis=-1)[..., None])[..., 0]
        N = np.clip(np.concatenate([1.0 - st.sum(axis=2, keepdims=True), st], axis=2), 0.0,
                    None)
        return N / N.sum(axis=2, keepdims=True)
    xi = np.zeros(p.shape[:2])
    eta = np.zeros(p.shape[:2])
    for _ in range(20):
        N = 0.25 * np.stack([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta),
                             (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)], axis=2)
        dxi = np.einsum("pnk,pkd->pnd", 0.25 * np.stack(
            [-(1 - eta), 1 - eta, 1 + eta, -(1 + eta)], axis=2), x)
        deta = np.einsum("pnk,pkd->pnd", 0.25 * np.stack(
            [-(1 - xi), -(1 + xi), 1 + xi, 1 - xi], axis=2), x)
        r = p - np.einsum("pnk,pkd->pnd", N, x)
        a11 = np.einsum("pnd,pnd->pn", dxi, dxi)
        a12 = np.einsum("pnd,pnd->pn", dxi, deta)
        a22 = np.einsum("pnd,pnd->pn", deta, deta)
        b1 = np.einsum("pnd,pnd->pn", dxi, r)
        b2 = np.einsum("pnd,pnd->pn", deta, r)
        det = a11 * a22 - a12 * a12
        s1, s2 = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
        xi, eta = xi + s1, eta + s2
        if s1.size == 0 or max(np.abs(s1).max(), np.abs(s2).max()) < 1e-14:
            break
    xi, eta = np.clip(xi, -1.0, 1.0), np.clip(eta, -1.0, 1.0)
    return 0.25 * np.stack([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta),
                            (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)], axis=2)


def _dual_batch(N: np.ndarray, k: int) -> np.ndarray:
    """:func:`_dual` of shape functions (P, n, k)."""
    P, n = N.shape[:2]
    return _dual(N.reshape(P * n, k), k).reshape(P, n, k)


def _plane(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Origin and orthonormal in-plane axes (d-1, d) of a facet (its line or plane)."""
    origin = x.mean(axis=0)
    e1 = x[1] - x[0]
    e1 = e1 / np.linalg.norm(e1)
    if x.shape[1] == 2:
        return origin, e1[None]
    n = np.cross(x[2] - x[0], x[-1] - x[1]) if x.shape[0] == 4 else np.cross(x[1] - x[0],
                                                                             x[2] - x[0])
    n = n / np.linalg.norm(n)
    e1 = e1 - (e1 @ n) * n
    e1 /= np.linalg.norm(e1)
    return origin, np.vstack([e1, np.cross(n, e1)])


def _clip(ps: np.ndarray, pm: np.ndarray) -> np.ndarray | None:
    """The intersection of the slave facet ``ps`` and the projected master facet ``pm`` in
    local coordinates: an interval (2, 1) or a convex polygon (n, 2); None if empty."""
    if ps.shape[1] == 1:
        lo = max(ps.min(), pm.min())
        hi = min(ps.max(), pm.max())
        return np.array([[lo], [hi]]) if hi > lo else None
    poly = _ccw(ps)
    for a, b in zip(_ccw(pm), np.roll(_ccw(pm), -1, axis=0), strict=True):
        poly = _cut(poly, a, b)
        if poly.shape[0] < 3:
            return None
    return poly if _polygon_area(poly) > 1e-14 * _polygon_area(_ccw(ps)) else None


def _ccw(p: np.ndarray) -> np.ndarray:
    return p if _signed_area(p) > 0 else p[::-1]


def _signed_area(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _polygon_area(p: np.ndarray) -> float:
    return abs(_signed_area(p))


def _cut(poly: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman: the part of ``poly`` left of the edge ``a -> b``."""
    e = b - a

    def side(p):
        return e[0] * (p[1] - a[1]) - e[1] * (p[0] - a[0])

    out = []
    for p, q in zip(poly, np.roll(poly, -1, axis=0), strict=True):
        sp_, sq = side(p), side(q)
        if sp_ >= 0:
            out.append(p)
        if (sp_ >= 0) != (sq >= 0):
            out.append(p + (q - p) * (sp_ / (sp_ - sq)))
    return np.array(out) if out else np.zeros((0, 2))


def _rule(region: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quadrature points (nq, d-1) in local coordinates and weights (nq,) [m or m^2] on an
    interval (2, 1) or a convex polygon (n, 2) (fan of triangles)."""
    if region.shape[1] == 1:
        lo, hi = float(region.min()), float(region.max())
        half = 0.5 * (hi - lo)
        return (0.5 * (lo + hi) + half * _GAUSS_X)[:, None], half * _GAUSS_W
    p0 = region[0]
    pts, wts = [], []
    for p1, p2 in zip(region[1:-1], region[2:], strict=True):
        a = 0.5 * abs((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]))
        pts.append(_TRI_P @ np.vstack([p0, p1, p2]))
        wts.append(_TRI_W * a)
    return np.vstack(pts), np.concatenate(wts)


def shape_functions(x: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Shape functions (n, k) of facet ``x`` (k, d) at the feet of the normals from the
    points ``p`` (n, d), their facet coordinates clamped to the facet (exact for points on a
    flat facet; the closest point's for points off a gently curved one): the one-facet case
    of :func:`_shape_functions`."""
    return _shape_functions(np.asarray(x)[None], np.asarray(p)[None])[0]


def _dual(N: np.ndarray, k: int) -> np.ndarray:
    """Dual shape functions (n, k) of a facet of ``k`` nodes at points whose shape functions
    are ``N`` (n, k) (segment ``2 N_i - N_j``, triangle ``4 N_i - 1``, quadrilateral: the
    tensor product of the segment's)."""
    if k == 2:
        return 2.0 * N - N[:, ::-1]
    if k == 3:
        return 4.0 * N - 1.0
    # bilinear: recover (xi, eta) from N = (1 -+ xi)(1 -+ eta) / 4
    xi = (N[:, 1] + N[:, 2]) - (N[:, 0] + N[:, 3])
    eta = (N[:, 2] + N[:, 3]) - (N[:, 0] + N[:, 1])
    a, b = 0.5 * (1 - 3 * xi), 0.5 * (1 + 3 * xi)
    c, d = 0.5 * (1 - 3 * eta), 0.5 * (1 + 3 * eta)
    return np.column_stack([a * c, b * c, b * d, a * d])
