"""One results file for a study (fretwear.study.aggregate): the members' results stacked
along ``member``, wear statistics on a common cycle grid, the band of FRFs.

References: members' results files built here with known values; the statistics recomputed
independently (linear interpolation by its formula, numpy's min/max/mean/quantile over the
members that reached a cycle, counted by hand).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import xarray as xr

from fretwear.study.aggregate import N_CYCLES, aggregate
from fretwear.study.members import Member
from fretwear.study.runner import RESULTS_FILE, MemberRecord

STUDY = SimpleNamespace(title="t", kind="ensemble", text="", base="base.toml")


def write(folder, ds):
    folder.mkdir(parents=True)
    ds.to_netcdf(folder / RESULTS_FILE, engine="h5netcdf")


def wear_member(last_cycle, scale, nc=3):
    """A wear run on ``nc`` nodes from 0 to ``last_cycle`` cycles in 4 steps: wear grows like
    ``scale x sqrt(cycles / 1e6) x (1, 2, 3...)`` (any shape would do: the statistics only
    interpolate and compare)."""
    cyc = np.array([0.0, 0.2, 0.6, 1.0]) * last_cycle
    w = scale * np.sqrt(cyc / 1e6)[:, None] * np.arange(1, nc + 1)
    return xr.Dataset({"cycles": ("step", cyc), "wear_depth": (("step", "contact_node"), w),
                       "worn_volume": ("step", w.sum(axis=1) * 1e-6),
                       "contact_position": (("contact_node", "dim"),
                                            np.c_[np.arange(nc) * 1e-3, np.zeros(nc)]),
                       "step_wall_time": ("step", np.ones(4))},
                      attrs={"stop_reason": "max_cycles"})


def test_wear_statistics_are_those_of_the_members_that_reached_each_cycle(tmp_path):
    """Three members reach 1e6, 1e6 and 5e5 cycles; a fourth failed. On the common grid
    (0 to the longest run) each member's worn volume is its own linear interpolation (to
    rounding, 1e-15 relative) and NaN past its end; the statistics at each cycle are numpy's
    mean and 5/50/95 % quantiles (the documented levels) over the members that reached it;
    the failed member is NaN everywhere and keeps its status and message; the varied key is
    a coordinate."""
    values = [1e-11, 2e-11, 3e-11, 4e-11]
    members = [Member(i, {"contact.wear_coefficient": v}) for i, v in enumerate(values)]
    records = [MemberRecord(0, "ok"), MemberRecord(1, "ok"), MemberRecord(2, "ok"),
               MemberRecord(3, "failed", "the mesh is bad")]
    runs = [wear_member(1e6, 1.0e-6), wear_member(1e6, 2.0e-6), wear_member(5e5, 4.0e-6)]
    for m, ds in zip(members, runs, strict=False):
        write(tmp_path / m.folder_name, ds)
    out = aggregate(STUDY, members, records, tmp_path)
    grid = out["cycle"].values
    np.testing.assert_array_equal(grid, np.linspace(0.0, 1e6, N_CYCLES))
    vol = out["worn_volume_on_cycles"].values
    for i, ds in enumerate(runs):
        cyc, v = ds["cycles"].values, ds["worn_volume"].values
        inside = grid <= cyc[-1]
        k = np.clip(np.searchsorted(cyc, grid[inside], side="right") - 1, 0, cyc.size - 2)
        t = (grid[inside] - cyc[k]) / (cyc[k + 1] - cyc[k])
        np.testing.assert_allclose(vol[i, inside], (1 - t) * v[k] + t * v[k + 1], rtol=1e-15,
                                   atol=0)
        assert np.all(np.isnan(vol[i, ~inside]))
    assert np.all(np.isnan(vol[3])) and out["member_status"].values.tolist()[3] == "failed"
    assert out["member_message"].values[3] == "the mesh is bad"
    reached = np.isfinite(vol).sum(axis=0)
    np.testing.assert_array_equal(out["members_reached"].values, reached)
    assert reached[0] == 3 and reached[-1] == 2
    for j in (0, 50, 100, 150, 200):
        live = vol[:3, j][np.isfinite(vol[:3, j])]
        assert out["worn_volume_mean"].values[j] == np.mean(live)
        np.testing.assert_array_equal(out["worn_volume_quantile"].values[:, j],
                                      np.quantile(live, (0.05, 0.5, 0.95)))
    np.testing.assert_array_equal(out["final_cycles"].values[:3], [1e6, 1e6, 5e5])
    np.testing.assert_array_equal(out["final_wear_depth"].values[2],
                                  runs[2]["wear_depth"].values[-1])
    np.testing.assert_array_equal(out["contact.wear_coefficient"].values, values)
    # stacked as is where every member has it, without the wall times
    np.testing.assert_array_equal(out["contact_position"].values[1],
                                  runs[1]["contact_position"].values)
    assert "step_wall_time" not in out and out.attrs["members_failed"] == 1


def test_sweep_members_give_the_band_of_their_frfs(tmp_path):
    """The envelope of the members' response amplitudes is their pointwise min and max
    (NaN points of one member left out); list values and strings of the varied keys become
    per-item variables and labels."""
    f = np.array([1.0, 2.0, 3.0])
    amps = [np.array([1.0, 5.0, 2.0]), np.array([2.0, np.nan, 1.0]), np.array([0.5, 4.0, 3.0])]
    members = [Member(0, {"grid.list": [1.0, 2.0], "grid.kind": "a"}),
               Member(1, {"grid.list": [3.0], "grid.kind": "b"}),
               Member(2, {"grid.list": [5.0, 6.0], "grid.kind": "c"})]
    records = [MemberRecord(i, "ok") for i in range(3)]
    for m, a in zip(members, amps, strict=True):
        write(tmp_path / m.folder_name, xr.Dataset({"response_amplitude": ("frequency", a)},
                                                   coords={"frequency": f}))
    out = aggregate(STUDY, members, records, tmp_path)
    stack = np.stack(amps)
    np.testing.assert_array_equal(out["response_amplitude_min"].values, np.nanmin(stack, 0))
    np.testing.assert_array_equal(out["response_amplitude_max"].values, np.nanmax(stack, 0))
    np.testing.assert_array_equal(out["frequency"].values, f)
    np.testing.assert_array_equal(out["grid.list"].values,
                                  [[1.0, 2.0], [3.0, np.nan], [5.0, 6.0]])
    assert out["grid.kind"].values.tolist() == ["a", "b", "c"]
