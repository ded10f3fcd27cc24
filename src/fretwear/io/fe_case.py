"""The model of a case file whose ``[model]`` holds matrices exported by an FE code
(``type = "matrices"`` with ``format`` or ``dofmap``): the files read with
:func:`fretwear.model.readers.read_fe`, the sections named by node ids turned into
:func:`~fretwear.model.readers.from_fe` records, each mistake naming its case-file key."""

from __future__ import annotations

import numpy as np

from fretwear.errors import InputError
from fretwear.model.build import Damping
from fretwear.model.readers import NodeContact, NodeForce, from_fe, read_fe, read_nodes

_AXES = {"x": 1, "y": 2, "z": 3}


def _nodes(value):
    """Node ids (a list) or a node-set name (a string), as the records take them."""
    return value if isinstance(value, str) else np.asarray(value, dtype=np.int64)


def _keyed(key: str, func, *args, **kwargs):
    """``func(*args)``, its InputError prefixed with the case-file key."""
    try:
        return func(*args, **kwargs)
    except InputError as exc:
        raise InputError(f"{key}: {exc}") from None


def build_from_fe(m: dict, title: str):
    """The :class:`~fretwear.model.core.Model` of a validated case with FE matrices."""
    spec = m["model"]
    fe = _keyed("model.K", read_fe, spec["K"], spec.get("M"), format=spec.get("format"),
                C=spec.get("C"), D=spec.get("D"), dofmap=spec.get("dofmap"),
                names=spec.get("names"))
    table = _keyed("model.nodes", read_nodes, spec["nodes"]) if "nodes" in spec else None
    dim = 3 if np.any(fe.dofs.component == 3) else 2
    contacts = []
    for i, c in enumerate(m["contact"]):
        normal = None if "normal" not in c else np.asarray(c["normal"], dtype=float)
        if normal is not None and normal.size != dim:
            raise InputError(f"contact[{i + 1}].normal = {c['normal']}: expected {dim} "
                             f"components (the matrices are {dim}D)")
        area = c["area"]
        contacts.append(NodeContact(
            nodes=_nodes(c["nodes"]), mu=c["mu"], normal=normal,
            partners=None if "partners" not in c else _nodes(c["partners"]), gap=c["gap"],
            area=np.asarray(area, dtype=float) if isinstance(area, list) else area,
            wear_coefficient=c["wear_coefficient"],
            partner_wear_coefficient=c["partner_wear_coefficient"], name=c["name"],
            pairing=c["pairing"], tolerance=c.get("tolerance"), thickness=c["thickness"]))
    loads = []
    for i, ld in enumerate(m.get("loads", [])):
        force = np.asarray(ld["force"], dtype=float)
        if force.size != dim:
            raise InputError(f"loads[{i + 1}].force = {ld['force']}: expected {dim} "
                             "components")
        coeff = ld.get("coefficients")
        loads.append(NodeForce(_nodes(ld["nodes"]), force, ld["waveform"],
                               ld.get("name") or f"load{i + 1}",
                               None if coeff is None else
                               {int(k): tuple(v) for k, v in coeff.items()}))
    fixed = [(_nodes(f["nodes"]), "all" if f["direction"] == "all" else [_AXES[f["direction"]]])
             for f in m.get("fixed", [])]
    damp = m["damping"]
    damping = Damping(loss_factor=damp["loss_factor"], rayleigh_mass=damp["rayleigh_mass"],
                      rayleigh_stiffness=damp["rayleigh_stiffness"])
    observed = {k: _nodes(v) if isinstance(v, str) else int(v)
                for k, v in m.get("observed", {}).items()}
    return from_fe(fe, contact=contacts, nodes=table, damping=damping, loads=loads, fixed=fixed,
                   observed=observed or None, name=title)
