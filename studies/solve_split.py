"""Where the periodic solve of benchmarks/scale_3d.py's partial-slip pad spends its CPU
(issue 27, item 4; docs/studies/large-interface-solve.md, "The growth's terms, measured").

One size in one process, as ``scale_3d.py`` runs it (warm-up, condensation, static preload,
``solve_periodic`` with the benchmark's options), with CPU timers around the solve's parts:
the products with the condensed operator (``Z~ U``, ``Z~^T U``, the stuck part's
``apply_sub``), the preconditioner's builds and applies, the contact law's evaluations
(time samples and their Jacobian blocks), the FFTs, the column norms, the active blocks'
copies, the penalty estimate (its power iterations apart: ``penalty_power``) and the static
preload; GMRES's own work split into the node-local correction's inverses
(``node_inverse``), the single-precision twin's making (``single_twin``), SciPy's GMRES
with what its operators do beside the timed products and applies (``gmres_arnoldi``: the
Arnoldi process and the node-block products with ``G``) and the rest (``gmres_other``: the
reduction to the active nodes); what is left of the solve is Powell's bookkeeping. A timer
inside another pauses it (the parts add up to the solve). Prints one JSON line.

    PYTHONPATH=$PWD/src OPENBLAS_NUM_THREADS=1 python studies/solve_split.py 32 [VARIANT ...]

Variants (for the measurements of docs/studies/large-interface-solve.md, "Iteration counts
and per-call terms"): ``solver=newton`` (the line-search Newton instead of Powell),
``norms=first`` (Powell's variable scales from the first Jacobian's column norms only, not
renewed at every Jacobian), ``single=0|1`` (the preconditioner's factors in double or single),
``sprod=0|1`` (GMRES's products in double or single, KrylovOptions.single_products),
``nodecorr=0|1`` (the node-local correction of the preconditioner,
KrylovOptions.node_correction), ``ctwin=N`` (GMRES's single products through the compressed
twin from N contact DOFs, KrylovOptions.compressed_products_min_dofs; 0: never). The
compressed twin's compression and cuts are the part ``twin``. ``pert=E``: the contact-closed
start (``DLFTProblem.initial_guess``) times ``1 + E`` (e.g. 1e-15: another rounding of the
same input, for Powell's spread of paths, "Powell near the law's kinks").
The solution is saved to ``/tmp/solve_split_<n><SPLIT_TAG>_U.npy`` for comparisons.
"""

from __future__ import annotations

import dataclasses
import json
import os
import resource
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                "benchmarks"))


class Split:
    """Exclusive CPU seconds and calls per part (a part inside another pauses it)."""

    def __init__(self):
        self.cpu, self.calls, self.stack = {}, {}, []

    def wrap(self, owner, name, part):
        f = getattr(owner, name)

        def timed(*a, **k):
            now = time.process_time()
            if self.stack:
                top = self.stack[-1]
                self.cpu[top[0]] = self.cpu.get(top[0], 0.0) + now - top[1]
            self.stack.append([part, now])
            try:
                return f(*a, **k)
            finally:
                end = time.process_time()
                p, t0 = self.stack.pop()
                self.cpu[p] = self.cpu.get(p, 0.0) + end - t0
                self.calls[p] = self.calls.get(p, 0) + 1
                if self.stack:
                    self.stack[-1][1] = end

        setattr(owner, name, timed)


