"""The style every figure of fretwear gets before it is written (:func:`apply_style`, called by
:func:`fretwear.analyses.figures.save` and the study figures):

* units in axis labels with SI prefixes: an axis labelled ``[m]`` whose values are microns is
  relabelled ``[µm]`` and its ticks read 0.5, 1, 1.5 (:func:`si_prefix`); ``m^3`` becomes
  ``mm³``, ``um`` becomes ``µm``; no offset and no multiplier (``1e-9``) in an axis corner;
* a frequency axis on a log scale only when its band spans more than one decade
  (:func:`frequency_scale`): a 900-1100 Hz sweep is drawn on a linear axis.

* the curves of one family on the same axes (profiles at several cycle counts, the FRFs
  before and after wear, linear references, modes) never hide one another
  (:func:`series_style`): each has its own marker and dash pattern, and the earlier ones are
  drawn wider, with larger open markers, below the later ones, so that where two curves
  coincide the earlier shows as a band and rings around the later.

The rules are pure functions of numbers and strings, so they are tested without drawing.
"""

from __future__ import annotations

import math
import re

#: SI prefixes from pico to giga: exponent of ten -> symbol
PREFIXES = {-12: "p", -9: "n", -6: "µ", -3: "m", 0: "", 3: "k", 6: "M", 9: "G"}
#: units that take a prefix (the base of a power: m^3 -> mm³)
PREFIXED_UNITS = ("m", "Hz", "Pa", "N", "J", "s", "W", "N/m")
_POWERS = {"2": "²", "3": "³"}
_UNIT = re.compile(r"\[([^\[\]]+)\]\s*$")


def si_prefix(largest: float, unit: str) -> tuple[float, str]:
    """The factor that turns values of ``unit`` whose largest magnitude is ``largest`` into
    numbers from 1 to 1000 with an SI prefix (for a power, the nearest prefix of its base),
    and the prefixed unit: ``(1e6, "µm")`` for
    ``(2.5e-6, "m")``, ``(1e-3, "kHz")`` for ``(7e3, "Hz")``, ``(1e9, "mm³")`` for
    ``(3e-10, "m^3")`` (a power takes the prefix of its base: mm³ = 1e-9 m³). Units without
    prefixes (``PREFIXED_UNITS``), zero and non-finite values: ``(1.0, unit)`` with the power
    written as a superscript. "um" is read as "µm"."""
    unit = unit.strip()
    if unit in ("um", "um^2", "um^3"):
        return 1.0, "µm" + _POWERS.get(unit[-1], "") if "^" in unit else "µm"
    base, _, power = unit.partition("^")
    p = int(power) if power.isdigit() else 1
    shown = base + (_POWERS.get(power, f"^{power}") if power else "")
    if base not in PREFIXED_UNITS or not (math.isfinite(largest) and largest > 0):
        return 1.0, shown
    root = largest ** (1.0 / p)
    step = math.log10(root) / 3
    # a power's prefixes are 1000^p apart: the nearest one (0.3 mm³ rather than 3e8 µm³)
    k = 3 * (math.floor(step + 1e-9) if p == 1 else round(step))
    k = min(max(k, min(PREFIXES)), max(PREFIXES))
    if base == "m" and k > 0:  # km of a contact or a wear depth: keep metres
        k = 0
    if base == "Hz" and k < 0:  # mHz: keep hertz
        k = 0
    return 10.0 ** (-k * p), PREFIXES[k] + shown


#: markers and dash patterns of the curves of a family, in order (:func:`series_style`)
SERIES_MARKERS = ("o", "s", "^", "v", "D", "P", "X", "<", ">", "*")
SERIES_DASHES = ("-", "--", "-.", ":")
#: the most points a curve of a family carries markers on (denser curves: dashes and widths)
MARKED_POINTS = 80


def series_style(i: int, n: int, *, markers: bool = True) -> dict:
    """Matplotlib keywords of the ``i``-th of ``n`` curves of one family drawn on the same
    axes, so that none hides another where they coincide: its own dash pattern and open
    marker, the line width from 2.6 (first) down to 1.0 (last) and the marker size from 8
    down to 3, drawn in order (``zorder`` rising), so that an earlier curve under a later one
    shows as a wider band with rings around the later one's markers. ``markers=False`` for
    dense curves (hundreds of points): dashes and widths only."""
    if n < 1 or not 0 <= i < n:
        raise ValueError(f"series_style: curve {i} of {n}")
    t = i / (n - 1) if n > 1 else 1.0
    style = {"linestyle": SERIES_DASHES[i % len(SERIES_DASHES)],
             "linewidth": round(2.6 - 1.6 * t, 2), "zorder": 2.0 + 0.01 * i}
    if markers:
        style.update(marker=SERIES_MARKERS[i % len(SERIES_MARKERS)],
                     markersize=round(8.0 - 5.0 * t, 2), markerfacecolor="none")
    return style


