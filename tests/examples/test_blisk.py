"""The lumped blisk sector (fretwear.examples.blisk) against its modes written out by hand.

Reference: its springs act alike in x and y, so in the disk's axes each direction is a scalar
chain whose wave of wavenumber m is the 2-DOF problem of a disk mass on
``k_g + 2 k_c (1 - cos m alpha) + k_b`` and a blade on ``k_b`` (closed form: a quadratic in
w^2). A sector's vector in its own axes, turned by ``j alpha`` into the disk's, carries the
wavenumbers ``k - 1`` and ``k + 1``: the modes of harmonic index ``k`` are those two chains'
waves. The cyclic reduction is exact: 1e-10 relative.
"""

from __future__ import annotations

import numpy as np
import pytest

from fretwear.examples.blisk import lumped_blisk
from fretwear.hb.cyclic import cyclic_modes


@pytest.mark.parametrize("k", [0, 1, 3, 6])
def test_modes_of_each_index_are_the_two_dof_closed_form(k):
    n, kc, kg, kb, md, mb = 12, 3e5, 1e7, 1e6, 0.5, 0.1
    s = lumped_blisk(n, coupling=kc)
    f, _ = cyclic_modes(s, k, 4)
    w2 = []
    for m in (k - 1, k + 1):
        kd = kg + 2 * kc * (1 - np.cos(m * 2 * np.pi / n)) + kb
        # det([[kd - md w2, -kb], [-kb, kb - mb w2]]) = 0
        w2 += list(np.roots([md * mb, -(kd * mb + kb * md), kd * kb - kb * kb]).real)
    want = np.sort(np.sqrt(w2) / (2 * np.pi))
    assert np.allclose(f, want, rtol=1e-10)


def test_blade_alone_is_near_503_hz():
    """A stiff disk leaves the blade on its own spring: sqrt(k_b / m_b) / 2 pi = 503.3 Hz."""
    f, _ = cyclic_modes(lumped_blisk(12, ground_stiffness=1e12), 2, 1)
    assert abs(f[0] - np.sqrt(1e6 / 0.1) / (2 * np.pi)) < 1e-3 * f[0]
