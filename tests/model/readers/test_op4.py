"""OP4 files, ASCII and binary (fretwear.model.readers.op4), against files written from the
documented format by tests/helpers/fe_files.py::write_op4 (dense columns and sparse strings;
the values are written with 17 digits or as the binary doubles themselves, so the matrices
read back to the last bit) and by pyNastran (tests/data/fe, ASCII). pyNastran 1.4.1's binary
writer is not used: it writes the column headers as doubles and no record-end markers, so its
binary files are not OUTPUT4's format."""

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import fe_files as ff

from fretwear.errors import InputError
from fretwear.model.readers.op4 import read_op4


def _matrices():
    """A banded K with gaps inside its columns (several strings a column) and a diagonal M."""
    rng = np.random.default_rng(4)
    A = sp.random(30, 30, density=0.15, random_state=rng)
    K = (A @ A.T + sp.identity(30)).tocsr()
    M = sp.diags(1.0 + np.arange(30) / 7.0).tocsr()
    return {"KAAX": K, "MAAX": M}


@pytest.mark.parametrize("sparse", [False, True])
@pytest.mark.parametrize("binary", [False, True])
def test_round_trip_to_the_last_bit(tmp_path, sparse, binary):
    """Dense or sparse columns, ASCII or binary: every matrix as written, bit for bit."""
    mats = _matrices()
    ff.write_op4(tmp_path / "m.op4", mats, sparse=sparse, binary=binary)
    got = read_op4(tmp_path / "m.op4")
    assert sorted(got) == sorted(mats)
    for k, A in mats.items():
        assert got[k].shape == A.shape
        np.testing.assert_array_equal(got[k].toarray(), A.toarray())


def test_big_endian_binary(tmp_path):
    """The byte order is found from the 24-byte header record: a big-endian file (every
    4-byte integer and 8-byte double swapped) reads as the little-endian one."""
    K = _matrices()["KAAX"]
    n = K.shape[0]

    def rec(body):
        mark = np.array([len(body)], ">i4").tobytes()
        return mark + body + mark

    data = rec(np.array([n, n, 6, 2], ">i4").tobytes() + b"KAAX    ")
    Kd = K.toarray()
    for j in range(n):
        data += rec(np.array([j + 1, 1, 2 * n], ">i4").tobytes() + Kd[:, j].astype(">f8")
                    .tobytes())
    data += rec(np.array([n + 1, 1, 2], ">i4").tobytes() + np.array([1.0], ">f8").tobytes())
    (tmp_path / "b.op4").write_bytes(data)
    np.testing.assert_array_equal(read_op4(tmp_path / "b.op4")["KAAX"].toarray(), Kd)


def test_bad_binary_files_are_one_line(tmp_path):
    """A truncated binary file, a wrong record marker, a complex matrix: one line each."""
    ff.write_op4(tmp_path / "m.op4", _matrices(), sparse=True, binary=True)
    data = (tmp_path / "m.op4").read_bytes()
    cases = {"cut": data[:len(data) // 2],
             "marker": data[:28] + b"\x07" + data[29:],
             "complex": data[:16] + np.int32(4).tobytes() + data[20:]}
    for what, msg in (("cut", "truncated"), ("marker", "truncated"), ("complex", "complex")):
        (tmp_path / f"{what}.op4").write_bytes(cases[what])
        with pytest.raises(InputError, match=msg) as exc:
            read_op4(tmp_path / f"{what}.op4")
        assert "\n" not in str(exc.value)
