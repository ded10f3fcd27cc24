"""The beam of Salles et al. (2011), section 4.2, built from its mesh: the model of the tests of
fretwear.model.build and fretwear.model.supports."""

from fretwear.model.build import ContactSpec, Damping, Material, Spring, Traction, from_mesh
from fretwear.model.mesh import rectangle

STEEL = Material(210e9, 0.3, 7800.0)
L, H, W = 0.1, 0.01, 0.01  # paper's beam, section 4.2 [m]


def paper_beam(**kw):
    """The beam of section 4.2: 30 Q4 along x (2 through the height, so that P_e = (L, h/2)
    is a node), contact on the bottom, spring 1e4 N/m along x at (0, h/2), P = 0.01 MPa on
    top, Q = 0.01 MPa on the end face x = L."""
    args = dict(
        thickness=W,
        damping=Damping(loss_factor=1e-3),
        supports=[Spring((0.0, H / 2), "x", 1e4)],
        loads=[Traction("top", pressure=1e4, name="P"),
               Traction("right", pressure=1e4, waveform="sin", name="Q")],
        contact=ContactSpec("bottom", mu=0.3, wear_coefficient=1e-11),
        observed={"Pe": (L, H / 2)},
        name="beam",
    )
    args.update(kw)
    return from_mesh(rectangle(L, H, 30, 2), STEEL, **args)
