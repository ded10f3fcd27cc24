"""The figures of a study, drawn from ``study.nc`` alone (so they can be redrawn):

* wear (and incremental-wear) studies: a fan chart of the worn volume against cycles (the
  5-95 % band, the median, the mean and every member thin) and the band of worn profiles at
  the last cycle every member reached;
* sweep studies: the family of FRFs (one curve per member, labelled with its varied keys)
  and their envelope; a split sweep: the joined FRF with the joins marked; a study of the
  excitation level alone (``analysis.excitation_scale``): the FRFs divided by the level on
  one axis and the peak amplitude and frequency against the level;
* periodic and transient studies: the response amplitude of each member (harmonic 1, the
  peak and the RMS over the period) against the first varied numeric key;
* linear FRF studies (``frf``): one FRF per member and interface (first observed point, on
  its axis of largest response);
* modes studies (``modes``): the natural frequencies against the first varied numeric key;
* nonlinear-modes studies: the natural frequency and the damping ratio against the modal
  amplitude, one curve per member (``study-backbones``);
* worn-state studies: each member's final worn profile, labelled with the kind of worn
  state it reached (``study-worn-profiles``);
* cyclic-modes studies: the natural frequencies against the nodal diameter, one colour per
  member and one line style per family (``study-cyclic-frequencies``).

Incremental-wear members get the wear figures (their history has cycles). Members whose
results hold none of these variables with the same shape in every member get no study figure
(the summary says so; each member's own figures are in its folder).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from fretwear.analyses.figure_style import apply_style, frequency_scale
from fretwear.files import atomic_write


def _save(fig, path: Path) -> Path:
    import matplotlib.pyplot as plt

    apply_style(fig)

    def write(tmp: Path) -> None:
        fig.savefig(tmp, format=path.suffix.lstrip("."), dpi=130, bbox_inches="tight")

    try:
        return atomic_write(path, write)
    finally:
        plt.close(fig)


def _figure(*args, **kwargs):
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt.subplots(*args, **kwargs)


def _finish(fig, ax, ds, path: Path, legend: bool, which: str = "major") -> Path:
    """The study's title over ``ax``, its legend where ``legend`` (few enough curves to
    read), the grid (``which`` lines), and the figure saved at ``path``."""
    ax.set_title(ds.attrs.get("title", ""), fontsize=9)
    if legend:
        ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which=which)
    return _save(fig, path)


def fan_chart(ds, path: Path) -> Path:
    """Worn volume against cycles: members, 5-95 % band, median and mean."""
    fig, ax = _figure(figsize=(7, 4.5))
    n = ds["cycle"].values
    for v in ds["worn_volume_on_cycles"].values:
        ax.plot(n, v, color="0.6", lw=0.6)
    q = ds["worn_volume_quantile"].values
    ax.fill_between(n, q[0], q[2], color="C0", alpha=0.3, label="5-95 % of the members")
    ax.plot(n, q[1], color="C0", lw=2, label="median")
    ax.plot(n, ds["worn_volume_mean"].values, color="C1", ls="--", label="mean")
    ax.set_xlabel("cycles N")
    ax.set_ylabel("worn volume [m^3]")
    ax.set_title(f"{ds.attrs.get('title', '')}: {int(ds.attrs.get('members_ok', 0))} members",
                 fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return _save(fig, path)


def profile_band(ds, path: Path) -> Path:
    """Worn profiles at the last cycle every member reached: members, band and median."""
    reached = ds["members_reached"].values
    full = np.flatnonzero(reached == reached.max())
    k = int(full[-1]) if full.size else ds.sizes["cycle"] - 1
    x = ds["contact_position"].values[..., 0] if "contact_position" in ds else \
        np.arange(ds.sizes["contact_node"])
    x = np.nanmean(x, axis=0) if x.ndim == 2 else x
    xs = x
    fig, ax = _figure(figsize=(7, 4.5))
    for w in ds["wear_depth_on_cycles"].values[:, k]:
        ax.plot(xs, w, color="0.6", lw=0.6)
    q = ds["wear_depth_quantile"].values[:, k]
    ax.fill_between(xs, q[0], q[2], color="C0", alpha=0.3, label="5-95 % of the members")
    ax.plot(xs, q[1], color="C0", lw=2, label="median")
    ax.set_xlabel("x [m]" if "contact_position" in ds else "contact node")
    ax.set_ylabel("wear depth [m]")
    ax.set_title(f"worn profiles at N = {float(ds['cycle'].values[k]):.3g}", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return _save(fig, path)


def _main_response(ds):
    """Amplitude of harmonic 1 of the first observed point along its largest axis:
    (member or none, frequency)."""
    amp = ds["response_amplitude"]
    sel = {}
    if "point" in amp.dims:
        sel["point"] = 0
    if "harmonic" in amp.dims:
        sel["harmonic"] = 0
    amp = amp.isel(sel)
    label = f"{str(ds['point'].values[0]) if 'point' in ds else ''}"
    if "axis" in amp.dims:
        with warnings.catch_warnings():  # an axis the point does not have is all NaN
            warnings.simplefilter("ignore", RuntimeWarning)
            largest = np.nanmax(amp.values.reshape(-1, amp.sizes["axis"]), axis=0)
        axis = int(np.nanargmax(np.where(np.isnan(largest), -np.inf, largest)))
        label += f" {str(ds['axis'].values[axis])}"
        amp = amp.isel(axis=axis)
    return amp, label.strip()


def frf_family(ds, path: Path, varied: list[str]) -> Path:
    """One FRF per member (amplitude of harmonic 1), labelled by its varied keys."""
    amp, label = _main_response(ds)
    f = ds["frequency"].values
    fig, ax = _figure(figsize=(7, 4.5))
    for i in range(ds.sizes["member"]):
        ax.plot(f, amp.values[i], lw=1, marker="." if f.size <= 80 else None, ms=3,
                alpha=0.85, label=_member_label(ds, i, varied))
    ax.set_yscale("log")
    ax.set_xscale(frequency_scale(f.min(), f.max()))
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"amplitude {label} [m]")
    return _finish(fig, ax, ds, path, ds.sizes["member"] <= 12, "both")


def joined_frf(ds, path: Path) -> Path:
    """The joined FRF of a split sweep, the joins marked (red where the check failed)."""
    amp, label = _main_response(ds)
    fig, ax = _figure(figsize=(7, 4.5))
    f = ds["frequency"].values
    ax.plot(f, amp.values, lw=1, marker=".", ms=3)
    for fj, ok in zip(ds["join_frequency"].values, ds["join_ok"].values, strict=True):
        if np.isfinite(fj):
            ax.axvline(fj, color="0.5" if ok else "red", lw=0.8, ls=":")
    ax.set_yscale("log")
    if f.size:
        ax.set_xscale(frequency_scale(f.min(), f.max()))
    ax.set_xlabel("frequency [Hz] (dotted: joins of chunks; red: join check failed)")
    ax.set_ylabel(f"amplitude {label} [m]")
    return _finish(fig, ax, ds, path, False, "both")


LEVEL_KEY = "analysis.excitation_scale"


def load_levels(ds, path: Path) -> Path:
    """The family of FRFs over the excitation level: every level's FRF divided by the level
    on one axis (they coincide where the joint is linear: stuck or sliding throughout), and
    the peak amplitude and its frequency against the level."""
    import matplotlib

    amp, label = _main_response(ds)
    levels = ds[LEVEL_KEY].values.astype(float)
    order = np.argsort(levels)
    f = ds["frequency"].values
    fig, axes = _figure(1, 3, figsize=(14, 4.2))
    colours = matplotlib.colormaps["viridis"](np.linspace(0.0, 0.9, max(len(levels), 1)))
    styles = ("-", "--", "-.", ":")
    for k, (c, i) in enumerate(zip(colours, order, strict=False)):
        # coinciding curves (linear levels) stay visible: thinner and dashed on top
        axes[0].plot(f, amp.values[i] / levels[i], color=c, ls=styles[k % 4],
                     lw=max(2.8 - 0.5 * k, 0.8), marker=".", ms=3, zorder=2 + k,
                     label=f"level {levels[i]:.3g}")
    axes[0].set_yscale("log")
    axes[0].set_xscale(frequency_scale(f.min(), f.max()))
    axes[0].set_xlabel("frequency [Hz]")
    axes[0].set_ylabel(f"amplitude {label} / level [m]")
    axes[0].legend(fontsize=7, title="excitation_scale", title_fontsize=7)
    lv, peak = levels[order], ds["peak_response_amplitude"].values[order]
    axes[1].loglog(lv, peak, marker="o", label="peak")
    ok = np.isfinite(peak)
    if ok.any():
        k = int(np.flatnonzero(ok)[0])
        axes[1].loglog(lv, peak[k] * lv / lv[k], color="0.5", ls="--", lw=0.8,
                       label="proportional to the level (linear)")
    axes[1].set_xlabel("excitation level (excitation_scale)")
    axes[1].set_ylabel(f"peak amplitude {label} [m]")
    axes[1].legend(fontsize=7)
    axes[2].semilogx(lv, ds["peak_frequency"].values[order], marker="o")
    axes[2].set_xlabel("excitation level (excitation_scale)")
    axes[2].set_ylabel("peak frequency [Hz]")
    for ax in axes:
        ax.grid(alpha=0.3, which="both")
    fig.suptitle(ds.attrs.get("title", ""), fontsize=9)
    return _save(fig, path)


#: the amplitude of each harmonic of the observed points in a periodic (or transient) result
PERIODIC_RESPONSE = "displacement_harmonic_amplitude"


def _numeric_key(ds, varied: list[str]):
    """The first varied key with one number per member (None: none)."""
    for k in varied:
        if k in ds.coords and ds[k].dims == ("member",) and ds[k].dtype.kind in "fi":
            return k
    return None


def response_per_member(ds, path: Path, varied: list[str]) -> Path:
    """Members without a frequency axis (periodic or transient responses): the amplitude of
    harmonic 1 of the first observed point (on its axis of largest response) against the first
    varied numeric key (the member number when none), one marker per member; with
    ``displacement_peak`` in the dataset, the peak and RMS of that displacement over the
    period beside it."""
    amp = ds[PERIODIC_RESPONSE]
    sel = {d: 0 for d in ("point", "harmonic") if d in amp.dims}
    amp = amp.isel(sel)
    label = str(ds["point"].values[0]) if "point" in ds else ""
    y = amp.values.reshape(ds.sizes["member"], -1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        largest = np.nanmax(y, axis=0)
    if "axis" in amp.dims and np.any(np.isfinite(largest)):
        a = int(np.nanargmax(np.where(np.isnan(largest), -np.inf, largest)))
        y = y[:, a]
        label += f" {str(ds['axis'].values[a])}"
    else:
        a, y = 0, y[:, 0]
    key = _numeric_key(ds, varied)
    x = ds[key].values if key else ds["member"].values
    fig, ax = _figure(figsize=(7, 4.5))
    order = np.argsort(x, kind="stable")
    if "displacement_peak" not in ds:
        ax.plot(x[order], y[order], marker="o", lw=0.8)
        ax.set_ylabel(f"amplitude {label.strip()} (harmonic 1) [m]")
    else:  # the peak and RMS over the period: a response that is not periodic has them too
        sel = {"point": 0, "axis": a} if "axis" in amp.dims else {"point": 0}
        ax.plot(x[order], y[order], marker="o", lw=0.8, label="harmonic 1")
        for name, what in (("displacement_peak", "peak"), ("displacement_rms", "RMS")):
            v = ds[name].isel({d: i for d, i in sel.items() if d in ds[name].dims}).values
            ax.plot(x[order], v[order], marker="s" if what == "peak" else "^", lw=0.8,
                    label=f"{what} over the period (mean apart)")
        ax.set_ylabel(f"displacement {label.strip()} [m]")
        ax.legend(fontsize=7)
    ax.set_xlabel(key or "member")
    return _finish(fig, ax, ds, path, False)


def _member_label(ds, i: int, varied: list[str]) -> str:
    """``key = value, ...`` of member ``i``'s varied keys (``member i`` when none)."""
    text = ", ".join(f"{k} = {ds[k].values[i]:.3g}" if ds[k].dtype.kind == "f"
                     else f"{k} = {ds[k].values[i]}" for k in varied if k in ds.coords
                     and ds[k].dims == ("member",))
    return text or f"member {i}"


