"""A mass on a friction plane held by a weak spring: the balance's slow direction
(the interface's mean tangential position, :mod:`fretwear.hb.slow_mode`)."""

import numpy as np

from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

MS = 1e-3  # mass of the contact node [kg]


def weakly_held(kw, force=2.0, kt=10.0, mu=0.5, normal=1.0):
    """A mass (1 kg, 0.02 N s/m) forced by ``force cos(w t)`` and held by a weak spring ``kw``
    to the ground, on a light slider (1 g) through a stiff spring ``kt``; the slider is pressed
    by ``normal`` on a rigid plane with friction ``mu`` (20 % of critical damping on the
    slider's own modes). Forced by 2 N against a friction limit of 0.5 N at 1.1 rad/s, the
    slider slips during 90 % of the period: no node sticks all period, and only ``kw`` holds
    the mean position of the mass and slider."""
    kz = 10.0
    cs, cz = 2 * 0.2 * np.sqrt(kt * MS), 2 * 0.2 * np.sqrt(kz * MS)
    K = np.array([[kw + kt, -kt, 0], [-kt, kt, 0], [0, 0, kz]])
    C = np.array([[0.02 + cs, -cs, 0], [-cs, cs, 0], [0, 0, cz]])
    return from_matrices(K, np.diag([1.0, MS, MS]),
                         contact=ContactDofs(normal_dofs=[2], tangential_dofs=[1], gap=0.0, mu=mu),
                         damping=Damping(C=C),
                         loads=[Load(np.array([force, 0, 0]), "cos"),
                                Load(np.array([0, 0, normal]), "constant")],
                         observed={"x": 0})
