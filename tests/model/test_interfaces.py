"""Several interfaces and node-to-node pairs (fretwear.model.interfaces and its users).

References independent of the code under test:

* a two-body model whose second body is very stiff and held is the node-to-rigid model of
  the first body, up to the compliance of the second (relative size ~ stiffness ratio);
* a body cut along a plane and rejoined by a stuck node-to-node interface is the uncut body
  (same mesh with the cut nodes merged), to rounding;
* rotating a whole model rigidly changes no contact force, wear or frequency response
  (objectivity), to rounding;
* two bodies that do not touch each other, each on its own rigid obstacle, solved as one
  model with two interfaces give each body's own solution;
* the DLFT Jacobian of pairs against central finite differences in every contact state;
* Archard's law on both surfaces: worn volume per cycle = sum over the sides of
  k_w(side) / mu x friction energy per cycle (Coulomb slip: lambda_T . dx = mu lambda_N |dx|).
"""

import dataclasses
import math

import numpy as np
import pytest
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense, recover
from fretwear.linear import frf, modes
from fretwear.model import (
    ContactDofs,
    ContactSpec,
    Damping,
    Material,
    Spring,
    Traction,
    combine,
    from_matrices,
    from_mesh,
    join,
    rectangle,
    transformed,
)
from fretwear.model.core import ContactInterface, Load, Model
from fretwear.model.interfaces import pair_transform
from fretwear.timedomain.options import InitialState, IntegrationOptions
from fretwear.wear.laws import side_depths, wear_coefficients, worn_volume

STEEL = Material(210e9, 0.3, 7800.0)
MU = 0.3
P0, Q0 = 20e6, 1e7  # preload pressure and tangential traction amplitude [Pa]
F_HZ = 2000.0
BASIS = FourierBasis.up_to(3, 32)


def block_loads(prefix="", scale=1.0):
    return [Traction(f"{prefix}top", pressure=scale * P0, waveform="constant"),
            Traction(f"{prefix}right", traction=(-scale * Q0, 0.0), waveform="cos")]


def rotation(theta):
    return np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])


def block_on_base(E_base=210e9, theta=0.0, kw=(1e-13, 0.0), block=STEEL, scale=1.0):
    """A 20 x 10 mm block (4 x 2 Q4) on a 20 x 5 mm base (4 x 1 Q4) held at its bottom,
    node-to-node on the block's bottom, the whole model rotated by ``theta``; the block held
    tangentially by a spring at its top left corner."""
    R = rotation(theta)
    upper = transformed(rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005)), R)
    base = transformed(rectangle(0.02, 0.005, 4, 1), R)
    mesh = join(("block", upper), ("base", base))
    return from_mesh(
        mesh, {"block": block, "base": Material(E_base, 0.3, 7800.0)},
        damping=Damping(loss_factor=0.02),
        supports=[Spring("block.top_left", tuple(R[:, 0]), scale * 1e7), ("base.bottom", "all")],
        loads=[Traction("block.top", pressure=scale * P0, waveform="constant"),
               Traction("block.right", traction=tuple(-scale * Q0 * R[:, 0]), waveform="cos")],
        contact=ContactSpec("block.bottom", mu=MU, partner="base.top", wear_coefficient=kw[0],
                            partner_wear_coefficient=kw[1], name="flat"),
        observed={"tip": tuple(R @ [0.02, 0.015])},
    )


def block_on_rigid(block=STEEL, scale=1.0):
    """The block of :func:`block_on_base` alone on a rigid flat."""
    return from_mesh(
        rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005)), block,
        damping=Damping(loss_factor=0.02), supports=[Spring("top_left", "x", scale * 1e7)],
        loads=block_loads(scale=scale), contact=ContactSpec("bottom", mu=MU),
        observed={"tip": (0.02, 0.015)},
    )


def test_stiff_held_body_is_a_rigid_obstacle():
    """Base 1e6 times stiffer than the block: the pair's contact forces and the block's
    motion are those of the block on a rigid flat. The base's compliance changes the
    interface displacements by about E_block / E_base = 1e-6 of the block's, so the contact
    forces move by the same relative amount: measured 0.197 x the ratio at ratios 1e-4,
    1e-5 and 1e-6 (linear in the ratio); tolerance 2 x the ratio."""
    ratio = 1e-6
    # a soft block (E = 1e7 Pa, density scaled to keep the steel block's frequencies) and
    # loads and spring scaled with E, so that the base's modulus 1e13 Pa stays in range
    scale = 1e7 / STEEL.E
    soft = Material(1e7, 0.3, 7800.0 * scale)
    stiff = block_on_base(E_base=1e7 / ratio, block=soft, scale=scale)
    rigid = block_on_rigid(block=soft, scale=scale)
    assert stiff.contact.has_pairs and not rigid.contact.has_pairs
    np.testing.assert_array_equal(stiff.contact.coords, rigid.contact.coords)
    np.testing.assert_array_equal(stiff.contact.frame, rigid.contact.frame)
    a = solve_periodic(stiff, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                       raise_on_failure=True)
    b = solve_periodic(rigid, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                       raise_on_failure=True)
    assert np.any(b.state == 2) and np.any(b.state == 1)  # stick-slip: the law is at work
    scale = np.abs(b.lam).max()
    np.testing.assert_allclose(a.lam, b.lam, rtol=0, atol=2 * ratio * scale)
    np.testing.assert_allclose(a.observed["tip"], b.observed["tip"], rtol=0,
                               atol=2 * ratio * np.abs(b.observed["tip"]).max())


