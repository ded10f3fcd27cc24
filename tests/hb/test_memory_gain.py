"""The split ``G(s) = G_c + sum_I w_I(z) r_I^T`` (fretwear.hb.memory_gain) against the
recursion of :func:`fretwear.hb.stability.shifted_gain`."""

import numpy as np
import pytest

from fretwear.hb import contact as law
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.memory_gain import memory_gain
from fretwear.hb.stability import shifted_gain


def _law_samples(rng, normal_force: bool, N: int):
    """Two 2D nodes, smooth random samples: with a unilateral normal they stick, slip and
    separate within the period; with a prescribed normal force they stick and slip."""
    t = 2 * np.pi * np.arange(N) / N
    lu = np.empty((2, 2, N))
    for p in range(2):
        lu[p, 0] = 0.2 + np.cos(t + rng.uniform(0, 6))
        lu[p, 1] = 1.5 * np.cos(t + rng.uniform(0, 6)) + 0.4 * np.sin(2 * t)
    mu = np.array([0.5, 0.7])
    normal = np.vstack([1 + 0.5 * np.cos(t), 2 + np.cos(t)]) if normal_force else None
    lx, state, _ = law.dlft_time(lu, mu, np.zeros((2, 1)), 1e-14, 200, normal)
    # the same periodic state from another instant: a stick interval across the period's end
    stick = state[0] == law.STICK
    i = int(np.flatnonzero(stick & np.roll(stick, 1))[0])
    roll = [np.roll(a, -i, axis=-1) for a in (lu, lx, state)]
    return *roll, mu, None if normal is None else np.roll(normal, -i, axis=-1)


@pytest.mark.parametrize("normal_force", [False, True])
def test_split_gain_is_the_recursion(normal_force):
    """At ``z = 1``, on the unit circle, inside and outside it, the split equals the
    recursion of ``shifted_gain`` (the same terms summed in another order: rounding, 1e-14 of
    the largest entry; measured 2e-16-1e-15), with stick, slip and (unilateral) separation
    intervals, one of which wraps around the period's end."""
    rng = np.random.default_rng(3)
    basis = FourierBasis.up_to(3, 48)
    P, Q = basis.matrices()
    lu, lx, state, mu, normal = _law_samples(rng, normal_force, basis.n_samples)
    kinds = set(np.unique(state).tolist())
    assert {law.STICK, law.SLIP} <= kinds
    assert normal_force or law.SEPARATION in kinds
    assert np.any((state[:, 0] == law.STICK) & (state[:, -1] == law.STICK))  # wraps around
    mg = memory_gain(lu, lx, state, mu, P, Q, law._normal(normal, lu))
    assert mg is not None and mg.node.size >= 1
    for z in (1.0, np.exp(-0.3j), np.exp(0.2 - 0.5j), 0.7):
        ref = shifted_gain(lu, lx, state, mu, P, Q, z, normal)
        assert np.abs(mg.at(z) - ref).max() <= 1e-14 * np.abs(ref).max()


def test_split_gain_refuses_what_it_does_not_cover():
    """A node that sticks all period (the recursion's singular seed) and a 3D contact keep
    the recursion: None."""
    basis = FourierBasis.up_to(2, 16)
    P, Q = basis.matrices()
    N = basis.n_samples
    lu = np.zeros((1, 2, N))
    lu[0, 0] = 1.0
    state = np.full((1, N), law.STICK, dtype=np.int8)
    normal = law._normal(None, lu)
    assert memory_gain(lu, lu.copy(), state, np.array([0.5]), P, Q, normal) is None
    lu3 = np.zeros((1, 3, N))
    assert memory_gain(lu3, lu3, state, np.array([0.5]), P, Q, normal) is None
