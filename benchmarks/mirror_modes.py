"""Even and odd modes found apart on a symmetric geometry: the CPU of a new geometry and the
answer, against one decomposition of all the modes.

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.mirror_modes [--no-write]
    # writes benchmarks/results/mirror_modes.md (~1 min)

For each preset whose modal form is symmetric (and one that is not, the control), the
median CPU time of a new geometry (``benchmarks.scene_overhead``'s "new geometry": the
half-width 0.01 % wider a solve, caches cleared before each series) with the modes split
into even and odd ones (as shipped) and with the whole decomposition
(``core.engines.nystrom.modal.mirrored`` answering False), the two series interleaved
``ROUNDS`` times in alternating order (the machine's speed moves during a run), and the
largest difference of the two answers' pressure (on their grid, every output time)
relative to its largest value.
"""

from __future__ import annotations

import os
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

import core.engines.nystrom.modal as modal
from benchmarks import run_lines
from benchmarks.scene_changes import changed_scene
from benchmarks.scene_overhead import SOLVES
from core.cache import clear_caches
from core.presets import read_preset
from core.scene import solve

PRESETS = ("stepped_punch", "patched_insert", "uniform_flat", "eccentric_creep",
           "young_concrete_50_years", "new_footing_beside_old")
ROUNDS = 5
RESULTS = Path(__file__).resolve().parent / "results" / "mirror_modes.md"
_SHIPPED = modal.mirrored


def _series(name: str, split: bool, symmetric: list[bool]) -> tuple[float, list]:
    """Median CPU ms of the new geometries of ``name``, and their answers; ``symmetric``
    gets whether each modal form was (with ``split``)."""

    def watched(grid) -> bool:
        symmetric.append(_SHIPPED(grid))
        return symmetric[-1]

    modal.mirrored = watched if split else (lambda grid: False)
    try:
        clear_caches()
        scene = read_preset(name)
        solve(scene)
        cpu, answers = [], []
        # the half-width 0.01 % wider a solve, as scene_overhead's "new geometry"
        for variant in (changed_scene(scene, "geometry", i, 1e-4)
                        for i in range(1, SOLVES + 1)):
            started = time.process_time()
            answers.append(solve(variant))
            cpu.append(time.process_time() - started)
        return 1e3 * float(np.median(cpu)), answers
    finally:
        modal.mirrored = _SHIPPED


def _difference(ours: list, theirs: list) -> float:
    """The largest difference of the pressures on the answers' own grids (every output
    time), relative to the largest pressure."""
    worst = 0.0
    for a, b in zip(ours, theirs, strict=True):
        qa, qb = np.asarray(a.pressure_on_grid), np.asarray(b.pressure_on_grid)
        worst = max(worst, float(np.max(np.abs(qa - qb)) / np.max(np.abs(qb))))
    return worst


def main(argv: list[str]) -> None:
    names = [a for a in argv if not a.startswith("--")] or list(PRESETS)
    started, load_before = datetime.now(UTC), os.getloadavg()[0]
    lines = ["| preset | symmetric | split [ms] | whole [ms] | split / whole | "
             "q difference (relative) |", "| --- | --- | --- | --- | --- | --- |"]
    for name in names:
        split_ms, whole_ms, differences = [], [], []
        symmetric: list[bool] = []
        for k in range(ROUNDS):
            order = (True, False) if k % 2 == 0 else (False, True)
            runs = {split: _series(name, split, symmetric) for split in order}
            split_ms.append(runs[True][0])
            whole_ms.append(runs[False][0])
            differences.append(_difference(runs[True][1], runs[False][1]))
        s, w = float(np.median(split_ms)), float(np.median(whole_ms))
        lines.append(f"| {name} | {'yes' if any(symmetric) else 'no'} | {s:.1f} | {w:.1f} | "
                     f"{s / w:.2f} | {max(differences):.1e} |")
        print(lines[-1], flush=True)
    text = "\n".join([
        "# Even and odd modes apart on a symmetric geometry", "", "Made with:", "",
        "```", "OPENBLAS_NUM_THREADS=1 python -m benchmarks.mirror_modes", "```", "",
        *run_lines(started, load_before, os.getloadavg()[0],
                   "CPU times of this process: the steadier figure on a shared machine"),
        f"- a new geometry (the half-width 0.01 % wider a solve), medians of {SOLVES} solves "
        f"a series, the median of {ROUNDS} series each way, interleaved; the difference "
        "of the pressures on the answers' grid at every output time, the largest over "
        "every solve, relative to the largest pressure", "", *lines, ""])
    if "--no-write" not in argv:
        RESULTS.write_text(text)
        print(f"written: {RESULTS}")


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    main(sys.argv[1:])
