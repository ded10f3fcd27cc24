"""One sector under an engine-order excitation against the whole disk.

Reference: the disk of N turned copies of the sector (fretwear.model.cyclic.whole_disk,
scipy sparse, real), under the travelling wave's loads, solved as an ordinary model; its
sector-0 DOFs (turned back) are compared with the sector's. Tolerances: 1e-8 relative, the
issue's figure; the two sides are exact (direct solves, or the DLFT balance converged to a
relative residual of 1e-13 on both), so they agree to rounding times the conditioning.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse.linalg as spla
from helpers.cyclic import sector_model

from fretwear.errors import InputError
from fretwear.hb.cyclic import cyclic_condenser, cyclic_frf, cyclic_modes
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.reduce import condense, exact_condenser, recover
from fretwear.model.cyclic import sector_maps, whole_disk

N = 8


@pytest.fixture(scope="module")
def sector():
    return sector_model(N)[0]


def test_cyclic_modes_are_the_disk_eigenvalues(sector):
    """The frequencies of every harmonic index together are the disk's lowest eigenvalues
    (dense generalized eigenproblem of the disk's free DOFs), to 1e-8 relative; each mode
    shape satisfies the disk's eigen-equation on sector 0."""
    per_k = [cyclic_modes(sector, k, 4)[0] for k in range(N)]
    union = np.sort(np.concatenate(per_k))
    below = min(f[-1] for f in per_k)  # every disk mode below this is in the union
    union = union[union <= below]
    disk = whole_disk(sector)
    free = disk.free_dofs()
    K, M = disk.K.toarray()[np.ix_(free, free)], disk.M.toarray()[np.ix_(free, free)]
    w2 = sla.eigh(K, M, eigvals_only=True, subset_by_index=[0, union.size - 1])
    f_disk = np.sqrt(w2) / (2 * np.pi)
    assert union.size >= 2 * N
    assert np.max(np.abs(union - f_disk) / f_disk) < 1e-8


def test_cyclic_mode_shapes_are_disk_modes(sector):
    """A mode of index k spread over the disk as the wave ``e^{i k j alpha}`` solves the
    disk's eigen-equation (residual 1e-8 of ``|K U|``)."""
    A, nd = sector_maps(sector)
    disk = whole_disk(sector)
    keep = sector.kept_dofs()
    for k in (0, 3, 4):
        f, X = cyclic_modes(sector, k, 2)
        for fi, x in zip(f, X, strict=True):
            U = sum(Aj[:, keep] @ (np.exp(1j * k * j * sector.angle) * x[keep])
                    for j, Aj in enumerate(A))
            free = disk.free_dofs()
            r = (disk.K @ U - (2 * np.pi * fi) ** 2 * (disk.M @ U))[free]
            assert np.linalg.norm(r) < 1e-8 * np.linalg.norm((disk.K @ U)[free])


def disk_frf(sector, eo, frequencies):
    """The disk's linear response (contact free) at sector 0's DOFs (its own axes)."""
    disk = whole_disk(sector, eo)
    A, _ = sector_maps(sector)
    free = disk.free_dofs()
    F = disk.load_harmonics(1)[1][free]
    out = []
    for f in frequencies:
        w = 2 * np.pi * f
        Z = disk.K - w * w * disk.M
        if disk.D is not None:
            Z = Z + 1j * disk.D
        if disk.C is not None:
            Z = Z + 1j * w * disk.C
        Z = Z.tocsc()[free][:, free]
        U = np.zeros(disk.ndof, dtype=complex)
        U[free] = spla.spsolve(Z, F)
        out.append(A[0].T @ U)
    return np.array(out)


@pytest.mark.parametrize("eo", [0, 1, 3, 4, 5, 11, -3])
def test_engine_order_frf_equals_the_disk(sector, eo):
    """Linear FRF of the sector (index EO mod N) = the disk's under the travelling wave, on
    sector 0's DOFs, to 1e-8 relative, across the resonances of the index."""
    freqs = [3000.0, 9825.0, 12416.0, 20000.0]
    U_s = cyclic_frf(sector, eo, freqs)
    U_d = disk_frf(sector, eo, freqs)
    assert np.max(np.abs(U_s - U_d)) < 1e-8 * np.max(np.abs(U_d))


def test_condensed_sector_equals_the_condensed_disk(sector):
    """The sector's Z_r, F_r per harmonic (index n EO mod N) equal the disk's condensation on
    sector 0's contact nodes, up to the other sectors' contact DOFs: checked through the
    response, ``Z_r^-1 F_r`` recovered on the sector equals the disk's recovery (contact
    held by its own stiffness only: a linear check of the condenser's parts)."""
    eo, f = 3, 7000.0
    cond = cyclic_condenser(sector, eo)
    orders = [0, 1, 2, 3]
    red = condense(sector.model, f, orders, condenser=cond)
    disk = whole_disk(sector, eo)
    red_d = condense(disk, f, orders, condenser=exact_condenser(disk))
    m = red.m
    A, _ = sector_maps(sector)
    for b in range(len(orders)):
        u = np.linalg.solve(red.Z[b], red.F[b])  # contact force 0: free response
        u_d = np.linalg.solve(red_d.Z[b], red_d.F[b])
        assert np.allclose(u, u_d[:m], rtol=0, atol=1e-8 * np.abs(u_d).max())
        Us = recover(sector.model, f, [orders[b]], u[None], condenser=cond)[0]
        Ud = A[0].T @ recover(disk, f, [orders[b]], u_d[None])[0]
        assert np.allclose(Us, Ud, rtol=0, atol=1e-8 * np.abs(Ud).max())
        assert np.allclose(red.obs_A[b] @ u + red.obs_b[b], Us[red.obs_dofs], rtol=0,
                           atol=1e-8 * np.abs(Ud).max())


TIGHT = SolveOptions(tol=1e-13, max_iter=200)


@pytest.mark.parametrize("eo", [3, 4])
def test_periodic_solve_equals_the_disk(sector, eo):
    """One DLFT periodic solve with friction at the tip (partial slip) on the sector equals
    the whole disk's (every sector with the same contact, the same eps, harmonics 1-3 in
    indices 3, 6, 1 for EO 3; 4, 0, 4 for EO 4): sector 0's contact harmonics and forces to
    1e-8 relative."""
    basis = FourierBasis((1, 2, 3), 32)
    f, eps = 9000.0, 3e9
    sol = solve_periodic(sector.model, basis, frequency=f, eps=eps, options=TIGHT,
                         condenser=cyclic_condenser(sector, eo))
    disk = whole_disk(sector, eo)
    sol_d = solve_periodic(disk, basis, frequency=f, eps=eps, options=TIGHT)
    assert sol.success and sol_d.success
    nc = sector.model.contact.n_nodes
    # partial slip (a node sticks and slips within the period): not a linear answer, and
    # harmonics 2 and 3 are excited through the friction law alone
    assert any(np.unique(s).size > 1 for s in sol.state)
    assert np.abs(sol.U[:, :, [2, 3, 5, 6]]).max() > 1e-3 * np.abs(sol.U[:, :, 1:]).max()
    scale = np.abs(sol_d.U[:nc]).max()
    assert np.max(np.abs(sol.U - sol_d.U[:nc])) < 1e-8 * scale
    assert np.max(np.abs(sol.lam - sol_d.lam[:nc])) < 1e-8 * np.abs(sol_d.lam[:nc]).max()
    assert np.max(np.abs(sol.observed["tip"] - sol_d.observed["tip"])) < \
        1e-8 * np.abs(sol_d.observed["tip"]).max()


def test_bad_engine_order_and_index(sector):
    with pytest.raises(InputError, match="engine_order"):
        cyclic_condenser(sector, 2.5)
    with pytest.raises(InputError, match="harmonic index"):
        cyclic_modes(sector, N)


def test_condenser_refuses_another_model(sector):
    other = sector_model(N)[1]
    with pytest.raises(InputError, match="another sector"):
        cyclic_condenser(sector, 1).check(other)


def test_real_blocks_of_a_complex_hermitian_block():
    """The balance's real cos/sin operator of a complex non-symmetric (Hermitian, k != 0,
    N/2) block is the complex product itself: ``to_real_blocks(Z) x = real(Z U)`` for random
    ``Z``, ``U`` (reference: complex arithmetic; rounding only)."""
    from fretwear.hb.reduce import loads_to_real, to_real_blocks

    rng = np.random.default_rng(1)
    m, nb = 4, 3
    Z = rng.normal(size=(nb, m, m)) + 1j * rng.normal(size=(nb, m, m))
    Z = Z + Z.conj().transpose(0, 2, 1)  # Hermitian, complex off the diagonal
    Z[0] = Z[0].real  # harmonic 0 lives in index 0: real
    U = rng.normal(size=(nb, m)) + 1j * rng.normal(size=(nb, m))
    U[0] = U[0].real
    x = loads_to_real(U).reshape(-1)  # DOF-major [a0, a.., b..] per DOF
    want = loads_to_real(np.einsum("bij,bj->bi", Z, U)).reshape(-1)
    assert np.allclose(to_real_blocks(Z, np.arange(nb)) @ x, want, rtol=0, atol=1e-12)


def test_short_sweep_equals_the_disk(sector):
    """A 4-point nonlinear sweep across the index-3 resonance (12.3 kHz) on the sector and on
    the disk, same eps: every point's contact harmonics to 1e-8 relative."""
    from fretwear.hb.options import SweepOptions
    from fretwear.hb.sweep import sweep

    eo = 3
    basis = FourierBasis((1, 2, 3), 32)
    opts = SweepOptions(solve=SolveOptions(tol=1e-13, max_iter=200), eps=3e9,
                        spacing="linear")
    res = sweep(sector.model, basis, 11500.0, 13000.0, 4, options=opts,
                condenser=cyclic_condenser(sector, eo))
    res_d = sweep(whole_disk(sector, eo), basis, 11500.0, 13000.0, 4, options=opts)
    assert res.success and res_d.success
    nc = sector.model.contact.n_nodes
    for p, p_d in zip(res.points, res_d.points, strict=True):
        U, U_d = p.solution.U, p_d.solution.U[:nc]
        assert np.max(np.abs(U - U_d)) < 1e-8 * np.abs(U_d).max()


@pytest.mark.parametrize("eo", [3, 4, 0])
def test_inter_blade_contact_equals_the_disk(eo):
    """Friction between neighbouring sectors (sector j's face A against sector j+1's face B,
    interference 0.2 um) and at the tip: one periodic solve on the sector (the partner's
    harmonic n phased by ``e^{+i n EO 2 pi / N}``) equals the disk's, in which A of every
    sector is paired with B of the next, to 1e-8 relative; the inter-blade nodes separate,
    stick and slip within the period. (With the phase's sign flipped the difference is 0.6.)"""
    sector, model = sector_model(N, slit=True)
    basis = FourierBasis((1, 2, 3), 32)
    f, eps = 9000.0, 3e9
    sol = solve_periodic(model, basis, frequency=f, eps=eps, options=TIGHT,
                         condenser=cyclic_condenser(sector, eo))
    sol_d = solve_periodic(whole_disk(sector, eo), basis, frequency=f, eps=eps, options=TIGHT)
    assert sol.success and sol_d.success
    nc = model.contact.n_nodes
    between = model.contact.interface_index() == 1
    # the inter-blade nodes change state within the period (EO 3 and 0: they separate,
    # stick and slip; EO 4: separate and stick)
    assert np.unique(sol.state[between]).size == (2 if eo == 4 else 3)
    assert np.max(np.abs(sol.U - sol_d.U[:nc])) < 1e-8 * np.abs(sol_d.U[:nc]).max()
    assert np.max(np.abs(sol.lam - sol_d.lam[:nc])) < 1e-8 * np.abs(sol_d.lam[:nc]).max()


def test_krylov_operator_path_takes_the_complex_hermitian_blocks():
    """The large-interface path (Jacobian as an operator, ``jacobian="krylov"``) on the
    sector with its inter-blade contact (Z_r complex and non-symmetric for EO 3) gives the
    dense path's disk answer to 1e-8 relative."""
    sector, model = sector_model(N, slit=True)
    basis = FourierBasis((1, 2, 3), 32)
    opts = SolveOptions(tol=1e-13, max_iter=200, jacobian="krylov")
    sol = solve_periodic(model, basis, frequency=9000.0, eps=3e9, options=opts,
                         condenser=cyclic_condenser(sector, 3))
    sol_d = solve_periodic(whole_disk(sector, 3), basis, frequency=9000.0, eps=3e9,
                           options=TIGHT)
    assert sol.success and sol_d.success
    nc = model.contact.n_nodes
    assert np.max(np.abs(sol.U - sol_d.U[:nc])) < 1e-8 * np.abs(sol_d.U[:nc]).max()


def test_wear_steps_equal_the_disk():
    """Three explicit wear steps of 1e6 cycles (Archard at the tip and between neighbours, both
    surfaces of the pair wearing) on the sector and on the disk: sector 0's wear depths to
    1e-8 relative, and every sector of the disk wears as sector 0 (the tuned assumption)."""
    from fretwear.wear.options import WearOptions
    from fretwear.wear.simulate import BalanceSetup, simulate_wear

    sector, model = sector_model(N, slit=True, wear=1e-14)
    basis = FourierBasis((1, 2, 3), 32)
    opts = WearOptions(scheme="explicit", adaptive=False, initial_jump=1e6, max_steps=3,
                       max_cycles=1e9, solve=SolveOptions(tol=1e-13, max_iter=100,
                                                          strategy=("start",)))
    r = simulate_wear(model, basis, frequency=9000.0, options=opts,
                      balance=BalanceSetup(eps=3e9, condenser=cyclic_condenser(sector, 3)))
    r_d = simulate_wear(whole_disk(sector, 3), basis, frequency=9000.0, options=opts,
                        balance=BalanceSetup(eps=3e9))
    assert r.success and r_d.success and r.history.cycles[-1] == 3e6
    nc = model.contact.n_nodes
    W, W_d = r.history.wear_depth, r_d.history.wear_depth.reshape(-1, N, nc)
    assert W[-1].max() > 1e-7  # it wears
    assert np.max(np.abs(W[:, None, :] - W_d)) < 1e-8 * W.max()


def test_3d_sector_periodic_solve_and_frf_equal_the_disk():
    """A coarse 3D sector (N = 6, axis z): the engine-order FRF (EO 1, 3 = N/2) and one
    periodic solve (EO 1 and 3, every tip node separating or slipping twice per period) equal
    the disk's to 1e-8 relative. 36 samples per period: a multiple of N, so that sector j's
    time shift ``EO j T / N`` is a whole number of samples and the disk's sampled law sees
    every sector's motion at the same instants (with 32 samples the disk differs from the
    travelling wave by its time-sampling error: 9e-4 at EO 1, 5e-5 with 128 samples)."""
    from helpers.cyclic import sector_model_3d

    sector, model = sector_model_3d(6)
    for eo in (1, 3):
        freqs = [2500.0, 4000.0]
        U_d = disk_frf(sector, eo, freqs)
        assert np.max(np.abs(cyclic_frf(sector, eo, freqs) - U_d)) < 1e-8 * np.abs(U_d).max()
    basis = FourierBasis((1, 2, 3), 36)
    nc = model.contact.n_nodes
    for eo in (1, 3):
        sol = solve_periodic(model, basis, frequency=2500.0, eps=1e9, options=TIGHT,
                             condenser=cyclic_condenser(sector, eo))
        sol_d = solve_periodic(whole_disk(sector, eo), basis, frequency=2500.0, eps=1e9,
                               options=TIGHT)
        assert sol.success and sol_d.success
        assert np.max(np.abs(sol.U - sol_d.U[:nc])) < 1e-8 * np.abs(sol_d.U[:nc]).max()
        assert np.max(np.abs(sol.observed["load"] - sol_d.observed["load"])) < \
            1e-8 * np.abs(sol_d.observed["load"]).max()


def test_static_condensation_of_load_vectors_is_refused(sector):
    """condense_static would apply the sector's load vectors to harmonic index 0's DOFs: a
    one-line InputError instead of a wrong answer; the drivers drop the time-domain fallback
    (it would integrate the sector without its cyclic boundaries)."""
    from fretwear.hb.reduce import condense_static

    cond = cyclic_condenser(sector, 1)
    assert cond.models_in_time is False
    with pytest.raises(InputError, match="not available on a sector"):
        condense_static(sector.model, condenser=cond).loads(np.zeros(sector.model.ndof))


def test_hill_dynamics_of_a_sector_are_refused(sector):
    """Hill's method and nonlinear modes build Z(lambda) from the condenser's own (index 0)
    matrices, which is not the sector's at k != 0: refused in one line."""
    from fretwear.hb.dynamics import structure_dynamics

    with pytest.raises(InputError, match="not available on one sector"):
        structure_dynamics(sector.model, cyclic_condenser(sector, 1))


def test_3d_cyclic_modes_are_the_disk_eigenvalues():
    """The coarse 3D sector (N = 6, hexahedra, axis z): the lowest modes of every harmonic
    index together are the lowest eigenvalues of the disk assembled from 6 turned copies
    (dense generalized eigenproblem of its free DOFs, contact free), to 1e-8 relative: the
    check of the 2D sector's modes on a 3D one, where the turn mixes x and y."""
    from helpers.cyclic import sector_model_3d

    sector, _ = sector_model_3d(6)
    per_k = [cyclic_modes(sector, k, 3)[0] for k in range(6)]
    union = np.sort(np.concatenate(per_k))
    union = union[union <= min(f[-1] for f in per_k)]
    disk = whole_disk(sector)
    free = disk.free_dofs()
    K, M = disk.K.toarray()[np.ix_(free, free)], disk.M.toarray()[np.ix_(free, free)]
    w2 = sla.eigh(K, M, eigvals_only=True, subset_by_index=[0, union.size - 1])
    f_disk = np.sqrt(w2) / (2 * np.pi)
    assert union.size >= 6
    assert np.max(np.abs(union - f_disk) / f_disk) < 1e-8


def test_3d_short_sweep_and_wear_steps_equal_the_disk():
    """The coarse 3D sector (N = 6, EO 1, tip friction against a casing, every tip node
    separating or slipping): a 3-point sweep and two explicit wear steps of 1e6 cycles on
    the sector equal those of the disk of 6 turned copies (fretwear.model.cyclic.whole_disk),
    contact harmonics and wear depths of sector 0 to 1e-8 relative, and every sector of the
    disk wears as sector 0 (the tuned assumption). One harmonic, 12 samples (a multiple of
    N: the disk's sampled law sees every sector at the same instants, as in
    test_3d_sector_periodic_solve_and_frf_equal_the_disk): the two exact balances agree to
    their tolerance 1e-13."""
    import dataclasses

    from helpers.cyclic import sector_model_3d

    from fretwear.hb.options import SweepOptions
    from fretwear.hb.sweep import sweep
    from fretwear.wear.options import WearOptions
    from fretwear.wear.simulate import BalanceSetup, simulate_wear

    sector, model = sector_model_3d(6)
    model = dataclasses.replace(model, contact=dataclasses.replace(model.contact,
                                                                   wear_coefficient=1e-13))
    sector = dataclasses.replace(sector, model=model)
    basis = FourierBasis((1,), 12)
    nc = model.contact.n_nodes
    opts = SweepOptions(solve=SolveOptions(tol=1e-13, max_iter=200), eps=1e9,
                        spacing="linear")
    res = sweep(model, basis, 2300.0, 2700.0, 3, options=opts,
                condenser=cyclic_condenser(sector, 1))
    res_d = sweep(whole_disk(sector, 1), basis, 2300.0, 2700.0, 3, options=opts)
    assert res.success and res_d.success and len(res.points) == len(res_d.points)
    for p, p_d in zip(res.points, res_d.points, strict=True):
        U, U_d = p.solution.U, p_d.solution.U[:nc]
        assert np.max(np.abs(U - U_d)) < 1e-8 * np.abs(U_d).max()
    wopts = WearOptions(scheme="explicit", adaptive=False, initial_jump=1e6, max_steps=2,
                        max_cycles=1e9, solve=SolveOptions(tol=1e-13, max_iter=100,
                                                           strategy=("start",)))
    r = simulate_wear(model, basis, frequency=2500.0, options=wopts,
                      balance=BalanceSetup(eps=1e9, condenser=cyclic_condenser(sector, 1)))
    r_d = simulate_wear(whole_disk(sector, 1), basis, frequency=2500.0, options=wopts,
                        balance=BalanceSetup(eps=1e9))
    assert r.success and r_d.success and r.history.cycles[-1] == 2e6
    W, W_d = r.history.wear_depth, r_d.history.wear_depth.reshape(-1, 6, nc)
    assert W[-1].max() > 1e-9  # it wears
    assert np.max(np.abs(W[:, None, :] - W_d)) < 1e-8 * W.max()


def test_cyclic_modes_of_a_massless_sector_are_refused(sector):
    """material.rho = 0 (the survey's case file: a LinAlgError from the generalized
    eigensolver): one InputError saying modes need a mass, for every harmonic index."""
    import dataclasses

    massless = dataclasses.replace(sector, model=dataclasses.replace(
        sector.model, M=0.0 * sector.model.M))
    for k in (0, 1):
        with pytest.raises(InputError, match="the sector has no mass"):
            cyclic_modes(massless, k, 2)