def test_pair_forces_are_equal_and_opposite():
    """The full field recovered from a pair solution balances: the internal forces
    ``Z_n U_n - F_n`` of every harmonic are zero except at the pair nodes, where they are
    ``-frame^T lambda`` on node a and ``+frame^T lambda`` on node b (equal and opposite;
    Newton's third law, independent of the change of variables). Tolerance: rounding of
    K U at 1e-9 of the largest nodal force."""
    model = block_on_base()
    sol = solve_periodic(model, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                         raise_on_failure=True)
    orders = np.array([0, *BASIS.harmonics])
    c = model.contact
    nc, d = c.dofs.shape
    Uc = BASIS.to_complex(sol.U.reshape(nc * d, -1))
    Ufull = recover(model, F_HZ, orders, Uc)
    lam = BASIS.to_complex(sol.lam.reshape(nc * d, -1)).reshape(orders.size, nc, d)
    F = model.load_harmonics(int(orders.max()))
    free = model.free_dofs()
    w = 2 * np.pi * F_HZ
    for b, n in enumerate(orders):
        Z = model.K + (0 if n == 0 else 1j * model.D - (n * w) ** 2 * model.M)
        r = Z @ Ufull[b] - F[n]
        expected = np.zeros(model.ndof, dtype=complex)
        glob = np.einsum("pkd,pk->pd", c.frame, lam[b])
        np.add.at(expected, c.dofs.ravel(), -glob.ravel())
        np.add.at(expected, c.partner_dofs.ravel(), glob.ravel())
        tol = 1e-9 * np.abs(F).max()
        np.testing.assert_allclose(r[free], expected[free], rtol=0, atol=tol)


def cut_beam(cut: bool, preload=0.0):
    """A 100 x 10 mm cantilever (10 x 2 Q4) clamped on its left face with a harmonic tip
    load; cut lengthwise along y = 5 mm into two halves rejoined node-to-node (``cut``, like
    the plates of a lap joint: the lower half clamped on its left face, the upper one at its
    top left corner, its other left node glued to the lower half's), or in one piece (with a
    contact far away that never closes: a 1 m gap)."""
    obs = {"tip": (0.1, 0.01)}
    if not cut:
        mesh = rectangle(0.1, 0.01, 10, 2)
        mesh.boundaries["far"] = mesh.boundaries["bottom"][5:6]
        return from_mesh(mesh, STEEL, damping=Damping(loss_factor=0.01),
                         supports=[("left", "all")],
                         loads=[Traction("right", traction=(0.0, 1e5), waveform="cos")],
                         observed=obs,
                         contact=ContactSpec("far", mu=MU, normal=(0.0, -1.0), gap=1.0))
    mesh = join(("lower", rectangle(0.1, 0.005, 10, 1)),
                ("upper", rectangle(0.1, 0.005, 10, 1, origin=(0.0, 0.005))))
    return from_mesh(mesh, STEEL, damping=Damping(loss_factor=0.01),
                     supports=[("lower.left", "all"), ("upper.top_left", "all")],
                     loads=[Traction("lower.right", traction=(0.0, 1e5), waveform="cos"),
                            Traction("upper.right", traction=(0.0, 1e5), waveform="cos"),
                            Traction("upper.top", pressure=preload, waveform="constant"),
                            Traction("lower.bottom", pressure=preload, waveform="constant")],
                     observed=obs,
                     contact=ContactSpec("upper.bottom", mu=100.0, partner="lower.top"))


@pytest.mark.parametrize("method", ["direct", "condensed"])
def test_cut_body_rejoined_stuck_is_the_uncut_body(method):
    """Linear FRF of the cut beam with its pairs stuck = FRF of the uncut beam (free
    interface far away), to rounding (1e-9 relative: the same linear system written in other
    coordinates, conditioning ~1e4)."""
    f = np.array([300.0, 800.0, 2500.0])
    cut = frf(cut_beam(True), f, interface="stuck", method=method)
    whole = frf(cut_beam(False), f, interface="free")
    ref = whole.observed["tip"]
    np.testing.assert_allclose(cut.observed["tip"], ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def test_cut_body_rejoined_stuck_has_the_modes_of_the_uncut_body():
    """Modes of the cut beam with its pairs stuck = modes of the uncut beam, to rounding
    (1e-10 relative: the same eigenproblem in other coordinates; measured 3e-13)."""
    a = modes(cut_beam(True), 6, interface="stuck")
    b = modes(cut_beam(False), 6, interface="free")
    np.testing.assert_allclose(a.frequency_hz, b.frequency_hz, rtol=1e-10)


def test_sliding_pairs_are_the_normal_gap_tied_by_a_stiff_spring():
    """Modes and FRF of the cut beam with its pairs sliding (relative normal displacement
    held, tangential free, exact elimination) against the same two halves with nothing but a
    stiff spring k = 1e16 N/m on the relative normal displacement of every pair (a penalty,
    no contact law). The penalty's error is linear in 1/k: measured 4e-3, 4e-5 at k = 1e12,
    1e14 on the FRF (1e-3, 1e-5 on the frequencies), so 4e-7 (1e-7) at 1e16; tolerances 1e-6
    and 3e-7."""
    cut = cut_beam(True)
    c = cut.contact
    normal = c.frame[:, 0, :]  # in the structure's axes
    rows = np.repeat(np.arange(c.n_nodes), 4)
    cols = np.concatenate([c.dofs, c.partner_dofs], axis=1).reshape(-1)
    vals = np.concatenate([normal, -normal], axis=1).reshape(-1)
    B = sp.csr_matrix((vals, (rows, cols)), shape=(c.n_nodes, cut.ndof))
    tied = dataclasses.replace(cut, K=(cut.K + 1e16 * (B.T @ B)).tocsr())
    f = np.array([300.0, 800.0, 2500.0])
    ua = frf(cut, f, interface="sliding").observed["tip"]
    ub = frf(tied, f, interface="free").observed["tip"]
    np.testing.assert_allclose(ua, ub, rtol=0, atol=1e-6 * np.abs(ub).max())
    ma = modes(cut, 4, interface="sliding").frequency_hz
    mb = modes(tied, 4, interface="free").frequency_hz
    np.testing.assert_allclose(ma, mb, rtol=3e-7)
    assert ma[0] < 0.7 * modes(cut, 1, interface="stuck").frequency_hz[0]  # the halves slide


def test_cut_body_with_preload_and_friction_vibrates_like_the_uncut_body():
    """The cut beam rejoined with a 200 MPa preload (pressure on both outer faces) and
    mu = 100: the interface stays closed and stuck, so the first harmonic of the tip is the
    uncut beam's linear FRF; the tolerance is the balance's convergence test (1e-12
    relative) times conditioning."""
    f = 800.0
    sol = solve_periodic(cut_beam(True, preload=200e6), BASIS, frequency=f,
                         options=SolveOptions(tol=1e-12), raise_on_failure=True)
    assert np.all(sol.state == 1)
    ref = frf(cut_beam(False), [f], interface="free").observed["tip"][0]
    k = BASIS.k
    got = sol.observed["tip"][:, 1] - 1j * sol.observed["tip"][:, 1 + k]  # U = a - i b
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-8 * np.abs(ref).max())


