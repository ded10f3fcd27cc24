"""Floquet multipliers from the exact time integration (:mod:`fretwear.timedomain.monodromy`)
and the agreement of Hill's method (:mod:`fretwear.hb.stability`) with them.

The models put the contact on a light node (1 g against masses of 1 kg) joined to the structure
by a spring: the time integration has rigid unilateral contact and exact Coulomb friction on
that node, the harmonic balance solves the same model (no contact springs), and both see the
same structure. References: the eigenvalues of the linear state matrix where the contact never
closes; Hill's multipliers where it does (the comparison is then between two discretisations,
the balance's harmonics and samples, the integration's step, of one model).
"""

import numpy as np

from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.solution import initial_state
from fretwear.hb.stability import stability
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices
from fretwear.timedomain.monodromy import SHOOTING, monodromy
from fretwear.timedomain.options import InitialState

MS = 1e-3  # mass of the contact node [kg]


def unilateral(kn=10.0, gap=0.5, force=0.1):
    """Two masses (springs 0, 1, 1 N/m, damping 0.03 K) and a unilateral spring ``kn`` on the
    first one through a light contact node on a rigid wall at ``gap``; the node's tangential
    DOF is a separate damped oscillator (frictionless contact)."""
    cs = 2 * 0.2 * np.sqrt(kn * MS)  # 20 % of critical damping on the node's own mode
    K = np.array([[1 + kn, -1, -kn, 0], [-1, 2, 0, 0], [-kn, 0, kn, 0], [0, 0, 0, 1.0]])
    C = np.array([[0.03 + cs, -0.03, -cs, 0], [-0.03, 0.06, 0, 0], [-cs, 0, cs, 0],
                  [0, 0, 0, 1.0]])
    return from_matrices(K, np.diag([1.0, 1.0, MS, 1.0]),
                         contact=ContactDofs(normal_dofs=[2], tangential_dofs=[3], gap=gap, mu=0.0),
                         damping=Damping(C=C), loads=[Load(np.array([0, force, 0, 0]), "cos")],
                         observed={"x1": 0, "x2": 1})


def friction(force, kt=0.5, mu=0.5, normal=1.0):
    """A mass (1 kg, 1 N/m, 0.02 N s/m) and a spring ``kt`` to a light node pressed by
    ``normal`` on a rigid plane with friction ``mu``: a Jenkins element with a 1 g slider."""
    kz = 10.0
    cs, cz = 2 * 0.2 * np.sqrt(kt * MS), 2 * 0.2 * np.sqrt(kz * MS)
    K = np.array([[1 + kt, -kt, 0], [-kt, kt, 0], [0, 0, kz]])
    C = np.array([[0.02 + cs, -cs, 0], [-cs, cs, 0], [0, 0, cz]])
    return from_matrices(K, np.diag([1.0, MS, MS]),
                         contact=ContactDofs(normal_dofs=[2], tangential_dofs=[1], gap=0.0, mu=mu),
                         damping=Damping(C=C),
                         loads=[Load(np.array([force, 0, 0]), "cos"),
                                Load(np.array([0, 0, normal]), "constant")],
                         observed={"x": 0})


