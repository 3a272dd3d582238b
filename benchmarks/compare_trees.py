"""A scene solve's CPU time in this tree against another tree (a commit checked out
elsewhere), the two measured in turn.

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.compare_trees OTHER_TREE [PRESET ...]
        [--kind loads|geometry] [--rounds 12] [--seconds 0.5] [--no-write]

On a shared machine the CPU time of one solve moves by tens of per cent from one minute
to the next, more than a change of a few per cent makes: :mod:`benchmarks.scene_overhead`
run once per tree cannot tell them apart. Here one worker process per tree (each
importing ``core`` from its own tree) solves a preset's scene for ``--seconds`` of CPU
time per round (at least once), and the rounds alternate between the two (``--rounds``,
the order swapped every round), so both see the same machine. The kinds of change are those of
``scene_overhead``: ``loads`` (the first given load larger at each solve) or
``geometry`` (the punch, or the last of several, a little wider or moved). Reported per
preset: the median over rounds of each tree's median CPU time per solve [ms], and the
median and range of the per-round ratios (this tree / the other). The table (both
commits, the date, the load) is written to ``benchmarks/results/compare_trees.md``
unless ``--no-write`` is given.

The other tree must be a whole checkout (``git worktree add /tmp/old COMMIT``): a module
it lacks would be imported from the installed package instead.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
from datetime import datetime, timezone
from pathlib import Path

from benchmarks import ROOT, run_lines, tree_commit

#: Where :func:`main` writes its table.
RESULTS = Path(__file__).resolve().parent / "results" / "compare_trees.md"

#: The worker, run with ``python -c`` so that it imports ``core`` from its own tree (an
#: older tree need not have this module): argv tree, preset, kind and the path of this
#: tree's :mod:`benchmarks.scene_changes`; it reads a CPU time budget [s] per line,
#: solves until it is spent (at least once) and answers the median CPU time per solve
#: [ms].
WORKER = r"""
import importlib.util, statistics, sys, time
tree, preset, kind, changes = sys.argv[1:5]
sys.path.insert(0, tree)
spec = importlib.util.spec_from_file_location("scene_changes", changes)
scene_changes = importlib.util.module_from_spec(spec)
spec.loader.exec_module(scene_changes)
from core.presets import read_preset
from core.scene import solve

scene = read_preset(preset)
solve(scene)  # imports and the first build: not measured
i = 0
for line in sys.stdin:
    cpu = []
    while not cpu or sum(cpu) < float(line):
        i += 1
        # steps 100 times smaller than scene_overhead's: many more solves, each still new
        new = scene_changes.changed_scene(scene, kind, i, 1e-5 if kind == "loads" else 1e-6)
        started = time.process_time()
        solve(new)
        cpu.append(time.process_time() - started)
    print(1e3 * statistics.median(cpu), flush=True)
"""


def compare(other: Path, preset: str, kind: str, rounds: int, seconds: float
            ) -> tuple[float, float, list[float]]:
    """(this tree's ms, the other's ms, per-round ratios this / other) for one preset.

    Raises RuntimeError naming the tree whose worker ended (a preset it does not have,
    an error of its solve: its message is on standard error)."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS=os.environ.get("OPENBLAS_NUM_THREADS", "1"))
    changes = str(Path(__file__).resolve().parent / "scene_changes.py")
    workers: dict[str, subprocess.Popen] = {}
    times: dict[str, list[float]] = {"this": [], "other": []}
    try:
        for name, tree in (("this", ROOT), ("other", other)):
            workers[name] = subprocess.Popen(
                [sys.executable, "-c", WORKER, str(tree), preset, kind, changes],
                stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env,
                cwd=str(tree))
        for r in range(rounds):
            for name in (("this", "other") if r % 2 == 0 else ("other", "this")):
                worker = workers[name]
                try:
                    worker.stdin.write(f"{seconds}\n")
                    worker.stdin.flush()
                    answer = worker.stdout.readline()
                except OSError:  # its pipe closed: it ended
                    answer = ""
                if not answer:
                    raise RuntimeError(f"the worker of the {name} tree ended (preset "
                                       f"{preset}); its error is above")
                times[name].append(float(answer))
    finally:
        for worker in workers.values():
            try:
                worker.stdin.close()
            except OSError:
                pass
            try:
                worker.wait(timeout=60)
            except subprocess.TimeoutExpired:
                worker.kill()
                worker.wait()
    ratios = [a / b for a, b in zip(times["this"], times["other"], strict=True)]
    return statistics.median(times["this"]), statistics.median(times["other"]), ratios


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("other", type=Path, help="the other tree (a checkout of a commit)")
    parser.add_argument("presets", nargs="*", help="preset names (default: all)")
    parser.add_argument("--kind", choices=("loads", "geometry"), default="loads")
    parser.add_argument("--rounds", type=int, default=12)
    parser.add_argument("--seconds", type=float, default=0.5,
                        help="CPU time of each tree's solves per round [s]")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    if not (args.other / "core" / "__init__.py").is_file():
        parser.error(f"other: {args.other} holds no core package (a checkout of the "
                     "repository is needed)")
    if args.rounds < 1:
        parser.error("--rounds: must be at least 1")
    if not 0.0 < args.seconds <= 600.0:
        parser.error("--seconds: must be > 0 and at most 600")
    return args


def main(argv: list[str] | None = None) -> None:
    from core.presets import preset_names

    args = parse_args(argv)
    names = args.presets or list(preset_names())
    unknown = sorted(set(names) - set(preset_names()))
    if unknown:
        raise SystemExit(f"presets: unknown {', '.join(unknown)}")
    started = datetime.now(timezone.utc)
    load_before = os.getloadavg()[0]
    lines = ["| preset | this tree [ms] | other tree [ms] | ratio (median) | ratio (range) |",
             "| --- | --- | --- | --- | --- |"]
    for name in names:
        try:
            mine, theirs, ratios = compare(args.other.resolve(), name, args.kind,
                                           args.rounds, args.seconds)
        except RuntimeError as exc:
            raise SystemExit(str(exc)) from None
        lines.append(f"| {name} | {mine:.2f} | {theirs:.2f} | {statistics.median(ratios):.3f} "
                     f"| {min(ratios):.2f}-{max(ratios):.2f} |")
        print(lines[-1], flush=True)
    load_after = os.getloadavg()[0]
    text = "\n".join([
        "# A scene solve's CPU time against another tree", "",
        f"    OPENBLAS_NUM_THREADS=1 python -m benchmarks.compare_trees OTHER "
        f"--kind {args.kind} --rounds {args.rounds} --seconds {args.seconds:g}", "",
        *run_lines(started, load_before, load_after,
                   "both trees measured in turn, so both see the same load"),
        f"- the other tree: commit {tree_commit(args.other)}",
        f"- change: {args.kind}; per round {args.seconds:g} s of CPU of solves per tree "
        "(at least one; their median), "
        f"{args.rounds} rounds alternating; the medians over rounds and the per-round "
        "ratios this / other", "", *lines, ""])
    if not args.no_write:
        RESULTS.write_text(text)
        print(f"written: {RESULTS}")


if __name__ == "__main__":
    main()
