"""Checkpoints of a frequency sweep: the points computed so far in one ``.npz`` file, written
atomically after every grid frequency, so that a sweep killed at any instant resumes to the
same result, bit for bit, as if it had never stopped.

What a point needs to be rebuilt exactly is small: its circular frequency, its harmonics ``U``,
its stick anchors and penalty, and the solver statistics and flags (its
:class:`~fretwear.hb.solution.PeriodicSolution` is re-assembled from them by the same
deterministic code, :func:`fretwear.hb.branch.rebuild_point`). The continuation state of the sweep
(the last two converged points of the secant predictor, the neighbour of a time-domain start)
is the sequence of converged points itself.

A checkpoint is read whole and checked before use (:func:`fretwear.files.read_archive`: every
member's CRC; the checksum of its whole content, :func:`fretwear.files.check_seal`, so that a
file edited by hand is refused; then keys, types, shapes and finite values): a damaged one is one
:class:`~fretwear.errors.InputError` naming the file, never a traceback, never a silent start
from zero. It is matched to its sweep by a fingerprint of everything that determines the points
(:func:`fingerprint`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.files import SEAL, atomic_write, check_seal, damaged, read_archive, seal

#: 2: sealed with the checksum of its content (:func:`fretwear.files.seal`)
SWEEP_CHECKPOINT_VERSION = 2
WHAT = "sweep checkpoint"
#: the arrays of a checkpoint and their shapes (p points, m contact unknowns, H coefficients)
SHAPES = {"omega": ("p",), "converged": ("p",), "U": ("p", "m", "H"), "eps": ("p",),
          "anchor": ("p", "nc", "d-1"), "next_index": ()}
_TEXT = ("fingerprint", "records", SEAL)


def _digest(h, obj) -> None:
    """Feed everything that defines ``obj`` (arrays, sparse matrices, dataclasses such as the
    model and its interface, lists, scalars) into the hash ``h``."""
    if obj is None:
        h.update(b"None")
    elif sp.issparse(obj):
        obj = sp.csr_matrix(obj)
        for a in (np.asarray(obj.shape), obj.indptr, obj.indices, obj.data):
            h.update(np.ascontiguousarray(a).tobytes())
    elif isinstance(obj, np.ndarray):
        h.update(str((obj.dtype.str, obj.shape)).encode())
        h.update(np.ascontiguousarray(obj).tobytes())
    elif dataclasses.is_dataclass(obj):
        for f in dataclasses.fields(obj):
            if f.name not in ("mesh", "fe_mesh", "meta", "name"):  # descriptions, not data
                h.update(f.name.encode())
                _digest(h, getattr(obj, f.name))
    elif isinstance(obj, dict):
        for k in sorted(obj, key=str):
            h.update(repr(k).encode())
            _digest(h, obj[k])
    elif isinstance(obj, list | tuple):
        h.update(f"[{len(obj)}]".encode())
        for x in obj:
            _digest(h, x)
    else:
        h.update(repr(obj).encode())


def fingerprint(model, basis, grid, settings: dict) -> str:
    """SHA-256 of everything that determines a sweep's points: the model (matrices, loads,
    interface, observed points), the basis, the frequency grid [Hz] and the solve
    ``settings`` (penalty, gap, anchors, solver, tolerances, continuation, fallbacks)."""
    h = hashlib.sha256()
    _digest(h, model)
    _digest(h, [list(basis.harmonics), int(basis.n_samples)])
    _digest(h, np.asarray(grid, float))
    _digest(h, settings)
    return h.hexdigest()


def save_sweep_checkpoint(path: Path | str, key: str, next_index: int, points: list,
                          shape: tuple[int, int, int]) -> Path:
    """Write the sweep's ``points`` so far (computed order) and the next grid index.

    ``shape = (nc, d, H)``: contact nodes, components, Fourier coefficients."""
    nc, d, H = shape
    p = len(points)
    U = np.zeros((p, nc * d, H))
    anchor = np.zeros((p, nc, d - 1))
    omega, eps = np.zeros(p), np.zeros(p)
    conv = np.zeros(p, bool)
    records = []
    for i, pt in enumerate(points):
        s = pt.solution
        if s is not None:
            conv[i] = True
            U[i], anchor[i], omega[i], eps[i] = s.U.reshape(nc * d, H), s.anchor, s.omega, s.eps
        records.append({"frequency_hz": pt.frequency_hz, "how": pt.how, "flags": pt.flags,
                        "on_grid": pt.on_grid, "time_domain": pt.time_domain,
                        "stats": dataclasses.asdict(pt.stats),
                        "attempts": [dataclasses.asdict(a) for a in pt.attempts]})
    arrays = {"U": U, "anchor": anchor, "omega": omega, "eps": eps, "converged": conv,
              "next_index": np.asarray(int(next_index)), "fingerprint": np.asarray(key),
              "records": np.asarray(json.dumps(records)),
              "version": np.asarray(SWEEP_CHECKPOINT_VERSION)}

    def write(tmp: Path):
        with open(tmp, "wb") as fh:
            np.savez(fh, **seal(arrays))

    return atomic_write(path, write)


def _check(data: dict) -> str:
    """What is wrong with the arrays of a sweep checkpoint ("" if nothing)."""
    missing = [k for k in (*SHAPES, *_TEXT) if k not in data]
    if missing:
        return f"missing {', '.join(missing)}"
    for k, a in data.items():
        if (a.dtype.kind == "U") != (k in _TEXT) or a.dtype.kind not in "biufU":
            return f"{k} has the type {a.dtype}"
    if data["U"].ndim != 3 or data["anchor"].ndim != 3:
        return "inconsistent arrays"
    p, m, H = data["U"].shape
    _, nc, dm1 = data["anchor"].shape
    dims = {"p": p, "m": m, "H": H, "nc": nc, "d-1": dm1}
    for k, shape in SHAPES.items():
        if data[k].shape != tuple(dims[n] for n in shape):
            return f"{k} has the shape {data[k].shape}"
    try:
        records = json.loads(str(data["records"]))
    except ValueError:
        return "unreadable point records"
    if not isinstance(records, list) or len(records) != p:
        return "point records inconsistent with the arrays"
    if int(data["next_index"]) < 0:
        return f"a negative next grid index ({int(data['next_index'])})"
    conv = data["converged"].astype(bool)
    for k in ("U", "anchor", "omega", "eps"):
        if not np.isfinite(data[k][conv]).all():
            return f"non-finite {k} at a converged point"
    for k in ("omega", "eps"):
        if np.any(data[k][conv] <= 0):
            return f"{k} <= 0 at a converged point"
    return ""


def load_sweep_checkpoint(path: Path | str, key: str, shape: tuple[int, int, int]):
    """Read a checkpoint of :func:`save_sweep_checkpoint` for the same sweep ``key`` and model
    ``shape = (nc, d, H)``.

    Returns
    -------
    ``(next_index, entries)``: the grid index to continue from, and per point in computed order
    a dict of ``record`` (frequency, how, flags, stats...) and, for converged points, ``omega``
    [rad/s], ``U`` (m, H), ``anchor`` (nc, d-1) and ``eps`` [N/m].

    Raises
    ------
    InputError
        The file is damaged, of another format version, or written for another sweep.
    """
    data = read_archive(path, WHAT)
    version = data.get("version")
    if version is None or version.shape != () or version.dtype.kind not in "iu":
        raise damaged(path, WHAT, "no format version")
    if int(version) != SWEEP_CHECKPOINT_VERSION:
        raise InputError(f"{WHAT} {str(path)!r} has another format version (written by "
                         "another version of fretwear); delete it to start again")
    check_seal(data, path, WHAT)
    why = _check(data)
    if why:
        raise damaged(path, WHAT, why)
    if str(data["fingerprint"]) != key:
        raise InputError(f"{WHAT} {str(path)!r} was written for a different model or different "
                         "sweep settings; delete it (or run without --resume) to start again")
    nc, d, H = shape
    if data["U"].shape[1:] != (nc * d, H) or data["anchor"].shape[1:] != (nc, d - 1):
        raise InputError(f"{WHAT} {str(path)!r} was written for a different model; delete it "
                         "(or run without --resume) to start again")
    entries = []
    for i, rec in enumerate(json.loads(str(data["records"]))):
        e = {"record": rec}
        if data["converged"][i]:
            e.update(omega=float(data["omega"][i]), U=data["U"][i], anchor=data["anchor"][i],
                     eps=float(data["eps"][i]))
        entries.append(e)
    return int(data["next_index"]), entries
