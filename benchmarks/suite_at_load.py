"""The README's test command on fresh clones beside a CPU hog: does the suite pass, and in
how long, on a busy 2-core machine?

Each run clones the repository at its current commit into a temporary directory and runs
``.ci/run`` there (the installation included, as CI does), while ``--hogs`` processes
spin beside it. The report gives each run's wall time, its exit code, the one-minute load
average sampled through the run, and the parts' summary lines.

Run from the repository root (it takes ``--runs`` times ~10 minutes)::

    python -m benchmarks.suite_at_load --runs 5 --hogs 1

A failed run's clone and log are kept (the path is printed). Note: ``.ci/run`` installs
the clone in editable mode, which takes over the environment's install of this package;
re-install the working copy afterwards (``python -m pip install --no-deps -e .``).
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from benchmarks import run_lines, tree_commit

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
#: The lines of the suite's output that summarise a part.
SUMMARY = re.compile(r"(\d+ passed|\d+ failed|exit codes|built in)")
#: The suite's bound (the developers' guide: "keep the suite under about 10 minutes").
GOAL_MINUTES = 10.0


def _hog(stop: Any) -> None:
    """Spin until ``stop`` is set (a multiprocessing event)."""
    while not stop.is_set():
        sum(i * i for i in range(10_000))


def _one_run(k: int, hogs: int) -> dict:
    """Run ``k``: a fresh clone's ``.ci/run`` beside ``hogs`` spinners."""
    work = Path(tempfile.mkdtemp(prefix=f"suite-at-load-{k}-"))
    clone = work / "clone"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
    commit = tree_commit(clone)  # the tree may move on between runs
    stop = multiprocessing.Event()
    spinners = [multiprocessing.Process(target=_hog, args=(stop,), daemon=True)
                for _ in range(hogs)]
    for p in spinners:
        p.start()
    loads: list[float] = []
    done = threading.Event()

    def sample() -> None:
        while not done.wait(15.0):
            loads.append(os.getloadavg()[0])

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    start = time.monotonic()
    log = work / "log.txt"
    with log.open("w") as out:
        rc = subprocess.run(["bash", ".ci/run"], cwd=clone, stdout=out,
                            stderr=subprocess.STDOUT).returncode
    wall = time.monotonic() - start
    done.set()
    stop.set()
    for p in spinners:
        p.join(5)
    text = log.read_text(errors="replace")
    lines = [line.strip() for line in text.splitlines() if SUMMARY.search(line)]
    failed = [line for line in text.splitlines() if line.startswith("FAILED")]
    if rc == 0:
        shutil.rmtree(work, ignore_errors=True)
    else:  # kept to be read: the clone and its log
        print(f"run {k + 1} failed: its log is {log}", flush=True)
        for line in failed:
            print(f"  {line}", flush=True)
    return {"commit": commit, "rc": rc, "wall": wall, "loads": loads, "lines": lines,
            "failed": failed}


def report(runs: list[dict], planned: int, hogs: int, started: datetime, load_before: float,
           commit: str) -> str:
    """The Markdown page of the runs so far (of ``planned``)."""
    rows = ["| run | commit | exit code | wall [min] | load (1 min): median, max | parts |",
            "| --- | --- | --- | --- | --- | --- |"]
    for k, r in enumerate(runs, 1):
        loads = sorted(r["loads"]) or [float("nan")]
        parts = "; ".join(r["lines"])
        rows.append(f"| {k} | {r['commit']} | {r['rc']} | {r['wall'] / 60:.1f} | "
                    f"{loads[len(loads) // 2]:.1f}, {loads[-1]:.1f} | {parts} |")
    failures = [f"- run {k}: {line}" for k, r in enumerate(runs, 1) for line in r["failed"]]
    green = sum(r["rc"] == 0 for r in runs)
    longest = max(r["wall"] for r in runs) / 60
    done = "" if len(runs) == planned else f" (of {planned} planned)"
    return "\n".join([
        "# The test suite on fresh clones beside a CPU hog",
        "",
        f"Made by `python -m benchmarks.suite_at_load --runs {planned} --hogs {hogs}`:",
        "",
        *run_lines(started, load_before, os.getloadavg()[0],
                   "the load the suite itself and the hogs make", commit=commit),
        "",
        f"Each run: a fresh clone, `.ci/run` (installation, ruff, import "
        f"contracts, the three pytest parts and the documentation), with {hogs} "
        f"spinning process(es) beside it. Goal: every run green, each under about "
        f"{GOAL_MINUTES:g} minutes.",
        "",
        f"**{green} of {len(runs)} runs{done} green; the longest {longest:.1f} min.**",
        "",
        *rows,
        "",
        *(["Failed tests:", "", *failures, ""] if failures else []),
    ]) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5, help="fresh-clone runs (default 5)")
    parser.add_argument("--hogs", type=int, default=1,
                        help="spinning processes beside each run (default 1)")
    parser.add_argument("--out", type=Path, default=RESULTS, metavar="DIR",
                        help="the folder of suite_at_load.md (default benchmarks/results)")
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error(f"--runs: must be at least 1, got {args.runs}")
    if args.hogs < 0:
        parser.error(f"--hogs: must be at least 0, got {args.hogs}")
    if args.out.exists() and not args.out.is_dir():
        parser.error(f"--out: {args.out}: must be a folder")
    target = args.out / "suite_at_load.md"
    started, load_before, commit = datetime.now(timezone.utc), os.getloadavg()[0], tree_commit()
    runs: list[dict] = []
    for k in range(args.runs):
        runs.append(_one_run(k, args.hogs))
        r = runs[-1]
        print(f"run {k + 1}: exit {r['rc']}, {r['wall'] / 60:.1f} min", flush=True)
        # written after every run: a series cut short still leaves its report
        args.out.mkdir(parents=True, exist_ok=True)
        target.write_text(report(runs, args.runs, args.hogs, started, load_before, commit),
                          encoding="utf-8")
    print(f"wrote {target}")
    green = sum(r["rc"] == 0 for r in runs)
    return 0 if green == len(runs) else 1


if __name__ == "__main__":
    sys.exit(main())
