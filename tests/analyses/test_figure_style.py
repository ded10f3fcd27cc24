"""The figure style (fretwear.analyses.figure_style): SI prefixes in axis units, plain tick
labels, a log frequency axis only for bands over a decade.

References: the SI prefixes by their definition (µ = 1e-6, k = 1e3, mm³ = 1e-9 m³), the
issue's cases (a 900-1100 Hz sweep, micrometre wear depths, "um"), and the tick labels of a
figure drawn here read back from matplotlib.
"""

from __future__ import annotations

import pytest
from matplotlib.figure import Figure

from fretwear.analyses.figure_style import (
    apply_style,
    frequency_scale,
    relabel,
    si_prefix,
    tick_text,
)


@pytest.mark.parametrize("largest, unit, factor, shown", [
    (2.5e-6, "m", 1e6, "µm"),
    (7e3, "Hz", 1e-3, "kHz"),
    (79e3, "Hz", 1e-3, "kHz"),
    (900.0, "Hz", 1.0, "Hz"),
    (3e-10, "m^3", 1e9, "mm³"),
    (4e-3, "m", 1e3, "mm"),
    (0.5, "m", 1e3, "mm"),
    (2e8, "Pa", 1e-6, "MPa"),
    (12.0, "N", 1.0, "N"),
    (3e-4, "J", 1e6, "µJ"),
    (5e4, "m", 1.0, "m"),            # no km for a structure
    (1e-3, "Hz", 1.0, "Hz"),         # no mHz
    (0.0, "m", 1.0, "m"),            # nothing to scale
    (3.0, "1", 1.0, "1"),            # no prefix for a ratio
    (1.0, "um", 1.0, "µm"),
])
def test_si_prefix_gives_numbers_from_1_to_1000(largest, unit, factor, shown):
    """The factor is a power of 1000 (of its cube for m^3) and brings the largest value into
    [1, 1000) where a prefix applies (a volume: the nearest prefix, 3e-10 m³ = 0.3 mm³); the
    unit is written with its prefix."""
    f, u = si_prefix(largest, unit)
    assert f == pytest.approx(factor, rel=1e-12) and u == shown
    if f != 1.0 and "^" not in unit:
        assert 1.0 <= largest * f < 1000.0


def test_frequency_axis_is_log_only_beyond_a_decade():
    assert frequency_scale(900.0, 1100.0) == "linear"
    assert frequency_scale(1e3, 1e4) == "linear"
    assert frequency_scale(1e3, 1.0001e4) == "log"
    assert frequency_scale(0.0, 10.0) == "linear"


def test_labels_and_ticks_read_without_exponents():
    """The unit in brackets takes its prefix, "um" becomes "µm", a label without unit is
    left alone; ticks are plain numbers (no offset, no multiplier)."""
    assert relabel("wear depth [m]", 3e-6) == (pytest.approx(1e6), "wear depth [µm]")
    assert relabel("depth [um]", 3.0) == (1.0, "depth [µm]")
    assert relabel("cycles N", 1e7) == (1.0, "cycles N")
    assert [tick_text(v) for v in (2.5, 0.0, 1200.0, 0.001, 1e-5, 2e7)] == \
        ["2.5", "0", "1200", "0.001", "1e-05", "2e+07"]
    assert tick_text(2.4999999999999996) == "2.5"


def test_a_narrow_sweep_is_drawn_on_a_linear_axis_in_khz_and_microns():
    """A 6-8 kHz band (less than a decade, as the issue's 900-1100 Hz) drawn loglog with
    amplitudes of a few microns: the frequency axis turns linear and reads kHz; the log
    amplitude axis keeps its scale and reads µm (every tick: less than a decade); a linear
    displacement axis reads µm with plain ticks."""
    fig = Figure()
    ax, bx = fig.subplots(1, 2)
    ax.loglog([6e3, 7e3, 8e3], [1e-6, 3e-6, 2e-6])
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("amplitude [m]")
    bx.plot([0.0, 1.0], [-2e-6, 2e-6])
    bx.set_ylabel("u [m]")
    apply_style(fig)
    assert ax.get_xscale() == "linear" and ax.get_xlabel() == "frequency [kHz]"
    assert ax.xaxis.get_major_formatter()(7e3, 0) == "7"
    assert ax.get_yscale() == "log" and ax.get_ylabel() == "amplitude [µm]"
    assert ax.yaxis.get_minor_formatter()(2e-6, 0) == "2"
    assert bx.get_ylabel() == "u [µm]" and bx.yaxis.get_major_formatter()(1.5e-6, 0) == "1.5"
    fig.canvas.draw()
    assert all("e" not in t.get_text() for t in bx.get_yticklabels())