def linear_frf_family(ds, path: Path, varied: list[str]) -> Path:
    """Linear FRFs (``frf`` members): the amplitude of the first observed point on its axis
    of largest response, one colour per member, one line style per interface."""
    amp = ds["displacement_amplitude"].isel(point=0)
    label = str(ds["point"].values[0]) if "point" in ds else ""
    with warnings.catch_warnings():  # an axis the point does not have is all NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        largest = np.nanmax(amp.values.reshape(-1, amp.sizes["axis"]), axis=0)
    axis = int(np.nanargmax(np.where(np.isnan(largest), -np.inf, largest)))
    amp = amp.isel(axis=axis)
    f = ds["frequency"].values
    interfaces = [str(v) for v in ds["interface"].values]
    fig, ax = _figure(figsize=(7, 4.5))
    for i in range(ds.sizes["member"]):
        for j, name in enumerate(interfaces):
            ax.plot(f, amp.isel(member=i, interface=j).values, lw=1, color=f"C{i % 10}",
                    ls=("-", "--", ":", "-.")[j % 4],
                    label=f"{_member_label(ds, i, varied)}, {name}")
    ax.set_yscale("log")
    ax.set_xscale(frequency_scale(f.min(), f.max()))
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"amplitude {label} {str(ds['axis'].values[axis])} [m]")
    return _finish(fig, ax, ds, path, ds.sizes["member"] * len(interfaces) <= 12, "both")


