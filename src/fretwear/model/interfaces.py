"""Several contact interfaces in one model, node-to-node pairs and their exact change of
variables.

A model holds one per-node contact record (:class:`~fretwear.model.core.ContactInterface`)
for all its interfaces: :func:`combine` concatenates the interfaces, records each node's
interface and refuses a node that belongs to two of them.

Node-to-node pairs ``(a, b)`` are taken to the relative coordinates the paper writes its
method in (subscript r) by an exact change of variables: ``U = P U'``, where ``U'`` equals
``U`` except at the DOFs of every node ``a``, which hold the relative displacement
``r = U_a - U_b``; ``P`` is the identity plus one identity block per pair (``U_a = r + U_b``).
Then ``P^T Z P U' = P^T F - [frame^T lambda on r; 0]``: the contact forces act on ``r``
only, equal and opposite on ``a`` and ``b`` by construction, and the model in the primed
coordinates (:func:`relative_model`) has node-to-rigid contact on the ``r`` DOFs. The
condensation, the DLFT law, its Jacobian, the sweeps and the wear integration see it
unchanged. The condensation holds ``r = 0`` (the pairs glued) and needs the glued assembly
to be held; a displacement field is recovered as ``U = P U'``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.core import ContactInterface, Load, Model, ObservedPoint, Segments


def combine(interfaces) -> ContactInterface:
    """One per-node record of several interfaces (each a :class:`ContactInterface`).

    The nodes keep their order, interface after interface; ``interface`` holds each node's
    interface index and ``interface_names`` the names (which must differ). Per-interface
    numbers (``mu``, wear coefficients) become per-node arrays, or stay one number when all
    interfaces have the same.

    Raises
    ------
    InputError
        Two interfaces with one name, mixed dimensions, or a DOF that belongs to two contact
        nodes (a node in two interfaces, or a node that is both a contact node and another
        pair's partner).
    """
    items = list(interfaces)
    if not items:
        raise InputError("contact: expected at least one interface")
    if len(items) == 1 and items[0].interface is None:
        return items[0]
    names = []
    for c in items:
        names.extend(c.names())
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise InputError(f"contact: two interfaces are named {dup!r}; expected distinct names")
    dims = {c.dim for c in items}
    if len(dims) != 1:
        raise InputError(f"contact: interfaces of dimensions {sorted(dims)}; expected one")
    d = dims.pop()
    offset = 0
    index = []
    for c in items:
        index.append(c.interface_index() + offset)
        offset += len(c.names())

    def cat(get):
        return np.concatenate([np.asarray(get(c)) for c in items])

    def partner(c):
        if c.partner_dofs is None:
            return np.full((c.n_nodes, d), -1, dtype=np.int64)
        return np.asarray(c.partner_dofs, dtype=np.int64)

    def ids(c, field):
        v = getattr(c, field)
        return np.full(c.n_nodes, -1, dtype=np.int64) if v is None else np.asarray(v, np.int64)

    out = ContactInterface(
        dofs=cat(lambda c: np.asarray(c.dofs, dtype=np.int64)),
        frame=cat(lambda c: np.asarray(c.frame, dtype=float)),
        gap=cat(lambda c: c._per_node(c.gap)),
        area=cat(lambda c: c._per_node(c.area)),
        mu=cat(lambda c: c.mu_nodes()),
        coords=cat(lambda c: np.asarray(c.coords, dtype=float).reshape(c.n_nodes, d)),
        node_ids=cat(lambda c: ids(c, "node_ids")),
        wear_coefficient=cat(lambda c: c.wear_nodes()),
        name=names[0],
        partner_dofs=cat(partner),
        partner_ids=cat(lambda c: ids(c, "partner_ids")),
        partner_wear_coefficient=cat(lambda c: c.partner_wear_nodes()),
        interface=np.concatenate(index),
        interface_names=tuple(names),
        normal_load=_combined_normal_load(items),
        kn=_combined_stiffness(items, "kn"),
        kt=_combined_stiffness(items, "kt"),
        segments=_combined_segments(items, d),
    )
    check_distinct(out)
    for key in ("mu", "wear_coefficient", "partner_wear_coefficient"):
        v = np.asarray(getattr(out, key))
        if v.size and np.all(v == v[0]):  # one number for every node stays one number
            setattr(out, key, float(v[0]))
    if not out.has_pairs:
        out.partner_dofs = out.partner_ids = out.segments = None
    return out


def _combined_segments(items, d: int) -> Segments | None:
    """The node-to-segment partners of several interfaces (node-to-node pairs become one
    term of weight 1); None when no interface has node-to-segment pairs."""
    if all(c.segments is None for c in items):
        return None
    terms = [c.partner_terms() for c in items]
    k = max(w.shape[1] for _, w in terms)

    def pad(a, fill):
        return np.concatenate([a, np.full((a.shape[0], k - a.shape[1], *a.shape[2:]), fill,
                                          dtype=a.dtype)], axis=1)

    ids = [pad(np.asarray(c.segments.ids, np.int64), -1) if c.segments is not None
           else np.where(w > 0, (np.full(c.n_nodes, -1) if c.partner_ids is None
                                  else np.asarray(c.partner_ids))[:, None], -1)
           for c, (_, w) in zip(items, terms, strict=True)]
    return Segments(dofs=np.concatenate([pad(p, -1) for p, _ in terms]),
                    weights=np.concatenate([pad(w, 0.0) for _, w in terms]),
                    ids=np.concatenate([pad(i, -1) for i in ids]))


def _combined_stiffness(items, field: str):
    """Per-node contact stiffness of several interfaces [N/m]: ``inf`` (rigid) where an
    interface has none; None when every node is rigid."""
    if all(getattr(c, field) is None for c in items):
        return None
    return np.concatenate([np.full(c.n_nodes, np.inf) if getattr(c, field) is None
                           else np.asarray(getattr(c, field), float) for c in items])


def _combined_normal_load(items) -> Load | None:
    """The prescribed normal load of several interfaces: one waveform for all (the record
    holds one ``N(t) = vector * g(omega t)``), NaN for the nodes in unilateral contact."""
    loaded = [c.normal_load for c in items if c.normal_load is not None]
    if not loaded:
        return None
    first = loaded[0]
    for ld in loaded[1:]:
        if ld.waveform != first.waveform or ld.coefficients != first.coefficients:
            raise InputError(
                f"contact: prescribed normal loads with waveforms {first.waveform!r} and "
                f"{ld.waveform!r}; expected one normal_waveform for every interface with a "
                "normal_pressure")
    vec = np.concatenate([np.full(c.n_nodes, np.nan) if c.normal_load is None
                          else np.asarray(c.normal_load.vector, float) for c in items])
    return Load(vec, first.waveform, first.coefficients, first.name)


def check_distinct(c: ContactInterface) -> None:
    """A DOF belongs to at most one contact node, and a pair's partner is not a node ``a``.

    Raises InputError naming the node, its interfaces and position.
    """
    dofs = np.asarray(c.dofs, dtype=np.int64)
    where = c.interface_index()
    names = c.names()
    flat = dofs.reshape(-1)
    values, first, counts = np.unique(flat, return_index=True, return_counts=True)
    if np.any(counts > 1):
        g = int(values[counts > 1][0])
        nodes = np.flatnonzero(np.any(dofs == g, axis=1))
        ifs = sorted({names[where[p]] for p in nodes})
        raise InputError(
            f"contact: the node at {tuple(np.round(c.coords[nodes[0]], 12).tolist())} (DOF {g}) "
            f"is in {len(nodes)} contact places (interfaces {ifs}); a node belongs to one "
            "interface only"
        )
    if c.partner_dofs is not None:
        pd = c.partner_terms()[0].reshape(c.n_nodes, -1)
        clash = np.intersect1d(pd[pd >= 0], flat)
        if clash.size:
            p = int(np.flatnonzero(np.any(pd == clash[0], axis=1))[0])
            raise InputError(
                f"contact: the partner (DOF {int(clash[0])}) of the pair at "
                f"{tuple(np.round(c.coords[p], 12).tolist())} (interface "
                f"{names[where[p]]!r}) is itself a contact node; a node belongs to one "
                "interface only"
            )


def pair_transform(contact: ContactInterface, ndof: int) -> sp.csr_matrix | None:
    """``P`` (ndof, ndof) with ``U = P U'`` (module docstring), or None without pairs."""
    if not contact.has_pairs:
        return None
    eye = np.arange(ndof)
    if contact.segments is None:
        pd = np.asarray(contact.partner_dofs, dtype=np.int64)
        keep = pd >= 0
        rows = np.asarray(contact.dofs, dtype=np.int64)[keep]
        cols = pd[keep]
        vals = np.ones(rows.size)
    else:  # node-to-segment: U_a = r + sum_k N_k U_k (one block N_k I per facet node)
        pdofs, weights = contact.partner_terms()
        w = np.broadcast_to(weights[:, :, None], pdofs.shape)
        keep = (pdofs >= 0) & (w != 0.0)
        rows = np.broadcast_to(np.asarray(contact.dofs, dtype=np.int64)[:, None, :],
                               pdofs.shape)[keep]
        cols, vals = pdofs[keep], w[keep]
    return sp.csr_matrix(
        (np.concatenate([np.ones(ndof), vals]),
         (np.concatenate([eye, rows]), np.concatenate([eye, cols]))),
        shape=(ndof, ndof),
    )


def relative_model(model: Model) -> tuple[Model, sp.csr_matrix | None]:
    """The model in the relative coordinates ``U'`` of its pairs, and ``P`` (``U = P U'``).

    ``K' = P^T K P`` (the same for ``M``, ``C``, ``D``), loads ``P^T F``; the contact record
    keeps its nodes with the partners dropped (node-to-rigid on the ``r`` DOFs); the
    observed points keep their DOFs, whose displacement is ``(P U')[dofs]``. A model without
    pairs is returned as it is, with ``P = None``.
    """
    P = pair_transform(model.contact, model.ndof)
    if P is None:
        return model, None
    fixed = np.asarray(model.fixed_dofs, dtype=np.int64)
    if np.intersect1d(fixed, np.asarray(model.contact.dofs).reshape(-1)).size:
        raise InputError("contact DOFs cannot also be fixed (Dirichlet) DOFs")
    Pt = P.T.tocsr()

    def tr(A):
        return None if A is None else (Pt @ A @ P).tocsr()

    loads = [dataclasses.replace(ld, vector=Pt @ np.asarray(ld.vector, dtype=float))
             for ld in model.loads]
    contact = dataclasses.replace(model.contact, partner_dofs=None, segments=None)
    rel = dataclasses.replace(model, K=tr(model.K), M=tr(model.M), C=tr(model.C), D=tr(model.D),
                              loads=loads, contact=contact,
                              observed=[ObservedPoint(p.name, p.dofs, p.coords)
                                        for p in model.observed])
    return rel, P


def observed_map(model: Model, P) -> tuple[np.ndarray, np.ndarray, sp.csr_matrix | None]:
    """Observed DOFs, the primed DOFs they depend on and the map between them.

    Returns ``(obs, cols, S)``: ``U[obs] = S @ U'[cols]`` (``S = None`` and ``cols = obs``
    without pairs).
    """
    obs = (np.concatenate([np.asarray(p.dofs, dtype=np.int64) for p in model.observed])
           if model.observed else np.zeros(0, dtype=np.int64))
    if P is None:
        return obs, obs, None
    rows = P[obs]
    cols = np.unique(rows.indices).astype(np.int64)
    return obs, cols, rows[:, cols].tocsr()
