"""A load study's batch answers against ``core.solve`` on every point's own scene.

    python -m benchmarks.liftoff_family [n_side]     # default 100: 10,000 points (~1 min CPU)

Runs :func:`core.study.run_batch` over the batches of
``benchmarks.sweep.loads_study(n_side)`` as the study plans them (its lift-off points
answered as one family per eccentricity side, :mod:`core.study.liftoff`), then
``core.solve`` on each point's scene, and prints per contact model the largest difference
of each output relative to that output's size at the point, whether the refused points
carry the same messages and no values, whether the flags are equal, and the largest
error estimates. Nothing is written: the figures go to ``benchmarks/results/sweep.md``
by hand.
"""

from __future__ import annotations

import sys
import time
from typing import Any

import numpy as np

from benchmarks.sweep import loads_study
from core import solve
from core.study import Study
from core.study.batch import run_batch
from core.study.definition import apply_point
from core.study.outputs import point_outputs
from core.study.plan import BatchPlan
from core.study.points import point_table
from core.study.run import default_batch_points


def compare(study: Study) -> dict[str, Any]:
    """Every point of ``study``: the batch answer against ``core.solve``'s.

    Returns ``kinds`` (points failed / unilateral / full), ``worst`` (per kind, the largest
    relative difference of each of ``study.outputs``), ``bad_failures`` and ``bad_flags``
    (points whose refusal or flags differ), ``flagged`` (points with flags),
    ``estimate_batch`` / ``estimate_solve`` (largest lift-off error estimates, relative)
    and ``cpu_batch`` (CPU seconds in ``run_batch``).
    """
    table = point_table(study)
    paths = [p.path for p in study.parameters]
    outputs = list(study.outputs)
    plan = BatchPlan(study, default_batch_points(study.n_points))
    batches = [plan.batch(k) for k in range(plan.n_batches)]
    worst = {"unilateral": np.zeros(len(outputs)), "full": np.zeros(len(outputs))}
    out: dict[str, Any] = {"kinds": {"failed": 0, "unilateral": 0, "full": 0},
                           "worst": worst, "bad_failures": 0, "bad_flags": 0, "flagged": 0,
                           "estimate_batch": 0.0, "estimate_solve": 0.0, "cpu_batch": 0.0,
                           "batches": len(batches), "outputs": outputs}
    for index in batches:
        values = np.stack([table[p][index] for p in paths], axis=1)
        started = time.process_time()
        got = run_batch(study.base, paths, values, outputs, len(study.times))
        out["cpu_batch"] += time.process_time() - started
        for i, row in enumerate(values):
            point = {p: float(v) for p, v in zip(paths, row, strict=True)}
            try:
                result = solve(apply_point(study.base, point))
            except ValueError as exc:
                out["kinds"]["failed"] += 1
                same = (got["flags"][i] == "failed"
                        and got["error"][i] == " ".join(str(exc).split())[:500]
                        and bool(np.all(np.isnan(got["values"][i]))))
                out["bad_failures"] += not same
                continue
            kind = result.info["contact"]
            out["kinds"][kind] += 1
            want = point_outputs(result, outputs)
            # each output relative to its own size at the point (over the times)
            scale = np.max(np.abs(want), axis=1)
            scale = np.where(scale > 0, scale, 1.0)
            worst[kind] = np.maximum(
                worst[kind], np.max(np.abs(got["values"][i] - want), axis=1) / scale)
            out["bad_flags"] += not (got["flags"][i] == ",".join(result.flags)
                                     and got["error"][i] == "")
            out["flagged"] += bool(result.flags)
            if kind == "unilateral":
                out["estimate_batch"] = max(out["estimate_batch"],
                                            float(got["error_estimate"][i]))
                out["estimate_solve"] = max(out["estimate_solve"],
                                            float(result.info["error_estimate"]))
    return out


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    n_side = int(args[0]) if args else 100
    started = time.process_time()
    out = compare(loads_study(n_side))
    print(f"points {n_side**2} in {out['batches']} batches; kinds {out['kinds']}")
    print(f"refused points with other messages or values: {out['bad_failures']}; points "
          f"with other flags: {out['bad_flags']}; flagged points: {out['flagged']}")
    for kind, w in out["worst"].items():
        print(f"{kind}: largest difference / output size: " + ", ".join(
            f"{o} {v:.2g}" for o, v in zip(out["outputs"], w, strict=True))
              + f"; all {w.max():.2g}")
    print(f"lift-off error estimates: batch <= {out['estimate_batch']:.2g}, core.solve <= "
          f"{out['estimate_solve']:.2g}")
    print(f"CPU: run_batch {out['cpu_batch']:.1f} s, all {time.process_time() - started:.1f} s")
    return 0 if out["bad_failures"] == 0 and out["bad_flags"] == 0 else 1


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    raise SystemExit(main())
