"""Contact stiffness in series with the contact law: a transformation of a :class:`Reduced`.

A contact node with normal and tangential contact stiffness ``kn``, ``kt`` (a physical
property of the interface: asperities, coatings, a Jenkins element's spring) is modelled
exactly by a massless *contact point* ``x`` joined to the structure's contact node ``u`` by the
springs ``Kc = diag(kn, kt(, kt))`` in the node's local frame; the DLFT law (paper eq. 23-28)
acts on ``x`` unchanged. Harmonic by harmonic, with ``Z_r u + Kc (u - x) = F_r`` for the
structure and ``Kc (x - u) + lambda = 0`` for the contact point, eliminating ``u`` gives the
reduced model seen by the law (the same condensation as paper eq. 19, one level further):

    Z_x = Kc - Kc (Z_r + Kc)^-1 Kc,      F_x = Kc (Z_r + Kc)^-1 F_r,
    u = (Z_r + Kc)^-1 (F_r + Kc x).

An infinite stiffness (a rigid direction, e.g. ``kn = inf`` with a finite ``kt``: a Jenkins
element on a rigid normal) ties ``u`` to ``x`` along it; the implementation eliminates only the
directions with a finite spring (:func:`connect`), so the rigid limit is exact, not a large
number. The result is another :class:`Reduced` (the observation rows included), so the
periodic solve, the sweeps and the wear take it unchanged; :class:`Connected` also keeps the
recovery of the structure's contact nodes ``u = node_A x + node_b``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.reduce import Reduced
from fretwear.model.core import ContactInterface


@dataclass
class Connected(Reduced):
    """A :class:`Reduced` seen by the contact law through contact springs.

    ``Z``, ``F``, ``obs_A``, ``obs_b`` are those of the contact points ``x``; the structure's
    contact nodes are ``u = node_A @ x + node_b`` harmonic by harmonic: ``node_A`` (nb, m, m),
    ``node_b`` (nb, m) complex. ``structure`` is the reduced model of the structure alone.
    """

    node_A: np.ndarray = None
    node_b: np.ndarray = None
    structure: Reduced = None


def stiffness(contact: ContactInterface) -> np.ndarray:
    """Contact stiffness per local DOF (m,) [N/m], node-major ``[kn, kt(, kt)]``; ``inf`` where
    the contact is rigid. Raises InputError naming ``kn``/``kt`` for values that are not
    positive (a zero spring disconnects the contact point)."""
    nc, d = contact.n_nodes, contact.dim
    out = np.full((nc, d), np.inf)
    for name, value, cols in (("kn", contact.kn, slice(0, 1)), ("kt", contact.kt,
                                                                 slice(1, d))):
        if value is None:
            continue
        k = np.broadcast_to(np.asarray(value, dtype=float), (nc,))
        bad = ~(k > 0) | np.isnan(k)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputError(f"contact {name} = {k[i]!r} N/m at node {i}: expected a positive "
                             "stiffness (inf: rigid)")
        out[:, cols] = k[:, None]
    return out.reshape(-1)


def connect(reduced: Reduced, contact: ContactInterface) -> Reduced:
    """The reduced model seen by the contact law through the contact springs of ``contact``
    (module docstring); ``reduced`` itself when the interface is rigid or ``reduced`` is
    already a :class:`Connected`."""
    if isinstance(reduced, Connected) or not contact.has_springs:
        return reduced
    k = stiffness(contact)
    m = reduced.m
    if k.size != m:
        raise InputError(f"contact stiffness has {k.size} entries for {m} reduced DOFs")
    f = np.flatnonzero(np.isfinite(k))  # directions with a spring: u_f is eliminated
    rigid = ~np.isfinite(k)  # u = x along them
    kf = np.where(rigid, 0.0, k)
    nb = reduced.Z.shape[0]
    Zx = np.empty_like(reduced.Z)
    Fx = np.empty_like(reduced.F)
    nA = np.empty((nb, m, m), dtype=complex)
    nbv = np.empty((nb, m), dtype=complex)
    for b in range(nb):
        Z, F = reduced.Z[b], reduced.F[b]
        # unknowns (u_f, x): u = E_f u_f + P_r x; stiffness [[Z + Kf, -Kf], [-Kf, Kf]] on (u, x)
        Zu = Z + np.diag(kf)
        Aff = Zu[np.ix_(f, f)]
        # A'_fx = E_f^T (Zu P_r - Kf) ; A'_xx = P_r Zu P_r - P_r Kf - Kf P_r + Kf
        Afx = Zu[f][:, rigid] @ np.eye(m)[rigid] - np.diag(kf)[f]
        Pr = np.diag(rigid.astype(float))
        Axx = Pr @ Zu @ Pr - Pr @ np.diag(kf) - np.diag(kf) @ Pr + np.diag(kf)
        Ff = F[f]
        Fxx = Pr @ F
        try:
            sol = np.linalg.solve(Aff, np.column_stack([Afx, Ff]))
        except np.linalg.LinAlgError:
            raise InputError(f"the structure with its contact springs is singular at harmonic "
                             f"{int(reduced.orders[b])} ({reduced.frequency:.6g} Hz)") from None
        X, y = sol[:, :m], sol[:, m]
        Axf = (Pr @ Zu - np.diag(kf))[:, f]
        Zx[b] = Axx - Axf @ X
        Fx[b] = Fxx - Axf @ y
        A = Pr.astype(complex)
        A[f] -= X
        nA[b] = A
        bv = np.zeros(m, dtype=complex)
        bv[f] = y
        nbv[b] = bv
    obs_A = np.einsum("bom,bmj->boj", reduced.obs_A, nA)
    obs_b = reduced.obs_b + np.einsum("bom,bm->bo", reduced.obs_A, nbv)
    return Connected(reduced.omega, reduced.orders, Zx, Fx, obs_A, obs_b, reduced.obs_dofs,
                     reduced.quasi_static, reduced.frequency, node_A=nA, node_b=nbv,
                     structure=reduced)


def node_displacements(reduced: Reduced, X: np.ndarray) -> np.ndarray:
    """The structure's contact-node amplitudes ``u`` (nb, m) complex [m] from the contact
    points' ``X`` (nb, m) complex [m]: ``X`` itself without contact springs."""
    if not isinstance(reduced, Connected):
        return X
    return np.einsum("bmj,bj->bm", reduced.node_A, X) + reduced.node_b
