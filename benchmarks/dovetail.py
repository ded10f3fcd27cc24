"""Cost of the two-body dovetail example (a 3D blade root in a disc slot, two node-to-node
flanks; src/fretwear/examples/dovetail-frf.toml and dovetail-wear.toml).

Prints, on this machine and in this run, with the number of unknowns of each stage:
- the model: DOFs, contact pairs, reduced DOFs (3 per pair, relative displacements);
- the condensation on the pairs' relative DOFs for harmonics [0, 1] and [0, 1, 2, 3];
- one periodic solve at 2.4 kHz with 1 and with 3 harmonics (unknowns = reduced DOFs x
  coefficients), and as a machine reference the time of one dense LU factorisation of the
  Jacobian's size, timed in the same run (``solve_over_lu``);
- one slow wear step of the wear example (its first step after the unworn balance);
- before them, one untimed-in-the-figures warm-up solve (the numba kernels are compiled on
  the first run of a fresh installation);
- the linear references of the FRF (sliding and stuck flanks) on the 1000 frequencies of a
  sweep's own grid by projection (``fretwear.linear.frf(method="projected")``: its sparse
  solves counted), against the direct FRF (one sparse solve per frequency) at 10 of them,
  timed in the same run, with the largest relative difference;
- a nonlinear FRF of ``--points`` (default 50) points from 1.9 to 2.8 kHz with the example's
  settings (1 harmonic), and how many converged, twice in the same run: with the exact
  condensation at every frequency, and with the case file's default (``condensation =
  "auto"``: one modal basis with residual vectors for the whole band, its error check
  printed); the largest relative difference of the points converged in both. The last lines
  are ``frf50_cpu_s=`` (processor seconds of the new path, its condenser's build included)
  and ``frf50_speedup=`` (the exact path's processor time over the new path's).

Run: ``python benchmarks/dovetail.py [--points 50] [--quick] [--verbose]`` (``--quick``
skips the nonlinear FRF, ``--verbose`` prints one line per FRF point: how it converged and
its time).
Quote the figures with the machine load (``uptime``).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
import scipy.linalg as sla

from fretwear import linear
from fretwear.analyses.run import load_case
from fretwear.examples import example_path
from fretwear.hb.condensers import condenser
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SweepOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.reduce import condense, exact_condenser
from fretwear.hb.sweep import sweep
from fretwear.io.case import build_model
from fretwear.wear import BalanceSetup, WearOptions, simulate_wear

CPU: list = [0.0]  # processor time of the last _timed call [s]


def _timed(fn):
    """``(fn(), wall time [s])``; the processor time of the call is left in ``CPU[0]`` (on a
    machine shared with other work the wall time grows with the load, the processor time
    much less)."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    CPU[0] = time.process_time() - c0
    return out, time.perf_counter() - t0


def _cpu() -> str:
    return f" (processor {CPU[0]:.2f} s)"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=50, help="points of the FRF sweep")
    ap.add_argument("--quick", action="store_true", help="skip the FRF sweep")
    ap.add_argument("--verbose", action="store_true", help="one line per FRF point")
    args = ap.parse_args()

    model, t_build = _timed(lambda: build_model(load_case(example_path("dovetail-frf"))))
    c = model.contact
    m = c.n_nodes * c.dim
    print(f"model: {model.ndof} DOFs, {c.n_nodes} node-to-node pairs on "
          f"{len(c.names())} flanks, {m} reduced DOFs; built in {t_build:.2f} s")

    f = 2400.0
    print(f"load average at the start: {os.getloadavg()[0]:.2f} ({os.cpu_count()} cores)")
    def set_up():  # the model's condenser, passed to every call below
        cond = exact_condenser(model)
        condense(model, 0.0, [0], quasi_static=True, condenser=cond)
        return cond

    cond, t = _timed(set_up)
    print(f"condensation set-up (once per model: blocks, static LU, harmonic 0): {t:.2f} s"
          + _cpu())
    basis = FourierBasis.up_to(1, 16)
    _, t = _timed(lambda: solve_periodic(model, basis, frequency=0.95 * f, eps="static",
                                         condenser=cond))
    print(f"warm-up: one periodic solve with its condensation {t:.2f} s (numba kernels "
          "compiled, or loaded from their cache)")
    for orders, fc in (([0, 1], f), ([0, 1, 2, 3], 1.01 * f)):  # no factorisation reused
        _, t = _timed(lambda o=orders, fc=fc: condense(model, fc, o, condenser=cond))
        print(f"condensation at a new frequency, harmonics {orders}: {t:.2f} s" + _cpu())

    for nh in (1, 3):
        basis = FourierBasis.up_to(nh, 16 * nh)
        red = condense(model, f, [0, *basis.harmonics], condenser=cond)
        sol, t = _timed(lambda b=basis, r=red: solve_periodic(model, b, frequency=f,
                                                              reduced=r, eps="static",
                                                              condenser=cond))
        cpu = _cpu()
        n = m * basis.size
        A = np.random.default_rng(0).standard_normal((n, n))
        _, t_lu = _timed(lambda a=A: sla.lu_factor(a))
        st = sol.stats
        print(f"periodic solve, {nh} harmonic(s): {n} unknowns, {t:.2f} s{cpu} "
              f"({st.iterations} iterations, success={sol.success}); dense LU of {n}: "
              f"{t_lu:.3f} s; solve_over_lu={t / t_lu:.1f}")

    wear_model = build_model(load_case(example_path("dovetail-wear")))
    wcase = load_case(example_path("dovetail-wear"))
    wb = FourierBasis.up_to(wcase.analysis["harmonics"], wcase.analysis["n_samples"])
    res, t = _timed(lambda: simulate_wear(wear_model, wb, frequency=wcase.analysis["frequency"],
                                          balance=BalanceSetup(eps="static"),
                                          options=WearOptions(max_steps=1)))
    h = res.history
    print(f"wear: first slow step {h.wall_time[-1]:.2f} s (run with the unworn balance "
          f"{t:.2f} s{_cpu()}, {m * wb.size} unknowns, jump {h.jump[-1]:.3g} cycles, "
          f"success={res.success})")

    freqs = linear.frequency_grid(1900.0, 2800.0, 1000, "linear")
    some = freqs[::100]
    solves = [0]
    real = linear._solve

    def counted(*a, **k):
        solves[0] += 1
        return real(*a, **k)

    for interface in ("sliding", "stuck"):
        solves[0] = 0
        linear._solve = counted
        try:
            r, t_p = _timed(lambda i=interface: linear.frf(model, freqs, interface=i,
                                                           method="projected"))
        finally:
            linear._solve = real
        d, t_d = _timed(lambda i=interface: linear.frf(model, some, interface=i))
        diff = max(float((np.abs(r.observed[k][::100] - d.observed[k]).max(axis=1)
                          / np.abs(d.observed[k]).max(axis=1)).max()) for k in d.observed)
        print(f"linear FRF, {interface} flanks: {freqs.size} frequencies by projection "
              f"{t_p:.1f} s ({solves[0]} sparse solves); direct {t_d / some.size:.2f} s per "
              f"frequency; largest relative difference at {some.size} frequencies {diff:.1e}")

    if not args.quick:
        _frf(model, m, args)
    else:
        print(f"load average at the end: {os.getloadavg()[0]:.2f}")


