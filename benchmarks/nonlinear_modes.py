"""Nonlinear modes and stability: accuracy against a closed form and the cost of Hill's method.

* The EPMC backbone of a Jenkins oscillator (m = k = kt = 1, mu N = 0.1) with one harmonic
  against the closed form of the element's describing function (docs/theory.md, "Nonlinear
  modes"), for 64 to 1024 samples: the error of the stick-slip instants falling between
  samples, O(N^-2).
* The virtual beam of Scheel, Weigele and Krack (J. Sound Vib. 2020; the parameters of
  NLtest's example BT01): its backbone with 7 harmonics and 256 samples over log10 a from
  -5.5 to -3.1, beside the one-harmonic backbone (the describing-function mode,
  tests/hb/test_nonlinear_modes.py) and the linear stuck and sliding modes; its cost.
* Hill's method at every point of three frequency sweeps (a forced Jenkins oscillator, 7
  harmonics; the two-DOF oscillator with a unilateral spring, 15 harmonics; the virtual beam
  forced at its tip across its first mode, 7 harmonics: a structure of 28 DOFs, whose
  candidates' pencil is truncated to the held structure's low modes), each point given the
  result of the nearest point already computed to track its candidates from (as
  :func:`fretwear.hb.sweep_stability.sweep_stability` does, on the problem the sweep solved
  the point on): its time against the point's solve, median and range.

The point's solve is what the sweep spent on it, as the sweep records it
(``SweepPoint.cpu_seconds`` and ``seconds``, :meth:`fretwear.hb.branch.Branch.lap`): the
predictor, the condensation at its frequency, every attempt (failed ones included), the
polish, the solution assembled. The median is over the grid points; the intermediate points
a ladder adds (substeps, the arclength's branch: the arclength records its points after
computing them all, so the first holds the others' share) are in the sweep's totals, printed
too. Two other denominators were used before, and both were
wrong: the attempts' own wall times (the solver's iterations alone, without the
condensation and the recording: about two thirds of the point's CPU on these models, so the
ratio was too high; none for the intermediate points), and a warm-started
:func:`~fretwear.hb.periodic.solve_periodic` repeated per point (with a single solve's
set-up, the static preload solve, a second condensation and the input checks, which the
sweep pays once: 2-2.5 times the point's CPU, so the ratio was too low). The ratio is of CPU
seconds: the machine is shared, and a wall time holds 4-8 ms of waiting for a core at random
points, more than a point's solve; the wall ratio is printed too.

Prints ``hill_cost_ratio_sweeps=`` (each sweep's median) and
``hill_cost_ratio_pooled_small=`` (the median over the two small oscillators' points pooled:
the headline before the beam's sweep was added). Ends with ``epmc_jenkins_err=<max relative
error, one harmonic, 1024 samples>``, ``hill_cost_ratio_wall=`` (wall seconds) and
``hill_cost_ratio=<stability time / solve time, the largest of the sweeps' medians>`` (CPU
seconds): the target is on every model, so a sweep of small ratios must not hide the beam's.
Run: ``python benchmarks/nonlinear_modes.py``
(the JIT warm-up, about a minute on first use, runs before the timings).
"""

from __future__ import annotations

import os
import time

import numpy as np
import scipy.linalg as sla

from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.nonlinear_modes import nonlinear_mode
from fretwear.hb.options import SweepOptions
from fretwear.hb.reduce import exact_condenser
from fretwear.hb.stability import hill_stability, stability
from fretwear.hb.sweep import sweep
from fretwear.hb.sweep_stability import Computed, nearest, point_problem, sweep_stability
from fretwear.model.beam import cantilever_matrices, modal_damping
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

M_, K_, KT, FS = 1.0, 1.0, 1.0, 0.1
#: the virtual beam's tip force in its sweep [N]: the element sticks and slips over the sweep
#: (61 to 84.5 Hz, from below the sliding mode's 68 Hz to above the stuck mode's 80 Hz)
BEAM_FORCE = 5.0


