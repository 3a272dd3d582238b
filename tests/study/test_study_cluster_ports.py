"""Two studies at once, each on a local cluster of its own (core/study/warm.py): the
scheduler's HTTP server took Dask's port 8787 whether or not a dashboard was asked for,
so the second warned "Port 8787 is already in use" (seen when two parts of the suite ran
studies at once; a user's page and command line would do the same)."""

from __future__ import annotations

import warnings

import pytest


@pytest.mark.soak
def test_two_local_clusters_at_once_take_free_ports_without_a_warning() -> None:
    from core.study.warm import start_local_cluster

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        first, close_first = start_local_cluster(1, warm=False)
        try:
            second, close_second = start_local_cluster(1, warm=False)
            try:
                ports = [client.scheduler_info()["services"] for client in (first, second)]
            finally:
                close_second()
        finally:
            close_first()
    assert not [w for w in caught if "already in use" in str(w.message)]
    assert ports[0] != ports[1]