def natural_frequencies(ds, path: Path, varied: list[str]) -> Path:
    """Modes members: each natural frequency against the first varied numeric key (the member
    number when none), one colour per mode, one line style per interface."""
    key = _numeric_key(ds, varied)
    x = ds[key].values if key else ds["member"].values
    order = np.argsort(x, kind="stable")
    fn = ds["natural_frequency"]
    fig, ax = _figure(figsize=(7, 4.5))
    for j, name in enumerate(str(v) for v in ds["interface"].values):
        for m in range(fn.sizes["mode"]):
            y = fn.isel(interface=j, mode=m).values
            ax.plot(x[order], y[order], marker="o", lw=0.8, color=f"C{m % 10}",
                    ls=("-", "--", ":", "-.")[j % 4],
                    label=f"{name}, mode {m + 1}" if fn.sizes["mode"] <= 6 else None)
    ax.set_xlabel(key or "member")
    ax.set_ylabel("natural frequency [Hz]")
    return _finish(fig, ax, ds, path, fn.sizes["mode"] <= 6)


def backbones(ds, path: Path, varied: list[str]) -> Path:
    """Nonlinear-modes members: the natural frequency and the damping ratio against the
    modal amplitude (log x), one curve per member labelled with its varied keys."""
    a = ds["member_modal_amplitude"].values
    unit = ds["member_modal_amplitude"].attrs.get("units", "m kg^0.5")
    fig, axes = _figure(2, 1, figsize=(7, 6.5), sharex=True)
    for i in range(ds.sizes["member"]):
        style = {"lw": 1, "marker": ".", "ms": 3, "color": f"C{i % 10}",
                 "label": _member_label(ds, i, varied)}
        axes[0].plot(a[i], ds["backbone_frequency"].values[i], **style)
        axes[1].plot(a[i], ds["damping_ratio"].values[i], **style)
    axes[0].set_ylabel("natural frequency [Hz]")
    axes[1].set_ylabel("damping ratio [-]")
    axes[1].set_xlabel(f"modal amplitude [{unit}]")
    for ax in axes:
        ax.set_xscale("log")
        ax.grid(alpha=0.3, which="both")
    if ds.sizes["member"] <= 12:
        axes[0].legend(fontsize=7)
    axes[0].set_title(ds.attrs.get("title", ""), fontsize=9)
    return _save(fig, path)


