"""Centrifugal loading (fretwear.model.rotation) against closed forms: the resultant
``m Omega^2 r_cg`` and the tip extension of a uniform bar spinning about one end."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.model.build import ContactSpec, Material, from_mesh
from fretwear.model.mesh import box, rectangle
from fretwear.model.rotation import centrifugal_load

E, RHO, OMEGA = 2e11, 7800.0, 1000.0


def test_resultant_is_mass_times_centre_distance():
    """The sum of the nodal forces is ``m Omega^2 r_cg`` (``m = rho V``, ``r_cg`` the centre
    of the box's distance vector to a tilted axis, by hand): exact up to rounding (the
    consistent mass integrates the linear field ``r`` exactly), so 1e-12 relative."""
    lx, ly, lz = 0.3, 0.1, 0.05
    origin = np.array([0.2, -0.1, 0.05])
    mesh = box(lx, ly, lz, 3, 2, 2, origin=tuple(origin))
    model = from_mesh(mesh, Material(E, 0.3, RHO), supports=[("xmin", "all")],
                      contact=ContactSpec("xmax", mu=0.3))
    a = np.array([1.0, 2.0, 2.0]) / 3.0
    p = np.array([0.01, 0.02, -0.03])
    load = centrifugal_load(model, OMEGA, axis=tuple(a), point=tuple(p))
    total = load.vector.reshape(-1, 3).sum(axis=0)
    c = origin + np.array([lx, ly, lz]) / 2 - p
    want = RHO * lx * ly * lz * OMEGA**2 * (c - (c @ a) * a)
    assert load.waveform == "constant"
    assert np.allclose(total, want, rtol=0, atol=1e-12 * np.abs(want).max())


def test_spinning_bar_tip_extension():
    """A bar of length L along x spinning about z through its end x = 0 (nu = 0, its end
    held in x): 1D theory gives ``u(L) = rho Omega^2 L^3 / (3 E)`` (sigma = rho Omega^2
    (L^2 - x^2) / 2; exact in 2D with nu = 0: u_x(x), u_y(y) decouple). With consistent
    nodal loads, linear elements are exact at the nodes for a bar (Tong 1969), so 1e-9
    relative (seen: 1e-13 at 20 and 80 elements); a wrong factor (2, Omega instead of
    Omega^2, a lumped or misplaced load) fails by far more."""
    nx = 20
    L, H = 1.0, 0.02
    mesh = rectangle(L, H, nx, 2, origin=(0.0, -H / 2))
    model = from_mesh(mesh, Material(E, 0.0, RHO), thickness=0.01,
                      supports=[("left", "x"), ((0.0, 0.0), "y")],
                      contact=ContactSpec("right", mu=0.3, gap=1.0))
    F = centrifugal_load(model, OMEGA).vector
    free = np.setdiff1d(np.arange(model.ndof), model.fixed_dofs)
    u = np.zeros(model.ndof)
    u[free] = spla.spsolve(model.K.tocsc()[free][:, free], F[free])
    tip = np.flatnonzero(np.isclose(mesh.points[:, 0], L))
    want = RHO * OMEGA**2 * L**3 / (3 * E)
    got = u[2 * tip].mean()
    assert abs(got - want) < 1e-9 * want, (got, want)


def test_bad_speed_and_axis():
    """A negative speed and a non-unit axis are one-line messages naming the argument."""
    model = from_mesh(rectangle(1.0, 0.1, 2, 1), Material(E, 0.3, RHO),
                      supports=[("left", "all")], contact=ContactSpec("right", mu=0.3))
    with pytest.raises(InputError, match=r"^speed = -1.0: expected"):
        centrifugal_load(model, -1.0)
    with pytest.raises(InputError, match=r"^axis = \(0, 1, 1\): expected a unit vector"):
        centrifugal_load(model, 1.0, axis=(0, 1, 1))