def test_rotated_model_gives_the_same_contact_forces_wear_and_frf():
    """The block on an elastic base, rotated by 0.7 rad: local contact forces, contact
    states, wear per cycle and the linear FRF (rotated back) are those of the unrotated
    model (objectivity; tolerance 1e-8 relative: rounding in the rotated assembly and the
    balance's 1e-12 convergence test)."""
    theta = 0.7
    a, b = block_on_base(), block_on_base(theta=theta)
    sa = solve_periodic(a, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                        raise_on_failure=True)
    sb = solve_periodic(b, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                        raise_on_failure=True)
    np.testing.assert_allclose(sb.lam, sa.lam, rtol=0, atol=1e-8 * np.abs(sa.lam).max())
    np.testing.assert_array_equal(sb.state, sa.state)
    from fretwear.wear.kernels import slip_work

    def wear(model, s):
        prob = DLFTProblem(condense(model, F_HZ, [0, *BASIS.harmonics]), model.contact, BASIS,
                           eps=s.eps, anchor=s.anchor)
        lu, lx, state, _ = prob.time_law(s.U.reshape(prob.m, -1))
        return wear_coefficients(model) * slip_work(lu, lx, state, s.eps)

    wa, wb = wear(a, sa), wear(b, sb)
    assert wa.max() > 0
    np.testing.assert_allclose(wb, wa, rtol=0, atol=1e-8 * wa.max())
    f = [1000.0, 5000.0]
    R = rotation(theta)
    for iface in ("sliding", "stuck"):
        ua = frf(a, f, interface=iface).observed["tip"]
        ub = frf(b, f, interface=iface).observed["tip"] @ R  # back to the unrotated axes
        np.testing.assert_allclose(ub, ua, rtol=0, atol=1e-8 * np.abs(ua).max())


def test_two_sided_archard_identity():
    """Both surfaces wear (k_w = 1e-13 and 3e-13 1/Pa): the worn volume per cycle of the
    two surfaces = sum over the sides of k_w(side) / mu x the friction energy per cycle
    (PeriodicSolution.friction_energy: lambda_T . dX, a different integrand from the slip
    work); each side's share is its coefficient's. Tolerance 1e-9: Coulomb's equality
    lambda_T . dx = mu lambda_N |dx| holds on the converged samples to the law's
    periodicity tolerance."""
    ka, kb = 1e-13, 3e-13
    model = block_on_base(kw=(ka, kb))
    sol = solve_periodic(model, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                         raise_on_failure=True)
    from fretwear.wear.kernels import slip_work

    prob = DLFTProblem(condense(model, F_HZ, [0, *BASIS.harmonics]), model.contact, BASIS,
                       eps=sol.eps, anchor=sol.anchor)
    lu, lx, state, _ = prob.time_law(sol.U.reshape(prob.m, -1))
    dW = wear_coefficients(model) * slip_work(lu, lx, state, sol.eps)
    Wa, Wb = side_depths(model, dW)
    energy = sol.friction_energy().sum()
    assert energy > 0
    volume = worn_volume(Wa, sol.area) + worn_volume(Wb, sol.area)
    np.testing.assert_allclose(volume, (ka + kb) / MU * energy, rtol=1e-9)
    np.testing.assert_allclose(worn_volume(Wb, sol.area), kb / MU * energy, rtol=1e-9)


