"""A lumped bladed disk (blisk) for teaching: one sector of two point masses and three springs,
with a friction contact at the blade tip.

Sector ``j`` has a disk mass ``m_d`` (node D on the left cyclic boundary, radius ``r_d``,
angle 0) held to the ground by ``k_g`` and coupled to the next sector's disk mass (node D',
the right cyclic boundary, angle ``2 pi / N``) by ``k_c``, and a blade mass ``m_b`` (node B,
radius ``r_b``, angle ``pi / N``) on a spring ``k_b`` to its disk mass. Every spring acts
alike in every in-plane direction (``k I``, 2D). The blade tip touches a rigid casing: a
friction contact of normal ``e_r`` (radial) pressed by a constant radial force ``N0``, and
the blade is excited by a tangential force ``F cos(w t)`` (the travelling wave of an engine
order). The coupling ``k_c`` sets how the blades share their vibration: with ``k_c << k_b``
the blades are nearly independent (every family of nodal diameters at the blade frequency,
the condition in which mistuning amplifies most).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.limits import check_loss_factor
from fretwear.model.core import ContactInterface, Load, Model, ObservedPoint
from fretwear.model.cyclic import CyclicSector, cyclic_sector_from_dofs
from fretwear.validate import number, reals, whole


def lumped_blisk(n_sectors: int = 12, *, coupling: float = 5e4, blade_stiffness: float = 1e6,
                 ground_stiffness: float = 1e7, masses=(0.5, 0.1), loss_factor: float = 0.005,
                 mu: float = 0.3, preload: float = 200.0, force: float = 20.0) -> CyclicSector:
    """The lumped blisk sector of the module docstring: ``coupling`` ``k_c``,
    ``blade_stiffness`` ``k_b``, ``ground_stiffness`` ``k_g`` [N/m], ``masses`` ``(m_d, m_b)``
    [kg], hysteretic ``loss_factor`` (``D = eta K``), friction coefficient ``mu`` of the tip,
    its radial ``preload`` ``N0`` [N] and the tangential excitation amplitude ``force`` [N].
    DOFs: ``(Dx, Dy, D'x, D'y, Bx, By)``; observed point ``"blade"`` (B); radii 0.2 m and
    0.3 m. With the defaults the blades vibrate near 503 Hz (``sqrt(k_b / m_b) / 2 pi``)."""
    n = whole(n_sectors, "n_sectors", low=2, high=10**6)
    for name, value in (("coupling", coupling), ("blade_stiffness", blade_stiffness),
                        ("ground_stiffness", ground_stiffness), ("force", force)):
        number(value, name, low=0.0, open_low=name.endswith("_stiffness"), high=1e20)
    number(preload, "preload", low=0.0, high=1e20)
    number(mu, "mu", low=0.0, high=10.0)
    check_loss_factor(loss_factor)
    if len(reals(masses, "masses", low=0.0, open_low=True, ndim=1)) != 2:
        raise InputError(f"masses = {masses!r}; expected two masses (m_d, m_b) > 0 [kg]")
    a = 2 * np.pi / n
    r_d, r_b = 0.2, 0.3
    pts = np.array([[r_d, 0.0], [r_d * np.cos(a), r_d * np.sin(a)],
                    [r_b * np.cos(a / 2), r_b * np.sin(a / 2)]])
    K = np.zeros((6, 6))
    I2 = np.eye(2)

    def spring(p, q, k):
        i, j = slice(2 * p, 2 * p + 2), slice(2 * q, 2 * q + 2)
        K[i, i] += k * I2
        K[j, j] += k * I2
        K[i, j] -= k * I2
        K[j, i] -= k * I2

    K[0:2, 0:2] += ground_stiffness * I2
    spring(0, 1, coupling)
    spring(0, 2, blade_stiffness)
    m_d, m_b = masses
    M = sp.diags([m_d, m_d, 0.0, 0.0, m_b, m_b]).tocsr()
    e_r = pts[2] / np.linalg.norm(pts[2])
    e_t = np.array([-e_r[1], e_r[0]])
    contact = ContactInterface(dofs=np.array([[4, 5]]), frame=np.array([[e_r, e_t]]),
                               gap=np.zeros(1), area=np.ones(1), mu=mu, coords=pts[2:3],
                               name="tip")
    press, excite = np.zeros(6), np.zeros(6)
    press[4:6] = preload * e_r
    excite[4:6] = force * e_t
    Ks = sp.csr_matrix(K)
    model = Model(K=Ks, M=M, D=(loss_factor * Ks).tocsr(), contact=contact,
                  loads=[Load(press, "constant", name="preload"),
                         Load(excite, "cos", name="excitation")],
                  observed=[ObservedPoint("blade", np.array([4, 5]), pts[2])], dim=2,
                  name=f"lumped blisk of {n} sectors")
    return cyclic_sector_from_dofs(model, n, (np.array([[0, 1]]), pts[0:1]),
                                   (np.array([[2, 3]]), pts[1:2]),
                                   node_dofs=np.arange(6).reshape(3, 2))
