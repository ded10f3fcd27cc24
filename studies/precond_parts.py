"""The preconditioner's build on the 1024-node partial-slip pad, this tree against a
reference tree, alternated in one process (issue 27, item 4;
docs/studies/large-interface-solve.md, "GMRES's own work and the preconditioner").

Runs ``studies/solve_split.py``'s solve once (this tree), keeping the inputs of the
preconditioner's first build (gains, the active blocks ``Za``, eps); then builds the
preconditioner ``ROUNDS`` times with this tree's
:class:`fretwear.hb.krylov.MeanGainPreconditioner` and the reference tree's (loaded from
``REF_SRC/fretwear/hb/krylov.py`` under another name), alternated, and checks that the
factors and their sharing are equal bit for bit. CPU seconds of the process; medians.

    PYTHONPATH=$PWD/src OPENBLAS_NUM_THREADS=1 python studies/precond_parts.py 32 REF_SRC
"""

from __future__ import annotations

import importlib.util
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

ROUNDS = 5


def reference(src: str):
    """The reference tree's fretwear.hb.krylov as a separate module."""
    spec = importlib.util.spec_from_file_location(
        "krylov_reference", os.path.join(src, "fretwear", "hb", "krylov.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def main():
    n, ref_src = sys.argv[1], sys.argv[2]
    from fretwear.hb import krylov

    ref = reference(ref_src)
    kept = {"build": None}
    init = krylov.MeanGainPreconditioner.__init__

    def spy(self, gbar, Z, eps, share=True, gosc=None, single=False):
        if kept["build"] is None:
            kept["build"] = (gbar.copy(), Z, eps, share, None if gosc is None else gosc.copy(),
                             single)
        return init(self, gbar, Z, eps, share, gosc, single)

    krylov.MeanGainPreconditioner.__init__ = spy
    sys.argv = [sys.argv[0], n]
    import solve_split

    solve_split.main()
    krylov.MeanGainPreconditioner.__init__ = init

    gbar, Z, eps, share, gosc, single = kept["build"]
    times = {"build_new": [], "build_ref": []}
    same = True
    load0 = os.getloadavg()[0]
    for _ in range(ROUNDS):
        for key, cls in (("build_new", krylov.MeanGainPreconditioner),
                         ("build_ref", ref.MeanGainPreconditioner)):
            t = time.process_time()
            pc = cls(gbar, Z, eps, share=share, gosc=gosc, single=single)
            times[key].append(time.process_time() - t)
            if key == "build_new":
                new = pc
        same &= new.shared == pc.shared and all(
            np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
            for a, b in zip(new.factors, pc.factors, strict=True))
        del new, pc
    out = {k: round(float(np.median(v)), 4) for k, v in times.items()}
    out.update(bit_equal=bool(same), load_before=load0, load_after=os.getloadavg()[0],
               rounds=ROUNDS)
    print("PARTS " + json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
