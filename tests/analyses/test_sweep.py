"""The DLFT analysis ``sweep`` run from case files through the command line.

The small variant of the paper's beam of tests/helpers/cases.py (10 x 2 elements, 3 harmonics, 32
samples per period, 4 frequencies) keeps each run to a few seconds. The results file is checked
against the tables of docs/results.md; points that did not converge are kept as NaN with the
reason.
"""

import numpy as np
import pytest
from helpers.cases import check_documented, run, small_case, with_key

from fretwear.io.results import read_results

SWEEP = """[analysis]
type = "sweep"
f_min = 1e3
f_max = 2e4
n_points = 4
harmonics = 3
n_samples = 32
linear_references = ["sliding", "stuck"]
"""



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
    assert ds.attrs["warnings"] == ""  # the static preload solve converged
    assert out.splitlines()[1] == f"sweep_converged={int(conv.sum())}/{n}"
    check_documented(ds, "sweep")
    assert ds["frequency"].values[[0, -1]].tolist() == pytest.approx([1e3, 2e4])
    assert ds.sizes["interface"] == 2 and ds.sizes["harmonic"] == 3
    amp = ds["response_amplitude"].sel(point="Pe", axis="x", harmonic=1).values
    assert np.all(np.isfinite(amp[conv == 1])) and np.all(amp[conv == 1] > 0)
    # with friction the response lies between the stuck and the frictionless limits; the
    # linear references have their own fine grid (200 points over the band, log spacing)
    # that holds the sweep's frequencies too
    lf = ds["linear_frequency"].values
    assert ds.sizes["linear_frequency"] >= 200 and np.all(np.diff(lf) > 0)
    assert lf[[0, -1]].tolist() == pytest.approx([1e3, 2e4])
    lin = ds["linear_response_amplitude"].sel(point="Pe", axis="x")
    stuck = lin.sel(interface="stuck", linear_frequency=ds["frequency"].values).values
    assert np.all(amp[conv == 1] > stuck[conv == 1])
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
    # the reason of the last attempt and how many were made (max_iter = 1 starves them all)
    assert "Hz: not converged: " in out and " attempts)" in out
    assert ds.attrs["flagged_points"].count("\n") == int(bad.sum()) - 1


def test_sweep_rejects_a_reversed_band_and_aliasing(tmp_path, capsys):
    bad = SWEEP.replace("f_max = 2e4", "f_max = 100.0")
    assert run(small_case(tmp_path, bad), capsys)[2] == (
        "error: analysis.f_max = 100.0: expected a value above f_min = 1000.0 Hz\n")
    bad = SWEEP.replace("harmonics = 3", "harmonics = [1, 3, 16]")
    assert run(small_case(tmp_path, bad), capsys)[2] == (
        "error: analysis.n_samples = 32: expected more than 32 samples per period "
        "(twice the highest harmonic, 16)\n")


def test_sweep_with_hill_stability(tmp_path, capsys):
    """``hill_stability = true`` adds the documented stability variables: every converged point
    classified (this beam is small enough for the dense Hill problem), its largest
    multiplier consistent with ``stable``, ``det J`` signed, the events and notes as
    attributes; the figure is still written (one harmonic, three frequencies: seconds). The
    reference for the classification itself is tests/hb/test_stability.py (shooting) and
    tests/hb/test_sweep_stability.py."""
    case = SWEEP
    for line in ("hill_stability = true", "n_points = 3", "harmonics = 1", "n_samples = 16"):
        case = with_key(case, line)
    status, out, err = run(small_case(tmp_path, case), capsys)
    res = tmp_path / "beam-results"
    ds = read_results(res / "results.nc")
    check_documented(ds, "sweep")
    conv = ds["converged"].values == 1
    stable = ds["stable"].values
    assert np.all(stable[conv] >= 0) and np.all(stable[~conv] == -1), ds.attrs["stability_notes"]
    rho = ds["floquet_multiplier_max"].values[conv]
    np.testing.assert_array_equal(stable[conv] == 1, rho <= 1 + 1e-6)
    assert np.all(np.abs(ds["jacobian_sign"].values[conv]) == 1)
    assert "branch_events" in ds.attrs and ds.attrs["stability_notes"] == ""
    assert (res / "sweep-Pe.png").stat().st_size > 10_000


def test_condensation_line_says_the_local_bases_and_their_polishes():
    """The summary line of how a sweep's frequencies were condensed, from the counts the sweep
    records (their equality with the condenser's own calls is tested in
    tests/hb/test_local_basis.py): said with every count when the continuation used local
    bases, nothing when every frequency was condensed exactly."""
    from fretwear.analyses.sweep import condensation_line
    from fretwear.hb.sweep_result import SweepResult

    line = condensation_line(SweepResult([], condensations={
        "exact": 210, "nearby": 153, "polished": 22, "polish_failed": 1}))
    assert line.startswith("condensation: 210 exact condensations, 153 frequencies")
    assert "22 recorded points" in line and "1 failed" in line and "1e-06" in line
    assert condensation_line(SweepResult([], condensations={"exact": 40, "nearby": 0})) == ""
    assert condensation_line(SweepResult([])) == ""
