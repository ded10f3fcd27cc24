"""Tests of the FRF of a worn interface (:mod:`fretwear.wear.worn_frf`, paper Fig. 24).

Reference: a rigid-body translation (uniform wear of a block held vertically by the contact
only changes no force, so the FRF is that of the unworn interface). Moved unchanged from
tests/wear/test_simulate.py; ``fretwear.frf_worn`` as the sweep of the worn gap is checked in
tests/test_api.py.
"""

from __future__ import annotations

import numpy as np
from helpers.wear_block import BASIS


def test_frf_worn_uniform_wear_is_a_rigid_shift(blk):
    """The block is held vertically by the contact only: a uniform wear depth translates it
    without changing any force, so the nonlinear FRF (fretwear.hb.sweep with the worn gap) is
    that of the unworn interface, to the solver tolerance (1e-6 relative)."""
    from fretwear.wear import frf_worn

    m, _, anc = blk
    grid = (2e3, 3e3, 3)
    a = frf_worn(m, BASIS, 0.0, *grid, anchor=anc)
    b = frf_worn(m, BASIS, np.full(m.contact.n_nodes, 1e-9), *grid, anchor=anc)
    assert a.success and b.success
    np.testing.assert_allclose(b.frequency_hz, a.frequency_hz)
    np.testing.assert_allclose(b.amplitude("Pe", 0), a.amplitude("Pe", 0), rtol=1e-6)
