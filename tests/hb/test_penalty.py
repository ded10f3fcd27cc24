"""The DLFT penalty rule (fretwear.hb.penalty): one function, one spelling of ``eps``.

The model is a hand-written 2D spring-mass system: two contact nodes joined by springs to an
interior node held by grounded springs, with hysteretic damping so that ``Z_r`` is complex.
The reference spectral radius is computed independently of fretwear.hb.reduce: the Schur
complement of the dense dynamic stiffness on the contact DOFs in the structure's axes (a
rotation into the contact frames does not change eigenvalues), written as the real block
matrix of the basis ``[cos, sin]`` per kept harmonic (``[[Re Z, Im Z], [-Im Z, Re Z]]``, the
static term ``Re Z_0``), whose eigenvalues are those of ``Z_r`` and their conjugates.
"""

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions, SweepOptions
from fretwear.hb.penalty import STIFF_FACTOR, penalty, rigid_slider, sweep_penalty
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.hb.sweep import sweep
from fretwear.model.core import ContactInterface, Load, Model

ETA = 0.02  # hysteretic loss factor
ORDERS = [0, 1, 3]


def tiny_model() -> Model:
    """Contact nodes 0 and 1 (DOFs 0-3), interior node 2 (DOFs 4, 5) [N/m, kg]."""
    K = np.zeros((6, 6))

    def spring(i, j, k):
        K[i, i] += k
        K[j, j] += k
        K[i, j] -= k
        K[j, i] -= k

    spring(0, 4, 3e6)  # x of node 0 - x of node 2
    spring(1, 5, 5e6)  # y of node 0 - y of node 2
    spring(2, 4, 2e6)
    spring(3, 5, 7e6)
    spring(0, 2, 1e6)  # between the contact nodes (x)
    K[4, 4] += 4e6  # interior node grounded
    K[5, 5] += 9e6
    M = np.diag([0.01, 0.01, 0.02, 0.02, 0.5, 0.5])
    frame = np.tile(np.array([[0.0, -1.0], [1.0, 0.0]]), (2, 1, 1))  # normal -y, tangent +x
    contact = ContactInterface(dofs=np.array([[0, 1], [2, 3]]), frame=frame, gap=np.zeros(2),
                               area=np.full(2, 1e-4), mu=0.3,
                               coords=np.array([[0.0, 0.0], [0.01, 0.0]]))
    loads = [Load(np.array([0, 0, 0, 0, 0, -100.0]), "constant", name="preload"),
             Load(np.array([0, 0, 0, 0, 10.0, 0]), "cos", name="shaker")]
    Ks = sp.csr_matrix(K)
    return Model(K=Ks, M=sp.csr_matrix(M), D=ETA * Ks, contact=contact, loads=loads)


def reference_radius(model: Model, omega: float, orders) -> float:
    """max |eig| of the real block matrix of Z_r over ``orders``, from dense matrices."""
    K, M = model.K.toarray(), model.M.toarray()
    c, i = np.arange(4), np.arange(4, 6)
    blocks = []
    for n in orders:
        Z = K.astype(complex) if n == 0 else K * (1 + 1j * ETA) - (n * omega) ** 2 * M
        Zr = Z[np.ix_(c, c)] - Z[np.ix_(c, i)] @ np.linalg.solve(Z[np.ix_(i, i)],
                                                                 Z[np.ix_(i, c)])
        if n == 0:
            blocks.append(Zr.real)
        else:
            blocks.append(np.block([[Zr.real, Zr.imag], [-Zr.imag, Zr.real]]))
    size = sum(b.shape[0] for b in blocks)
    R = np.zeros((size, size))
    at = 0
    for b in blocks:
        R[at : at + b.shape[0], at : at + b.shape[0]] = b
        at += b.shape[0]
    return float(np.max(np.abs(np.linalg.eigvals(R))))


