"""What a back-analysis costs: fits of two and three scene fields to 30 readings.

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.calibrate [--no-write]

Each case fits synthetic readings (the scene at known values plus noise, a new draw each
fit, so no solve repeats an earlier one from the caches) from a start away from the
truth, :data:`FITS` times; the first fit of a case also prepares the geometry and is
reported apart. Cases:

* *exponential creep, 3 fields*: ``base.creep.compliance``, ``base.creep.rate`` and
  ``loading.force`` of the footing of ``tests/back_analysis/test_fit.py`` (eccentric load on
  a layer with exponential creep), 30 settlements over a year with 1e-5 m noise;
* *young concrete, 2 fields*: ``base.creep.relative_humidity`` and
  ``base.age_at_loading`` of the preset ``young_concrete_50_years`` (fib Model Code
  2010), 30 settlements over two years with 1e-6 m noise (the docs' example);
* *young concrete, 3 fields*: the same with ``loading.force`` as well.

Prints and writes (unless ``--no-write``) ``benchmarks/results/calibrate.md``: the median
wall time per fit, solves per fit and time per solve, with the commit, the UTC date and
the load average.
"""

from __future__ import annotations

import os
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from benchmarks import run_lines
from core.back_analysis import calibrate
from core.presets import read_preset
from core.scene import solve
from core.study import apply_point
from tests.support.creeping_footing import creeping_footing

#: Fits per case after the first (medians are reported).
FITS = 5
#: The goal of a three-field fit to 30 readings [s].
GOAL_SECONDS = 2.0
RESULTS = Path(__file__).resolve().parent / "results" / "calibrate.md"

CREEPING = creeping_footing()


def _cases() -> list[tuple[str, dict, dict, dict, np.ndarray, float]]:
    young = read_preset("young_concrete_50_years")
    return [
        ("exponential creep, 3 fields", CREEPING,
         {"base.creep.compliance": 3e-9, "base.creep.rate": 0.02, "loading.force": 2e5},
         {"base.creep.compliance": 2e-9, "base.creep.rate": 0.03, "loading.force": 2.5e5},
         np.linspace(365 / 30, 365, 30), 1e-5),
        ("young concrete, 2 fields", young,
         {"base.creep.relative_humidity": 70.0, "base.age_at_loading": 10.0},
         {"base.creep.relative_humidity": 60.0, "base.age_at_loading": 7.0},
         np.linspace(730 / 30, 730, 30), 1e-6),
        ("young concrete, 3 fields", young,
         {"base.creep.relative_humidity": 70.0, "base.age_at_loading": 10.0,
          "loading.force": 6e5},
         {"base.creep.relative_humidity": 60.0, "base.age_at_loading": 7.0,
          "loading.force": 5.5e5},
         np.linspace(730 / 30, 730, 30), 1e-6),
    ]


def measure(scene: dict, truth: dict, start: dict, times: np.ndarray, noise: float
            ) -> tuple[float, float, float, float]:
    """``(first fit s, median fit s, median solves, median s per solve)``."""
    exact = solve(apply_point(scene, truth) | {"times": times.tolist()}).settlement
    rng = np.random.default_rng(1)
    walls, solves = [], []
    for _ in range(FITS + 1):
        readings = {"time": times.tolist(), "settlement_std": noise,
                    "settlement": (exact + noise * rng.standard_normal(times.size)).tolist()}
        started = time.perf_counter()
        fit = calibrate(apply_point(scene, start), readings, fit=list(truth),
                        bounds={"base.creep.relative_humidity": (20.0, 100.0)}
                        if "base.creep.relative_humidity" in truth else None)
        walls.append(time.perf_counter() - started)
        solves.append(fit.solves)
    wall, count = float(np.median(walls[1:])), float(np.median(solves[1:]))
    return walls[0], wall, count, wall / count


def main() -> None:
    started = datetime.now(timezone.utc)
    load_before = os.getloadavg()[0]
    lines = ["| case | first fit [s] | fit [s] | solves per fit | per solve [s] |",
             "| --- | --- | --- | --- | --- |"]
    for name, scene, truth, start, times, noise in _cases():
        first, wall, count, per = measure(scene, truth, start, times, noise)
        mark = " (over)" if name.endswith("3 fields") and wall > GOAL_SECONDS else ""
        lines.append(f"| {name} | {first:.2f} | {wall:.2f}{mark} | {count:.0f} | "
                     f"{per:.3f} |")
        print(lines[-1], flush=True)
    load_after = os.getloadavg()[0]
    text = "\n".join([
        "# What a back-analysis costs", "",
        "    OPENBLAS_NUM_THREADS=1 python -m benchmarks.calibrate", "",
        *run_lines(started, load_before, load_after),
        f"- wall time per fit: the first (geometry prepared) and the median of the next "
        f"{FITS} (new noise draws); goal of a three-field fit to 30 readings: "
        f"{GOAL_SECONDS:g} s", "",
        *lines, ""])
    if "--no-write" not in sys.argv:
        RESULTS.write_text(text)
        print(f"written: {RESULTS}")


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    main()
