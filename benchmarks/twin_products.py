"""GMRES's twin of the condensed operator (KrylovOptions.single_products): the dense
single-precision copy against the compressed one (``single(compress)``: the stored matrices
compressed hierarchically and held in float32, fretwear.hb.hmatrix), on the partial-slip pad
of benchmarks/scale_3d.py (10 modes, ``representation="operator"``).

Per size (``--sizes``, nodes a side): the compression's CPU (made once per condensation),
bytes held, the stated error of each compressed matrix (compression and float32 rounding),
then the time of the solver's product ``Z~ U`` (``OperatorBlocks.apply``, 15 columns as the
GMRES matvec) with the double operator, the dense single twin and the compressed twin,
alternated in one process (``--reps`` rounds, the median of each), their relative
differences from the double product, and the same on an active sub-operator (three quarters
of the nodes, ``sub``: the cut's CPU). CPU seconds of the process; the load before and after.

    PYTHONPATH=$PWD/src OPENBLAS_NUM_THREADS=1 python benchmarks/twin_products.py --sizes 16,24,32
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from hmatrix import _median_time  # noqa: E402
from scale_3d import LOADS, H, pad  # noqa: E402

from fretwear.hb.krylov import twin_tolerance  # noqa: E402
from fretwear.hb.operator_blocks import OperatorBlocks  # noqa: E402
from fretwear.hb.solvers import KRYLOV  # noqa: E402


def _cpu(f):
    t = time.process_time()
    out = f()
    return out, time.process_time() - t


def size(n: int, reps: int) -> None:
    from fretwear.hb.modal import ModalCondenser

    load = LOADS["slip"]
    model = pad(n, load)
    mc = ModalCondenser(model, load.freq * 1.2, H, modes=load.modes, representation="operator")
    Z = OperatorBlocks(mc.reduced(2 * np.pi * load.freq, np.arange(H + 1)).Z)
    tol = twin_tolerance(KRYLOV.single_products_rtol)
    single = Z.single()
    comp, tc = _cpu(lambda: Z.single(tol))
    errs = ", ".join(f"{A.error:.2e}" for A in comp.op.mats)
    held = sum(A.nbytes for A in comp.op.mats) / sum(A.nbytes for A in Z.op.mats)
    print(f"n = {n} ({n * n} nodes, m = {Z.m}): compression to {tol:g} {tc:.2f} s CPU, "
          f"held {held:.3f} of the double matrices, stated errors (K, M) {errs}", flush=True)
    rng = np.random.default_rng(0)
    for label, dofs in (("all", None), ("3/4", np.sort(rng.permutation(Z.m)[: 3 * Z.m // 4]))):
        if dofs is None:
            B, Bs, Bc, tcut = Z, single, comp, 0.0
        else:
            B = Z.sub(dofs)
            Bs = B.single()
            Bc, tcut = _cpu(lambda B=B: B.single(tol))
        U = rng.standard_normal((B.m, B.H))
        ref = B.apply(U)
        t = {k: [] for k in ("double", "single", "compressed")}
        for _ in range(2):
            for k, X in (("double", B), ("single", Bs), ("compressed", Bc)):
                t[k].append(_median_time(lambda X=X, U=U: X.apply(U), reps))
        d = {k: float(np.linalg.norm(X.apply(U) - ref) / np.linalg.norm(ref))
             for k, X in (("single", Bs), ("compressed", Bc))}
        print(f"  {label} DOFs{'' if dofs is None else f' (cut {tcut:.3f} s CPU)'}: Z~ U "
              f"double {1e3 * min(t['double']):.2f} ms, single {1e3 * min(t['single']):.2f} "
              f"ms, compressed {1e3 * min(t['compressed']):.2f} ms; difference from double: "
              f"single {d['single']:.1e}, compressed {d['compressed']:.1e}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="16,24,32")
    ap.add_argument("--reps", type=int, default=7)
    a = ap.parse_args()
    print(f"load before: {os.getloadavg()}", flush=True)
    for n in (int(s) for s in a.sizes.split(",")):
        size(n, a.reps)
    print(f"load after: {os.getloadavg()}", flush=True)


if __name__ == "__main__":
    main()
