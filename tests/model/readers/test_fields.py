"""Whole-array conversion of FE-file fields (fretwear.model.readers.fields) against Python's
own float() and int() of the same numbers written out with an explicit E exponent."""

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.model.readers.fields import byte_lines, fixed_fields, integers, reals


def test_nastran_reals_as_arrays():
    """E, D and implied exponents, signs, blanks: the values float() gives the E forms."""
    text = np.array([" 1.5E+3", "1.5D+3", "1.5+3", "-2.5-3", "-.25-12", "7.", "  3.125 ",
                     "-1.234567890123456E-05", "6.02+23"])
    want = [1.5e3, 1.5e3, 1.5e3, -2.5e-3, -0.25e-12, 7.0, 3.125, -1.234567890123456e-05,
            6.02e23]
    np.testing.assert_array_equal(reals(text, "x"), want)
    np.testing.assert_array_equal(integers(np.array([" 12", "", "-3"]), "x"), [12, 0, -3])
    with pytest.raises(InputError, match=r"x: entry 2 \('1\.5Q'\) is not a number"):
        reals(np.array(["1.", "1.5Q"]), "x")
    with pytest.raises(InputError, match="entry 1"):
        integers(np.array(["1.5"]), "y")


def test_fixed_fields_small_and_large():
    """8-character fields, and 16-character ones after a first field with ``*``."""
    lines = ["DMIG    KAAX    1       2               3       4       5.0",
             "DMIG*   KAAX                   10               1",
             "*                     10               12.9659285301D+06"]
    first, f = fixed_fields(byte_lines(lines, 72))
    assert first.tolist() == [b"DMIG", b"DMIG*", b"*"]
    assert f[0].tolist() == [b"KAAX", b"1", b"2", b"", b"3", b"4", b"5.0", b""]
    assert f[1, :4].tolist() == [b"KAAX", b"10", b"1", b""]
    assert f[2, :4].tolist() == [b"10", b"1", b"2.9659285301D+06", b""]
    assert reals(f[2, 2:3], "x")[0] == 2.9659285301e6
