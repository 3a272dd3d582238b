"""How long the command line takes from a cold process to its answer.

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.cold_start [--runs N] [--out DIR]

Runs each command below ``N`` times (default 10) in a new Python process, the commands
interleaved (so a change of the machine's load touches them alike), and prints the median
and least wall time [s] and the median user CPU time [s] of the child, with the machine's
load average at the start and the end: on a shared machine wall times grow with the load,
user CPU much less. Writes the table to ``benchmarks/results/cold_start.md`` (or
``DIR/cold_start.md``) with the commit and the UTC date.

The commands: ``python -m core solve preset:worn_coating -o OUT.json`` (elastic, thin
coating), ``solve preset:uniform_flat`` (aging creep), ``validate preset:uniform_flat``
and ``--version``; and the floor under them: ``python -c pass`` (the interpreter and its
site packages) and ``python -c "import numpy, scipy.linalg"`` (what every solve needs).

Bytecode: the children run as an installed package does, from cached bytecode (a private
``PYTHONPYCACHEPREFIX``, filled by one unmeasured run of each command), even where
``PYTHONDONTWRITEBYTECODE`` is set; ``--source`` measures them compiling every module
from source instead.
"""

from __future__ import annotations

import argparse
import datetime
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from benchmarks import tree_commit

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
#: Cold runs of each command (medians and minima are reported).
RUNS = 10
#: The goal for a command of the command line on a quiet 2-core machine [s].
GOAL_SECONDS = 0.6


def commands(out_dir: Path) -> list[tuple[str, list[str]]]:
    """``(label, argv after python)`` of every measured command."""
    return [
        ("`solve preset:worn_coating -o x.json` (elastic)",
         ["-m", "core", "solve", "preset:worn_coating", "-o", str(out_dir / "worn.json")]),
        ("`solve preset:uniform_flat -o x.json` (creep)",
         ["-m", "core", "solve", "preset:uniform_flat", "-o", str(out_dir / "flat.json")]),
        ("`validate preset:uniform_flat`", ["-m", "core", "validate", "preset:uniform_flat"]),
        ("`--version`", ["-m", "core", "--version"]),
        ("floor: `python -c pass`", ["-c", "pass"]),
        ("floor: `import numpy, scipy.linalg`", ["-c", "import numpy, scipy.linalg"]),
    ]


def child_env(pycache: Path | None) -> dict[str, str]:
    """The children's environment: this tree first, one BLAS thread, bytecode cached in
    ``pycache`` (None: compiled from source at every run)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT)
    env["OPENBLAS_NUM_THREADS"] = "1"
    if pycache is None:
        env["PYTHONDONTWRITEBYTECODE"] = "1"
        env.pop("PYTHONPYCACHEPREFIX", None)
    else:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(pycache)
    return env


def run_once(argv: Sequence[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and user CPU time [s] of one child process running ``python argv``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    start = time.perf_counter()
    subprocess.run([sys.executable, *argv], env=env, cwd=ROOT, check=True,
                   stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    return wall, resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before


def measure(runs: int, source: bool) -> tuple[list[tuple[str, float, float, float]],
                                              float, float]:
    """``(label, median wall, least wall, median user CPU)`` per command [s], and the load
    average (1 min) at the start and the end."""
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        env = child_env(None if source else work / "pycache")
        todo = commands(work)
        for _, argv in todo:  # the bytecode cache filled, the caches of the OS warm
            run_once(argv, env)
        load_start = os.getloadavg()[0]
        walls: dict[str, list[float]] = {label: [] for label, _ in todo}
        users: dict[str, list[float]] = {label: [] for label, _ in todo}
        for _ in range(runs):
            for label, argv in todo:
                wall, user = run_once(argv, env)
                walls[label].append(wall)
                users[label].append(user)
        load_end = os.getloadavg()[0]
    rows = [(label, statistics.median(walls[label]), min(walls[label]),
             statistics.median(users[label])) for label, _ in todo]
    return rows, load_start, load_end


def report(rows: list[tuple[str, float, float, float]], load: tuple[float, float],
           runs: int, source: bool, command: str) -> str:
    """The Markdown page of one measurement."""
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    bytecode = ("compiling every module from source (`--source`)" if source else
                "from cached bytecode, as an installed package runs")
    lines = ["# The command line from a cold process", "",
             f"Made by `{command}` at commit {tree_commit()}, {date}, on a {os.cpu_count()}-core "
             f"machine; load average (1 min) {load[0]:.2f} at the start, {load[1]:.2f} at "
             f"the end (a shared machine inflates wall times; user CPU much less). "
             f"{runs} runs of each command, interleaved, {bytecode}. The goal: "
             f"<= {GOAL_SECONDS} s wall on a quiet 2-core machine.", "",
             "| command | median wall [s] | least wall [s] | median user CPU [s] |",
             "| --- | --- | --- | --- |"]
    lines += [f"| {label} | {wall:.3f} | {least:.3f} | {user:.3f} |"
              for label, wall, least, user in rows]
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.cold_start",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=RUNS, help="cold runs per command")
    parser.add_argument("--out", type=Path, default=RESULTS, metavar="DIR",
                        help="the folder of cold_start.md")
    parser.add_argument("--source", action="store_true",
                        help="compile every module at every run (no bytecode cache)")
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error(f"--runs: must be at least 1, got {args.runs}")
    if args.out.exists() and not args.out.is_dir():
        parser.error(f"--out: {args.out}: must be a folder")
    rows, load_start, load_end = measure(args.runs, args.source)
    print(f"load average (1 min) {load_start:.2f} at the start, {load_end:.2f} at the end")
    for label, wall, least, user in rows:
        print(f"{label:52s} median {wall:.3f} s  least {least:.3f} s  user {user:.3f} s")
    command = "python -m benchmarks.cold_start" + (" ".join([""] + list(argv or sys.argv[1:])))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "cold_start.md").write_text(
        report(rows, (load_start, load_end), args.runs, args.source, command))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
