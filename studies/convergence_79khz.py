"""Mesh, harmonic, sampling and penalty convergence of the paper's 79 kHz wear case.

The beam of Salles et al. (2011), section 4.2 (:func:`fretwear.examples.builders.paper_beam`,
as ``examples/salles2011-79khz.toml``), excited at 79 kHz. Baseline: 30 Q4 elements along x
(31 contact nodes), 7 harmonics, 128 samples per period, DLFT penalty ``eps`` = spectral
radius of the reduced dynamic stiffness ``Z_r`` over the kept harmonics (the paper's rule,
section 3.2). Each variant changes one setting:

* mesh: nx = 60, 100 (``eps`` by the paper's rule on that mesh, and nx = 100 with the
  baseline's ``eps`` value, to separate mesh and penalty);
* harmonics: 11 (128 samples) and 15 (256 samples), with the paper's rule and with the
  baseline's ``eps`` value (the rule gives a 7x larger ``eps`` there, see
  docs/studies/79khz-convergence.md);
* samples: 256, 512 at 7 harmonics;
* penalty: 0.1, 0.3, 3, 10 x the spectral radius, and the spectral radius of the *static*
  reduced stiffness (the default of frequency sweeps).

For each variant:

1. the unworn periodic response (Powell, relative residual 1e-9, 200 iterations: the
   settings of the first solve of :func:`fretwear.wear.simulate.simulate_wear`). When that fails,
   the
   solve is retried from the baseline's 7-harmonic solution (same mesh only) with 400
   iterations, then with Newton; every attempt is reported. Reported: harmonic-1 amplitude
   of u_x at P_e, stops of P_e per period (``PeriodicSolution.stops_per_period``, |v| below 5 %
   of its peak as in ``fretwear.analyses.periodic``), friction energy per cycle, contact-state
   fractions (node-instants), iterations, wall time;
2. the wear (default adaptive scheme, tolerance 1e-2) to a common ``N = 5e6`` cycles
   (``max_cycles``, ``plateau_rate = 0``), below the known failure near 1.02e7 cycles
   (docs/studies/79khz-wear.md); the worn profile is compared with the baseline's on a
   fine grid in x (linear interpolation of the nodal depths), with the worn volume and the
   zero-wear zones (nodes with a depth below 1 % of the maximum);
3. how far the run goes with the default stop criteria (plateau at 1e-3 of the initial
   worn-volume rate), resumed from the checkpoint of step 2 and cut at a wall-time cap.

Results go to a JSON + NPZ cache (``docs/studies/figures/convergence_79khz.json`` and
``.npz``), written atomically after each stage of each variant: an interrupted study resumes
where it stopped, and ``--plot-only`` redraws the figures from the cache. Wear checkpoints go
to ``--work`` (default: a folder in the temporary directory).

BLAS threads: one (set before numpy is imported). Wall times on a shared machine are noisy.

Usage::

    python studies/convergence_79khz.py [--plot-only] [--only KEY,...] [--redo]
        [--no-extend] [--wear-cap 900] [--extend-cap 150] [--work DIR]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import tempfile
import textwrap
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # before numpy is imported

import numpy as np  # noqa: E402

FREQ = 79e3  # [Hz]
N_COMMON = 5e6  # [cycles] common cycle count of the profile comparison
ZERO_FRACTION = 1e-2  # a node with W below this fraction of max W is in a zero-wear zone
PAPER_ZERO_ZONES = "x = 0.005 m and 0.025-0.040 m (paper, 79 kHz, at the plateau)"
ROOT = Path(__file__).resolve().parents[1]
FIG_DIR = ROOT / "docs" / "studies" / "figures"
CACHE_JSON = FIG_DIR / "convergence_79khz.json"
CACHE_NPZ = FIG_DIR / "convergence_79khz.npz"

BASE = {"nx": 30, "nh": 7, "ns": 128, "eps": ("auto", 1.0)}


def _variant(key, family, label, **change):
    v = dict(BASE)
    v.update(change)
    return {"key": key, "family": family, "label": label, **v}


#: the variants, cheapest first; ``eps`` is (rule, factor): "auto" = spectral radius of Z_r
#: over the kept harmonics, "static" = that of the static K_r, "base" = the baseline's value
VARIANTS = [
    _variant("base", "baseline", "baseline: nx 30, 7 h, 128, eps = rho(Z_r)"),
    _variant("eps0.1", "eps", "eps = 0.1 rho", eps=("auto", 0.1)),
    _variant("eps0.3", "eps", "eps = 0.3 rho", eps=("auto", 0.3)),
    _variant("eps3", "eps", "eps = 3 rho", eps=("auto", 3.0)),
    _variant("eps10", "eps", "eps = 10 rho", eps=("auto", 10.0)),
    _variant("eps_static", "eps", "eps = rho(K_r) (static)", eps=("static", 1.0)),
    _variant("s256", "samples", "256 samples", ns=256),
    _variant("s512", "samples", "512 samples", ns=512),
    _variant("nx60", "mesh", "nx = 60", nx=60),
    _variant("nx100", "mesh", "nx = 100", nx=100),
    _variant("nx100_epsb", "mesh", "nx = 100, eps of the baseline", nx=100, eps=("base", 1.0)),
    _variant("h11", "harmonics", "11 h, 128", nh=11),
    _variant("h11_epsb", "harmonics", "11 h, 128, eps of the baseline", nh=11,
             eps=("base", 1.0)),
    _variant("h15", "harmonics", "15 h, 256", nh=15, ns=256),
    _variant("h15_epsb", "harmonics", "15 h, 256, eps of the baseline", nh=15, ns=256,
             eps=("base", 1.0)),
    # at a tenth of the baseline's eps (where the 7-harmonic solve is easy), compared with
    # the 7-harmonic solution at that eps ("eps0.1")
    _variant("h11_epsb0.1", "harmonics", "11 h, 128, eps = 0.1 rho of the baseline", nh=11,
             eps=("base", 0.1), ref="eps0.1"),
    _variant("h15_epsb0.1", "harmonics", "15 h, 256, eps = 0.1 rho of the baseline", nh=15,
             ns=256, eps=("base", 0.1), ref="eps0.1"),
]
FAMILIES = ("mesh", "harmonics", "samples", "eps")


# --------------------------------------------------------------------------------------------
# cache
# --------------------------------------------------------------------------------------------
def load_cache():
    data = json.loads(CACHE_JSON.read_text()) if CACHE_JSON.is_file() else {}
    arrays = {}
    if CACHE_NPZ.is_file():
        with np.load(CACHE_NPZ) as z:
            arrays = {k: z[k] for k in z.files}
    return data, arrays


def save_cache(data, arrays):
    from fretwear.files import atomic_write

    FIG_DIR.mkdir(parents=True, exist_ok=True)

    def write_json(tmp):
        tmp.write_text(json.dumps(data, indent=1, sort_keys=True, default=float) + "\n")

    def write_npz(tmp):
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    atomic_write(CACHE_JSON, write_json)
    atomic_write(CACHE_NPZ, write_npz)


# --------------------------------------------------------------------------------------------
# computation
# --------------------------------------------------------------------------------------------
class WallCap(Exception):
    pass


class _Alarm:
    """Interrupt a wear run after ``seconds`` of wall time: raises KeyboardInterrupt from a
    SIGALRM handler, which :func:`simulate_wear` turns into a checkpoint of the last accepted
    step before re-raising; ``fired`` tells a cap from a real Ctrl-C."""

    def __init__(self, seconds):
        self.seconds, self.fired = float(seconds), False

    def _handler(self, signum, frame):
        self.fired = True
        raise KeyboardInterrupt

    def __enter__(self):
        self.old = signal.signal(signal.SIGALRM, self._handler)
        signal.setitimer(signal.ITIMER_REAL, self.seconds)
        return self

    def __exit__(self, *exc):
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, self.old)
        return False


class Study:
    def __init__(self, work: Path):
        self.work = work
        self.models, self.anchors, self.reduced = {}, {}, {}
        self.base_eps = None
        self.base_U = None  # the baseline's unworn solution (nc, d, H), 7 harmonics

    def model(self, nx):
        from fretwear.examples.builders import paper_beam
        from fretwear.hb.preload import static_anchor

        if nx not in self.models:
            self.models[nx] = paper_beam(nx=nx, ny=4)
            self.anchors[nx] = static_anchor(self.models[nx])
        return self.models[nx], self.anchors[nx]

    def condensed(self, nx, basis):
        from fretwear.hb.reduce import condense

        key = (nx, tuple(basis.orders))
        if key not in self.reduced:
            model, _ = self.model(nx)
            self.reduced = {key: condense(model, FREQ, basis.orders)}
        return self.reduced[key]

    def baseline_eps(self):
        from fretwear.hb.fourier import FourierBasis

        if self.base_eps is None:
            b = FourierBasis.up_to(BASE["nh"], BASE["ns"])
            self.base_eps = self.condensed(BASE["nx"], b).spectral_radius()
        return self.base_eps

    def penalty(self, v, red):
        from fretwear.hb.penalty import penalty

        rule, factor = v["eps"]
        if rule in ("auto", "static"):
            model, _ = self.model(v["nx"])
            return factor * penalty(rule, model=model, reduced=red)
        return factor * self.baseline_eps()

    def modes_near(self, nx):
        """Natural frequencies [Hz] of the linear beam (sliding and stuck interface) between
        50 and 110 kHz: how far 79 kHz is from a resonance on this mesh."""
        from fretwear.linear import modes

        model, _ = self.model(nx)
        out = {}
        for iface in ("sliding", "stuck"):
            f = modes(model, interface=iface, f_max=110e3).frequency_hz
            out[iface] = [float(x) for x in f if x >= 50e3]
        return out

    def embedded_base(self, basis, model):
        """The baseline's 7-harmonic unworn solution in ``basis`` (higher harmonics 0), on
        the contact nodes of ``model`` (linear interpolation along x for another mesh)."""
        from fretwear.hb.fourier import FourierBasis

        b7 = FourierBasis.up_to(BASE["nh"], BASE["ns"])
        U7 = self.base_U  # (nc, d, H)
        x = np.asarray(model.contact.coords)[:, 0]
        if x.size != U7.shape[0]:
            xb = np.asarray(self.models[BASE["nx"]].contact.coords)[:, 0]
            o = np.argsort(xb)
            U7 = np.stack([[np.interp(x, xb[o], U7[o, c, j]) for j in range(U7.shape[2])]
                           for c in range(U7.shape[1])]).transpose(2, 0, 1)
        U7 = U7.reshape(-1, b7.size)
        U = np.zeros((U7.shape[0], basis.size))
        U[:, 0] = U7[:, 0]
        for j, h in enumerate(b7.harmonics):
            i = list(basis.harmonics).index(h)
            U[:, 1 + i] = U7[:, 1 + j]
            U[:, 1 + basis.k + i] = U7[:, 1 + b7.k + j]
        return U

    # -- stage 1 ------------------------------------------------------------------------
    def unworn(self, v):
        """Unworn periodic solve; returns (record, solution or None, eps)."""
        from fretwear.hb.fourier import FourierBasis
        from fretwear.hb.options import SolveOptions
        from fretwear.hb.periodic import solve_periodic

        model, anchor = self.model(v["nx"])
        basis = FourierBasis.up_to(v["nh"], v["ns"])
        t0 = time.perf_counter()
        red = self.condensed(v["nx"], basis)
        eps = self.penalty(v, red)
        t_setup = time.perf_counter() - t0
        attempts = [("default start, powell, 200 it.", None, "powell", 200)]
        if self.base_U is not None:
            attempts += [("from the baseline solution, powell, 400 it.", "base", "powell", 400),
                         ("from the baseline solution, newton, 100 it.", "base", "newton",
                          100)]
        tried = []
        sol = None
        for name, start, solver, max_iter in attempts:
            U0 = None if start is None else self.embedded_base(basis, model)
            sol = solve_periodic(model, basis, frequency=FREQ, reduced=red,
                                 eps=eps, anchor=anchor, U0=U0,
                                 options=SolveOptions(solver=solver, tol=1e-9,
                                                      max_iter=max_iter))
            st = sol.stats
            tried.append({"start": name, "converged": bool(st.success),
                          "message": st.message, "residual": float(st.residual),
                          "iterations": int(st.iterations), "wall_s": float(st.wall_time)})
            if sol.success:
                break
        if not sol.success:
            sol = None  # the last iterate of a failed solve is no result
        rec = {"modes_near_79khz": self.modes_near(v["nx"]), "eps": float(eps),
               "rho_orders": [float(np.abs(np.linalg.eigvals(z)).max())
                                                 for z in red.Z],
               "n_contact": int(model.contact.dofs.shape[0]),
               "unknowns": int(red.m * basis.size), "setup_s": t_setup, "attempts": tried,
               "converged": sol is not None}
        if sol is not None:
            c = sol.observed["Pe"][0]
            u, vel = sol.observed_time("Pe")
            frac = sol.state_fractions().mean(axis=0)
            rec.update({
                "amp_ux1_Pe": float(np.hypot(c[1], c[1 + basis.k])),
                "ux_half_range_Pe": float(0.5 * (u[0].max() - u[0].min())),
                "stops_Pe": int(sol.stops_per_period("Pe", 0)),
                "friction_energy": float(sol.friction_energy().sum()),
                "fraction_sep_stick_slip": [float(f) for f in frac],
                "nodes_stuck_all_period": float(np.mean((sol.state == 1).all(axis=1))),
                "nodes_slipping": int(np.sum((sol.state == 2).any(axis=1))),
            })
            arr = {"tau": basis.tau, "ux": u[0], "vx": vel[0]}
        else:
            arr = {}
        return rec, sol, arr

    # -- stage 2 and 3 ------------------------------------------------------------------
    def wear(self, v, sol, eps, *, max_cycles, plateau_rate, cap_s, suffix=""):
        """Wear run (resumed from the variant's checkpoint when there is one)."""
        from fretwear.hb.fourier import FourierBasis
        from fretwear.wear import BalanceSetup, RunControl, WearOptions, simulate_wear

        model, anchor = self.model(v["nx"])
        basis = FourierBasis.up_to(v["nh"], v["ns"])
        red = self.condensed(v["nx"], basis)
        ckpt = self.work / f"{v['key']}{suffix}.npz"
        if suffix and not ckpt.is_file():
            # the longer run starts from the checkpoint at N_COMMON, in a copy of its own
            ckpt.write_bytes((self.work / f"{v['key']}.npz").read_bytes())
        opts = WearOptions(max_cycles=max_cycles, plateau_rate=plateau_rate)
        t0 = time.perf_counter()
        alarm = _Alarm(cap_s)
        try:
            with alarm:
                r = simulate_wear(model, basis, frequency=FREQ, options=opts,
                                  balance=BalanceSetup(reduced=red, eps=eps, anchor=anchor,
                                                       U0=sol.U),
                                  run=RunControl(checkpoint=ckpt, resume=True))
        except KeyboardInterrupt:
            if not alarm.fired:
                raise
            with np.load(ckpt) as z:
                n = float(z["state_cycles"])
                steps = int(z["state_step"])
            return {"stop_reason": "wall_cap", "cycles": n, "steps": steps,
                    "message": f"stopped at the wall-time cap of {cap_s:g} s (last accepted "
                               f"step {steps}, N = {n:.4g})",
                    "wall_s": time.perf_counter() - t0}, None
        h = r.history
        rec = {"stop_reason": r.stop_reason, "message": r.message, "cycles": float(h.cycles[-1]),
               "steps": int(h.n_steps - 1), "newton_iterations": int(h.newton_iterations.sum()),
               "rescued_steps": int(h.rescued.sum()), "wall_s": time.perf_counter() - t0,
               "resumed_from": int(r.resumed_from),
               "stability_jump": float(r.stability_jump),
               "max_depth": float(h.wear_depth[-1].max()),
               "worn_volume": float(h.worn_volume[-1]),
               "volume_rate_ratio": float(h.volume_rate[-1] / max(h.volume_rate[0], 1e-300))}
        x = np.asarray(model.contact.coords)[:, 0]
        return rec, {"x": x, "W": np.asarray(h.wear_depth[-1], float),
                     "hist_N": np.asarray(h.cycles, float),
                     "hist_W": np.asarray(h.wear_depth, float)}


def zero_zones(x, W, frac=ZERO_FRACTION):
    """Intervals [x_first, x_last] of consecutive nodes with W <= frac max W."""
    from fretwear.wear import zero_wear_zones

    return zero_wear_zones(x, W, frac)


def profile_difference(xb, Wb, x, W):
    """max |W - W_base| / max W_base on a fine grid (linear interpolation of both)."""
    xs = np.linspace(0.0, 0.1, 2001)
    ib, iv = np.argsort(xb), np.argsort(x)
    wb = np.interp(xs, xb[ib], Wb[ib])
    wv = np.interp(xs, x[iv], W[iv])
    return float(np.abs(wv - wb).max() / Wb.max())


def run(args):
    data, arrays = load_cache()
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    study = Study(work)
    keys = [v["key"] for v in VARIANTS]
    only = args.only.split(",") if args.only else keys
    for k in only:
        if k not in keys:
            sys.exit(f"--only: unknown variant {k!r}; expected some of {', '.join(keys)}")
    todo = [v for v in VARIANTS if v["key"] in only]
    if "base" not in only:
        todo.insert(0, VARIANTS[0])  # its solution starts the fallbacks and sets "base" eps
    sols = {}
    # stage 1 + 2, variant by variant
    for v in todo:
        k = v["key"]
        redo = args.redo and k in only
        rec = data.get(k, {}) if not redo else {}
        rec.update({"family": v["family"], "label": v["label"], "nx": v["nx"], "nh": v["nh"],
                    "ns": v["ns"], "eps_rule": list(v["eps"]), "ref": v.get("ref")})
        if "unworn" not in rec or k == "base" or redo:
            print(f"[{k}] unworn periodic solve ...", flush=True)
            un, sol, arr = study.unworn(v)
            rec["unworn"] = un
            for a, val in arr.items():
                arrays[f"{k}__{a}"] = val
            data[k] = rec
            save_cache(data, arrays)
            print(f"[{k}] {'converged' if un['converged'] else 'NOT converged'}: "
                  f"{un['attempts'][-1]}", flush=True)
        else:
            sol = None
            if "modes_near_79khz" not in rec["unworn"]:
                rec["unworn"]["modes_near_79khz"] = study.modes_near(v["nx"])
        if k == "base":
            if sol is None:
                sys.exit("the baseline's unworn solve failed: nothing to compare with")
            study.base_U = sol.U.copy()
            study.base_eps = rec["unworn"]["eps"]
        sols[k] = sol
        if "wear" in rec and not redo:
            continue
        if not rec["unworn"]["converged"]:
            rec["wear"] = {"stop_reason": "not_run", "message": "unworn solve failed"}
            data[k] = rec
            save_cache(data, arrays)
            continue
        if sol is None:
            un, sol, arr = study.unworn(v)
        print(f"[{k}] wear to N = {N_COMMON:.3g} ...", flush=True)
        wr, prof = study.wear(v, sol, rec["unworn"]["eps"], max_cycles=N_COMMON,
                              plateau_rate=0.0, cap_s=args.wear_cap)
        rec["wear"] = wr
        if prof is not None:
            arrays[f"{k}__x"] = prof["x"]
            arrays[f"{k}__W"] = prof["W"]
            if k == "base":
                arrays["base__hist_N"] = prof["hist_N"]
                arrays["base__hist_W"] = prof["hist_W"]
            rec["wear"]["zero_zones"] = zero_zones(prof["x"], prof["W"])
        data[k] = rec
        save_cache(data, arrays)
        print(f"[{k}] {wr['message']} ({wr['wall_s']:.1f} s)", flush=True)
    # profile differences against the baseline
    compare(data, arrays)
    save_cache(data, arrays)
    # stage 3: how far each run goes with the default stop criteria
    if not args.no_extend:
        for v in todo:
            k = v["key"]
            rec = data[k]
            if rec.get("wear", {}).get("stop_reason") != "max_cycles":
                continue
            if "extend" in rec and not (args.redo and k in only):
                continue
            sol = sols.get(k)
            if sol is None:
                _, sol, _ = study.unworn(v)
            print(f"[{k}] wear with the default stop criteria, cap {args.extend_cap:g} s ...",
                  flush=True)
            wr, _ = study.wear(v, sol, rec["unworn"]["eps"], max_cycles=1e15,
                               plateau_rate=1e-3, cap_s=args.extend_cap,
                               suffix="-default")
            wr.pop("zero_zones", None)
            rec["extend"] = wr
            data[k] = rec
            save_cache(data, arrays)
            print(f"[{k}] {wr['message']} ({wr['wall_s']:.1f} s)", flush=True)


def compare(data, arrays):
    if "base__W" not in arrays:
        return
    xb, Wb = arrays["base__x"], arrays["base__W"]
    for k, rec in data.items():
        w = rec.get("wear", {})
        if (f"{k}__W" in arrays and w.get("stop_reason") == "solver_failed"
                and "base__hist_N" in arrays):
            # a run that stopped early: against the baseline at the same N (linear in N
            # between the baseline's steps)
            hN, hW = arrays["base__hist_N"], arrays["base__hist_W"]
            Wb_n = np.array([np.interp(w["cycles"], hN, hW[:, i]) for i in range(hW.shape[1])])
            w["profile_diff_same_N"] = profile_difference(xb, Wb_n, arrays[f"{k}__x"],
                                                          arrays[f"{k}__W"])
        if f"{k}__W" in arrays and w.get("stop_reason") == "max_cycles":
            rec["wear"]["profile_diff"] = profile_difference(xb, Wb, arrays[f"{k}__x"],
                                                             arrays[f"{k}__W"])
            rec["wear"]["volume_change"] = rec["wear"]["worn_volume"] / \
                data["base"]["wear"]["worn_volume"] - 1.0
            ref = rec.get("ref")
            if ref and f"{ref}__W" in arrays:
                rec["wear"]["profile_diff_ref"] = profile_difference(
                    arrays[f"{ref}__x"], arrays[f"{ref}__W"], arrays[f"{k}__x"],
                    arrays[f"{k}__W"])
                rec["wear"]["volume_change_ref"] = rec["wear"]["worn_volume"] / \
                    data[ref]["wear"]["worn_volume"] - 1.0


# --------------------------------------------------------------------------------------------
# report
# --------------------------------------------------------------------------------------------
def _fmt(x, f=".4g"):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, f)


