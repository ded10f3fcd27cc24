"""The hierarchical low-rank compression (fretwear.hb.hmatrix) of the condensed contact
stiffness and mass of the pad of benchmarks/scale_3d.py (partial-slip load, 10 modes, the
modal condensation with ``representation="operator"``), against the dense matrices.

``--sizes`` (default 16,24,32 nodes a side: 256, 576, 1024 contact nodes) prints per size
and matrix (``K^cc``, ``M^cc``, contact-local frames) and per tolerance (``--tols``): the
time of the compression, the bytes held against the dense matrix, the ranks, the error
``||A - A_H||_F / ||A||_F`` stated by the compression and measured against the formed
``A_H`` (where it fits: m <= 4000), and the time of one product with ``2 H + 1 = 15``
columns (as the solver's ``Z~ U``: every harmonic's columns at once), compressed and dense
alternately (``--reps`` rounds; the median of each), then the solver's whole product
``Z~ U`` (``OperatorBlocks.apply``) with and without the compressed forms. The growth of
the product time with the unknowns (exponent between the first and the last size) closes
the table.

``--solve N`` instead runs the periodic solve at N x N contact nodes (scale_3d's
``solve_periodic`` call, the static preload first) with the operator representation, dense
products (``--reference``: the operator's or the dense blocks'), then compressed at each
tolerance of ``--tols``, then (up to 256 nodes) dense again, in one process, and prints
CPU and wall seconds, iteration counts and the relative difference of each converged
solution ``U~`` from the dense one.

CPU seconds of the process beside wall seconds and the load before and after: the machine
is shared. Run: ``python benchmarks/hmatrix.py [--sizes 16,24,32] [--tols 1e-4,1e-6,1e-8]``
or ``python benchmarks/hmatrix.py --solve 16 [--no-dense]``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from scale_3d import LOADS, Clock, Counts, H, options, pad, peak_gib, warm_up  # noqa: E402


def _condenser(model, load, compress=None, representation="operator"):
    from fretwear.hb.modal import ModalCondenser, Representation

    return ModalCondenser(model, load.freq * 1.2, H, modes=load.modes,
                          representation=(representation if compress is None
                                          else Representation("compressed", compress)))


def _median_time(f, reps: int) -> float:
    out = []
    for _ in range(reps):
        t = time.process_time()
        f()
        out.append(time.process_time() - t)
    return float(np.median(out))


def compression(n: int, tols, reps: int) -> list[dict]:
    """The table's rows of one size."""
    from fretwear.hb.hmatrix import compress
    from fretwear.hb.operator_blocks import OperatorBlocks

    load = LOADS["slip"]
    model = pad(n, load)
    with Clock() as c:
        mc = _condenser(model, load)
    print(f"n = {n} ({n * n} contact nodes): condensation {c}", flush=True)
    coords = np.asarray(model.contact.coords, dtype=float)
    red = mc.reduced(2 * np.pi * load.freq, np.arange(H + 1))
    rows = []
    rng = np.random.default_rng(0)
    for tol in tols:
        prods = []
        for name in mc.proj_local:
            A = mc.proj_local[name][0]
            m = A.shape[0]
            with Clock() as c:
                Hm = compress(A, coords, tol)
            prods.append(Hm)
            X = rng.standard_normal((m, 2 * H + 1))
            th = _median_time(lambda Hm=Hm, X=X: Hm @ X, reps)
            td = _median_time(lambda A=A, X=X: A @ X, reps)
            th = min(th, _median_time(lambda Hm=Hm, X=X: Hm @ X, reps))
            measured = (float(np.linalg.norm(A - Hm.toarray()) / np.linalg.norm(A))
                        if m <= 4000 else float("nan"))
            r = Hm.ranks()
            row = {"n": n, "m": m, "matrix": name, "tol": tol, "compress_cpu": c.cpu,
                   "bytes_ratio": Hm.nbytes / A.nbytes, "blocks": len(Hm.blocks),
                   "rank_max": int(r.max(initial=0)), "rank_mean": float(r.mean()) if r.size
                   else 0.0, "error": Hm.error, "error_measured": measured,
                   "product_ms": 1e3 * th, "dense_ms": 1e3 * td}
            rows.append(row)
            print(f"  {name}^cc m={m} tol={tol:g}: compress {c.cpu:.2f} s CPU, "
                  f"{Hm.nbytes / 2**20:.1f} MiB = {row['bytes_ratio']:.3f} of dense, "
                  f"{len(Hm.blocks)} blocks, rank max {row['rank_max']} mean "
                  f"{row['rank_mean']:.1f}, error {Hm.error:.2e} (formed: {measured:.2e}), "
                  f"product {row['product_ms']:.2f} ms vs dense {row['dense_ms']:.2f} ms",
                  flush=True)
        op = red.Z
        dense = OperatorBlocks(op)
        op_c = type(op)(op.mats, op.coef, op.U, op.Y, op.symmetric, prods)
        comp = OperatorBlocks(op_c)
        U = rng.standard_normal((op.m, 2 * H + 1))
        td = _median_time(lambda U=U, B=dense: B.apply(U), reps)
        tc = _median_time(lambda U=U, B=comp: B.apply(U), reps)
        diff = float(np.linalg.norm(comp.apply(U) - dense.apply(U))
                     / np.linalg.norm(dense.apply(U)))
        rows.append({"n": n, "m": op.m, "matrix": "Z~U", "tol": tol, "product_ms": 1e3 * tc,
                     "dense_ms": 1e3 * td, "error": diff})
        print(f"  Z~ U (OperatorBlocks.apply, tol={tol:g}): {1e3 * tc:.2f} ms vs dense "
              f"{1e3 * td:.2f} ms, relative difference {diff:.2e}", flush=True)
    return rows


