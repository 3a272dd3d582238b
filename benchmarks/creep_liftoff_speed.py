"""Lift-off under creep: CPU time against the goals of slider speed, with the estimates.

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.creep_liftoff_speed [--no-write]
    # writes benchmarks/results/creep_liftoff_speed.md (~3 min)

Goals (issue "Honest to the edges under creep", point 3): a load change of the lift-off
preset <= 20 ms, its new scene <= 100 ms, a lift-off whose eccentricity grows under creep
<= 1 s; and the crown radius as a live slider of the explorer (its live bound,
``explorer.app.LIVE_SOLVE_S``, 0.1 s). Cases, each through ``core.solve`` (or
``solve_dimensionless`` where it is a dimensionless scene), the CPU time of this process:

* the preset ``eccentric_footing_liftoff`` (creep, 20 outputs, tol 1e-4): a new scene
  (caches cleared) and a load change (the moment 1 % up, the rest warm);
* the default scene (``uniform_flat``: a creeping slab under a 20 mm coating) with a
  crowned punch of radius R = 5 ... 25 km, at its tol 1e-6 and at 1e-4, caches cleared:
  its contact spreads as the slab creeps;
* ``liftoff_exp_growing`` of ``benchmarks/creep_honesty.py``: e(t) from 0.3 to 0.6 a on an
  exponential kernel, tol 1e-4;
* the preset ``stepped_punch`` under a centred force rising from 160 to 800 kN/m over a
  year (its outer steps come into contact), tol 1e-6.

A problem even in x (the crowns, the stepped punch: symmetric and centred) is marched on
the half x > 0 (``core.contact.systems.Mirror``); for those the table also gives the CPU
time of the march on the whole rule (the fold turned off, as before it) and how far the
two settlement histories are apart, relative to the largest settlement.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from typing import Any

import numpy as np

from benchmarks import ROOT, run_lines, tree_commit
from benchmarks.creep_honesty import cases
from core.cache import clear_caches
from core.contact.systems import Mirror
from core.presets import read_preset
from core.scene import solve
from core.solver import solve_dimensionless

RESULTS = ROOT / "benchmarks" / "results" / "creep_liftoff_speed.md"
RADII_KM = (5.0, 10.0, 15.0, 20.0, 25.0)


def cpu(call: Callable[[], Any], repeats: int = 3, cold: bool = True) -> tuple[float, Any]:
    """Median CPU seconds of ``repeats`` runs (caches cleared before each when ``cold``)."""
    times, out = [], None
    for _ in range(repeats):
        if cold:
            clear_caches()
        start = time.process_time()
        out = call()
        times.append(time.process_time() - start)
    return sorted(times)[len(times) // 2], out


def _crowned(radius_km: float, tol: float) -> dict[str, Any]:
    scene = read_preset("uniform_flat")
    scene["punch"]["shape"] = {"kind": "polynomial",
                               "coefficients": [0.0, 0.0, 1.0 / (2.0 * radius_km * 1e3)]}
    scene["solver"]["tol"] = tol
    return scene


@contextmanager
def whole_problem() -> Iterator[None]:
    """Even problems marched on the whole rule, as before the fold onto x > 0."""
    saved = Mirror.__dict__["centred"]
    Mirror.centred = staticmethod(lambda given, loads: False)  # type: ignore[method-assign]
    try:
        yield
    finally:
        Mirror.centred = saved  # type: ignore[method-assign]


def _row(label: str, seconds: float, goal: float | None, result: Any,
         whole: tuple[float, Any] | None = None) -> str:
    info = result.info
    met = "-" if goal is None else ("yes" if seconds <= goal else "no")
    if whole is None:
        compared = "- | -"
    else:
        settlement = np.asarray(result.settlement, dtype=float)
        before = np.asarray(whole[1].settlement, dtype=float)
        difference = np.max(np.abs(settlement - before)) / np.max(np.abs(before))
        compared = f"{1e3 * whole[0]:.0f} | {difference:.1e}"
    return (f"| {label} | {1e3 * seconds:.0f} | {'-' if goal is None else f'{1e3 * goal:.0f}'}"
            f" | {met} | {info.get('success')} | {info.get('contact', '')} | "
            f"{info.get('n_steps', '')} | {info.get('n_nodes', '')} | "
            f"{float(info.get('error_estimate', float('nan'))):.1e} | {compared} |")


def _stepped_ramp() -> dict[str, Any]:
    scene = read_preset("stepped_punch")
    scene["loading"] = {"force": {"kind": "table", "points": [[0.0, 1.6e5], [365.0, 8e5]]},
                        "moment": 0.0}
    return scene


def rows(progress: bool = True) -> list[str]:
    out = []

    def say(line: str) -> None:
        out.append(line)
        if progress:
            print(line, flush=True)

    def even(call: Callable[[], Any], repeats: int = 3) -> tuple[float, Any,
                                                                 tuple[float, Any]]:
        seconds, result = cpu(call, repeats=repeats)
        with whole_problem():
            whole = cpu(call, repeats=repeats)
        return seconds, result, whole

    preset = read_preset("eccentric_footing_liftoff")
    seconds, result = cpu(lambda: solve(preset))
    say(_row("lift-off preset, new scene", seconds, 0.1, result))
    moments = iter(1.0 + 0.01 * k for k in range(1, 100))

    def load_change() -> Any:
        moved = dict(preset, loading=dict(preset["loading"]))
        moved["loading"]["moment"] = preset["loading"]["moment"] * next(moments)
        return solve(moved)

    solve(preset)
    seconds, result = cpu(load_change, cold=False)
    say(_row("lift-off preset, a load change (moment +1 %)", seconds, 0.02, result))
    for tol in (1e-6, 1e-4):
        for radius in RADII_KM:
            scene = _crowned(radius, tol)
            seconds, result, whole = even(lambda scene=scene: solve(scene))
            say(_row(f"crowned default, R = {radius:g} km, tol {tol:.0e}", seconds, 0.1,
                     result, whole))
    growing = next(c for c in cases() if c.key == "liftoff_exp_growing")
    seconds, result = cpu(lambda: solve_dimensionless(tol=1e-4, contact=growing.contact,
                                                      **growing.at(1e-4)), repeats=3)
    say(_row("growing eccentricity e(t) 0.3 -> 0.6 a, tol 1e-4", seconds, 1.0, result))
    seconds, result, whole = even(lambda: solve(_stepped_ramp()), repeats=1)
    say(_row("stepped punch, centred force 160 -> 800 kN/m, tol 1e-6", seconds, None,
             result, whole))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    started, load_before, commit = datetime.now(UTC), os.getloadavg()[0], tree_commit()
    table = rows()
    text = "\n".join([
        "# Lift-off under creep: CPU time against slider speed", "", "Made with:", "",
        "```", "OPENBLAS_NUM_THREADS=1 python -m benchmarks.creep_liftoff_speed", "```", "",
        *run_lines(started, load_before, os.getloadavg()[0],
                   "CPU times of this process: the steadier figure on a shared machine",
                   commit=commit),
        "", "The cases and goals: the docstring of `benchmarks/creep_liftoff_speed.py`. "
        "Medians of 3 runs (the stepped punch: one; CPU times of one run vary by up to ~30 % "
        "on this shared machine).", "",
        "| case | CPU ms | goal ms | goal met | success | contact | steps | nodes | "
        "error estimate | whole march CPU ms | settlement difference |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        *table, ""])
    if args.no_write:
        print(text)
    else:
        RESULTS.write_text(text)
        print(f"wrote {RESULTS.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