def worn_profiles(ds, path: Path, varied: list[str]) -> Path:
    """Worn-state members: each member's final worn profile (its worn state when reached;
    dashed when not), labelled with its varied keys and the kind of state it reached."""
    fig, ax = _figure(figsize=(7, 4.5))
    for i in range(ds.sizes["member"]):
        x = ds["contact_position"].values[i, :, 0] if "contact_position" in ds else \
            np.arange(ds.sizes["contact_node"])
        kind = str(ds["member_worn_state_kind"].values[i])
        w = ds["final_wear_depth"].values[i]
        ax.plot(x[: w.size], w, lw=1, marker=".", ms=3, color=f"C{i % 10}",
                ls="--" if kind == "not_reached" else "-",
                label=f"{_member_label(ds, i, varied)} ({kind or 'failed'})")
    ax.set_xlabel("x [m]" if "contact_position" in ds else "contact node")
    ax.set_ylabel("wear depth [m]")
    return _finish(fig, ax, ds, path, ds.sizes["member"] <= 12)


def cyclic_frequencies(ds, path: Path, varied: list[str]) -> Path:
    """Cyclic-modes members: the natural frequency against the nodal diameter, one colour per
    member (labelled with its varied keys), one line style per family of modes."""
    fn = ds["cyclic_frequency"]
    nd = ds["nodal_diameter"].values if "nodal_diameter" in ds.coords else \
        np.arange(fn.sizes["nodal_diameter"])
    fig, ax = _figure(figsize=(7, 4.5))
    for i in range(ds.sizes["member"]):
        for m in range(fn.sizes["mode"]):
            ax.plot(nd, fn.isel(member=i, mode=m).values, lw=1, marker="o", ms=3,
                    color=f"C{i % 10}", ls=("-", "--", ":", "-.")[m % 4],
                    label=_member_label(ds, i, varied) if m == 0 else None)
    ax.set_xlabel("nodal diameter (line style: family of modes)")
    ax.set_ylabel("natural frequency [Hz]")
    ax.set_xticks(nd)
    return _finish(fig, ax, ds, path, ds.sizes["member"] <= 12)


