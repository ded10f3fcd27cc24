"""Test configuration: one BLAS thread (the suite is many small dense problems; BLAS threads
only oversubscribe a 2-core machine), and a non-interactive matplotlib backend."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")
