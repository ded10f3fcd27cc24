"""The DLFT analyses ``periodic`` and ``sweep`` run from case files through the command line.

A small variant of the paper's beam (10 x 2 elements, 3 harmonics, 32 samples per period) keeps
each run to a few seconds. The results files are checked against the tables of
docs/results.md (every variable written is documented in its analysis' section with the same
units and dimensions); a solve that did not converge must leave no solution in the file.
"""

import re
from pathlib import Path

import meshio
import numpy as np
import pytest

from fretwear import cli
from fretwear.analyses.run import load_case
from fretwear.io.results import read_results

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "src" / "fretwear" / "examples"
LINEAR_EXAMPLE = EXAMPLES / "beam-linear-frf.toml"
DLFT_EXAMPLES = ("salles2011-79khz-periodic", "salles2011-frf", "beam-quasistatic-periodic")

PERIODIC = """[analysis]
type = "periodic"
frequency = 1e4
harmonics = 3
n_samples = 32
"""
SWEEP = """[analysis]
type = "sweep"
f_min = 1e3
f_max = 2e4
n_points = 4
harmonics = 3
n_samples = 32
linear_references = ["sliding", "stuck"]
"""


def small_case(tmp_path: Path, analysis: str, name: str = "beam.toml") -> Path:
    """The shipped beam on a 10 x 2 mesh with another ``[analysis]`` table."""
    text = LINEAR_EXAMPLE.read_text()
    for old, new in {"nx = 30": "nx = 10", "ny = 4 ": "ny = 2 "}.items():
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / name
    path.write_text(text[: text.index("[analysis]")] + analysis)
    return path


def with_key(analysis: str, line: str) -> str:
    """``analysis`` with the key of ``line`` set by ``line`` (replaced or added)."""
    key = line.split("=")[0].strip()
    kept = [x for x in analysis.splitlines() if x.split("=")[0].strip() != key]
    return "\n".join(kept + [line]) + "\n"


def run(path: Path, capsys) -> tuple[int, str, str]:
    status = cli.main(["run", str(path), "--no-progress"])
    out = capsys.readouterr()
    return status, out.out, out.err


# --- the documented schema ------------------------------------------------------------------
def doc_rows(section: str | None = None) -> dict[str, tuple[str, str]]:
    """name -> (dimensions, units) from the tables of docs/results.md: the shared sections
    (dimensions, geometry) and, if given, the section ``## `section```."""
    rows, current = {}, None
    for line in (ROOT / "docs" / "results.md").read_text().splitlines():
        if line.startswith("## "):
            current = line[3:].strip()
        shared = current in ("Rules for every analysis",)
        if not (shared or current == f"`{section}`"):
            continue
        m = re.match(r"\| `(\w+)` \| ([^|]*) \| ([^|]*) \|", line)
        if m:
            rows[m.group(1)] = (m.group(2).strip(), m.group(3).strip())
    return rows


def check_documented(ds, section: str) -> None:
    docs = doc_rows(section)
    for name, var in list(ds.coords.items()) + list(ds.data_vars.items()):
        assert name in docs, f"{name} is not documented in docs/results.md ({section})"
        assert var.attrs["units"] == docs[name][1], name
        assert var.attrs["long_name"], name
    for name, var in ds.data_vars.items():
        assert ", ".join(var.dims) == docs[name][0], name


def test_variable_names_mean_one_thing_across_docs():
    """A name documented twice must have the same units and dimensions, except for the
    documented convention that a wear history records a per-period quantity at every slow step
    under the same name with a leading ``step`` dimension (docs/results.md, rules)."""
    seen = {}
    for line in (ROOT / "docs" / "results.md").read_text().splitlines():
        m = re.match(r"\| `(\w+)` \| ([^|]*) \| ([^|]*) \|", line)
        if m:
            dims, units = m.group(2).strip(), m.group(3).strip()
            dims = dims.removeprefix("step, ") if dims != "step" else dims
            row = (dims, units)
            assert seen.setdefault(m.group(1), row) == row, m.group(1)


