"""Files written so that they are complete or absent: results, checkpoints, figures.

No file format lives here (see :mod:`fretwear.io`); the numerical core (wear checkpoints) and
the file writers share this one rule.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import stat
import tempfile
import time
import zipfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from fretwear.errors import InputError

#: the temporary files of :func:`atomic_write`: ``.<name>.<random>.tmp`` beside the target
#: (``tempfile.mkstemp`` draws ``<random>`` from lowercase letters, digits and ``_``)
TEMPORARY = re.compile(r"\.(?P<name>.+)\.[a-z0-9_]+\.tmp")


def atomic_write(path: Path | str, write: Callable[[Path], None]) -> Path:
    """Write a file so that it is either complete or absent (never half-written).

    ``write(tmp)`` writes a temporary file in the same folder; it is flushed to disk and
    renamed over ``path`` (``os.replace``, atomic on POSIX and Windows). If ``write`` fails
    or is interrupted, the temporary file is removed and an existing ``path`` is kept.

    Returns
    -------
    The absolute path written.
    """
    path = Path(path).resolve()
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    # (the name matches TEMPORARY: remove_stale_temporaries clears it if the process is killed)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        write(tmp)
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes it private; use the usual mode
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise
    _fsync_dir(path.parent)
    return path


def remove_stale_temporaries(folder: Path | str, min_age_s: float = 60.0) -> list[Path]:
    """Remove the temporary files that :func:`atomic_write` left in ``folder`` when its
    process was killed mid-write (SIGKILL, power loss): the regular files directly in
    ``folder`` whose name matches :data:`TEMPORARY` (``.<name>.<random>.tmp``) and that were
    last modified more than ``min_age_s`` seconds ago (a write in progress keeps its file
    fresh). Nothing else is touched; files that cannot be removed are left.

    Returns
    -------
    The files removed.
    """
    folder = Path(folder)
    removed = []
    try:
        entries = list(folder.iterdir())
    except OSError:  # no folder (yet), or not readable: nothing to clean
        return removed
    now = time.time()
    for p in entries:
        if not TEMPORARY.fullmatch(p.name):
            continue
        try:
            st = p.lstat()  # a link or a folder of that name is not ours
            if not stat.S_ISREG(st.st_mode) or now - st.st_mtime < min_age_s:
                continue
            p.unlink()
        except OSError:
            continue
        removed.append(p)
    return sorted(removed)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _fsync_dir(folder: Path) -> None:
    """Make the rename durable (POSIX); a no-op where folders cannot be opened."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


#: longest file name part made from a user's name (most file systems allow 255 bytes)
MAX_NAME = 100


def safe_name(text: str, max_len: int = MAX_NAME) -> str:
    """``text`` made safe as part of a file name: only letters, digits and ``. _ + -`` kept
    (anything else, path separators included, becomes ``_``), no leading dot, and at most
    ``max_len`` characters (a long name is cut and ends with a short hash of the whole, so two
    long names stay different). A name can then never point outside its folder."""
    clean = re.sub(r"[^A-Za-z0-9._+-]", "_", str(text)).lstrip(".") or "_"
    if len(clean) > max_len:
        digest = hashlib.sha1(str(text).encode("utf-8")).hexdigest()[:8]
        clean = clean[: max_len - 9] + "-" + digest
    return clean


def inside(folder: Path | str, path: Path | str) -> Path:
    """``path`` resolved, after checking that it lies in ``folder`` (a guard for every file a
    run writes: nothing is written outside the output folder)."""
    folder, path = Path(folder).resolve(), Path(path).resolve()
    if folder != path and folder not in path.parents:
        raise ValueError(f"{path} is outside the output folder {folder}")
    return path


def check_state_file(path: Path | str, what: str) -> None:
    """Refuse a state file path (``what``, e.g. ``"wear checkpoint"``) that is a folder or
    another non-file: it could be neither read nor written, and the run would fail at its
    first save."""
    path = Path(path)
    if path.exists() and not path.is_file():
        kind = "a folder, not a file" if path.is_dir() else "not a regular file"
        raise InputError(f"the {what} {str(path)!r} is {kind}: move or delete it (the run writes "
                         f"its {what.split()[-1]} there)")


def damaged(path: Path | str, what: str, why: str) -> InputError:
    """The one error of a state file (``what``) that cannot be used: it names the file, says
    why and what to do."""
    return InputError(f"the {what} {str(path)!r} is damaged ({why}); delete it to start the run "
                      "over (a run without --resume also starts over and replaces it)")


#: the array of a state file that holds the SHA-256 of all its other arrays (:func:`seal`)
SEAL = "content_sha256"


def content_digest(arrays: dict) -> str:
    """SHA-256 of the arrays of a state file (every key but :data:`SEAL`, in sorted order:
    name, dtype, shape and bytes of each)."""
    h = hashlib.sha256()
    for k in sorted(arrays):
        if k == SEAL:
            continue
        a = np.ascontiguousarray(arrays[k])
        h.update(f"{k}|{a.dtype.str}|{a.shape}|".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def seal(arrays: dict) -> dict:
    """``arrays`` with :data:`SEAL`: the checksum of their content, checked on reading
    (:func:`check_seal`), so that a state file edited by hand or corrupted in a way its CRCs
    do not catch (a value changed and the archive rewritten) is refused, never resumed."""
    return {**arrays, SEAL: np.asarray(content_digest(arrays))}


def check_seal(data: dict, path: Path | str, what: str) -> None:
    """Refuse (:func:`damaged`) a state file whose :data:`SEAL` is missing or does not match
    its content."""
    stored = data.get(SEAL)
    if stored is None or stored.dtype.kind != "U" or stored.shape != ():
        raise damaged(path, what, "no content checksum")
    if str(stored) != content_digest(data):
        raise damaged(path, what, "its content does not match its checksum: it was edited or "
                      "corrupted after it was written")


def read_archive(path: Path | str, what: str) -> dict:
    """Every array of a ``.npz`` state file (``what``, e.g. ``"wear checkpoint"``), read whole
    so that every member's CRC is checked, with no pickled objects.

    Raises
    ------
    InputError
        One message naming the file: missing, a folder, unreadable, or damaged (truncated,
        empty, altered, another kind of file: :func:`damaged`).
    """
    path = Path(path)
    check_state_file(path, what)
    if not path.is_file():
        raise InputError(f"{what} {str(path)!r} does not exist")
    try:
        with open(path, "rb") as fh:
            complete = zipfile.is_zipfile(fh)  # its end record is there
    except OSError as exc:  # e.g. no permission: not damaged
        raise InputError(f"cannot read the {what} {str(path)!r}: {exc.strerror}") from None
    if not complete:
        raise damaged(path, what, "not a complete .npz archive: truncated, empty or another kind "
                      "of file")
    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}  # reads every member: checks every CRC
    except Exception as exc:  # zip, npy header, EOF, CRC, memory errors: all say "damaged"
        text = " ".join(str(exc).split())
        raise damaged(path, what, f"{type(exc).__name__}: {text}" if text
                      else type(exc).__name__) from None
