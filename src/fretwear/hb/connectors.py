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
    ``node_b`` (nb, m) complex. ``structure`` is the reduced model of the structure alone;
    ``estimate`` is its (a model of the local bases is one through the springs too).
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


@dataclass(frozen=True)
class Springs:
    """The contact springs of an interface as :func:`connect` uses them, prepared once per
    interface (a sweep connects the reduced model of every frequency through the same
    springs). ``k`` (m,) [N/m] (:func:`stiffness`); ``f`` the directions with a finite
    spring (their ``u`` is eliminated) and ``kf`` (nf,) their springs [N/m]; ``r`` the rigid
    directions (``u = x`` along them); ``perm`` the order ``[r, f]`` (None when it is the
    node-major order itself)."""

    k: np.ndarray
    f: np.ndarray
    kf: np.ndarray
    r: np.ndarray
    perm: np.ndarray | None = None


def springs(contact: ContactInterface) -> Springs | None:
    """The prepared :class:`Springs` of ``contact``; None when the interface is rigid."""
    if not contact.has_springs:
        return None
    k = stiffness(contact)
    f = np.flatnonzero(np.isfinite(k))
    r = np.flatnonzero(~np.isfinite(k))
    perm = np.concatenate([r, f])
    return Springs(k, f, k[f], r, None if np.array_equal(perm, np.arange(k.size)) else perm)


def connect(reduced: Reduced, contact: ContactInterface,
            prepared: Springs | None = None) -> Reduced:
    """The reduced model seen by the contact law through the contact springs of ``contact``
    (module docstring); ``reduced`` itself when the interface is rigid or ``reduced`` is
    already a :class:`Connected`. ``prepared``: ``springs(contact)`` if already made.

    With the finite directions ``f`` (springs ``K_f``) and the rigid ones ``r`` (``u_r =
    x_r``), eliminating ``u_f`` harmonic by harmonic from
    ``(Z_ff + K_f) u_f + Z_fr x_r - K_f x_f = F_f`` gives ``u_f = y - X x`` with
    ``[X, y] = (Z_ff + K_f)^-1 [[Z_fr, -K_f], F_f]`` (columns ``x_r``, ``x_f``), and

        Z_x = [[Z_rr, 0], [0, K_f]] - [[Z_rf], [-K_f]] X,   F_x = [F_r; 0] - [[Z_rf], [-K_f]] y

    (rows ``r`` then ``f``): the module docstring's formulas with the rigid directions tied.
    Every harmonic is eliminated at once (batched LAPACK)."""
    if isinstance(reduced, Connected):
        return reduced
    sp = springs(contact) if prepared is None else prepared
    if sp is None:
        return reduced
    m = reduced.m
    if sp.k.size != m:
        raise InputError(f"contact stiffness has {sp.k.size} entries for {m} reduced DOFs")
    kf, nr = sp.kf, sp.r.size
    Z, F = reduced.Z, reduced.F
    if not isinstance(Z, np.ndarray):  # a ReducedOperator (hb/modal_operator.py): formed
        Z = np.stack(list(Z))
    if sp.perm is not None:  # rigid directions first: the blocks are then slices
        Z, F = Z[:, sp.perm[:, None], sp.perm], F[:, sp.perm]
    nb = Z.shape[0]
    Kff = np.diag(kf)
    Aff = Z[:, nr:, nr:] + Kff
    # [X, y] = (Z_ff + K_f)^-1 [Z_fr, -K_f, F_f]
    rhs = np.empty((nb, m - nr, m + 1), dtype=complex)
    rhs[:, :, :nr] = Z[:, nr:, :nr]
    rhs[:, :, nr:m] = -Kff
    rhs[:, :, m] = F[:, nr:]
    try:
        sol = np.linalg.solve(Aff, rhs)
    except np.linalg.LinAlgError:
        for b in range(nb):  # name the singular harmonic
            try:
                np.linalg.solve(Aff[b], rhs[b])
            except np.linalg.LinAlgError:
                raise InputError(f"the structure with its contact springs is singular at "
                                 f"harmonic {int(reduced.orders[b])} "
                                 f"({reduced.frequency:.6g} Hz)") from None
        raise
    X, y = sol[:, :, :m], sol[:, :, m]  # u_f = y - X x
    Axf = np.empty((nb, m, m - nr), dtype=complex)
    Axf[:, :nr] = Z[:, :nr, nr:]
    Axf[:, nr:] = -Kff
    Zx = np.zeros(Z.shape, dtype=complex)  # Z may be real (undamped), X is complex
    Zx[:, :nr, :nr] = Z[:, :nr, :nr]
    Zx[:, nr:, nr:] = Kff
    Zx -= Axf @ X
    Fx = np.zeros_like(F)
    Fx[:, :nr] = F[:, :nr]
    Fx -= (Axf @ y[:, :, None])[:, :, 0]
    nA = np.zeros((nb, m, m), dtype=complex)  # u = node_A x + node_b
    nA[:, :nr, :nr] = np.eye(nr)
    nA[:, nr:, :] = -X
    nbv = np.zeros(F.shape, dtype=complex)
    nbv[:, nr:] = y
    if sp.perm is not None:  # back to the node-major order
        inv = np.argsort(sp.perm)
        Zx, Fx = Zx[:, inv[:, None], inv], Fx[:, inv]
        nA, nbv = nA[:, inv[:, None], inv], nbv[:, inv]
    obs_A = reduced.obs_A @ nA
    obs_b = reduced.obs_b + (reduced.obs_A @ nbv[:, :, None])[:, :, 0]
    return Connected(reduced.omega, reduced.orders, Zx, Fx, obs_A, obs_b, reduced.obs_dofs,
                     reduced.quasi_static, reduced.frequency, reduced.estimate, node_A=nA,
                     node_b=nbv, structure=reduced)


def node_displacements(reduced: Reduced, X: np.ndarray) -> np.ndarray:
    """The structure's contact-node amplitudes ``u`` (nb, m) complex [m] from the contact
    points' ``X`` (nb, m) complex [m]: ``X`` itself without contact springs."""
    if not isinstance(reduced, Connected):
        return X
    return (reduced.node_A @ X[:, :, None])[:, :, 0] + reduced.node_b
