"""Fixtures of the sweep tests: an in-process Dask cluster."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def client():
    """A Client on an in-process LocalCluster of two one-thread workers, closed afterwards."""
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0"
    )
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()
