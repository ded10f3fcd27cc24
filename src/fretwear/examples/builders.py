"""Python builders of the paper's models (the same models as the shipped case files).

:func:`paper_beam` is the beam of Salles et al. (2011), section 4.2; :func:`stromberg_beam` the
beam of section 4.1 (Stromberg 1997). Every modelling choice the paper leaves open is the one
documented in the corresponding case file (``fretwear example show NAME``).
"""

from __future__ import annotations

from fretwear.model.build import ContactSpec, Damping, Material, Spring, Traction, from_mesh
from fretwear.model.core import Model
from fretwear.model.mesh import rectangle


def paper_beam(nx: int = 30, ny: int = 4, *, mu: float = 0.3, loss_factor: float = 1e-3,
               spring: float = 1e4, P: float = 1e4, Q: float = 1e4,
               wear_coefficient: float = 1e-11) -> Model:
    """Section 4.2 beam: L = 100 mm, h = 10 mm, width 10 mm, steel, loss factor 0.001,
    x-spring 1e4 N/m at the bottom-left node, P = 0.01 MPa static on the top face, Q = 0.01 MPa
    sinusoidal on the end face x = L, bottom face on a rigid flat (mu = 0.3, k_w = 1e-11 1/Pa),
    observed point P_e = (L, h/2). As ``examples/beam-linear-frf.toml``."""
    L, h, w = 0.1, 0.01, 0.01
    mesh = rectangle(L, h, nx, ny)
    return from_mesh(
        mesh,
        Material(210e9, 0.3, 7800.0),
        thickness=w,
        damping=Damping(loss_factor=loss_factor),
        supports=[Spring("bottom_left", "x", spring)],
        loads=[Traction("top", pressure=P, waveform="constant", name="P"),
               Traction("right", pressure=Q, waveform="sin", name="Q")],
        contact=ContactSpec("bottom", mu=mu, normal=(0.0, -1.0), gap=0.0,
                            wear_coefficient=wear_coefficient),
        observed={"Pe": (L, h / 2)},
        name="salles2011-beam",
    )


def stromberg_beam(nx: int = 30, ny: int = 4, *, waveform: str = "sin", P: float = 50e6,
                   Q: float = 20e6) -> Model:
    """Section 4.1 beam (Stromberg 1997): L = 50 mm, h = 5 mm, width l = 5 mm, E = 210 GPa,
    nu = 0.3, mu = 0.2, k_w = 1e-11 1/Pa, bottom face on a rigid flat with zero gap,
    quasi-static. The paper's "P = 50 MN/m" and "Q = 20 MN/m" are read as distributed loads
    of Stromberg's plane model of unit thickness, i.e. tractions: ``P`` [Pa] uniform on the
    top face, ``Q`` [Pa] on the end face x = L with the time evolution ``waveform`` ("sin":
    the paper's sinusoidal approximation; "triangle": Stromberg's linear evolution). Then
    ``Q h / (mu P L) = 0.2``: partial slip (fretting). The infinitely stiff x-spring holds
    the top-left node (0, h): the bottom-left node is a contact node, which cannot be held.
    Every choice is argued in ``examples/stromberg1997.toml`` and docs/examples.md."""
    L, h, w = 0.05, 0.005, 0.005
    mesh = rectangle(L, h, nx, ny)
    return from_mesh(
        mesh,
        Material(210e9, 0.3, 7800.0),
        thickness=w,
        supports=[Spring((0.0, h), "x", float("inf"))],
        loads=[Traction("top", pressure=P, waveform="constant", name="P"),
               Traction("right", pressure=Q, waveform=waveform, name="Q")],
        contact=ContactSpec("bottom", mu=0.2, normal=(0.0, -1.0), gap=0.0,
                            wear_coefficient=1e-11),
        observed={"Pe": (L, h / 2)},
        name="stromberg1997-beam",
    )