def test_auto_is_the_spectral_radius_of_z_r_over_the_kept_harmonics():
    model = tiny_model()
    for f in (300.0, 2000.0):
        rho = reference_radius(model, 2 * np.pi * f, ORDERS)
        eps = penalty("auto", model=model, frequency=f, orders=ORDERS)
        assert eps == pytest.approx(rho, rel=1e-10)
        red = condense(model, f, ORDERS)
        assert penalty("auto", reduced=red) == eps
    # the rule depends on the frequency (inertia of the interior node)
    assert penalty("auto", model=model, frequency=2000.0, orders=ORDERS) != \
        pytest.approx(penalty("auto", model=model, frequency=300.0, orders=ORDERS))


def test_auto_quasi_static_is_the_static_radius():
    model = tiny_model()
    qs = penalty("auto", model=model, frequency=2000.0, orders=ORDERS, quasi_static=True)
    assert qs == pytest.approx(reference_radius(model, 0.0, [0]), rel=1e-10)


def test_static_is_the_radius_of_k_r_at_every_frequency():
    model = tiny_model()
    rho0 = reference_radius(model, 0.0, [0])
    a = penalty("static", model=model, frequency=300.0, orders=ORDERS)
    b = penalty("static", model=model, frequency=2000.0, orders=ORDERS)
    assert a == b
    assert a == pytest.approx(rho0, rel=1e-10)
    # from a condensation alone: its order-0 block is K_r whatever the frequency
    red = condense(model, 2000.0, ORDERS)
    assert penalty("static", reduced=red) == pytest.approx(a, rel=1e-14)


@pytest.mark.parametrize("value", [3e9, 7, np.float64(2.5e8)])
def test_a_number_is_used_as_given(value):
    assert penalty(value, model=tiny_model(), frequency=1.0, orders=ORDERS) == float(value)
    assert isinstance(penalty(value), float)


@pytest.mark.parametrize("value", ["paper", "per-frequency", "Auto", 0, -1e9, float("nan"),
                                   float("inf"), True, None, [1e9]])
def test_a_bad_value_is_rejected_naming_eps(value):
    with pytest.raises(ValueError, match=r'eps = .*"auto".*"static".*positive number'):
        penalty(value, model=tiny_model(), frequency=1.0, orders=ORDERS)


def test_the_solvers_take_the_same_words():
    model = tiny_model()
    basis = FourierBasis((1, 3), 16)
    red = condense(model, 300.0, basis.orders)
    for rule in ("auto", "static", 4e7):
        expected = penalty(rule, model=model, reduced=red)
        assert DLFTProblem(red, model.contact, basis, eps=rule).eps == pytest.approx(
            expected, rel=1e-14)
        sol = solve_periodic(model, basis, frequency=300.0, reduced=red, eps=rule)
        st = sol.stats
        assert st.success, st.message
        assert sol.eps == expected
    assert DLFTProblem(red, model.contact, basis).eps == penalty("auto", reduced=red)
    for call in (lambda: DLFTProblem(red, model.contact, basis, eps="paper"),
                 lambda: solve_periodic(model, basis, frequency=300.0, eps=-1.0),
                 lambda: sweep(model, basis, 100.0, 200.0, 2,
                               options=SweepOptions(eps="per-frequency"))):
        with pytest.raises(ValueError, match="eps = "):
            call()


