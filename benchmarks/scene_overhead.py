"""What a dimensional scene solve costs around the solver, preset by preset.

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.scene_overhead [PRESET ...] [--no-write]

For each shipped preset (default: all of them), ``core.solve`` on scene dicts (validation
included, as the explorer, the CLI and studies call it), eight solves each:

* *new geometry*: the punch half-width 0.01 % wider at each solve (every geometry cache
  misses: the samples, the gap minimum, the model-error map, the engine's prepared grid);
  of several punches, the last punch moved by 0.01 % of its half-width (the drag of a
  punch's centre);
* *loads only*: the first given load 0.1 % larger at each solve (of several punches, the
  first punch's first constant load);

and prints the median CPU time of this process per solve [ms], the median
``info["cpu_seconds"]`` (the solve's thread CPU time, validation included: what the
explorer compares with its live-drag bound) and ``info["seconds"]`` (the engine's wall
time), with the machine's load average: on a shared machine both CPU and wall times grow
with the load. The table (with the commit, the date and the load) is written to
``benchmarks/results/scene_overhead.md`` unless ``--no-write`` is given.
"""

from __future__ import annotations

import os
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from benchmarks import run_lines
from benchmarks.scene_changes import changed_scene
from core.presets import preset_names, read_preset
from core.scene import solve

#: Solves per preset and kind (medians are reported).
SOLVES = 8


def _variants(scene: dict, kind: str) -> list[dict]:
    # 0.01 % of the half-width, 0.1 % of the load a solve (benchmarks/scene_changes.py)
    if kind == "new geometry":
        return [changed_scene(scene, "geometry", i, 1e-4) for i in range(1, SOLVES + 1)]
    return [changed_scene(scene, "loads", i, 1e-3) for i in range(1, SOLVES + 1)]


def measure(name: str) -> list[tuple[str, float, float, float]]:
    """``(kind, CPU ms, info cpu_seconds ms, info seconds ms)`` medians for one preset."""
    scene = read_preset(name)
    solve(scene)  # imports and the first build: not measured
    rows = []
    for kind in ("new geometry", "loads only"):
        cpu, cpu_info, wall_info = [], [], []
        for variant in _variants(scene, kind):
            started = time.process_time()
            result = solve(variant)
            cpu.append(time.process_time() - started)
            cpu_info.append(result.info["cpu_seconds"])
            # several punches report their engine's time per punch
            wall_info.append(result.info.get("seconds", max(
                (p.info.get("seconds", np.nan) for p in getattr(result, "punches", ())),
                default=np.nan)))
        rows.append((kind, 1e3 * float(np.median(cpu)), 1e3 * float(np.median(cpu_info)),
                     1e3 * float(np.median(wall_info))))
    return rows


#: The goals of a live slider (CPU per solve, ms): a geometry move and a load move.
GOALS_MS = {"new geometry": 30.0, "loads only": 5.0}
#: Where :func:`main` writes its table.
RESULTS = Path(__file__).resolve().parent / "results" / "scene_overhead.md"


def main(argv: list[str]) -> None:
    names = argv or list(preset_names())
    started = datetime.now(timezone.utc)
    load_before = os.getloadavg()[0]
    lines = ["| preset | change | CPU per solve [ms] | goal [ms] | info cpu_seconds [ms] | "
             "engine wall [ms] |", "| --- | --- | --- | --- | --- | --- |"]
    for name in names:
        for kind, cpu, cpu_info, wall_info in measure(name):
            goal = GOALS_MS[kind]
            mark = "" if cpu <= goal else " (over)"
            lines.append(f"| {name} | {kind} | {cpu:.2f}{mark} | {goal:g} | {cpu_info:.2f} | "
                         f"{wall_info:.2f} |")
            print(lines[-1], flush=True)
    load_after = os.getloadavg()[0]
    text = "\n".join([
        "# What a scene solve costs around the engine", "",
        "    OPENBLAS_NUM_THREADS=1 python -m benchmarks.scene_overhead", "",
        *run_lines(started, load_before, load_after,
                   "CPU times move little with the load; the engine's wall time does"),
        f"- medians of {SOLVES} solves per preset and kind; \"new geometry\": the punch "
        "half-width 0.01 % wider each solve (every geometry cache misses; of several "
        "punches, the last one moved by 0.01 % of its half-width); \"loads only\": "
        "the first given load 0.1 % larger each solve", "",
        *lines, ""])
    if "--no-write" not in sys.argv:
        RESULTS.write_text(text)
        print(f"written: {RESULTS}")


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    main([a for a in sys.argv[1:] if not a.startswith("--")])
