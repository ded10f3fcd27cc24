"""The cyclic-modes analysis (fretwear.analyses.cyclic_modes) of a case-file sector.

Reference: the eigenfrequencies of the whole disk assembled from N turned copies of the
Python sector of tests/helpers/cyclic.py (fretwear.model.cyclic.whole_disk)."""

from __future__ import annotations

import numpy as np
import pytest

from fretwear.analyses.run import run_case
from fretwear.errors import InputError
from fretwear.io.results import read_results
from fretwear.model.cyclic import whole_disk
from tests.helpers.cases import check_documented
from tests.helpers.cyclic import sector_model, write_sector_case

N, EO = 8, 3


def test_cyclic_modes_analysis_gives_disk_frequencies(tmp_path):
    """``type = "cyclic-modes"``: every frequency of nodal diameters 0 .. N/2 is an
    eigenfrequency of the whole disk (dense generalised eigenproblem of the assembled disk,
    contact free) to 1e-8 relative (rounding of two eigensolvers), and the diagram is
    written; without [cyclic] the analysis is refused in one line."""
    import scipy.linalg as sla

    analysis = '[analysis]\ntype = "cyclic-modes"\nn_modes = 2\n'
    path, _ = write_sector_case(tmp_path, N, EO, analysis=analysis)
    text = path.read_text().replace("figures = false", "figures = true")
    path.write_text(text)
    out = run_case(path, progress=False, echo=False)
    ds = read_results(out.results)
    f = ds["cyclic_frequency"].values
    assert f.shape == (N // 2 + 1, 2) and np.all(np.isfinite(f))
    check_documented(ds, "cyclic-modes")
    assert (tmp_path / "sector-results" / "nodal-diameter-diagram.png").is_file()
    sector, _ = sector_model(N)
    disk = whole_disk(sector)
    free = disk.free_dofs()
    w2 = sla.eigh(disk.K.toarray()[np.ix_(free, free)], disk.M.toarray()[np.ix_(free, free)],
                  eigvals_only=True, subset_by_index=[0, 4 * N])
    f_disk = np.sqrt(w2) / (2 * np.pi)
    assert f.max() < f_disk.max()  # every sector frequency lies within the computed band
    for x in f.reshape(-1):
        assert np.min(np.abs(f_disk - x)) < 1e-8 * x
    path.write_text(text.replace(text[text.index("[cyclic]"):text.index("[analysis]")], ""))
    with pytest.raises(InputError, match=r'^analysis.type = "cyclic-modes": the case has no '):
        run_case(path, progress=False, echo=False)
