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
    ``master_facets`` (module docstring); ``points`` (nn, d) are the mesh coordinates."""
    from scipy.spatial import cKDTree  # lazy: scipy.spatial is slow to import

    sf = np.asarray(slave_facets, dtype=np.int64)
    mf = np.asarray(master_facets, dtype=np.int64)
    slaves = np.asarray(slaves, dtype=np.int64)
    pos = {int(n): i for i, n in enumerate(slaves)}
    xm = points[mf]
    centre = xm.mean(axis=1)
    rm = float(np.linalg.norm(xm - centre[:, None], axis=2).max())
    tree = cKDTree(centre)
    coupling: list[dict] = [dict() for _ in slaves]
    cover = np.zeros(slaves.size)
    area = np.zeros(slaves.size)
    for f in sf:
        xs = points[f]
        origin, axes = _plane(xs)
        ps = (xs - origin) @ axes.T
        c = xs.mean(axis=0)
        rs = float(np.linalg.norm(xs - c, axis=1).max())
        rows = [pos[int(n)] for n in f]
        lo, hi = ps.min(axis=0), ps.max(axis=0)
        q, w = _rule(ps)  # the slave facet itself: int N_s
        area[rows] += w @ shape_functions(xs, origin + q @ axes)
        for m in tree.query_ball_point(c, rs + rm + 1e-9 * (rs + rm)):
            pm = (xm[m] - origin) @ axes.T
            if np.any(pm.max(axis=0) <= lo) or np.any(pm.min(axis=0) >= hi):
                continue  # the boxes do not overlap
            clip = _clip(ps, pm)
            if clip is None:
                continue
            q, w = _rule(clip)
            x = origin + q @ axes
            phi = _dual(shape_functions(xs, x), xs.shape[0])  # (nq, ks)
            M = (w[:, None] * phi).T @ shape_functions(xm[m], x)  # (ks, km)
            cover[rows] += w @ phi
            for a, r in enumerate(rows):
                for b, node in enumerate(mf[m]):
                    if M[a, b] != 0.0:
                        coupling[r][int(node)] = coupling[r].get(int(node), 0.0) + M[a, b]
    k = max(1, max(len(cp) for cp in coupling))
    nodes = np.full((slaves.size, k), -1, dtype=np.int64)
    weights = np.zeros((slaves.size, k))
    point = np.zeros((slaves.size, points.shape[1]))
    for i, cp in enumerate(coupling):
        if not cp or cover[i] == 0.0:
            continue
        ids = np.array(sorted(cp), dtype=np.int64)
        w = snapped(np.array([cp[n] for n in ids]) / cover[i])
        keep = w != 0.0
        nodes[i, :keep.sum()] = ids[keep]
        weights[i, :keep.sum()] = w[keep]
        point[i] = w[keep] @ points[ids[keep]]
    with np.errstate(invalid="ignore", divide="ignore"):
        coverage = np.where(area > 0, cover / area, 0.0)
    return Mortar(nodes, weights, coverage, point)


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
    flat facet; the closest point's for points off a gently curved one)."""
    k = x.shape[0]
    if k == 2:
        ab = x[1] - x[0]
        t = np.clip((p - x[0]) @ ab / (ab @ ab), 0.0, 1.0)
        return np.column_stack([1.0 - t, t])
    if k == 3:
        e1, e2 = x[1] - x[0], x[2] - x[0]
        G = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
        st = np.linalg.solve(G, np.column_stack([(p - x[0]) @ e1, (p - x[0]) @ e2]).T).T
        N = np.clip(np.column_stack([1.0 - st.sum(axis=1), st]), 0.0, None)
        return N / N.sum(axis=1, keepdims=True)
    xi = np.zeros(p.shape[0])
    eta = np.zeros(p.shape[0])
    for _ in range(20):
        N = 0.25 * np.column_stack([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta),
                                    (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)])
        dxi = 0.25 * np.column_stack([-(1 - eta), 1 - eta, 1 + eta, -(1 + eta)]) @ x
        deta = 0.25 * np.column_stack([-(1 - xi), -(1 + xi), 1 + xi, 1 - xi]) @ x
        r = p - N @ x
        a11 = np.einsum("nd,nd->n", dxi, dxi)
        a12 = np.einsum("nd,nd->n", dxi, deta)
        a22 = np.einsum("nd,nd->n", deta, deta)
        b1 = np.einsum("nd,nd->n", dxi, r)
        b2 = np.einsum("nd,nd->n", deta, r)
        det = a11 * a22 - a12 * a12
        s1, s2 = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
        xi, eta = xi + s1, eta + s2
        if max(np.abs(s1).max(), np.abs(s2).max()) < 1e-14:
            break
    xi, eta = np.clip(xi, -1.0, 1.0), np.clip(eta, -1.0, 1.0)
    return 0.25 * np.column_stack([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta),
                                   (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)])


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
