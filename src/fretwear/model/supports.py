"""Is a model held? The checks that refuse a structure that only friction could hold.

With every contact node held in its normal direction (as a frictionless contact does) and
every fixed DOF held, the stiffness must be non-singular; otherwise nothing but friction holds
the structure and the problem has no unique solution. :func:`check_supported` tests the
rigid-body modes of every body of a mesh exactly and names the free motions;
:func:`rigid_motion_check` tests any stiffness matrix (models from user matrices) by its
smallest eigenvalues.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.model.core import Mesh, Model
from fretwear.model.interfaces import relative_model
from fretwear.model.places import AXES, axis_index


def rigid_body_modes(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Rigid-body displacement fields of a set of nodes.

    Returns
    -------
    R : (ndof, 3) in 2D, (ndof, 6) in 3D
        Columns: unit translations along x, y(, z), then rotations about the z axis (2D) or
        about x, y, z (3D) through the centroid, scaled by ``1 / size`` so that every entry
        is at most about 1 [m/m].
    centre : (d,) centroid [m]; size : bounding-box diagonal [m].
    """
    points = np.asarray(points, dtype=float)
    nn, d = points.shape
    centre = points.mean(axis=0)
    size = float(np.linalg.norm(np.ptp(points, axis=0))) or 1.0
    x = (points - centre) / size
    if d == 2:
        rot = [np.column_stack([-x[:, 1], x[:, 0]])]
    else:
        rot = [np.cross(e, x) for e in np.eye(3)]
    cols = [np.tile(e, nn) for e in np.eye(d)] + [r.ravel() for r in rot]
    return np.column_stack(cols), centre, size


def _rref(N: np.ndarray) -> np.ndarray:
    """Reduced row echelon form of the rows of N (k, nr), to describe motions simply."""
    A = N.copy()
    r = 0
    for c in range(A.shape[1]):
        if r == A.shape[0]:
            break
        p = r + int(np.argmax(np.abs(A[r:, c])))
        if abs(A[p, c]) < 1e-8:
            continue
        A[[r, p]] = A[[p, r]]
        A[r] /= A[r, c]
        others = np.arange(A.shape[0]) != r
        A[others] -= np.outer(A[others, c], A[r])
        r += 1
    A[np.abs(A) < 1e-10] = 0.0
    return A[:r]


def _fmt_vec(v: np.ndarray) -> str:
    axis = axis_index(v / np.linalg.norm(v))
    if axis is not None:
        return AXES[axis]
    return "(" + ", ".join(f"{c:.3g}" for c in v / np.linalg.norm(v)) + ")"


def _describe(a: np.ndarray, d: int, centre: np.ndarray, size: float) -> str:
    """Words for the rigid motion with coefficients ``a`` on :func:`rigid_body_modes`."""
    t = a[:d]
    w = a[d:] / size  # rotation per unit of the coefficient [rad]
    if np.linalg.norm(w) * size < 1e-9:
        return f"translate along {_fmt_vec(t)}"
    pt = lambda p: "(" + ", ".join(  # noqa: E731
        f"{c:.4g}" for c in np.round(p / size, 5) * size + 0.0) + ")"
    if d == 2:
        w = float(w[0])
        p = centre + np.array([-t[1], t[0]]) / w
        return f"rotate about the z axis through {pt(p)}"
    p = centre + np.cross(w, t) / (w @ w)
    slide = (w @ t) / np.linalg.norm(w)
    extra = " and slide along it" if abs(slide) > 1e-9 * np.linalg.norm(t) + 1e-300 else ""
    return f"rotate about an axis along {_fmt_vec(w)} through {pt(p)}{extra}"


