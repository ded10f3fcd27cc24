"""The small 3D block shared by the tests of the blocked modal condensation and of its
operators (tests/hb/test_modal_blocked.py, test_operator_blocks.py, test_modal_operator.py,
test_schur.py), and the comparison of two modal condensers of it."""

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.preload import static_anchor
from fretwear.hb.reduce import exact_condenser
from fretwear.model import ContactSpec, Material, Spring, Traction, box, from_mesh

F_MAX = 20e3  # Hz (as test_modal.py)
ORDERS = np.arange(8)


def block(damping=None, traction=3e5, cells=4):
    """test_modal.py's 10 x 10 x 5 mm steel block on a rigid flat, optionally damped;
    ``cells`` elements along each side of the contact face (4: 25 contact nodes)."""
    return from_mesh(box(0.01, 0.01, 0.005, cells, cells, 2), Material(210e9, 0.3, 7800.0),
                     damping=damping,
                     supports=[Spring("zmax", "x", 1e7), Spring("zmax", "y", 1e7)],
                     loads=[Traction("zmax", pressure=1e6),
                            Traction("zmax", traction=(traction, 0.5 * traction, 0.0),
                                     waveform="cos")],
                     contact=ContactSpec("zmin", mu=0.5),
                     observed={"corner": (0.01, 0.01, 0.005)})


def rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max()


def same_reductions(model, ref, other, tol: float):
    """The reductions of ``model`` by the condensers ``ref`` and ``other`` at 15 kHz,
    ``(a, b)``, after checking that ``other``'s ``Z_r`` (every harmonic of :data:`ORDERS`),
    loads, observed rows and recovery equal ``ref``'s to ``tol`` relative, and that its
    harmonic 0 equals the exact condensation to 1e-10 (the static constraint modes are exact
    on every path). The caller says why ``tol``."""
    w = 2 * np.pi * 15e3
    a, b = ref.reduced(w, ORDERS), other.reduced(w, ORDERS)
    for n in range(ORDERS.size):
        assert rel(b.Z[n], a.Z[n]) < tol, n
    for name in ("F", "obs_A", "obs_b"):
        assert rel(getattr(b, name), getattr(a, name)) < tol, name
    u = np.random.default_rng(1).standard_normal((ORDERS.size, a.m)) + 0j
    assert rel(other.recover(w, ORDERS, u), ref.recover(w, ORDERS, u)) < tol
    ex = exact_condenser(model).reduced(w, ORDERS[:1])
    assert rel(b.Z[0], ex.Z[0]) < 1e-10 and rel(b.F[0], ex.F[0]) < 1e-10
    return a, b


def same_partial_slip_solution(make_ref, make_other, tol: float = 1e-8):
    """The periodic solves of the block in partial slip (traction 4.5e5 Pa, 3 harmonics, 64
    samples, 12 kHz) through the condensers ``make_ref(model)`` and ``make_other(model)``:
    both converge, the second in partial slip, and its harmonics equal the first's to
    ``tol`` relative (the caller says why)."""
    model = block(traction=4.5e5)
    basis = FourierBasis.up_to(3, 64)
    out = []
    for make in (make_ref, make_other):
        c = make(model)
        sol = solve_periodic(model, basis, frequency=12e3, condenser=c,
                             anchor=static_anchor(model, condenser=c))
        assert sol.success
        out.append(sol)
    assert 0.02 < out[1].state_fractions().mean(axis=0)[2] < 0.98  # partial slip
    assert rel(out[1].U, out[0].U) < tol
