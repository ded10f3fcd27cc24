"""A sweep split into chunks (fretwear.study.sweep_split): the difference at a join and the
chunks joined into one sweep.

References: chunks built here with known values at their shared frequencies (the relative
difference worked out by hand), and the whole band they cut, so that the joined sweep can be
compared point by point with what each chunk holds.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

from fretwear.study.members import Member
from fretwear.study.runner import RESULTS_FILE, MemberRecord
from fretwear.study.sweep_split import join_chunks


def test_a_join_between_different_solutions_is_flagged():
    """join_difference on two constructed chunks: the relative difference it reports is the
    one computed by hand, and a frequency mismatch is NaN."""
    from fretwear.study.sweep_split import join_difference

    def chunk(freqs, amp_end, amp_start):
        amp = np.ones((len(freqs), 1, 2, 1))
        amp[-1, 0, 0, 0], amp[0, 0, 0, 0] = amp_end, amp_start
        return xr.Dataset({"response_amplitude": (("frequency", "point", "axis", "harmonic"),
                                                  amp)}, coords={"frequency": freqs})

    f, d = join_difference(chunk([1.0, 2.0], 4.0, 1.0), chunk([2.0, 3.0], 1.0, 3.0))
    assert f == 2.0 and d == abs(4.0 - 3.0) / 4.0
    assert np.isnan(join_difference(chunk([1.0, 2.0], 1, 1), chunk([2.5, 3.0], 1, 1))[1])


def amplitude(f):
    """The response of a chunk at frequencies ``f``: one point, two axes, one harmonic, an
    arbitrary smooth function of the frequency (any would do: the join copies values)."""
    f = np.asarray(f, float)
    return np.stack([1.0 / (1.0 + f), f**2], axis=-1)[:, None, :, None]


def write_chunk(folder, freqs, first_scale=1.0):
    """A chunk's results file: its sweep, a linear reference on its own finer grid, and a
    scalar. ``first_scale`` multiplies its first point (a join that found another solution)."""
    amp = amplitude(freqs)
    amp[0] *= first_scale
    lf = np.linspace(freqs[0], freqs[-1], 2 * len(freqs) - 1)
    ds = xr.Dataset({"response_amplitude": (("frequency", "point", "axis", "harmonic"), amp),
                     "linear_response_amplitude": ("linear_frequency", lf**3),
                     "model_mass": ((), 2.5)},
                    coords={"frequency": freqs, "linear_frequency": lf})
    folder.mkdir(parents=True)
    ds.to_netcdf(folder / RESULTS_FILE, engine="h5netcdf")


def split(tmp_path, statuses, second_join_scale, rtol=1e-6):
    """Three chunks of the grid 1..7 Hz (1-3, 3-5, 5-7) joined with join_rtol ``rtol``."""
    study = SimpleNamespace(split={"join_rtol": rtol}, title="t", text="", base="base.toml")
    members = [Member(i, {}) for i in range(3)]
    records = [MemberRecord(i, s) for i, s in enumerate(statuses)]
    for m, r, f0 in zip(members, records, (1.0, 3.0, 5.0), strict=True):
        if r.status == "ok":
            write_chunk(tmp_path / m.folder_name, np.arange(f0, f0 + 3.0),
                        second_join_scale if f0 == 5.0 else 1.0)
    return join_chunks(study, members, records, tmp_path)


def test_joined_chunks_are_the_whole_band_once_with_each_join_judged(tmp_path):
    """The joined sweep holds each frequency of the band once, the shared ones from the
    chunk that ends there, with the values of the chunk that computed them (exact copies);
    the first join matches (difference 0); at the second the right chunk starts 1e-3
    higher, a difference of 1e-3 x 25 (the f^2 axis) relative to the larger amplitude
    1.001 x 25, i.e. 1e-3 / 1.001 (to rounding, 1e-9) and beyond join_rtol: flagged. The
    linear references' grids are joined into one increasing grid without repeats; a scalar
    is kept."""
    ds = split(tmp_path, ["ok", "ok", "ok"], 1.001)
    np.testing.assert_array_equal(ds["frequency"].values, np.arange(1.0, 8.0))
    np.testing.assert_array_equal(ds["response_amplitude"].values, amplitude(np.arange(1, 8)))
    np.testing.assert_array_equal(ds["join_frequency"].values, [3.0, 5.0])
    assert ds["join_difference"].values[0] == 0.0
    assert ds["join_difference"].values[1] == pytest.approx(1e-3 / 1.001, rel=1e-9)
    assert ds["join_ok"].values.tolist() == [1, 0]
    lf = ds["linear_frequency"].values
    np.testing.assert_array_equal(lf, np.linspace(1.0, 7.0, 13))
    np.testing.assert_array_equal(ds["linear_response_amplitude"].values, lf**3)
    assert float(ds["model_mass"]) == 2.5
    assert ds.attrs["complete"] == 1 and ds.attrs["joins_ok"] == 0
    assert ds.attrs["chunks"] == 3 and ds.attrs["study_kind"] == "split"
    # the verdict is the comparison with join_rtol: just above the difference it passes
    ds = split(tmp_path / "looser", ["ok", "ok", "ok"], 1.001, rtol=1.0001e-3 / 1.001)
    assert ds["join_ok"].values.tolist() == [1, 1] and ds.attrs["joins_ok"] == 1
    ds = split(tmp_path / "tighter", ["ok", "ok", "ok"], 1.001, rtol=0.9999e-3 / 1.001)
    assert ds["join_ok"].values.tolist() == [1, 0]


def test_a_failed_chunk_leaves_its_part_of_the_band_out(tmp_path):
    """The middle chunk failed: the band has a hole (3 to 5 Hz), both joins are unjudged
    (NaN, not ok) and the sweep is marked incomplete; no point is duplicated."""
    ds = split(tmp_path, ["ok", "failed", "ok"], 1.0)
    np.testing.assert_array_equal(ds["frequency"].values, [1.0, 2.0, 3.0, 5.0, 6.0, 7.0])
    assert np.all(np.isnan(ds["join_frequency"].values))
    assert ds["join_ok"].values.tolist() == [0, 0]
    assert ds["chunk_status"].values.tolist() == ["ok", "failed", "ok"]
    assert ds.attrs["complete"] == 0 and ds.attrs["joins_ok"] == 0