def test_two_sided_energy_law_identity():
    """Energy law on both surfaces (k_e = 2e-15 and 5e-15 m^3/J): the worn volume per cycle
    of the two surfaces = sum over the sides of k_e(side) x the friction energy per cycle
    (PeriodicSolution.friction_energy: lambda_T . dX, a different integrand from the slip
    work the wear rate is computed with); each side's share is its coefficient's. A
    node-to-rigid model gives its partner side nothing. Tolerance 1e-9 as the Archard
    identity's."""
    ka, kb = 2e-15, 5e-15
    model = block_on_base()
    sol = solve_periodic(model, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                         raise_on_failure=True)
    from fretwear.wear.kernels import slip_work

    prob = DLFTProblem(condense(model, F_HZ, [0, *BASIS.harmonics]), model.contact, BASIS,
                       eps=sol.eps, anchor=sol.anchor)
    lu, lx, state, _ = prob.time_law(sol.U.reshape(prob.m, -1))
    dW = wear_coefficients(model, "energy", ka, kb) * slip_work(lu, lx, state, sol.eps)
    Wa, Wb = side_depths(model, dW, "energy", ka, kb)
    energy = sol.friction_energy().sum()
    assert energy > 0
    volume = worn_volume(Wa, sol.area) + worn_volume(Wb, sol.area)
    np.testing.assert_allclose(volume, (ka + kb) * energy, rtol=1e-9)
    np.testing.assert_allclose(worn_volume(Wb, sol.area), kb * energy, rtol=1e-9)
    rigid = block_on_rigid()
    np.testing.assert_array_equal(wear_coefficients(rigid, "energy", ka, kb),
                                  wear_coefficients(rigid, "energy", ka))
    assert not np.any(side_depths(rigid, np.ones(rigid.contact.n_nodes), "energy", ka, kb)[1])


def test_two_interfaces_on_two_separate_bodies():
    """Two blocks that do not touch each other, each on its own rigid flat with its own mu,
    as one model with two interfaces: each block's contact forces are those of the block
    solved alone (the bodies are uncoupled); tolerance 1e-8: the balance's convergence test
    on a system twice as large."""
    def block(origin):
        return rectangle(0.02, 0.01, 4, 2, origin=origin)

    mesh = join(("one", block((0.0, 0.0))), ("two", block((0.05, 0.0))))
    model = from_mesh(
        mesh, STEEL, damping=Damping(loss_factor=0.02),
        supports=[Spring("one.top_left", "x", 1e7), Spring("two.top_left", "x", 1e7)],
        loads=block_loads("one.") + block_loads("two."),
        contact=[ContactSpec("one.bottom", mu=0.3, name="soft"),
                 ContactSpec("two.bottom", mu=0.6, name="hard")],
    )
    c = model.contact
    assert c.names() == ["soft", "hard"]
    np.testing.assert_array_equal(c.interface_index(), [0] * 5 + [1] * 5)
    np.testing.assert_array_equal(c.mu_nodes(), [0.3] * 5 + [0.6] * 5)
    both = solve_periodic(model, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                          raise_on_failure=True)
    for k, mu in enumerate((0.3, 0.6)):
        alone = from_mesh(block((0.0, 0.0)), STEEL, damping=Damping(loss_factor=0.02),
                          supports=[Spring("top_left", "x", 1e7)], loads=block_loads(),
                          contact=ContactSpec("bottom", mu=mu))
        ref = solve_periodic(alone, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                             raise_on_failure=True)
        got = both.lam[c.interface_index() == k]
        np.testing.assert_allclose(got, ref.lam, rtol=0, atol=1e-8 * np.abs(ref.lam).max())


# --- the DLFT Jacobian of pairs -----------------------------------------------------------
def pair_chain(d, nc=4, seed=3):
    """Random SPD matrices; contact node p (DOFs p*d..) paired with node nc+p, random frames;
    the relative motion is loaded through node a (static + cos + sin)."""
    rng = np.random.default_rng(seed)
    nd = 2 * nc * d + 3
    A = rng.standard_normal((nd, nd))
    K = A @ A.T + nd * np.eye(nd)
    M = np.diag(rng.uniform(0.5, 1.5, nd))
    frames = np.array([np.linalg.qr(rng.standard_normal((d, d)))[0] for _ in range(nc)])
    dofs = np.arange(nc * d).reshape(nc, d)
    contact = ContactInterface(dofs=dofs, frame=frames, gap=np.zeros(nc), area=np.ones(nc),
                               mu=np.array([0.2, 0.3, 0.4, 0.5])[:nc],
                               coords=np.zeros((nc, d)), partner_dofs=dofs + nc * d)
    F = rng.standard_normal(nd)
    return Model(K=sp.csr_matrix(K), M=sp.csr_matrix(M), D=sp.csr_matrix(0.02 * K),
                 contact=contact, dim=d,
                 loads=[Load(F, "constant"), Load(0.5 * F, "cos"), Load(0.2 * F, "sin")])


