"""What one BLAS thread per solve buys in a Python session, preset by preset.

    python -m benchmarks.blas_threads [PRESET ...] [--no-write]

Run it without ``OPENBLAS_NUM_THREADS`` (or the other variables of
``core.work.BLAS_THREAD_VARIABLES``) set: it compares, in fresh processes, the solver as a
plain Python session gets it (no variable set: each solve on one BLAS thread,
``core.work.one_blas_thread``) with the same session where the user asked for one BLAS
thread per core (``OPENBLAS_NUM_THREADS`` = the number of cores, which the solver keeps:
what every session got before solves set their threads). For each preset (default: all
of them), after a first solve: eight new geometries (the punch half-width 0.01 % wider
each time) and eight load changes (0.1 % larger), as in ``benchmarks.scene_overhead``;
the median wall and CPU time [ms] of ``core.solve`` per solve, the two processes run one
after the other for each preset so that both see the same machine. The table (with the
commit, the date and the load) is written to ``benchmarks/results/blas_threads.md``
unless ``--no-write`` is given.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

from benchmarks import ROOT, run_lines

RESULTS = Path(__file__).resolve().parent / "results" / "blas_threads.md"
#: The two ways a session runs (the environment variable set, or None: none set).
SETTINGS = (("one BLAS thread a solve (no variable set)", None),
            ("one BLAS thread per core (OPENBLAS_NUM_THREADS set)", str(os.cpu_count() or 1)))


def child(names: list[str]) -> None:
    """In the measured process: one JSON line per preset and kind of change."""
    from benchmarks.scene_overhead import _variants
    from core.presets import read_preset
    from core.scene import solve

    for name in names:
        scene = read_preset(name)
        solve(scene)  # imports and the first build: not measured
        for kind in ("new geometry", "loads only"):
            wall, cpu = [], []
            for variant in _variants(scene, kind):
                started, started_cpu = time.perf_counter(), time.process_time()
                solve(variant)
                wall.append(time.perf_counter() - started)
                cpu.append(time.process_time() - started_cpu)
            print(json.dumps({"preset": name, "kind": kind,
                              "wall": 1e3 * statistics.median(wall),
                              "cpu": 1e3 * statistics.median(cpu)}), flush=True)


def run_setting(names: list[str], threads: str | None) -> list[dict]:
    from core.work import BLAS_THREAD_VARIABLES

    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    if threads is not None:
        env["OPENBLAS_NUM_THREADS"] = threads
    out = subprocess.run([sys.executable, "-m", "benchmarks.blas_threads", "--child", *names],
                         cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    return [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]


def main(argv: list[str]) -> None:
    from core.presets import preset_names
    from core.work import BLAS_THREAD_VARIABLES

    names = [a for a in argv if not a.startswith("--")] or list(preset_names())
    set_here = [name for name in BLAS_THREAD_VARIABLES if os.environ.get(name)]
    if set_here:
        # harmless (each process gets its own), but say what the table compares
        print(f"note: {', '.join(set_here)} set here; the measured processes run without it")
    started = datetime.now(timezone.utc)
    load_before = os.getloadavg()[0]
    lines = ["| preset | change | wall, one thread [ms] | wall, per core [ms] | ratio | "
             "CPU, one thread [ms] | CPU, per core [ms] | ratio |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for name in names:
        one, per_core = (run_setting([name], threads) for _, threads in SETTINGS)
        for a, b in zip(one, per_core, strict=True):
            lines.append(f"| {name} | {a['kind']} | {a['wall']:.2f} | {b['wall']:.2f} | "
                         f"{b['wall'] / a['wall']:.2f} | {a['cpu']:.2f} | {b['cpu']:.2f} | "
                         f"{b['cpu'] / a['cpu']:.2f} |")
            print(lines[-1], flush=True)
    load_after = os.getloadavg()[0]
    text = "\n".join([
        "# One BLAS thread a solve, against one per core", "",
        "    python -m benchmarks.blas_threads", "",
        *run_lines(started, load_before, load_after,
                   "the two settings run one after the other per preset"),
        f"- {os.cpu_count()} cores; medians of 8 solves per preset and kind in a fresh "
        "process for each setting (after a first solve); \"new geometry\": the punch "
        "half-width 0.01 % wider each solve; \"loads only\": the first given load 0.1 % "
        "larger; ratio: per core / one thread", "",
        *lines, ""])
    if "--no-write" not in argv:
        RESULTS.write_text(text)
        print(f"written: {RESULTS}")


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    if sys.argv[1:2] == ["--child"]:
        child(sys.argv[2:])
    else:
        main(sys.argv[1:])
