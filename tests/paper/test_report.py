"""What the reproduction report reads off results (fretwear.paper.report): resonance peaks,
which results count, the facts of a wear run, and how they are written.

References: resonance frequencies of a sum of two damped oscillators (analytic), and a wear
run built here whose zero-wear zones, pillar, deepest point, rates and time-domain steps are
known by construction (the definitions of section 4.2 of the paper, as the module states them).
"""

import numpy as np
import pytest
import xarray as xr

from fretwear.paper.report import khz, load, missing, mm_zones, peaks, pillar_text, wear_facts
from fretwear.paper.runs import Outcome


def test_peaks_are_the_resonances_inside_the_band():
    """|H| of two oscillators at 3 and 20 kHz (damping ratio 1 %) plus a third beyond the
    band at 120 kHz (the response rises at the band's end: not a peak). The maxima of an
    isolated oscillator lie at f_i sqrt(1 - 2 zeta^2), 1e-4 below f_i; the grid steps by
    0.35 %: each peak within 0.5 % of f_i. With f_min = 5 kHz only the second remains."""
    f = np.geomspace(1e2, 1e5, 2000)
    w = 2 * np.pi * f
    amp = np.zeros_like(f)
    for fi in (3e3, 2e4, 1.2e5):
        wi = 2 * np.pi * fi
        amp = amp + 1.0 / (wi**2 - w**2 + 2j * 0.01 * wi * w)
    amp = np.abs(amp)
    got = peaks(f, amp)
    assert got.size == 2
    np.testing.assert_allclose(got, [3e3, 2e4], rtol=5e-3)
    np.testing.assert_allclose(peaks(f, amp, f_min=5e3), [2e4], rtol=5e-3)
    holes = amp.copy()
    holes[::7] = np.nan  # failed sweep points are left out, not read as zeros
    np.testing.assert_allclose(peaks(f, holes), [3e3, 2e4], rtol=5e-3)


def _write(path, converged, analysis_type):
    path.parent.mkdir(parents=True)
    ds = xr.Dataset({"x": ("frequency", np.ones(3))}, coords={"frequency": [1.0, 2.0, 3.0]},
                    attrs={"converged": converged, "analysis_type": analysis_type})
    ds.to_netcdf(path, engine="h5netcdf")


def test_load_takes_converged_runs_and_the_points_of_a_sweep(tmp_path):
    """A converged run is a result; a periodic run that did not converge is not; a sweep
    that did not converge everywhere keeps its converged points; a missing or unreadable
    file is no result (None), never an error in the report."""
    _write(tmp_path / "ok" / "results.nc", 1, "periodic")
    _write(tmp_path / "bad" / "results.nc", 0, "periodic")
    _write(tmp_path / "sweep" / "results.nc", 0, "sweep")
    (tmp_path / "text").mkdir()
    (tmp_path / "text" / "results.nc").write_text("not netcdf")
    assert load(tmp_path, "ok") is not None
    assert load(tmp_path, "bad") is None
    assert load(tmp_path, "sweep")["x"].values.tolist() == [1.0, 1.0, 1.0]
    assert load(tmp_path, "text") is None and load(tmp_path, "none") is None


X = np.linspace(0.0, 0.04, 9)  # contact node positions [m], 5 mm apart
W = np.array([0.0, 0.0, 1.0, 2.0, 0.01, 2.0, 1.5, 1.0, 0.5]) * 1e-6  # final wear [m]


