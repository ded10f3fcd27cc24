"""The command line, run as users run it (``python -m fretwear`` in a subprocess).

Runs use the shipped example with few frequencies (or a coarse mesh) so each takes seconds.
The results file is checked against the tables of docs/results.md: every variable written is
documented there with the same units and dimensions.
"""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from fretwear import __version__, cli
from fretwear.io.results import read_results

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "src" / "fretwear" / "examples" / "beam-linear-frf.toml"


def fretwear(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fretwear", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=120)


def reduced_example(tmp_path: Path, analysis: str | None = None, **replace) -> Path:
    """The shipped example with 5 frequencies, ``replace``-d text, or another [analysis]."""
    text = EXAMPLE.read_text()
    for old, new in {"n_points = 600": "n_points = 5", **replace}.items():
        assert old in text
        text = text.replace(old, new)
    if analysis is not None:
        text = text[: text.index("[analysis]")] + analysis
    path = tmp_path / "beam.toml"
    path.write_text(text)
    return path


def documented() -> dict[str, tuple[str, str]]:
    """name -> (dimensions, units) from the tables of docs/results.md."""
    out = {}
    for line in (ROOT / "docs" / "results.md").read_text().splitlines():
        m = re.match(r"\| `(\w+)` \| ([^|]*) \| ([^|]*) \|", line)
        if m:
            out.setdefault(m.group(1), (m.group(2).strip(), m.group(3).strip()))
    return out


def check_documented(ds) -> None:
    docs = documented()
    for name, var in list(ds.coords.items()) + list(ds.data_vars.items()):
        assert name in docs, f"{name} is not documented in docs/results.md"
        assert var.attrs["units"] == docs[name][1], name
        assert var.attrs["long_name"], name
    for name, var in ds.data_vars.items():
        assert ", ".join(var.dims) == docs[name][0], name


def test_version():
    r = fretwear("--version")
    assert r.returncode == 0
    assert r.stdout.strip() == f"fretwear {__version__}"


def test_example_list_and_show():
    r = fretwear("example", "list")
    assert r.returncode == 0
    assert re.search(r"^beam-linear-frf\s+Salles 2011", r.stdout, re.M)
    r = fretwear("example", "show", "beam-linear-frf")
    assert r.returncode == 0
    assert r.stdout == EXAMPLE.read_text()
    r = fretwear("example", "show", "beam-linear")
    assert r.returncode == 2
    assert r.stderr.startswith("error: unknown example 'beam-linear'; expected one of: ")
    assert r.stderr.endswith("(did you mean 'beam-linear-frf'?)\n")
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr


def test_bad_case_gives_one_line_and_status_2(tmp_path):
    path = reduced_example(tmp_path, **{"nu = 0.3": "nu = 0.5"})
    r = fretwear("run", str(path))
    assert r.returncode == 2
    assert r.stderr == "error: material.nu = 0.5: expected a number in (-1, 0.5)\n"
    assert "Traceback" not in r.stdout + r.stderr
    assert not (tmp_path / "beam-results").exists()


def test_error_found_while_building_the_model(tmp_path):
    path = reduced_example(tmp_path, **{'at = "bottom_left"': 'at = "bottom_middle"'})
    r = fretwear("run", str(path))
    assert r.returncode == 2
    assert r.stderr.startswith('error: springs[1].at = "bottom_middle": expected one of ')
    assert len(r.stderr.splitlines()) == 1


def test_run_frf_writes_documented_results_and_figures(tmp_path):
    path = reduced_example(tmp_path)
    r = fretwear("run", str(path), "-o", "out", "--no-progress", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "results:" in r.stdout
    ds = read_results(tmp_path / "out" / "results.nc")
    assert ds.attrs["analysis_type"] == "frf"
    assert ds.attrs["converged"] == 1
    assert ds.attrs["case_file"] == path.read_text()
    assert ds.sizes == {"interface": 2, "frequency": 5, "point": 1, "axis": 2,
                        "contact_node": 31, "component": 2}
    assert ds["frequency"].values[[0, -1]].tolist() == [1.0, 1e5]
    check_documented(ds)
    assert (tmp_path / "out" / "frf-Pe.png").stat().st_size > 10_000


def test_run_modes_writes_paraview_files(tmp_path):
    path = reduced_example(tmp_path, '[analysis]\ntype = "modes"\nn_modes = 3\n',
                           **{"nx = 30": "nx = 10", "ny = 4": "ny = 1"})
    r = fretwear("run", str(path), "--no-progress")
    assert r.returncode == 0, r.stderr
    out = tmp_path / "beam-results"  # default: beside the case file
    ds = read_results(out / "results.nc")
    assert ds.sizes["mode"] == 3 and ds.sizes["dof"] == 2 * 11 * 2
    check_documented(ds)
    for interface in ("sliding", "stuck"):
        assert (out / f"modes-{interface}.png").is_file()
        assert (out / f"modes-{interface}.pvd").is_file()
        assert len(list((out / f"modes-{interface}").glob("mode-*.vtu"))) == 3
    assert (out / "natural-frequencies.png").is_file()


def test_resume_skips_a_complete_run(tmp_path, capsys):
    path = reduced_example(tmp_path)
    assert cli.main(["run", str(path), "--no-progress"]) == 0
    first = (tmp_path / "beam-results" / "results.nc").stat().st_mtime_ns
    capsys.readouterr()
    assert cli.main(["run", str(path), "--no-progress", "--resume"]) == 0
    assert "results are up to date" in capsys.readouterr().out
    assert (tmp_path / "beam-results" / "results.nc").stat().st_mtime_ns == first


def test_ctrl_c_says_what_was_saved(tmp_path, monkeypatch, capsys):
    import fretwear.linear

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(fretwear.linear, "frf", interrupted)
    path = reduced_example(tmp_path)
    assert cli.main(["run", str(path), "--no-progress"]) == 130
    assert capsys.readouterr().err == "interrupted: nothing was saved\n"


def test_sigterm_is_handled_as_ctrl_c(tmp_path, monkeypatch, capsys):
    """SIGTERM (a batch scheduler's notice) stops a run as Ctrl-C does, with the exit status
    128 + 15; the previous handler is back afterwards (wear runs: the checkpoint is saved,
    tests/wear/test_checkpoint.py)."""
    import os
    import signal

    import fretwear.linear

    def terminated(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGTERM)
        raise AssertionError("SIGTERM did not interrupt the run")

    before = signal.getsignal(signal.SIGTERM)
    monkeypatch.setattr(fretwear.linear, "frf", terminated)
    path = reduced_example(tmp_path)
    assert cli.main(["run", str(path), "--no-progress"]) == 143
    assert capsys.readouterr().err == "terminated (SIGTERM): nothing was saved\n"
    assert signal.getsignal(signal.SIGTERM) is before


@pytest.mark.parametrize("argv", [["run"], ["example", "frobnicate"], []])
def test_usage_errors_exit_2_without_traceback(argv):
    r = fretwear(*argv)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and "usage: fretwear" in r.stderr


def test_example_run_writes_beside_the_working_directory(tmp_path, monkeypatch, capsys):
    (tmp_path / "src").mkdir()
    reduced = reduced_example(tmp_path / "src")  # stands for the shipped file
    monkeypatch.setattr(cli, "examples", lambda: {"beam-linear-frf": reduced})
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    assert cli.main(["example", "run", "beam-linear-frf", "--no-progress"]) == 0
    assert (work / "beam-linear-frf-results" / "results.nc").is_file()
    assert not (tmp_path / "src" / "beam-results").exists()  # nothing beside the example


def test_a_wear_run_that_cannot_wear_says_so_in_one_line(tmp_path, monkeypatch, capsys):
    """A wear case whose Archard coefficient is 0 (the default of a contact) stopped at once
    with "no wear" and exit 0, saying nothing else; now a warning says why before the run,
    printed as one line (Python's default format adds the file, the line number and the
    source line). The run itself is replaced by a Ctrl-C here: only what is said before it
    is checked."""
    import fretwear.analyses.wear  # noqa: F401 (reads the defaults of the real driver)
    import fretwear.wear

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(fretwear.wear, "simulate_wear", interrupted)
    analysis = ('[analysis]\ntype = "wear"\nquasi_static = true\nharmonics = 1\n'
                'n_samples = 16\n')
    path = reduced_example(tmp_path, analysis, **{"wear_coefficient = 1e-11": ""})
    assert cli.main(["run", str(path), "--no-progress"]) == 130
    err = capsys.readouterr().err.splitlines()
    said = [line for line in err if "wear_coefficient" in line]
    assert said == ["warning: UnusualValueWarning: contact.wear_coefficient = 0 on every "
                    "contact node (and on their partners): nothing wears under the Archard "
                    "law, and the run will report no wear; give Archard's k_w [1/Pa] "
                    "(metals: 1e-17 to 1e-12)"]
    assert not any(line.startswith(" ") or ".py:" in line for line in err)
