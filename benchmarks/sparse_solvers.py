"""Sparse direct solvers on fretwear's interior matrices: factorisation and blocked solves.

The matrices are those of the exact and modal condensations (fretwear.hb.reduce,
fretwear.hb.modal): the real symmetric positive definite interior stiffness ``K_ii`` and the
complex symmetric ``Z_ii = K_ii - (n w)^2 M_ii`` at the highest harmonic, of the pad of
benchmarks/scale_3d.py (``--nodes 256,1024``: n x n contact nodes) or of the shipped dovetail
(``--dovetail``). For each backend of fretwear.hb.sparse_lu that is importable here (and
SciPy's SuperLU with each column ordering), it prints the factorisation time, the blocked
solve of ``m`` right-hand sides (``K_ii^-1 K_ic``: the static constraint modes Psi) and
the time of 200 single-vector solves (what a shift-invert Lanczos pays per iteration), in
CPU seconds of the process beside wall seconds, and the relative residual of the solve.

``--save DIR`` writes the matrices (npz) and ``--load DIR`` reads them back, so that the
backends can be timed in other environments (a virtual environment with one backend
installed) on the same matrices without fretwear.

Run: ``python benchmarks/sparse_solvers.py [--nodes 256,1024] [--dovetail]``.
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from scale_3d import Clock  # noqa: E402

FREQ, H = 6000.0, 7  # the highest harmonic of scale_3d.py's modal condenser (1.2 x 5 kHz)


def pad_matrices(n: int) -> dict:
    """``K_ii, M_ii, K_ic`` of the scale_3d pad with n x n contact nodes."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from scale_3d import pad

    from fretwear.hb.reduce import _partition, _structure

    s = _structure(pad(n))
    c, i = _partition(s)
    return _blocks(s.K.tocsr(), s.M.tocsr(), c, i)


def dovetail_matrices() -> dict:
    """``K_ii, M_ii, K_ic`` of the shipped dovetail example."""
    from fretwear.api import load_case
    from fretwear.hb.reduce import _partition, _structure

    case = load_case("dovetail")
    s = _structure(case.model)
    c, i = _partition(s)
    return _blocks(s.K.tocsr(), s.M.tocsr(), c, i)


def _blocks(K, M, c, i) -> dict:
    Ki = K[i]
    return {"Kii": Ki[:, i].tocsc(), "Mii": M[i][:, i].tocsc(), "Kic": Ki[:, c].tocsc()}


def backends() -> list:
    """``(label, factor)`` of every backend importable here: fretwear's (when fretwear is
    importable) and SciPy's SuperLU with each column ordering."""
    import scipy.sparse.linalg as spla

    out = []
    for perm in ("COLAMD", "MMD_AT_PLUS_A"):
        out.append((f"superlu-{perm}",
                    lambda A, kind, perm=perm: _SuperLU(spla.splu(A, permc_spec=perm))))
    out += _kvxopt()
    try:
        from fretwear.hb import sparse_lu
    except ImportError:
        return out
    for name in sparse_lu.available():
        out.append((f"fretwear:{name}",
                    lambda A, kind, name=name: sparse_lu.factor(A, kind, backend=name)))
    return out


def _kvxopt() -> list:
    """CHOLMOD (real SPD) and UMFPACK (any) of kvxopt, when installed: candidates measured
    beside fretwear's backends (not used by fretwear)."""
    try:
        import kvxopt
        from kvxopt import cholmod, umfpack
    except ImportError:
        return []

    def spm(A):
        C = A.tocoo()
        return kvxopt.spmatrix(kvxopt.matrix(C.data), kvxopt.matrix(C.row.astype(np.int64)),
                               kvxopt.matrix(C.col.astype(np.int64)), A.shape)

    class Chol:
        def __init__(self, A, kind):
            if kind != "spd":
                raise ValueError("CHOLMOD: Hermitian positive definite matrices only")
            self.A = spm(A)
            self.F = cholmod.symbolic(self.A)
            cholmod.numeric(self.A, self.F)

        def solve(self, B):
            X = kvxopt.matrix(np.asfortranarray(B))
            cholmod.solve(self.F, X)
            return np.array(X).reshape(B.shape)

    class Umf:
        def __init__(self, A, kind):
            self.A = spm(A)
            self.F = umfpack.numeric(self.A, umfpack.symbolic(self.A))

        def solve(self, B):
            X = kvxopt.matrix(np.asfortranarray(B))
            umfpack.solve(self.A, self.F, X)
            return np.array(X).reshape(B.shape)

    return [("kvxopt-cholmod", Chol), ("kvxopt-umfpack", Umf)]


