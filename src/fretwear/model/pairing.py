"""The partners of the contact nodes of a two-body interface: node-to-node or node-to-segment.

``pairing`` (:class:`fretwear.model.build.ContactSpec`, case-file ``[[contact]] pairing``):

* ``"node-to-node"``: each contact node faces the node of the partner boundary at its
  position, within ``tolerance`` (default ``1e-6`` times the model size).
* ``"node-to-segment"``: each contact node faces the closest point of a facet of the partner
  boundary (:mod:`fretwear.model.projection`), within ``tolerance`` (default a tenth of the
  partner's longest facet edge); the signed distance to that point along the node's normal
  is added to its initial gap (0 on flat faces; below ``1e-12`` times the model size it is
  rounding, and taken as 0).
* ``"mortar"``: each contact node's relative displacement is the average over its
  tributary area, weighted by its dual shape function, of the slave face's displacement
  relative to the master face's (:mod:`fretwear.model.mortar`); every node's area must be
  covered by the partner face (at least ``MIN_COVERAGE`` of it). It passes the patch test
  (uniform pressure and slip across any two meshes) exactly; node-to-segment does not
  when the meshes are not nested.
* ``"auto"`` (default): node-to-node when every contact node has a partner node within the
  node-to-node tolerance (so matching meshes keep their pairs and answers exactly), else
  mortar.

Node-to-segment and mortar pairs hold, for each contact node, the partner nodes and their
weights (:class:`fretwear.model.core.Segments`); a weight within ``1e-10`` of 1 is exactly 1
and the others 0, so that coincident nodes pair exactly as node-to-node.

When some nodes have no partner, the error lists them, and when most of them lie outside
the partner face it suggests restricting the contact to the overlap (``region``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fretwear.errors import InputError
from fretwear.model.core import Mesh, Segments
from fretwear.model.mesh import boundary as _boundary
from fretwear.model.mesh import model_size
from fretwear.model.mortar import mortar
from fretwear.model.projection import project
from fretwear.model.regions import bounding_region

PAIRINGS = ("auto", "node-to-node", "mortar", "node-to-segment")
#: the smallest fraction of a contact node's area that the partner face must cover (mortar)
MIN_COVERAGE = 0.99


@dataclass
class Partners:
    """partner_dofs (nc, d), partner_ids (nc,): the partner node (of largest weight);
    segments : the node-to-segment terms or None; gap : (nc,) added to the initial gap [m]."""

    partner_dofs: np.ndarray
    partner_ids: np.ndarray
    segments: Segments | None
    gap: np.ndarray


def check_pairing(pairing, what: str) -> str:
    if pairing not in PAIRINGS:
        raise InputError(f"{what}: pairing = {pairing!r}; expected one of {list(PAIRINGS)}")
    return pairing


def pair(mesh: Mesh, nodes: np.ndarray, normals: np.ndarray, partner: str, *,
         face: np.ndarray | None = None, tolerance: float | None = None,
         pairing: str = "auto", what: str = "contact") -> Partners:
    """The partners of the contact ``nodes`` (nc,) on boundary ``partner``; ``normals``
    (nc, d) are their contact normals and ``face`` the facets of the contact face (needed by
    the mortar pairing) (module docstring)."""
    from scipy.spatial import cKDTree  # lazy: scipy.spatial is slow to import

    check_pairing(pairing, what)
    if partner not in mesh.boundaries:
        raise InputError(f"{what}: unknown partner boundary {partner!r}; the mesh has "
                         f"boundaries {sorted(mesh.boundaries)}")
    facets = _boundary(mesh, partner)
    cand = np.unique(facets)
    if cand.size == 0:
        raise InputError(f"{what}: partner boundary {partner!r} is empty")
    d = mesh.dim
    tol = 1e-6 * model_size(mesh) if tolerance is None else tolerance
    dist, idx = cKDTree(mesh.points[cand]).query(mesh.points[nodes])
    if pairing == "node-to-node" or (pairing == "auto" and np.all(dist <= tol)):
        other = _node_to_node(mesh, nodes, cand, dist, idx, partner, tol, what)
        return Partners(d * other[:, None] + np.arange(d), other, None, np.zeros(nodes.size))
    if tolerance is None:
        edges = np.linalg.norm(mesh.points[facets] - mesh.points[np.roll(facets, 1, axis=1)],
                               axis=2)
        tol = 0.1 * float(edges.max())
    proj = project(mesh.points, nodes, facets)
    far = np.flatnonzero(proj.distance > tol)
    if far.size:
        _no_partner(mesh, nodes, far, proj.distance, cand, partner, tol, what,
                    "node-to-segment and mortar: the partner face must cover the contact "
                    "nodes")
    ids, weights, point = proj.nodes, proj.weights, proj.point
    if pairing != "node-to-segment":
        mo = mortar(mesh.points, nodes, face, facets)
        low = np.flatnonzero(mo.coverage < MIN_COVERAGE)
        if low.size:
            _no_partner(mesh, nodes, low, 1.0 - mo.coverage, cand, partner, 1 - MIN_COVERAGE,
                        what, "mortar: the partner face must cover the area of every contact "
                        "node (the distance shown is the uncovered fraction of its area)")
        ids, weights, point = mo.nodes, mo.weights, mo.point
    same = np.intersect1d(ids[ids >= 0], nodes)
    if same.size:
        raise InputError(f"{what}: node {int(same[0])} is on both boundaries of the pair; the "
                         "two bodies need their own nodes at the interface")
    primary = ids[np.arange(nodes.size), np.argmax(weights, axis=1)]
    seg = Segments(dofs=np.where(ids[..., None] >= 0, d * ids[..., None] + np.arange(d), -1),
                   weights=weights, ids=ids)
    gap = np.einsum("nd,nd->n", normals, point - mesh.points[nodes])
    gap[np.abs(gap) <= 1e-12 * model_size(mesh)] = 0.0  # rounding of the weighted points
    return Partners(d * primary[:, None] + np.arange(d), primary, seg, gap)


def _node_to_node(mesh, nodes, cand, dist, idx, partner, tol, what) -> np.ndarray:
    far = np.flatnonzero(dist > tol)
    if far.size:
        _no_partner(mesh, nodes, far, dist, cand, partner, tol, what,
                    'the two boundaries need matching nodes (pairing = "node-to-segment" '
                    "pairs non-matching meshes)")
    out = cand[idx]
    same = np.intersect1d(out, nodes)
    if same.size:
        raise InputError(f"{what}: node {int(same[0])} is on both boundaries of the pair; the "
                         "two bodies need their own nodes at the interface")
    values, counts = np.unique(out, return_counts=True)
    if np.any(counts > 1):
        j = int(values[counts > 1][0])
        raise InputError(f"{what}: node {j} of boundary {partner!r} is the partner of "
                         f"{int(counts.max())} contact nodes; expected one-to-one pairs")
    return out


def _no_partner(mesh, nodes, far, dist, cand, partner, tol, what, hint) -> None:
    """InputError listing the contact nodes without a partner within ``tol``; when most of
    them lie outside the partner face's bounding box, the hint is to restrict the contact
    boundary to the overlap."""
    listed = ", ".join(str(int(nodes[i])) for i in far[:12]) + (" ..." if far.size > 12 else "")
    i = int(far[np.argmax(dist[far])])
    lo, hi = mesh.points[cand].min(axis=0), mesh.points[cand].max(axis=0)
    slack = tol + 1e-9 * model_size(mesh)
    p = mesh.points[nodes]
    out = np.any((p < lo - slack) | (p > hi + slack), axis=1)
    msg = (f"{what}: {far.size} of {nodes.size} contact nodes have no partner on boundary "
           f"{partner!r} within {tol:.3g} m: nodes {listed} (farthest: node {int(nodes[i])} at "
           f"{tuple(np.round(mesh.points[nodes[i]], 12).tolist())}, {dist[i]:.3g} m away)")
    if out[far].sum() * 2 > far.size:
        inside = nodes[~out]
        where = f" such as region = {bounding_region(mesh, inside)}" if inside.size else ""
        raise InputError(f"{msg}; {int(out[far].sum())} of them lie outside the partner face: "
                         f"restrict the contact boundary to the part that touches it (region"
                         f"{where})")
    raise InputError(f"{msg}: {hint}, or a larger tolerance")
