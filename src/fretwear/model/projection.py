"""Node-to-segment pairing of non-matching interface meshes.

Each contact node ``s`` of one face (the *slave*: the contact boundary) is projected onto
the closest point of the facets of the other face (the *master*: the partner boundary):
segments in 2D, triangles and (bilinear) quadrilaterals in 3D. At that point the facet's
shape functions ``N_k(xi)`` give the partner displacement ``sum_k N_k U_k``, and the contact
law acts on ``u_s - sum_k N_k U_k`` in the slave node's contact frame (the change of
variables of :mod:`fretwear.model.interfaces` with one block ``N_k I`` per facet node; the
contact forces on the facet nodes are ``-N_k lambda``, equal and opposite in total).

A projection that lands on a master node (within ``1e-10`` in the facet coordinates) has the
weights ``(1, 0, ...)`` exactly, so that matching meshes give the node-to-node pairs. Weights
below ``1e-10`` are dropped and the others scaled to add up to 1.

The wear of the master surface is computed at each slave node (the worn depth of the master
at the projection point, which opens that node's gap with the slave's own); on the master's
own nodes, for output, it is the average of the slave values weighted by the same weights
times the slave areas (:func:`partner_node_values`), so that a uniform worn depth stays
uniform.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fretwear.model.core import ContactInterface

SNAP = 1e-10


@dataclass
class Projection:
    """Closest points of slave nodes on master facets.

    facet : (ns,) index of the master facet of each node; nodes : (ns, k) the facet's node
    numbers (``-1`` padding for a triangle among quads); weights : (ns, k) shape functions at
    the projection (0 for padding and dropped terms); point : (ns, d) the projection [m];
    distance : (ns,) from the node to it [m].
    """

    facet: np.ndarray
    nodes: np.ndarray
    weights: np.ndarray
    point: np.ndarray
    distance: np.ndarray


def project(points: np.ndarray, slaves: np.ndarray, facets: np.ndarray) -> Projection:
    """Project the nodes ``slaves`` onto the facets ``facets`` (nf, k) of one mesh whose
    node coordinates are ``points`` (nn, d): the closest point of the closest facet.

    Candidate facets are those whose centre lies within the distance to the nearest centre
    plus the largest facet radius (every facet that can hold the closest point).
    """
    from scipy.spatial import cKDTree  # lazy: scipy.spatial is slow to import

    facets = np.asarray(facets, dtype=np.int64)
    slaves = np.asarray(slaves, dtype=np.int64)
    xf = points[facets]  # (nf, k, d)
    centre = xf.mean(axis=1)
    radius = float(np.linalg.norm(xf - centre[:, None], axis=2).max())
    tree = cKDTree(centre)
    near, _ = tree.query(points[slaves])
    k = facets.shape[1]
    ns, d = slaves.size, points.shape[1]
    out = Projection(np.zeros(ns, np.int64), np.full((ns, k), -1, np.int64), np.zeros((ns, k)),
                     np.zeros((ns, d)), np.zeros(ns))
    for i, s in enumerate(slaves):
        p = points[s]
        cand = np.asarray(tree.query_ball_point(p, near[i] + radius * (1 + 1e-9) + 1e-300),
                          dtype=np.int64)
        best = None
        for f in cand:
            w, x = closest_on_facet(xf[f], p)
            dist = float(np.linalg.norm(x - p))
            if best is None or dist < best[0] * (1 - 1e-12):
                best = (dist, f, w, x)
        dist, f, w, x = best
        out.facet[i], out.distance[i], out.point[i] = f, dist, x
        w = snapped(w)
        out.nodes[i] = np.where(w != 0.0, facets[f], -1)
        out.weights[i] = w
    return out


def snapped(w: np.ndarray) -> np.ndarray:
    """Weights with those below ``SNAP`` dropped, exactly ``(1, 0...)`` on a node, and the
    others scaled to add up to 1."""
    w = np.where(np.abs(w) < SNAP, 0.0, w)
    if w.max() > 1.0 - SNAP:
        out = np.zeros(w.size)
        out[np.argmax(w)] = 1.0
        return out
    return w / w.sum()


def closest_on_facet(x: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shape-function weights (k,) and position (d,) of the point of facet ``x`` (k, d)
    closest to ``p``: a segment (k = 2), a triangle (3) or a bilinear quadrilateral (4)."""
    k = x.shape[0]
    if k == 2:
        return _on_segment(x[0], x[1], p)
    if k == 3:
        return _on_triangle(x, p)
    if k == 4:
        return _on_quad(x, p)
    raise ValueError(f"facets of {k} nodes are not supported (2, 3 or 4)")


