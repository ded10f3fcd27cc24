"""The writer of format-3 wear checkpoints (fretwear before format 4), kept to test that they
are refused with a message that says why (they carry no content checksum: fretwear cannot tell
them from a file edited by hand), never resumed."""

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


def assert_format_3_is_refused(path: Path) -> None:
    """Rewrite the checkpoint at ``path`` (this format) as format 3, with the same state and
    history, and check that it is refused with one InputError naming the file and why."""
    import pytest

    from fretwear.errors import InputError
    from fretwear.wear import load_checkpoint

    with np.load(path) as z:
        key = str(z["fingerprint"])
    state, records = load_checkpoint(path, key)
    save_format_3(path, state, records, key)
    with np.load(path) as z:
        assert int(z["version"]) == 3 and "state_vrate0" in z.files
    with pytest.raises(InputError, match=f"wear checkpoint '{path}' was written by an earlier "
                                         "fretwear whose checkpoints carry no content checksum"):
        load_checkpoint(path, key)