# --- periodic -------------------------------------------------------------------------------
def test_periodic_writes_documented_results_figures_and_paraview(tmp_path, capsys):
    status, out, err = run(small_case(tmp_path, PERIODIC), capsys)
    assert status == 0, err
    assert "periodic at 10 kHz: converged" in out
    res = tmp_path / "beam-results"
    ds = read_results(res / "results.nc")
    assert ds.attrs["analysis_type"] == "periodic"
    assert ds.attrs["converged"] == 1
    assert ds.sizes == {"point": 1, "axis": 2, "contact_node": 11, "component": 2,
                        "harmonic_coefficient": 7, "tau": 32, "harmonic": 3}
    check_documented(ds, "periodic")
    for key in ("residual", "iterations", "nfev", "njev", "wall_time", "eps", "solver"):
        assert key in ds.attrs, key
    assert ds.attrs["residual"] <= 1e-8 and ds.attrs["eps"] > 0
    assert ds.attrs["excitation_frequency"] == 1e4
    state = ds["contact_state"]
    assert state.dtype == np.int8 and set(np.unique(state.values)) <= {0, 1, 2}
    assert state.attrs["flag_meanings"] == "separation stick slip"
    # the friction energy per node adds up to the total; the pressure carries the preload
    np.testing.assert_allclose(ds["dissipated_energy"].sum(), ds["total_dissipated_energy"])
    assert float(ds["pressure_mean"].mean()) == pytest.approx(1e4, rel=0.1)
    for stem in ("periodic-Pe", "contact-state", "contact-profiles", "hysteresis"):
        assert (res / f"{stem}.png").stat().st_size > 10_000, stem
    # ParaView: one .vtu per instant; the full field at P_e is the observed displacement
    pvd = (res / "periodic.pvd").read_text()
    files = re.findall(r'file="([^"]+)"', pvd)
    assert len(files) == 32
    m = meshio.read(res / files[7])
    node = np.argmin(np.linalg.norm(m.points[:, :2] - ds["point_position"].values[0], axis=1))
    np.testing.assert_allclose(m.point_data["displacement"][node, :2],
                               ds["displacement"].values[0, :, 7], rtol=1e-8, atol=1e-20)


def test_quasi_static_needs_no_frequency_and_takes_a_list_of_harmonics(tmp_path, capsys):
    analysis = ('[analysis]\ntype = "periodic"\nquasi_static = true\nharmonics = [1, 3]\n'
                "n_samples = 16\n")
    text = small_case(tmp_path, analysis).read_text() + '[output]\nvtu = false\n'
    path = tmp_path / "qs.toml"
    path.write_text(text)
    status, out, err = run(path, capsys)
    assert status == 0, err
    assert "periodic at quasi-static loading: converged" in out
    ds = read_results(tmp_path / "qs-results" / "results.nc")
    assert ds.attrs["quasi_static"] == 1 and ds.attrs["excitation_frequency"] == 1.0
    assert ds["harmonic"].values.tolist() == [1, 3]
    assert ds["harmonic_coefficient"].values.tolist() == ["0", "c1", "c3", "s1", "s3"]
    assert not (tmp_path / "qs-results" / "periodic.pvd").exists()


def test_a_periodic_solve_that_fails_saves_no_solution(tmp_path, capsys):
    path = small_case(tmp_path, with_key(PERIODIC, "max_iter = 1"))
    status, out, err = run(path, capsys)
    assert status == 1
    assert err == ""
    line = next(x for x in out.splitlines() if "did not converge" in x)
    assert line.startswith("periodic solve at 10 kHz did not converge: maximum number of "
                           "iterations reached (relative residual ")
    assert "No solution was saved" in line
    res = tmp_path / "beam-results"
    ds = read_results(res / "results.nc")
    assert ds.attrs["converged"] == 0
    assert len(ds.variables) == 0  # no solution, not even the coordinates
    assert ds.attrs["iterations"] == 1 and ds.attrs["residual"] > 1e-8
    assert not list(res.glob("*.png")) and not (res / "periodic.pvd").exists()