def test_sweep_static_and_top_are_one_penalty_and_auto_one_per_frequency():
    """``"top"`` in a sweep is one eps for every point: the median over 5
    frequencies of the band of the spectral radius of Z_r at the highest kept harmonic,
    compared with ``reference_radius`` (dense matrices, module docstring) to rounding;
    ``"stiff"`` is ten times that (``STIFF_FACTOR``); the default ``"contact"`` is ``"top"``
    on this unilateral interface."""
    model = tiny_model()
    basis = FourierBasis((1,), 16)
    # between the resonances of the interior node with the contact held (675 and 1031 Hz),
    # where Z_r(w) outweighs K_r
    f = np.array([700.0, 800.0])
    top = sweep(model, basis, f[0], f[1], 2, options=SweepOptions(spacing="linear",
                                                                  time_domain=None, eps="top"))
    ref_top = float(np.median([reference_radius(model, 2 * np.pi * x, [1])
                               for x in np.linspace(f[0], f[1], 5)]))
    assert [p.solution.eps for p in top.points] == pytest.approx([ref_top] * 2, rel=1e-12)
    static = sweep(model, basis, f[0], f[1], 2,
                   options=SweepOptions(spacing="linear", time_domain=None, eps="static"))
    default = sweep(model, basis, f[0], f[1], 2, options=SweepOptions(spacing="linear",
                                                                      time_domain=None))
    stiff = sweep(model, basis, f[0], f[1], 2,
                  options=SweepOptions(spacing="linear", time_domain=None, eps="stiff"))
    auto = sweep(model, basis, f[0], f[1], 2, options=SweepOptions(spacing="linear",
                                                                   time_domain=None, eps="auto"))
    for res in (static, top, default, stiff, auto):
        assert res.success, res.message
        np.testing.assert_allclose(res.frequency_hz, f, rtol=1e-15)
    k_r = penalty("static", model=model)
    assert [p.solution.eps for p in static.points] == [k_r, k_r]
    assert STIFF_FACTOR == 10.0
    assert [p.solution.eps for p in default.points] == pytest.approx([ref_top] * 2, rel=1e-12)
    assert [p.solution.eps for p in stiff.points] == pytest.approx([10.0 * ref_top] * 2,
                                                                   rel=1e-12)
    per_point = [penalty("auto", model=model, frequency=x, orders=basis.orders)
                 for x in f]
    assert [p.solution.eps for p in auto.points] == per_point
    assert per_point[0] != pytest.approx(per_point[1])


def test_top_is_the_spectral_radius_at_the_highest_kept_harmonic():
    """``"top"`` vs ``reference_radius`` on the highest kept order alone (dense matrices);
    ``"stiff"`` ten times it."""
    model = tiny_model()
    for f in (300.0, 2000.0):
        ref = reference_radius(model, 2 * np.pi * f, [ORDERS[-1]])
        assert penalty("top", model=model, frequency=f, orders=ORDERS) == pytest.approx(
            ref, rel=1e-12)
        assert penalty("stiff", model=model, frequency=f, orders=ORDERS) == pytest.approx(
            10.0 * ref, rel=1e-12)


def _with_contact(model: Model, **changes) -> Model:
    """``model`` with its contact interface changed (``normal_load``, ``kt``)."""
    return dataclasses.replace(model, contact=dataclasses.replace(model.contact, **changes))


def test_contact_is_stiff_on_rigid_sliders_under_a_prescribed_load_and_top_elsewhere():
    """The default rule ``"contact"``: ten times ``"top"`` (checked against the dense
    reference above) when every node rubs rigidly under a prescribed normal load, ``"top"``
    when a node is unilateral, the contact spring where every law row has the same one
    (exact, :func:`fretwear.hb.penalty.spring_penalty`). Exact equalities: the rule picks one
    of the other rules, so the values are the same floating-point numbers."""
    model, orders = tiny_model(), [0, 1]
    both = _with_contact(model, normal_load=Load(np.array([20.0, 30.0]), "constant"))
    one = _with_contact(model, normal_load=Load(np.array([20.0, np.nan]), "constant"))
    spring = _with_contact(both, kt=np.full(2, 4e6))
    assert rigid_slider(both.contact)
    assert not rigid_slider(model.contact) and not rigid_slider(one.contact)
    assert not rigid_slider(spring.contact) and not rigid_slider(None)
    f = 800.0
    # with both normal loads prescribed the law rows are the two tangential ones (DOFs 0 and
    # 2 of the structure: Z_r's rows 1 and 3 in the contact frames): their reference radius
    K, M = both.K.toarray(), both.M.toarray()
    w, c, i = 2 * np.pi * f, np.array([0, 2]), np.array([1, 3, 4, 5])
    Z = K * (1 + 1j * ETA) - w**2 * M
    Zr = Z[np.ix_(c, c)] - Z[np.ix_(c, i)] @ np.linalg.solve(Z[np.ix_(i, i)], Z[np.ix_(i, c)])
    ref_top = float(np.max(np.abs(np.linalg.eigvals(Zr))))
    for m, factor in ((both, STIFF_FACTOR), (one, 1.0), (model, 1.0)):
        top = penalty("top", model=m, frequency=f, orders=orders)
        assert penalty("contact", model=m, frequency=f, orders=orders) == factor * top
        assert sweep_penalty("contact", m, orders, 700.0, 900.0) == factor * sweep_penalty(
            "top", m, orders, 700.0, 900.0)
    assert penalty("top", model=both, frequency=f, orders=orders) == pytest.approx(
        ref_top, rel=1e-12)
    assert penalty("contact", model=spring, frequency=f, orders=orders) == 4e6
    assert SweepOptions().eps == "contact"


