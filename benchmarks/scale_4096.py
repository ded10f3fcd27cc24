"""Memory and time of the modal condensation of a large interface (fretwear.hb.modal) and the
periodic solve on the pad of benchmarks/scale_3d.py (its model and loads, imported: the
partial-slip load by default, ``--load stuck`` the earlier one) at n x n
contact nodes: 64 x 64 (4096 contact nodes, 7 harmonics, 172 032 unknowns) by default.

It prints, in one process run under an address-space limit (``--limit-gib``, default 20):
the model build (not counted), the condensation (factorisation of ``K_ii``, modes,
projections block by block and the error check; then the reduced model of the frequency),
the memory of its parts (the shared ``m x m`` matrices, the low-rank factors, the kept
sparse LU), the static preload solve and the periodic solve (operator Jacobian), contact
states, CPU seconds of the process beside wall seconds, the peak resident memory, and the
load before and after (the machine is shared). The condenser is the one
:func:`~fretwear.hb.modal.modal_condenser` chooses (``--path auto``: the partial
factorisations where CHOLMOD is present), or ``--path blocked`` / ``--path dense`` the
blocked or the dense static-modes condenser, for comparison. ``--condense-only`` stops after
the condensation (``solve_4096_s=not-run``).

The last lines read ``solve_4096_s=``, ``condense_4096_s=`` (CPU seconds) and
``peak_rss_4096_gib=`` (named after 4096 whatever ``--n``; the size is printed above).

Run: ``python benchmarks/scale_4096.py [--n 64] [--path auto|blocked|dense] [--condense-only]
[--compressed-twin DOFS] [--limit-gib 20]`` (``--compressed-twin``: GMRES's products through
the compressed twin from that many contact DOFs, which is off by default).
"""

from __future__ import annotations

import argparse
import os
import resource
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from scale_3d import LOADS, Clock, H, pad, peak_gib  # noqa: E402


def solve_options(twin: int | None):
    """The periodic solve's options: the defaults, with GMRES's compressed twin from ``twin``
    contact DOFs where given."""
    import dataclasses

    from fretwear.hb.options import PERIODIC

    if twin is None:
        return PERIODIC
    return PERIODIC.replace(krylov=dataclasses.replace(PERIODIC.krylov,
                                                       compressed_products_min_dofs=twin))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=64, help="contact nodes per side")
    ap.add_argument("--path", choices=("auto", "blocked", "dense"), default="auto",
                    help="the condenser: modal_condenser's choice, or the blocked or dense "
                         "static modes")
    ap.add_argument("--condense-only", action="store_true", help="no periodic solve")
    ap.add_argument("--compressed-twin", type=int, default=None, metavar="DOFS",
                    help="GMRES's products through the compressed twin from this many contact "
                         "DOFs (KrylovOptions.compressed_products_min_dofs; default: the "
                         "option's own default)")
    ap.add_argument("--limit-gib", type=float, default=20.0, help="address-space limit")
    ap.add_argument("--load", choices=sorted(LOADS), default="slip",
                    help="the load case of scale_3d.py (default: partial slip)")
    args = ap.parse_args()
    cap = int(args.limit_gib * 2**30)
    hard = resource.getrlimit(resource.RLIMIT_AS)[1]
    if hard != resource.RLIM_INFINITY:  # only lowered (e.g. under ulimit -v)
        cap = min(cap, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))

    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.modal import BlockedModalCondenser, ModalCondenser, modal_condenser
    from fretwear.hb.periodic import solve_periodic
    from fretwear.hb.preload import static_anchor

    n = args.n
    load = LOADS[args.load]
    FREQ = load.freq
    print(f"load: {os.getloadavg()}; OPENBLAS_NUM_THREADS="
          f"{os.environ.get('OPENBLAS_NUM_THREADS')}", flush=True)
    with Clock() as c:
        model = pad(n, load)
    print(f"{n * n} contact nodes, {model.ndof} DOFs: model built in {c} (not counted)",
          flush=True)
    basis = FourierBasis.up_to(H, 128)
    make = {"auto": modal_condenser, "blocked": BlockedModalCondenser,
            "dense": ModalCondenser}[args.path]
    with Clock() as cc:
        mc = make(model, FREQ * 1.2, H, modes=load.modes)
        red = mc.reduced(2 * np.pi * FREQ, basis.orders, frequency=FREQ)
    m = mc.m
    print(f"condensation ({type(mc).__name__}: {mc.path}; {mc.n_modes} modes, q = {mc.q}, "
          f"checked error {mc.error:.2g}): {cc}; peak {peak_gib():.2f} GiB", flush=True)
    lu = mc._lus.get(("static",))
    lu_gib = getattr(lu, "nbytes", float("nan") * 2**30) / 2**30
    if args.path == "dense":
        parts = {"Z_r blocks": red.Z.nbytes, "Psi": mc.Psi.nbytes,
                 "proj (local frames)": sum(x.nbytes for p in (mc.proj_local,)
                                           for v in p.values() for x in v)}
    else:
        Z = red.Z
        parts = {"shared X^cc": sum(a.nbytes for a in Z.mats),
                 "low-rank U_n, Y_n": Z.nbytes - sum(a.nbytes for a in Z.mats)}
    parts = {k: v / 2**30 for k, v in parts.items()}
    parts["sparse LU of K_ii"] = lu_gib
    print(f"  m = {m}: one m x m real {8 * m * m / 2**30:.2f} GiB; parts [GiB]: "
          + ", ".join(f"{k} {v:.2f}" for k, v in parts.items()), flush=True)
    if args.condense_only:
        print(f"load: {os.getloadavg()}")
        print(f"contact_nodes={n * n}")
        print("solve_4096_s=not-run")
        print(f"condense_4096_s={cc.cpu:.1f}")
        print(f"peak_rss_4096_gib={peak_gib():.2f}")
        return
    with Clock() as cs:
        anchor = static_anchor(model, condenser=mc)
        sol = solve_periodic(model, basis, frequency=FREQ, reduced=red, anchor=anchor,
                             condenser=mc, options=solve_options(args.compressed_twin))
    st = sol.stats
    frac = sol.state_fractions().mean(axis=0)
    active = int(np.sum(np.any(sol.state != 1, axis=1)))
    print(f"periodic solve: {cs}; success {sol.success}, {st.iterations} iterations, residual "
          f"{st.residual:.2g}, eps {sol.eps:.3g} N/m; states sep/stick/slip "
          f"{frac[0]:.3f}/{frac[1]:.3f}/{frac[2]:.3f}, {active} nodes slip or separate",
          flush=True)
    print(f"load: {os.getloadavg()}")
    print(f"contact_nodes={n * n}")
    print(f"solve_4096_s={cs.cpu:.1f}")
    print(f"condense_4096_s={cc.cpu:.1f}")
    print(f"peak_rss_4096_gib={peak_gib():.2f}")


if __name__ == "__main__":
    main()
