"""``fretwear reproduce``: resumable runs and the comparison report.

The reproduction's numbers come from the shipped examples (their physics is tested in
tests/test_examples.py); here the driver is checked: a second call reads finished runs back
instead of running them again, a missing run is reported as missing, and the report's figures
agree with the results files it was measured on. The edited case files are checked in
test_catalogue.py.
"""

import numpy as np
import pytest

from fretwear.cli import main
from fretwear.errors import InputError
from fretwear.io.results import read_results
from fretwear.paper.runs import plan, reproduce


def test_plan_orders_runs_and_rejects_unknown_keys():
    keys = plan()
    assert keys.index("frf-worn-79khz") > keys.index("wear-79khz")
    assert plan(["periodic-79khz", "frf"]) == ["frf", "periodic-79khz"]
    with pytest.raises(InputError, match="unknown reproduction run.*bogus"):
        plan(["bogus"])


def test_empty_work_folder_gives_a_report_of_missing_runs(tmp_path):
    """Nothing run: every figure of the paper is listed with "no result", nothing fails."""
    doc = reproduce(tmp_path / "work", tmp_path / "rep.md", only=[], say=lambda s: None)
    text = doc.read_text()
    for fig in ("| 5 |", "| 14 |", "| 16 |", "| 19-21 |", "| 24 |", "| 25 |"):
        assert fig in text
    assert text.count("no result") >= 10


@pytest.mark.slow
def test_quick_runs_resume_and_the_report_matches_the_results(tmp_path):
    """Two quick runs (~10 s): the report states the facts measured on their results files
    (P_e stops 4 times per period at 79 kHz with the shipped numerics, docs/examples.md; no
    wear next to the spring and a plateau in the quasi-static case); a second call finds both
    up to date and runs nothing again."""
    work, doc = tmp_path / "work", tmp_path / "docs" / "reproduction.md"
    lines = []
    only = ["periodic-79khz", "wear-quasistatic"]
    reproduce(work, doc, quick=True, only=only, say=lines.append)
    assert [ln.split()[:2] for ln in lines[:2]] == [["wear-quasistatic", "done"],
                                                     ["periodic-79khz", "done"]]
    text = doc.read_text()
    p79 = read_results(work / "periodic-79khz" / "results.nc")
    stops = int(p79["stops_per_period"].sel(point="Pe").values.ravel()[0])
    assert stops == 4
    assert "79 kHz: 4 stops per period" in text
    qs = read_results(work / "wear-quasistatic" / "results.nc")
    w = qs["wear_depth"].values[-1]
    x = qs["contact_position"].values[:, 0]
    assert w[0] == 0.0 and qs.attrs["stop_reason"] == "plateau"
    assert f"deepest at x = {x[np.argmax(w)] * 1e3:.1f} mm" in text
    for name in ("fig06-13-quasistatic.png", "fig16-pe.png"):
        assert (doc.parent / "reproduction" / name).stat().st_size > 10_000
        assert f"reproduction/{name}" in text
    lines.clear()
    reproduce(work, doc, quick=True, only=only, say=lines.append)
    assert [ln.split()[1] for ln in lines[:2]] == ["up", "up"]  # "up to date"


@pytest.mark.slow
def test_two_jobs_give_the_same_results_as_one(tmp_path):
    """The process pool runs the same case files: same results as a sequential run."""
    only = ["periodic-10khz"]
    reproduce(tmp_path / "a", quick=True, only=only, say=lambda s: None)
    reproduce(tmp_path / "b", quick=True, only=only + ["wear-quasistatic"], jobs=2,
              say=lambda s: None)
    a = read_results(tmp_path / "a" / "periodic-10khz" / "results.nc")
    b = read_results(tmp_path / "b" / "periodic-10khz" / "results.nc")
    np.testing.assert_array_equal(a["displacement"].values, b["displacement"].values)


def test_cli_messages(tmp_path, capsys):
    assert main(["reproduce", "-o", str(tmp_path), "--only", "bogus"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown reproduction run(s) bogus" in err
    assert main(["example", "run", "stromberg1997", "--all"]) == 2
    assert "salles2011 --all" in capsys.readouterr().err
    assert main(["reproduce", "-o", str(tmp_path), "--jobs", "0", "--only", "frf"]) == 2
    assert "jobs = 0" in capsys.readouterr().err
