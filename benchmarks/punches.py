"""What a scene of two punches costs against one punch of the same resolution.

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.punches [--no-write]

The uniform preset on an elastic base at tol 1e-6. *One punch*: the punch alone by the
same model (thin layer, default engine: ``scene.dimensionless.solve()``), its half-width
0.01 % wider at each solve so that every cache misses (*loads only*: its force changed).
*Two punches*: ``core.solve`` of
two punches 1 m apart (the second 0.6 times as wide, so the two grids differ, or the same
width, so they share one), both half-widths changed at each solve; *loads only*: the two
punches' forces changed. *Creep*: the same in full contact on a creeping base (exponential
creep, 6 output times over a year): a new geometry steps the coupled modal equations in
time, a load change combines the cached time-stepped responses to each load's shape.
*Lift-off*: the first punch (and the punch alone) under a moment that lifts its heel off,
contact ``"unilateral"``; *under creep*: the same on the creeping base (``CREEP_SOLVES``
solves each) under ``CREEP_LIFTING_MOMENT``. Medians
of the CPU time of this process per solve [ms], with the machine's load average; written to
``benchmarks/results/punches.md`` unless ``--no-write``.
"""

from __future__ import annotations

import os
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

import core
from benchmarks import tree_commit
from core.presets import read_preset
from core.scene import SceneSolution, scene_from_dict

SOLVES = 8
#: Solves of each creep lift-off row (a second or more each).
CREEP_SOLVES = 3
#: The moment [N] of the creep lift-off rows (e = 0.6 a): the punch alone lifts its heel
#: off under it from the first time (measured: zone from -0.313 to -0.369 over the year).
CREEP_LIFTING_MOMENT = 3e5
#: The creeping base of the creep lift-off rows (as tests/scene/test_punches.py's).
CREEP = {"model": "exponential", "modulus": 3.0e10, "compliance": 3.0e-11, "rate": 0.05}


def _scene(creep: bool = False) -> dict:
    d = read_preset("uniform_flat")
    d["base"]["creep"] = dict(CREEP) if creep else {"model": "elastic", "modulus": 3.0e10}
    d["times"] = ({"end": 365.0, "count": 6, "spacing": "log"} if creep
                  else {"end": 10.0, "count": 3})
    d["solver"] = {"tol": 1e-6}
    return d


#: The moment [N] that lifts the first punch's heel off in the lift-off rows (e = 0.6 a;
#: measured: zone from -0.313 a). Under 2e5 N (e = 0.4 a) the punch alone kept full
#: contact, and rows so named measured no lift-off.
LIFTING_MOMENT = 3e5


def _single(i: int, force_step: float = 0.0, geometry_step: float = 1e-4,
            moment: float = 0.0, creep: bool = False) -> None:
    d = _scene(creep)
    d["punch"]["half_width"] *= 1 + geometry_step * i
    d["loading"]["force"] *= 1 + force_step * i
    d["loading"]["moment"] = moment
    if moment:
        d["solver"]["contact"] = "unilateral"
    scene = scene_from_dict(d)
    SceneSolution(scene, scene.dimensionless, scene.dimensionless.solve())


def _pair(i: int, ratio: float, force_step: float = 0.0, geometry_step: float = 1e-4,
          moment: float = 0.0, creep: bool = False) -> None:
    d = _scene(creep)
    del d["punch"], d["loading"]
    a0, a1 = 1.0 * (1 + geometry_step * i), ratio * (1 + geometry_step * i)
    d["punches"] = [
        {"center": 0.0, "half_width": a0,
         "loading": {"force": 5e5 * (1 + force_step * i), "moment": moment}},
        {"center": a0 + 1.0 + a1, "half_width": a1,
         "loading": {"force": 3e5 * (1 + force_step * i), "moment": 0.0}}]
    if moment:
        d["solver"]["contact"] = "unilateral"
    core.solve(d)


def _median_ms(run, solves: int = SOLVES) -> float:  # noqa: ANN001
    times = []
    for i in range(1, solves + 1):
        start = time.process_time()
        run(i)
        times.append(time.process_time() - start)
    return 1e3 * float(np.median(times))