@pytest.mark.parametrize("d", [2, 3])
def test_pair_jacobian_matches_finite_differences(d):
    """DLFTProblem.residual's Jacobian on a pair model vs central differences, at points
    where the nodes are in every state over the period (separation, stick, slip): lambda_u
    of each node is set to a chosen signal (normal mean and amplitude, tangential amplitude)
    by solving (eps I - Z) U = lambda_u - F + eps W. Tolerance 1e-6 eps: the central
    difference error of a step 1e-7 |U| away from the state switches."""
    model = pair_chain(d)
    basis = FourierBasis.up_to(2, 16)
    red = condense(model, 5.0, [0, *basis.harmonics])
    eps = 2.0 * red.spectral_radius()
    prob = DLFTProblem(red, model.contact, basis, eps=eps)
    # (normal mean, normal cos amplitude, tangential sin amplitude) per node [N]
    signals = [(5.0, 1.0, 0.5), (3.0, 1.0, 4.0), (0.5, 2.0, 1.0), (-4.0, 1.0, 1.0)]
    target = np.zeros((prob.nc, d, prob.H))
    for p, (mean, amp, tang) in enumerate(signals):
        target[p, 0, 0] = mean
        target[p, 0, 1] = amp
        target[p, 1:, 1 + basis.k] = tang * np.array([1.0, 0.7][: d - 1])
    Zb = prob.Z
    n = prob.m * prob.H
    rhs = (target.reshape(prob.m, -1) - prob.F + eps * prob.W).reshape(-1)
    U = np.linalg.solve(eps * np.eye(n) - Zb, rhs).reshape(prob.m, prob.H)
    _, _, state, _ = prob.time_law(U)
    assert {0, 1, 2} <= set(np.unique(state).tolist())
    f0, J = prob.residual(U)
    h = 1e-7 * np.abs(U).max()
    J_fd = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        fp, _ = prob.residual(U + e.reshape(U.shape), jacobian=False)
        fm, _ = prob.residual(U - e.reshape(U.shape), jacobian=False)
        J_fd[:, j] = (fp - fm) / (2 * h)
    np.testing.assert_allclose(J, J_fd, rtol=0, atol=1e-6 * eps)
    assert np.abs(J - eps * np.eye(n)).max() > 0.1 * eps  # the contact law is at work


def test_pair_condensation_is_the_relative_schur_complement():
    """The reduced stiffness of a pair model = R (P^T Z P)_schur R^T written here with dense
    linear algebra from the definition U_a = r + U_b (not through the package's
    relative_model), to rounding."""
    model = pair_chain(3)
    nc, d = model.contact.dofs.shape
    red = condense(model, 5.0, [0, 1])
    nd = model.ndof
    P = np.eye(nd)
    for a, b in zip(model.contact.dofs.ravel(), model.contact.partner_dofs.ravel(), strict=True):
        P[a, b] = 1.0
    np.testing.assert_array_equal(pair_transform(model.contact, nd).toarray(), P)
    w = 2 * np.pi * 5.0
    Z = (model.K + 1j * model.D - w**2 * model.M).toarray()
    Zp = P.T @ Z @ P
    c = model.contact.dofs.ravel()
    i = np.setdiff1d(np.arange(nd), c)
    S = Zp[np.ix_(c, c)] - Zp[np.ix_(c, i)] @ np.linalg.solve(Zp[np.ix_(i, i)], Zp[np.ix_(i, c)])
    R = np.zeros((nc * d, nc * d))
    for p in range(nc):
        R[p * d:(p + 1) * d, p * d:(p + 1) * d] = model.contact.frame[p]
    ref = R @ S @ R.T
    np.testing.assert_allclose(red.Z[1], ref, rtol=0, atol=1e-12 * np.abs(ref).max())


# --- bad input: one clear message ---------------------------------------------------------
def test_unmatched_pair_names_the_node_and_its_distance():
    block = rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))
    base = rectangle(0.02, 0.005, 5, 1)  # 5 elements: nodes do not match the block's 4
    mesh = join(("block", block), ("base", base))
    with pytest.raises(InputError, match=r"contact nodes have no partner on boundary "
                                         r"'base.top' within .* m: nodes \d+.* \(farthest: "
                                         r"node \d+ at \(.*\), .* m away\)"):
        from_mesh(mesh, STEEL, supports=[("base.bottom", "all")],
                  contact=ContactSpec("block.bottom", mu=MU, partner="base.top",
                                      pairing="node-to-node"))


def test_node_in_two_interfaces_is_refused():
    mesh = rectangle(0.02, 0.01, 4, 2)
    with pytest.raises(InputError, match=r"is in 2 contact places \(interfaces \['left', "
                                         r"'under'\]\); a node belongs to one interface"):
        from_mesh(mesh, STEEL, contact=[ContactSpec("bottom", mu=MU, name="under"),
                                        ContactSpec("left", mu=MU, name="left")])


def test_interfaces_need_distinct_names():
    one = ContactInterface(np.array([[0, 1]]), np.eye(2)[None], np.zeros(1), np.ones(1), 0.3,
                           np.zeros((1, 2)))
    two = ContactInterface(np.array([[2, 3]]), np.eye(2)[None], np.zeros(1), np.ones(1), 0.3,
                           np.zeros((1, 2)))
    with pytest.raises(InputError, match="two interfaces are named 'contact'"):
        combine([one, two])


def test_zero_area_node_is_refused():
    with pytest.raises(InputError, match="area"):
        from_matrices(np.eye(2), np.eye(2),
                      contact=ContactDofs(normal_dofs=[0], tangential_dofs=[1], mu=0.3, area=0.0))


def pressed_or_pulled_block(pressure):
    """The block of :func:`block_on_base` on its base under a uniform ``pressure`` on its top
    (negative: pulled away), held by springs at its top corners along x and y (1e6 N/m, so
    that a pulled block is held)."""
    upper = rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))
    mesh = join(("block", upper), ("base", rectangle(0.02, 0.005, 4, 1)))
    return from_mesh(
        mesh, STEEL, supports=[Spring("block.top_left", "x", 1e7),
                               Spring("block.top_left", "y", 1e6),
                               Spring("block.top_right", "y", 1e6), ("base.bottom", "all")],
        loads=[Traction("block.top", pressure=pressure, waveform="constant")],
        contact=ContactSpec("block.bottom", mu=MU, partner="base.top", name="flat"))


