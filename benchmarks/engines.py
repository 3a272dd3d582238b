"""Speed against error of the two engines, side by side, and the engine goals.

    python benchmarks/engines.py            # all scenes, report in benchmarks/results/
    python benchmarks/engines.py --quick    # three scenes, fewer repeats

For each scene of :mod:`tests.support.scenes`: the default engine (``method="nystrom"``) and
the seed's projection (``method="projection"``), each swept over ``tol``. The error is the
largest of delta, alpha (relative to max(|delta|, |alpha|)), P, M (relative to
max(|P|, |M|)) and q relative to max|q| on 2001 points of the whole of [-1, 1] (both ends,
both sides of every jump), against the default engine at tol 1e-10, which is itself
checked against the projection at tol 1e-10 on the same points (the agreement is in the
report). Times are medians of repeated runs after a warm-up:

* new scene: the whole solve from a fresh start (the engine's prepared geometry and the
  projection's stage caches emptied before each run);
* loads only: the same geometry, another force each run (``PreparedContact.solve`` for the
  default engine, with q at 400 points; the projection with its caches warm).

Then the goals of the engine: creep with 100 and 1000 outputs, 10,000 elastic outputs,
and ``python -m core solve`` of a shipped scene from a cold process. Every time is given
as wall-clock and as CPU time of the process (the machine is shared; run with
``OPENBLAS_NUM_THREADS=1``). A full run takes ~6 minutes on the shared machine (load
average ~13), ``--quick`` about a third of that. Output: ``benchmarks/results/engines.md``,
``engines.json`` and one PNG per scene (``engine_<scene>.png``; needs matplotlib, from the
``[bench]`` extra, else the report is written without them).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import core  # noqa: E402
from benchmarks import run_lines, tree_commit  # noqa: E402
from core.cache import clear_caches  # noqa: E402
from core.solver import solve_dimensionless  # noqa: E402
from tests.support.scenes import Scene, creep_times, suite  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"
TOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
TARGET = 1e-6


def points(scene: Scene) -> np.ndarray:
    x = np.cos(np.linspace(0.0, np.pi, 2001))
    for b in scene.breakpoints:
        x = np.concatenate([x[np.abs(x - b) > 1e-7], [b - 1e-9, b + 1e-9]])
    return np.sort(x)


def error(sol: Any, ref: Any, x: np.ndarray, q_ref: np.ndarray) -> float:
    """Largest relative error of delta, alpha, P, M and of q at the points ``x``."""
    kin = max(np.max(np.abs(ref.settlement)), np.max(np.abs(ref.tilt)), 1e-300)
    dyn = max(np.max(np.abs(ref.force)), np.max(np.abs(ref.moment)), 1e-300)
    parts = [np.max(np.abs(sol.settlement - ref.settlement)) / kin,
             np.max(np.abs(sol.tilt - ref.tilt)) / kin,
             np.max(np.abs(sol.force - ref.force)) / dyn,
             np.max(np.abs(sol.moment - ref.moment)) / dyn,
             np.max(np.abs(sol.pressure(x) - q_ref)) / np.max(np.abs(q_ref))]
    return float(max(parts))


def loads_of(scene: Scene, scale: float = 1.0) -> dict[str, Any]:
    """The time-side arguments of ``PreparedContact.solve`` (loads times ``scale``)."""
    return {k: v for k, v in scene.arguments(scale).items() if k != "breakpoints"}


def fresh() -> None:
    """Forget every cached geometry of both engines."""
    clear_caches()  # the projection's stage caches and the prepared geometries


def median_time(call: Callable[[], Any], repeats: int, before: Callable[[], None] | None
                ) -> tuple[float, Any]:
    """Median wall-clock time [s] of ``call`` and its last result; see :func:`median_times`."""
    wall, _, out = median_times(call, repeats, before)
    return wall, out


def median_times(call: Callable[[], Any], repeats: int, before: Callable[[], None] | None
                 ) -> tuple[float, float, Any]:
    """Median wall-clock and CPU time [s] of ``call`` (this process, numpy's threads
    included) and its last result. The machine is shared: CPU time is what the code
    costs, wall time what a user waits."""
    out = call()  # warm-up (imports, tables)
    times, cpu = [], []
    for _ in range(repeats):
        if before is not None:
            before()
        t0, c0 = time.perf_counter(), time.process_time()
        out = call()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return statistics.median(times), statistics.median(cpu), out


def sweep(scene: Scene, repeats: int) -> dict[str, Any]:
    x = points(scene)
    args = scene.arguments()
    ref = solve_dimensionless(scene.lam, scene.m, scene.g, scene.times, tol=1e-10, **args)
    q_ref = ref.pressure(x)
    interior = np.linspace(-0.95, 0.95, 381)
    for b in scene.breakpoints:
        interior = interior[np.abs(interior - b) > 0.02]
    check = solve_dimensionless(scene.lam, scene.m, scene.g, scene.times, tol=1e-10,
                                method="projection", **args)
    agreement = float(np.max(np.abs(check.pressure(x) - q_ref)) / np.max(np.abs(q_ref)))
    q_interior = ref.pressure(interior)
    runs = []
    for method in ("nystrom", "projection"):
        for tol in TOLS:
            def call(tol=tol, method=method):
                return solve_dimensionless(scene.lam, scene.m, scene.g, scene.times, tol=tol,
                                           method=method, **args)
            cold, cold_cpu, sol = median_times(call, repeats, fresh)
            warm_scale = iter(np.linspace(1.01, 1.5, 1000))
            if method == "nystrom":
                prep = core.prepare(scene.lam, scene.m, scene.g,
                                    breakpoints=scene.breakpoints, tol=tol)
                xs400 = np.linspace(-1.0, 1.0, 400)

                def warm_call(prep=prep, xs400=xs400, warm_scale=warm_scale):
                    s = next(warm_scale)
                    out = prep.solve(scene.times, **loads_of(scene, s))
                    out.pressure(xs400)
                    return out
            else:
                def warm_call(tol=tol, warm_scale=warm_scale):
                    s = next(warm_scale)
                    return solve_dimensionless(scene.lam, scene.m, scene.g, scene.times,
                                               tol=tol, method="projection",
                                               **scene.arguments(s))
            warm, warm_cpu, _ = median_times(warm_call, repeats, None)
            runs.append({"method": method, "tol": tol, "cold_s": cold, "warm_s": warm,
                         "cold_cpu_s": cold_cpu, "warm_cpu_s": warm_cpu,
                         "error": error(sol, ref, x, q_ref),
                         "interior_error": error(sol, ref, interior, q_interior),
                         "estimate": float(sol.info["error_estimate"]),
                         "success": bool(sol.info["success"]),
                         "size": int(sol.info.get("n_nodes", sol.info.get("n_modes", 0)))})
            print(f"  {scene.key:18s} {method:10s} tol {tol:.0e}: error {runs[-1]['error']:.1e}"
                  f" est {runs[-1]['estimate']:.1e} new {cold * 1e3:8.2f} ms"
                  f" (cpu {cold_cpu * 1e3:7.2f})"
                  f" loads-only {warm * 1e3:7.3f} ms", flush=True)
    return {"key": scene.key, "title": scene.title, "runs": runs, "agreement": agreement}


def cheapest(runs: list[dict], method: str, which: str, target: float = TARGET
             ) -> dict | None:
    ok = [r for r in runs if r["method"] == method and r["error"] <= target]
    return min(ok, key=lambda r: r[which]) if ok else None


def goals(repeats: int) -> dict[str, float]:
    """The engine goals that are not in the scene sweep: wall and CPU times (ms, s)."""
    out: dict[str, float] = {}
    aging = next(s for s in suite() if s.key == "aging_creep")
    for count in (100, 1000):
        scene = aging.with_times(creep_times(1000.0, count))
        args = scene.arguments()
        cold, cold_cpu, _ = median_times(lambda scene=scene, args=args: solve_dimensionless(
            scene.lam, scene.m, scene.g, scene.times, tol=1e-6, **args), repeats, fresh)
        out[f"creep_{count}_new_ms"] = cold * 1e3
        out[f"creep_{count}_new_cpu_ms"] = cold_cpu * 1e3
        prep = core.prepare(scene.lam, scene.m, scene.g, tol=1e-6)
        scales = iter(np.linspace(1.01, 1.5, 1000))
        warm, warm_cpu, _ = median_times(
            lambda prep=prep, scene=scene, scales=scales: prep.solve(
                scene.times, **loads_of(scene, next(scales))), repeats, None)
        out[f"creep_{count}_loads_ms"] = warm * 1e3
        out[f"creep_{count}_loads_cpu_ms"] = warm_cpu * 1e3
    smooth = suite()[0]
    prep = core.prepare(smooth.lam, smooth.m, smooth.g, tol=1e-6)
    many = np.linspace(1.0, 100.0, 10_000)
    warm, warm_cpu, _ = median_times(
        lambda: prep.solve(many, force=lambda t: 1 + 0.5 * np.sin(t), moment=0.1), repeats,
        None)
    out["elastic_10000_times_ms"] = warm * 1e3
    out["elastic_10000_times_cpu_ms"] = warm_cpu * 1e3
    cold_cli, cold_cli_cpu = [], []
    scene_file = ROOT / "core" / "presets" / "scenes" / "uniform_flat.json"
    for _ in range(max(3, repeats // 2)):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "core", "solve", str(scene_file)], cwd=ROOT,
                       check=True, capture_output=True,
                       env={**os.environ, "OPENBLAS_NUM_THREADS": "1"})
        cold_cli.append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cold_cli_cpu.append(after.ru_utime + after.ru_stime - before.ru_utime
                            - before.ru_stime)
    out["cli_cold_s"] = statistics.median(cold_cli)
    out["cli_cold_cpu_s"] = statistics.median(cold_cli_cpu)
    return out


def plot(result: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for method, style in (("nystrom", "o-"), ("projection", "s--")):
        runs = [r for r in result["runs"] if r["method"] == method]
        err = [max(r["error"], 1e-16) for r in runs]
        ax.loglog(err, [r["cold_s"] * 1e3 for r in runs], style, label=f"{method}, new scene")
        ax.loglog(err, [r["warm_s"] * 1e3 for r in runs], style, alpha=0.45,
                  label=f"{method}, loads only")
    ax.set_xlabel("error (max of delta, alpha, P, M, q on [-1, 1]), relative")
    ax.set_ylabel("time [ms], median")
    ax.set_title(result["title"])
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def ms(run: dict | None, key: str) -> str:
    return "not reached" if run is None else f"{run[key] * 1e3:.3g}"


def goal_rows(results: list[dict], goal: dict[str, float]
              ) -> list[tuple[str, float, float, float, str]]:
    """(goal, wall, CPU, limit, unit) of every engine goal measured in this run.

    A new elastic scene is timed at ``tol = TARGET`` (what a user asks for), over the scenes
    where that run's measured error meets it.
    """
    at_target = [run for r in results for run in r["runs"]
                 if run["method"] == "nystrom" and run["tol"] == TARGET
                 and run["error"] <= TARGET]
    rows = []
    if at_target:
        wall = [run["cold_s"] * 1e3 for run in at_target]
        cpu = [run["cold_cpu_s"] * 1e3 for run in at_target]
        rows += [(f"new elastic scene at tol 1e-6, median of {len(wall)} scenes",
                  statistics.median(wall), statistics.median(cpu), 5.0, "ms"),
                 ("new elastic scene at tol 1e-6, the hardest", max(wall), max(cpu), 20.0,
                  "ms"),
                 ("loads only, q at 400 points, median of the scenes",
                  statistics.median(run["warm_s"] * 1e3 for run in at_target),
                  statistics.median(run["warm_cpu_s"] * 1e3 for run in at_target), 0.2, "ms"),
                 ("loads only, q at 400 points, the slowest scene",
                  max(run["warm_s"] * 1e3 for run in at_target),
                  max(run["warm_cpu_s"] * 1e3 for run in at_target), 0.2, "ms")]
    for key, name, limit in (("creep_100_new", "aging creep, 100 outputs, new scene", 20.0),
                             ("creep_100_loads", "aging creep, 100 outputs, loads only", 2.0),
                             ("creep_1000_new", "aging creep, 1000 outputs, new scene", 50.0),
                             ("elastic_10000_times", "elastic, 10,000 output times", 20.0)):
        if f"{key}_ms" in goal:
            rows.append((name, goal[f"{key}_ms"], goal[f"{key}_cpu_ms"], limit, "ms"))
    if "cli_cold_s" in goal:
        rows.append(("`python -m core solve` of a shipped scene, cold process",
                     goal["cli_cold_s"], goal["cli_cold_cpu_s"], 1.0, "s"))
    return rows


#: The report's note when the figures could not be drawn.
FIGURES_MISSING = ("Figures: not drawn in this run (matplotlib, from the `[bench]` extra, was "
                   "missing); the PNGs next to this report are from an earlier run of the "
                   "previous version.")


def report(results: list[dict], goal: dict[str, float], command: str, out: Path,
           figures: bool = True, run: list[str] | None = None) -> None:
    """Write ``engines.md`` to ``out``; ``run``: :func:`benchmarks.run_lines` of the run
    (the commit, the date, the machine and its load)."""
    lines = ["# The two engines: speed against error", "",
             f"Made by `{command}` (absolute times grow with the machine's load and vary "
             "between runs; ratios between the engines measured in the same run are the "
             "meaningful part).", "", *(run or []), "",
             "Error: the largest of delta, alpha, P, M and q on the whole of [-1, 1] "
             "(edges and both sides of jumps included) against the default engine at tol "
             "1e-10; 'reference check' is that reference against the projection at tol "
             "1e-10 on the same points.", "",
             *([] if figures else [FIGURES_MISSING, ""]),
             "## Cheapest setting with error <= 1e-6", "",
             "| scene | Nystrom, new scene [ms] (CPU) | Nystrom, loads only [ms] (CPU) | "
             "projection, new scene [ms] | projection, loads only [ms] | speed-up, new scene "
             "| reference check |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in results:
        n_c, n_w = cheapest(r["runs"], "nystrom", "cold_s"), cheapest(r["runs"], "nystrom",
                                                                       "warm_s")
        p_c, p_w = cheapest(r["runs"], "projection", "cold_s"), cheapest(
            r["runs"], "projection", "warm_s")

        speed = (f"{p_c['cold_s'] / n_c['cold_s']:.1f}x" if n_c and p_c else "-")
        lines.append(f"| {r['title']} | {ms(n_c, 'cold_s')} ({ms(n_c, 'cold_cpu_s')}) | "
                     f"{ms(n_w, 'warm_s')} ({ms(n_w, 'warm_cpu_s')}) | "
                     f"{ms(p_c, 'cold_s')} | {ms(p_w, 'warm_s')} | {speed} | "
                     f"{r['agreement']:.1e} |")
    lines += ["", "## Successes off by more than tol", "",
              "Runs that claim success while their error (the largest of delta, alpha, P, M "
              "and q on the whole of [-1, 1]) exceeds their tol.", "",
              "| method | runs | successes | off by more than tol |", "| --- | --- | --- | --- |"]
    for method in ("nystrom", "projection"):
        runs = [run for r in results for run in r["runs"] if run["method"] == method]
        won = [run for run in runs if run["success"]]
        off = [run for run in won if run["error"] > run["tol"]]
        lines.append(f"| {method} | {len(runs)} | {len(won)} | {len(off)} |")
    lines += ["", "## Goals of the engine", "",
              "Medians of the runs; 'met' is judged on wall-clock and on CPU time separately "
              "(the machine was shared: CPU time is what the code costs).", "",
              "| goal | wall | CPU | met (wall / CPU) |", "| --- | --- | --- | --- |"]
    for name, wall, cpu, limit, unit in goal_rows(results, goal):
        verdict = " / ".join("met" if v <= limit else "missed" for v in (wall, cpu))
        lines.append(f"| {name} | {wall:.3g} {unit} | {cpu:.3g} {unit} | {verdict} |")
    lines += ["", "## Every run", ""]
    for r in results:
        lines += [f"### {r['title']}", "", f"![{r['key']}](engine_{r['key']}.png)", "",
                  "| method | tol | error | interior error | estimate | success | size | "
                  "new [ms] | new, CPU [ms] | loads only [ms] |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for run in r["runs"]:
            lines.append(f"| {run['method']} | {run['tol']:.0e} | {run['error']:.1e} | "
                         f"{run['interior_error']:.1e} | "
                         f"{run['estimate']:.1e} | {run['success']} | {run['size']} | "
                         f"{run['cold_s'] * 1e3:.3g} | {run['cold_cpu_s'] * 1e3:.3g} | "
                         f"{run['warm_s'] * 1e3:.3g} |")
        lines.append("")
    (out / "engines.md").write_text("\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="three scenes, fewer repeats")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--scenes", nargs="*", default=None)
    parser.add_argument("--out", type=Path, default=RESULTS, metavar="DIR",
                        help="folder of the report (engines.md, engines.json and the "
                             "figures; default benchmarks/results)")
    args = parser.parse_args(argv)
    if args.out.suffix or (args.out.exists() and not args.out.is_dir()):
        parser.error(f"--out: {args.out} names a file; give the folder the report's files "
                     "go to (engines.md, engines.json, the figures)")
    scenes = [s for s in suite() if not s.creeping]
    if args.scenes:
        scenes = [s for s in scenes if s.key in args.scenes]
    elif args.quick:
        scenes = scenes[:3]
    repeats = 3 if args.quick else args.repeats
    started, commit, load_before = datetime.now(timezone.utc), tree_commit(), os.getloadavg()[0]
    args.out.mkdir(parents=True, exist_ok=True)
    results = []
    figures = True
    for scene in scenes:
        print(scene.key, flush=True)
        results.append(sweep(scene, repeats))
        try:
            plot(results[-1], args.out / f"engine_{scene.key}.png")
        except ModuleNotFoundError as exc:  # matplotlib comes with the [bench] extra
            print(f"  no figure: {exc}", flush=True)
            figures = False
    goal = goals(repeats)
    command = "python benchmarks/engines.py" + (" --quick" if args.quick else "")
    report(results, goal, command, args.out, figures,
           run_lines(started, load_before, os.getloadavg()[0], commit=commit))
    (args.out / "engines.json").write_text(json.dumps({"scenes": results, "goals": goal},
                                                      indent=1))
    print(json.dumps(goal, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
