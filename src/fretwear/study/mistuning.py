"""The amplification factor of a study over mistuning patterns (members whose case has a
``[cyclic.mistuning]`` table: each runs the whole disk, :mod:`fretwear.model.mistuning`).

Every member's blade response is, for each sector ``j``, the largest length of the first
harmonic's amplitude vector at its observed point ``<name>@j`` (``sqrt(sum_c |U_1,c|^2)``,
the same in any axes) over the member's frequencies (a sweep's, the FRFs of a wear run) or at
its one frequency (a periodic run); the first observed point of the case is used. The tuned
reference is the members whose factors are all 1 (an ensemble's member 0 with
``include_base``); a member's amplification factor is its largest blade response over the
largest of the tuned members', to compare with Whitehead's bound ``(1 + sqrt(N)) / 2``.
"""

from __future__ import annotations

import warnings

import numpy as np

from fretwear.model.mistuning import whitehead_bound

#: the results variables holding the observed amplitudes, by analysis: (name, harmonic axis)
_AMPLITUDES = (("response_amplitude", True), ("displacement_harmonic_amplitude", True),
               ("frf_amplitude", False))


def _point_groups(ds) -> dict[str, list[str]]:
    """Base name -> the point names ``<name>@0 .. <name>@N-1`` (in sector order)."""
    n = int(ds.attrs["mistuned_sectors"])
    names = [str(p) for p in ds["point"].values] if "point" in ds.coords else []
    groups = {}
    for p in names:
        base, _, j = p.rpartition("@")
        if base and j.isdigit():
            groups.setdefault(base, []).append(p)
    return {b: [f"{b}@{j}" for j in range(n)] for b, v in groups.items() if len(v) == n}


def blade_response(ds) -> np.ndarray | None:
    """(N,) the blade responses of one member's results [m] (module docstring), or None
    (no mistuned disk, or no per-sector observed point)."""
    if "mistuned_sectors" not in ds.attrs:
        return None
    groups = _point_groups(ds)
    if not groups:
        return None
    points = next(iter(groups.values()))
    for name, harmonic in _AMPLITUDES:
        if name in ds:
            a = ds[name].sel(point=points)
            if harmonic:
                a = a.sel(harmonic=1)
            a = a.transpose(..., "point", "axis").values
            b = np.sqrt(np.nansum(a ** 2, axis=-1))
            return np.nanmax(b.reshape(-1, len(points)), axis=0)
    return None


def _tuned(ds) -> bool:
    return all(np.all(np.asarray(ds.attrs.get(f"mistuning_{k}", 1.0)) == 1.0)
               for k in ("young", "mu", "wear"))


def amplification(members, done: dict) -> tuple[dict, dict]:
    """``(data variables, attributes)`` of the study's dataset: ``blade_response`` (member,
    sector), ``amplification_factor`` (member), the attributes ``whitehead_bound``,
    ``amplification_max`` and ``tuned_members``; empty when the members are not mistuned
    disks. Without a tuned member the factors are NaN (the attribute says so)."""
    resp = {i: blade_response(ds) for i, ds in done.items()}
    resp = {i: r for i, r in resp.items() if r is not None}
    if not resp:
        return {}, {}
    n = next(iter(resp.values())).size
    blade = np.full((len(members), n), np.nan)
    for row, m in enumerate(members):
        if m.index in resp and resp[m.index].size == n:
            blade[row] = resp[m.index]
    tuned = [m.index for m in members if m.index in resp and _tuned(done[m.index])]
    ref = max((float(np.nanmax(resp[i])) for i in tuned), default=np.nan)
    with warnings.catch_warnings():  # a failed member's row is all NaN: its factor is NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        amp = np.nanmax(blade, axis=1) / ref if np.isfinite(ref) else np.full(len(members),
                                                                             np.nan)
    data = {
        "blade_response": (("member", "sector"), blade, {
            "units": "m", "long_name": "largest first-harmonic amplitude of each blade's "
            "observed point over the member's frequencies"}),
        "amplification_factor": ("member", amp, {
            "units": "1", "long_name": "largest blade response of the member over the tuned "
            "members' largest (NaN without a tuned member)"}),
    }
    attrs = {"whitehead_bound": whitehead_bound(n),
             "amplification_max": float(np.nanmax(amp)) if np.isfinite(amp).any()
             else np.nan,
             "tuned_members": ", ".join(str(i) for i in tuned) or "none"}
    return data, attrs


def summary_line(ds) -> str | None:
    """One line of the study's summary, or None."""
    if "amplification_factor" not in ds:
        return None
    n = ds.sizes["sector"]
    if ds.attrs["tuned_members"] == "none":
        return ("  amplification factor: no tuned member (every mistuning factor 1) to "
                "compare with")
    return (f"  amplification factor: largest {ds.attrs['amplification_max']:.4g} over the "
            f"members (tuned: members {ds.attrs['tuned_members']}); Whitehead's bound "
            f"(1 + sqrt({n})) / 2 = {ds.attrs['whitehead_bound']:.4g}")
