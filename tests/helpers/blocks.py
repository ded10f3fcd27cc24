"""Small 2D and 3D blocks on a rigid flat whose periodic response has separation, stick and
slip during the period: the cases on which the large-interface paths (fretwear.hb.krylov) are
compared with the dense ones."""

import numpy as np

from fretwear.model import (
    ContactSpec,
    Damping,
    Material,
    Spring,
    Traction,
    box,
    from_mesh,
    rectangle,
)

P0, MU = 1e6, 0.5  # Pa, -


def block(dim, loss_factor=0.0):
    """A steel block on a rigid flat, pressed by P0, under a cyclic tangential traction (mu P0
    in 3D, 0.5 mu P0 in 2D) and a cyclic normal traction growing along x to 1.3 P0 (in
    quadrature), so that the edge at large x lifts off during part of the period while the
    other edge sticks. ``loss_factor``: hysteretic damping (complex ``Z_r`` blocks; without
    it they are real)."""
    a = 0.01
    if dim == 2:
        mesh, top, bottom = rectangle(a, 0.004, 6, 2), "top", "bottom"
        cyc, lift = (0.5 * MU * P0, 0.0), (lambda x: np.column_stack([0 * x[:, 0],
                                                                      1.3 * P0 * x[:, 0] / a]))
        springs = [Spring(top, "x", 1e7)]
    else:
        mesh, top, bottom = box(a, a, 0.005, 4, 4, 1), "zmax", "zmin"
        cyc = (MU * P0, 0.0, 0.0)
        lift = (lambda x: np.column_stack([0 * x[:, 0], 0 * x[:, 0], 1.3 * P0 * x[:, 0] / a]))
        springs = [Spring(top, "x", 1e7), Spring(top, "y", 1e7)]
    damping = Damping(loss_factor=loss_factor) if loss_factor else None
    return from_mesh(mesh, Material(210e9, 0.3, 7800.0), supports=springs, damping=damping,
                     loads=[Traction(top, pressure=P0),
                            Traction(top, traction=cyc, waveform="cos"),
                            Traction(top, traction=lift, waveform="sin")],
                     contact=ContactSpec(bottom, mu=MU))


CLOSED_L, CLOSED_H = 0.02, 0.01  # [m]


def closed_block(mu=0.0, q=1e5):
    """Steel block 20 x 10 mm (6 x 2 Q4) pressed by 1 MPa on a rigid flat, held in x by a spring,
    driven by a cosine pressure ``q`` [Pa] on its right face (0.1 MPa: stays closed)."""
    L, H = CLOSED_L, CLOSED_H
    return from_mesh(rectangle(L, H, nx=6, ny=2), Material(210e9, 0.3, 7800.0), thickness=0.01,
                     damping=Damping(rayleigh_stiffness=5e-6),
                     supports=[Spring(at=(0.0, H / 2), direction="x", stiffness=1e7)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("right", pressure=q, waveform="cos")],
                     contact=ContactSpec("bottom", mu=mu),
                     observed={"Pe": (L, H / 2)})