def table(data):
    """Two markdown tables: the unworn response, and the wear."""
    un = ["| variant | eps [N/m] | unknowns | unworn solve | it. | wall [s] | |u_x1(P_e)| [m] "
          "| stops of P_e | E_fric [J/cycle] | sep / stick / slip |", "|---" * 10 + "|"]
    we = ["| variant | wear to N = 5e6 | steps | wall [s] | max W [m] | worn volume [m^3] "
          "| dV vs baseline | max|W - W_b| / max W_b | zero-wear zones (W < 1 % max) [m] "
          "| default stop criteria |", "|---" * 10 + "|"]
    for v in VARIANTS:
        rec = data.get(v["key"])
        if rec is None:
            continue
        u = rec["unworn"]
        last = u["attempts"][-1]
        conv = ("yes" if u["converged"] else "**no**") + (
            f" ({last['start']})" if len(u["attempts"]) > 1 else "")
        if not u["converged"]:
            conv += f": {last['message']}, residual {last['residual']:.1e}"
        frac = " / ".join(f"{f:.2f}" for f in u.get("fraction_sep_stick_slip", []))
        un.append(
            f"| {v['label']} | {u['eps']:.3g} | {u['unknowns']} | {conv} | "
            f"{sum(a['iterations'] for a in u['attempts'])} | "
            f"{sum(a['wall_s'] for a in u['attempts']):.1f} | {_fmt(u.get('amp_ux1_Pe'))} | "
            f"{u.get('stops_Pe', '-')} | {_fmt(u.get('friction_energy'))} | {frac or '-'} |")
        w = rec.get("wear", {})
        if not u["converged"]:
            continue
        ww = w.get("stop_reason", "-")
        if ww not in ("max_cycles", "-", "not_run") and "cycles" in w:
            ww = f"**{ww}** at N = {w['cycles']:.3g}"
            if "profile_diff_same_N" in w:
                ww += f" (max|dW| vs the baseline at that N: {w['profile_diff_same_N']:.0%})"
        diff = _fmt(w.get("profile_diff"), ".1%")
        if "profile_diff_ref" in w:
            diff += (f" (vs {rec['ref']}: {w['profile_diff_ref']:.1%}, "
                     f"volume {w['volume_change_ref']:+.1%})")
        zones = "; ".join(f"{a:.4g}-{b:.4g}" if b > a else f"{a:.4g}"
                          for a, b in w.get("zero_zones", []))
        e = rec.get("extend", {})
        ext = f"{e['stop_reason']} at N = {e['cycles']:.3g} ({e['wall_s']:.0f} s)" if e else "-"
        we.append(
            f"| {v['label']} | {ww} | {w.get('steps', '-')} | {_fmt(w.get('wall_s'), '.0f')} | "
            f"{_fmt(w.get('max_depth'))} | {_fmt(w.get('worn_volume'))} | "
            f"{_fmt(w.get('volume_change'), '+.1%')} | {diff} | {zones or '-'} | {ext} |")
    return "\n".join(un) + "\n\n" + "\n".join(we)


