"""Tests of the quasi-static incremental wear solver (fretwear.timedomain.quasistatic) in 3D
with many contact nodes.

Compared with: the quasi-static DLFT wear rate (eq. 29 on the converged harmonic balance of
the same model, :mod:`fretwear.wear`), a different method (frequency domain, truncated to a few
harmonics) for the same cyclic load; and Archard's law with Coulomb slip (worn volume per
cycle = k_w / mu x friction energy per cycle), which holds exactly for the load steps; and
a closed form for one 3D node under a rotating tangential load. The 2D flat punch is in
test_integrate.py.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from helpers.pads import MU_PAD, dlft_friction_energy, pad_3d

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.reduce import condense
from fretwear.model.core import ContactInterface, Load, Model
from fretwear.timedomain.options import IncrementalWearOptions
from fretwear.timedomain.quasistatic import incremental_wear
from fretwear.wear import SlowProblem, wear_coefficients

KW = 1e-14  # [1/Pa]: the gap opens by ~3e-15 m per cycle, far below the slips (~1e-8 m)


def dlft_wear_rate(model, H):
    """Worn volume per cycle [m^3] and friction energy per cycle [J] of the quasi-static DLFT
    solution with H harmonics (16 samples per harmonic)."""
    basis = FourierBasis.up_to(H, 16 * H)
    sol = solve_periodic(model, basis, quasi_static=True, options=SolveOptions(tol=1e-11))
    assert sol.success, sol.message
    coef = wear_coefficients(model)
    sp = SlowProblem(model, condense(model, 1.0, basis.orders, quasi_static=True), basis, coef,
                     eps=sol.eps, anchor=sol.anchor)
    sp.set_state(np.zeros(len(coef)), sol.anchor)
    g = sp.rate(sol.U.reshape(sp.m, sp.H))
    return float(model.contact.area @ g), dlft_friction_energy(sol)


@pytest.mark.parametrize("steps", [8, 64])
def test_3d_node_under_a_rotating_load_slides_on_the_discrete_circle(steps):
    """One 3D node pressed by N, held tangentially by an isotropic spring k, under a rotating
    tangential force F0 (cos tau, sin tau) > mu N: it slides on a circle. With N_s load steps
    per cycle the slip of each step is a chord of the circle and the friction force lies along
    it (the incremental law); equilibrium at step k+1 in axes turned with the load gives, with
    s = pi / N_s and the lag phi of the position behind the load,
    ``sin phi = mu N cos s / F0``, ``k X = F0 cos(s + phi) / cos s`` (``X ->
    sqrt(F0^2 - mu^2 N^2) / k`` as s -> 0). Per cycle: slip ``2 N_s X sin s``, friction
    energy mu N times it, wear ``k_w N / area`` times it: exact for the load steps, so
    round-off (1e-12) from the seventh cycle on (the start from rest dies out geometrically:
    2.7e-11 in the fourth cycle with 8 steps)."""
    k, n0, f0, mu, kw, area = 1e6, 100.0, 50.0, 0.3, 1e-12, 1e-4
    c = ContactInterface(dofs=np.array([[0, 1, 2]]), frame=np.eye(3)[None], gap=np.zeros(1),
                         area=np.full(1, area), mu=mu, coords=np.zeros((1, 3)),
                         wear_coefficient=kw)
    model = Model(K=sp.csr_matrix(np.diag([0.0, k, k])), M=sp.csr_matrix((3, 3)), contact=c,
                  loads=[Load(np.array([n0, 0.0, 0.0]), "constant"),
                         Load(np.array([0.0, f0, 0.0]), "cos"),
                         Load(np.array([0.0, 0.0, f0]), "sin")], dim=3)
    res = incremental_wear(model, n_cycles=10,
                           options=IncrementalWearOptions(steps_per_cycle=steps))
    assert res.success, res.message
    s = np.pi / steps
    phi = np.arcsin(mu * n0 * np.cos(s) / f0)
    X = f0 * np.cos(s + phi) / np.cos(s) / k
    slip = 2 * steps * X * np.sin(s)
    np.testing.assert_allclose(res.slip[6:, 0], slip, rtol=1e-12)
    np.testing.assert_allclose(res.dissipation[6:], mu * n0 * slip, rtol=1e-12)
    np.testing.assert_allclose(np.diff(res.wear[:, 0])[5:], kw * n0 * slip / area, rtol=1e-12)


def test_3d_pad_wear_per_cycle_agrees_with_the_dlft():
    """The 16-node pad (4 x 4 nodes, 10 MPa, cyclic traction 0.8 mu P at 30 deg: partial slip)
    worn by load steps: every contact solve settles (the active-set iteration this replaced
    failed on every step), and the worn volume of the third cycle (the first includes the
    loading) agrees with the quasi-static DLFT wear rate.

    Tolerance: the sum of the two methods' discretisation errors, each estimated by halving
    its resolution: ``|DLFT(16) - DLFT(8)|`` (measured 3.0 %) and ``|N = 256 - N = 128 steps|``
    (0.25 %); measured gap 0.7 %. The solver starts unloaded and the DLFT from the static
    preload: the stuck nodes lock in slightly different states, which settles over a few
    cycles (the worn volume per cycle changes by 0.4 % from the third to the fourth)."""
    model = pad_3d(k_w=KW)
    v = {}
    for N in (128, 256):
        res = incremental_wear(model, options=IncrementalWearOptions(steps_per_cycle=N), n_cycles=3)
        assert res.success, res.message
        v[N] = np.diff(res.worn_volume)[-1]
        # Archard with Coulomb slip: worn volume = k_w / mu x friction energy, per cycle
        np.testing.assert_allclose(np.diff(res.worn_volume), KW / MU_PAD * res.dissipation[1:],
                                   rtol=1e-9)
        last = np.diff(res.wear, axis=0)[-1]  # partial slip: some nodes stick all cycle
        assert np.all(last >= 0) and 0 < np.count_nonzero(last) < last.size
    (v8, _), (v16, e16) = dlft_wear_rate(model, 8), dlft_wear_rate(model, 16)
    assert v16 > 0
    assert v16 == pytest.approx(KW / MU_PAD * e16, rel=1e-6)  # the same identity in the DLFT
    assert abs(v[256] - v16) <= abs(v16 - v8) + abs(v[256] - v[128])


def test_3d_pad_sliding_bodily_wears_every_node():
    """Traction 1.5 mu P: the pad slides back and forth on its springs (gross slip); every load
    step settles and every node wears; the worn volume per cycle repeats from the second
    cycle on to 1e-9 (the slides are the same each cycle: the springs centre them) and equals
    k_w / mu x the friction energy. The friction energy per cycle is that of a rigid block
    on a spring ``k = 1e7 N/m`` with friction force ``F = mu P A`` under ``Q0 cos``,
    ``4 F (Q0 - F) / k``, to 3 % (the pad's elasticity and its pressure peaks at the edges
    make the slip start at different instants over the face; measured 1.6 %)."""
    model = pad_3d(ratio=1.5, k_w=KW)
    res = incremental_wear(model, options=IncrementalWearOptions(steps_per_cycle=64), n_cycles=3)
    assert res.success, res.message
    dv = np.diff(res.worn_volume)
    assert dv[1] == pytest.approx(dv[0], rel=1e-9)
    assert np.all(np.diff(res.wear, axis=0) > 0)
    np.testing.assert_allclose(dv, KW / MU_PAD * res.dissipation[1:], rtol=1e-9)
    F = MU_PAD * 10e6 * 1e-4
    Q0 = 1.5 * F
    assert res.dissipation[-1] == pytest.approx(4 * F * (Q0 - F) / 1e7, rel=0.03)


def test_a_run_of_more_load_steps_than_a_day_is_refused_at_once():
    """n_cycles = 10^9 without a cycle jump: 10^9 computed cycles of 16 load steps, refused in
    one line before the condensation (the survey found it building its list of jumps for
    minutes, then running for days). The jumps of a run that fits are those of the loop
    they replace (1, then J, the last shortened), written out here for 7 and 23 cycles."""
    from fretwear.errors import InputError
    from fretwear.timedomain.quasistatic import _cycle_jumps

    opts = IncrementalWearOptions(steps_per_cycle=16)
    with pytest.raises(InputError, match=r"1,000,000,000 computed cycles of 16 load steps "
                                         r"\(n_cycles = 1,000,000,000, cycle_jump = 1\)"):
        incremental_wear(None, n_cycles=10**9, options=opts)
    assert _cycle_jumps(7, 3).tolist() == [1, 3, 3]
    assert _cycle_jumps(23, 5).tolist() == [1, 5, 5, 5, 5, 2]
    assert _cycle_jumps(1, 4).tolist() == [1]
