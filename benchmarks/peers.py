"""fretwear against pyHarm-os 1.2.2 on two friction oscillators, with references from neither.

pyHarm is installed in the benchmark's own environment, never as a fretwear dependency:

    python3 -m venv /tmp/pyharm-venv && /tmp/pyharm-venv/bin/pip install pyharm-os==1.2.2

then, from the repository root (with fretwear importable, e.g. ``PYTHONPATH=src``)::

    python benchmarks/peers.py [--pyharm /tmp/pyharm-venv/bin/python] [--harmonics 7 15]
        [--problems a b] [--default-only] [--recorded-references]

(``--problems``: which problems; ``--default-only``: on (b) only fretwear's default rule and
pyHarm, without the rows of "top" and eps = 1000 N/m; ``--recorded-references``: the
references of :data:`RECORDED`, as this script computes them, instead of computing them
again: for a loaded machine.)

Problems (benchmarks/reference_oscillators.py):

* (a) one DOF m = 1, k = 1, c = 0.02 with a Jenkins element (kt = 0.5 in series with a Coulomb
  slider, mu N = 0.5), forcing 0.2 cos(w t), w = 0.7-1.3 rad/s. fretwear: interface stiffness
  kt under a prescribed normal load (no normal DOF). pyHarm: its ``Jenkins`` connector.
* (b) two-DOF chain (m = 1, 1; k = 1, 1; c = 0.02, 0.02 to the ground), forcing on mass 1,
  mass 2 on a rigid Coulomb contact (mu N = 0.5), w = 1.0-1.8 rad/s (its peak is at 1.49).
  fretwear: prescribed normal load on a rigid contact. pyHarm: its ``DLFTFriction`` connector
  (eps = 1000, the value the issue used).

References: event-driven integration with exact stick/slip switching plus Newton shooting
(periodic to 1e-10), peak of the first-harmonic amplitude A1 of mass 1 by golden section.

Each code runs in a fresh process of its own interpreter (``cold``: first run in that process,
imports and just-in-time compilation included) and runs the same analysis again in that
process (``warm``). fretwear: 121 (a) / 137 (b) linearly spaced frequencies (``fretwear.sweep``,
default eps rule, "contact": the spring on (a), "stiff" (ten times "top") on (b); on (b)
also with the rule "top", the default before "contact", row ``fretwear^``, and with
pyHarm's eps = 1000, row ``fretwear*``); pyHarm: its arclength continuation over the same
band (step ``ds = 0.05``: its default continuation did not end on (b)), stopped after
``PYHARM_MAX_SOLUTIONS`` solutions if it has not left the band by then. The peak of each
curve is the largest A1 of its points refined by a parabola through the three points around
it, then refined by the same code on grids 10, 100, 1000 and 10000 times finer around it
(:func:`refined_peak`, untimed; the same estimator for both codes).

Prints per code, problem and H: points, converged, warm and cold wall time [s], CPU time of the
warm run [s], peak amplitude and frequency errors (relative); then the machine load; the last
lines are ``peak_err_ratio_b=<|peak error of fretwear's default| / |pyHarm's| on (b), the
largest over the H run>`` and ``speedup_vs_pyharm_warm=<geometric mean over problems and H
of pyHarm warm / fretwear warm>`` (wall times: the machine's load is printed beside them).

``--first-ever`` adds, per code, the cold run of problem (a) at the first H in a process whose
caches are empty: numba's on-disk cache of compiled kernels (``NUMBA_CACHE_DIR``) and Python's
bytecode cache (``PYTHONPYCACHEPREFIX``, so every imported module, numpy and scipy included,
is compiled from source as on a fresh installation), both in a temporary folder: the cost of a
user's very first run.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import reference_oscillators as ref  # noqa: E402

BAND = {"a": (0.7, 1.3), "b": (1.0, 1.8)}  # rad/s
#: the references (w [rad/s], A1) as this script computes them (``ref.peak``, golden section to
#: 1e-8), for ``--recorded-references``: recomputing them takes a minute on a quiet machine
#: and 13 minutes at a load of 19 on 2 cores
RECORDED = {"a": (1.1802562, 1.3630690), "b": (1.4905405, 0.7686448)}
#: pyHarm's continuation stops at this many solutions if it has not left the band (without it,
#: on (b) at H = 7, it was still running after 39 min, 12 min of CPU; 300 solutions end at
#: w = 1.53 rad/s, past the peak)
PYHARM_MAX_SOLUTIONS = 300
PYHARM_DS = 0.05  # arclength step of pyHarm's continuation over the band
N_POINTS = {"a": 121, "b": 137}
#: the peak of each code's curve is refined by the same code at REFINE_POINTS frequencies
#: over +-REFINE_HALF spacings around its largest point, REFINE_STAGES times, the spacing
#: shrinking tenfold each time (:func:`refined_peak`)
REFINE_HALF, REFINE_POINTS, REFINE_STAGES = 1.5, 31, 4
REFINE_JUMP = 2e-2  # a point this far from the coarse peak (relative A1) is off the curve

FRETWEAR_CHILD = r'''
import json, sys, time
t0 = time.perf_counter()
import numpy as np
import fretwear
import fretwear.hb.penalty
from fretwear.hb.fourier import FourierBasis
from fretwear.model.core import Load
from fretwear.model.build import Damping
from fretwear.model.matrices import ContactDofs, from_matrices

prob, H, n, w0, w1 = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), \
    float(sys.argv[5])
eps = sys.argv[6] if sys.argv[6] in ("default", *fretwear.hb.penalty.RULES) else \
    float(sys.argv[6])


def model():
    if prob == "a":
        return from_matrices([[1.0]], [[1.0]],
                             contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=0.5,
                                                 normal_load=1.0, kt=0.5),
                             damping=Damping(C=[[0.02]]), loads=[Load(np.array([0.2]), "cos")],
                             observed={"x": 0})
    return from_matrices(np.array([[2.0, -1.0], [-1.0, 1.0]]), np.eye(2),
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[1], mu=0.5,
                                             normal_load=1.0),
                         damping=Damping(C=0.02 * np.eye(2)),
                         loads=[Load(np.array([0.2, 0.0]), "cos")], observed={"x": 0})


def run():
    given = {} if eps == "default" else {"eps": eps}  # "default": the sweep's own rule
    res = fretwear.sweep(model(), FourierBasis.up_to(H, 128), w0 / (2 * np.pi),
                         w1 / (2 * np.pi), n,
                         options=fretwear.SweepOptions(spacing="linear", **given),
                         time_domain=False)
    pts = [p for p in res.points if p.on_grid]
    w = [2 * np.pi * p.frequency_hz for p in pts if p.success]
    a = [float(p.solution.observed_amplitude("x")[0][0]) for p in pts if p.success]
    used = res.points[0].solution.eps if res.points[0].success else float("nan")
    return {"points": len(pts), "converged": len(w), "w": w, "a": a, "eps": used}


out = run()
out["cold"] = time.perf_counter() - t0
if sys.argv[7:] != ["once"]:
    t1, c1 = time.perf_counter(), time.process_time()
    run()
    out["warm"], out["warm_cpu"] = time.perf_counter() - t1, time.process_time() - c1
print("RESULT " + json.dumps(out))
'''

PYHARM_CHILD = r'''
import copy, json, logging, sys, time, warnings
warnings.filterwarnings("ignore")
t0 = time.perf_counter()
import numpy as np
from pyHarm.Maestro import Maestro

prob, H, w0, w1 = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
MAX_SOLUTIONS, DS = int(sys.argv[5]), float(sys.argv[6])
if prob == "a":
    subs = {"m": {"type": "onlydofs", "ndofs": 1, "nnodes": 1}}
    con = {"k": {"type": "LinearSpring", "connect": {"m": [0]}, "dirs": [0], "k": 1.0},
           "c": {"type": "LinearDamper", "connect": {"m": [0]}, "dirs": [0], "k": 0.02},
           "mass": {"type": "GOElement", "connect": {"m": [0]}, "dirs": [0], "dto": 2, "xo": 1,
                    "k": 1.0},
           "f": {"type": "CosinusForcing", "connect": {"m": [0]}, "dirs": [0], "amp": 0.2},
           "jenkins": {"type": "Jenkins", "connect": {"m": [0]}, "dirs": [0], "mu": 0.5,
                       "N0": 1.0, "k": 0.5}}
else:
    subs = {"m": {"type": "onlydofs", "ndofs": 1, "nnodes": 2}}
    con = {"k1": {"type": "LinearSpring", "connect": {"m": [0]}, "dirs": [0], "k": 1.0},
           "k2": {"type": "LinearSpring", "connect": [("m", [0]), ("m", [1])], "dirs": [0],
                  "k": 1.0},
           "c1": {"type": "LinearDamper", "connect": {"m": [0]}, "dirs": [0], "k": 0.02},
           "c2": {"type": "LinearDamper", "connect": {"m": [1]}, "dirs": [0], "k": 0.02},
           "m1": {"type": "GOElement", "connect": {"m": [0]}, "dirs": [0], "dto": 2, "xo": 1,
                  "k": 1.0},
           "m2": {"type": "GOElement", "connect": {"m": [1]}, "dirs": [0], "dto": 2, "xo": 1,
                  "k": 1.0},
           "f": {"type": "CosinusForcing", "connect": {"m": [0]}, "dirs": [0], "amp": 0.2},
           "friction": {"type": "DLFTFriction", "connect": {"m": [1]}, "dirs": [0], "mu": 0.5,
                        "N0": 1.0, "eps": 1000.0}}
idata = {"system": {"type": "Base", "nh": H, "nti": 128}, "substructures": subs,
         "connectors": con,
         "analysis": {"frf": {"study": "frf", "puls_inf": w0, "puls_sup": w1, "ds0": DS,
                              "ds_max": DS, "ds_min": 1e-6, "verbose": False,
                              "stopper": "solnumber",
                              "stopper_options": {"max_solutions": MAX_SOLUTIONS}}}}


def run():
    m = Maestro(copy.deepcopy(idata))
    m.operate()
    edf = m.system.expl_dofs
    pick = lambda cs: int(edf[(edf["harm"] == 1) & (edf["cs"] == cs) & (edf["node_num"] == 0)
                              & (edf["sub"] == "m")].index[0])
    ic, js = pick("c"), pick("s")
    sols = m.nls["frf"].SolList
    ok = [s for s in sols if s.flag_accepted]
    w = [float(s.x[-1]) for s in ok]
    a = [float(np.hypot(s.x[ic], s.x[js])) for s in ok]
    return {"points": len(sols), "converged": len(ok), "w": w, "a": a}


def at(ws):
    """A1 at each of the frequencies ``ws``: the first solution of a continuation that starts
    there (solution number 1 stops it)."""
    a = []
    for w in ws:
        data = copy.deepcopy(idata)
        data["analysis"]["frf"].update(puls_inf=w, puls_sup=w * (1 + 1e-6),
                                       stopper_options={"max_solutions": 1})
        m = Maestro(data)
        m.operate()
        edf = m.system.expl_dofs
        pick = lambda cs: int(edf[(edf["harm"] == 1) & (edf["cs"] == cs)
                                  & (edf["node_num"] == 0) & (edf["sub"] == "m")].index[0])
        sol = [s for s in m.nls["frf"].SolList if s.flag_accepted][0]
        a.append(float(np.hypot(sol.x[pick("c")], sol.x[pick("s")])))
    return a


logging.disable(logging.CRITICAL)
if sys.argv[7:8] == ["at"]:  # A1 at the given frequencies only
    ws = list(np.linspace(w0, w1, int(sys.argv[8])))
    print("RESULT " + json.dumps({"w": ws, "a": at(ws)}))
    sys.exit(0)
out = run()
out["cold"] = time.perf_counter() - t0
if sys.argv[7:] != ["once"]:
    t1, c1 = time.perf_counter(), time.process_time()
    run()
    out["warm"], out["warm_cpu"] = time.perf_counter() - t1, time.process_time() - c1
print("RESULT " + json.dumps(out))
'''


def child(python: str, code: str, args, env=None) -> dict:
    """Run ``code`` with ``python`` in a fresh process; its ``RESULT {json}`` line."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "child.py"
        path.write_text(code)
        proc = subprocess.run([python, str(path), *map(str, args)], capture_output=True,
                              text=True, cwd=tmp, env=env, timeout=3600)
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    return {"error": (proc.stderr or proc.stdout).strip().splitlines()[-1:] or ["no output"]}