def test_shared_axes_name_the_unit_their_ticks_are_in():
    """Two panels sharing x, only the lower labelled (x in m up to 0.1 m): the shared ticks
    read millimetres and the label says mm (a label never names a unit its ticks are not
    in); a log axis over less than a decade reads its prefixed unit on every tick; an axis
    with a formatter of its own keeps its label's unit."""
    from matplotlib import ticker

    fig = Figure()
    top, low = fig.subplots(2, 1, sharex=True)
    for ax in (top, low):
        ax.plot([0.0, 0.1], [1.0, 2.0])
    low.set_xlabel("x [m]")
    right = fig.add_axes((0.7, 0.7, 0.2, 0.2))
    right.semilogy([1.0, 2.0], [7.8e-10, 7.9e-10])
    right.set_ylabel("|u| [m]")
    right.xaxis.set_major_formatter(ticker.FormatStrFormatter("%.1f"))
    right.set_xlabel("t [s]")
    apply_style(fig)
    assert low.get_xlabel() == "x [mm]" and top.get_xlabel() == ""
    assert low.xaxis.get_major_formatter()(0.1, 0) == "100"
    assert top.xaxis.get_major_formatter()(0.05, 0) == "50"
    assert right.get_ylabel() == "|u| [pm]"
    assert right.yaxis.get_minor_formatter()(7.85e-10, 0) == "785"
    assert right.get_xlabel() == "t [s]" and right.xaxis.get_major_formatter()(2.0, 0) == "2.0"


def test_series_styles_tell_every_curve_apart():
    """The curves of a family get distinct (dash, marker) pairs, widths and marker sizes
    that fall from the first to the last and rising z-order (the earlier curve drawn wider,
    below): the rule that keeps a curve visible under a later one that coincides with it."""
    from fretwear.analyses.figure_style import series_style

    for n in (1, 2, 5, 10):
        styles = [series_style(i, n) for i in range(n)]
        assert len({(s["linestyle"], s["marker"]) for s in styles}) == n
        for a, b in zip(styles[:-1], styles[1:], strict=True):
            assert a["linewidth"] > b["linewidth"] and a["markersize"] > b["markersize"]
            assert a["zorder"] < b["zorder"]
    assert "marker" not in series_style(0, 3, markers=False)
    with pytest.raises(ValueError):
        series_style(3, 3)


def test_coinciding_frfs_before_and_after_wear_both_show(tmp_path):
    """The FRFs before and after wear drawn by the wear analysis, equal to the last bit (a
    wear too small to move them): the first one ("unworn") still shows around the second in
    the written image (its colour covers at least a third as many pixels as the second's).
    Drawn alike, the second hid the first entirely but for its legend line."""
    import matplotlib.image as mpimg
    import numpy as np
    import xarray as xr

    from fretwear.analyses.wear import plot_frf_before_after

    f = np.linspace(900.0, 1100.0, 41)
    y = 1e-6 / np.sqrt((1 - (f / 1e3) ** 2) ** 2 + 0.05**2)
    amp = np.broadcast_to(y[None, :, None, None], (2, f.size, 1, 1))
    ds = xr.Dataset({"frf_amplitude": (("wear_state", "frequency", "point", "axis"), amp)},
                    coords={"wear_state": ["unworn", "worn"], "frequency": f,
                            "point": ["tip"], "axis": ["y"]})
    img = mpimg.imread(plot_frf_before_after(ds, tmp_path / "frf.png", "tip"))[..., :3]

    def pixels(colour):
        rgb = np.array([int(colour[i:i + 2], 16) / 255 for i in (1, 3, 5)])
        return int((np.abs(img - rgb).max(axis=-1) < 0.08).sum())

    first, second = pixels("#1f77b4"), pixels("#ff7f0e")  # C0, C1
    assert second > 0 and first >= second / 3, (first, second)


def test_an_axis_without_unit_has_no_multiplier_in_its_corner():
    """Axes with no unit to prefix and values from 1e6 up (cycles to 1e7, a varied Young's
    modulus 2.0e11-2.1e11 as a study's x axis): matplotlib would print "1e7" or "1e11" in the
    axis corner; each tick says its own value instead (read back from the drawn figure), with
    digits enough to tell 2.025e11 from 2.05e11. Small plain values keep matplotlib's ticks."""
    fig = Figure()
    ax, bx, cx = fig.subplots(1, 3)
    ax.plot([0.0, 1e7], [0.0, 1.0])
    ax.set_xlabel("cycles N")
    bx.plot([2.0e11, 2.1e11], [1.0, 2.0])
    bx.set_xlabel("material.E")
    cx.plot([0.0, 3.0], [0.0, 1.0])
    cx.set_xlabel("member")
    apply_style(fig)
    fig.canvas.draw()
    for axes in (ax, bx):
        assert axes.xaxis.get_offset_text().get_text() == ""
        labels = [t.get_text() for t in axes.get_xticklabels() if t.get_text()]
        assert len(set(labels)) == len(labels) >= 2
        assert all("e+" in t or t == "0" for t in labels)
    assert bx.xaxis.get_major_formatter()(2.025e11, 0) == "2.025e+11"
    from matplotlib import ticker

    assert isinstance(cx.xaxis.get_major_formatter(), ticker.ScalarFormatter)
