"""Argument checks shared by the time-domain solvers (one line naming the argument)."""

from __future__ import annotations

import math

import numpy as np

from fretwear.errors import InputError
from fretwear.model.core import Model


def positive(value, what: str, high: float = 1e20) -> float:
    """``value`` as a float after checking it is a real number (not a string or a bool) in
    ``(0, high]``."""
    if isinstance(value, str | bytes | bool | np.bool_):
        raise InputError(f"{what} = {value!r}; expected a positive number")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} = {value!r}; expected a positive number") from None
    if not (math.isfinite(v) and 0.0 < v <= high):
        raise InputError(f"{what} = {value!r}; expected a positive finite number (at most "
                         f"{high:g})")
    return v


def count(value, what: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InputError(f"{what} = {value!r}; expected an integer >= {minimum}")
    if value < minimum or value > 2**62:
        raise InputError(f"{what} = {value}; expected an integer >= {minimum} (and at most "
                         "2^62)")
    return int(value)


def c_float(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


def check_contact(model: Model) -> None:
    c = model.contact
    dofs = np.asarray(c.dofs)
    if dofs.ndim != 2 or dofs.shape[0] == 0 or dofs.shape[1] not in (2, 3):
        raise InputError(f"contact.dofs has shape {dofs.shape}; expected (nc >= 1, 2 or 3)")
    if np.unique(dofs).size != dofs.size:
        raise InputError("contact.dofs: a DOF belongs to two contact nodes (or twice to one); "
                         "the time-domain solver needs distinct contact DOFs")
    fixed = np.intersect1d(dofs.ravel(), np.asarray(model.fixed_dofs, dtype=np.int64))
    if fixed.size:
        raise InputError(f"contact DOF {int(fixed[0])} is also a fixed DOF; a contact node must "
                         "be free to move in all its directions for the time-domain solver")
    mu = c.mu_nodes()
    if not np.all(np.isfinite(mu) & (mu >= 0.0)):
        bad = float(mu[~(np.isfinite(mu) & (mu >= 0.0))][0])
        raise InputError(f"contact.mu = {bad!r}; expected a friction coefficient >= 0")
    if getattr(c, "has_connectors", False):
        raise InputError("contact stiffness (kn, kt) and prescribed normal loads are modelled "
                         "by the harmonic balance only; the time-domain solver takes rigid "
                         "unilateral contacts (write the springs as massless DOFs instead)")


def node_wear(wear, nc: int, what: str = "wear") -> np.ndarray:
    if wear is None:
        return np.zeros(nc)
    w = np.asarray(wear, dtype=float)
    if w.shape != (nc,) or not np.all(np.isfinite(w)):
        raise InputError(f"{what} has shape {w.shape}; expected ({nc},) finite depths [m] (one "
                         "per contact node)")
    return w.copy()
