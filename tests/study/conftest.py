"""One local Dask cluster of two worker processes for a test module (starting one costs a
few seconds)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def client():
    """A LocalCluster of 2 worker processes (1 thread each) shared by a test module."""
    import logging

    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=":0", silence_logs=logging.ERROR)
    c = Client(cluster)
    try:
        yield c
    finally:
        c.close()
        cluster.close()