def test_linear_response_multipliers_are_the_state_matrix_exponentials():
    """The wall far away: the period map is linear and its multipliers are ``e^{lambda T}``
    of the state matrix, up to the trapezoidal rule's phase error ``(w_j h)^3 / 12`` per step:
    2.4e-4 over a period of 1024 steps for the fastest mode that does not decay (1.62 rad/s,
    2.3 oscillations a period; measured 1.7e-4; 4e-4 allowed). The shooting needs one Newton
    step."""
    model = unilateral(gap=50.0)
    w = 0.7
    sol = solve_periodic(model, FourierBasis.up_to(3, 32), frequency=w / (2 * np.pi),
                         time_domain=None)
    U0, V0 = initial_state(model, sol)
    mono = monodromy(model, w / (2 * np.pi), start=InitialState(U0=U0, V0=V0))
    assert mono.success and mono.iterations <= 1
    K = model.K.toarray()
    M = model.M.toarray()
    C = model.C.toarray()
    A = np.block([[np.zeros((4, 4)), np.eye(4)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    ref = np.exp(np.linalg.eigvals(A) * 2 * np.pi / w)
    big = ref[np.abs(ref) > 1e-3]  # the light node's own mode decays within a period
    for r in big:
        assert np.min(np.abs(mono.multipliers - r)) < 4e-4


def test_unilateral_contact_hill_agrees_with_the_time_integration():
    """Contact during ~8 % of the period (0.60 rad/s on the upper branch): the four
    multipliers of the masses from Hill's method (15 harmonics, 256 samples) and from the
    monodromy of the exact integration (2048 steps) agree to 1e-2 (measured 9e-3: the
    balance's truncation of the contact's kink); the integration's other multipliers (the
    light node) are below 1e-2."""
    model = unilateral()
    basis = FourierBasis.up_to(15, 256)
    U = None
    for w in (0.56, 0.58, 0.60):
        sol = solve_periodic(model, basis, frequency=w / (2 * np.pi), time_domain=None, U0=U)
        U = sol.U
    assert sol.success and 0.0 < sol.state_fractions()[0, 2] + sol.state_fractions()[0, 1]
    hill = stability(model, sol, dyn=structure_dynamics(model))
    U0, V0 = initial_state(model, sol)
    mono = monodromy(model, w / (2 * np.pi), start=InitialState(U0=U0, V0=V0),
                     integration=SHOOTING.replace(steps_per_period=2048))
    assert mono.success
    tangential = np.exp(-np.pi / w)  # |rho| of the separate tangential oscillator
    main = hill.multipliers[np.abs(np.abs(hill.multipliers) - tangential) > 1e-6]
    assert main.size == 4
    td = mono.multipliers[np.abs(np.abs(mono.multipliers) - tangential) > 1e-3]
    for r in main:
        assert np.min(np.abs(td[:4] - r)) < 1e-2
    assert np.all(np.abs(td[4:]) < 1e-2)
    assert hill.stable and mono.max_multiplier < 1


def test_friction_hill_agrees_with_the_time_integration():
    """A Jenkins element with a light slider that sticks ~40 % of the period: Hill's two
    multipliers (the law's memory included, eps = kt) and the integration's dominant pair
    agree to 1e-2 (measured 3e-3 at 25 harmonics, 1e-2 at 15); the integration's slider has a
    multiplier ~0 (a slip resets it), which the balance's contact point does not have."""
    model = friction(0.5)
    w = 1.1
    sol = solve_periodic(model, FourierBasis.up_to(25, 512), frequency=w / (2 * np.pi),
                         time_domain=None, eps=0.5)
    hill = stability(model, sol)
    main = hill.multipliers[hill.kind == "refined"]
    assert main.size == 2 and np.all(np.abs(hill.multipliers[hill.kind != "refined"]) < 1e-8)
    U0, V0 = initial_state(model, sol)
    mono = monodromy(model, w / (2 * np.pi), start=InitialState(U0=U0, V0=V0),
                     integration=SHOOTING.replace(steps_per_period=2048))
    assert mono.success
    for r in main:
        assert np.min(np.abs(mono.multipliers[:2] - r)) < 1e-2
    assert abs(mono.multipliers[2]) < 1e-2


def test_fold_and_period_doubling_of_the_unilateral_sweep_agree_with_the_time_integration():
    """The turning points of the unilateral oscillator's folded response (15 harmonics, 256
    samples, 30 points from 0.56 to 0.8 rad/s: the sweep passes the fold near 0.74-0.77 rad/s
    by arclength): at every converged point where Hill's method is clear about it (its largest
    real positive multiplier above 1.05 or below 0.95), the monodromy of the exact integration
    (1024 steps) has a real multiplier above 1 exactly where Hill's has (the middle branch,
    where ``det J < 0``), the two within 0.12 of each other (measured up to 0.083 there: the
    balance's truncation of the contact's kink, which the steep unstable branch magnifies).
    Points within 0.05 of 1 are the turning points themselves, where the two discretisations
    put the fold a point apart. Period doubling: where Hill's method has a real multiplier
    below -1.2 (the upper branch next to the fold, -1.23 to -1.55), the integration has one
    below -1 (measured -1.09 to -1.47); nearer -1 the two differ by the truncation (Hill's
    -1.10 at 0.684 and 0.709 rad/s against the integration's -0.97 and -0.95: docs/theory.md,
    section 9)."""
    from fretwear.hb.options import SweepOptions
    from fretwear.hb.reduce import exact_condenser
    from fretwear.hb.sweep import sweep
    from fretwear.hb.sweep_stability import sweep_stability

    model = unilateral()
    cond = exact_condenser(model)
    res = sweep(model, FourierBasis.up_to(15, 256), 0.56 / (2 * np.pi), 0.8 / (2 * np.pi), 30,
                options=SweepOptions(spacing="linear"), condenser=cond)
    st = sweep_stability(model, res, condenser=cond)
    compared, middle, doubled = 0, 0, 0
    for i, p in enumerate(res.points):
        fl = st.floquet[i]
        if fl is None:
            continue
        rho = fl.multipliers
        pos = rho[(np.abs(rho.imag) <= 1e-6 * np.abs(rho)) & (rho.real > 0)].real
        top = pos.max(initial=0.0)
        if 0.95 <= top <= 1.05:
            continue
        U0, V0 = initial_state(model, p.solution, cond)
        mono = monodromy(model, p.frequency_hz, start=InitialState(U0=U0, V0=V0),
                         integration=SHOOTING.replace(steps_per_period=1024))
        assert mono.success
        r = mono.multipliers
        td = r[(np.abs(r.imag) <= 1e-6 * np.abs(r)) & (r.real > 0)].real.max(initial=0.0)
        assert (top > 1) == (td > 1) == (fl.det_sign < 0), (p.frequency_hz, top, td)
        if top > 1:
            assert abs(top - td) < 0.12
            middle += 1
        compared += 1
        neg = rho[(np.abs(rho.imag) <= 1e-6 * np.abs(rho)) & (rho.real < 0)].real
        if neg.min(initial=0.0) < -1.2:  # a clear period doubling by Hill's method
            assert r[(np.abs(r.imag) <= 1e-6 * np.abs(r)) & (r.real < 0)].real.min() < -1
            doubled += 1
    assert middle >= 10 and compared >= 40  # both branches are compared
    assert doubled >= 5


def test_neimark_sacker_point_of_the_unilateral_sweep_agrees_with_the_time_integration():
    """The unilateral oscillator forced harder (0.3 N) loses stability between 0.80 and 0.81
    rad/s by a complex pair of multipliers leaving the unit circle: a Neimark-Sacker point,
    which the sweep's stability reports (15 harmonics, 256 samples). The monodromy of the exact
    integration (512 steps a period) at the two ends of the stretch has its dominant pair
    complex too, inside the unit circle at 0.80 rad/s and outside at 0.83 rad/s, within 0.03 of
    Hill's pair (measured 0.008 and 0.02: the balance's truncation of the contact's kink and the
    integration's step)."""
    from fretwear.hb.options import SweepOptions
    from fretwear.hb.reduce import exact_condenser
    from fretwear.hb.sweep import sweep
    from fretwear.hb.sweep_stability import sweep_stability

    model = unilateral(force=0.3)
    cond = exact_condenser(model)
    res = sweep(model, FourierBasis.up_to(15, 256), 0.80 / (2 * np.pi), 0.83 / (2 * np.pi), 4,
                options=SweepOptions(spacing="linear"), condenser=cond)
    st = sweep_stability(model, res, condenser=cond)
    assert list(st.stable) == [1, 0, 0, 0]
    (event,) = st.events
    assert event.kind == "Neimark-Sacker" and event.change == "stable -> unstable"
    assert abs(event.multiplier.imag) > 0.1 and abs(event.multiplier) > 1
    for i, outside in ((0, False), (3, True)):
        p, fl = res.points[i], st.floquet[i]
        hill = fl.critical(1)[0]
        U0, V0 = initial_state(model, p.solution, cond)
        mono = monodromy(model, p.frequency_hz, start=InitialState(U0=U0, V0=V0),
                         integration=SHOOTING.replace(steps_per_period=512))
        assert mono.success
        r = mono.multipliers[np.argsort(-np.abs(mono.multipliers))]
        assert abs(r[0].imag) > 0.1 and abs(r[0] - np.conj(r[1])) < 1e-8  # a complex pair
        td = r[0] if r[0].imag * hill.imag > 0 else r[1]
        assert abs(td - hill) < 0.03, (p.frequency_hz, td, hill)
        assert (abs(td) > 1) == (abs(hill) > 1) == outside