def jenkins(force=None, c=0.0):
    loads = [Load(np.array([force]), "cos")] if force else []
    return from_matrices([[K_]], [[M_]],
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=FS,
                                             normal_load=1.0, kt=KT),
                         damping=Damping(C=[[c]] if c else None), loads=loads,
                         observed={"x": 0})


def two_dof(kn=10.0, gap=0.5, force=0.1):
    K = np.diag([0.0, 0.0, 1.0])
    K[:2, :2] = [[1.0, -1.0], [-1.0, 2.0]]
    C = 0.03 * K
    C[2, 2] = 1.0
    return from_matrices(K, np.eye(3),
                         contact=ContactDofs(normal_dofs=[0], tangential_dofs=[2], gap=gap,
                                             mu=0.0, kn=kn, kt=kn),
                         damping=Damping(C=C), loads=[Load(np.array([0.0, force, 0.0]), "cos")],
                         observed={"x1": 0, "x2": 1})


def closed_form(a):
    a_s = FS / KT
    th = np.arccos(np.clip(1.0 - 2.0 * a_s / a, -1.0, 1.0))
    K = np.where(a > a_s, KT / np.pi * (th - np.sin(2.0 * th) / 2.0), KT)
    D = np.where(a > a_s, 4.0 * FS * (a - a_s) / (np.pi * a * a), 0.0)
    w = np.sqrt((K_ + K) / M_)
    return w, D / (2.0 * M_ * w * w)


def epmc_errors():
    amps = np.geomspace(0.01, 10.0, 40)
    out = {}
    for n in (64, 128, 256, 512, 1024):
        t0 = time.perf_counter()
        bb = nonlinear_mode(jenkins(), FourierBasis((1,), n), amps)
        wall = time.perf_counter() - t0
        a = bb.array("amplitude") / np.sqrt(M_)
        w_ref, z_ref = closed_form(a)
        slip = z_ref > 0
        ew = float(np.max(np.abs(bb.array("omega") / w_ref - 1.0)))
        ez = float(np.max(np.abs(bb.array("damping_ratio")[slip] / z_ref[slip] - 1.0)))
        out[n] = max(ew, ez)
        print(f"  {n:5d} samples: frequency {ew:.2e}, damping ratio {ez:.2e} (relative), "
              f"backbone of {len(bb.points)} amplitudes in {wall:.2f} s")
    return out


def virtual_beam(force=None):
    """NLtest's BT01 beam: 15-node cantilever (L 0.71 m, h 0.05 m, t 0.06 m, E 0.6725 x 210
    GPa, rho 7850 kg/m^3), a Jenkins element (kt 1e7 N/m, mu N 15 N) on the deflection of
    node 6 (node 1 clamped), 1 % damping on every mode with the element stuck; the tip (node
    15) observed, and loaded by ``force`` [N] (cosine) where given. Returns the model and the
    element's DOF."""
    K, M = cantilever_matrices(0.71, 0.05, 0.06, 0.6725 * 210e9, 7850.0, 15)
    kt, dof = 1e7, 8
    e = np.zeros(len(K))
    e[dof] = 1.0
    C = modal_damping(K + kt * np.outer(e, e), M, 0.01)
    loads = []
    if force:
        f = np.zeros(len(K))
        f[len(K) - 2] = force
        loads = [Load(f, "cos")]
    model = from_matrices(K, M, contact=ContactDofs(normal_dofs=None, tangential_dofs=[dof],
                                                    mu=15.0, normal_load=1.0, kt=kt),
                          damping=Damping(C=C), loads=loads, observed={"tip": len(K) - 2})
    return model, dof