def curve_peak(w, a):
    """Peak (w, A1) of sampled points: the largest, refined by a parabola through its
    neighbours (the sample itself at an end of the band)."""
    pts = sorted(zip(w, a, strict=True))
    if not pts:
        return math.nan, math.nan
    ws, As = zip(*pts, strict=True)
    i = max(range(len(As)), key=As.__getitem__)
    if 0 < i < len(As) - 1:
        x0, x1, x2 = ws[i - 1 : i + 2]
        y0, y1, y2 = As[i - 1 : i + 2]
        den = (x0 - x1) * (x0 - x2) * (x1 - x2)
        A = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den
        B = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / den
        C = (x1 * x2 * (x1 - x2) * y0 + x2 * x0 * (x2 - x0) * y1
             + x0 * x1 * (x0 - x1) * y2) / den
        if A < 0:
            xv = -B / (2 * A)
            return xv, C - B * B / (4 * A)
    return ws[i], As[i]


def refined_peak(code, r, prob, H, pyharm, env):
    """The peak (w, A1) of a code's curve, found by the same code and the same estimator for
    both codes: from the coarse peak of its points (:func:`curve_peak`), the code's A1 at
    :data:`REFINE_POINTS` frequencies over +-:data:`REFINE_HALF` spacings around the largest
    point, :data:`REFINE_STAGES` times, the spacing shrinking tenfold each time; the largest
    A1 of the last stage. Near these peaks A1(w) has a cusp a few 1e-4 rad/s wide (with 128
    samples per period the instants of stick and slip move by whole samples), where a
    parabola through three points 0.005 rad/s apart is off by 1e-4 and more, as much as the
    errors compared; the last stage's spacing bounds the estimator's error by about 1e-7 of
    A1. At a given frequency both codes give the same A1 on (a) to 1e-10 (the same discrete
    equations: docs/theory.md, "A contact spring is the exact eps"). Returns ``(w, A1,
    refined)``. Points more than :data:`REFINE_JUMP` away from the coarse peak are left
    out (solutions off the curve: pyHarm's first solution at a frequency is not always on
    its branch); the coarse peak and False when a stage has no point left. Untimed: it
    measures accuracy, not speed."""
    wp, ap_ = coarse = curve_peak(r["w"], r["a"])
    if not math.isfinite(wp):
        return wp, ap_, False
    half = REFINE_HALF * (BAND[prob][1] - BAND[prob][0]) / (N_POINTS[prob] - 1)
    for _ in range(REFINE_STAGES):
        band = (wp - half, wp + half)
        if code == "pyHarm":
            fine = child(pyharm, PYHARM_CHILD, [prob, H, *band, 1, 1.0, "at", REFINE_POINTS],
                         env)
        else:
            fine = child(sys.executable, FRETWEAR_CHILD, [prob, H, REFINE_POINTS, *band,
                                                          r["eps"], "once"], env)
        on = [(a, w) for w, a in zip(fine.get("w", []), fine.get("a", []), strict=True)
              if abs(a / coarse[1] - 1) <= REFINE_JUMP]  # points off the curve left out
        if not on:
            return (*coarse, False)
        ap_, wp = max(on)
        half /= 10
    return wp, ap_, True


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pyharm", default=os.environ.get("PYHARM_PYTHON",
                                                       "/tmp/pyharm-venv/bin/python"),
                    help="python of the environment where pyharm-os 1.2.2 is installed")
    ap.add_argument("--harmonics", type=int, nargs="+", default=[7, 15])
    ap.add_argument("--first-ever", action="store_true",
                    help="also time a first run with empty numba and bytecode caches")
    ap.add_argument("--problems", nargs="+", choices=sorted(BAND), default=sorted(BAND),
                    help="problems to run (default: both)")
    ap.add_argument("--default-only", action="store_true",
                    help='on (b), leave out the rows of "top" and of eps = 1000 N/m')
    ap.add_argument("--recorded-references", action="store_true",
                    help="take the references from RECORDED instead of computing them")
    args = ap.parse_args(argv)
    have_pyharm = Path(args.pyharm).exists()
    if not have_pyharm:
        print(f"# no pyHarm interpreter at {args.pyharm}: install it with\n"
              "#   python3 -m venv /tmp/pyharm-venv && /tmp/pyharm-venv/bin/pip install "
              "pyharm-os==1.2.2")

    t0 = time.perf_counter()
    if args.recorded_references:
        refs, how = {k: RECORDED[k] for k in args.problems}, "recorded"
    else:
        systems = {"a": (ref.Jenkins(), 1.1, 1.3), "b": (ref.Chain(), 1.4, 1.6)}
        refs = {k: ref.peak(*systems[k]) for k in args.problems}
        how = f"event-driven + shooting, {time.perf_counter() - t0:.0f} s"
    print(f"# references ({how}): "
          + ", ".join(f"({k}) A1 = {v[1]:.7f} at w = {v[0]:.7f}" for k, v in refs.items()),
          flush=True)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    print(f"# machine load at the start (uptime): {os.getloadavg()[0]:.2f} "
          f"{os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f} on {os.cpu_count()} cores")
    print(f"{'code':9s} {'prob':4s} {'H':>3s} {'points':>6s} {'conv':>5s} {'warm_s':>8s} "
          f"{'cold_s':>8s} {'warm_cpu':>8s} {'peak_err':>10s} {'freq_err':>10s}  notes")
    ratios, err_ratios = [], []
    for prob in args.problems:
        w_ref, a_ref = refs[prob]
        for H in args.harmonics:
            rows = {"fretwear": child(sys.executable, FRETWEAR_CHILD,
                                      [prob, H, N_POINTS[prob], *BAND[prob], "default"], env)}
            if prob == "b" and not args.default_only:  # the rule "top" (the default before
                # "contact", which takes ten times it on (b)), and the penalty that pyHarm is
                # given, for a like-for-like accuracy
                for code, eps in (("fretwear^", "top"), ("fretwear*", 1000.0)):
                    rows[code] = child(sys.executable, FRETWEAR_CHILD,
                                       [prob, H, N_POINTS[prob], *BAND[prob], eps], env)
            errors = {}
            if have_pyharm:
                rows["pyHarm"] = child(args.pyharm, PYHARM_CHILD,
                                       [prob, H, *BAND[prob], PYHARM_MAX_SOLUTIONS, PYHARM_DS],
                                       env)
            for code, r in rows.items():
                if "error" in r:
                    print(f"{code:9s} {prob:4s} {H:3d}  failed: {r['error']}")
                    continue
                wp, ap_, refined = refined_peak(code, r, prob, H, args.pyharm, env)
                note = f"eps = {r['eps']:.3g} N/m" if "eps" in r else ""
                if not refined:
                    note += " peak not refined (coarse parabola)"
                errors[code] = ap_ / a_ref - 1
                print(f"{code:9s} {prob:4s} {H:3d} {r['points']:6d} {r['converged']:5d} "
                      f"{r['warm']:8.2f} {r['cold']:8.2f} {r['warm_cpu']:8.2f} "
                      f"{errors[code]:+10.2e} "
                      f"{wp / w_ref - 1:+10.2e}  {note}", flush=True)
            if prob == "b" and all(c in errors for c in ("fretwear", "pyHarm")):
                err_ratios.append(abs(errors["fretwear"]) / abs(errors["pyHarm"]))
            if all(c in rows and "error" not in rows[c] for c in ("fretwear", "pyHarm")):
                ratios.append(rows["pyHarm"]["warm"] / rows["fretwear"]["warm"])
    if args.first_ever:
        H = args.harmonics[0]
        for code, python, src, cargs in (
                ("fretwear", sys.executable, FRETWEAR_CHILD,
                 ["a", H, N_POINTS["a"], *BAND["a"], "default"]),
                ("pyHarm", args.pyharm if have_pyharm else None, PYHARM_CHILD,
                 ["a", H, *BAND["a"], PYHARM_MAX_SOLUTIONS, PYHARM_DS])):
            if python is None:
                continue
            with tempfile.TemporaryDirectory() as tmp:
                fresh = dict(env, NUMBA_CACHE_DIR=str(Path(tmp) / "numba"),
                             PYTHONPYCACHEPREFIX=str(Path(tmp) / "pycache"))
                t0 = time.perf_counter()
                r = child(python, src, cargs, fresh)
                wall = time.perf_counter() - t0
            if "error" in r:
                print(f"# first-ever {code}: failed: {r['error']}")
            else:
                print(f"# first-ever run, empty caches, (a) H = {H}: {code} cold "
                      f"{r['cold']:.2f} s (process wall time {wall:.2f} s)")
    print(f"# machine load (uptime): {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} "
          f"{os.getloadavg()[2]:.2f} on {os.cpu_count()} cores")
    gm = math.exp(sum(map(math.log, ratios)) / len(ratios)) if ratios else math.nan
    print(f"peak_err_ratio_b={max(err_ratios) if err_ratios else math.nan:.3g}")
    print(f"speedup_vs_pyharm_warm={gm:.3g}")


if __name__ == "__main__":
    main()