class _SuperLU:
    def __init__(self, lu):
        self.lu = lu

    def solve(self, B):
        return self.lu.solve(B)


def time_one(label, make, A, kind, B, singles) -> dict:
    with Clock() as cf:
        f = make(A, kind)
    with Clock() as cs:
        X = f.solve(B)
    with Clock() as c1:
        for b in singles:
            f.solve(b)
    res = np.linalg.norm(A @ X - B) / np.linalg.norm(B)
    return {"backend": label, "kind": kind, "factor_cpu": cf.cpu, "factor_wall": cf.wall,
            "solve_m_cpu": cs.cpu, "solve_m_wall": cs.wall, "solve200_cpu": c1.cpu,
            "solve200_wall": c1.wall, "residual": float(res)}


def run(name: str, mats: dict, rhs: int | None = None, only=()) -> None:
    Kii, Mii, Kic = mats["Kii"], mats["Mii"], mats["Kic"]
    w = 2 * np.pi * H * FREQ
    Zii = (Kii.astype(complex) - (w * w) * Mii).tocsc()
    rng = np.random.default_rng(0)
    B = Kic.toarray()[:, :rhs]
    ni, m = B.shape
    print(f"# {name}: n_i = {ni}, nnz(K_ii) = {Kii.nnz}, m = {m}; load {os.getloadavg()}",
          flush=True)
    singles = [rng.standard_normal(ni) for _ in range(200)]
    csingles = [s + 0j for s in singles]
    for label, make in backends():
        if only and not any(o in label for o in only):
            continue
        for kind, A, rhs, sg in (("spd", Kii, B, singles),
                                 ("general", Zii, B.astype(complex), csingles)):
            try:
                r = time_one(label, make, A, kind, rhs, sg)
            except Exception as exc:  # a backend that cannot do this kind: say so, go on
                print(f"{name} {label} {kind}: failed ({type(exc).__name__}: {exc})")
                continue
            print(f"{name} {label:28s} {kind:9s} factor {r['factor_cpu']:7.2f} s CPU "
                  f"({r['factor_wall']:6.2f} wall)  solve m {r['solve_m_cpu']:7.2f} s CPU "
                  f"({r['solve_m_wall']:6.2f} wall)  200 x 1 {r['solve200_cpu']:6.2f} s CPU  "
                  f"residual {r['residual']:.1e}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", default="256,1024", help="contact nodes of the pads (squares)")
    ap.add_argument("--dovetail", action="store_true", help="also the shipped dovetail")
    ap.add_argument("--rhs", type=int, help="at most this many right-hand sides (all: m)")
    ap.add_argument("--only", default="", help="comma-separated parts of backend labels")
    ap.add_argument("--save", help="write the matrices into this folder")
    ap.add_argument("--load", help="read the matrices from this folder (no fretwear needed)")
    args = ap.parse_args()
    sets = {}
    if args.load:
        for f in sorted(os.listdir(args.load)):
            if f.endswith("_Kii.npz"):
                key = f[: -len("_Kii.npz")]
                sets[key] = {p: sp.load_npz(os.path.join(args.load, f"{key}_{p}.npz")).tocsc()
                             for p in ("Kii", "Mii", "Kic")}
    else:
        for nodes in (int(s) for s in args.nodes.split(",") if s):
            sets[f"pad{nodes}"] = pad_matrices(round(nodes ** 0.5))
        if args.dovetail:
            sets["dovetail"] = dovetail_matrices()
    if args.save:
        os.makedirs(args.save, exist_ok=True)
        for key, mats in sets.items():
            for p, A in mats.items():
                sp.save_npz(os.path.join(args.save, f"{key}_{p}.npz"), A)
        return
    for key, mats in sets.items():
        run(key, mats, args.rhs, [o for o in args.only.split(",") if o])


if __name__ == "__main__":
    main()