def main():
    from scale_3d import LOADS, Counts, H, condenser, options, pad, warm_up

    from fretwear.hb import (
        contact,
        fourier,
        krylov,
        nearfield_preconditioner,
        operator_blocks,
        penalty,
        periodic,
        preload,
        solvers,
    )
    from fretwear.hb.fourier import FourierBasis

    n = int(sys.argv[1])
    variants = dict(a.split("=", 1) for a in sys.argv[2:])
    opts = options(LOADS["slip"])
    if "solver" in variants:
        opts = opts.replace(solver=variants["solver"])
    kry = {"single": "single_factors", "sprod": "single_products",
           "nodecorr": "node_correction"}
    for key, field in kry.items():
        if key in variants:
            opts = opts.replace(krylov=dataclasses.replace(opts.krylov,
                                                           **{field: variants[key] == "1"}))
    if "ctwin" in variants:
        least = int(variants["ctwin"]) or None
        opts = opts.replace(krylov=dataclasses.replace(
            opts.krylov, compressed_products_min_dofs=least))
    if "pert" in variants:
        from fretwear.hb.problem import DLFTProblem

        guess, scale = DLFTProblem.initial_guess, 1.0 + float(variants["pert"])
        DLFTProblem.initial_guess = lambda self: guess(self) * scale
    if variants.get("norms") == "first":  # the first Jacobian's column norms kept
        from powell_kinks import keep_first_column_norms

        keep_first_column_norms(solvers)
    load = LOADS["slip"]
    warm_up(load)
    model = pad(n, load)
    basis = FourierBasis.up_to(H, 128)
    c0 = time.process_time()
    mc = condenser(model, load)
    red = mc.reduced(2 * np.pi * load.freq, basis.orders, frequency=load.freq)
    cond = time.process_time() - c0
    sp = Split()
    for cls in (krylov.HarmonicBlocks, operator_blocks.OperatorBlocks):
        for name in ("apply", "apply_T", "apply_sub"):
            sp.wrap(cls, name, "products")
    sp.wrap(krylov.MeanGainPreconditioner, "__init__", "precond_build")
    sp.wrap(krylov.MeanGainPreconditioner, "apply", "precond_apply")
    sp.wrap(nearfield_preconditioner.NearFieldPreconditioner, "__init__", "precond_build")
    sp.wrap(nearfield_preconditioner.NearFieldPreconditioner, "apply", "precond_apply")
    sp.wrap(contact, "dlft_time", "law")
    sp.wrap(contact, "dlft_jacobian", "law_jacobian")
    sp.wrap(FourierBasis, "to_time", "fft")
    sp.wrap(FourierBasis, "to_freq", "fft")
    sp.wrap(krylov.KrylovJacobian, "column_norms", "column_norms")
    sp.wrap(krylov.KrylovJacobian, "_active_blocks", "active_blocks")
    sp.wrap(krylov.KrylovJacobian, "solve", "gmres_other")
    # GMRES's own work, finer: the node-local correction's inverses, the single twin's
    # making, SciPy's GMRES (its Arnoldi process and what GMRES's operators do beside the
    # timed products and applies: the node-block products with G); the penalty's power
    # iterations
    sp.wrap(krylov, "node_local_inverse", "node_inverse")
    sp.wrap(krylov.KrylovJacobian, "_single_blocks", "single_twin")
    sp.wrap(krylov.spla, "gmres", "gmres_arnoldi")
    sp.wrap(penalty, "_radius", "penalty_power")
    for mod in (penalty, periodic):
        sp.wrap(mod, "penalty", "penalty")
    sp.wrap(preload, "static_anchor", "static_preload")
    from fretwear.hb.modal_operator import ReducedOperator

    sp.wrap(ReducedOperator, "_compressed_twin", "twin")
    del fourier
    load0 = os.getloadavg()[0]
    with Counts() as counts:
        c0, w0 = time.process_time(), time.perf_counter()
        anchor = preload.static_anchor(model, condenser=mc)
        sol = periodic.solve_periodic(model, basis, frequency=load.freq,
                                      options=opts, reduced=red, anchor=anchor,
                                      condenser=mc)
        cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    parts = {k: round(v, 3) for k, v in sorted(sp.cpu.items())}
    parts["powell_and_rest"] = round(cpu - sum(sp.cpu.values()), 3)
    out = {"n": n, "variants": variants, "nodes": n * n, "unknowns": 3 * n * n * basis.size,
           "condense_cpu": cond,
           "solve_cpu": cpu, "solve_wall": wall, "success": sol.success,
           "residual": sol.stats.residual,
           "attempts": [f"{a.method} ({a.iterations})" for a in sol.attempts],
           "powell": sol.stats.iterations, "newton": counts.steps + len(counts.gmres),
           "gmres": int(sum(counts.gmres)), "gmres_per_step": counts.gmres,
           "parts": parts, "calls": sp.calls, "load_before": load0,
           "load_after": os.getloadavg()[0],
           "peak_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20}
    np.save(f"/tmp/solve_split_{n}{os.environ.get('SPLIT_TAG', '')}_U.npy", sol.U)
    print("RESULT " + json.dumps(out, default=float), flush=True)


if __name__ == "__main__":
    main()
