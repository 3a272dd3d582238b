"""A solve runs its linear algebra on one BLAS thread and gives the libraries back their
thread counts; a count the user set by environment variable is kept.

Checked in fresh processes: the suite itself runs with ``OPENBLAS_NUM_THREADS=1``
(tests/run.sh), which a solve keeps, so only a process without the variables shows the
limit. Inside a solve the count is read by a stand-in for a stage of the solver that
records ``threadpoolctl.threadpool_info()`` and then calls the stage.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from core.work import BLAS_THREAD_VARIABLES

ROOT = Path(__file__).resolve().parents[2]

# Run in a fresh process: the BLAS thread counts before, inside and after solves (a scene,
# two scenes in two threads at once, the dimensionless problem, a prepared geometry and
# its solve), as JSON.
SCRIPT = r"""
import json, sys, threading
from unittest import mock

from threadpoolctl import threadpool_info, threadpool_limits

import core
import core.scene.pipeline as pipeline
import core.solver as solver

def counts():
    return sorted({lib["num_threads"] for lib in threadpool_info()
                   if lib["user_api"] == "blas"})

if sys.argv[1] == "user":
    # the user's own setting at run time, not by environment variable
    threadpool_limits(2, user_api="blas")
seen = {"before": counts(), "inside": []}

def recording(stage):
    def record(*args, **kwargs):
        seen["inside"].append(counts())
        return stage(*args, **kwargs)
    return record

with mock.patch.object(pipeline, "solve_scene_layered",
                       recording(pipeline.solve_scene_layered)):
    core.solve(core.load_scene("preset:worn_coating"))
    scene = core.load_scene("preset:uniform_flat").to_dict()
    scene["punch"]["half_width"] = 1.01
    threads = [threading.Thread(target=core.solve, args=(dict(scene, name=str(k)),))
               for k in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
with mock.patch.object(solver, "validate_geometry", recording(solver.validate_geometry)):
    core.solve_dimensionless(0.5, 0.05, 0.0, [1.0], force=1.0, moment=0.0)
prepared = sys.modules["core.engines.nystrom.prepared"]
with mock.patch.object(prepared, "validate_geometry", recording(prepared.validate_geometry)), \
        mock.patch.object(prepared.PreparedContact, "solve_validated",
                          recording(prepared.PreparedContact.solve_validated)):
    geometry = core.prepare(0.5, 0.06, 0.0)
    geometry.solve([1.0], force=1.0, moment=0.0)
seen["after"] = counts()
print(json.dumps(seen))
"""


def _run(how: str, **variables: str) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    env.update(variables)
    out = subprocess.run([sys.executable, "-c", SCRIPT, how], cwd=ROOT, env=env,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_solves_run_on_one_blas_thread_and_give_the_users_count_back() -> None:
    seen = _run("user")
    assert seen["before"] == [2]  # NumPy's and SciPy's OpenBLAS, set to 2 by the user
    # a scene, two at once in threads, the dimensionless problem, a prepared geometry and
    # its solve
    assert seen["inside"] == [[1]] * 6
    assert seen["after"] == [2]


def test_a_count_set_by_environment_variable_is_kept() -> None:
    seen = _run("environment", OMP_NUM_THREADS="2")
    assert seen["before"] == [2]
    assert seen["inside"] == [[2]] * 6
    assert seen["after"] == [2]


def test_a_library_that_cannot_be_set_leaves_the_solve_as_it_was(monkeypatch) -> None:
    """The thread count is a matter of speed: where the libraries cannot be read or set,
    the solve runs as it would have without the limit."""
    import core
    import core.work as work

    for name in BLAS_THREAD_VARIABLES:
        monkeypatch.delenv(name, raising=False)

    def unreadable():
        raise RuntimeError("no BLAS library this tool knows")

    monkeypatch.setattr(work, "_controller", unreadable)
    result = core.solve(core.load_scene("preset:worn_coating"))
    assert result.info["success"]
    assert work._blas_solves == 0 and work._blas_limiter is None