def test_interface_open_under_the_preload_is_flagged():
    """A block pulled away from its base (the static load opens the interface): the static
    contact problem finds no node in contact and the run's notes say so, naming the
    interface. Pressed instead, every node is in contact and the normal forces carry the
    part of the static load the springs do not: the equilibrium of the block along y (the
    springs' force is k times the displacement of the spring nodes), to rounding (1e-9: the
    static solve's 1e-10 convergence test)."""
    from fretwear.analyses.common import preload_notes
    from fretwear.hb.preload import _static_solve, preload_contact
    from fretwear.hb.reduce import condense_static

    pulled = pressed_or_pulled_block(-1e6)
    pre = preload_contact(pulled)
    assert pre.success and pre.closed.tolist() == [0] and pre.open_interfaces() == ["flat"]
    np.testing.assert_array_equal(pre.normal_force, 0.0)
    notes, names = preload_notes(pulled)
    assert names == ["flat"] and len(notes) == 1
    assert notes[0].startswith("warning: interface 'flat' is open at all its 5 nodes under "
                               "the static loads")

    pressed = pressed_or_pulled_block(P0)
    pre = preload_contact(pressed)
    assert pre.closed.tolist() == [5] and preload_notes(pressed) == ([], [])
    F = pressed.loads[0].vector  # the pressure on the top, as nodal forces [N]
    load_y = float(np.sum(F[1::2]))  # pushing the block down: negative
    assert load_y < 0
    # the static field, to read the springs' forces k u_y at the block's top corners
    prob, x, st = _static_solve(pressed, None, "static")
    assert st.success
    U = condense_static(pressed).recover(x, F)
    pts = pressed.mesh.points
    corners = [int(np.flatnonzero(np.all(np.isclose(pts, c), axis=1))[0])
               for c in ((0.0, 0.015), (0.02, 0.015))]
    spring_y = -1e6 * sum(U[2 * n + 1] for n in corners)  # on the block, upwards positive
    total = float(np.sum(pre.normal_force))  # on the base, downwards; the base pushes back
    assert 0 < spring_y < 1e-4 * total  # the springs hold the block's own weightless motion
    np.testing.assert_allclose(total, -load_y - spring_y, rtol=1e-9)


def test_rigid_obstacle_does_not_wear():
    with pytest.raises(InputError, match="partner_wear_coefficient .* without a partner"):
        ContactSpec("bottom", mu=MU, partner_wear_coefficient=1e-13)


def test_glued_assembly_that_is_not_held_is_named():
    """A pair of nodes attached to nothing: with the pair glued (r = 0) the partner can still
    move freely, and the condensation says so."""
    K = sp.csr_matrix(np.diag([0.0, 0.0, 0.0, 0.0, 1.0]))
    contact = ContactInterface(dofs=np.array([[0, 1]]), frame=np.eye(2)[None], gap=np.zeros(1),
                               area=np.ones(1), mu=MU, coords=np.zeros((1, 2)),
                               partner_dofs=np.array([[2, 3]]))
    model = Model(K=K, M=sp.identity(5, format="csr"), contact=contact, dim=2)
    with pytest.raises(InputError, match=r"node-to-node pairs glued\) is .*singular"):
        condense(model, 0.0, [0], quasi_static=True)


def test_explicit_pairs_from_matrices_match_the_mesh_model():
    """The block-on-base model rebuilt from its matrices with explicit pairs (DOF triplets of
    both nodes and the frames, rotated by 0.7 rad): the same reduced dynamic stiffness as
    the mesh model, to rounding (the same change of variables from other inputs)."""
    mesh_model = block_on_base(theta=0.7)
    c = mesh_model.contact
    model = from_matrices(
        mesh_model.K, mesh_model.M,
        contact=ContactDofs(normal_dofs=c.dofs[:, 0], tangential_dofs=c.dofs[:, 1], mu=MU,
                            area=c.area, partner_dofs=c.partner_dofs, frames=c.frame),
        damping=Damping(D=mesh_model.D), loads=mesh_model.loads,
        fixed_dofs=mesh_model.fixed_dofs)
    a = condense(mesh_model, F_HZ, [0, 1])
    b = condense(model, F_HZ, [0, 1])
    np.testing.assert_allclose(b.Z, a.Z, rtol=0, atol=1e-12 * np.abs(a.Z).max())
    np.testing.assert_allclose(b.F, a.F, rtol=0, atol=1e-12 * np.abs(a.F).max())
    with pytest.raises(InputError, match=r"contact_frames\[0\] is not orthonormal"):
        from_matrices(mesh_model.K, mesh_model.M,
                      contact=ContactDofs(normal_dofs=c.dofs[:, 0], tangential_dofs=c.dofs[:, 1],
                                          mu=MU, partner_dofs=c.partner_dofs, frames=2 * c.frame),
                      fixed_dofs=mesh_model.fixed_dofs)


