"""Writes the pyNastran-made test files of this folder (run once by hand; pyNastran 1.4.1 is
not a dependency of fretwear, and needs ``np.in1d`` restored to import on NumPy >= 2.4).

    PYTHONPATH=<pyNastran install> python tests/data/fe/make_pynastran_files.py

The matrices are those of tests/model/readers/test_nastran.py::spring_chain: a chain of three
grids (ids 10, 20, 30), translations 1-3, and one scalar point (id 100, component 0)."""

from pathlib import Path

import numpy as np

np.in1d = np.isin  # noqa: NPY201  (removed in NumPy 2.4, still used by pyNastran 1.4.1)
import scipy.sparse as sp  # noqa: E402
from pyNastran.bdf.bdf import BDF  # noqa: E402
from pyNastran.op4.op4 import OP4  # noqa: E402

HERE = Path(__file__).parent


def spring_chain():
    """The test matrices: K (10 x 10) symmetric positive definite, M diagonal."""
    rng = np.random.default_rng(32)
    A = rng.standard_normal((10, 10))
    K = (A @ A.T + 10.0 * np.eye(10)) * 1.234567e5
    M = np.diag(1.0 + np.arange(10) / 7.0)
    nodes = [10, 10, 10, 20, 20, 20, 30, 30, 30, 100]
    comps = [1, 2, 3, 1, 2, 3, 1, 2, 3, 0]
    return K, M, nodes, comps


def main():
    K, M, nodes, comps = spring_chain()
    model = BDF(debug=None)
    for name, A, tin in (("KAAX", K, 2), ("MAAX", M, 1)):
        gcj, gci, real = [], [], []
        for j in range(10):
            for i in range(j, 10):  # lower triangle, column by column
                if A[i, j] != 0.0:
                    gcj.append((nodes[j], comps[j]))
                    gci.append((nodes[i], comps[i]))
                    real.append(A[i, j])
        model.add_dmig(name, ifo=6, tin=tin, tout=tin, polar=0, ncols=10, GCj=gcj, GCi=gci,
                       Real=real)
    model.write_bdf(HERE / "pynastran-dmig-small.bdf", size=8)
    model.write_bdf(HERE / "pynastran-dmig-large.bdf", size=16, is_double=True)
    OP4().write_op4(HERE / "pynastran-ascii.op4",
                    {"KAAX": (6, K), "MAAX": (6, sp.coo_matrix(M))}, precision="double",
                    is_binary=False)


if __name__ == "__main__":
    main()
