"""A 3D contact pad (hexahedra pressed on a rigid flat) shared by the tests of the time-domain
solvers in 3D with many contact nodes."""

import numpy as np

from fretwear.model.build import ContactSpec, Damping, Material, Spring, Traction, from_mesh
from fretwear.model.mesh import box

MU_PAD = 0.3
P_PAD = 10e6  # contact pressure [Pa]
F_PAD = 1e3  # forcing frequency [Hz] (far below the pad's first resonance, ~30 kHz)


def pad_3d(n=3, ratio=0.8, angle_deg=30.0, k_w=0.0):
    """Steel pad 10 x 10 x 5 mm (n x n x 1 hexahedra: (n+1)^2 contact nodes) on a rigid flat
    (face zmin), pressed by P = 10 MPa on top and loaded on top by a uniform traction
    ``ratio`` mu P cos(omega t) at ``angle_deg`` from x in the contact plane; springs on the top
    face along x and y (1e7 N/m each) hold it. Rayleigh stiffness damping (2 % at 100 kHz):
    the same viscous damping in the time domain and in the harmonic balance (a loss factor
    would become an equivalent viscous damping at the forcing frequency only in time)."""
    q = ratio * MU_PAD * P_PAD
    t = np.radians(angle_deg)
    return from_mesh(
        box(0.01, 0.01, 0.005, n, n, 1), Material(210e9, 0.3, 7800.0),
        damping=Damping(rayleigh_stiffness=0.02 / (2 * np.pi * 1e5)),
        supports=[Spring("zmax", "x", 1e7), Spring("zmax", "y", 1e7)],
        loads=[Traction("zmax", pressure=P_PAD),
               Traction("zmax", traction=(q * np.cos(t), q * np.sin(t), 0.0), waveform="cos")],
        contact=ContactSpec("zmin", mu=MU_PAD, wear_coefficient=k_w),
        observed={"top": (0.005, 0.005, 0.005)})


def dlft_friction_energy(sol):
    """Friction energy per cycle of a DLFT solution [J]: the work of the tangential forces on
    the slip increments of its time grid, ``sum_k lam_T(t_k) . (x_T(t_k) - x_T(t_k-1))``."""
    lt, xt = sol.lam_t[:, 1:, :], sol.x_t[:, 1:, :]
    return float(np.sum(lt * (xt - np.roll(xt, 1, axis=2))))
