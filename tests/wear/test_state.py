"""Tests of the typed state of a wear run (fretwear.wear.state): the step record, the state the
next step starts from, and the rescue codes.

References, each independent of the code under test:

* docs/results.md, the public meaning of the results variable ``time_domain_start`` (the
  history's ``rescued``): its integers must not change;
* the arrays a real run produced (a quasi-static wear run of the Stromberg beam): the shapes
  declared in the fields' metadata must be theirs, in the model's dimensions;
* the record a state was made from: a state holds the same numbers, in arrays of its own.
"""

from __future__ import annotations

import re
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest
from helpers.wear_runs import short_run

from fretwear.wear import HISTORY_FIELDS
from fretwear.wear.state import Rescue, SlowStep, StepRecord, shape_of

DOCS = Path(__file__).resolve().parents[2] / "docs"


@pytest.fixture(scope="module")
def run():
    """The short run of :func:`helpers.wear_runs.short_run` (result, records, dimensions)."""
    return short_run()


def test_rescue_codes_are_the_documented_ones():
    """The integers of :class:`Rescue` are those of the public results variable
    ``time_domain_start`` (docs/results.md) and of the history's column description."""
    row = next(line for line in (DOCS / "results.md").read_text().splitlines()
               if line.startswith("| `time_domain_start` |"))
    meaning = dict(re.findall(r"(\d): ([^;(]+)", row.split("|")[4]))
    assert meaning["0"].startswith("balanced") and int(Rescue.BALANCED) == 0
    assert meaning["1"].startswith("balance started from a time integration")
    assert int(Rescue.TIME_START) == 1
    assert meaning["2"].startswith("wear rate averaged over a time integration")
    assert int(Rescue.TIME_AVERAGED) == 2
    assert len(Rescue) == 3
    assert HISTORY_FIELDS["rescued"][1].startswith("0: balanced step")


def test_declared_shapes_are_those_of_a_run(run):
    """Every field of the records and of the state has the shape its metadata declares, in
    the model's dimensions (those the checkpoint checks a file against)."""
    res, seen, dims = run
    assert len(seen) == res.history.n_steps - 1 == 6
    for record in seen:
        for f in fields(StepRecord):
            assert np.shape(getattr(record, f.name)) == shape_of(f, dims), f.name
        assert record.rescued is Rescue.BALANCED and record.has_balance
    state = SlowStep.balanced(seen[-1], 1.0, SlowStep.balanced(seen[-2], 1.0))
    for f in fields(SlowStep):
        shape = shape_of(f, dims)
        value = np.asarray(getattr(state, f.name))
        if shape is not None and not (f.metadata["empty"] and value.size == 0):
            assert value.shape == shape, f.name
    assert all(f.metadata["units"] is not None and f.metadata["doc"]
               for f in fields(SlowStep) + fields(StepRecord))


def test_state_after_a_step_holds_its_record(run):
    """The state after a balanced step holds its record's wear, balance, anchors, rate,
    cycles and worn-volume rate (equal numbers, arrays of its own), counts one more step than
    the state before and keeps its initial rate and stability limit; nothing of a time
    integration."""
    _, seen, dims = run
    first = SlowStep.balanced(seen[0], 10.0, stability_jump=123.0)
    assert first.step == 0 and first.volume_rate0 == seen[0].volume_rate
    assert first.stability_jump == 123.0 and not first.in_time_integration
    after = SlowStep.balanced(seen[1], 20.0, first)
    assert after.step == 1 and after.jump == 20.0
    assert after.volume_rate0 == first.volume_rate0 and after.stability_jump == 123.0
    for name, column in (("W", "wear_depth"), ("g", "wear_rate"), ("anchor", "anchor")):
        np.testing.assert_array_equal(getattr(after, name), getattr(seen[1], column))
        assert not np.shares_memory(getattr(after, name), getattr(seen[1], column))
    np.testing.assert_array_equal(after.U, seen[1].U.reshape(dims["m"], dims["H"]))
    assert not np.shares_memory(after.U, seen[1].U)
    assert after.cycles == seen[1].cycles and after.volume_rate == seen[1].volume_rate
    assert after.Js.size == after.time_U.size == after.time_V.size == 0
    assert after.retry_balance_at == 0.0 and after.stop_reason == ""
