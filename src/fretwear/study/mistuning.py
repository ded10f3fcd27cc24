"""The amplification factor (and the wear) of a study over mistuning patterns (members whose
case has a ``[cyclic.mistuning]`` table: each runs the whole disk,
:mod:`fretwear.model.mistuning`).

Every member's blade response is, for each sector ``j``, the largest length of the first
harmonic's amplitude vector at its observed point ``<name>@j`` (``sqrt(sum_c |U_1,c|^2)``,
the same in any axes) over the member's frequencies (a sweep's, the FRFs of a wear run) or at
its one frequency (a periodic run); the first observed point of the case is used. The tuned
reference is the members whose factors are all 1 (an ensemble's member 0 with
``include_base``); a member's amplification factor is its largest blade response over the
largest of the tuned members', to compare with Whitehead's bound ``(1 + sqrt(N)) / 2``. A
wear member's sectors also get their deepest final wear, and the member its deepest over the
tuned members' deepest (``wear_amplification``).
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


def sector_wear(ds) -> np.ndarray | None:
    """(N,) the deepest final wear of each sector's contact nodes [m] of one member's wear
    results (the disk's contact nodes are sector 0's, then sector 1's, ..), or None."""
    if "mistuned_sectors" not in ds.attrs or "wear_depth" not in ds:
        return None
    n = int(ds.attrs["mistuned_sectors"])
    w = np.asarray(ds["wear_depth"].values)[-1]
    if w.size % n:
        return None
    return np.max(w.reshape(n, -1), axis=1)


def _tuned(ds) -> bool:
    return all(np.all(np.asarray(ds.attrs.get(f"mistuning_{k}", 1.0)) == 1.0)
               for k in ("young", "mu", "wear"))


def amplification(members, done: dict) -> tuple[dict, dict]:
    """``(data variables, attributes)`` of the study's dataset: ``blade_response`` (member,
    sector), ``amplification_factor`` (member), for wear members ``sector_wear_depth``
    (member, sector) and ``wear_amplification`` (member), the attributes
    ``whitehead_bound``, ``amplification_max`` and ``tuned_members``; empty when the members
    are not mistuned disks. Without a tuned member the factors are NaN (the attribute says
    so)."""
    resp = {i: blade_response(ds) for i, ds in done.items()}
    resp = {i: r for i, r in resp.items() if r is not None}
    sizes = [int(ds.attrs["mistuned_sectors"]) for ds in done.values()
             if "mistuned_sectors" in ds.attrs]
    if not sizes:
        return {}, {}
    n = sizes[0]
    blade = np.full((len(members), n), np.nan)
    for row, m in enumerate(members):
        if m.index in resp and resp[m.index].size == n:
            blade[row] = resp[m.index]
    tuned = [m.index for m in members if m.index in done and _tuned(done[m.index])]
    ref = max((float(np.nanmax(resp[i])) for i in tuned if i in resp), default=np.nan)
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
    wear = {i: sector_wear(ds) for i, ds in done.items()}
    wear = {i: w for i, w in wear.items() if w is not None and w.size == n}
    if wear:
        depth = np.full((len(members), n), np.nan)
        for row, m in enumerate(members):
            if m.index in wear:
                depth[row] = wear[m.index]
        top = max((float(wear[i].max()) for i in tuned if i in wear), default=np.nan)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            ratio = np.nanmax(depth, axis=1) / top if np.isfinite(top) and top > 0 \
                else np.full(len(members), np.nan)
        data["sector_wear_depth"] = (("member", "sector"), depth, {
            "units": "m", "long_name": "deepest final wear of each sector's contact nodes"})
        data["wear_amplification"] = ("member", ratio, {
            "units": "1", "long_name": "deepest wear of the member over the tuned members' "
            "deepest (NaN without a tuned member)"})
    attrs = {"whitehead_bound": whitehead_bound(n),
             "amplification_max": float(np.nanmax(amp)) if np.isfinite(amp).any()
             else np.nan,
             "tuned_members": ", ".join(str(i) for i in tuned) or "none"}
    return data, attrs


def summary_line(ds) -> str | None:
    """The study summary's lines on the mistuning (amplification, wear), or None."""
    if "amplification_factor" not in ds:
        return None
    n = ds.sizes["sector"]
    if ds.attrs["tuned_members"] == "none":
        return ("  amplification factor: no tuned member (every mistuning factor 1) to "
                "compare with")
    lines = []
    if np.isfinite(ds.attrs["amplification_max"]):
        lines.append(f"  amplification factor: largest {ds.attrs['amplification_max']:.4g} over "
                     f"the members (tuned: members {ds.attrs['tuned_members']}); Whitehead's "
                     f"bound (1 + sqrt({n})) / 2 = {ds.attrs['whitehead_bound']:.4g}")
    if "wear_amplification" in ds and np.isfinite(ds["wear_amplification"].values).any():
        lines.append(f"  deepest wear over the tuned disk's: largest "
                     f"{np.nanmax(ds['wear_amplification'].values):.4g} over the members")
    return "\n".join(lines) or None
