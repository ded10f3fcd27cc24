"""A two-mass model whose frictional FRF folds (three periodic states between 0.68 and 0.76
rad/s): the first mass strikes a rigid wall inclined at 30 degrees through a light contact node
that slides along it. Why it folds, and its stability on each branch:
tests/timedomain/test_folded_friction.py; its sweep passing the fold by the arclength alone:
tests/hb/test_attempts.py."""

import numpy as np

from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

MS = 1e-3  # mass of the contact node [kg]


def inclined(kn=10.0, kt=10.0, angle=30.0, mu=0.3, gap=0.5, force=0.1):
    """DOFs: the two masses (1 kg), the node's normal and tangential displacements; the node's
    springs ``kn (n - x1 cos a)`` and ``kt (t - x1 sin a)`` (20 % of critical damping on its
    own modes), the masses' springs with 0.03 K damping."""
    c, s = np.cos(np.radians(angle)), np.sin(np.radians(angle))
    Ks = np.array([[1, -1, 0, 0], [-1, 2, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0.0]])
    bn, bt = np.array([-c, 0, 1, 0]), np.array([-s, 0, 0, 1])
    K = Ks + kn * np.outer(bn, bn) + kt * np.outer(bt, bt)
    cn, ct = 2 * 0.2 * np.sqrt(kn * MS), 2 * 0.2 * np.sqrt(kt * MS)
    C = 0.03 * Ks + cn * np.outer(bn, bn) + ct * np.outer(bt, bt)
    return from_matrices(K, np.diag([1.0, 1.0, MS, MS]),
                         contact=ContactDofs(normal_dofs=[2], tangential_dofs=[3], gap=gap, mu=mu),
                         damping=Damping(C=C), loads=[Load(np.array([0, force, 0, 0]), "cos")],
                         observed={"x1": 0, "x2": 1})
