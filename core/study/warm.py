"""Workers warmed for studies when their cluster starts, not on their first batch.

A fresh worker process pays, on the first batch it runs, for importing the solver and for
the tables every solve shares (quadrature rules, kernel tables, the lift-off family's
interpolation): :func:`warm_worker` pays them up front by running two small batches of a
scene of its own (a flat punch on a coating over an elastic base: a few load points, in
and out of full contact, and a coating modulus), whose geometry no study shares, so no
study's own results are prepared ahead. :class:`WarmStudyWorker` runs it on every worker
of a cluster, those joining later included; :func:`start_local_cluster` starts the local
cluster :func:`core.study.sweep` uses, warmed, so that the warming counts in the
cluster's start. This module imports Dask's ``distributed``: :mod:`core.study.run` imports
it only when a cluster is used.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from distributed.diagnostics.plugin import WorkerPlugin

from core.work import BLAS_THREAD_VARIABLES

#: The scene of the warming batches (SI units): unlike any study's base but solved by the
#: same paths (exact layered kernel, load batches, lift-off families, one-point solves).
WARM_SCENE: dict[str, Any] = {
    "schema_version": 1, "name": "warming a study worker",
    "punch": {"half_width": 0.7, "shape": 0.0},
    "coating": [{"thickness": 0.015, "modulus": 6.0e8, "poisson": 0.3}],
    "base": {"thickness": 3.0, "poisson": 0.2, "age_at_loading": 28.0,
             "creep": {"model": "elastic", "modulus": 2.5e10}},
    "loading": {"force": 3.0e5, "moment": 0.0},
    "times": [365.0],
    "solver": {"tol": 1e-6},
}
#: Force [N/m] and moment [N] of the warming load batch: three full-contact points, one
#: that lifts off (e = 0.5 m on the 0.7 m half width) and one scaled from it (twice the
#: loads). A lift-off family (ten eccentricities or more) is left out: it would cost
#: ~2.7 s of CPU, mostly this geometry's own zone solves, which no study shares.
WARM_LOADS = np.array([[2e5, 0.0], [3e5, 2e4], [4e5, 4e4], [2e5, 1e5], [4e5, 2e5]])


def warm_worker() -> float:
    """Import what a study's batch uses and run the two warming batches in this process;
    the CPU seconds it took [s]."""
    from core.study.batch import run_batch
    from core.study.definition import OUTPUT_UNITS

    cpu = time.process_time()
    outputs = tuple(OUTPUT_UNITS)
    run_batch(WARM_SCENE, ["loading.force", "loading.moment"], WARM_LOADS, outputs, 1)
    run_batch(WARM_SCENE, ["coating[0].modulus"], np.array([[4.0e8]]), outputs, 1)
    return time.process_time() - cpu


class WarmStudyWorker(WorkerPlugin):
    """Runs :func:`warm_worker` on every worker when it joins (its setup); the CPU
    seconds it took are kept as the worker's ``coated_punch_warm_cpu``."""

    name = "coated-punch-study-warm"

    def setup(self, worker: Any) -> None:
        """Warm the worker (:func:`warm_worker`); a failure is kept as the worker's
        ``coated_punch_warm_error``, never stopping it: warming only saves time."""
        try:
            worker.coated_punch_warm_cpu = warm_worker()
        except Exception as exc:  # noqa: BLE001 - the study's own batches report errors
            worker.coated_punch_warm_error = f"{type(exc).__name__}: {exc}"[:500]


def warm_workers(client: Any) -> None:
    """Register :class:`WarmStudyWorker` on ``client``'s cluster: returns when every
    current worker ran :func:`warm_worker`."""
    client.register_plugin(WarmStudyWorker())


def quiet_worker_logs() -> None:
    """Run on each worker as its cluster closes: its ``distributed`` logs say nothing
    below CRITICAL from then on (the close's own races are no error of the study)."""
    logging.getLogger("distributed").setLevel(logging.CRITICAL)


def start_local_cluster(n_workers: int | None = None,
                        warm: bool = True) -> tuple[Any, Callable[[], None]]:
    """A local cluster of ``n_workers`` (default: one per core) single-threaded worker
    processes on 127.0.0.1 with BLAS on one thread, warmed (``warm``) before this returns;
    the client and a function that closes both."""
    from distributed import Client, LocalCluster

    workers = n_workers or os.cpu_count() or 1
    # one single-threaded worker process per core; BLAS threads would only compete
    # (the scheduler's HTTP server, dashboard or not, on a free port: on Dask's 8787 a
    # second study at once, the page's beside the command line's, warned it was taken)
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           host="127.0.0.1", dashboard_address=None,
                           scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                           env=dict.fromkeys(BLAS_THREAD_VARIABLES, "1"))
    client = Client(cluster)

    def close() -> None:
        try:
            # a worker's heartbeat racing the scheduler's close logs a traceback of its
            # own on the script's stderr (the README's study example, on a loaded machine)
            client.run(quiet_worker_logs)
        except Exception:  # noqa: BLE001 - a worker already gone has nothing to log
            pass
        client.close()
        cluster.close()
    try:
        client.wait_for_workers(workers)
        if warm:
            warm_workers(client)
    except BaseException:
        close()
        raise
    return client, close
