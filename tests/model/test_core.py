"""The plain data objects of a model (fretwear.model.core): load waveforms and their Fourier
coefficients, the per-node records of the contact interface and its local transform.

References independent of the code under test: the DFT of exact waveform samples, the direct
sum ``Re sum_n F_n e^{i n tau}`` against the exact samples, and the local displacements
``frame @ (U[dofs] - U[partner_dofs])`` of the module docstring evaluated node by node by hand.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from fretwear.hb.fourier import FourierBasis
from fretwear.model.core import ContactInterface, Load, Model, ObservedPoint

RNG = np.random.default_rng(2024)
TOL = 1e-12  # FFT of O(1) data with N <= 256: rounding ~ 1e-15 * log2(N); margin 100x


def test_load_waveforms_consistent_with_transform():
    """The closed-form Fourier coefficients of the load waveforms (core.Load) vs the DFT of the
    exact samples. The triangle has all odd harmonics decaying like 1/n^2: with N = 4096 the
    aliased energy in harmonics <= 7 is ~8/pi^2 * 2/(N-7)^2 ~ 1e-7, hence the tolerance."""
    basis = FourierBasis.up_to(7, 4096)
    for wf, tol in (("cos", TOL), ("sin", TOL), ("constant", TOL), ("triangle", 2e-7)):
        load = Load(np.ones(1), wf)
        a, b = load.fourier_coefficients(7)
        c = basis.to_freq(load.waveform_samples(basis.tau))
        np.testing.assert_allclose(c, np.concatenate([[a[0]], a[1:], b[1:]]), rtol=0, atol=tol)


def rotation(theta):
    return np.array([[np.cos(theta), np.sin(theta)], [-np.sin(theta), np.cos(theta)]])


def two_pairs_and_a_rigid_node():
    """Three contact nodes of a 2D model of 10 DOFs, with tilted frames: the nodes at DOFs
    (0, 1) and (2, 3) are node a of pairs with the nodes at (4, 5) and (6, 7); the node at
    (8, 9) is on a rigid obstacle (partner -1)."""
    dofs = np.array([[0, 1], [2, 3], [8, 9]])
    partner = np.array([[4, 5], [6, 7], [-1, -1]])
    frame = np.stack([rotation(t) for t in (0.2, -0.7, 1.1)])
    return ContactInterface(dofs=dofs, frame=frame, gap=np.zeros(3), area=np.ones(3),
                            mu=0.4, coords=np.zeros((3, 2)), partner_dofs=partner,
                            wear_coefficient=[1e-11, 2e-11, 3e-11],
                            partner_wear_coefficient=5e-12)


def test_local_transform_is_the_frame_of_the_relative_displacement():
    """``T @ U`` against ``frame @ (U[dofs] - U[partner_dofs])`` evaluated node by node for a
    random U (``frame @ U[dofs]`` for the node on the rigid obstacle): a sum of at most four
    products per entry, exact to rounding (1e-14 of O(1) data)."""
    c = two_pairs_and_a_rigid_node()
    U = RNG.standard_normal(10)
    by_hand = []
    for a, b, frame in zip(c.dofs, c.partner_dofs, c.frame, strict=True):
        rel = U[a] - (U[b] if b[0] >= 0 else 0.0)
        by_hand.append(frame @ rel)
    T = c.local_transform(10)
    assert T.shape == (6, 10)
    np.testing.assert_allclose(T @ U, np.concatenate(by_hand), rtol=0, atol=1e-14)


def test_per_node_values_broadcast_and_partners_wear_only_where_paired():
    """One number stands for every node; the partner's Archard coefficient applies to pairs
    only (a rigid obstacle does not wear); one interface when none is named (exact)."""
    c = two_pairs_and_a_rigid_node()
    assert c.paired().tolist() == [True, True, False] and c.has_pairs
    np.testing.assert_array_equal(c.mu_nodes(), [0.4, 0.4, 0.4])
    np.testing.assert_array_equal(c.wear_nodes(), [1e-11, 2e-11, 3e-11])
    np.testing.assert_array_equal(c.partner_wear_nodes(), [5e-12, 5e-12, 0.0])
    assert c.interface_index().tolist() == [0, 0, 0] and c.names() == ["contact"]
    assert not c.has_springs and not c.has_connectors
    c.kt = np.array([np.inf, 1e6, np.inf])
    assert c.has_springs and c.has_connectors


def test_load_harmonics_sum_to_the_exact_load_history():
    """``Re sum_n F_n e^{i n tau}`` from :meth:`Model.load_harmonics` against
    :meth:`Model.load_time` (exact samples of the waveforms) for constant, cos, sin and
    user Fourier loads, whose series end at harmonic 3: equal to rounding (1e-13 of O(1)
    forces, a few sums of four terms)."""
    n = 4
    loads = [Load(RNG.standard_normal(n), "constant"), Load(RNG.standard_normal(n), "cos"),
             Load(RNG.standard_normal(n), "sin"),
             Load(RNG.standard_normal(n), "fourier", {0: (0.3, 9.0), 2: (0.5, -0.2),
                                                      3: (0.0, 1.0)})]
    contact = ContactInterface(dofs=np.array([[0, 1]]), frame=np.eye(2)[None], gap=np.zeros(1),
                               area=np.ones(1), mu=0.3, coords=np.zeros((1, 2)))
    model = Model(K=sp.eye(n).tocsr(), M=sp.eye(n).tocsr(), contact=contact, loads=loads)
    tau = np.linspace(0.0, 2 * np.pi, 37)
    F = model.load_harmonics(3)
    assert F.shape == (4, n) and np.all(F[0].imag == 0.0)  # b_0 is ignored: a real mean
    series = np.real(np.exp(1j * np.outer(tau, np.arange(4))) @ F)
    np.testing.assert_allclose(series, model.load_time(tau), rtol=0, atol=1e-13)


def test_prescribed_normal_forces_are_the_waveform_times_each_nodes_force():
    """``N(tau) = vector x g(tau)`` on the prescribed nodes, a NaN row on the unilateral one,
    nothing when no node is prescribed (exact: one product per entry)."""
    c = two_pairs_and_a_rigid_node()
    assert c.normal_force_samples([0.0]) is None
    c.normal_load = Load(np.array([2.0, np.nan, -1.0]), "cos")
    tau = np.array([0.0, np.pi / 3, np.pi])
    N = c.normal_force_samples(tau)
    assert c.prescribed_nodes().tolist() == [True, False, True] and c.has_connectors
    np.testing.assert_array_equal(N[0], 2.0 * np.cos(tau))
    assert np.all(np.isnan(N[1]))
    np.testing.assert_array_equal(N[2], -np.cos(tau))


def test_free_dofs_observed_points_and_unknown_waveforms():
    """The free DOFs are the complement of the fixed ones; an unknown observed point and an
    unknown waveform are refused naming what exists."""
    contact = two_pairs_and_a_rigid_node()
    model = Model(K=sp.eye(10).tocsr(), M=sp.eye(10).tocsr(), contact=contact,
                  fixed_dofs=np.array([5, 1]), observed=[ObservedPoint("tip", np.array([3]),
                                                                       np.zeros(2))])
    assert model.free_dofs().tolist() == [0, 2, 3, 4, 6, 7, 8, 9] and model.ndof == 10
    assert model.observed_point("tip").dofs.tolist() == [3]
    with pytest.raises(KeyError, match=r"no observed point named 'top'.*\['tip'\]"):
        model.observed_point("top")
    with pytest.raises(ValueError, match="unknown waveform 'square'"):
        Load(np.ones(1), "square").fourier_coefficients(3)
    with pytest.raises(ValueError, match="unknown waveform 'square'"):
        Load(np.ones(1), "square").waveform_samples(np.zeros(1))
