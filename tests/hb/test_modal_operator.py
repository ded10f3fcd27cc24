"""fretwear.hb.modal_operator: a ReducedOperator is determined by its stored arrays (what the
wear checkpoint's fingerprint hashes), and those change with the frequency."""

import numpy as np
from helpers.operator_models import F_MAX, ORDERS, block

from fretwear.hb.modal import BlockedModalCondenser


def test_operator_arrays_determine_it():
    """``arrays()`` (what a wear checkpoint's fingerprint hashes instead of the formed
    blocks) changes with the frequency and is the same for the same frequency."""
    bc = BlockedModalCondenser(block(), F_MAX, 7, tol=1e-2)
    a, b, c = (bc.reduced(2 * np.pi * f, ORDERS).Z.arrays() for f in (12e3, 12e3, 13e3))
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert not all(np.array_equal(x, y) for x, y in zip(a, c, strict=True))

