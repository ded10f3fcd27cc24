"""The nonlinear FRF (fretwear.hb.sweep): its grid, and a sweep in the linear limit.

References independent of the code under test: ``numpy.geomspace``/``numpy.linspace`` for the
frequency grid; for the sweep, the linear FRF of :mod:`fretwear.linear` (a sparse complex solve
of the constrained full model): a frictionless interface held closed by its preload is the
linear structure whose contact nodes are held normally and free tangentially ("sliding"),
so every point of the DLFT sweep equals that FRF. Tolerance 1e-8 relative: the balance's
residual test is 1e-10 relative to |Z U| and the kept harmonics are exact for a linear response.
"""

import numpy as np

from fretwear.hb.contact import SEPARATION
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.sweep import frequency_grid, sweep
from fretwear.linear import frf
from fretwear.model import ContactSpec, Damping, Material, Spring, Traction, from_mesh, rectangle

L, H = 0.02, 0.01  # [m]
BASIS = FourierBasis.up_to(3, 32)


def closed_block(mu=0.0, q=1e5):
    """Steel block 20 x 10 mm (6 x 2 Q4) pressed by 1 MPa on a rigid flat, held in x by a spring,
    driven by a cosine pressure ``q`` [Pa] on its right face (0.1 MPa: stays closed)."""
    return from_mesh(rectangle(L, H, nx=6, ny=2), Material(210e9, 0.3, 7800.0), thickness=0.01,
                     damping=Damping(rayleigh_stiffness=5e-6),
                     springs=[Spring(at=(0.0, H / 2), direction="x", stiffness=1e7)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("right", pressure=q, waveform="cos")],
                     contact=ContactSpec("bottom", mu=mu),
                     observed={"Pe": (L, H / 2)})


def test_frequency_grid_is_geomspace_or_linspace():
    np.testing.assert_allclose(frequency_grid(1e3, 2e4, 7), np.geomspace(1e3, 2e4, 7),
                               rtol=1e-15)
    np.testing.assert_allclose(frequency_grid(1e3, 2e4, 7, "linear"), np.linspace(1e3, 2e4, 7),
                               rtol=1e-15)


def test_frictionless_closed_sweep_is_the_linear_frf():
    model = closed_block()
    res = sweep(model, BASIS, 1e3, 3e3, 3, tol=1e-10)
    assert res.success, res.message
    assert res.point_success.tolist() == [True] * 3
    f = res.frequency_hz
    np.testing.assert_allclose(f, np.geomspace(1e3, 3e3, 3), rtol=1e-12)
    ref = frf(model, f, interface="sliding").observed["Pe"][:, 0]  # (n,) complex, x
    got = []
    for p in res.points:
        assert not np.any(p.solution.state == SEPARATION)  # closed: the reference applies
        got.append(BASIS.to_complex(p.solution.observed["Pe"])[1][0])
    np.testing.assert_allclose(got, ref, rtol=1e-8, atol=1e-8 * np.abs(ref).max())
    np.testing.assert_allclose(res.amplitude("Pe", 0), np.abs(ref), rtol=1e-8)


def test_failed_points_say_so():
    """Slip (a tangential load above the friction capacity), one iteration per point and no
    continuation: points fail, each with its reason."""
    res = sweep(closed_block(mu=0.3, q=2e6), BASIS, 1e3, 3e3, 2, max_iter=1, continuation=False,
                max_bisections=0)
    assert not res.point_success.all()
    assert res.success is False or not res.success
    assert isinstance(res.message, str) and res.message
    for p, ok in zip(res.points, res.point_success, strict=True):
        assert p.success == ok and isinstance(p.message, str) and p.message
