"""Non-matching interface meshes converge to the matching-mesh answer as both are refined.

A steel block pressed on a steel base (2D plane strain: 20 x 10 mm on 20 x 5 mm; 3D: 10 x 10
x 4 mm on 10 x 10 x 4 mm) with friction (mu = 0.3) under a static pressure of 20 MPa and a
harmonic tangential traction on the block's side (stick and slip), solved by harmonic balance
(harmonics 0-3) at 2 kHz. At refinement level ``l`` the block has ``4 x 2^l`` elements along
the interface and the base ``5 x 2^l`` (non-matching: mortar pairing, or node-to-segment), or
``4 x 2^l`` (matching: node-to-node). The quantity is the first-harmonic amplitude of the
block's far top corner along the load. Printed per level: the two answers, their relative
difference, and the observed rate ``log2(diff(l-1) / diff(l))`` of that difference; CPU seconds
of the process and wall seconds. The last line reads
``nonmatching_rate_2d=<rate of the last level, mortar>``.

Run: ``python benchmarks/nonmatching.py [2d|3d]`` (both by default).
"""

from __future__ import annotations

import math
import os
import sys
import time

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.model import (
    ContactSpec,
    Damping,
    Material,
    Spring,
    Traction,
    box,
    from_mesh,
    join,
    rectangle,
)

STEEL = Material(210e9, 0.3, 7800.0)
BASIS = FourierBasis.up_to(3, 32)


def joint_2d(level: int, base_ratio: float, pairing: str):
    """The 2D block on base at ``level`` (module docstring)."""
    n = 4 * 2**level
    nb = round(base_ratio * n)
    mesh = join(("block", rectangle(0.02, 0.01, n, n // 2, origin=(0.0, 0.005))),
                ("base", rectangle(0.02, 0.005, nb, max(1, nb // 4))))
    return from_mesh(
        mesh, STEEL, damping=Damping(loss_factor=0.02),
        supports=[Spring("block.top_left", "x", 1e7), ("base.bottom", "all")],
        loads=[Traction("block.top", pressure=20e6, waveform="constant"),
               Traction("block.right", traction=(-1e7, 0.0), waveform="cos")],
        contact=ContactSpec("block.bottom", mu=0.3, partner="base.top", pairing=pairing),
        observed={"tip": (0.02, 0.015)})


def joint_3d(level: int, base_ratio: float, pairing: str):
    """The 3D block on base at ``level`` (module docstring)."""
    n = 2 * 2**level
    nb = round(base_ratio * n)
    mesh = join(("block", box(0.01, 0.01, 0.004, n, n, max(1, n // 2),
                              origin=(0.0, 0.0, 0.004))),
                ("base", box(0.01, 0.01, 0.004, nb, nb, max(1, nb // 2))))
    return from_mesh(
        mesh, STEEL, damping=Damping(loss_factor=0.02),
        supports=[Spring((0.0, 0.0, 0.008), "x", 1e7), Spring((0.0, 0.0, 0.008), "y", 1e7),
                  Spring((0.0, 0.01, 0.008), "x", 1e7), ("base.zmin", "all")],
        loads=[Traction("block.zmax", pressure=20e6, waveform="constant"),
               Traction("block.xmax", traction=(-2e6, 0.0, 0.0), waveform="cos")],
        contact=ContactSpec("block.zmin", mu=0.3, partner="base.zmax", pairing=pairing),
        observed={"tip": (0.01, 0.0, 0.008)})


def amplitude(model) -> float:
    """First-harmonic amplitude of the tip along x [m]."""
    sol = solve_periodic(model, BASIS, frequency=2000.0, options=SolveOptions(tol=1e-12),
                         raise_on_failure=True)
    u = np.asarray(sol.observed["tip"])[0]
    return float(np.hypot(u[1], u[2]))


def converge(build, levels, base_ratio) -> list[float]:
    """Relative differences of the non-matching answers (mortar and node-to-segment) from the
    matching one, per level; prints a table."""
    print(f"{'level':>5} {'matching':>12} {'mortar':>12} {'diff':>9} {'rate':>5} "
          f"{'n-to-seg':>12} {'diff':>9} {'rate':>5} {'cpu s':>6} {'wall s':>6}")
    diffs = {"mortar": [], "node-to-segment": []}
    for level in levels:
        t0, w0 = time.process_time(), time.perf_counter()
        ref = amplitude(build(level, 1.0, "node-to-node"))
        row = [f"{level:5d} {ref:12.5e}"]
        for pairing, d in diffs.items():
            a = amplitude(build(level, base_ratio, pairing))
            d.append(abs(a - ref) / abs(ref))
            rate = math.log2(d[-2] / d[-1]) if len(d) > 1 and d[-1] > 0 else float("nan")
            row.append(f"{a:12.5e} {d[-1]:9.2e} {rate:5.2f}")
        print(" ".join(row), f"{time.process_time() - t0:6.1f} {time.perf_counter() - w0:6.1f}")
    return diffs["mortar"]


def main() -> None:
    which = sys.argv[1:] or ["2d", "3d"]
    print(f"load before: {os.getloadavg()[0]:.2f}")
    rate = float("nan")
    if "2d" in which:
        print("2D: block 4 x 2^l against base 5 x 2^l elements along the interface")
        d = converge(joint_2d, range(4), 1.25)
        rate = math.log2(d[-2] / d[-1])
    if "3d" in which:
        print("3D: block (2 x 2^l)^2 against base (3 x 2^l)^2 faces")
        converge(joint_3d, range(3), 1.5)
    print(f"load after: {os.getloadavg()[0]:.2f}")
    print(f"nonmatching_rate_2d={rate:.2f}")


if __name__ == "__main__":
    main()
