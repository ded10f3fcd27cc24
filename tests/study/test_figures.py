"""The figures of a study (fretwear.study.figures), drawn from ``study.nc`` alone.

References: study datasets built here with known values; what each figure draws is read back
from its matplotlib artists (the lines' data, labels and colours) and compared with the
dataset's values in the figure's units, and the files are checked to be PNG images.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from fretwear.study import figures

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def drawn(monkeypatch):
    """The figures as they are saved: path name -> matplotlib figure."""
    out = {}
    save = figures._save

    def keep(fig, path):
        out[path.name] = fig
        return save(fig, path)

    monkeypatch.setattr(figures, "_save", keep)
    return out


def wear_study() -> xr.Dataset:
    """3 members on 5 cycles and 2 nodes; member 2 stops after cycle index 2, so the last
    cycle every member reached is index 2."""
    vol = np.array([[0, 1, 2, 3, 4], [0, 2, 3, 4, 5], [0, 1, 5, np.nan, np.nan]], float) * 1e-9
    depth = np.stack([vol * 1e3, vol * 2e3], axis=-1)  # (member, cycle, node) [m]
    reached = np.isfinite(vol).sum(axis=0)
    with np.errstate(all="ignore"):
        q = np.nanquantile(vol, (0.05, 0.5, 0.95), axis=0)
        qd = np.nanquantile(depth, (0.05, 0.5, 0.95), axis=0)
    return xr.Dataset({
        "worn_volume_on_cycles": (("member", "cycle"), vol),
        "worn_volume_quantile": (("quantile", "cycle"), q),
        "worn_volume_mean": ("cycle", np.nanmean(vol, axis=0)),
        "members_reached": ("cycle", reached),
        "wear_depth_on_cycles": (("member", "cycle", "contact_node"), depth),
        "wear_depth_quantile": (("quantile", "cycle", "contact_node"), qd),
        "contact_position": (("member", "contact_node", "dim"),
                             np.tile([[0.001, 0.0], [0.002, 0.0]], (3, 1, 1)))},
        coords={"cycle": np.linspace(0.0, 4e6, 5)}, attrs={"title": "t", "members_ok": 3})


def test_wear_figures_draw_the_statistics_in_their_units(tmp_path, drawn):
    """Fan chart: one thin line per member, the median and the mean of the dataset in m^3,
    the axis labelled in mm³ by the figure style (ticks 1e9 x m^3). Profiles: drawn at the
    last cycle every member reached (index 2, found by hand), x in m labelled mm, the median
    in m labelled µm. Both files are PNG images."""
    ds = wear_study()
    paths = figures.study_figures(ds, tmp_path, ["contact.mu"])
    assert [p.name for p in paths] == ["study-worn-volume.png", "study-wear-profiles.png"]
    assert all(p.read_bytes()[:8] == PNG for p in paths)
    ax = drawn["study-worn-volume.png"].axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    assert sum(lb.startswith("_") for lb in lines) == 3  # members, unlabelled
    np.testing.assert_array_equal(lines["median"].get_ydata(),
                                  ds["worn_volume_quantile"].values[1])
    np.testing.assert_array_equal(lines["mean"].get_ydata(), ds["worn_volume_mean"].values)
    assert ax.get_ylabel() == "worn volume [mm³]"
    assert ax.yaxis.get_major_formatter()(4e-9, 0) == "4"
    ax = drawn["study-wear-profiles.png"].axes[0]
    median = next(ln for ln in ax.get_lines() if ln.get_label() == "median")
    np.testing.assert_array_equal(median.get_xdata(), [0.001, 0.002])
    np.testing.assert_array_equal(median.get_ydata(), ds["wear_depth_quantile"].values[1, 2])
    assert ax.get_xlabel() == "x [mm]" and ax.get_ylabel() == "wear depth [µm]"
    assert ax.get_title() == "worn profiles at N = 2e+06"


def sweep_study(joined: bool) -> xr.Dataset:
    f = np.array([1e3, 2e3, 4e3])
    if joined:
        amp = np.array([1e-6, 3e-6, 2e-6])[:, None, None, None] * np.array([1, 10])[:, None]
        return xr.Dataset({"response_amplitude": (("frequency", "point", "axis", "harmonic"),
                                                  amp),
                           "join_frequency": ("join", [2e3, np.nan]),
                           "join_ok": ("join", [0, 0])},
                          coords={"frequency": f, "point": ["Pe"], "axis": ["x", "y"]})
    amp = np.array([[1e-6, 2e-6, 1e-6], [2e-6, 5e-6, 3e-6]])[:, :, None, None, None]
    amp = amp * np.array([1, 10])[:, None]  # axis y larger: the one drawn
    return xr.Dataset({"response_amplitude": (("member", "frequency", "point", "axis",
                                               "harmonic"), amp)},
                      coords={"frequency": f, "point": ["Pe"], "axis": ["x", "y"],
                              "contact.mu": ("member", [0.1, 0.3])}, attrs={"title": "t"})


def test_sweep_family_draws_each_member_on_the_axis_of_largest_response(tmp_path, drawn):
    """One curve per member labelled with its varied key, on the axis with the largest
    amplitude (y, 10 x x), in metres, the axis labelled in µm."""
    ds = sweep_study(joined=False)
    paths = figures.study_figures(ds, tmp_path, ["contact.mu"])
    assert [p.name for p in paths] == ["study-frf-family.png"]
    ax = drawn["study-frf-family.png"].axes[0]
    assert [ln.get_label() for ln in ax.get_lines()] == ["contact.mu = 0.1", "contact.mu = 0.3"]
    for i, ln in enumerate(ax.get_lines()):
        np.testing.assert_array_equal(ln.get_ydata(),
                                      ds["response_amplitude"].values[i, :, 0, 1, 0])
    assert ax.get_ylabel() == "amplitude Pe y [µm]"  # the figure style's prefix


def test_joined_sweep_marks_its_joins_red_where_the_check_failed(tmp_path, drawn):
    """The failed join at 2 kHz is a red dotted line; the unjudged one (NaN) is not drawn."""
    paths = figures.study_figures(sweep_study(joined=True), tmp_path, [])
    assert [p.name for p in paths] == ["study-frf-joined.png"]
    ax = drawn["study-frf-joined.png"].axes[0]
    marks = [ln for ln in ax.get_lines() if ln.get_linestyle() == ":"]
    assert len(marks) == 1 and marks[0].get_color() == "red"
    assert list(marks[0].get_xdata()) == [2e3, 2e3]


def test_periodic_members_draw_their_response_against_the_varied_key(tmp_path, drawn):
    """Members without a frequency axis: one marker per member at its varied value (sorted
    by it), the harmonic-1 amplitude of the first point on its axis of largest response (y,
    10 x x here), in metres; the harmonic-3 values are not drawn."""
    amp = np.array([3e-6, 1e-6, 2e-6])[:, None, None, None] * np.array([1, 10])[:, None]
    amp = amp * np.array([1.0, 0.1])  # harmonics 1, 3
    ds = xr.Dataset({"displacement_harmonic_amplitude": (("member", "point", "axis",
                                                          "harmonic"), amp)},
                    coords={"point": ["Pe"], "axis": ["x", "y"], "harmonic": [1, 3],
                            "contact.mu": ("member", [0.3, 0.1, 0.2])}, attrs={"title": "t"})
    paths = figures.study_figures(ds, tmp_path, ["contact.mu"])
    assert [p.name for p in paths] == ["study-response.png"]
    ax = drawn["study-response.png"].axes[0]
    (line,) = ax.get_lines()
    np.testing.assert_array_equal(line.get_xdata(), [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(line.get_ydata(), amp[[1, 2, 0], 0, 1, 0])
    assert ax.get_xlabel() == "contact.mu" and ax.get_ylabel() == \
        "amplitude Pe y (harmonic 1) [µm]"


def test_linear_frf_members_draw_one_frf_per_member_and_interface(tmp_path, drawn):
    """Linear FRF members (``frf``: ``displacement_amplitude`` over member, interface,
    frequency, point, axis) wrote no study figure; now one curve per member and interface,
    of the first point on its axis of largest response (x here, 10 x y), in the member's
    colour and the interface's dash, with the values of the dataset."""
    f = np.array([100.0, 200.0, 300.0])
    amp = np.arange(1.0, 13.0).reshape(2, 2, 3, 1, 1) * np.array([10.0, 1.0]) * 1e-7
    ds = xr.Dataset({"displacement_amplitude": (("member", "interface", "frequency",
                                                 "point", "axis"), amp)},
                    coords={"frequency": f, "interface": ["sliding", "stuck"], "point": ["tip"],
                            "axis": ["x", "y"], "material.E": ("member", [2.0e11, 2.2e11])},
                    attrs={"title": "t"})
    paths = figures.study_figures(ds, tmp_path, ["material.E"])
    assert [p.name for p in paths] == ["study-frf-family.png"]
    assert paths[0].read_bytes()[:8] == PNG
    lines = drawn["study-frf-family.png"].axes[0].get_lines()
    assert [ln.get_label() for ln in lines] == [
        "material.E = 2e+11, sliding", "material.E = 2e+11, stuck",
        "material.E = 2.2e+11, sliding", "material.E = 2.2e+11, stuck"]
    for k, ln in enumerate(lines):
        np.testing.assert_array_equal(ln.get_ydata(), amp[k // 2, k % 2, :, 0, 0])
    assert lines[0].get_color() == lines[1].get_color() != lines[2].get_color()
    assert lines[0].get_linestyle() != lines[1].get_linestyle()


def test_modes_members_draw_their_natural_frequencies_against_the_varied_key(tmp_path, drawn):
    """Modes members (``natural_frequency`` over member, interface, mode) wrote no study
    figure; now each mode's frequency against the varied key, sorted by it, in Hz (the
    figure's kHz after the style), and no multiplier in the x axis corner."""
    fn = np.array([[[1e3, 3e3]], [[2e3, 5e3]], [[1.5e3, 4e3]]])  # (member, interface, mode)
    ds = xr.Dataset({"natural_frequency": (("member", "interface", "mode"), fn)},
                    coords={"interface": ["stuck"], "mode": [1, 2],
                            "material.E": ("member", [2.0e11, 2.2e11, 2.1e11])},
                    attrs={"title": "t"})
    paths = figures.study_figures(ds, tmp_path, ["material.E"])
    assert [p.name for p in paths] == ["study-natural-frequencies.png"]
    fig = drawn["study-natural-frequencies.png"]
    ax = fig.axes[0]
    lines = ax.get_lines()
    assert len(lines) == 2
    np.testing.assert_array_equal(lines[0].get_xdata(), [2.0e11, 2.1e11, 2.2e11])
    np.testing.assert_array_equal(lines[1].get_ydata(), [3e3, 4e3, 5e3])
    assert ax.get_ylabel() == "natural frequency [kHz]" and ax.get_xlabel() == "material.E"
    fig.canvas.draw()
    assert ax.xaxis.get_offset_text().get_text() == ""