def beam_backbone():
    model, _ = virtual_beam()
    K, M = cantilever_matrices(0.71, 0.05, 0.06, 0.6725 * 210e9, 7850.0, 15)
    w_slide = np.sqrt(sla.eigh(K, M, eigvals_only=True)[0])
    amps = 10.0 ** np.linspace(-5.5, -3.1, 25)
    c0, t0 = time.process_time(), time.perf_counter()
    bb = nonlinear_mode(model, FourierBasis.up_to(7, 256), amps)
    cpu, wall = time.process_time() - c0, time.perf_counter() - t0
    one = nonlinear_mode(model, FourierBasis((1,), 256), amps)
    f7, z7 = bb.array("frequency"), bb.array("damping_ratio")
    f1, z1 = one.array("frequency"), one.array("damping_ratio")
    print(f"  virtual beam, 7 harmonics, 256 samples: {len(bb.points)} of {amps.size} "
          f"amplitudes ({bb.message or 'all converged'}), {cpu:.2f} s CPU, {wall:.2f} s wall")
    print("   log10 a   f [Hz] zeta [%]   f(H=1)  zeta(H=1)")
    for i, p in enumerate(bb.points):
        print(f"   {np.log10(p.amplitude):6.2f} {f7[i]:8.3f} {100 * z7[i]:7.3f} "
              f"{f1[i]:9.3f} {100 * z1[i]:7.3f}")
    print(f"  stuck mode {f7[0]:.3f} Hz at {100 * z7[0]:.3f} %, sliding mode "
          f"{w_slide / (2 * np.pi):.3f} Hz; largest difference from one harmonic: "
          f"frequency {np.max(np.abs(f7 / f1 - 1)):.2e}, damping ratio "
          f"{np.max(np.abs(z7 / z1 - 1)):.2e} (relative); peak damping "
          f"{100 * z7.max():.2f} % at log10 a = {np.log10(amps[np.argmax(z7)]):.2f}")


def _hill(model, p, dyn, cond, seen):
    """Hill's method at the sweep point ``p`` as :func:`sweep_stability` does it: on the
    problem the sweep solved it on, candidates from the nearest point already computed."""
    prob = point_problem(model, p, cond)
    return hill_stability(prob, p.solution.U.reshape(prob.m, prob.H), dyn,
                          previous=nearest(p.solution.U, seen))


def hill_ratios(model, basis, f_min, f_max, n_points, label):
    """Hill's time at every converged point, over what the sweep spent on that point
    (:attr:`~fretwear.hb.sweep_result.SweepPoint.cpu_seconds` and ``seconds``): CPU over CPU
    and wall over wall (printed, the load disturbs it), median over the grid points; the
    sweep's totals (Hill at every point, intermediate ones included, over the whole sweep's
    points) beside it."""
    cond = exact_condenser(model)
    res = sweep(model, basis, f_min, f_max, n_points, options=SweepOptions(spacing="linear"),
                condenser=cond)
    dyn = structure_dynamics(model, cond)
    ratios, cpu_ratios, unstable, evals, tracked, seen = [], [], 0, 0, 0, Computed()
    hill_grid = solve_grid = hill_all = solve_all = 0.0
    for p in res.points:
        if p.solution is None:
            continue
        t0, c0 = time.perf_counter(), time.process_time()
        fl = _hill(model, p, dyn, cond, seen)
        wall, hill_cpu = time.perf_counter() - t0, time.process_time() - c0
        seen.append((p.solution.U, fl))
        hill_all += hill_cpu
        solve_all += p.cpu_seconds
        if not p.on_grid:  # a substep or the arclength's: in the totals only (the arclength
            continue  # records its points after computing them all: the first one's
        ratios.append(wall / max(p.seconds, 1e-9))  # share holds the others')
        cpu_ratios.append(hill_cpu / max(p.cpu_seconds, 1e-9))
        hill_grid += hill_cpu
        solve_grid += p.cpu_seconds
        tracked += fl.tracked
        evals += fl.evaluations
        unstable += not fl.stable
    r, rc, n = np.array(ratios), np.array(cpu_ratios), len(ratios)
    print(f"  {label}: {n} grid points ({unstable} unstable), stability / solve (CPU): median "
          f"{np.median(rc):.2f}, range {rc.min():.2f}-{rc.max():.2f}; wall: median "
          f"{np.median(r):.2f}; per grid point: Hill CPU {1e3 * hill_grid / n:.2f} ms, the "
          f"solve's {1e3 * solve_grid / n:.2f} ms, {evals / n:.1f} evaluations of T(s), "
          f"{tracked} tracked from the nearest computed point; the whole sweep "
          f"({len(seen)} points): Hill {hill_all:.3f} s CPU, the solves {solve_all:.3f} s, "
          f"ratio {hill_all / solve_all:.2f}")
    return r, rc


