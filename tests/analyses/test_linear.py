"""The linear analyses ``modes`` and ``frf`` (fretwear.analyses.linear) run from case files.

The 10 x 2 variant of the shipped beam (tests/helpers/cases.py), a few modes and frequencies.
The results files are checked against the tables of docs/results.md (every variable written is
documented in its analysis' section with the same units and dimensions), and their numbers
against a direct call of fretwear.linear on the same model (the analysis only copies them:
compared to 1e-12 relative, the rounding of a float64 NetCDF round trip being exact).
"""

import numpy as np
import pytest
from helpers.cases import check_documented, run, small_case

from fretwear.analyses.run import load_case
from fretwear.io.case import build_model
from fretwear.io.results import read_results
from fretwear.linear import frf, modes

MODES = """[analysis]
type = "modes"
n_modes = 4
"""
FRF = """[analysis]
type = "frf"
f_min = 1e3
f_max = 2e4
n_points = 5
"""


def test_modes_writes_documented_results_equal_to_the_linear_modes(tmp_path, capsys):
    status, out, err = run(small_case(tmp_path, MODES), capsys)
    assert status == 0, err
    ds = read_results(tmp_path / "beam-results" / "results.nc")
    check_documented(ds, "modes")
    model = build_model(load_case(tmp_path / "beam.toml"))
    for interface in ds["interface"].values:
        ref = modes(model, 4, interface=str(interface)).frequency_hz
        got = ds["natural_frequency"].sel(interface=interface).values
        np.testing.assert_allclose(got, ref, rtol=1e-12)


def test_frf_writes_documented_results_equal_to_the_linear_frf(tmp_path, capsys):
    path = small_case(tmp_path, FRF)
    status, out, err = run(path, capsys)
    assert status == 0, err
    ds = read_results(tmp_path / "beam-results" / "results.nc")
    check_documented(ds, "frf")
    freqs = ds["frequency"].values
    np.testing.assert_allclose(freqs, np.geomspace(1e3, 2e4, 5), rtol=1e-12)
    model = build_model(load_case(path))
    for interface in ds["interface"].values:
        ref = frf(model, freqs, interface=str(interface)).observed["Pe"]  # (n, d) complex
        amp = ds["displacement_amplitude"].sel(interface=interface, point="Pe")
        amp = amp.transpose("frequency", "axis").values
        np.testing.assert_allclose(amp, np.abs(ref), rtol=1e-12)


@pytest.mark.parametrize("table, message", [
    (FRF.replace("f_max = 2e4", "f_max = 100.0"), "analysis.f_max = 100.0: expected a value "
     "above f_min = 1000.0 Hz"),
    (MODES.replace("n_modes = 4", "n_modes = 0"), "analysis.n_modes = 0: expected an integer "
     ">= 1"),
])
def test_bad_input_gives_one_clear_line(tmp_path, capsys, table, message):
    status, _, err = run(small_case(tmp_path, table), capsys)
    assert status == 2 and err == f"error: {message}\n"
