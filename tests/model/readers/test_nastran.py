"""Nastran DMIG and OP4 readers against files written by pyNastran (tests/data/fe, made by
make_pynastran_files.py there) and by a writer of the documented format (tests/helpers)."""

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import fe_files

from fretwear.errors import InputError
from fretwear.model.readers import read_fe, write_dofmap
from fretwear.model.readers.nastran import nastran_real, read_dmig, read_op4

DATA = Path(__file__).resolve().parents[2] / "data" / "fe"


def spring_chain():
    """The matrices given to pyNastran (the generator's function, without importing
    pyNastran)."""
    rng = np.random.default_rng(32)
    A = rng.standard_normal((10, 10))
    K = (A @ A.T + 10.0 * np.eye(10)) * 1.234567e5
    M = np.diag(1.0 + np.arange(10) / 7.0)
    return K, M, [10, 10, 10, 20, 20, 20, 30, 30, 30, 100], [1, 2, 3, 1, 2, 3, 1, 2, 3, 0]


@pytest.mark.parametrize("name, m_rtol", [("pynastran-dmig-small.bdf", 5e-7),
                                          ("pynastran-dmig-large.bdf", 5e-10)])
def test_dmig_written_by_pynastran(name, m_rtol):
    """K and M (symmetric, one triangle in the file) and the DOF map (grids and a scalar
    point) equal the numbers given to pyNastran, to the digits its fields hold: 10 significant
    digits in 16-character fields (K, double precision: 5e-10 relative, half a unit in the
    last digit), 7 in the 8-character single-precision fields of M in the small-field file
    (5e-7)."""
    K, M, nodes, comps = spring_chain()
    fe = read_fe(DATA / name)
    np.testing.assert_array_equal(fe.dofs.node, sorted(nodes))
    order = np.lexsort((comps, nodes))
    np.testing.assert_array_equal(fe.dofs.component, np.asarray(comps)[order])
    Kp, Mp = K[np.ix_(order, order)], M[np.ix_(order, order)]
    np.testing.assert_allclose(fe.K.toarray(), Kp, rtol=5e-10, atol=0)
    np.testing.assert_allclose(fe.M.toarray(), Mp, rtol=m_rtol, atol=0)
    assert fe.C is None and fe.D is None


def test_op4_written_by_pynastran():
    """ASCII OP4 (dense K columns, sparse M strings): the matrices to the last bit (17 digits)."""
    K, M, _, _ = spring_chain()
    mats = read_op4(DATA / "pynastran-ascii.op4")
    np.testing.assert_array_equal(mats["KAAX"].toarray(), K)
    np.testing.assert_array_equal(mats["MAAX"].toarray(), M)


def test_dmig_and_op4_of_the_documented_format_round_trip(tmp_path):
    """A sparse K with C and D written by the test writer (DMIG: 10 digits; OP4: 17) reads
    back onto the same rows."""
    rng = np.random.default_rng(3)
    A = sp.random(12, 12, density=0.3, random_state=rng)
    K = (A @ A.T + sp.identity(12)).tocsr()
    dofs = fe_files.DofMap(np.repeat([1, 2, 3, 4], 3), np.tile([1, 2, 3], 4))
    fe_files.write_dmig(tmp_path / "se.pch", {"KAAX": K, "MAAX": 2 * K, "BAAX": 3 * K,
                                              "K4AX": 4 * K}, dofs)
    fe = read_fe(tmp_path / "se.pch")
    for got, f in ((fe.K, 1), (fe.M, 2), (fe.C, 3), (fe.D, 4)):
        np.testing.assert_allclose(got.toarray(), f * K.toarray(), rtol=0,
                                   atol=5e-10 * f * abs(K).max())
    fe_files.write_op4(tmp_path / "se.op4", {"KAAX": K, "MAAX": 2 * K})
    write_dofmap(tmp_path / "dofs.txt", dofs)
    fe = read_fe(tmp_path / "se.op4", dofmap=tmp_path / "dofs.txt")
    np.testing.assert_array_equal(fe.K.toarray(), K.toarray())
    np.testing.assert_array_equal(fe.dofs.node, dofs.node)


def test_nastran_reals():
    """Nastran's real fields: implied exponents and D exponents."""
    assert nastran_real("1.5-3", "x") == 1.5e-3
    assert nastran_real("-2.+4", "x") == -2e4
    assert nastran_real("3.25D-03", "x") == 3.25e-3
    assert nastran_real(" 7.", "x") == 7.0


def _one_line(exc):
    text = str(exc.value)
    assert "\n" not in text and "Traceback" not in text
    return text


def test_bad_nastran_files_are_one_line(tmp_path):
    """A truncated DMIG card, complex terms, a term given twice, a missing K name, a binary or
    truncated OP4: one InputError line each."""
    good = (DATA / "pynastran-dmig-large.bdf").read_text().splitlines()
    cut = tmp_path / "cut.bdf"
    cut.write_text("\n".join(good[:-1]) + "\n")  # the last continuation line is lost
    with pytest.raises(InputError) as exc:
        read_fe(cut)
    assert "truncated" in _one_line(exc)
    cplx = tmp_path / "c.bdf"
    cplx.write_text("DMIG    KAAX    0       6       3       3               1\n")
    with pytest.raises(InputError, match="complex") as exc:
        read_fe(cplx)
    _one_line(exc)
    twice = tmp_path / "t.bdf"
    card = lambda *f: "".join(f"{v:<8}" for v in f)  # noqa: E731  (small field)
    twice.write_text("\n".join([card("DMIG", "KAAX", 0, 6, 1, 1, "", 1),
                                card("DMIG", "KAAX", 1, 1, "", 1, 1, "1."),
                                card("DMIG", "KAAX", 1, 1, "", 1, 1, "2.")]) + "\n")
    with pytest.raises(InputError, match="twice"):
        read_dmig(twice)
    only_k = tmp_path / "k.bdf"
    only_k.write_text("\n".join(twice.read_text().splitlines()[:2]) + "\n")
    with pytest.raises(InputError, match=r"no DMIG MAAX \(M\)"):
        read_fe(only_k)
    (tmp_path / "b.op4").write_bytes(b"\x18\x00\x00\x00" + bytes(60))
    with pytest.raises(InputError, match="binary"):
        read_fe(tmp_path / "b.op4", dofmap=fe_files.DofMap([1], [1]))
    lines = (DATA / "pynastran-ascii.op4").read_text().splitlines()
    (tmp_path / "cut.op4").write_text("\n".join(lines[:6]) + "\n")
    with pytest.raises(InputError) as exc:
        read_op4(tmp_path / "cut.op4")
    assert "truncated" in _one_line(exc)
