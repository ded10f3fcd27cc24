"""The partial-slip block of the wear tests (tests/wear/): a 10 x 2 steel block on a rigid
flat, quasi-static, 3 harmonics, with the Archard coefficient of the paper."""

from __future__ import annotations

from fretwear.hb.fourier import FourierBasis
from fretwear.model.build import ContactSpec, Material, Spring, Traction, from_mesh
from fretwear.model.mesh import rectangle

KW = 1e-11  # Archard coefficient [1/Pa] (paper section 4)
MU = 0.3
BASIS = FourierBasis.up_to(3, 32)


def block(q_ratio=0.5, wear_coefficient=KW):
    """A steel block 20 x 4 mm (10 x 2 Q4) on a rigid flat, held in x by a spring at the
    bottom-left corner, pressed by 1 MPa on top, with a sinusoidal pressure on its right face
    worth ``q_ratio`` of the friction capacity: partial slip next to the loaded end; Archard's
    ``wear_coefficient`` [1/Pa] on the contact."""
    q = q_ratio * 1e6 * MU * 0.02 / 0.004
    return from_mesh(rectangle(0.02, 0.004, 10, 2), Material(210e9, 0.3, 7800), thickness=0.01,
                     supports=[Spring("bottom_left", "x", 1e5)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("right", pressure=q, waveform="sin")],
                     contact=ContactSpec("bottom", mu=MU, normal=(0, -1),
                                             wear_coefficient=wear_coefficient),
                     observed={"Pe": (0.02, 0.002)})
