"""One sector against its whole disk: a coarse 3D annular sector (N = 24, steel, hub clamped,
a tip strip rubbing on a rigid casing, a static radial press and a tangential force of
engine order EO = 3 near the tip), every sector of the disk with the same contact.

For each of a few frequencies: one DLFT periodic solve (harmonics 1-3, fixed eps, relative
residual 1e-12) on the sector with its cyclic condenser (fretwear.hb.cyclic) and on the disk
assembled from 24 turned copies (fretwear.model.cyclic.whole_disk) with the exact condenser;
the largest difference of sector 0's contact harmonics relative to their largest value, and
the CPU seconds of the process (condenser set-up included) beside wall seconds; ``uptime``
before and after. The last lines read ``sector_vs_disk_speedup=<disk CPU s / sector CPU s>``
and ``sector_vs_disk_diff=<max relative difference>``.

The excitation is large enough for every tip node to separate or slip twice per period: a
3D node that sticks all but one instant of the period has a family of periodic states (its
force traces a curve inside the friction disc that touches the disc once; any position
along that contact is periodic), and the disk's time law, which starts every sector's
period at t = 0 from the same anchor, then settles each sector at another one of them, so
that the disk's answer is not a travelling wave (measured: 6 % apart at 1/10 of this load,
N = 6); the sector gives the travelling-wave one (docs/theory.md).

Run: ``python benchmarks/cyclic.py``.
"""

from __future__ import annotations

import os
import subprocess
import time

import numpy as np

from fretwear.hb.cyclic import cyclic_condenser
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.reduce import exact_condenser
from fretwear.model import ContactSpec, Material, NodalForce, from_mesh
from fretwear.model.core import Mesh
from fretwear.model.cyclic import cyclic_sector, whole_disk
from fretwear.model.mesh import box

N, EO = 24, 3
R_IN, R_OUT, WIDTH = 0.1, 0.2, 0.02
FREQUENCIES = (2500.0, 4000.0)


def sector_mesh(nr=3, nt=3, nz=2) -> Mesh:
    """Hexahedra on ``R_IN <= r <= R_OUT``, ``0 <= theta <= 2 pi / N``, ``0 <= z <= WIDTH``:
    node sets ``left`` (theta = 0), ``right`` (theta = alpha), ``hub``, ``load``; boundary
    ``tip`` (r = R_OUT, the facets off the cyclic boundaries)."""
    alpha = 2 * np.pi / N
    m = box(R_OUT - R_IN, alpha, WIDTH, nr, nt, nz, origin=(R_IN, 0.0, 0.0))
    r, t, z = m.points.T
    pts = np.column_stack([r * np.cos(t), r * np.sin(t), z])
    on_side = (t < 1e-12) | (t > alpha - 1e-12)
    tip = m.boundaries["xmax"]
    tip = tip[~np.any(on_side[tip], axis=1)]
    inner = np.flatnonzero((np.abs(r - (R_IN + (nr - 1) * (R_OUT - R_IN) / nr)) < 1e-12)
                           & ~on_side & (z < 1e-12))
    sets = {"left": m.node_sets["ymin"], "right": m.node_sets["ymax"],
            "hub": m.node_sets["xmin"], "load": inner[:1]}
    return Mesh(pts, m.cells, "hexahedron", {"tip": tip, "hub": m.boundaries["xmin"]}, sets)


def build():
    mesh = sector_mesh()
    x = mesh.points[mesh.node_sets["load"][0]]
    e_r = np.array([x[0], x[1], 0.0]) / np.hypot(x[0], x[1])
    e_t = np.array([-e_r[1], e_r[0], 0.0])
    loads = [NodalForce("load", tuple(2e4 * e_r), "constant", name="press"),
             NodalForce("load", tuple(3e4 * e_t + 1e4 * np.array([0, 0, 1.0])), "cos",
                        name="engine order")]
    model = from_mesh(mesh, Material(2e11, 0.3, 7800.0), supports=[("hub", "all")],
                      loads=loads, contact=ContactSpec("tip", mu=0.3, name="casing"),
                      name="coarse 3D sector")
    return cyclic_sector(model, N, "left", "right", axis=(0.0, 0.0, 1.0)), model


def timed(fn):
    c0, w0 = time.process_time(), time.perf_counter()
    out = fn()
    return out, time.process_time() - c0, time.perf_counter() - w0


def main():
    print("uptime before:", subprocess.run(["uptime"], capture_output=True, text=True).stdout
          .strip())
    sector, model = build()
    disk = whole_disk(sector, EO)
    nc = model.contact.n_nodes
    print(f"sector: {model.ndof} DOFs, {nc} contact nodes; disk of {N}: {disk.ndof} DOFs, "
          f"{disk.contact.n_nodes} contact nodes; EO {EO}; OPENBLAS_NUM_THREADS="
          f"{os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}")
    basis = FourierBasis((1, 2, 3), 32)
    opts = SolveOptions(tol=1e-12, max_iter=200)
    eps = 1e9
    solve_periodic(model, basis, frequency=FREQUENCIES[0], eps=eps, options=opts,
                   condenser=cyclic_condenser(sector, EO))  # compile the kernels: not timed

    def run_sector():
        cond = cyclic_condenser(sector, EO)
        return [solve_periodic(model, basis, frequency=f, eps=eps, options=opts,
                               condenser=cond) for f in FREQUENCIES]

    def run_disk():
        cond = exact_condenser(disk)
        return [solve_periodic(disk, basis, frequency=f, eps=eps, options=opts,
                               condenser=cond) for f in FREQUENCIES]

    sols, cpu_s, wall_s = timed(run_sector)
    sols_d, cpu_d, wall_d = timed(run_disk)
    diff = 0.0
    for f, s, d in zip(FREQUENCIES, sols, sols_d, strict=True):
        e = float(np.abs(s.U - d.U[:nc]).max() / np.abs(d.U[:nc]).max())
        states = np.unique(s.state).tolist()
        print(f"{f:8.0f} Hz: sector {s.success} ({s.stats.iterations} it), disk {d.success} "
              f"({d.stats.iterations} it), states {states}, max |U| "
              f"{np.abs(s.U).max():.3e} m, relative difference {e:.2e}")
        diff = max(diff, e) if s.success and d.success else float("inf")
    print(f"sector: {cpu_s:.2f} s CPU, {wall_s:.2f} s wall; disk: {cpu_d:.2f} s CPU, "
          f"{wall_d:.2f} s wall")
    print("uptime after:", subprocess.run(["uptime"], capture_output=True, text=True).stdout
          .strip())
    print(f"sector_vs_disk_speedup={cpu_d / cpu_s:.1f}")
    print(f"sector_vs_disk_diff={diff:.2e}")


if __name__ == "__main__":
    main()