def study_figures(ds, outdir: Path, varied: list[str], fmt: str = "png") -> list[Path]:
    """Every figure that applies to the dataset; returns the files written."""
    out = []
    if "join_frequency" in ds and "response_amplitude" in ds:
        out.append(joined_frf(ds, outdir / f"study-frf-joined.{fmt}"))
    elif "worn_volume_on_cycles" in ds:
        out.append(fan_chart(ds, outdir / f"study-worn-volume.{fmt}"))
        out.append(profile_band(ds, outdir / f"study-wear-profiles.{fmt}"))
    elif "member_modal_amplitude" in ds and "backbone_frequency" in ds:
        out.append(backbones(ds, outdir / f"study-backbones.{fmt}", varied))
    elif "member_worn_state_kind" in ds:
        out.append(worn_profiles(ds, outdir / f"study-worn-profiles.{fmt}", varied))
    elif "cyclic_frequency" in ds and "member" in ds["cyclic_frequency"].dims:
        out.append(cyclic_frequencies(ds, outdir / f"study-cyclic-frequencies.{fmt}", varied))
    elif PERIODIC_RESPONSE in ds and "member" in ds[PERIODIC_RESPONSE].dims:
        out.append(response_per_member(ds, outdir / f"study-response.{fmt}", varied))
    elif "response_amplitude" in ds and "member" in ds["response_amplitude"].dims:
        out.append(frf_family(ds, outdir / f"study-frf-family.{fmt}", varied))
        if varied == [LEVEL_KEY] and "peak_frequency" in ds:
            out.append(load_levels(ds, outdir / f"study-load-levels.{fmt}"))
    elif "displacement_amplitude" in ds and "member" in ds["displacement_amplitude"].dims \
            and "frequency" in ds["displacement_amplitude"].dims:
        out.append(linear_frf_family(ds, outdir / f"study-frf-family.{fmt}", varied))
    elif "natural_frequency" in ds and "member" in ds["natural_frequency"].dims:
        out.append(natural_frequencies(ds, outdir / f"study-natural-frequencies.{fmt}", varied))
    return out