# --- sweep ----------------------------------------------------------------------------------
def test_sweep_writes_documented_results_and_figures(tmp_path, capsys):
    status, out, err = run(small_case(tmp_path, SWEEP), capsys)
    res = tmp_path / "beam-results"
    ds = read_results(res / "results.nc")
    conv = ds["converged"].values
    assert status == (0 if conv.all() else 1), err
    n = ds.sizes["frequency"]
    assert n >= 4 and conv.any()
    assert ds.attrs["sweep_converged"] == f"{int(conv.sum())}/{n}"
    assert out.splitlines()[1] == f"sweep_converged={int(conv.sum())}/{n}"
    check_documented(ds, "sweep")
    assert ds["frequency"].values[[0, -1]].tolist() == pytest.approx([1e3, 2e4])
    assert ds.sizes["interface"] == 2 and ds.sizes["harmonic"] == 3
    amp = ds["response_amplitude"].sel(point="Pe", axis="x", harmonic=1).values
    assert np.all(np.isfinite(amp[conv == 1])) and np.all(amp[conv == 1] > 0)
    # with friction the response lies between the stuck and the frictionless limits
    lin = ds["linear_response_amplitude"].sel(point="Pe", axis="x")
    assert np.all(amp[conv == 1] > lin.sel(interface="stuck").values[conv == 1])
    frac = ds[["separation_fraction", "stick_fraction", "slip_fraction"]].to_array().sum("variable")
    np.testing.assert_allclose(frac.values[conv == 1], 1.0)
    for stem in ("sweep-Pe", "sweep-interface"):
        assert (res / f"{stem}.png").stat().st_size > 10_000, stem


def test_sweep_points_that_fail_are_kept_as_nan_with_the_reason(tmp_path, capsys):
    path = small_case(tmp_path, with_key(with_key(SWEEP, "max_iter = 1"),
                                         "continuation = false"))
    status, out, _ = run(path, capsys)
    assert status == 1
    ds = read_results(tmp_path / "beam-results" / "results.nc")
    bad = ds["converged"].values == 0
    assert bad.any() and ds.attrs["converged"] == 0
    assert np.all(np.isnan(ds["response_amplitude"].values[bad]))
    assert all(f.startswith("not converged: ") for f in ds["flags"].values[bad])
    assert "not converged: maximum number of iterations reached" in out
    assert ds.attrs["flagged_points"].count("\n") == int(bad.sum()) - 1


# --- input errors ---------------------------------------------------------------------------
@pytest.mark.parametrize("line, message", [
    ("n_samples = 6", "analysis.n_samples = 6: expected more than 6 samples per period "
                      "(twice the highest harmonic, 3)"),
    ("frequency = -50.0", "analysis.frequency = -50.0: expected a number > 0"),
    ('solver = "powel"', 'analysis.solver = "powel": expected one of "powell", "newton", '
                         '"hybr" (did you mean "powell"?)'),
    ('eps = "paper"', 'analysis.eps = "paper": expected one of "auto", "static" or a number '
                      "> 0"),
    ("harmonics = 0", "analysis.harmonics = 0: expected an integer >= 1 or a non-empty list "
                      "of integers >= 1 (no repeats)"),
])
def test_bad_periodic_input_gives_one_clear_line(tmp_path, capsys, line, message):
    status, out, err = run(small_case(tmp_path, with_key(PERIODIC, line)), capsys)
    assert status == 2
    assert err == f"error: {message}\n"
    assert not (tmp_path / "beam-results").exists()


def test_frequency_is_required_unless_quasi_static(tmp_path, capsys):
    status, _, err = run(small_case(tmp_path, '[analysis]\ntype = "periodic"\n'), capsys)
    assert status == 2
    assert err.startswith("error: missing required key 'analysis.frequency' (excitation "
                          "frequency [Hz]")
    assert len(err.splitlines()) == 1


def test_sweep_rejects_a_reversed_band_and_aliasing(tmp_path, capsys):
    bad = SWEEP.replace("f_max = 2e4", "f_max = 100.0")
    assert run(small_case(tmp_path, bad), capsys)[2] == (
        "error: analysis.f_max = 100.0: expected a value above f_min = 1000.0 Hz\n")
    bad = SWEEP.replace("harmonics = 3", "harmonics = [1, 3, 16]")
    assert run(small_case(tmp_path, bad), capsys)[2] == (
        "error: analysis.n_samples = 32: expected more than 32 samples per period "
        "(twice the highest harmonic, 16)\n")


# --- shipped examples -----------------------------------------------------------------------
@pytest.mark.parametrize("name", DLFT_EXAMPLES)
def test_examples_share_the_model_of_the_linear_example(name):
    """Same model text (and comments) as beam-linear-frf: the figures compare like with like."""
    def model_part(path):
        text = path.read_text()
        return text[text.index("[model]"): text.index("[analysis]")]

    path = cli.examples()[name]
    assert model_part(path) == model_part(LINEAR_EXAMPLE)
    case = load_case(path)
    assert case.analysis["type"] in ("periodic", "sweep")
    assert case.title.startswith("Salles 2011 section 4.2 beam")
