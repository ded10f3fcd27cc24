"""Checkpoints of a wear simulation: the complete state and the history so far in one ``.npz``
file, written atomically, so that an interrupted run resumes to the same result.

A checkpoint is matched to its run by a fingerprint of everything that determines the
trajectory (:func:`fingerprint`); the stop criteria are not part of it, so a finished run can be
extended by resuming with, e.g., a larger ``max_cycles``.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from fretwear.errors import InputError
from fretwear.files import atomic_write
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.reduce import Reduced
from fretwear.model.core import Model
from fretwear.wear.history import HISTORY_FIELDS, LATE_HISTORY_FIELDS, WearHistory
from fretwear.wear.options import WearOptions

CHECKPOINT_VERSION = 2


def fingerprint(model: Model, reduced: Reduced, basis: FourierBasis, eps: float, coef,
                options: WearOptions, W0, anchor0) -> str:
    """SHA-256 of everything that determines the trajectory (model data after condensation,
    basis, penalty, wear factors, options, initial state)."""
    h = hashlib.sha256()
    for a in (reduced.Z, reduced.F, np.asarray(model.contact.gap, float),
              np.asarray(model.contact.area, float), np.asarray(coef, float),
              np.asarray(W0, float), np.asarray(anchor0, float)):
        h.update(np.ascontiguousarray(a).tobytes())
    meta = {"basis": [list(basis.harmonics), basis.n_samples], "eps": float(eps),
            "mu": float(model.contact.mu), "omega": float(reduced.omega),
            "quasi_static": bool(reduced.quasi_static), "options": options.trajectory_key()}
    h.update(json.dumps(meta, sort_keys=True, default=str).encode())
    return h.hexdigest()


def save_checkpoint(path: Path | str, state: dict, rows: list[dict], key: str) -> Path:
    """Write the state and the history so far to ``path`` (``.npz``) atomically."""
    arrays = {f"state_{k}": np.asarray(v) for k, v in state.items()}
    hist = WearHistory.from_rows(rows)
    arrays.update({f"hist_{k}": getattr(hist, k) for k in HISTORY_FIELDS})
    arrays["fingerprint"] = np.asarray(key)
    arrays["version"] = np.asarray(CHECKPOINT_VERSION)

    def write(tmp: Path):
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)

    return atomic_write(path, write)


def _read_checkpoint(path: Path | str) -> dict:
    """The arrays of a checkpoint of this format version (:func:`save_checkpoint`)."""
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read the wear checkpoint {str(path)!r}: {exc}") from None
    if int(data.get("version", -1)) != CHECKPOINT_VERSION:
        raise InputError(f"wear checkpoint {str(path)!r} has another format version; delete it "
                         "to start again")
    return data


def _history(data) -> WearHistory:
    """The history arrays of a checkpoint
    (:data:`~fretwear.wear.history.LATE_HISTORY_FIELDS` filled with NaN in checkpoints written
    before they were recorded)."""
    n = len(data["hist_cycles"])
    late = {k: np.full(n, np.nan) for k in LATE_HISTORY_FIELDS if f"hist_{k}" not in data}
    return WearHistory(**{k: late[k] if k in late else data[f"hist_{k}"]
                          for k in HISTORY_FIELDS})


def read_history(path: Path | str) -> WearHistory:
    """The wear history stored in a checkpoint, whatever case wrote it (to look at a run that
    is going on or was interrupted; :func:`load_checkpoint` to resume one)."""
    return _history(_read_checkpoint(path))


def load_checkpoint(path: Path | str, key: str) -> tuple[dict, list[dict]]:
    """Read a checkpoint written by :func:`save_checkpoint` for the same trajectory ``key``.

    Raises
    ------
    InputError
        The file is unreadable, of another version, or written for a different case.
    """
    data = _read_checkpoint(path)
    if str(data["fingerprint"]) != key:
        raise InputError(f"wear checkpoint {str(path)!r} was written for a different model or "
                         "different wear settings; delete it (or run without --resume) to start "
                         "again")
    state = {k[6:]: data[k] for k in data if k.startswith("state_")}
    return state, _history(data).rows()
