"""The output folder of a run (fretwear.analyses.run: run_case, check_output). Output paths a
hostile user gives: every one gets one clear message before anything is
computed (exit 2, no traceback), and no run ever writes outside its output folder.

Reference: the rules of the command line (docs: README "Using it"): an output folder that
cannot be written is refused before the run starts; names that become file names are made
safe (fretwear.files.safe_name).
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "src" / "fretwear" / "examples" / "beam-linear-frf.toml"


def fretwear(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fretwear", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=120)


def small_case(folder: Path, point: str = "Pe") -> Path:
    """The shipped linear FRF example with 3 frequencies and its observed point renamed."""
    text = EXAMPLE.read_text().replace("n_points = 600", "n_points = 3")
    text = text.replace("\nPe = ", f"\n{point!r} = ".replace("'", '"'), 1)
    path = folder / "case.toml"
    path.write_text(text)
    return path


def refused(r: subprocess.CompletedProcess, *words: str) -> None:
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr
    line = r.stderr.strip()
    assert line.startswith("error:") and "\n" not in line, line
    for w in words:
        assert w in line, line


def test_output_folder_that_is_a_file(tmp_path):
    case = small_case(tmp_path)
    (tmp_path / "taken").write_text("mine")
    refused(fretwear("run", str(case), "-o", str(tmp_path / "taken")), "is a file")
    assert (tmp_path / "taken").read_text() == "mine"


def test_output_folder_under_a_file(tmp_path):
    case = small_case(tmp_path)
    (tmp_path / "taken").write_text("mine")
    refused(fretwear("run", str(case), "-o", str(tmp_path / "taken" / "sub")),
            "a part of the path is a file")


def test_output_folder_name_too_long(tmp_path):
    case = small_case(tmp_path)
    refused(fretwear("run", str(case), "-o", str(tmp_path / ("x" * 300))), "too long")


def test_output_to_dev_null(tmp_path):
    refused(fretwear("run", str(small_case(tmp_path)), "-o", os.devnull), "is a file")


def test_output_folder_without_write_permission(tmp_path):
    """/proc refuses new folders even to root (a permission test with chmod would not hold
    for root, which CI may be)."""
    refused(fretwear("run", str(small_case(tmp_path)), "-o", "/proc/fretwear-out"),
            "cannot write in the output folder")


def test_a_failed_run_leaves_no_empty_output_folder(tmp_path):
    text = small_case(tmp_path).read_text().replace('boundary = "bottom"', 'boundary = "nope"')
    (tmp_path / "case.toml").write_text(text)
    r = fretwear("run", str(tmp_path / "case.toml"), "-o", str(tmp_path / "out"))
    refused(r, "nope")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("point", ["../../../escape", "a/b", "x" * 400])
def test_point_names_never_write_outside_the_output_folder(tmp_path, point):
    work = tmp_path / "work"
    work.mkdir()
    case = small_case(work, point)
    before = {p for p in tmp_path.rglob("*")}
    r = fretwear("run", str(case), "-o", str(work / "out"))
    assert r.returncode == 0, r.stderr
    new = {p for p in tmp_path.rglob("*")} - before
    assert new and all(work / "out" in p.parents or p == work / "out" for p in new), new
    figures = [p for p in (work / "out").iterdir() if p.suffix == ".png"]
    assert figures and all(len(p.name) <= 120 for p in figures)


def test_keys_the_analysis_does_not_read_are_named(tmp_path, capsys):
    """The shipped beam keeps its wear coefficient, unused, outside wear (as the shipped
    examples do), and is given `[output] whole_disk = true`, which only a periodic or wear analysis
    reads. For a modes analysis both are named, each in one line with the analyses that read
    it: the wear coefficient as a note (a property of the interface), whole_disk as a warning
    (an option of the run); so are, for the modes (free vibration of the undamped structure
    with the interface held or free), its damping, its loads and its friction coefficient;
    for a periodic analysis only the wear coefficient is, and `vtu = false` (a switch turned
    off) is not. Reference: the schema's declarations, by hand."""

    from helpers.cases import small_case

    from fretwear.analyses.registry import analysis_tables
    from fretwear.analyses.run import load_case
    from fretwear.io.case import ignored_notes

    modes = '[analysis]\ntype = "modes"\nn_modes = 2\n[output]\nwhole_disk = true\n'
    lines = ignored_notes(load_case(small_case(tmp_path, modes)), analysis_tables())
    assert lines == [
        "note: damping = {loss_factor = 0.001} is not used by a modes analysis (read by every "
        "analysis but modes, cyclic-modes, incremental-wear): it is ignored",
        'note: loads = [{name = "P", boundary = "top", pressure = 10000.0, wavef... is not '
        "used by a modes analysis (read by every analysis but modes, cyclic-modes): it is "
        "ignored",
        "note: contact.mu = 0.3 is not used by a modes analysis (read by every analysis but "
        "modes, frf, cyclic-modes): it is ignored",
        "note: contact.wear_coefficient = 1e-11 is not used by a modes analysis (only by "
        "wear, incremental-wear, worn-state): it is ignored",
        "warning: output.whole_disk = true is not used by a modes analysis (only by "
        "periodic, wear): it is ignored"]
    periodic = ('[analysis]\ntype = "periodic"\nfrequency = 1e4\n[output]\nwhole_disk = true\n'
                'vtu = false\n')
    lines = ignored_notes(load_case(small_case(tmp_path, periodic)), analysis_tables())
    assert lines == ["note: contact.wear_coefficient = 1e-11 is not used by a periodic "
                     "analysis (only by wear, incremental-wear, worn-state): it is ignored"]