def check_supported(model: Model, neighbour: Neighbours | None = None) -> None:
    """Refuse a model that only friction could hold.

    With every contact node held in its normal direction and every fixed DOF held, ``K``
    must be non-singular. For a model with a mesh, the rigid-body modes of the nodes are
    tested exactly (a mode is free if it moves no held direction and costs no strain or
    spring energy); for a model from matrices :func:`rigid_motion_check` is used.

    ``neighbour``: for one sector of a cyclically symmetric structure, the contact nodes
    whose partner is the *next* sector's copy of a node (an under-platform damper between
    two blades, :func:`fretwear.model.cyclic.neighbour_contact`). Such a pair holds
    ``n . (U_a - e^{i k 2 pi / N} Q U_b)`` (``Q`` the turn by ``2 pi / N``) in the family
    of harmonic index ``k``; the structure must be held in every family ``k = 0 .. N / 2``
    (a body held only by contacts, one of them with the next sector, is held).

    Raises
    ------
    InputError
        Naming the free motion(s), e.g. "the structure can translate along x".
    """
    if model.mesh is None:
        c = model.contact
        normal_dofs = c.dofs[np.arange(c.n_nodes), np.argmax(np.abs(c.frame[:, 0, :]), axis=1)]
        # pairs: in the relative coordinates the normal DOF of node a holds n . (U_a - U_b)
        rigid_motion_check(relative_model(model)[0].K, np.union1d(normal_dofs,
                                                                  model.fixed_dofs))
        return
    d = model.dim
    points = model.mesh.points
    body = bodies(model.mesh)
    nb = int(body.max()) + 1
    # the rigid-body modes of every body (a mesh of several bodies: join, node-to-node pairs)
    parts = []
    for k in range(nb):
        nodes = np.flatnonzero(body == k)
        Rk, centre_k, size_k = rigid_body_modes(points[nodes])
        dofs = (d * nodes[:, None] + np.arange(d)).ravel()
        Rfull = np.zeros((model.ndof, Rk.shape[1]))
        Rfull[dofs] = Rk
        parts.append((Rfull, centre_k, size_k, int(nodes[0])))
    R = np.hstack([p[0] for p in parts])
    c = model.contact
    # K R vanishes for the elastic structure (up to rounding); what remains is the springs'
    # reaction to each rigid mode. Entries within a rounding bound are cleared, and each
    # remaining row (a DOF with a spring) becomes a constraint like a held DOF.
    KR = model.K @ R
    KR[np.abs(KR) <= 64 * np.finfo(float).eps * (abs(model.K) @ np.abs(R))] = 0.0
    springs = KR[np.any(KR != 0.0, axis=1)]
    springs = springs / np.linalg.norm(springs, axis=1, keepdims=True)
    held = np.vstack([R[np.asarray(model.fixed_dofs, dtype=np.int64)], springs])
    free = np.zeros((R.shape[1], 0))
    for phase in (_family_phases(neighbour) if neighbour is not None else [1.0]):
        A = np.vstack([_normal_rows(c, R, neighbour, phase), held])
        _, s, Vt = np.linalg.svd(A)
        rank = int(np.sum(s > 1e-8 * max(1.0, s.max(initial=0.0))))
        if rank < Vt.shape[0]:  # rigid motions that move no held direction, strain no spring
            free = _real_motions(Vt[rank:])
            break
    if free.shape[1] == 0:
        return
    nr = parts[0][0].shape[1]
    motions = []
    for a in _rref(free.T):
        k = int(np.argmax([np.abs(a[j * nr:(j + 1) * nr]).max() for j in range(nb)]))
        _, centre_k, size_k, first = parts[k]
        words = _describe(a[k * nr:(k + 1) * nr], d, centre_k, size_k)
        if nb > 1:
            others = [j for j in range(nb) if j != k and np.abs(a[j * nr:(j + 1) * nr]).max()
                      > 1e-8]
            who = _body_name(model.mesh, np.flatnonzero(body == k), first)
            words = f"{who}{' (with others)' if others else ''} can {words}"
        motions.append(words)
    lead = "the structure can " if nb == 1 else ""
    raise Unsupported(
        "with the contact held only along its normal (frictionless), " + lead
        + (", ".join(motions[:-1]) + " and " if len(motions) > 1 else "") + motions[-1]
        + " with nothing to hold it but friction", d)


@dataclass(frozen=True)
class Neighbours:
    """The pairs of a sector with the next sector (:func:`check_supported`).

    nodes : (nc,) bool, the contact nodes whose partner is in the next sector.
    rotation : (d, d) the turn by ``2 pi / N`` of a vector's components.
    n_sectors : ``N``.
    """

    nodes: np.ndarray
    rotation: np.ndarray
    n_sectors: int


