"""The small-problem path of the DLFT balance (fretwear.hb.small) against the general path.

``DLFTProblem`` takes the compiled residual+Jacobian kernel with matrix Fourier transforms
when ``m H <= small.SMALL_MAX``; the general path (FFTs, numpy products, the same law kernels)
is what it replaces, and is forced here by setting ``SMALL_MAX = -1``. The two are different
implementations of eq. 22-28, so they must agree to rounding: the residual and Jacobian at the
same point to 1e-12 relative (a few hundred roundings of O(1e-16)), the converged answers of
the same solve to 1e-10 relative (solved to a relative residual of 1e-12, so each answer is
within ~1e-12 x the conditioning of its exact solution). Models: (a) the one-DOF Jenkins
oscillator and (b) the two-DOF chain on a rigid Coulomb contact of benchmarks/peers.py, and a
plane-strain block in unilateral contact whose nodes separate, stick and slip.
"""

import numpy as np
import pytest

from fretwear.hb import small
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SWEEP_POINT, SolveOptions, SweepOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.hb.sweep import sweep
from fretwear.model import ContactSpec, Damping, Material, Spring, Traction, from_mesh, rectangle
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

W_HZ = 1.0 / (2 * np.pi)  # the oscillators' frequencies are given in rad/s


def jenkins():
    """(a): m = 1, k = 1, c = 0.02, a Jenkins element kt = 0.5 under mu N = 0.5."""
    return from_matrices([[1.0]], [[1.0]],
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=0.5,
                                             normal_load=1.0, kt=0.5),
                         damping=Damping(C=[[0.02]]), loads=[Load(np.array([0.2]), "cos")],
                         observed={"x": 0})


def chain():
    """(b): two masses, mass 2 on a rigid Coulomb contact under a constant normal load."""
    return from_matrices(np.array([[2.0, -1.0], [-1.0, 1.0]]), np.eye(2),
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[1], mu=0.5,
                                             normal_load=1.0),
                         damping=Damping(C=0.02 * np.eye(2)),
                         loads=[Load(np.array([0.2, 0.0]), "cos")], observed={"x": 0})


def block():
    """A steel block 20 x 10 mm (4 x 2 Q4, plane strain) pressed on a rigid flat (mu = 0.8)
    and rocked by a cosine pressure on its right face strong enough to lift an edge:
    separation, stick and slip in one period (asserted below)."""
    L, H = 0.02, 0.01
    return from_mesh(
        rectangle(L, H, nx=4, ny=2), Material(210e9, 0.3, 7800.0), thickness=0.01,
        damping=Damping(rayleigh_stiffness=5e-6),
        supports=[Spring(at=(0.0, H / 2), direction="x", stiffness=1e7)],
        loads=[Traction("top", pressure=1e6),
               Traction("right", pressure=2e6, waveform="cos")],
        contact=ContactSpec("bottom", mu=0.8), observed={"Pe": (L, H / 2)})


CASES = {  # model, frequency [Hz], eps [N/m]
    "jenkins": (jenkins, 1.18 * W_HZ, 0.5),
    "chain": (chain, 1.49 * W_HZ, 100.0),
    "block": (block, 1500.0, "auto"),
}


def problem(name, nh=7):
    make, f, eps = CASES[name]
    model = make()
    basis = FourierBasis.up_to(nh, 64)
    red = condense(model, f, basis.orders)
    return model, basis, f, eps, DLFTProblem(red, model.contact, basis, eps=eps)


@pytest.mark.parametrize("name", list(CASES))
def test_residual_and_jacobian_equal_the_general_path(name, monkeypatch):
    """At a vibrating state (the converged solution plus a perturbation of 10 % of its size,
    so that the law's states differ from the solution's), the compiled kernel's residual and
    Jacobian equal the general path's."""
    model, basis, f, eps, prob = problem(name)
    assert prob.small
    sol = solve_periodic(model, basis, frequency=f, eps=eps, options=SolveOptions(tol=1e-10))
    assert sol.success
    U = sol.U.reshape(prob.m, prob.H)
    U = U + 0.1 * np.abs(U).max() * np.random.default_rng(0).standard_normal(U.shape)
    f_s, J_s = prob.residual(U)
    monkeypatch.setattr(small, "SMALL_MAX", -1)
    general = DLFTProblem(prob.reduced, model.contact, basis, eps=prob.eps)
    assert not general.small
    f_g, J_g = general.residual(U)
    assert np.abs(f_s - f_g).max() <= 1e-12 * np.abs(f_g).max()
    assert np.abs(J_s - J_g).max() <= 1e-12 * np.abs(J_g).max()
    np.testing.assert_array_equal(prob.time_law(U)[2], general.time_law(U)[2])  # states


@pytest.mark.parametrize("name", list(CASES))
def test_converged_answers_equal_the_general_path(name, monkeypatch):
    """The same periodic solve on both paths converges to the same answer: displacements,
    contact forces and the observed point to 1e-10 relative; on the block every contact
    state (separation, stick, slip) occurs."""
    model, basis, f, eps, _ = problem(name)
    a = solve_periodic(model, basis, frequency=f, eps=eps, options=SolveOptions(tol=1e-12))
    monkeypatch.setattr(small, "SMALL_MAX", -1)
    b = solve_periodic(model, basis, frequency=f, eps=eps, options=SolveOptions(tol=1e-12))
    assert a.success and b.success
    for x, y in ((a.U, b.U), (a.lam, b.lam), (a.observed[list(a.observed)[0]],
                                              b.observed[list(b.observed)[0]])):
        assert np.abs(x - y).max() <= 1e-10 * np.abs(y).max()
    if name == "block":
        assert set(np.unique(a.state)) == {0, 1, 2}


@pytest.mark.parametrize("name", ["jenkins", "chain"])
def test_sweeps_equal_the_general_path(name, monkeypatch):
    """A sweep through the resonance (problems sharing their set-up from one frequency to the
    next, batched condensation and contact springs) gives the general path's amplitudes to
    1e-10 relative, solved to 1e-12."""
    make, f, eps = CASES[name]
    band = (0.9 * f, 1.1 * f)

    def run():
        res = sweep(make(), FourierBasis.up_to(5, 64), *band, 9,
                    options=SweepOptions(solve=SWEEP_POINT.replace(tol=1e-12), spacing="linear",
                                         eps=eps))
        assert res.success
        return res.amplitude("x")

    a = run()
    monkeypatch.setattr(small, "SMALL_MAX", -1)
    b = run()
    assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max()
