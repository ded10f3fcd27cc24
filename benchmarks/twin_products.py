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

``--before SRC`` (the ``src`` directory of another checkout) adds the compressed twin made by
that checkout's ``fretwear/hb/hmatrix.py`` (the same compression, its own product), alternated
with the others: the change of the compressed product measured in one process.

    PYTHONPATH=$PWD/src OPENBLAS_NUM_THREADS=1 python benchmarks/twin_products.py --sizes 16,24,32
"""

from __future__ import annotations

import argparse
import importlib.util
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


def _hmatrix_module(src: str):
    """The module ``fretwear/hb/hmatrix.py`` of the checkout whose sources are ``src``."""
    path = os.path.join(src, "fretwear", "hb", "hmatrix.py")
    spec = importlib.util.spec_from_file_location("hmatrix_before", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # (dataclasses look their module up)
    spec.loader.exec_module(mod)
    return mod


def _twin_before(Z, comp, tol, hm):
    """The compressed twin ``comp`` with its matrices made by the module ``hm``."""
    from fretwear.hb.modal_operator import ReducedOperator

    op = comp.op
    mats = [hm.compress(A, Z.op.coords, tol, leaf=hm.LEAF).astype(np.float32)
            for A in Z.op.mats]
    return OperatorBlocks(ReducedOperator(mats, op.coef, op.U, op.Y, op.symmetric))


def size(n: int, reps: int, before=None) -> None:
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
    old = None if before is None else _twin_before(Z, comp, tol, before)
    rng = np.random.default_rng(0)
    for label, dofs in (("all", None), ("3/4", np.sort(rng.permutation(Z.m)[: 3 * Z.m // 4]))):
        if dofs is None:
            B, Bs, Bc, Bo, tcut = Z, single, comp, old, 0.0
        else:
            B = Z.sub(dofs)
            Bs = B.single()
            Bc, tcut = _cpu(lambda B=B: B.single(tol))
            Bo = None if old is None else OperatorBlocks(old.op.sub(dofs))
        U = rng.standard_normal((B.m, B.H))
        ref = B.apply(U)
        ops = {"double": B, "single": Bs, "compressed": Bc}
        if Bo is not None:
            ops["compressed before"] = Bo
        t = {k: [] for k in ops}
        for _ in range(2):
            for k, X in ops.items():
                t[k].append(_median_time(lambda X=X, U=U: X.apply(U), reps))
        d = {k: float(np.linalg.norm(X.apply(U) - ref) / np.linalg.norm(ref))
             for k, X in ops.items() if k != "double"}
        times = ", ".join(f"{k} {1e3 * min(v):.2f} ms" for k, v in t.items())
        diffs = ", ".join(f"{k} {v:.1e}" for k, v in d.items())
        print(f"  {label} DOFs{'' if dofs is None else f' (cut {tcut:.3f} s CPU)'}: Z~ U "
              f"{times}; difference from double: {diffs}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="16,24,32")
    ap.add_argument("--reps", type=int, default=7)
    ap.add_argument("--before", default=None,
                    help="src directory of another checkout: its compressed product beside")
    a = ap.parse_args()
    before = None if a.before is None else _hmatrix_module(a.before)
    print(f"load before: {os.getloadavg()}", flush=True)
    for n in (int(s) for s in a.sizes.split(",")):
        size(n, a.reps, before)
    print(f"load after: {os.getloadavg()}", flush=True)


if __name__ == "__main__":
    main()
