"""Cost of the eps rule at scale: the spectral radius of one reduced block of 1024 contact
nodes x 3 DOFs (3072 rows, complex), as :func:`fretwear.hb.penalty.radius` computes it (power
iteration above EXACT_SIZE rows), against a dense eigenvalue decomposition of a quarter of that
size timed in the same run (the full size takes minutes).

    PYTHONPATH=src OPENBLAS_NUM_THREADS=1 python benchmarks/penalty_scale.py

Prints the times [s], the ratio, the estimate's relative error on a matrix of known spectrum
and the machine load.
"""

import os
import time

import numpy as np

from fretwear.hb.penalty import radius


def known(n, seed=0):
    """A complex symmetric normal matrix Q diag(l) Q^T with |l|max known."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    lam = rng.uniform(1.0, 3.0, n) * np.exp(1j * rng.uniform(0.0, 0.05, n))
    lam[0] = 4.0 + 0.1j
    return (Q * lam) @ Q.T, abs(lam[0])


Z, rho = known(3072)
t0 = time.perf_counter()
est = radius(Z)
t_est = time.perf_counter() - t0
Zq = Z[:768, :768]
t0 = time.perf_counter()
np.linalg.eigvals(Zq)
t_eig = time.perf_counter() - t0
print(f"radius_3072_s={t_est:.3f} eigvals_768_s={t_eig:.3f} ratio={t_eig / t_est:.1f} "
      f"relative_error={est / rho - 1:+.1e}")
print(f"load={os.getloadavg()[0]:.2f} cores={os.cpu_count()}")
