"""The ``wear`` analysis run from a case file (fretwear.analyses.wear).

The case is the 10 x 2 block of tests/wear/test_simulate.py, quasi-static, 3 harmonics and 32
samples, a few slow steps. The results dataset is compared with the
:class:`~fretwear.wear.WearResult` it was written from (caught on its way out of
``simulate_wear``): same numbers, copied, so compared exactly; units and dimensions with the
``wear`` table of docs/results.md.
"""

import functools

import numpy as np
import pytest
from helpers.cases import WEAR_BLOCK, check_documented

from fretwear import api
from fretwear.analyses.run import run_case
from fretwear.io.results import read_results

CASE = f"""
title = "wear test block"
{WEAR_BLOCK}[analysis]
type = "wear"
quasi_static = true
harmonics = 3
n_samples = 32
tolerance = 0.05
max_cycles = 3e5
checkpoint_every_s = 0.0
[analysis.frf_before_after]
f_min = 2e3
f_max = 3e3
n_points = 3
"""


def test_case_file_run_and_resume(tmp_path):
    """`analysis = "wear"` end to end: results.nc follows the schema (units on every variable,
    dims step/contact_node), figures exist, the checkpoint is there, and --resume of a finished
    run reports it up to date."""
    from fretwear.analyses.run import run_case
    from fretwear.io.results import read_results

    case = tmp_path / "w.toml"
    case.write_text(CASE)
    out = run_case(case, progress=False, echo=False)
    ds = read_results(out.results)
    assert ds.attrs["analysis_type"] == "wear" and ds.attrs["stop_reason"] == "max_cycles"
    for name in ("cycles", "wear_depth", "worn_volume", "pressure_max",
                 "slip_amplitude", "state_fraction", "newton_iterations"):
        assert "units" in ds[name].attrs, name
    assert ds["wear_depth"].dims == ("step", "contact_node")
    assert float(ds["cycles"][-1]) == pytest.approx(3e5)
    assert all(p.is_file() for p in out.figures) and len(out.figures) == 5
    assert ds["frf_amplitude"].dims == ("wear_state", "frequency", "point", "axis")
    assert int(ds["frf_converged"].sum()) == 6
    assert (case.parent / "w-results" / "wear-checkpoint.npz").is_file()
    again = run_case(case, progress=False, echo=False, resume=True)
    assert again.summary == "up to date"


def test_case_file_needs_frequency(tmp_path):
    from fretwear.analyses.run import load_case
    from fretwear.errors import InputError

    case = tmp_path / "w.toml"
    case.write_text(CASE.replace("quasi_static = true", ""))
    with pytest.raises(InputError, match="frequency"):
        load_case(case)


def test_dataset_is_the_wear_result_it_came_from(tmp_path, monkeypatch):
    caught = []
    real = api.simulate_wear  # the driver the analysis calls

    @functools.wraps(real)
    def simulate_wear(*args, **kw):
        caught.append(real(*args, **kw))
        return caught[-1]

    monkeypatch.setattr(api, "simulate_wear", simulate_wear)
    case = tmp_path / "w.toml"
    case.write_text(CASE[: CASE.index("[analysis.frf_before_after]")].replace(
        "max_cycles = 3e5", "max_cycles = 1e5"))
    out = run_case(case, progress=False, echo=False)
    ds = read_results(out.results)
    (result,) = caught
    h = result.history
    assert ds.attrs["stop_reason"] == result.stop_reason == "max_cycles"
    assert bool(ds.attrs["converged"]) == result.success
    check_documented(ds, "wear")  # every variable, coordinate and scalar in docs/results.md
    assert ds.sizes["step"] == h.n_steps  # record_every = 1: every step kept
    for name, field in [("cycles", "cycles"), ("wear_depth", "wear_depth"),
                        ("worn_volume", "worn_volume"), ("pressure_max", "pressure_max"),
                        ("slip_amplitude", "slip_amplitude"),
                        ("dissipated_energy", "friction_energy")]:
        np.testing.assert_array_equal(ds[name].values, np.asarray(getattr(h, field)), name)
    np.testing.assert_array_equal(ds["wear_depth"].values[-1], result.final_wear)
    assert float(ds["penalty"]) == result.penalty
    assert float(ds["cycles"][-1]) == pytest.approx(1e5)