def test_radius_estimate_of_large_blocks():
    """Above EXACT_SIZE rows the spectral radius is a power-iteration estimate of the largest
    singular value: on a complex symmetric matrix with a known spectrum (Q diag(l) Q^T, Q
    real orthogonal, so the matrix is normal and |l|max is both the spectral radius and the
    2-norm, here 2.5 x the next one) it matches to 1e-3 (the iteration stops at a 1e-3 relative
    change, and converges geometrically with ratio (2/5)^2 per step)."""
    from fretwear.hb.penalty import EXACT_SIZE, radius

    n = EXACT_SIZE + 44
    rng = np.random.default_rng(1)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    lam = rng.uniform(1.0, 2.0, n) * np.exp(1j * rng.uniform(0, 0.1, n))
    lam[7] = 5.0 + 0.2j
    Z = (Q * lam) @ Q.T
    assert radius(Z) == pytest.approx(abs(lam[7]), rel=1e-3)
    assert radius(Z[:40, :40]) == pytest.approx(np.abs(np.linalg.eigvals(Z[:40, :40])).max(),
                                                rel=1e-12)


def test_radius_of_several_blocks_warm_started():
    """radius_max over several large blocks (each power iteration started from the previous
    block's vector plus the cold start) against the known spectra (Q diag(l_b) Q^T, real
    orthogonal Q: the radius of block b is max |l_b|): to 1e-3, the iteration's stopping
    test. The blocks' top modes are orthogonal columns of Q, so a start from the previous
    block's vector alone would have no component on the next top mode and stop at the
    second eigenvalue (0.4 of the top one: far outside the tolerance); the largest radius is
    that of the last block."""
    from fretwear.hb.penalty import EXACT_SIZE, radius, radius_max

    n = EXACT_SIZE + 44
    rng = np.random.default_rng(3)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    blocks, tops = [], []
    for b, top in enumerate((5.0, 6.0, 7.0)):
        lam = rng.uniform(1.0, 2.0, n)
        lam[b] = top  # block b's top mode: column b of Q
        blocks.append((Q * lam) @ Q.T)
        tops.append(top)
    assert radius_max(blocks) == pytest.approx(7.0, rel=1e-3)
    # each block alone (cold start) gives the same
    for Z, top in zip(blocks, tops, strict=True):
        assert radius(Z) == pytest.approx(top, rel=1e-3)
    # the previous block's top mode is kept (10) and a new one 1.5 times larger appears (a
    # harmonic nearing a resonance): the warm vector dominates the start, the random part
    # must still let the new mode take over (a tenth of it stops at 10.002, measured)
    base = rng.uniform(1.0, 2.0, n)
    a, b = base.copy(), base.copy()
    a[0] = b[0] = 10.0
    b[1] = 15.0
    assert radius_max([(Q * a) @ Q.T, (Q * b) @ Q.T]) == pytest.approx(15.0, rel=1e-3)


# --- contact springs: eps = k makes the DLFT the alternating frequency-time balance --------

