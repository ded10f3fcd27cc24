"""Powell on the partial-slip pad of benchmarks/scale_3d.py, iteration by iteration (issue 27,
item 4; docs/studies/large-interface-solve.md, "Powell near the law's kinks").

One periodic solve of ``pad(n, LOADS["slip"])`` (10 modes, H 7, 128 samples) on the operator
(Krylov) Jacobian, from the contact-closed guess times ``1 + pert``, with the condensed blocks
dense or as an operator; prints a line per Powell iteration: ``|f|``, trust radius, predicted
and actual decrease of ``|f|^2`` and their ratio, Newton step or dog-leg, GMRES iterations and
the step's linear relative residual, accepted or not, and how many contact nodes change their
regime (stick / slip / separation at some sample) between the iterate and the trial point.

    PYTHONPATH=$PWD/src OPENBLAS_NUM_THREADS=1 python studies/powell_kinks.py 24 dense 1e-15 \
        [max_iter] [monotone | memory=M]

(``monotone``: without the watchdog stretches of fretwear.hb.solvers.powell, as before them;
``memory=M``: their reference the largest ``|f|`` of the last M iterates; ``norms=first``:
the variable scales of the first Jacobian only; ``unclipped``: without the stretches after
crawling dog-leg steps, ``WATCHDOG_CLIPPED``; a sixth argument and on: ``nolocal`` without
the local phase of fretwear.hb.kinks, ``single`` / ``double`` with single- /
double-precision GMRES products (single by default), ``renew`` the variable scales renewed
at every Jacobian (``KrylovOptions(first_scales=False)``; the defaults before them: ``double
renew``),
``NAME=value`` a constant of fretwear.hb.kinks or fretwear.hb.solvers set, e.g.
``LOCAL_CLIPPED=2``;
``KINKS_ROOT=<file>`` prints the distance to a root saved before.) With
``KINKS_SAVE=<folder>`` every iterate is saved there as ``xNNN.npy`` (N the Powell
iteration), for the local methods of ``studies/kinks_local.py``.
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                "benchmarks"))


def keep_first_column_norms(solvers) -> None:
    """Powell's variable scales from each problem's first Jacobian only: ``solvers``'
    column norms replaced by those of the first Jacobian of the same problem (keyed by its
    owner and shape: the static preload's problem is another)."""
    first = {}
    norms = solvers._column_norms

    def kept(J):
        key = (id(getattr(J, "owner", None)), J.shape)
        if key not in first:
            first[key] = norms(J)
        return first[key].copy()

    solvers._column_norms = kept


def main():
    from scale_3d import LOADS, H, condenser, pad, warm_up

    from fretwear.hb import solvers
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.options import PERIODIC
    from fretwear.hb.preload import static_anchor
    from fretwear.hb.problem import DLFTProblem
    from fretwear.hb.solvers import powell

    n = int(sys.argv[1])
    rep = sys.argv[2] if len(sys.argv) > 2 else "dense"
    pert = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    max_iter = int(sys.argv[4]) if len(sys.argv) > 4 else PERIODIC.max_iter
    variant = sys.argv[5] if len(sys.argv) > 5 else ""
    if variant == "monotone":  # without the watchdog stretches
        solvers.WATCHDOG_AFTER = 10**9
    elif variant.startswith("memory="):  # the stretches' reference over more iterates
        solvers.WATCHDOG_MEMORY = int(variant.split("=")[1])
    elif variant == "norms=first":  # the variable scales of the first Jacobian only
        keep_first_column_norms(solvers)
    elif variant == "unclipped":  # without the stretches after crawling dog-leg steps
        solvers.WATCHDOG_CLIPPED = 10**9
    load = LOADS["slip"]
    warm_up(load)
    model = pad(n, load)
    basis = FourierBasis.up_to(H, 128)
    c0 = time.process_time()
    mc = condenser(model, load)
    mc.representation = rep
    red = mc.reduced(2 * np.pi * load.freq, basis.orders, frequency=load.freq)
    anchor = static_anchor(model, condenser=mc)
    print(f"n {n} x {n}, {rep}, pert {pert:g}: condensation + preload "
          f"{time.process_time() - c0:.1f} s CPU, load {os.getloadavg()[0]:.1f}", flush=True)
    from fretwear.hb.connectors import connect
    from fretwear.hb.penalty import penalty

    red = connect(red, model.contact)
    eps = penalty("auto", model=model, reduced=red, condenser=mc)
    prob = DLFTProblem(red, model.contact, basis, eps=eps, anchor=anchor, jacobian="krylov")
    law = prob.time_law
    seen = {}

    def time_law(U):
        out = law(U)
        seen["state"] = out[2].copy()
        return out

    prob.time_law = time_law
    changed = []

    def fun(x, jac=True):
        out = prob.residual(x.reshape(prob.m, prob.H), jac)
        if jac:
            seen["at_x"] = seen["state"]
        else:
            changed.append(int(np.sum(np.any(seen["state"] != seen["at_x"], axis=1))))
        return out

    x0 = prob.initial_guess().reshape(-1) * (1.0 + pert)
    trace = []
    print(" it        |f|     delta   pred/|f|^2 act/|f|^2   ratio  N  gm    lin   acc chg")

    save = os.environ.get("KINKS_SAVE")  # a folder: each iterate saved there

    def line(it, x, fn):
        t, ch = trace[-1], changed[-1]
        if save:
            np.save(os.path.join(save, f"x{t['it']:03d}.npy"), x)
        print(f"{t['it']:3d} {t['f']:10.4e} {t['delta']:9.3e} {t['pred'] / t['f'] ** 2:10.3e} "
              f"{t['actual'] / t['f'] ** 2:10.3e} {t['ratio']:7.3f} "
              f"{'N' if t['newton'] else 'd'} {t['gmres']:3d} {t['lin']:8.2e} "
              f"{'+' if t['accepted'] else '-'}{'w' if t['watchdog'] else ' '}"
              f"{'F' if t.get('forced') else ' '}{ch:4d}",
              flush=True)

    c0, w0 = time.process_time(), time.perf_counter()
    from fretwear.hb import kinks
    from fretwear.hb.kinks import local_phase

    for arg in sys.argv[6:]:  # NAME=value: a constant of fretwear.hb.kinks or of solvers
        if "=" in arg:
            name, value = arg.split("=")
            owner = kinks if hasattr(kinks, name) else solvers
            setattr(owner, name, type(getattr(owner, name))(float(value)))
            print(f"{owner.__name__}.{name} = {getattr(owner, name)}", flush=True)
    local = None if "nolocal" in sys.argv[6:] else local_phase(prob)
    from fretwear.hb.options import KrylovOptions

    prob.krylov = KrylovOptions(  # products in single precision unless "double"; the
        single_products="double" not in sys.argv[6:],  # first Jacobian's scales unless
        first_scales="renew" not in sys.argv[6:])  # "renew" (the defaults before: both)
    x, f, st = powell(fun, x0, lambda x: prob.scale(x.reshape(prob.m, prob.H)),
                      tol=PERIODIC.tol, max_iter=max_iter, trace=trace, callback=line,
                      local=local)
    if os.environ.get("KINKS_ROOT"):  # the distance to a root saved before
        root = np.load(os.environ["KINKS_ROOT"])
        print(f"|x - root| {np.linalg.norm(x - root):.3e} (|root| {np.linalg.norm(root):.3e})")
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    newton = sum(t["new_step"] for t in trace)
    gm = sum(t["gmres"] for t in trace)
    out = {"n": n, "rep": rep, "pert": pert, "watchdog_after": solvers.WATCHDOG_AFTER,
           "memory": solvers.WATCHDOG_MEMORY,
           "success": st.success, "residual": st.residual,
           "powell": st.iterations, "newton": newton, "gmres": gm, "cpu": cpu, "wall": wall,
           "message": st.message, "load": os.getloadavg()[0],
           "peak_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20}
    print("RESULT " + json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