def test_wear_of_a_pair_on_a_stiff_held_body_is_the_rigid_obstacle_wear(tmp_path):
    """A wear run (adaptive scheme, checkpoint written and resumed) on the soft block over a
    1e6 times stiffer held base = the same run on a rigid flat: wear depths and step cycles
    agree to 5 x the stiffness ratio (measured 1.3 x the ratio at ratios 1e-5 and 1e-6:
    linear in the ratio). Resuming from the checkpoint after the run gives the same final
    wear (the fingerprint takes the pair model)."""
    from fretwear.wear import RunControl, WearOptions, simulate_wear

    scale = 1e7 / STEEL.E
    soft = Material(1e7, 0.3, 7800.0 * scale)
    models = {"pair": block_on_base(E_base=1e7 / 1e-6, block=soft, scale=scale,
                                    kw=(1e-9, 3e-9)),
              "rigid": block_on_rigid(block=soft, scale=scale)}
    models["rigid"].contact.wear_coefficient = 4e-9  # the sum of both surfaces'
    opts = WearOptions(max_steps=4, tolerance=0.1)
    out = {k: simulate_wear(m, BASIS, frequency=F_HZ, options=opts,
                            run=RunControl(checkpoint=tmp_path / f"{k}.npz"))
           for k, m in models.items()}
    wa, wb = out["pair"].history.wear_depth, out["rigid"].history.wear_depth
    assert out["pair"].success and wb[-1].max() > 0
    np.testing.assert_allclose(out["pair"].history.cycles, out["rigid"].history.cycles,
                               rtol=5e-6)
    np.testing.assert_allclose(wa, wb, rtol=0, atol=5e-6 * wb[-1].max())
    again = simulate_wear(models["pair"], BASIS, frequency=F_HZ, options=opts,
                          run=RunControl(checkpoint=tmp_path / "pair.npz", resume=True))
    assert again.resumed_from >= 0
    np.testing.assert_array_equal(again.final_wear, out["pair"].final_wear)


def test_time_integration_of_a_pair_on_a_stiff_held_body_is_the_rigid_obstacle_one():
    """The time-domain reference takes pairs through the same change of variables in its
    reduced model: 10 periods of the soft block on a 1e6 times stiffer held base = the block
    on a rigid flat (contact forces and tip motion over the last period, to 20 x the
    stiffness ratio: an O(ratio) perturbation carried through stick-slip transitions). Each
    starts from its own periodic balance's state at t = 0 (the preload applied at once from
    rest is a shock the contact solve of the first step does not settle); 256 steps per
    period, because at 64 a few contact solves of either model, the rigid one included, do
    not settle."""
    from fretwear.hb.solution import initial_state
    from fretwear.timedomain.integrate import integrate

    ratio = 1e-6
    scale = 1e7 / STEEL.E
    soft = Material(1e7, 0.3, 7800.0 * scale)
    pair = block_on_base(E_base=1e7 / ratio, block=soft, scale=scale)
    rigid = block_on_rigid(block=soft, scale=scale)
    run = {}
    for key, model in (("pair", pair), ("rigid", rigid)):
        U0, V0 = initial_state(model, solve_periodic(model, BASIS, frequency=F_HZ,
                                                     options=SolveOptions(tol=1e-12)))
        run[key] = integrate(model, F_HZ, options=IntegrationOptions(steps_per_period=256),
                             start=InitialState(U0=U0, V0=V0), n_periods=10, record="last")
    a, b = run["pair"], run["rigid"]
    assert a.success and b.success and np.any(b.state == 2)
    np.testing.assert_allclose(a.lam, b.lam, rtol=0, atol=20 * ratio * np.abs(b.lam).max())
    tip_a, tip_b = a.observed["tip"], b.observed["tip"]
    np.testing.assert_allclose(tip_a, tip_b, rtol=0, atol=20 * ratio * np.abs(tip_b).max())


def test_compare_on_a_pair_on_a_stiff_held_body_is_the_rigid_obstacle_one():
    """`fretwear compare` (the DLFT periodic solution against the time-domain steady state)
    on the soft block over a 1e6 times stiffer held base gives the table of the block on a
    rigid flat: every quantity of both methods to 20 x the stiffness ratio (as the time
    integration above)."""
    from fretwear.analyses.compare import compare_periodic

    ratio = 1e-6
    scale = 1e7 / STEEL.E
    soft = Material(1e7, 0.3, 7800.0 * scale)
    table = {"frequency": F_HZ, "harmonics": 3, "n_samples": 32, "eps": "auto",
             "solver": "powell", "tol": 1e-10, "max_iter": 100}
    rows = [compare_periodic(m, table, None, steps_per_period=256, max_periods=3000)
            for m in (block_on_base(E_base=1e7 / ratio, block=soft, scale=scale),
                      block_on_rigid(block=soft, scale=scale))]
    assert all(r.classification == "periodic" and r.dlft_converged for r in rows)
    for (name, dlft, td, _), (name_r, dlft_r, td_r, _) in zip(rows[0].rows, rows[1].rows,
                                                             strict=True):
        assert name == name_r
        np.testing.assert_allclose([dlft, td], [dlft_r, td_r], rtol=20 * ratio, err_msg=name)
    assert 0 < rows[1].rows[-1][2] < 1  # stick-slip


