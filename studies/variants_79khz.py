"""Which open modelling choice decides the 79 kHz wear run of the paper's beam (section 4.2)?

The paper (Salles et al. 2011, section 4.2, Fig. 16-25, Table 1) runs fretting wear at 79 kHz to
a plateau of the worn volume. fretwear's reading of its beam (``paper_beam()``) does not: the
7-harmonic balance fails at N ~ 7e7 cycles and the response is no longer periodic. This script
changes one open modelling choice at a time (damping model, where the x-spring acts, elements
through the height, plane strain / plane stress) and, for each variant, records:

* the linear resonances of u_x(P_e) between 60 and 100 kHz, sliding and stuck interface
  (peaks of the FRF, :func:`fretwear.linear.count_resonances`, refined to the nearest normal
  mode of :func:`fretwear.linear.modes`);
* the unworn periodic solution at 79 kHz (7 harmonics, 128 samples): converged?, Powell
  iterations, harmonic-1 amplitude of u_x(P_e), stops of P_e per period (paper: 4; counted by
  ``PeriodicSolution.stops_per_period`` with the 5 % rule of the ``periodic``
  analysis, ``fretwear.analyses.common.STOP_TOL``);
* its time-domain stability (:func:`fretwear.timedomain.stability.check_periodic`);
* the wear run (:func:`fretwear.wear.simulate.simulate_wear`, adaptive linearly implicit Euler,
  tolerance 1e-2, ``max_cycles`` 1e8 by default): N where the balance first fails (first
  step with ``rescued == Rescue.TIME_AVERAGED``, 2), stop reason, N reached, worn volume,
  max depth, worn-volume rate at the end / initial, steps and wall time, zero-wear zones
  (nodes with wear < 1 % of the max, the paper's "pillars").

Everything is cached in ``docs/studies/figures/variants-79khz.json`` after each stage, so an
interrupted study loses nothing; the wear runs also keep a checkpoint (``--work``) and resume
from it. ``--plot-only`` redraws the figures from the cache:
``docs/studies/figures/variants-79khz-profiles.png`` (final wear profiles) and
``docs/studies/figures/variants-79khz-volume.png`` (worn volume vs cycles).

Plane stress is not a fretwear option (2D meshes are plane strain). The plane-stress variant
uses the exact equivalence of the isotropic elasticity matrices: plane strain with
``E' = E (1 + 2 nu) / (1 + nu)^2`` and ``nu' = nu / (1 + nu)`` is plane stress with ``E, nu``
(same density, same out-of-plane width, so the same mass and loads).

Wall times were measured on a shared 2-core machine: noisy, by up to a factor of 2.

Usage::

    python studies/variants_79khz.py [--variants baseline,rayleigh,...] [--max-cycles 1e8]
        [--wall-budget 600] [--skip-stability] [--plot-only] [--fresh]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # before numpy is imported: 2 shared cores

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FIG_DIR = ROOT / "docs" / "studies" / "figures"
CACHE = FIG_DIR / "variants-79khz.json"
F_HZ = 79e3
L, H, WIDTH = 0.1, 0.01, 0.01
ETA = 1e-3

#: name -> (label, changes from the baseline)
VARIANTS = {
    "baseline": ("baseline: loss factor 0.001, spring bottom-left, ny = 4, plane strain", {}),
    "rayleigh": ("viscous b K, damping ratio 0.0005 at 79 kHz", {"damping": "rayleigh"}),
    "spring_top": ("spring on the top-left node", {"spring_at": "top_left"}),
    "spring_mid": ("spring at mid-height of the left face", {"spring_at": "mid_left"}),
    "ny2": ("ny = 2", {"ny": 2}),
    "ny6": ("ny = 6", {"ny": 6}),
    "plane_stress": ("plane stress", {"plane": "stress"}),
}


# --------------------------------------------------------------------------------------------
# models
# --------------------------------------------------------------------------------------------
def build(nx=30, ny=4, damping="loss", spring_at="bottom_left", plane="strain"):
    """The section 4.2 beam of ``builders.paper_beam`` with one open choice changed."""
    from fretwear.model.build import ContactSpec, Damping, Material, Spring, Traction, from_mesh
    from fretwear.model.mesh import rectangle

    E, nu = 210e9, 0.3
    if plane == "stress":  # plane strain with these constants is plane stress with E, nu
        E, nu = E * (1 + 2 * nu) / (1 + nu) ** 2, nu / (1 + nu)
    if damping == "loss":
        damp = Damping(loss_factor=ETA)
    else:  # C = b K with b omega / 2 = eta / 2 at 79 kHz (viscous: the ratio grows with f)
        damp = Damping(rayleigh_stiffness=ETA / (2 * np.pi * F_HZ))
    at = {"bottom_left": "bottom_left", "top_left": "top_left", "mid_left": (0.0, H / 2)}
    return from_mesh(
        rectangle(L, H, nx, ny),
        Material(E, nu, 7800.0),
        thickness=WIDTH,
        damping=damp,
        springs=[Spring(at[spring_at], "x", 1e4)],
        loads=[Traction("top", pressure=1e4, waveform="constant", name="P"),
               Traction("right", pressure=1e4, waveform="sin", name="Q")],
        contact=ContactSpec("bottom", mu=0.3, normal=(0.0, -1.0), gap=0.0,
                            wear_coefficient=1e-11),
        observed={"Pe": (L, H / 2)},
        name="salles2011-beam-variant",
    )


# --------------------------------------------------------------------------------------------
# cache
# --------------------------------------------------------------------------------------------
def load_cache() -> dict:
    if CACHE.is_file():
        return json.loads(CACHE.read_text())
    return {}


def save_cache(cache: dict) -> None:
    from fretwear.files import atomic_write

    text = json.dumps(cache, indent=1, default=float)
    atomic_write(CACHE, lambda tmp: tmp.write_text(text))


# --------------------------------------------------------------------------------------------
# stages
# --------------------------------------------------------------------------------------------
def resonances(model) -> dict:
    """Peaks of |u_x(P_e)| in 60-100 kHz, sliding and stuck, at the nearest normal mode."""
    from fretwear.linear import count_resonances, frf, modes

    f = np.linspace(60e3, 100e3, 1601)  # 25 Hz: a third of the half-power width eta f
    out = {}
    for itf in ("sliding", "stuck"):
        _, peaks = count_resonances(frf(model, f, interface=itf), "Pe", "x", prominence=0.3)
        fm = modes(model, interface=itf, f_max=110e3).frequency_hz
        out[itf] = [float(fm[np.argmin(np.abs(fm - p))]) for p in peaks]
    return out


def unworn(model, basis) -> tuple[dict, object]:
    from fretwear.hb.periodic import solve_periodic

    t0 = time.perf_counter()
    sol = solve_periodic(model, basis, frequency=F_HZ)
    st = sol.stats
    d = {"converged": bool(st.success), "iterations": int(st.iterations),
         "wall_s": time.perf_counter() - t0, "message": st.message}
    if not sol.success:
        sol = None  # the last iterate of a failed solve is no result
    if sol is not None:
        c = sol.observed["Pe"][0]
        d.update(amp_ux=float(np.hypot(c[1], c[1 + basis.k])),
                 stops=int(sol.stops_per_period("Pe", 0)),
                 friction_energy=float(sol.friction_energy().sum()),
                 stuck_all_period=float(np.mean((sol.state == 1).all(axis=1))))
    return d, sol


def stability(model, sol) -> dict:
    from fretwear.timedomain.stability import check_periodic

    chk = check_periodic(model, sol)
    return {"verdict": chk.verdict, "distance": chk.distance, "periods": chk.periods,
            "wall_s": chk.wall_time, "message": chk.message}


def zero_zones(x, w, frac=0.01) -> list[list[float]]:
    """x-intervals [m] of consecutive contact nodes whose wear is at most ``frac`` of the max."""
    from fretwear.wear import zero_wear_zones

    return zero_wear_zones(x, w, frac)


def wear_run(name, model, basis, max_cycles, wall_budget, work: Path, fresh: bool) -> dict:
    """The wear run, with a checkpoint; stops (resumably) after ``wall_budget`` seconds."""
    from fretwear.errors import ConvergenceError
    from fretwear.timedomain.averaged_rate import RESPONSE_KINDS
    from fretwear.wear import (
        HISTORY_FIELDS,
        Rescue,
        RunControl,
        WearHistory,
        WearOptions,
        simulate_wear,
    )

    work.mkdir(parents=True, exist_ok=True)
    ckpt = work / f"{name}.npz"
    if fresh and ckpt.exists():
        ckpt.unlink()
    opts = WearOptions(tolerance=1e-2, max_cycles=max_cycles, checkpoint_every_s=0.0)
    t0 = time.perf_counter()

    def log(step, record):
        kind = int(record.response)
        print(f"  [{name}] step {step:4d}  N = {record.cycles:.4g}  jump {record.jump:.3g}  "
              f"V = {record.worn_volume:.4e} m^3  dV/dN = {record.volume_rate:.3e}  "
              f"rescued {int(record.rescued)}"
              + (f" ({RESPONSE_KINDS[kind]})" if kind >= 0 else "")
              + f"  {time.perf_counter() - t0:.0f} s", flush=True)
        if time.perf_counter() - t0 > wall_budget:
            raise KeyboardInterrupt  # simulate_wear saves the checkpoint first

    stop = ""
    try:
        r = simulate_wear(model, basis, frequency=F_HZ, options=opts,
                          run=RunControl(checkpoint=ckpt, resume=True, callback=log))
        hist, stop, msg = r.history, r.stop_reason, r.message
    except ConvergenceError as exc:
        return {"stop_reason": "unworn_failed", "message": str(exc)}
    except KeyboardInterrupt:
        with np.load(ckpt, allow_pickle=False) as z:
            hist = WearHistory(**{k: z[f"hist_{k}"] for k in HISTORY_FIELDS})
        stop, msg = "wall_budget", f"stopped after the wall budget of {wall_budget:g} s"
    wall = time.perf_counter() - t0
    resc = np.asarray(hist.rescued)
    td = np.flatnonzero(resc == Rescue.TIME_AVERAGED)
    w = np.asarray(hist.wear_depth[-1])
    x = model.contact.coords[:, 0]
    vr = np.asarray(hist.volume_rate)
    kinds = [RESPONSE_KINDS[int(k)] for k in hist.response if int(k) >= 0]
    return {
        "stop_reason": stop, "message": msg, "wall_s_this_call": wall,
        "wall_s_total": float(np.sum(hist.wall_time)),
        "n_steps": int(hist.n_steps - 1), "N_reached": float(hist.cycles[-1]),
        "N_balance_fails": float(hist.cycles[td[0]]) if td.size else None,
        "steps_time_domain": int(td.size), "steps_restarted": int(np.sum(resc == 1)),
        "responses": {k: kinds.count(k) for k in sorted(set(kinds))},
        "worn_volume": float(hist.worn_volume[-1]), "max_depth": float(w.max()),
        "x_max_depth": float(x[int(np.argmax(w))]),
        "rate_end_over_initial": float(vr[-1] / vr[0]),
        "rate_last5_over_initial": [float(v) for v in vr[-5:] / vr[0]],
        "zero_wear_zones": zero_zones(x, w),
        "x": x.tolist(), "final_wear": w.tolist(),
        "cycles": np.asarray(hist.cycles).tolist(),
        "worn_volume_history": np.asarray(hist.worn_volume).tolist(),
        "volume_rate_history": vr.tolist(), "rescued": resc.astype(int).tolist(),
    }


# --------------------------------------------------------------------------------------------
# report and figures
# --------------------------------------------------------------------------------------------
def fmt(v, spec=".3g"):
    return "-" if v is None else format(v, spec)


def summary(cache: dict) -> None:
    print("\nvariant        | sliding res. [kHz]  | stuck res. [kHz]   | conv it stops | stability"
          "        | balance fails N | stop        N reached  V [m^3]    max W [m]  "
          "rate end/0 | steps wall[s] | zero-wear zones [mm]")
    for name in VARIANTS:
        c = cache.get(name)
        if not c:
            continue
        res = c.get("resonances", {})
        u = c.get("unworn", {})
        s = c.get("stability", {})
        w = c.get("wear", {})
        zones = " ".join(f"{1e3 * a:.1f}-{1e3 * b:.1f}" for a, b in w.get("zero_wear_zones", []))
        print(f"{name:14s} | {' '.join(f'{f / 1e3:.1f}' for f in res.get('sliding', [])):19s} | "
              f"{' '.join(f'{f / 1e3:.1f}' for f in res.get('stuck', [])):18s} | "
              f"{'yes' if u.get('converged') else 'no':>4s} {u.get('iterations', 0):3d} "
              f"{u.get('stops', '-'):>4} | {s.get('verdict', '-'):16s} | "
              f"{fmt(w.get('N_balance_fails')):>15s} | {w.get('stop_reason', '-'):11s} "
              f"{fmt(w.get('N_reached')):>9s} {fmt(w.get('worn_volume'), '.3e'):>10s} "
              f"{fmt(w.get('max_depth'), '.3e'):>10s} {fmt(w.get('rate_end_over_initial')):>10s}"
              f" | {w.get('n_steps', 0):5d} {w.get('wall_s_total', 0):7.0f} | {zones}")


def plot(cache: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [n for n in VARIANTS if cache.get(n, {}).get("wear", {}).get("x")]
    if not names:
        return
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for n in names:
        w = cache[n]["wear"]
        ax.plot(np.array(w["x"]) * 1e3, np.array(w["final_wear"]) * 1e9, marker=".",
                label=f"{n}: N = {w['N_reached']:.2g}")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("wear depth [nm]")
    ax.set_title("79 kHz: wear profile at the end of each run (one change per variant)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(FIG_DIR / "variants-79khz-profiles.png", dpi=110)
    plt.close(fig)

    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for n in names:
        w = cache[n]["wear"]
        N = np.array(w["cycles"])
        V = np.array(w["worn_volume_history"])
        R = np.array(w["volume_rate_history"]) / w["volume_rate_history"][0]
        line, = ax.plot(N, V * 1e12, label=n)
        ax2.plot(N, R, color=line.get_color())
        td = np.flatnonzero(np.array(w["rescued"]) == 2)
        if td.size:  # steps whose rate was averaged over a time integration
            ax.plot(N[td], V[td] * 1e12, "x", color=line.get_color(), ms=4)
            ax2.plot(N[td], R[td], "x", color=line.get_color(), ms=4)
    ax.set_ylabel("worn volume [$10^{-12}$ m$^3$]")
    ax.set_title("79 kHz: worn volume and its rate (x: time-domain steps, no periodic balance)")
    ax2.set_ylabel("worn-volume rate / initial")
    ax2.set_xlabel("cycles N")
    for a in (ax, ax2):
        a.grid(alpha=0.3)
    ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(FIG_DIR / "variants-79khz-volume.png", dpi=110)
    plt.close(fig)


# --------------------------------------------------------------------------------------------
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", default=",".join(VARIANTS),
                    help=f"comma-separated, from {list(VARIANTS)}")
    ap.add_argument("--max-cycles", type=float, default=1e8)
    ap.add_argument("--wall-budget", type=float, default=600.0,
                    help="stop a wear run after this many seconds (resumable) [s]")
    ap.add_argument("--skip-stability", action="store_true")
    ap.add_argument("--skip-wear", action="store_true")
    ap.add_argument("--plot-only", action="store_true")
    ap.add_argument("--fresh", action="store_true", help="recompute, ignoring cache/checkpoints")
    ap.add_argument("--work", type=Path, default=Path("/tmp/fretwear-variants-79khz"),
                    help="folder of the wear checkpoints")
    args = ap.parse_args(argv)

    cache = load_cache()
    if args.plot_only:
        summary(cache)
        plot(cache)
        return 0
    from fretwear.hb.fourier import FourierBasis

    basis = FourierBasis.up_to(7, 128)
    for name in args.variants.split(","):
        if name not in VARIANTS:
            print(f"unknown variant {name!r}; expected one of {list(VARIANTS)}")
            return 2
        label, kw = VARIANTS[name]
        c = {} if args.fresh else cache.get(name, {})
        c["label"], c["changes"] = label, kw
        cache[name] = c
        print(f"\n=== {name}: {label}", flush=True)
        model = build(**kw)
        if "resonances" not in c:
            c["resonances"] = resonances(model)
            save_cache(cache)
        print(f"  resonances of u_x(P_e), 60-100 kHz: sliding "
              f"{[round(f / 1e3, 2) for f in c['resonances']['sliding']]} kHz, stuck "
              f"{[round(f / 1e3, 2) for f in c['resonances']['stuck']]} kHz", flush=True)
        sol = None
        if "unworn" not in c or (not args.skip_stability and "stability" not in c):
            c["unworn"], sol = unworn(model, basis)
            save_cache(cache)
        u = c["unworn"]
        print(f"  unworn 79 kHz solve: converged {u['converged']} ({u['iterations']} it.), "
              f"|u_x1(Pe)| = {u.get('amp_ux', math.nan):.4g} m, P_e stops {u.get('stops')} "
              "times per period", flush=True)
        if not args.skip_stability and "stability" not in c and sol is not None:
            c["stability"] = stability(model, sol)
            save_cache(cache)
        if "stability" in c:
            print(f"  stability: {c['stability']['verdict']}: {c['stability']['message']} "
                  f"({c['stability']['wall_s']:.0f} s)", flush=True)
        if not args.skip_wear:
            prev = c.get("wear", {})
            again = prev.get("stop_reason") in (None, "wall_budget") or \
                prev.get("N_reached", 0) < args.max_cycles * (1 - 1e-12) and \
                prev.get("stop_reason") == "max_cycles"
            if again:
                c["wear"] = wear_run(name, model, basis, args.max_cycles, args.wall_budget,
                                     args.work, args.fresh)
                save_cache(cache)
            w = c["wear"]
            print(f"  wear: {w.get('message')}; balance fails at N = "
                  f"{fmt(w.get('N_balance_fails'))}; V = {fmt(w.get('worn_volume'), '.4e')} "
                  f"m^3, max W = {fmt(w.get('max_depth'), '.4e')} m, rate end/initial "
                  f"{fmt(w.get('rate_end_over_initial'))}; zero-wear zones "
                  f"{w.get('zero_wear_zones')} m", flush=True)
        plot(cache)
    summary(cache)
    return 0


if __name__ == "__main__":
    sys.exit(main())
