"""Figures of computed results (matplotlib, files only, no screen).

Each function takes result objects or a results dataset and the path of the figure file,
writes it and returns the path. Common style: :func:`new_figure` and :func:`save` (which
applies :func:`fretwear.analyses.figure_style.apply_style`: SI prefixes in the units, no offset
or multiplier in an axis corner, a linear frequency axis for a band of a decade or less); one
curve per interface with the colours of :data:`INTERFACE_STYLE`; axis labels carry units.
Figures are made with :class:`matplotlib.figure.Figure` directly (rendered by Agg), not
with ``pyplot``: no window, no global backend switch, nothing left open.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from fretwear.analyses.common import cell_edges, interface_abscissa
from fretwear.analyses.figure_style import apply_style, series_style
from fretwear.hb.contact import STATE_NAMES

#: line style of each linear interface, shared by all figures
INTERFACE_STYLE = {  # widest below, so that coinciding references all show
    "free": {"color": "tab:green", "linestyle": ":", "linewidth": 1.2, "zorder": 2.2},
    "sliding": {"color": "tab:blue", "linestyle": "-", "linewidth": 2.6, "zorder": 2.0},
    "stuck": {"color": "tab:red", "linestyle": "--", "linewidth": 1.8, "zorder": 2.1},
}
#: colours of the contact states (separation, stick, slip) in every figure
STATE_COLOURS = ("0.85", "tab:blue", "tab:orange")
AXIS_NAMES = ("x", "y", "z")


def new_figure(nrows: int = 1, ncols: int = 1, *, title: str | None = None,
               panel_size=(5.5, 3.6), sharex: bool = False):
    """A figure with a grid of axes (always a 2D array) and an optional title.

    Parameters
    ----------
    nrows, ncols : grid of panels.
    title : figure title (e.g. the case title).
    panel_size : (width, height) of one panel [inches].
    """
    fig = Figure(figsize=(panel_size[0] * ncols, panel_size[1] * nrows))
    axes = fig.subplots(nrows, ncols, squeeze=False, sharex=sharex)
    if title:
        # long case titles wrap instead of running off the figure
        width = max(40, int(11 * panel_size[0] * ncols))
        fig.suptitle(textwrap.fill(title, width), fontsize="medium")
    return fig, axes


def _guard_log_axes(fig) -> None:
    """A log axis with nothing positive to show (every solve of a sweep failed, a response
    that is exactly zero) cannot be drawn: make it linear and say so on the panel."""
    for ax in fig.axes:
        for which in ("x", "y"):
            if getattr(ax, f"get_{which}scale")() != "log":
                continue
            data = [np.asarray(getattr(ln, f"get_{which}data")(), float).ravel()
                    for ln in ax.get_lines()
                    if ln.get_transform() == ax.transData]  # not markers in axes units
            values = np.concatenate(data) if data else np.zeros(0)
            if not np.any(np.isfinite(values) & (values > 0)):
                getattr(ax, f"set_{which}scale")("linear")
                ax.text(0.5, 0.5, "nothing to draw (no positive value)", ha="center",
                        va="center", transform=ax.transAxes, color="0.4")


def save(fig, path: Path | str, dpi: int = 150) -> Path:
    """Lay out and write ``fig``; the format follows the file extension."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _guard_log_axes(fig)
    apply_style(fig)
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    return path


def format_frequency(f_hz: float) -> str:
    """``"56.99 Hz"``, ``"27.13 kHz"``, ``"1.008 MHz"``: 4 significant digits."""
    for factor, unit in ((1e6, "MHz"), (1e3, "kHz")):
        if abs(f_hz) >= factor:
            return f"{f_hz / factor:.4g} {unit}"
    return f"{f_hz:.4g} Hz"