def _on_segment(a, b, p):
    ab = b - a
    t = float(np.clip((p - a) @ ab / (ab @ ab), 0.0, 1.0))
    return np.array([1.0 - t, t]), a + t * ab


def _on_triangle(x, p):
    """Barycentric weights of the closest point: the projection on the plane when inside,
    else the closest point of the three edges."""
    a, b, c = x
    e1, e2 = b - a, c - a
    G = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
    s, t = np.linalg.solve(G, [e1 @ (p - a), e2 @ (p - a)])
    w = np.array([1.0 - s - t, s, t])
    if w.min() >= -SNAP:
        w = np.clip(w, 0.0, None)
        return w / w.sum(), w @ x / w.sum()
    return _on_edges(x, p, ((0, 1), (1, 2), (2, 0)))


def _on_edges(x, p, edges):
    best = None
    for i, j in edges:
        we, q = _on_segment(x[i], x[j], p)
        dist = np.linalg.norm(q - p)
        if best is None or dist < best[0]:
            w = np.zeros(x.shape[0])
            w[i], w[j] = we
            best = (dist, w, q)
    return best[1], best[2]


def _bilinear(xi, eta):
    return 0.25 * np.array([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta),
                            (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)])


def _on_quad(x, p):
    """Bilinear quadrilateral (nodes counter-clockwise): Gauss-Newton on ``(xi, eta)`` for
    the foot of the normal; the closest point of the four edges when it falls outside."""
    xi = eta = 0.0
    for _ in range(20):
        N = _bilinear(xi, eta)
        dxi = 0.25 * np.array([-(1 - eta), 1 - eta, 1 + eta, -(1 + eta)]) @ x
        deta = 0.25 * np.array([-(1 - xi), -(1 + xi), 1 + xi, 1 - xi]) @ x
        J = np.column_stack([dxi, deta])
        step = np.linalg.solve(J.T @ J, J.T @ (p - N @ x))
        xi, eta = xi + step[0], eta + step[1]
        if np.abs(step).max() < 1e-14:
            break
    if max(abs(xi), abs(eta)) <= 1.0 + SNAP:
        xi, eta = float(np.clip(xi, -1, 1)), float(np.clip(eta, -1, 1))
        w = _bilinear(xi, eta)
        return w, w @ x
    return _on_edges(x, p, ((0, 1), (1, 2), (2, 3), (3, 0)))


def partner_node_values(contact: ContactInterface, values: np.ndarray):
    """``(ids, v)``: a per-contact-node quantity of the partner surface (e.g. its worn depth)
    on the partner's own mesh nodes. Node-to-node: each pair's value on its partner node;
    node-to-segment and mortar: on each partner node ``m``, the average of the contact nodes'
    values weighted by their weights times their areas, ``sum_s w_sm a_s v_s / sum_s w_sm
    a_s`` (for the mortar weights the denominator is the partner node's own area, so a
    uniform value stays uniform); nodes whose total weight is not positive are left out."""
    values = np.asarray(values, dtype=float)
    pair = contact.paired()
    if contact.segments is None:
        return np.asarray(contact.partner_ids)[pair], values[pair]
    ids = np.asarray(contact.segments.ids, dtype=np.int64)
    w = np.asarray(contact.segments.weights, dtype=float) \
        * np.asarray(contact.area, dtype=float)[:, None]
    keep = (ids >= 0) & (w != 0.0)
    nodes, where = np.unique(ids[keep], return_inverse=True)
    total = np.zeros(nodes.size)
    weight = np.zeros(nodes.size)
    np.add.at(total, where, (w * values[:, None])[keep])
    np.add.at(weight, where, w[keep])
    good = weight > 0.0
    return nodes[good], total[good] / weight[good]
