"""Cost and robustness of the time-domain contact solve in 3D (the isotropic Coulomb cone).

A steel pad 10 x 10 x 5 mm of n x n x 1 hexahedra ((n+1)^2 contact nodes) pressed on a rigid
flat by 10 MPa and loaded on top by a uniform traction ``ratio`` mu P cos(2 pi 1000 t) at 30 deg
(mu = 0.3), held along x and y by springs (1e7 N/m). Prints, on this machine and in this run,
for each pad:

- the time integration from rest (20 periods of 256 steps; the default step): wall time,
  microseconds per step, contact solves that did not settle, largest Newton iteration count;
  and the time per step as a ratio to one dense LU factorisation of the m x m step operator
  (``m = 3 x nodes``) timed in the same run (``step_over_lu``);
- the incremental wear by load steps (5 cycles of 64 steps): wall time, steps that did not
  settle, largest iteration count;
- for ratio 0.8 (partial slip) and 1.5 (the pad slides on its springs).

Run: ``python benchmarks/contact_3d.py [--sizes 3 5 7]``. Before this solver, the 16-node pad
(n = 3, ratio 0.8) reported 1650 contact solves that did not settle in 20 periods.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
import scipy.linalg as sla

from fretwear.model.build import ContactSpec, Damping, Material, Spring, Traction, from_mesh
from fretwear.model.mesh import box
from fretwear.timedomain.integrate import integrate
from fretwear.timedomain.options import IncrementalWearOptions, IntegrationOptions
from fretwear.timedomain.quasistatic import incremental_wear

MU, P = 0.3, 10e6


def pad(n, ratio):
    q = ratio * MU * P
    t = np.radians(30.0)
    return from_mesh(
        box(0.01, 0.01, 0.005, n, n, 1), Material(210e9, 0.3, 7800.0),
        damping=Damping(rayleigh_stiffness=0.02 / (2 * np.pi * 1e5)),
        supports=[Spring("zmax", "x", 1e7), Spring("zmax", "y", 1e7)],
        loads=[Traction("zmax", pressure=P),
               Traction("zmax", traction=(q * np.cos(t), q * np.sin(t), 0.0), waveform="cos")],
        contact=ContactSpec("zmin", mu=MU, wear_coefficient=1e-14),
        observed={"top": (0.005, 0.005, 0.005)})


def lu_time(m, repeat=20):
    a = np.random.default_rng(0).standard_normal((m, m)) + m * np.eye(m)
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        sla.lu_factor(a)
        best = min(best, time.perf_counter() - t0)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[3, 5, 7])
    args = ap.parse_args()
    # compile the kernels once (cached on disk afterwards)
    t0 = time.perf_counter()
    integrate(pad(1, 0.8), 1e3, options=IntegrationOptions(steps_per_period=16), n_periods=1)
    incremental_wear(pad(1, 0.8), options=IncrementalWearOptions(steps_per_cycle=8), n_cycles=1)
    print(f"warm-up (numba compile or cache load): {time.perf_counter() - t0:.2f} s")
    for n in args.sizes:
        nodes = (n + 1) ** 2
        m = 3 * nodes
        t_lu = lu_time(m)
        for ratio in (0.8, 1.5):
            model = pad(n, ratio)
            steps, periods = 256, 20
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                res = integrate(model, 1e3, options=IntegrationOptions(steps_per_period=steps),
                                n_periods=periods)
            per_step = res.wall_time / (steps * periods)
            print(f"pad {nodes} nodes, ratio {ratio}: integrate {res.wall_time:.2f} s "
                  f"({per_step * 1e6:.0f} us/step, step_over_lu={per_step / t_lu:.1f}, "
                  f"lu {t_lu * 1e6:.0f} us), failed={res.info['failed_steps']}, "
                  f"max_iterations={res.info['max_active_set_iterations']}")
            wr = incremental_wear(model, options=IncrementalWearOptions(steps_per_cycle=64),
                                  n_cycles=5, raise_on_failure=False)
            print(f"pad {nodes} nodes, ratio {ratio}: incremental_wear {wr.wall_time:.2f} s, "
                  f"success={wr.success}, max_iterations="
                  f"{wr.info['max_active_set_iterations']}")


if __name__ == "__main__":
    main()