def growth(rows: list[dict]) -> None:
    """Exponent of the product time against the unknowns between the first and last size."""
    sizes = sorted({r["n"] for r in rows})
    if len(sizes) < 2:
        return
    a, b = sizes[0], sizes[-1]
    for key in sorted({(r["matrix"], r["tol"]) for r in rows}):
        ra = next(r for r in rows if (r["matrix"], r["tol"]) == key and r["n"] == a)
        rb = next(r for r in rows if (r["matrix"], r["tol"]) == key and r["n"] == b)
        x = np.log(rb["m"] / ra["m"])
        print(f"growth {key[0]} tol={key[1]:g} from {a * a} to {b * b} nodes: compressed "
              f"unknowns^{np.log(rb['product_ms'] / ra['product_ms']) / x:.2f}, dense "
              f"unknowns^{np.log(rb['dense_ms'] / ra['dense_ms']) / x:.2f}"
              + (f", memory ratio {ra['bytes_ratio']:.3f} -> {rb['bytes_ratio']:.3f}"
                 if "bytes_ratio" in ra else ""))


class PrecondClock:
    """CPU seconds and counts of the preconditioners' builds and applies inside a ``with``
    block (benchmark only: wraps both classes' ``__init__`` and ``apply``)."""

    def __enter__(self):
        from fretwear.hb import krylov, nearfield_preconditioner

        self.classes = (krylov.MeanGainPreconditioner,
                        nearfield_preconditioner.NearFieldPreconditioner)
        self.saved = [(c, c.__init__, c.apply) for c in self.classes]
        self.build = self.apply = 0.0
        self.builds = self.applies = 0
        self.nnz = []
        clock = self

        for cls, init, apply in self.saved:
            def new_init(pc, *a, _init=init, **k):
                t = time.process_time()
                _init(pc, *a, **k)
                clock.build += time.process_time() - t
                clock.builds += 1
                if hasattr(pc, "factor_nnz"):
                    clock.nnz.append((pc.m, pc.nnz, pc.factor_nnz))

            def new_apply(pc, r, _apply=apply):
                t = time.process_time()
                out = _apply(pc, r)
                clock.apply += time.process_time() - t
                clock.applies += 1
                return out

            cls.__init__, cls.apply = new_init, new_apply
        return self

    def __exit__(self, *exc):
        for cls, init, apply in self.saved:
            cls.__init__, cls.apply = init, apply

    def __str__(self):
        out = (f"preconditioner: {self.builds} builds {self.build:.2f} s CPU, "
               f"{self.applies} applies {self.apply:.2f} s CPU"
               f" ({1e3 * self.apply / max(self.applies, 1):.1f} ms each)")
        if self.nnz:
            m, nnz, fnnz = max(self.nnz)
            out += (f"; largest near field m_a={m}: {nnz} entries ({nnz / m**2 / 8:.3f} of "
                    f"8 dense blocks), LU factors {fnnz}")
        return out


