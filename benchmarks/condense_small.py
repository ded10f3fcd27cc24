"""Per-frequency cost of the condensation of small and medium models: the dense (LAPACK) path
against the sparse (SuperLU) path, both timed in this run.

Models: issue 19's 3-DOF chain (masses 1, 1, springs 1, 1, the second mass on a rigid flat
through a stiff normal DOF), and plane-strain blocks of increasing size (a 10 x 4 mm steel
block on a rigid flat, nx x ny quadrilaterals). For each, the time of one condensation at 8
harmonic orders ``[0..7]`` (CPU time of the process) averaged over a sweep of 50 frequencies
(the Condenser reused, as a sweep does), on each path; the crossover justifies
``fretwear.hb.reduce.DENSE_MAX``.
The last line reads ``small_condense_ms=<ms per frequency of the 3-DOF chain, default path>``.

Run: ``python benchmarks/condense_small.py``.
"""

from __future__ import annotations

import os
import time

import numpy as np
import scipy.sparse as sp

from fretwear.hb import reduce
from fretwear.model import (
    ContactSpec,
    Damping,
    Material,
    Spring,
    Traction,
    from_mesh,
    rectangle,
)
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

ORDERS = np.arange(8)


def chain():
    """Issue 19 (b): masses 1, 1, springs 1, 1, damping 0.02; mass 2 pressed (N = 1) on the
    flat through a massless normal DOF of stiffness 1e3; force on mass 1."""
    K = sp.csr_matrix(np.array([[2.0, -1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 1e3]]))
    M = sp.csr_matrix(np.diag([1.0, 1.0, 0.0]))
    C = sp.csr_matrix(np.array([[0.04, -0.02, 0.0], [-0.02, 0.02, 0.0], [0.0, 0.0, 0.0]]))
    return from_matrices(K, M, contact=ContactDofs(normal_dofs=[2], tangential_dofs=[1], mu=0.5),
                         damping=Damping(C=C), loads=[Load(np.array([0.0, 0.0, 1.0]), "constant"),
                                                      Load(np.array([0.2, 0.0, 0.0]), "cos")])


def block(nx, ny):
    return from_mesh(rectangle(0.01, 0.004, nx, ny), Material(210e9, 0.3, 7800.0),
                     supports=[Spring("top", "x", 1e7)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("top", traction=(3e5, 0.0), waveform="cos")],
                     contact=ContactSpec("bottom", mu=0.5))


def per_frequency(model, dense, freqs):
    cond = reduce.Condenser(reduce._structure(model), dense=dense)
    cond.reduced(2 * np.pi * freqs[0], ORDERS)  # the static LU, first factorisations
    t0 = time.process_time()  # CPU time: the machine may be shared
    for f in freqs:
        cond.reduced(2 * np.pi * f, ORDERS)
    return (time.process_time() - t0) / len(freqs) * 1e3


def main():
    print(f"load: {os.getloadavg()}")
    freqs = np.linspace(0.1, 0.3, 50)
    m = chain()
    small = {d: per_frequency(m, d, freqs) for d in (True, False)}
    print(f"3-DOF chain: dense {small[True]:.2f} ms, sparse {small[False]:.2f} ms a frequency")
    freqs = np.linspace(1000.0, 5000.0, 10)
    for nx, ny in ((4, 2), (10, 4), (14, 6), (20, 8), (30, 12)):
        m = block(nx, ny)
        ni = reduce.Condenser(reduce._structure(m)).ni
        t = {d: per_frequency(m, d, freqs) for d in (True, False)}
        print(f"block {nx} x {ny} ({m.ndof} DOFs, {ni} interior): dense {t[True]:.1f} ms, "
              f"sparse {t[False]:.1f} ms a frequency")
    print(f"load: {os.getloadavg()}")
    default = reduce.Condenser(reduce._structure(chain())).dense
    print(f"small_condense_ms={small[default]:.3f}")


if __name__ == "__main__":
    main()
