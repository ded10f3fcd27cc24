"""Frictionless contact (mu = 0): unilateral contact with no tangential force.

References, independent of the DLFT:
- a preloaded interface that stays closed and has no friction is a linear structure whose
  contact nodes are held normally and free tangentially: its response is the "sliding"
  linear FRF (fretwear.linear, a sparse complex solve of the constrained full model);
- no friction force means no friction energy, so the energy wear law gives no wear.
"""

import numpy as np
import pytest

from fretwear.hb.contact import SEPARATION
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.linear import frf
from fretwear.model import ContactSpec, Damping, Material, Spring, Traction, from_mesh, rectangle

L, H, W = 0.02, 0.01, 0.01  # m
P, F_HZ = 1e6, 1500.0  # Pa, Hz


def block(mu):
    """Steel block 20 x 10 mm (6 x 2 Q4, plane strain) pressed on a rigid flat by 1 MPa, held
    in x by a 1e7 N/m spring and driven by a cosine pressure on its right face (0.1 MPa: the
    preload keeps every node closed)."""
    return from_mesh(
        rectangle(L, H, nx=6, ny=2), Material(210e9, 0.3, 7800.0), thickness=W,
        damping=Damping(rayleigh_stiffness=5e-6),
        supports=[Spring(at=(0.0, H / 2), direction="x", stiffness=1e7)],
        loads=[Traction("top", pressure=P),
               Traction("right", pressure=0.1 * P, waveform="cos")],
        contact=ContactSpec("bottom", mu=mu, wear_coefficient=1e-14),
        observed={"Pe": (L, H / 2)})


@pytest.mark.parametrize("mu", [0.0, 1e-300])
def test_frictionless_response_is_the_sliding_linear_frf(mu):
    """The DLFT with mu = 0 (and a mu so small that mu P underflows against every force)
    equals the sliding FRF at the observed point. Tolerance 1e-8 relative: the solver's
    residual test is 1e-10 relative to |Z U|, and the 3 harmonics kept are exact for a
    linear response (only the first is loaded)."""
    model = block(mu)
    sol = solve_periodic(model, FourierBasis.up_to(3, 32), frequency=F_HZ,
                         options=SolveOptions(tol=1e-10))
    assert sol.success, sol.message
    assert not np.any(sol.state == SEPARATION)  # closed all period: the reference applies
    np.testing.assert_allclose(sol.lam[:, 1:, :], 0.0, atol=1e-12 * np.abs(sol.lam).max())
    ref = frf(model, [F_HZ], interface="sliding").observed["Pe"][0]  # (d,) complex
    b = sol.basis
    u1 = b.to_complex(sol.observed["Pe"])[1]  # first harmonic, complex, (d,)
    np.testing.assert_allclose(u1, ref, rtol=1e-8, atol=1e-8 * np.abs(ref).max())


def test_frictionless_contact_does_no_friction_work_and_no_energy_wear():
    """No tangential force: the friction energy per cycle is zero up to the rounding of the
    balance (1e-10 of the largest work a unit friction coefficient could do, max lam_N times
    the tangential excursion: the residual test is 1e-10 relative), and the energy law's
    factor c_p = k_e mu / area is exactly zero, so wear runs with it wear nothing."""
    from fretwear.wear import wear_coefficients

    model = block(0.0)
    sol = solve_periodic(model, FourierBasis.up_to(3, 32), frequency=F_HZ,
                         options=SolveOptions(tol=1e-10))
    assert sol.success, sol.message
    scale = np.abs(sol.lam_t[:, 0]).max() * np.ptp(sol.x_t[:, 1], axis=-1).max()
    assert scale > 0
    assert np.abs(sol.friction_energy()).max() <= 1e-10 * scale
    assert np.all(wear_coefficients(model, "energy", 1e-6) == 0.0)
