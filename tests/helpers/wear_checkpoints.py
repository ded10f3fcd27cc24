"""The writer of format-3 wear checkpoints (fretwear before format 4), kept to test that they
are still read: the state under its format-3 names, spelt out here rather than taken from
:data:`fretwear.wear.checkpoint.FORMAT_3_NAMES`, so that a wrong mapping there is caught."""

from dataclasses import fields
from pathlib import Path

import numpy as np

from fretwear.wear import HISTORY_FIELDS, WearHistory
from fretwear.wear.state import SlowStep, StepRecord


def format_3_state(state: SlowStep) -> dict:
    """The state dict of a format-3 checkpoint (its 15 keys) holding ``state``."""
    return {"step": state.step, "cycles": state.cycles, "W": state.W, "U": state.U,
            "anchor": state.anchor, "g": state.g, "jump": state.jump,
            "vrate": state.volume_rate, "vrate0": state.volume_rate0,
            "stability_jump": state.stability_jump, "stop_reason": np.asarray(state.stop_reason),
            "td_U": state.time_U, "td_V": state.time_V, "td_retry_at": state.retry_balance_at,
            "Js": state.Js}


def save_format_3(path: Path, state: SlowStep, records: list[StepRecord], key: str) -> None:
    """Write ``state`` and the history ``records`` as a format-3 checkpoint did (its
    ``save_checkpoint``; not atomically: a test file)."""
    arrays = {f"state_{k}": np.asarray(v) for k, v in format_3_state(state).items()}
    hist = WearHistory.from_records(records)
    arrays.update({f"hist_{k}": getattr(hist, k) for k in HISTORY_FIELDS})
    arrays["fingerprint"] = np.asarray(key)
    arrays["version"] = np.asarray(3)
    with open(path, "wb") as fh:
        np.savez(fh, **arrays)


def assert_reads_as_format_3(path: Path) -> None:
    """Rewrite the checkpoint at ``path`` (this format) as format 3, with the same state and
    history, and check that it reads back as the same state, field by field."""
    from fretwear.wear import load_checkpoint

    with np.load(path) as z:
        key = str(z["fingerprint"])
    state, records = load_checkpoint(path, key)
    save_format_3(path, state, records, key)
    with np.load(path) as z:
        assert int(z["version"]) == 3 and "state_vrate0" in z.files
    again, records3 = load_checkpoint(path, key)
    assert len(records3) == len(records)
    for f in fields(SlowStep):
        a, b = getattr(again, f.name), getattr(state, f.name)
        assert type(a) is type(b), f.name
        np.testing.assert_array_equal(a, b, err_msg=f.name)