def test_time_integration_takes_a_friction_coefficient_per_interface():
    """Two blocks of different lengths (no shared eigenfrequencies), apart, each on its own
    rigid flat with its own mu (0.3 and 0.4), integrated in time as one model with two
    interfaces: each block's contact forces and states over the last of 10 periods are those
    of the block integrated alone with its own mu (the bodies are uncoupled). Each run starts
    from its own balance's state at t = 0 (as the pair test above), all balances at one eps
    (a 3-harmonic balance depends on eps, and the default rule gives the joint model another
    one). Tolerance 1e-10 of the largest force: the contact solves settle to 1e-10 of the
    largest force of the model they solve; measured 4e-14."""
    from fretwear.hb.solution import initial_state
    from fretwear.timedomain.integrate import integrate

    sizes = {"one": (0.02, 4), "two": (0.015, 3)}

    def block(name, origin=(0.0, 0.0)):
        length, nx = sizes[name]
        return rectangle(length, 0.01, nx, 2, origin=origin)

    def run(model):
        U0, V0 = initial_state(model, solve_periodic(model, BASIS, frequency=F_HZ,
                                                     options=SolveOptions(tol=1e-12), eps=1e9,
                                                     raise_on_failure=True))
        out = integrate(model, F_HZ, options=IntegrationOptions(steps_per_period=256),
                        start=InitialState(U0=U0, V0=V0), n_periods=10, record="last")
        assert out.success
        return out

    mesh = join(("one", block("one")), ("two", block("two", (0.05, 0.0))))
    both = run(from_mesh(
        mesh, STEEL, damping=Damping(loss_factor=0.02),
        supports=[Spring("one.top_left", "x", 1e7), Spring("two.top_left", "x", 1e7)],
        loads=block_loads("one.") + block_loads("two."),
        contact=[ContactSpec("one.bottom", mu=0.3, name="soft"),
                 ContactSpec("two.bottom", mu=0.4, name="high")]))
    first = 0
    for name, mu in (("one", 0.3), ("two", 0.4)):
        alone = run(from_mesh(block(name), STEEL, damping=Damping(loss_factor=0.02),
                              supports=[Spring("top_left", "x", 1e7)], loads=block_loads(),
                              contact=ContactSpec("bottom", mu=mu)))
        n = sizes[name][1] + 1
        got = both.lam[:, first:first + n]
        first += n
        assert np.any(alone.state == 2) and np.any(alone.state == 1)  # stick-slip
        np.testing.assert_array_equal(both.state[:, first - n:first], alone.state)
        np.testing.assert_allclose(got, alone.lam, rtol=0, atol=1e-10 * np.abs(alone.lam).max())


def mapped(nx, ny, x_of, height):
    """A structured Q4 mesh of the region ``x_of(u, y)`` (u in [0, 1], y in [0, height])."""
    m = rectangle(1.0, height, nx, ny)
    u, y = m.points[:, 0].copy(), m.points[:, 1].copy()
    m.points[:, 0] = x_of(u, y)
    return m


def dovetail_2d():
    """A 2D dovetail root (20 mm wide at the bottom, 8 mm at the top, 6 mm high: 45 degree
    flanks) between two disc blocks held at their bottoms, mirror-symmetric about x = 0 node
    by node; node-to-node on both flanks; a radial static pull and a radial harmonic load on
    the root's top."""
    wb, wt, h, W = 0.02, 0.008, 0.006, 0.04

    def flank(y):
        return 0.5 * (wb - (wb - wt) * y / h)

    root = mapped(6, 4, lambda u, y: (2 * u - 1) * flank(y), h)
    right = mapped(4, 4, lambda u, y: flank(y) + u * (W / 2 - flank(y)), h)
    left = mapped(4, 4, lambda u, y: -(flank(y) + (1 - u) * (W / 2 - flank(y))), h)
    mesh = join(("root", root), ("left", left), ("right", right))
    return from_mesh(
        mesh, STEEL, thickness=0.01, damping=Damping(loss_factor=0.01),
        supports=[("left.bottom", "all"), ("right.bottom", "all")],
        loads=[Traction("root.top", traction=(0.0, 200e6), waveform="constant"),
               Traction("root.top", traction=(0.0, 150e6), waveform="cos")],
        contact=[ContactSpec("root.left", mu=MU, partner="left.right", name="west",
                             wear_coefficient=1e-13, partner_wear_coefficient=2e-13),
                 ContactSpec("root.right", mu=MU, partner="right.left", name="east",
                             wear_coefficient=1e-13, partner_wear_coefficient=2e-13)],
    )


def test_symmetric_dovetail_gives_symmetric_forces_and_wear():
    """Mirror-symmetric model and loads: the contact forces and wear per cycle of the two
    flanks are mirror images (normal forces and wear equal, tangential forces opposite: the
    default tangents of mirrored normals point the same way along x), to rounding (1e-9 of
    the largest: the balance's 1e-12 convergence test, conditioning ~1e3)."""
    model = dovetail_2d()
    c = model.contact
    west, east = c.interface_index() == 0, c.interface_index() == 1
    x = c.coords
    mirror = np.array([int(np.flatnonzero(east & np.all(np.isclose(x, [-p[0], p[1]]), axis=1))[0])
                       for p in x[west]])
    np.testing.assert_allclose(c.frame[west][:, 0], c.frame[mirror][:, 0] * [-1, 1], atol=1e-15)
    f = 3000.0
    sol = solve_periodic(model, BASIS, frequency=f, options=SolveOptions(tol=1e-12),
                         raise_on_failure=True)
    assert np.any(sol.state == 2) and np.any(sol.state == 1)
    lam = sol.lam
    scale = np.abs(lam).max()
    np.testing.assert_allclose(lam[west][:, 0], lam[mirror][:, 0], rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(lam[west][:, 1], -lam[mirror][:, 1], rtol=0, atol=1e-9 * scale)
    from fretwear.wear.kernels import slip_work

    prob = DLFTProblem(condense(model, f, [0, *BASIS.harmonics]), c, BASIS, eps=sol.eps,
                       anchor=sol.anchor)
    lu, lx, state, _ = prob.time_law(sol.U.reshape(prob.m, -1))
    dW = wear_coefficients(model) * slip_work(lu, lx, state, sol.eps)
    assert dW.max() > 0
    np.testing.assert_allclose(dW[west], dW[mirror], rtol=0, atol=1e-9 * dW.max())