def _jenkins_aft(w, H, N, m=1.0, k=1.0, c=0.02, kt=0.5, slip=0.5, f0=0.2):
    """Periodic response x(t_n), t_n = n T / N, of ``m x'' + c x' + k x + f = f0 cos(w t)``
    with ``f`` a spring ``kt`` in series with a Coulomb slider of threshold ``slip``, by the
    harmonic balance on H harmonics with the force evaluated in time from the truncated
    displacement (return mapping over periods until the force repeats), solved by scipy's
    hybrid method with finite-difference Jacobians. Written here from the equations, sharing
    nothing with fretwear."""
    from scipy.optimize import root

    t = np.arange(N) / N * 2 * np.pi
    n = np.arange(1, H + 1)
    C, S = np.cos(np.outer(n, t)), np.sin(np.outer(n, t))

    def signal(z):  # z = [a0, a1..aH, b1..bH]: x = a0 + sum a_n cos + b_n sin
        return z[0] + z[1:H + 1] @ C + z[H + 1:] @ S

    def force(x):
        f = 0.0
        for _ in range(50):  # passes until the start state repeats
            start, out = f, np.empty(N)
            for i in range(N):
                f = np.clip(f + kt * (x[i] - x[i - 1]), -slip, slip)
                out[i] = f
            if abs(f - start) < 1e-15:
                break
        return out

    def residual(z):
        f = force(signal(z))
        fa0, fa, fb = f.mean(), 2 * C @ f / N, 2 * S @ f / N
        a, b = z[1:H + 1], z[H + 1:]
        d = k - m * (n * w) ** 2
        ra = d * a + c * n * w * b + fa - f0 * (n == 1)
        rb = d * b - c * n * w * a + fb
        return np.concatenate([[k * z[0] + fa0], ra, rb])

    z0 = np.zeros(2 * H + 1)
    z0[1] = f0 / abs(k + kt - m * w * w)
    sol = root(residual, z0, method="hybr", options={"xtol": 1e-14})
    assert np.max(np.abs(residual(sol.x))) < 1e-12
    return signal(sol.x)


@pytest.mark.parametrize("w, f0", [(1.18, 0.2), (1.1, 0.5)])
def test_jenkins_eps_is_its_spring_and_equals_the_aft_balance(w, f0):
    """A Jenkins element (``kt`` in series with a slider, prescribed normal load): every eps
    rule gives ``kt``, and the DLFT answer at that eps is the alternating frequency-time
    balance of the spring-slider law (independent implementation above, hybrid solver with
    finite differences). It is an identity of the two sets of discrete equations
    (hb/penalty.spring_penalty), so both solvers reach the same root to rounding (1e-15
    measured; 1e-10 allows for the reference's finite-difference solver); at the previous
    value of the "top" rule (0.505 N/m, the top harmonic's spectral radius) the two
    differ by far more, so the comparison can fail. Both frequencies slip in both directions
    every period (amplitude above ``mu N / kt``), where the periodic state is unique (a
    Jenkins element that sticks all period has a free mean)."""
    from fretwear.model.build import Damping
    from fretwear.model.matrices import ContactDofs, from_matrices

    H, N = 5, 64
    model = from_matrices([[1.0]], [[1.0]],
                          contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=0.5,
                                              normal_load=1.0, kt=0.5),
                          damping=Damping(C=[[0.02]]), loads=[Load(np.array([f0]), "cos")],
                          observed={"x": 0})
    basis = FourierBasis.up_to(H, N)
    for rule in ("top", "auto", "static"):
        assert penalty(rule, model=model, frequency=w / (2 * np.pi),
                       orders=basis.orders) == 0.5
    ref = _jenkins_aft(w, H, N, f0=f0)
    assert np.ptp(ref) / 2 > 0.5 / 0.5  # slips both ways: amplitude above mu N / kt
    scale = np.max(np.abs(ref))

    def error(eps):
        sol = solve_periodic(model, basis, frequency=w / (2 * np.pi), eps=eps,
                             options=SolveOptions(tol=1e-12))
        assert sol.success
        return np.max(np.abs(sol.observed_time("x")[0][0] - ref)) / scale

    assert error("top") < 1e-10
    assert error(0.505) > 1e-5
