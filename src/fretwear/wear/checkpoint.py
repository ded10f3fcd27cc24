"""Checkpoints of a wear simulation: the complete state and the history so far in one ``.npz``
file, written atomically, so that an interrupted run resumes to the same result.

A checkpoint is read whole and checked before use (every member's CRC, every key, types and
shapes consistent with one another and with the model): a damaged one (truncated, altered,
incomplete, not a checkpoint at all) is one :class:`~fretwear.errors.InputError` naming the
file, never a traceback and never a silent start from zero.

A checkpoint is matched to its run by a fingerprint of everything that determines the
trajectory (:func:`fingerprint`); the stop criteria are not part of it, so a finished run can be
extended by resuming with, e.g., a larger ``max_cycles``.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import fields
from pathlib import Path

import numpy as np

from fretwear.errors import InputError
from fretwear.files import (
    SEAL,
    atomic_write,
    check_seal,
    check_state_file,
    damaged,
    read_archive,
    seal,
)
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.reduce import Reduced
from fretwear.model.core import Model
from fretwear.wear.history import HISTORY_FIELDS, LATE_HISTORY_FIELDS, WearHistory
from fretwear.wear.options import WearOptions
from fretwear.wear.state import SlowStep, StepRecord, shape_of

#: 5: sealed with the checksum of its content (:func:`fretwear.files.seal`); 4: the state is
#: the fields of :class:`~fretwear.wear.state.SlowStep`, some renamed;
#: 3: the fingerprint hashes the reduced model as stored, real for an undamped modal
#: condensation (complex before), so an earlier checkpoint cannot match it: say so by the
#: version rather than by "written for a different model"
CHECKPOINT_VERSION = 5
#: the versions read: only sealed ones (an unsealed checkpoint cannot be told from one edited
#: by hand, so formats 3 and 4 are refused with a message that says why)
READ_VERSIONS = (5,)
#: the fields of the state and of the history (:class:`StepRecord`): shapes, units, meanings
STATE_FIELDS = fields(SlowStep)
RECORD_FIELDS = {f.name: f for f in fields(StepRecord)}


def _mu_key(mu):
    """One number for one coefficient (the key of earlier checkpoints), else the list."""
    mu = np.asarray(mu, dtype=float)
    return float(mu) if mu.ndim == 0 else mu.tolist()


def fingerprint(model: Model, reduced: Reduced, basis: FourierBasis, eps: float, coef,
                options: WearOptions, wear0, anchor0) -> str:
    """SHA-256 of everything that determines the trajectory (model data after condensation,
    basis, penalty, wear factors, options, initial state)."""
    h = hashlib.sha256()
    Z = reduced.Z.arrays() if hasattr(reduced.Z, "arrays") else [reduced.Z]  # an operator
    for a in (*Z, reduced.F, np.asarray(model.contact.gap, float),
              np.asarray(model.contact.area, float), np.asarray(coef, float),
              np.asarray(wear0, float), np.asarray(anchor0, float)):
        h.update(np.ascontiguousarray(a).tobytes())
    meta = {"basis": [list(basis.harmonics), basis.n_samples], "eps": float(eps),
            "mu": _mu_key(model.contact.mu), "omega": float(reduced.omega),
            "quasi_static": bool(reduced.quasi_static), "options": options.trajectory_key()}
    h.update(json.dumps(meta, sort_keys=True, default=str).encode())
    return h.hexdigest()


def save_checkpoint(path: Path | str, state: SlowStep, records: list[StepRecord],
                    key: str) -> Path:
    """Write the state (every field of :class:`~fretwear.wear.state.SlowStep`, ``state_``
    and its name) and the history so far (``hist_`` and its column) to ``path`` (``.npz``)
    atomically."""
    arrays = {f"state_{f.name}": np.asarray(getattr(state, f.name)) for f in STATE_FIELDS}
    hist = WearHistory.from_records(records)
    arrays.update({f"hist_{k}": getattr(hist, k) for k in HISTORY_FIELDS})
    arrays["fingerprint"] = np.asarray(key)
    arrays["version"] = np.asarray(CHECKPOINT_VERSION)

    def write(tmp: Path):
        with open(tmp, "wb") as fh:
            np.savez(fh, **seal(arrays))

    return atomic_write(path, write)


#: text arrays (every other one is numeric)
_TEXT = ("fingerprint", SEAL, *(f"state_{f.name}" for f in STATE_FIELDS if f.type == "str"))


WHAT = "wear checkpoint"


def _damaged(path: Path | str, why: str) -> InputError:
    """The one error of a checkpoint that cannot be used (:func:`fretwear.files.damaged`)."""
    return damaged(path, WHAT, why)


def check_checkpoint_path(path: Path | str) -> None:
    """Refuse a checkpoint path that is a folder (or other non-file): it could be neither
    read nor written, and the run would fail at its first save."""
    check_state_file(path, WHAT)


def _read_checkpoint(path: Path | str) -> dict:
    """The arrays of a checkpoint of a version read (:data:`READ_VERSIONS`), its state under
    the names of :class:`~fretwear.wear.state.SlowStep`, checked for completeness and
    consistency (:func:`_check_arrays`).

    Raises
    ------
    InputError
        One message naming the file, whatever is wrong with it (:func:`_damaged`).
    """
    data = read_archive(path, WHAT)
    version = data.get("version")
    if version is None or version.shape != () or version.dtype.kind not in "iu":
        raise _damaged(path, "no format version")
    if int(version) in (3, 4):
        raise InputError(f"wear checkpoint {str(path)!r} was written by an earlier fretwear "
                         "whose checkpoints carry no content checksum (this one cannot tell it "
                         "from a file edited by hand); delete it to start again")
    if int(version) not in READ_VERSIONS:
        raise InputError(f"wear checkpoint {str(path)!r} has another format version; delete it "
                         "to start again")
    check_seal(data, path, WHAT)
    why = _check_arrays(data)
    if why:
        raise _damaged(path, why)
    return data


def _dims(data: dict) -> dict:
    """The dimensions of a checkpoint, read from its history of contact displacements."""
    s, nc, d, H = data["hist_U"].shape
    return {"s": s, "nc": nc, "d": d, "H": H, "m": nc * d, "d-1": d - 1}


def _check_arrays(data: dict) -> str:
    """What is wrong with the arrays of a checkpoint ("" if nothing): every key present,
    numeric (text where text is expected), and shapes consistent with one another."""
    need = ["fingerprint", *(f"state_{f.name}" for f in STATE_FIELDS),
            *(f"hist_{k}" for k in HISTORY_FIELDS if k not in LATE_HISTORY_FIELDS)]
    missing = [k for k in need if k not in data]
    if missing:
        return f"missing {', '.join(missing[:4])}{' ...' if len(missing) > 4 else ''}"
    for k, a in data.items():
        if (a.dtype.kind == "U") != (k in _TEXT) or (a.dtype.kind not in "biufU"):
            return f"{k} has the type {a.dtype}"
    if data["fingerprint"].shape != () or data["hist_U"].ndim != 4:
        return "inconsistent arrays"
    dims = _dims(data)
    if dims["s"] < 1 or dims["d"] < 2:
        return "an empty history"  # (or fewer than 2 components)
    wanted = {f"state_{f.name}": f for f in STATE_FIELDS}
    wanted.update({f"hist_{k}": f for k, f in RECORD_FIELDS.items()})
    for k, f in wanted.items():
        shape = shape_of(f, dims)
        if k.startswith("hist_"):
            shape = (dims["s"], *shape)
        a = data.get(k)
        if (a is not None and shape is not None and a.shape != shape
                and not (f.metadata["empty"] and a.size == 0)):
            return f"{k} has the shape {a.shape}"
    if int(data["state_step"]) != dims["s"] - 1:
        return f"state at step {int(data['state_step'])} with a history of {dims['s']} steps"
    return _check_values(data)


#: arrays of a checkpoint whose values must be finite, and those that must also be >= 0 (a
#: worn depth, a cycle count, a jump)
_FINITE = ("state_U", "state_anchor", "state_g", "hist_U")
_NON_NEGATIVE = ("state_W", "state_cycles", "state_jump", "hist_wear_depth", "hist_cycles")
#: counts of a checkpoint (>= 0), and its index arrays (>= -1: -1 for none)
_COUNTS = ("state_step", "hist_newton_iterations", "hist_rejected", "hist_rescued")
_INDICES = ("hist_response",)


def _check_values(data: dict) -> str:
    """What is wrong with the values of a checkpoint ("" if nothing): the resumed state and
    the history are finite, depths and cycle counts >= 0 and the cycles never decrease (a
    file rewritten with its checksum recomputed passes the seal, not this)."""
    for k in (*_FINITE, *_NON_NEGATIVE):
        a = np.asarray(data[k], dtype=float)
        if not np.all(np.isfinite(a)):
            return f"{k} holds non-finite values"
        if k in _NON_NEGATIVE and np.any(a < 0):
            return f"{k} holds a negative value ({float(a.min()):g})"
    for k in (*_COUNTS, *_INDICES):
        if k in data and np.any(np.asarray(data[k]) < (0 if k in _COUNTS else -1)):
            return f"{k} holds {int(np.min(data[k]))}, out of range"
    if np.any(np.diff(data["hist_cycles"]) < 0) \
            or float(data["state_cycles"]) != float(data["hist_cycles"][-1]):
        return "its cycle counts are not those of one run (they decrease or disagree)"
    return ""


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


def load_checkpoint(path: Path | str, key: str, shape: tuple[int, int, int] | None = None
                    ) -> tuple[SlowStep, list[StepRecord]]:
    """Read a checkpoint written by :func:`save_checkpoint` (this format or format 3) for the
    same trajectory ``key`` and, when given, the model's ``shape = (nc, d, H)`` (contact nodes,
    components, Fourier coefficients): the state and the records of the history.

    Raises
    ------
    InputError
        The file is damaged (unreadable, truncated, incomplete, inconsistent), of another
        version, or written for a different case.
    """
    data = _read_checkpoint(path)
    if str(data["fingerprint"]) != key:
        raise InputError(f"wear checkpoint {str(path)!r} was written for a different model or "
                         "different wear settings (the model as condensed counts: a modal "
                         "condensation by another path, e.g. partial factorisations where "
                         "kvxopt is installed and static modes where it is not, differs in its "
                         "last digits); delete it (or run without --resume) to start again")
    dims = _dims(data)
    if shape is not None and (dims["nc"], dims["d"], dims["H"]) != tuple(shape):
        raise InputError(f"wear checkpoint {str(path)!r} was written for a different model "
                         f"({dims['nc']} contact nodes, {dims['d']} components, {dims['H']} "
                         f"Fourier coefficients instead of {shape[0]}, {shape[1]}, {shape[2]}); "
                         "delete it (or run without --resume) to start again")
    state = SlowStep(**{f.name: _value(f, data[f"state_{f.name}"]) for f in STATE_FIELDS})
    return state, _history(data).records()


def _value(f, a: np.ndarray):
    """The value of the state field ``f`` stored as the array ``a``: a Python number or
    text where the field is one, else the array."""
    convert = {"int": int, "float": float, "str": str}.get(f.type)
    return convert(a) if convert is not None else a
