"""The nonlinear FRF (fretwear.hb.sweep): its grid, and a sweep in the linear limit.

References independent of the code under test: ``numpy.geomspace``/``numpy.linspace`` for the
frequency grid; for the sweep, the linear FRF of :mod:`fretwear.linear` (a sparse complex solve
of the constrained full model): a frictionless interface held closed by its preload is the
linear structure whose contact nodes are held normally and free tangentially ("sliding"),
so every point of the DLFT sweep equals that FRF. Tolerance 1e-8 relative: the balance's
residual test is 1e-10 relative to |Z U| and the kept harmonics are exact for a linear response.
"""

import numpy as np
from helpers.blocks import closed_block

from fretwear.hb.contact import SEPARATION
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SWEEP_POINT, SweepOptions
from fretwear.hb.sweep import frequency_grid, sweep
from fretwear.linear import frf

BASIS = FourierBasis.up_to(3, 32)


def test_frequency_grid_is_geomspace_or_linspace():
    np.testing.assert_allclose(frequency_grid(1e3, 2e4, 7), np.geomspace(1e3, 2e4, 7),
                               rtol=1e-15)
    np.testing.assert_allclose(frequency_grid(1e3, 2e4, 7, "linear"), np.linspace(1e3, 2e4, 7),
                               rtol=1e-15)


def test_frictionless_closed_sweep_is_the_linear_frf():
    model = closed_block()
    res = sweep(model, BASIS, 1e3, 3e3, 3,
                options=SweepOptions(solve=SWEEP_POINT.replace(tol=1e-10)))
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
    res = sweep(closed_block(mu=0.3, q=2e6), BASIS, 1e3, 3e3, 2,
                options=SweepOptions(solve=SWEEP_POINT.replace(max_iter=1), continuation=False,
                                     max_bisections=0))
    assert not res.point_success.all()
    assert res.success is False or not res.success
    assert isinstance(res.message, str) and res.message
    for p, ok in zip(res.points, res.point_success, strict=True):
        assert p.success == ok and isinstance(p.message, str) and p.message


def test_point_passed_by_eps_continuation_keeps_the_sweep_eps_and_its_attempts():
    """The issue's two-DOF chain at 15 harmonics with eps = 1 N/m: the grid solve fails at
    the first point (no neighbour to retry from), the eps continuation converges; the point
    says so (``how``), keeps every attempt in order, and its answer is at the sweep's eps (no
    eps jump). Independent check: the residual of a fresh problem at eps = 1 at the point's
    harmonics is below the tolerance."""
    from fretwear.hb.problem import DLFTProblem
    from fretwear.hb.reduce import condense
    from fretwear.model.build import Damping
    from fretwear.model.core import Load
    from fretwear.model.matrices import ContactDofs, from_matrices

    model = from_matrices(np.array([[2.0, -1.0], [-1.0, 1.0]]), np.eye(2),
                          contact=ContactDofs(normal_dofs=None, tangential_dofs=[1], mu=0.5,
                                              normal_load=1.0),
                          damping=Damping(C=0.02 * np.eye(2)),
                          loads=[Load(np.array([0.2, 0.0]), "cos")], observed={"x": 0})
    basis = FourierBasis.up_to(15, 128)
    f = 1.4905405 / (2 * np.pi)
    res = sweep(model, basis, f, 1.01 * f, 2, options=SweepOptions(eps=1.0, time_domain=None))
    p = res.points[0]
    assert p.success and p.how == "eps-continuation"
    assert [a.method for a in p.attempts][0] == "grid" and not p.attempts[0].success
    assert p.attempts[-1].method == "eps-continuation" and p.attempts[-1].success
    assert p.solution.eps == 1.0 and p.solution.attempts is p.attempts
    assert all(q.solution.eps == 1.0 for q in res.points if q.success)
    red = condense(model, p.frequency_hz, basis.orders)
    prob = DLFTProblem(red, model.contact, basis, eps=1.0, anchor=p.solution.anchor)
    U = p.solution.U.reshape(prob.m, prob.H)
    fres, _ = prob.residual(U, jacobian=False)
    assert np.linalg.norm(fres) <= 1e-8 * prob.scale(U)


def test_point_times_hold_every_attempt_and_add_up_within_the_sweep():
    """``SweepPoint.seconds`` is the lap of the sweep's clock from the start of the point's
    ladder to its recording (``Branch.lap``): it encloses each of the point's attempts, timed
    inside it (their sum is a lower bound), and the laps of all the points, which do not
    overlap, add up to at most the sweep's own wall time (its set-up before the first point is
    outside them). Converged points and failed ones (recorded in ``_grid_point``) alike."""
    for model, solve, ok in ((closed_block(), SWEEP_POINT, True),
                             (closed_block(mu=0.3, q=2e6), SWEEP_POINT.replace(max_iter=1),
                              False)):
        res = sweep(model, BASIS, 1e3, 3e3, 3,
                    options=SweepOptions(solve=solve, continuation=False, max_bisections=0))
        assert res.point_success.all() == ok
        for p in res.points:
            assert p.seconds >= sum(a.wall_time for a in p.attempts) > 0.0
            assert p.cpu_seconds > 0.0
        assert sum(p.seconds for p in res.points) <= res.wall_time