def solves(n: int, tols, dense: bool = True, reference: str = "operator",
           preconds=("nearfield",)) -> None:
    """The periodic solve with dense and compressed products (module docstring); the
    compressed ones with each preconditioner of ``preconds`` ("nearfield": from the
    compressed forms, hb/nearfield_preconditioner.py; "mean-gain": the dense LU)."""
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.options import KrylovOptions
    from fretwear.hb.periodic import solve_periodic
    from fretwear.hb.preload import static_anchor

    load = LOADS["slip"]
    model = pad(n, load)
    basis = FourierBasis.up_to(H, 128)
    warm_up(load)  # the compiled kernels loaded, untimed
    ref = None
    runs = ([None, *tols, None] if dense and n * n <= 256 else
            [None, *tols] if dense else list(tols))
    runs = [(t, p) for t in runs for p in ((None,) if t is None else preconds)]
    for tol, pname in runs:
        opts = options(load).replace(krylov=KrylovOptions(preconditioner=pname or "nearfield"))
        before = os.getloadavg()[0]
        with Clock() as cc:
            mc = _condenser(model, load, tol, reference)
            red = mc.reduced(2 * np.pi * load.freq, basis.orders, frequency=load.freq)
        with Counts() as counts, Clock() as c, PrecondClock() as pcc:
            anchor = static_anchor(model, condenser=mc)
            sol = solve_periodic(model, basis, frequency=load.freq, options=opts,
                                 reduced=red, anchor=anchor, condenser=mc)
        U = np.asarray(sol.U)
        if ref is None and tol is None:
            ref = U
        diff = (float("nan") if ref is None
                else float(np.linalg.norm(U - ref) / np.linalg.norm(ref)))
        err = ("" if tol is None else
               "compression errors " + ", ".join(f"{p.error:.1e}" for p in red.Z.products))
        name = f"dense ({reference})" if tol is None else f"compress={tol:g} {pname}"
        print(f"{n * n} nodes, {name}: attempts "
              + "; ".join(f"{a.method} ({a.iterations})" for a in sol.attempts) + ": "
              f"condensation{'+compression' if tol else ''} {cc}, solve {c}, success "
              f"{sol.success}, Powell {sol.stats.iterations}, Newton {counts.steps}, GMRES "
              f"{sum(counts.gmres)}, eps {sol.eps:.4g}, |U - U_dense| / |U_dense| = "
              f"{diff:.2e}; {err}; load {before:.1f}-{os.getloadavg()[0]:.1f}, peak "
              f"{peak_gib():.2f} GiB; {pcc}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="16,24,32")
    ap.add_argument("--tols", default="1e-4,1e-6,1e-8")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--solve", type=int, default=0)
    ap.add_argument("--reference", choices=("operator", "dense"), default="operator",
                    help="--solve: the uncompressed run's representation")
    ap.add_argument("--no-dense", action="store_true",
                    help="--solve: the compressed solves only (no difference printed)")
    ap.add_argument("--precond", default="nearfield,mean-gain",
                    help="--solve: the compressed solves' preconditioners, in turn")
    args = ap.parse_args()
    tols = [float(t) for t in args.tols.split(",")]
    print(f"load {os.getloadavg()[0]:.1f}", flush=True)
    if args.solve:
        solves(args.solve, tols, not args.no_dense, args.reference,
               args.precond.split(","))
        return
    rows = []
    for n in (int(s) for s in args.sizes.split(",")):
        rows += compression(n, tols, args.reps)
    growth(rows)
    print(f"load {os.getloadavg()[0]:.1f}, peak {peak_gib():.2f} GiB")


if __name__ == "__main__":
    main()