def frequency_scale(f_min: float, f_max: float) -> str:
    """``"log"`` when the band spans more than one decade (``f_max / f_min > 10``), else
    ``"linear"`` (a narrow band on a log axis gets one or two tick labels)."""
    if not (f_min > 0 and math.isfinite(f_max)) or f_max <= 0:
        return "linear"
    return "log" if f_max / f_min > 10.0 else "linear"


def tick_text(value: float) -> str:
    """A tick label without an exponent where it reads as a plain number: ``"2.5"``,
    ``"0.001"``, ``"1200"``; ``"1e-05"`` only below 1e-4 or from 1e6."""
    if value == 0:
        return "0"
    a = abs(value)
    if 1e-4 <= a < 1e6:
        return f"{value:.6g}" if a >= 1e-3 else f"{value:.6f}".rstrip("0").rstrip(".")
    return f"{value:.6g}"  # enough digits to tell neighbouring ticks apart


def relabel(label: str, largest: float) -> tuple[float, str]:
    """The factor for the values of an axis and its new label: the unit in brackets at the
    end of ``label`` with its SI prefix (:func:`si_prefix`); ``(1.0, label)`` when the label
    has no unit in brackets. "um" anywhere in the label reads "µm"."""
    label = re.sub(r"\bum\b", "µm", label)
    m = _UNIT.search(label)
    if not m:
        return 1.0, label
    factor, unit = si_prefix(largest, m.group(1))
    return factor, label[: m.start(1)] + unit + label[m.end(1):]


def _style_axis(ax, which: str) -> None:
    """One axis: a linear scale for a narrow frequency band, then the unit of its label with
    its prefix and tick labels in it. The label's unit changes only where the tick labels
    change with it (a formatter of matplotlib's own, or one set here: shared axes share it),
    so that a label never names a unit the ticks are not in."""
    from matplotlib import ticker

    axis = getattr(ax, f"{which}axis")
    label = axis.get_label_text()
    lo, hi = getattr(ax, f"get_{which}lim")()
    log = getattr(ax, f"get_{which}scale")() == "log"
    if log and "frequency" in label.lower() and frequency_scale(min(lo, hi), max(lo, hi)) \
            == "linear":
        getattr(ax, f"set_{which}scale")("linear")
        getattr(ax, f"set_{which}lim")(lo, hi)
        log = False
    factor, new = relabel(label, max(abs(lo), abs(hi)))
    fmt = axis.get_major_formatter()
    ours = getattr(fmt, "fretwear_factor", None)
    theirs = isinstance(fmt, ticker.LogFormatter if log else ticker.ScalarFormatter)
    if not _UNIT.search(new) or not (theirs or ours is not None):
        if isinstance(fmt, ticker.ScalarFormatter):
            fmt.set_useOffset(False)
            if not log and not 1e-4 <= max(abs(lo), abs(hi)) < 1e6:
                # no unit to prefix (cycles, a varied case-file key): each tick says its
                # exponent, not a multiplier (1e7) in the axis corner
                axis.set_major_formatter(ticker.FuncFormatter(lambda v, _pos: tick_text(v)))
        axis.set_label_text(relabel(label, 0.0)[1])  # "um" -> "µm", powers, no prefix
        return
    if ours is not None and ours != factor:  # a shared axis styled with another label
        return
    text = ticker.FuncFormatter(lambda v, _pos: tick_text(v * factor))
    text.fretwear_factor = factor
    axis.set_major_formatter(text)
    if log:
        narrow = 0 < min(lo, hi) and max(lo, hi) / min(lo, hi) < 10.0
        minor = ticker.FuncFormatter(lambda v, _pos: tick_text(v * factor))
        axis.set_minor_formatter(minor if narrow else ticker.NullFormatter())
    axis.set_label_text(new)


def apply_style(fig) -> None:
    """The figure style (module docstring) on every axes of ``fig``: prefixed units and
    plain tick labels, linear frequency axes for bands of a decade or less."""
    for ax in fig.axes:
        if not ax.get_visible() or ax.get_label() == "<colorbar>":
            continue
        for which in ("x", "y"):
            _style_axis(ax, which)
