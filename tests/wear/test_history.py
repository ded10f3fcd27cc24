"""Tests of the recorded history of a wear run (:mod:`fretwear.wear.history`).

Reference: the records the run's callback got, step by step, and the history rebuilt from its
own records (a round trip: the same numbers, bit for bit, in the same dtypes). Moved unchanged
from tests/wear/test_state.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.wear_runs import short_run

from fretwear.wear import HISTORY_FIELDS, WearHistory
from fretwear.wear.state import Rescue


@pytest.fixture(scope="module")
def run():
    """The short run of :func:`helpers.wear_runs.short_run` (result, records, dimensions)."""
    return short_run()


def test_history_of_records_and_back(run):
    """The history is the records stacked step by step; its records are the same numbers,
    with the rescue as a :class:`Rescue`."""
    res, seen, _ = run
    h = res.history
    again = WearHistory.from_records(h.records(), h.stop_reason)
    for name in HISTORY_FIELDS:
        a, b = getattr(h, name), getattr(again, name)
        assert a.dtype == b.dtype, name
        np.testing.assert_array_equal(a, b, err_msg=name)
    assert h.rescued.dtype.kind == "i"
    for k, record in enumerate(seen, start=1):
        np.testing.assert_array_equal(h.wear_depth[k], record.wear_depth)
        assert h.cycles[k] == record.cycles
    assert all(isinstance(r.rescued, Rescue) for r in h.records())
