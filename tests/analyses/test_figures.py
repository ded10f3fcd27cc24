"""Figures of computed results (fretwear.analyses.figures): what each figure draws, read back
from its matplotlib artists and compared with the dataset it was given, and the geometry
helpers behind the mesh and interface figures.

References: datasets and meshes built here with known values; edges of small meshes counted
by hand; distances between points (an in-plane view of a plane interface must keep them);
the stated scale of a deformed shape. Files are checked to be PNG images.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from fretwear.analyses import figures
from fretwear.model.mesh import box, rectangle

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def drawn(monkeypatch):
    """The figures as they are saved: file name -> matplotlib figure."""
    out = {}
    save = figures.save

    def keep(fig, path, dpi=150):
        out[path.name if hasattr(path, "name") else str(path)] = fig
        return save(fig, path, dpi=dpi)

    monkeypatch.setattr(figures, "save", keep)
    return out


def test_format_frequency_four_significant_digits_in_the_right_unit():
    assert figures.format_frequency(56.987) == "56.99 Hz"
    assert figures.format_frequency(27131.0) == "27.13 kHz"
    assert figures.format_frequency(1.0084e6) == "1.008 MHz"
    assert figures.format_frequency(1e3) == "1 kHz" and figures.format_frequency(0.0) == "0 Hz"


def frf(amplitude: dict) -> xr.Dataset:
    """An frf dataset: interface -> (frequency, axis) amplitudes at one point."""
    names = list(amplitude)
    data = np.stack([amplitude[n] for n in names])[:, :, None, :]
    return xr.Dataset({"displacement_amplitude": (("interface", "frequency", "point", "axis"),
                                                  data)},
                      coords={"interface": names, "frequency": [10.0, 100.0, 1000.0],
                              "point": ["Pe"], "axis": ["x", "y"]})


def test_frf_draws_each_interface_in_its_style_and_leaves_out_what_cannot_be_drawn(tmp_path,
                                                                                 drawn):
    """One panel per axis, one curve per interface with its documented style; a zero
    amplitude is a gap (NaN) on the log scale; an interface with no value at all has no
    curve. The file is a PNG image."""
    amp = {"sliding": np.array([[1e-6, 2e-6], [0.0, 4e-6], [3e-6, 1e-6]]),
           "stuck": np.array([[1e-7, 2e-7], [5e-7, 4e-7], [3e-7, 1e-7]]),
           "free": np.full((3, 2), np.nan)}
    path = figures.plot_frf(frf(amp), tmp_path / "frf.png", "Pe", title="t")
    assert path.read_bytes()[:8] == PNG
    fig = drawn["frf.png"]
    assert len(fig.axes) == 2
    for a, ax in enumerate(fig.axes):
        lines = {ln.get_label(): ln for ln in ax.get_lines()}
        assert set(lines) == {"sliding", "stuck"}
        for name, ln in lines.items():
            y = amp[name][:, a]
            np.testing.assert_array_equal(ln.get_ydata(), np.where(y > 0, y, np.nan))
            assert ln.get_color() == figures.INTERFACE_STYLE[name]["color"]
            assert ln.get_linestyle() == figures.INTERFACE_STYLE[name]["linestyle"]
        assert ax.get_xscale() == "log" and ax.get_yscale() == "log"


def test_a_log_axis_with_nothing_positive_becomes_linear_and_says_so(tmp_path, drawn):
    """Every amplitude zero (e.g. every solve of a sweep failed): a log axis cannot be drawn;
    the panel turns linear and carries the note, and the file is still written."""
    amp = {"sliding": np.zeros((3, 2))}
    figures.plot_frf(frf(amp), tmp_path / "empty.png", "Pe")
    for ax in drawn["empty.png"].axes:
        assert ax.get_yscale() == "linear"
        assert [t.get_text() for t in ax.texts] == ["nothing to draw (no positive value)"]
    assert (tmp_path / "empty.png").read_bytes()[:8] == PNG


def test_natural_frequencies_leave_out_rigid_body_modes_and_count_them(tmp_path, drawn):
    """Frequencies below 1e-6 of the highest are rigid-body modes: not drawn on the log
    scale, counted in the legend (3 here, by construction)."""
    f = np.array([[1e-9, 2e-8, 0.0, 120.0, 450.0], [80.0, 300.0, 900.0, 2e3, 5e3]])
    ds = xr.Dataset({"natural_frequency": (("interface", "mode"), f)},
                    coords={"interface": ["free", "stuck"], "mode": np.arange(1, 6)})
    figures.plot_natural_frequencies(ds, tmp_path / "nf.png")
    lines = drawn["nf.png"].axes[0].get_lines()
    np.testing.assert_array_equal(lines[0].get_ydata(), [120.0, 450.0])
    np.testing.assert_array_equal(lines[0].get_xdata(), [4, 5])
    assert "(3 rigid-body modes" in lines[0].get_label()
    np.testing.assert_array_equal(lines[1].get_ydata(), f[1])
    assert lines[1].get_label() == "stuck"


def test_state_map_shows_each_node_in_order_along_the_interface(tmp_path, drawn):
    """Nodes given out of order along x: the map's columns are the nodes sorted by x, its
    rows the samples of the period (the states as given)."""
    x = np.array([0.3, 0.1, 0.2])
    state = np.array([[2, 2, 0, 0], [1, 1, 1, 1], [1, 2, 2, 1]], dtype=np.int8)
    ds = xr.Dataset({"contact_state": (("contact_node", "tau"), state),
                     "contact_position": (("contact_node", "axis"), np.c_[x, np.zeros(3)])},
                    coords={"axis": ["x", "y"]})
    figures.plot_state_map(ds, tmp_path / "map.png")
    mesh = drawn["map.png"].axes[0].collections[0]
    np.testing.assert_array_equal(np.asarray(mesh.get_array()).reshape(4, 3),
                                  state[[1, 2, 0]].T)


def test_mesh_edges_counted_by_hand():
    """Two quads side by side share one edge: 7 edges; one hexahedron: its 12 edges (from its
    6 boundary faces, each edge shared by two)."""
    assert len(figures._mesh_edges(rectangle(2.0, 1.0, 2, 1))) == 7
    assert len(figures._mesh_edges(box(1.0, 1.0, 1.0, 1, 1, 1))) == 12


def test_deformed_shape_scales_the_largest_displacement_to_the_fraction_of_the_size():
    """Unit square (size = diagonal sqrt 2): the largest displacement (norm 2) becomes
    0.1 sqrt 2; no displacement, no scale (exact up to rounding)."""
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    u = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    moved, scale = figures.deformed(pts, u)
    assert scale == pytest.approx(0.1 * np.sqrt(2) / 2, rel=1e-15)
    assert np.linalg.norm(moved - pts, axis=1).max() == pytest.approx(0.1 * np.sqrt(2))
    still, zero = figures.deformed(pts, np.zeros_like(pts))
    assert zero == 0.0 and np.array_equal(still, pts)


def test_an_inclined_plane_interface_is_drawn_without_distortion():
    """Nodes on a plane tilted in 3D: the in-surface coordinates keep every distance between
    nodes (an isometry of the plane: 1e-12 of the size), and the axis labels name in-plane
    directions (orthogonal to the plane's normal). In 2D the abscissa keeps the distances
    along a straight interface."""
    rng = np.random.default_rng(4)
    e1 = np.array([1.0, 0.0, 1.0]) / np.sqrt(2)
    e2 = np.array([0.0, 1.0, 0.0])
    ab = rng.uniform(-0.01, 0.01, (12, 2))
    p = np.array([0.1, 0.2, 0.3]) + ab @ np.vstack([e1, e2])
    uv, labels = figures.surface_coordinates(p)
    d3 = np.linalg.norm(p[:, None] - p[None], axis=-1)
    d2 = np.linalg.norm(uv[:, None] - uv[None], axis=-1)
    np.testing.assert_allclose(d2, d3, atol=1e-12 * 0.02)
    assert labels[0].startswith("along (") and labels[0].endswith(") [m]")
    line = np.c_[np.linspace(0.0, 0.05, 6), 0.5 * np.linspace(0.0, 0.05, 6)]
    uv2, _ = figures.surface_coordinates(line)
    np.testing.assert_allclose(np.abs(np.diff(uv2[:, 0])), np.hypot(0.01, 0.005), rtol=1e-12)
    assert np.all(uv2[:, 1] == 0.0)


def test_interface_maps_are_for_3d_or_several_interfaces():
    def ds(pos, names):
        return xr.Dataset({"contact_position": (("contact_node", "axis"), pos),
                           "contact_interface": ("contact_node", names)})

    flat = np.c_[np.arange(3.0), np.zeros(3)]
    assert not figures.wants_interface_maps(ds(flat, ["a", "a", "a"]))
    assert figures.wants_interface_maps(ds(flat, ["a", "b", "b"]))
    assert figures.wants_interface_maps(ds(np.c_[flat, np.ones(3)], ["a", "a", "a"]))