def _family_phases(neighbour: Neighbours) -> list[complex]:
    """``e^{i k 2 pi / N}`` of the families ``k = 0 .. N / 2`` (``N - k``: the conjugate)."""
    n = int(neighbour.n_sectors)
    return [np.exp(2j * np.pi * k / n) for k in range(n // 2 + 1)]


def _normal_rows(c, R: np.ndarray, neighbour: Neighbours | None, phase: complex) -> np.ndarray:
    """(nc, nr) the normal relative displacement ``n . (U_a - U_b)`` of every contact node
    under each rigid mode (a partner in the next sector: ``e^{i k alpha} Q U_b``)."""
    Rrel = R[c.dofs]
    if c.has_pairs:  # a pair holds the relative normal displacement n . (U_a - U_b)
        pdofs, weights = c.partner_terms()  # U_b = sum_k N_k U_k (node-to-segment)
        if neighbour is not None:
            Rrel = Rrel.astype(complex)
        for k in range(weights.shape[1]):
            pd = pdofs[:, k]
            Rb = weights[:, k, None, None] * R[np.maximum(pd, 0)]
            if neighbour is not None:
                nb = np.asarray(neighbour.nodes, dtype=bool)
                turned = phase * np.einsum("ij,njr->nir", neighbour.rotation, Rb)
                Rb = np.where(nb[:, None, None], turned, Rb)
            Rrel = Rrel - np.where(pd[..., None] >= 0, Rb, 0.0)
    return np.einsum("nd,ndr->nr", c.frame[:, 0, :], Rrel)


def _real_motions(V: np.ndarray) -> np.ndarray:
    """(nr, m) a real basis of the rigid motions spanned by the rows of ``V`` (complex in a
    family ``k != 0``: its real and imaginary parts, the standing waves)."""
    if not np.iscomplexobj(V):
        return V.T
    W = np.vstack([V.real, V.imag])
    _, s, Vt = np.linalg.svd(W)
    return Vt[: int(np.sum(s > 1e-8 * max(1.0, s.max(initial=0.0))))].T


class Unsupported(InputError):
    """A model that only friction could hold: the message says how it can move and, in the
    words of the Python API, what would hold it; :meth:`in_case_file` says it in those of a
    case file."""

    def __init__(self, what: str, dim: int):
        self.what, self.dim = what, dim
        hint = ", ".join(f"Spring(at, {AXES[i]!r}, stiffness)" for i in range(dim))
        super().__init__(f"{what}: add a spring or a fixed DOF (supports = [{hint}] or "
                         "(at, direction)) at a node off the contact boundary")

    def in_case_file(self) -> InputError:
        """The same refusal, with the remedy as case-file blocks."""
        return InputError(f"{self.what}: add a [[springs]] block (at = \"<node set>\" or "
                          "[x, y(, z)], direction = \"x\", stiffness = ... N/m) or a [[fixed]] "
                          "block at a node off the contact boundary")


def _body_name(mesh: Mesh, nodes: np.ndarray, first: int) -> str:
    """``"body 'blade'"`` when a node set holds exactly the nodes of the body (as
    :func:`fretwear.model.join` names each body), else ``"the body of node <first>"``."""
    for name, members in mesh.node_sets.items():
        m = np.asarray(members)
        if m.size == nodes.size and np.array_equal(np.sort(m), nodes):
            return f"body {name!r}"
    return f"the body of node {first}"


def bodies(mesh: Mesh) -> np.ndarray:
    """The body of every node (nn,) int: the connected components of the mesh's cells."""
    from scipy.sparse.csgraph import connected_components

    cells = np.asarray(mesh.cells, dtype=np.int64)
    nn = mesh.points.shape[0]
    k = cells.shape[1]
    rows = np.repeat(cells, k, axis=1).ravel()
    cols = np.tile(cells, (1, k)).ravel()
    graph = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(nn, nn))
    return connected_components(graph, directed=False)[1]


def rigid_motion_check(K, held_dofs, *, dense_limit: int = 600) -> None:
    """Refuse a stiffness matrix that is singular once ``held_dofs`` are held.

    The matrix restricted to the other DOFs is scaled to unit diagonal and its smallest
    eigenvalues are computed (dense below ``dense_limit`` DOFs, else shift-invert Lanczos);
    an eigenvalue below ``1e-12`` times the largest (a zero-energy motion up to rounding)
    means the structure can move with nothing but friction to hold it.

    Parameters
    ----------
    K : (n, n) sparse or dense symmetric stiffness [N/m]
    held_dofs : int array
        DOFs held (contact normal DOFs and fixed DOFs).

    Raises
    ------
    InputError
        Naming the DOFs that move in a zero-energy motion.
    """
    K = sp.csr_matrix(K)
    n = K.shape[0]
    mask = np.ones(n, dtype=bool)
    mask[np.asarray(held_dofs, dtype=np.int64)] = False
    free = np.flatnonzero(mask)
    if free.size == 0:
        return
    Kff = K[free][:, free]
    diag = Kff.diagonal()
    zero = np.flatnonzero(diag <= 0.0)
    if zero.size:
        raise InputError(
            f"DOF(s) {free[zero][:10].tolist()} have no stiffness (diagonal of K <= 0) and are "
            "neither contact normal DOFs nor fixed: nothing holds them but friction; add "
            "stiffness (a spring to ground) or fix them (fixed_dofs)"
        )
    s = 1.0 / np.sqrt(diag)
    S = sp.diags(s) @ Kff @ sp.diags(s)
    scale = float(abs(S).sum(axis=1).max())  # >= largest eigenvalue
    if free.size <= dense_limit:
        lam, V = sla.eigh(S.toarray())
        lam, V = lam[:6], V[:, :6]
    else:
        lam, V = spla.eigsh(S.tocsc(), k=6, sigma=-1e-6 * scale, which="LM",
                            v0=np.random.default_rng(0).standard_normal(S.shape[0]))
    bad = lam < 1e-12 * scale
    if not np.any(bad):
        return
    u = s * V[:, int(np.argmin(lam))]
    moving = free[np.abs(u) > 0.1 * np.abs(u).max()]
    listed = moving[:10].tolist() + (["..."] if moving.size > 10 else [])
    raise InputError(
        f"the stiffness matrix with the contact normal DOFs and the fixed DOFs held is "
        f"singular ({int(bad.sum())} zero-energy motion(s)): DOFs {listed} can move with "
        "nothing to hold them but friction; add stiffness there (a spring to ground) or fix "
        "DOFs (fixed_dofs)"
    )
