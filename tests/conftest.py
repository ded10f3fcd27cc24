"""Test configuration: one BLAS thread (the suite is many small dense problems; BLAS threads
only oversubscribe a 2-core machine), a non-interactive matplotlib backend, and, under
pytest-xdist (``pytest -n 2``), a numba cache folder per worker.

numba writes each compiled kernel atomically but updates a kernel's cache index without a
lock: two workers saving two signatures of one kernel at the same moment could leave an index
entry that names the other signature's file. One cache folder per worker (``.numba-cache/gwN``
at the top of the checkout, set before numba is imported) rules that out; a cold cache then
costs one compilation per worker.
"""

import os
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")
_worker = os.environ.get("PYTEST_XDIST_WORKER")
if _worker:
    os.environ["NUMBA_CACHE_DIR"] = str(Path(__file__).resolve().parents[1] / ".numba-cache"
                                        / _worker)