def _frf(model, m, args):
    """The nonlinear FRF of the example's settings twice in this run: with the exact
    condensation at every frequency (one exact condenser, as before) and with the case file's
    default condensation (``fretwear.condenser(model, "auto", f_max=, max_order=)``: one modal
    basis with residual vectors for the whole band, its build timed with it); the largest
    relative difference of the points converged in both, on the observed responses and on the
    contact displacements and forces."""
    case = load_case(example_path("dovetail-frf"))
    a = case.analysis
    basis = FourierBasis.up_to(a["harmonics"], a["n_samples"])
    t_sweep = [time.perf_counter()]

    def show(i, n, pt):
        now = time.perf_counter()
        if args.verbose:
            print(f"  {i + 1:3d}/{n} {pt.frequency_hz:8.1f} Hz {pt.how:22s} "
                  f"{pt.stats.iterations:3d} it, {len(pt.attempts)} attempts, "
                  f"{now - t_sweep[0]:6.1f} s, success={pt.success}", flush=True)
        t_sweep[0] = now

    def run(make):
        cond = make()
        res = sweep(model, basis, a["f_min"], a["f_max"], args.points,
                    options=SweepOptions(spacing="linear", eps=a["eps"], progress=show),
                    condenser=cond)
        return cond, res

    out, cpu = {}, {}
    for name, make in (("exact at every frequency", lambda: condenser(model, "exact")),
                       ("auto (one modal basis)",
                        lambda: condenser(model, "auto", f_max=a["f_max"],
                                          max_order=max(basis.harmonics)))):
        print(f"load average before the FRF, {name}: {os.getloadavg()[0]:.2f}")
        (cond, res), t = _timed(lambda mk=make: run(mk))
        cpu[name] = CPU[0]
        out[name] = res
        grid = [p for p in res.points if p.on_grid]
        ok = sum(p.success for p in grid)
        print(f"FRF, condensation {name}: {args.points} points, {m * basis.size} unknowns "
              f"each, {t:.1f} s{_cpu()}, {t / args.points:.2f} s per point; "
              f"sweep_converged={ok}/{len(grid)} ({len(res.points) - len(grid)} intermediate "
              f"points)")
        print(f"  {cond.choice.summary()}")
    ref, new = out.values()
    d_obs, d_u, d_lam, both = _differences(ref, new)
    print(f"converged in both: {both} grid points; largest relative difference: observed "
          f"responses {d_obs:.2e}, contact displacements {d_u:.2e}, contact forces "
          f"{d_lam:.2e}")
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")
    c_ref, c_new = cpu.values()
    print(f"frf50_cpu_s={c_new:.2f}")
    print(f"frf50_speedup={c_ref / c_new:.1f}")


def _differences(ref, new):
    """Largest relative differences (observed harmonics, contact ``U``, contact ``lam``: each
    ``max |new - ref| / max |ref|`` per point) over the grid points converged in both."""
    pr = {p.frequency_hz: p for p in ref.points if p.on_grid and p.success}
    d_obs = d_u = d_lam = 0.0
    both = 0
    for p in new.points:
        q = pr.get(p.frequency_hz)
        if q is None or not (p.on_grid and p.success):
            continue
        both += 1
        for k, c in q.solution.observed.items():
            d_obs = max(d_obs, _rel(p.solution.observed[k], c))
        d_u = max(d_u, _rel(p.solution.U, q.solution.U))
        d_lam = max(d_lam, _rel(p.solution.lam, q.solution.lam))
    return d_obs, d_u, d_lam, both


def _rel(a, b) -> float:
    return float(np.abs(np.asarray(a) - b).max() / max(np.abs(b).max(), 1e-300))

if __name__ == "__main__":
    main()
