"""The small 3D block shared by the tests of the blocked modal condensation and of its
operators (tests/hb/test_modal_blocked.py, test_operator_blocks.py, test_modal_operator.py)."""

import numpy as np

from fretwear.model import ContactSpec, Material, Spring, Traction, box, from_mesh

F_MAX = 20e3  # Hz (as test_modal.py)
ORDERS = np.arange(8)


def block(damping=None, traction=3e5):
    """test_modal.py's 10 x 10 x 5 mm steel block on a rigid flat, optionally damped."""
    return from_mesh(box(0.01, 0.01, 0.005, 4, 4, 2), Material(210e9, 0.3, 7800.0),
                     damping=damping,
                     supports=[Spring("zmax", "x", 1e7), Spring("zmax", "y", 1e7)],
                     loads=[Traction("zmax", pressure=1e6),
                            Traction("zmax", traction=(traction, 0.5 * traction, 0.0),
                                     waveform="cos")],
                     contact=ContactSpec("zmin", mu=0.5),
                     observed={"corner": (0.01, 0.01, 0.005)})


def rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max()
