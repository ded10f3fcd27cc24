"""Files that are complete or absent (fretwear.files): atomic writes and the cleanup of their
temporaries, safe names and the output-folder guard, and the reading of ``.npz`` state files.

References: the documented guarantees of each function, checked against what the operating
system shows (directory listings, the mode of a file made by ``open``) and against numpy's own
writer (``np.savez``) for the archives.
"""

import os
import time
from pathlib import Path

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.files import (
    TEMPORARY,
    atomic_write,
    check_state_file,
    inside,
    read_archive,
    remove_stale_temporaries,
    safe_name,
)

CKPT = "wear-checkpoint.npz"


def test_atomic_write_temporaries_match_the_cleanup_pattern(tmp_path):
    names = []

    def write(tmp: Path):
        names.append(tmp.name)
        tmp.write_text("x")

    atomic_write(tmp_path / "results.nc", write)
    atomic_write(tmp_path / CKPT, write)
    assert all(TEMPORARY.fullmatch(n) for n in names) and len(names) == 2


def test_stale_temporaries_are_removed_and_nothing_else(tmp_path):
    old = time.time() - 120
    files = {
        ".results.nc.abc123.tmp": True,  # stale: removed
        f".{CKPT}.k2j_9xq1.tmp": True,  # stale: removed
        ".results.nc.fresh123.tmp": False,  # a write that may be in progress
        ".results.tmp": False,  # not the pattern (no random part)
        ".results.nc.abc123.tmp.bak": False,
        ".results.nc.ABC123.tmp": False,  # mkstemp draws lowercase
        "results.nc.abc123.tmp": False,  # not hidden
        "notes.txt": False,
    }
    for name in files:
        (tmp_path / name).write_text(name)
        if name != ".results.nc.fresh123.tmp":
            os.utime(tmp_path / name, (old, old))
    (tmp_path / ".dir.abc123.tmp").mkdir()  # a folder of that name: kept
    os.utime(tmp_path / ".dir.abc123.tmp", (old, old))
    (tmp_path / "sub").mkdir()  # only the folder itself is cleaned, not below
    (tmp_path / "sub" / ".results.nc.abc123.tmp").write_text("x")
    os.utime(tmp_path / "sub" / ".results.nc.abc123.tmp", (old, old))
    removed = remove_stale_temporaries(tmp_path)
    assert sorted(p.name for p in removed) == sorted(n for n, gone in files.items() if gone)
    for name, gone in files.items():
        assert (tmp_path / name).exists() is not gone, name
        if not gone:
            assert (tmp_path / name).read_text() == name
    assert (tmp_path / ".dir.abc123.tmp").is_dir()
    assert (tmp_path / "sub" / ".results.nc.abc123.tmp").is_file()
    assert remove_stale_temporaries(tmp_path / "missing") == []



def test_safe_name_rules():
    assert safe_name("Pe") == "Pe"
    assert safe_name("../../x") == "_.._x"
    assert "/" not in safe_name("a/b") and safe_name("a/b") == "a_b"
    long_a, long_b = safe_name("y" * 300 + "a"), safe_name("y" * 300 + "b")
    assert len(long_a) == 100 and long_a != long_b
    assert safe_name("") == "_" and safe_name("...") == "_"


def test_inside_guard(tmp_path):
    assert inside(tmp_path, tmp_path / "a" / "b.png") == (tmp_path / "a" / "b.png").resolve()
    with pytest.raises(ValueError, match="outside the output folder"):
        inside(tmp_path / "out", tmp_path / "out" / ".." / "escape.png")


def test_a_failed_write_keeps_the_old_file_and_leaves_nothing(tmp_path):
    """``write`` raises after writing half a file: the existing target is kept byte for byte
    and the folder holds exactly what it held before (no temporary left behind)."""
    target = tmp_path / "results.nc"
    target.write_bytes(b"the old results")
    before = sorted(p.name for p in tmp_path.iterdir())

    def write(tmp: Path):
        tmp.write_bytes(b"half")
        raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        atomic_write(target, write)
    assert target.read_bytes() == b"the old results"
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_an_atomic_write_has_the_mode_of_an_ordinary_new_file(tmp_path):
    """mkstemp makes its file private (0600); the file written must get the mode ``open``
    gives a new file under the same umask (the operating system's rule, applied here by
    the kernel itself), and the content written, in a folder made on the way."""
    plain = tmp_path / "plain"
    with open(plain, "w") as fh:
        fh.write("x")
    path = atomic_write(tmp_path / "sub" / "out.txt", lambda tmp: tmp.write_text("content"))
    assert path == (tmp_path / "sub" / "out.txt").resolve()
    assert path.read_text() == "content"
    assert path.stat().st_mode & 0o777 == plain.stat().st_mode & 0o777


def test_read_archive_reads_back_what_numpy_wrote_and_refuses_a_damaged_file(tmp_path):
    """Every array of an archive written by ``np.savez`` comes back equal (dtype and values);
    the same archive cut short, an object array (it would need pickle) and a text file are
    each one InputError saying "damaged" and naming the file; a missing file and a folder in
    its place are refused with their own words."""
    arrays = {"W": np.linspace(0.0, 1e-6, 11), "step": np.array(7), "shape": np.arange(3)}
    path = tmp_path / "state.npz"
    np.savez(path, **arrays)
    got = read_archive(path, "wear checkpoint")
    assert set(got) == set(arrays)
    for k, v in arrays.items():
        assert got[k].dtype == v.dtype and np.array_equal(got[k], v), k
    data = path.read_bytes()
    (tmp_path / "cut.npz").write_bytes(data[: len(data) // 2])
    np.savez(tmp_path / "objects.npz", a=np.array([{"x": 1}], dtype=object))
    (tmp_path / "text.npz").write_text("not an archive")
    for name in ("cut.npz", "objects.npz", "text.npz"):
        with pytest.raises(InputError, match=rf"wear checkpoint '.*{name}' is damaged"):
            read_archive(tmp_path / name, "wear checkpoint")
    with pytest.raises(InputError, match="does not exist"):
        read_archive(tmp_path / "none.npz", "wear checkpoint")
    (tmp_path / "folder.npz").mkdir()
    with pytest.raises(InputError, match="is a folder, not a file"):
        read_archive(tmp_path / "folder.npz", "wear checkpoint")
    check_state_file(tmp_path / "none.npz", "wear checkpoint")  # absent: fine, it is made
