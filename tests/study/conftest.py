"""One local Dask cluster of two worker processes for a test module (starting one costs a
few seconds)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def client():
    """The LocalCluster `fretwear study` starts by default
    (:func:`fretwear.study.runner.dask_client` without a scheduler), with 2 worker processes
    of 1 thread each, shared by a test module."""
    from fretwear.study.runner import dask_client

    with dask_client(None, workers=2) as c:
        yield c
