"""Centrifugal loading of a structure rotating at a constant speed (a bladed disk in
service): the body force ``rho Omega^2 r`` as a static load.

At a speed ``Omega`` [rad/s] about a unit axis ``a`` through a point ``p``, a material point
at ``x`` carries, in the rotating frame, the body force per unit volume

    b(x) = rho Omega^2 r(x),        r(x) = (x - p) - ((x - p) . a) a,

(``r``: the position's component normal to the axis). Its consistent nodal forces
``F_i = int N_i rho Omega^2 r dV`` are exactly ``Omega^2 M r_h`` with the consistent mass
matrix ``M`` and ``r_h`` the nodal values of ``r``: ``r`` is linear in ``x``, so it is
interpolated exactly by the isoparametric elements of :mod:`fretwear.model.fem` and the
integral is the mass matrix's. Their sum is ``m Omega^2 r_cg`` (the total mass times the
centre of mass's distance to the axis).

Left out (docs/theory.md, "Centrifugal loading"): the load is taken on the undeformed
geometry (no follower term ``rho Omega^2 u``, the spin softening that lowers the stiffness by
``Omega^2 M_r``), no stress stiffening (the geometric stiffness of the centrifugal
prestress), no Coriolis forces (``2 Omega`` gyroscopic matrix) in the dynamics.
"""

from __future__ import annotations

import math

import numpy as np

from fretwear.errors import InputError
from fretwear.model.checks import model_argument
from fretwear.model.core import Load, Model


def _speed(speed) -> float:
    if isinstance(speed, bool) or not isinstance(speed, int | float | np.floating) \
            or not math.isfinite(speed) or not 0 <= speed <= 1e10:
        raise InputError(f"speed = {speed!r}: expected a rotation speed >= 0 [rad/s]")
    return float(speed)


def radial_positions(model: Model, axis=(0.0, 0.0, 1.0), point=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(ndof,) the component ``r`` normal to the axis of every node's position [m], laid out
    as the model's DOFs (``d i + c``: a mesh model)."""
    from fretwear.model.cyclic import _axis

    mesh = model.mesh
    if mesh is None:
        raise InputError("centrifugal_load: the model has no mesh (node positions); give the "
                         "load of a model of user matrices as a load vector")
    d = mesh.dim
    a, p = _axis(axis, point, d)
    x = np.asarray(mesh.points, float) - p[:d]
    if d == 2:
        r = x  # the axis is (0, 0, +-1): every in-plane position is normal to it
    else:
        r = x - np.outer(x @ a, a)
    out = np.zeros(model.ndof)
    out[: r.size] = r.reshape(-1)
    return out


@model_argument
def centrifugal_load(model: Model, speed: float, *, axis=(0.0, 0.0, 1.0),
                     point=(0.0, 0.0, 0.0), name: str = "centrifugal") -> Load:
    """The static :class:`~fretwear.model.core.Load` of the body force ``rho Omega^2 r`` at
    the rotation ``speed`` ``Omega`` [rad/s] about the unit ``axis`` through ``point`` [m]
    (module docstring): ``Omega^2 M r_h`` [N], waveform ``"constant"``. Add it to the
    model's loads (``dataclasses.replace(model, loads=[*model.loads, load])``); it presses a
    blade root into its slot. ``model``: built from a mesh (its ``M`` the consistent mass)."""
    w = _speed(speed)
    r = radial_positions(model, axis, point)
    vector = w * w * np.asarray(model.M @ r, dtype=float)
    return Load(vector, "constant", name=name)