def wear_run() -> xr.Dataset:
    """A wear run of 3 steps on 9 nodes: no wear on the first two (next to the spring), a
    node at x = 20 mm that sticks all period under 5 x the mean pressure with 0.5 % of the
    deepest wear between two worn nodes (a pillar), time-domain rates on the last two steps
    and a start from a time integration."""
    nc, steps = X.size, 4
    wear = np.outer(np.linspace(0.0, 1.0, steps), W)
    p = np.full((steps, nc), 1e6)
    p[-1, 4] = 10e6
    state = np.zeros((steps, nc, 3))
    state[..., 2] = 1.0  # slipping all period...
    state[-1, 4] = [0.0, 1.0, 0.0]  # ...but the pillar, stuck
    slip = np.full((steps, nc), 1e-6)
    slip[-1, :3] = 0.0  # at the end a third of the nodes stay still
    return xr.Dataset(
        {"contact_position": (("contact_node", "dim"), np.c_[X, np.zeros(nc)]),
         "wear_depth": (("step", "contact_node"), wear),
         "cycles": ("step", [0.0, 1e3, 1e4, 1e5]),
         "worn_volume_rate": ("step", [4.0, 3.0, 2.0, 1.0]),
         "worn_volume": ("step", [0.0, 1.0, 2.0, 3.0]),
         "pressure_mean": (("step", "contact_node"), p),
         "slip_amplitude": (("step", "contact_node"), slip),
         "state_fraction": (("step", "contact_node", "contact_state"), state),
         "time_domain_start": ("step", [2, 0, 2, 2]),
         "time_domain_response": ("step", [0, 0, 0, 3]),
         "newton_iterations": ("step", [0, 3, 4, 5]),
         "step_wall_time": ("step", [0.0, 0.5, 0.25, 0.25])},
        coords={"contact_state": ["separation", "stick", "slip"]},
        attrs={"stop_reason": "plateau"})


def test_wear_facts_are_those_built_into_the_run():
    """Every fact against its value by construction (exact, or to rounding of a mean)."""
    f = wear_facts(wear_run())
    assert f["zones"] == [[0.0, 0.005], [0.02, 0.02]]  # wear <= 1 % of the deepest
    assert f["spring_zone"] == [0.0, 0.005] and f["pillars"] == [[0.02, 0.02]]
    assert f["pillar_pressure"] == pytest.approx([5.0])  # 10 MPa / mean 2 MPa
    assert len(f["sticking_pillars"]) == 1
    np.testing.assert_allclose(f["sticking_pillars"][0], (0.02, 5.0, 0.005))
    assert f["deepest_x"] == 0.015 and f["deepest"] == 2e-6  # first of the two deepest
    assert (f["cycles"], f["steps"], f["newton"], f["wall"]) == (1e5, 3, 12, 1.0)
    assert f["rate_ratio"] == 0.25 and f["volume"] == 3.0 and f["stop"] == "plateau"
    assert f["moving"] == pytest.approx([1.0, 6 / 9])
    assert (f["td_steps"], f["td_start"], f["first_td"]) == (2, True, 1e4)
    assert f["kinds"] == "periodic 3, quasi-periodic 1"
    text, verdict = pillar_text(f)
    assert verdict == "agrees" and "x = 20.0 mm (5.0 x the mean pressure" in text


def test_no_pillar_when_the_low_node_does_not_stick():
    """The same run with the low node slipping: still a zero-wear zone inside the worn zone
    (the weaker form of the paper's statement), no sticking pillar."""
    ds = wear_run()
    ds["state_fraction"].values[-1, 4] = [0.0, 0.5, 0.5]
    f = wear_facts(ds)
    assert f["sticking_pillars"] == [] and f["pillars"] == [[0.02, 0.02]]
    text, verdict = pillar_text(f)
    assert verdict == "agrees" and text.startswith("zero-wear zone(s) x = 20.0 mm")
    f["pillars"] = []
    assert pillar_text(f) == ("no pillar inside the worn zone", "differs")


def test_words_of_the_report():
    """Exact strings: frequencies in kHz, zones in mm, why a run has no result."""
    assert khz([3e4, 7.05e4]) == "30.0, 70.5 kHz" and khz([]) == "none"
    assert mm_zones([[0.005, 0.005], [0.025, 0.04]]) == "x = 5.0 mm; x = 25.0-40.0 mm"
    assert mm_zones([]) == "none"
    assert missing("frf", {}) == "not run (`frf`)"
    out = {"frf": Outcome("frf", "failed", "boom")}
    assert missing("frf", out) == "no result: run `frf` failed (boom)"