def main():
    print(f"load average before: {os.getloadavg()[0]:.1f}")
    c0 = time.process_time()
    # JIT warm-up
    nonlinear_mode(jenkins(), FourierBasis((1,), 16), [0.5, 1.0])
    sol_model = jenkins(0.2, c=0.02)
    res = sweep(sol_model, FourierBasis.up_to(3, 32), 0.18, 0.2, 3,
                options=SweepOptions(spacing="linear"))
    stability(sol_model, res.points[-1].solution)
    # and Hill's along a sweep: the tracking's and the warm-started refinement's kernels are
    # loaded from numba's cache at their first call, which the point above does not make
    # (with no Hill run before, the Jenkins sweep's Hill took 0.23 s of CPU on its first
    # pass, 0.08 s on the next ones)
    res = sweep(sol_model, FourierBasis.up_to(3, 32), 0.15, 0.23, 8,
                options=SweepOptions(spacing="linear"))
    sweep_stability(sol_model, res)
    # and the law without memory's tracking (the harmonic split, the certified copies, the
    # dense eigensolve): on a cold cache the two-DOF sweep's first points compiled them
    # inside the timing (one point 590 times its solve)
    res = sweep(two_dof(), FourierBasis.up_to(5, 64), 0.56 / (2 * np.pi), 0.8 / (2 * np.pi),
                8, options=SweepOptions(spacing="linear"))
    sweep_stability(two_dof(), res)
    print("EPMC of a Jenkins oscillator, one harmonic, against the describing function:")
    err = epmc_errors()
    print("Nonlinear mode of the virtual beam (NLtest BT01):")
    beam_backbone()
    print("Hill's method on sweeps:")
    r1 = hill_ratios(jenkins(0.2, c=0.02), FourierBasis.up_to(7, 128), 0.15, 0.23, 30,
                     "Jenkins oscillator, 7 harmonics")
    r2 = hill_ratios(two_dof(), FourierBasis.up_to(15, 256), 0.56 / (2 * np.pi),
                     0.8 / (2 * np.pi), 30, "two-DOF unilateral spring, 15 harmonics")
    r3 = hill_ratios(virtual_beam(BEAM_FORCE)[0], FourierBasis.up_to(7, 256), 61.0, 84.5, 30,
                     f"virtual beam, {BEAM_FORCE:g} N at the tip, 7 harmonics")
    print(f"load average after: {os.getloadavg()[0]:.1f}; CPU {time.process_time() - c0:.1f} s")
    names = ("jenkins", "two_dof", "beam")
    medians = [float(np.median(r[1])) for r in (r1, r2, r3)]
    print("hill_cost_ratio_sweeps="
          + ",".join(f"{n}:{v:.3g}" for n, v in zip(names, medians, strict=True)))
    print("hill_cost_ratio_pooled_small="
          f"{float(np.median(np.concatenate([r1[1], r2[1]]))):.3g}")
    print(f"epmc_jenkins_err={err[1024]:.3g}")
    print(f"hill_cost_ratio_wall={max(float(np.median(r[0])) for r in (r1, r2, r3)):.3g}")
    print(f"hill_cost_ratio={max(medians):.3g}")


if __name__ == "__main__":
    main()
