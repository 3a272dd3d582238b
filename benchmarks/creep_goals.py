"""The creep goals of the engine alone, with CPU time next to wall time.

Run from the repository root:

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.creep_goals [--repeats 5]

The same solves as the creep goals of ``benchmarks/engines.py`` (the ``aging_creep``
scene of :mod:`tests.support.scenes` with 100 and 1000 output times over 1000 days, tol
1e-6: a new scene with every cache cleared, then only the loads changed on a prepared
geometry) and the 50-year preset ``core/presets/scenes/young_concrete_50_years.json`` with
both design-code models (a new scene, and a load change rebuilt from the scene dict).
Medians of ``--repeats`` runs after a warm-up. On a shared machine the wall time is
inflated by other work far more than the CPU time of this process, so both are printed
with the load average.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import core
from core.cache import clear_caches
from core.scene import scene_from_dict
from core.solver import solve_dimensionless
from tests.support.scenes import creep_times, suite

PRESET = Path(__file__).resolve().parents[1] / "core" / "presets" / "scenes" / \
    "young_concrete_50_years.json"


def timed(call: Callable[[], Any], repeats: int, before: Callable[[], None] | None = None
          ) -> tuple[float, float, Any]:
    """Median CPU and wall time [ms] of ``repeats`` runs after a warm-up, and the answer."""
    out = call()
    cpu, wall = [], []
    for _ in range(repeats):
        if before is not None:
            before()
        c0, w0 = time.process_time(), time.perf_counter()
        out = call()
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    return 1e3 * statistics.median(cpu), 1e3 * statistics.median(wall), out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    repeats = parser.parse_args(argv).repeats
    print(f"load average at the start {os.getloadavg()[0]:.1f}; medians of {repeats}, "
          "CPU ms / wall ms")
    aging = next(s for s in suite() if s.key == "aging_creep")
    for count in (100, 1000):
        scene = aging.with_times(creep_times(1000.0, count))
        args = scene.arguments()
        cpu, wall, sol = timed(lambda scene=scene, args=args: solve_dimensionless(
            scene.lam, scene.m, scene.g, scene.times, tol=1e-6, **args), repeats, clear_caches)
        prepared = core.prepare(scene.lam, scene.m, scene.g, tol=1e-6)
        scales = iter(np.linspace(1.01, 1.5, 1000))

        def loads(prepared=prepared, scene=scene, scales=scales) -> Any:
            changed = {k: v for k, v in scene.arguments(next(scales)).items()
                       if k != "breakpoints"}
            return prepared.solve(scene.times, **changed)

        cpu_l, wall_l, _ = timed(loads, repeats)
        print(f"aging creep, {count} outputs: new scene {cpu:.1f} / {wall:.1f}, loads only "
              f"{cpu_l:.2f} / {wall_l:.2f} (steps {sol.info['n_steps']}, estimate "
              f"{sol.info['error_estimate']:.1e})")
    preset = json.loads(PRESET.read_text())
    for model in ("fib_mc2010", "eurocode2"):
        data = dict(preset, base=dict(preset["base"], creep=dict(preset["base"]["creep"],
                                                                 model=model)))
        cpu, wall, sol = timed(lambda data=data: scene_from_dict(data).dimensionless.solve(),
                               repeats, clear_caches)
        forces = iter(6.0e5 * (1.0 + 0.01 * np.arange(1, 1000)))
        cpu_l, wall_l, _ = timed(lambda data=data, forces=forces: scene_from_dict(dict(
            data, loading={"force": float(next(forces)), "moment": 0.0})).dimensionless.solve(),
            repeats)
        print(f"50 years, {model}: new scene {cpu:.1f} / {wall:.1f}, load change "
              f"{cpu_l:.2f} / {wall_l:.2f} (steps {sol.info['n_steps']}, estimate "
              f"{sol.info['error_estimate']:.1e})")
    print(f"load average at the end {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