# --- FRF -------------------------------------------------------------------------------
def plot_frf(ds, path: Path | str, point: str, *, title: str | None = None) -> Path:
    """Amplitude of the FRF at one observed point, log-log, one panel per axis.

    Parameters
    ----------
    ds : an ``frf`` results dataset (``displacement_amplitude`` over interface, frequency,
        point, axis; see ``docs/results.md``).
    path : figure file.
    point : observed point name.
    title : figure title.
    """
    amp = ds["displacement_amplitude"].sel(point=point)
    axes_labels = [str(a) for a in ds["axis"].values]
    fig, axes = new_figure(len(axes_labels), 1, title=title, sharex=True)
    f = ds["frequency"].values
    for ax, axis in zip(axes[:, 0], axes_labels, strict=True):
        for interface in ds["interface"].values:
            y = amp.sel(interface=interface, axis=axis).values
            if np.all(np.isnan(y)):
                continue
            ax.loglog(f, np.where(y > 0, y, np.nan), label=str(interface),
                      **INTERFACE_STYLE.get(str(interface), {}))
        ax.set_ylabel(f"|u_{axis}| at {point} [m]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(title="interface")
    axes[-1, 0].set_xlabel("frequency [Hz]")
    return save(fig, path)


# --- mode shapes -------------------------------------------------------------------------
def _mesh_edges(mesh) -> np.ndarray:
    """Unique cell edges ``(ne, 2)`` of a mesh (for 3D: the edges of its boundary facets)."""
    if mesh.dim == 2:
        k = mesh.cells.shape[1]
        pairs = [(i, (i + 1) % k) for i in range(k)]
        edges = np.vstack([mesh.cells[:, list(p)] for p in pairs])
    else:
        facets = [np.asarray(f) for f in mesh.boundaries.values() if len(f)]
        if not facets:
            return np.zeros((0, 2), dtype=np.int64)
        edges = []
        for f in facets:
            k = f.shape[1]
            edges += [f[:, [i, (i + 1) % k]] for i in range(k)]
        edges = np.vstack(edges)
    return np.unique(np.sort(edges, axis=1), axis=0)


def deformed(points: np.ndarray, displacement: np.ndarray, fraction: float = 0.1):
    """Points moved by ``displacement`` scaled so that its largest value is ``fraction`` of
    the model size; returns ``(moved points, scale factor)``."""
    size = float(np.linalg.norm(np.ptp(points, axis=0)))
    peak = float(np.max(np.linalg.norm(displacement, axis=1))) if displacement.size else 0.0
    scale = fraction * size / peak if peak > 0 else 0.0
    return points + scale * displacement, scale


def _draw_mesh(ax, mesh, points, *, color, lw, fill=None):
    if mesh.dim == 2:
        polys = points[mesh.cells]
        ax.add_collection(PolyCollection(polys, facecolors=fill or "none", edgecolors=color,
                                         linewidths=lw))
    else:  # 3D: projection on the x-y plane of the surface edges
        edges = _mesh_edges(mesh)
        ax.add_collection(LineCollection(points[edges][:, :, :2], colors=color, linewidths=lw))
    ax.autoscale_view()


def plot_mode_shapes(mesh, frequency_hz, shapes, path: Path | str, *, n: int = 6,
                     title: str | None = None) -> Path:
    """Deformed mesh of the first ``n`` modes over the undeformed mesh (grey).

    Parameters
    ----------
    mesh : the model's :class:`~fretwear.model.core.Mesh`.
    frequency_hz : (nm,) natural frequencies [Hz].
    shapes : (nm, ndof) mode shapes with node-major DOFs.
    path : figure file.
    n : number of modes drawn (at most).
    title : figure title.

    Notes
    -----
    Shapes are drawn to a common visual scale (largest displacement 10 % of the model size);
    3D meshes are drawn as their surface edges projected on the x-y plane.
    """
    nm = min(n, len(frequency_hz))
    ncols = min(nm, 2) if nm else 1
    nrows = max(1, -(-nm // ncols))
    size = mesh.points.max(axis=0) - mesh.points.min(axis=0)
    aspect = size[1] / size[0] if size[0] > 0 else 1.0
    panel = (6.0, float(np.clip(6.0 * aspect + 1.8, 2.4, 5.0)))
    fig, axes = new_figure(nrows, ncols, title=title, panel_size=panel)
    for k, ax in enumerate(axes.ravel()):
        if k >= nm:
            ax.set_axis_off()
            continue
        u = np.asarray(shapes[k]).reshape(mesh.points.shape[0], mesh.dim)
        moved, _ = deformed(mesh.points, u)
        _draw_mesh(ax, mesh, mesh.points, color="0.75", lw=0.5)
        _draw_mesh(ax, mesh, moved, color="tab:blue", lw=0.8, fill=(0.12, 0.47, 0.71, 0.15))
        ax.set_aspect("equal")
        ax.set_title(f"mode {k + 1}: {format_frequency(frequency_hz[k])}")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]" if mesh.dim == 2 else "y [m] (surface edges seen along z)")
    return save(fig, path)


def plot_natural_frequencies(ds, path: Path | str, *, title: str | None = None) -> Path:
    """Natural frequencies per interface (a ``modes`` results dataset), log scale.

    Rigid-body modes (below 1e-6 of the highest frequency of the dataset) cannot be drawn on
    a log scale: the legend says how many were left out.
    """
    fig, axes = new_figure(title=title, panel_size=(8.0, 3.6))
    ax = axes[0, 0]
    rigid_below = 1e-6 * float(np.nanmax(ds["natural_frequency"].values, initial=0.0))
    interfaces = ds["interface"].values
    for j, interface in enumerate(interfaces):
        f = ds["natural_frequency"].sel(interface=interface).values
        ok = np.isfinite(f) & (f > rigid_below)
        n_rigid = int(np.sum(np.isfinite(f) & ~ok))
        label = str(interface) + (f"\n({n_rigid} rigid-body modes\nat ~0 Hz not shown)"
                                  if n_rigid else "")
        style = INTERFACE_STYLE.get(str(interface), {})
        ax.semilogy(ds["mode"].values[ok], f[ok], label=label,
                    **{**series_style(j, len(interfaces)), "color": style.get("color"),
                       "linestyle": style.get("linestyle", "-")})
    ax.set_xlabel("mode number")
    ax.set_ylabel("natural frequency [Hz]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(title="interface", loc="upper left", bbox_to_anchor=(1.01, 1.0),
              fontsize="small")
    return save(fig, path)


# --- contact states ----------------------------------------------------------------------
def plot_state_map(ds, path: Path | str, *, title: str | None = None) -> Path:
    """Contact state of every node over one period: separation, stick, slip.

    ``ds`` holds ``contact_state`` (contact_node, tau) and ``contact_position`` (a
    ``periodic`` or ``transient`` results dataset).
    """
    x, xlabel = interface_abscissa(ds)
    order = np.argsort(x, kind="stable")
    n = ds.sizes["tau"]
    t_edges = (np.arange(n + 1) - 0.5) / n
    state = ds["contact_state"].values[order].T  # (N, nc)
    fig, axes = new_figure(title=title, panel_size=(7.5, 4.0))
    ax = axes[0, 0]
    cmap = ListedColormap(STATE_COLOURS)
    ax.pcolormesh(cell_edges(x[order]), t_edges, state, cmap=cmap,
                  norm=BoundaryNorm([-0.5, 0.5, 1.5, 2.5], cmap.N), shading="flat")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("t / T [-] (fraction of the period)")
    handles = [Patch(facecolor=c, edgecolor="0.5", label=s)
               for c, s in zip(STATE_COLOURS, STATE_NAMES, strict=True)]
    ax.legend(handles=handles, title="contact state", loc="upper left",
              bbox_to_anchor=(1.01, 1.0), fontsize="small")
    return save(fig, path)


def surface_coordinates(position: np.ndarray) -> tuple[np.ndarray, list[str]]:
    """In-surface coordinates (n, 2) [m] of the contact nodes of one interface (n, d), and
    the axis labels: the two principal directions of the node cloud (a flank of a 3D
    interface drawn flat, whatever its inclination); in 2D the abscissa along the boundary
    and zero."""
    p = np.asarray(position, dtype=float)
    c = p - p.mean(axis=0)
    _, _, Vt = np.linalg.svd(c, full_matrices=False)
    uv = c @ Vt[:2].T if p.shape[1] == 3 else np.column_stack([c @ Vt[0], np.zeros(len(p))])
    names = ["".join(f"{v:+.2f}{a}" for v, a in zip(row, AXIS_NAMES, strict=False)
                     if abs(v) > 0.005) for row in Vt[:2]]
    return uv, [f"along ({n}) [m]" for n in names]


def wants_interface_maps(ds) -> bool:
    """Maps per interface are drawn for 3D interfaces and for several interfaces (a single
    2D interface has its profiles)."""
    pos = np.asarray(ds["contact_position"].values, dtype=float)
    three_d = pos.shape[1] == 3 and bool(np.all(np.isfinite(pos)))
    return "contact_interface" in ds and (
        three_d or len(set(np.asarray(ds["contact_interface"].values).tolist())) > 1)


def plot_interface_maps(ds, fields, path: Path | str, *, title: str | None = None) -> Path:
    """Maps of nodal quantities over each interface's surface: one row per interface (named by
    ``contact_interface``), one panel per field. 3D interfaces are drawn flat in their own
    principal directions (:func:`surface_coordinates`), each node a dot coloured by its
    value; 2D interfaces as curves along the boundary.

    Parameters
    ----------
    ds : a results dataset with ``contact_position`` and ``contact_interface``.
    fields : list of ``(label, values (nc,), unit)``.
    """
    pos = np.asarray(ds["contact_position"].values, dtype=float)
    pos = pos[:, np.all(np.isfinite(pos), axis=0)]
    names = np.asarray(ds["contact_interface"].values).astype(str)
    order = list(dict.fromkeys(names.tolist()))
    fig, axes = new_figure(len(order), len(fields), title=title, panel_size=(4.4, 3.4))
    for i, name in enumerate(order):
        sel = names == name
        uv, labels = surface_coordinates(pos[sel])
        for j, (label, values, unit) in enumerate(fields):
            ax = axes[i, j]
            v = np.asarray(values, dtype=float)[sel]
            if pos.shape[1] == 3:
                sc = ax.scatter(uv[:, 0], uv[:, 1], c=v, s=28, cmap="viridis")
                fig.colorbar(sc, ax=ax, label=f"{label} [{unit}]")
                ax.set_ylabel(labels[1])
                ax.set_aspect("equal", adjustable="datalim")
            else:
                o = np.argsort(uv[:, 0])
                ax.plot(uv[o, 0], v[o], marker=".")
                ax.set_ylabel(f"{label} [{unit}]")
            ax.set_xlabel(labels[0])
            ax.set_title(f"{name}: {label}", fontsize="small")
            ax.grid(True, alpha=0.3)
    return save(fig, path)