def main(argv: list[str]) -> None:
    _single(0), _pair(0, 0.6)  # imports and first builds: not measured
    rows = [("one punch (a = 1 m), new geometry", _median_ms(_single)),
            ("two punches (a = 1, 0.6 m), new geometry", _median_ms(lambda i: _pair(i, 0.6))),
            ("two punches (a = 1, 1 m), new geometry", _median_ms(lambda i: _pair(i, 1.0))),
            ("one punch (a = 1 m), loads only",
             _median_ms(lambda i: _single(1000, force_step=1e-3 * i, geometry_step=0.0))),
            ("two punches (a = 1, 0.6 m), loads only",
             _median_ms(lambda i: _pair(1000, 0.6, force_step=1e-3 * i, geometry_step=0.0)))]
    single = rows[0][1]
    # full contact on a creeping base: a new geometry, and loads only
    creep_rows = [
        ("one punch (a = 1 m), creep, new geometry",
         _median_ms(lambda i: _single(i, creep=True), CREEP_SOLVES)),
        ("two punches (a = 1, 0.6 m), creep, new geometry",
         _median_ms(lambda i: _pair(i, 0.6, creep=True), CREEP_SOLVES)),
        ("one punch (a = 1 m), creep, loads only",
         _median_ms(lambda i: _single(1000, force_step=1e-3 * i, geometry_step=0.0,
                                      creep=True))),
        ("two punches (a = 1, 0.6 m), creep, loads only",
         _median_ms(lambda i: _pair(1000, 0.6, force_step=1e-3 * i, geometry_step=0.0,
                                    creep=True)))]
    # lift-off (contact "unilateral"), against one punch lifting off alike
    lifting = [("one punch (a = 1 m), lift-off, new geometry",
                _median_ms(lambda i: _single(i, moment=LIFTING_MOMENT))),
               ("two punches (a = 1, 0.6 m), the first lifting off, new geometry",
                _median_ms(lambda i: _pair(i, 0.6, moment=LIFTING_MOMENT)))]
    creeping = [("one punch (a = 1 m), lift-off under creep, new geometry",
                 _median_ms(lambda i: _single(i, moment=CREEP_LIFTING_MOMENT, creep=True),
                            CREEP_SOLVES)),
                ("two punches (a = 1, 0.6 m), the first lifting off under creep, new geometry",
                 _median_ms(lambda i: _pair(i, 0.6, moment=CREEP_LIFTING_MOMENT, creep=True),
                            CREEP_SOLVES))]
    commit = tree_commit()
    load = os.getloadavg()
    lines = ["# Two punches against one", "",
             f"commit {commit}, {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, load average "
             f"{load[0]:.2f} {load[1]:.2f} {load[2]:.2f}, OPENBLAS_NUM_THREADS="
             f"{os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}; uniform preset, elastic "
             "base, tol 1e-6, 3 output times; median CPU time of "
             f"{SOLVES} solves (`python -m benchmarks.punches`).", "",
             "| solve | CPU [ms] | against one punch |", "| --- | --- | --- |"]
    lines += [f"| {name} | {ms:.1f} | {ms / single:.2f}x |" for name, ms in rows]
    lines += ["", "Full contact on a creeping base (exponential creep, 6 output times over a "
              f"year; new geometries: median of {CREEP_SOLVES} solves):", "",
              "| solve | CPU [ms] | against one punch, new geometry |", "| --- | --- | --- |"]
    lines += [f"| {name} | {ms:.1f} | {ms / creep_rows[0][1]:.2f}x |"
              for name, ms in creep_rows]
    lines += ["", "Lift-off (`solver.contact` \"unilateral\", the moment "
              f"{LIFTING_MOMENT:g} N on the first punch, e = 0.6 a):", "",
              "| solve | CPU [ms] | against one punch lifting off |", "| --- | --- | --- |"]
    lines += [f"| {name} | {ms:.1f} | {ms / lifting[0][1]:.2f}x |" for name, ms in lifting]
    lines += ["", "Lift-off under creep (exponential creep, 6 output times over a year, the "
              f"moment {CREEP_LIFTING_MOMENT:g} N on the first punch, e = 0.6 a; median of "
              f"{CREEP_SOLVES} solves):", "",
              "| solve | CPU [ms] | against one punch lifting off |", "| --- | --- | --- |"]
    lines += [f"| {name} | {ms:.1f} | {ms / creeping[0][1]:.2f}x |" for name, ms in creeping]
    text = "\n".join(lines) + "\n"
    print(text)
    if "--no-write" not in argv:
        out = Path(__file__).resolve().parent / "results" / "punches.md"
        out.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    main(sys.argv[1:])