def figures(data, arrays):
    from fretwear.analyses import figures as plots

    members = {f: ["base"] + [v["key"] for v in VARIANTS if v["family"] == f] for f in FAMILIES}
    labels = {v["key"]: v["label"] for v in VARIANTS}
    labels["base"] = "baseline (nx 30, 7 h, 128, rho)"
    titles = {"mesh": "mesh (elements along x)", "harmonics": "harmonics",
              "samples": "samples per period (7 h)", "eps": "penalty eps (rho = spectral radius)"}
    out = []
    fig, axes = plots.new_figure(2, 2, title=f"79 kHz: worn profile at N = {N_COMMON:.0e} "
                                 "cycles, one setting varied", panel_size=(6.0, 3.8))
    for ax, fam in zip(axes.ravel(), FAMILIES, strict=True):
        for i, k in enumerate(members[fam]):
            if f"{k}__W" not in arrays or data[k]["wear"].get("stop_reason") != "max_cycles":
                continue
            x, W = arrays[f"{k}__x"], arrays[f"{k}__W"]
            o = np.argsort(x)
            ax.plot(1e3 * x[o], 1e9 * W[o], marker="." if len(x) < 70 else None,
                    color="k" if k == "base" else f"C{i}", lw=2.0 if k == "base" else 1.2,
                    ls="-" if k == "base" else ("--" if i % 2 else "-."), label=labels[k])
        missing = [labels[k] for k in members[fam] if f"{k}__W" not in arrays
                   or data.get(k, {}).get("wear", {}).get("stop_reason") != "max_cycles"]
        if missing:
            ax.text(0.02, 0.55, textwrap.fill("no profile at N = 5e6 (see the table): "
                                              + "; ".join(missing), 45),
                    transform=ax.transAxes, fontsize="x-small", va="top", color="0.3")
        ax.set_title(titles[fam], fontsize="small")
        ax.set_xlabel("x along the interface [mm]")
        ax.set_ylabel("wear depth W [nm]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="x-small")
    out.append(plots.save(fig, FIG_DIR / "convergence_79khz_profiles.png"))

    fig, axes = plots.new_figure(4, 2, title="79 kHz: unworn response of P_e over one period",
                                 panel_size=(5.5, 2.8))
    for r, fam in enumerate(FAMILIES):
        for i, k in enumerate(members[fam]):
            if f"{k}__ux" not in arrays:
                continue
            tau = arrays[f"{k}__tau"]
            t = np.append(tau, 2 * np.pi) / (2 * np.pi)
            ux, vx = arrays[f"{k}__ux"], arrays[f"{k}__vx"]
            style = dict(color="k" if k == "base" else f"C{i}", lw=2.0 if k == "base" else 1.1,
                         ls="-" if k == "base" else ("--" if i % 2 else "-."),
                         label=f"{labels[k]} ({data[k]['unworn']['stops_Pe']} stops)")
            ax = axes[r, 0]
            ax.plot(t, 1e9 * np.append(ux - ux.mean(), ux[0] - ux.mean()), **style)
            axes[r, 1].plot(t, 1e3 * np.append(vx, vx[0]), **style)
        axes[r, 0].set_ylabel(f"{fam}:\nu_x - mean [nm]")
        axes[r, 1].set_ylabel("v_x [mm/s]")
        axes[r, 1].legend(fontsize="xx-small", loc="upper right")
        for ax in axes[r]:
            ax.grid(True, alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("t / T [-]")
    out.append(plots.save(fig, FIG_DIR / "convergence_79khz_pe.png"))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot-only", action="store_true", help="redraw from the cache")
    ap.add_argument("--only", default="", help="comma-separated variant keys")
    ap.add_argument("--redo", action="store_true", help="ignore the cache for these variants")
    ap.add_argument("--no-extend", action="store_true", help="skip stage 3")
    ap.add_argument("--wear-cap", type=float, default=900.0,
                    help="wall-time cap of a wear run to N = 5e6 [s]")
    ap.add_argument("--extend-cap", type=float, default=150.0,
                    help="wall-time cap of the run with default stop criteria [s]")
    ap.add_argument("--work", default=str(Path(tempfile.gettempdir()) / "fretwear-conv79"),
                    help="folder of the wear checkpoints")
    args = ap.parse_args(argv)
    if not args.plot_only:
        run(args)
    data, arrays = load_cache()
    if not data:
        sys.exit(f"no cache at {CACHE_JSON}: run without --plot-only first")
    compare(data, arrays)
    print(table(data))
    for p in figures(data, arrays):
        print(f"figure: {p.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
