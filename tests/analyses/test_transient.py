"""The time-domain analyses ``transient`` and ``incremental-wear`` run from case files.

A small variant of the paper's beam (10 x 2 elements) at 1 kHz, where the time-domain response
becomes periodic within a few tens of periods, keeps each run to a few seconds. The results
files are checked against the tables of docs/results.md (every variable documented in its
analysis' section with the same units and dimensions).
"""

import numpy as np
import pytest
from helpers.cases import FIXED, check_documented, run, small_case

from fretwear.io.results import read_results

TRANSIENT = """[analysis]
type = "transient"
frequency = 1e3
steps_per_period = 256
harmonics = 7
"""
WEAR = """[analysis]
type = "incremental-wear"
steps_per_cycle = 32
n_cycles = 1000
cycle_jump = 100
"""


def test_steady_state_run_writes_documented_results_and_figures(tmp_path, capsys):
    status, out, err = run(small_case(tmp_path, TRANSIENT), capsys)
    assert status == 0, err
    assert "transient at 1 kHz: periodic" in out
    res = tmp_path / "beam-results"
    ds = read_results(res / "results.nc")
    check_documented(ds, "transient")
    assert ds.attrs["classification"] == "periodic"
    assert ds.sizes["tau"] == 256 and ds.sizes["harmonic"] == 7
    assert ds.sizes["time"] == 128  # the periods integrated after the classification
    # the friction energy per node adds up; the energy balance of the scheme holds
    np.testing.assert_allclose(ds["dissipated_energy"].sum(), ds["total_dissipated_energy"])
    assert ds.attrs["energy_residual"] < 1e-6 * float(ds["total_dissipated_energy"])
    # periodic: the friction dissipation over the period (N - 1 steps recorded + the closing
    # step) matches the per-node sum to the share of one step
    e_cum = float(ds["cumulative_friction_dissipation"][-1])
    assert e_cum == pytest.approx(float(ds["total_dissipated_energy"]), rel=2e-2)
    frac = [ds.attrs[f"{n}_fraction"] for n in ("separation", "stick", "slip")]
    assert sum(frac) == pytest.approx(1.0) and 0 < frac[2] < 1  # partial slip
    assert set(np.unique(ds["contact_state"].values)) <= {0, 1, 2}
    # a periodic response: the Poincare samples do not move
    p = ds["poincare_displacement"].sel(point="Pe", axis="x").values
    assert np.ptp(p) < 1e-6 * np.ptp(ds["displacement"].sel(point="Pe", axis="x").values)
    for stem in ("transient-Pe", "poincare-Pe", "contact-state"):
        assert (res / f"{stem}.png").stat().st_size > 10_000, stem


def test_fixed_mode_keeps_every_period(tmp_path, capsys):
    status, out, err = run(small_case(tmp_path, FIXED), capsys)
    assert status == 0, err
    ds = read_results(tmp_path / "beam-results" / "results.nc")
    check_documented(ds, "transient")
    assert ds.attrs["mode"] == "fixed" and ds.attrs["periods"] == 20
    assert ds.sizes["time"] == 20 and ds.sizes["tau"] == 64
    np.testing.assert_allclose(np.diff(ds["time"].values), 1e-3, rtol=1e-9)


def test_steps_must_resolve_the_harmonics(tmp_path, capsys):
    bad = TRANSIENT.replace("steps_per_period = 256", "steps_per_period = 14")
    status, out, err = run(small_case(tmp_path, bad), capsys)
    assert status == 2
    assert "analysis.steps_per_period = 14" in err and "more than 14 steps" in err


def test_incremental_wear_writes_the_wear_history(tmp_path, capsys):
    status, out, err = run(small_case(tmp_path, WEAR), capsys)
    assert status == 0, err
    res = tmp_path / "beam-results"
    ds = read_results(res / "results.nc")
    check_documented(ds, "incremental-wear")
    assert ds.attrs["computed_cycles"] == 11 and ds.attrs["cycle_jump"] == 100
    assert int(ds["cycles"][-1]) == 1000
    w = ds["wear_depth"].values
    assert np.all(np.diff(w, axis=0) >= 0) and w[-1].max() > 0  # wear only grows
    np.testing.assert_allclose(ds["worn_volume"], w @ ds["contact_area"].values, rtol=1e-12)
    # Archard: the worn volume per cycle is k_w / mu times the friction dissipation
    rate = (ds["worn_volume"][-1] - ds["worn_volume"][-2]) / 100
    assert float(rate) == pytest.approx(1e-11 / 0.3 * float(ds["cycle_dissipation"][-1]),
                                        rel=1e-6)
    assert (res / "wear-profile.png").stat().st_size > 10_000
