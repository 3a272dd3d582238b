"""Design studies on Dask: throughput, speed-up with workers, and a design chart.

    python -m benchmarks.sweep              # the report (about 10 minutes on 2 cores)
    python -m benchmarks.sweep --quick      # smaller studies, one repeat (about 2 minutes)
    python -m benchmarks.sweep --chart-only # only the design chart
    python -m benchmarks.sweep --no-chart   # only the measurements (no matplotlib needed)
    python -m benchmarks.sweep --point-costs  # where the loads study's CPU goes (no Dask)
    python -m benchmarks.sweep --memory 100000 1000000  # peak memory, batches on disk
    python -m benchmarks.sweep --loads-runs --repeats 3  # the loads study on 2 / 1 workers

Measured (``core.sweep`` on a local Dask cluster of single-threaded worker processes on
127.0.0.1, a fresh cluster for every run so that no worker starts with the study's caches;
the cluster's start, its workers' warming included, is timed separately):

* 10,000 elastic points over two loads (force x moment, 100 x 100, one output time):
  goal <= 10 s on 2 workers;
* 1,000 points over the coating modulus (a new geometry per point): goal <= 30 s;
* the same two studies on 1 worker (speed-up 1 vs 2 workers), and a serial loop in this
  process on a tenth of the points (the cost of a point without Dask);
* the design chart of ``core/presets/studies/eccentric_design.json`` (settlement and tilt 50
  years after loading over the eccentricity and the coating modulus, the region where the
  heel has lifted off hatched, points short of their tolerance marked).

Output: ``benchmarks/results/sweep.md`` and ``benchmarks/results/sweep_design_chart.png``
(``--quick``: ``benchmarks/results/quick/``, not kept in the repository).
"""

from __future__ import annotations

import argparse
import contextlib
import faulthandler
import json
import os
import platform
import signal
import statistics
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from core.study import Study, study_from_dict, sweep  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"
DESIGN_STUDY = ROOT / "core" / "presets" / "studies" / "eccentric_design.json"
GOALS = {"loads": 10.0, "modulus": 30.0}


def elastic_scene() -> dict[str, Any]:
    """The uniform-coating preset on an elastic base, one output time (a year)."""
    scene = json.loads((ROOT / "core" / "presets" / "scenes" / "uniform_flat.json").read_text())
    scene["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    scene["times"] = [365.0]
    return scene


def loads_study(n_side: int) -> Study:
    """``n_side``^2 points over force [N/m] and moment [N]."""
    return study_from_dict({
        "study_version": 1, "name": "loads", "scene": elastic_scene(),
        "vary": [{"field": "loading.force", "linspace": {"start": 1e5, "stop": 1e6,
                                                         "count": n_side}},
                 {"field": "loading.moment", "linspace": {"start": 0.0, "stop": 2e5,
                                                          "count": n_side}}]})


def modulus_study(n: int) -> Study:
    """``n`` points over the coating modulus [Pa], 50 MPa to 20 GPa."""
    return study_from_dict({
        "study_version": 1, "name": "modulus", "scene": elastic_scene(),
        "vary": [{"field": "coating[0].modulus", "logspace": {"start": 5e7, "stop": 2e10,
                                                              "count": n}}]})


def on_fresh_cluster(study: Study, workers: int, warm: bool = True) -> dict[str, float]:
    """Run ``study`` on a new local cluster of ``workers`` processes started as
    :func:`core.sweep` starts its own (:func:`core.study.start_local_cluster`, the
    workers warmed unless ``warm`` is false: that is counted in the start); seconds of the
    start and of the study, the workers' CPU in the study and in the warming [s], and the
    points that failed."""
    from core.study.warm import start_local_cluster

    start = time.perf_counter()
    client, close = start_local_cluster(workers, warm=warm)
    started = time.perf_counter() - start
    try:
        warm_cpu = sum(client.run(
            lambda dask_worker: getattr(dask_worker, "coated_punch_warm_cpu", 0.0)).values())
        cpu_before = client.run(time.process_time)
        start = time.perf_counter()
        info = sweep(study, client=client, return_dataset=False)
        seconds = time.perf_counter() - start
        # the workers' own CPU time: on a shared machine the wall time also counts the
        # time other people's processes held the cores
        cpu_after = client.run(time.process_time)
        cpu = sum(cpu_after[w] - cpu_before.get(w, 0.0) for w in cpu_after)
    finally:
        close()
    return {"start": started, "seconds": seconds, "cpu": cpu, "warm_cpu": warm_cpu,
            "load": os.getloadavg()[0], "failed": info["points_failed"],
            "flagged": info["points_flagged"], "batches": info["batches"]}


def serial_seconds_per_point(study: Study, points: int) -> float:
    """Seconds per point of a serial loop in this process over the first ``points``
    points of a grid study (the same batching, no Dask)."""
    from dataclasses import replace

    first = study.parameters[0]
    per_value = study.n_points // len(first.values)
    keep = max(1, points // per_value)
    cut = replace(study, parameters=(replace(first, values=first.values[:keep]),)
                  + study.parameters[1:])
    start = time.perf_counter()
    sweep(cut, client="serial", return_dataset=False)
    return (time.perf_counter() - start) / cut.n_points


def serial_cpu_per_point(study: Study, points: int) -> tuple[float, float]:
    """Wall and CPU seconds per point of :func:`serial_seconds_per_point`'s loop."""
    cpu = time.process_time()
    wall = serial_seconds_per_point(study, points)
    return wall, (time.process_time() - cpu) / max(1, _cut_points(study, points))


def _cut_points(study: Study, points: int) -> int:
    first = study.parameters[0]
    per_value = study.n_points // len(first.values)
    return max(1, points // per_value) * per_value


def point_costs(study: Study, batch: int | None = None) -> dict[str, dict[str, float]]:
    """Where a load-only study's CPU time goes, in this process with no Dask, batch by
    batch as :func:`core.study.sweep` plans them (``batch`` points each, default as the
    study's default): the points :func:`core.study.solve_load_batch` answers at
    once (``batched``), and the whole of :func:`core.study.run_batch`
    (``run_batch``: the batched points again, the lift-off families of
    :mod:`core.study.liftoff`, the scaled points and the one-point solves, counted in
    ``one-point solves``). CPU seconds [s] from ``time.process_time``."""
    import core.study.batch as batch_module
    from core.study.batch import _load_only_base, run_batch
    from core.study.loads import solve_load_batch
    from core.study.plan import BatchPlan
    from core.study.points import StudyPoints
    from core.study.run import default_batch_points

    paths = [p.path for p in study.parameters]
    loads = [path.split(".", 1)[1] for path in paths]
    points = StudyPoints(study)
    scene = _load_only_base(study.base, paths)
    if scene is None:
        raise ValueError("study: point_costs needs a study over given loads only")
    plan = BatchPlan(study, batch or default_batch_points(study.n_points), points)
    batches = (plan.batch(k) for k in range(plan.n_batches))
    batched, batched_cpu, run_cpu, failed, flagged = 0, 0.0, 0.0, 0, 0
    solves: list[float] = []
    one_point = batch_module.solve

    def counted(point_scene):
        cpu = time.process_time()
        try:
            return one_point(point_scene)
        finally:
            solves.append(time.process_time() - cpu)

    batch_module.solve = counted
    try:
        for index in batches:
            point = points(index)
            values = np.stack([point[p] for p in paths], axis=1)
            cpu = time.process_time()
            answer = solve_load_batch(scene, {q: values[:, j] for j, q in enumerate(loads)},
                                      study.outputs)
            batched_cpu += time.process_time() - cpu
            batched += int(answer.answered.sum())
            cpu = time.process_time()
            got = run_batch(study.base, paths, values, study.outputs, len(study.times))
            run_cpu += time.process_time() - cpu
            failed += int(np.sum(got["flags"] == "failed"))
            flagged += int(np.sum((got["flags"] != "") & (got["flags"] != "failed")))
    finally:
        batch_module.solve = one_point
    return {"batched": {"points": batched, "cpu": batched_cpu},
            "run_batch": {"points": study.n_points, "batches": len(batches), "cpu": run_cpu,
                          "failed": failed, "flagged": flagged},
            "one-point solves": {"count": len(solves), "cpu": float(np.sum(solves)),
                                 "median": float(np.median(solves)) if solves else 0.0}}


def full_contact_study(n_force: int, n_moment: int) -> Study:
    """``n_force`` x ``n_moment`` points over force [N/m] and moment [N] that all keep full
    contact (eccentricity at most 0.2 m on the 2 m punch): the cheapest points, so the
    study's size, not its solves, is what a large one measures."""
    return study_from_dict({
        "study_version": 1, "name": "full contact loads", "scene": elastic_scene(),
        "vary": [{"field": "loading.force", "linspace": {"start": 1e5, "stop": 1e6,
                                                         "count": n_force}},
                 {"field": "loading.moment", "linspace": {"start": 0.0, "stop": 2e4,
                                                          "count": n_moment}}]})


def _peak_rss_mb() -> float:
    """Peak resident memory of this process [MB] (Linux reports kB)."""
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


@contextlib.contextmanager
def separate_cluster(workers: int) -> Iterator[str]:
    """A ``dask scheduler`` and ``workers`` single-threaded ``dask worker`` processes on
    127.0.0.1, each its own program (so that the client's, the scheduler's and each
    worker's memory are measured apart); yields the scheduler's address."""
    import tempfile

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    with tempfile.TemporaryDirectory(prefix="study-cluster-") as where:
        file = Path(where) / "scheduler.json"
        common = ["--scheduler-file", str(file), "--no-dashboard"]
        procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler",
                                   "--host", "127.0.0.1", "--port", "0", *common],
                                  cwd=where, env=env, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL)]
        try:
            deadline = time.monotonic() + 120
            while not file.exists() and time.monotonic() < deadline:
                time.sleep(0.1)
            procs += [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker",
                                        "--no-nanny", "--nthreads", "1", "--host",
                                        "127.0.0.1", *common], cwd=where, env=env,
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                      for _ in range(workers)]
            yield json.loads(file.read_text())["address"]
        finally:
            for proc in reversed(procs):
                proc.terminate()
            for proc in procs:
                try:
                    proc.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait(timeout=30)


def memory_of_study(study: Study, workers: int, work_dir: Path) -> dict[str, float]:
    """Run ``study`` on a fresh cluster of separate processes (:func:`separate_cluster`)
    with its batches streamed to ``work_dir`` (no dataset assembled:
    ``return_dataset=False``); the peak resident memory [MB] of this process (the client
    alone), of the scheduler and of the larger worker, the seconds, the workers' CPU [s]
    and the size of the written parts [MB]."""
    from distributed import Client

    with separate_cluster(workers) as address, Client(address, timeout=120) as client:
        client.wait_for_workers(workers, timeout=120)
        before = _peak_rss_mb()
        scheduler_before = client.run_on_scheduler(_peak_rss_mb)
        worker_before = client.run(_peak_rss_mb)
        cpu_before = client.run(time.process_time)
        start = time.perf_counter()
        info = sweep(study, client=client, work_dir=work_dir, return_dataset=False)
        seconds = time.perf_counter() - start
        cpu = sum(t - cpu_before.get(w, 0.0) for w, t in client.run(time.process_time).items())
        workers_peak = client.run(_peak_rss_mb)
        scheduler_peak = client.run_on_scheduler(_peak_rss_mb)
        client_peak = _peak_rss_mb()
    parts = sum(f.stat().st_size for f in Path(work_dir).rglob("*") if f.is_file())
    return {"points": study.n_points, "seconds": seconds, "cpu": cpu,
            "client_before": before, "client_peak": client_peak,
            "scheduler_before": scheduler_before, "scheduler_peak": scheduler_peak,
            "workers_before": max(worker_before.values()),
            "workers_peak": max(workers_peak.values()), "parts_mb": parts / 2**20,
            "batches": info["batches"], "failed": info["points_failed"],
            "load": os.getloadavg()[0]}


def measure(name: str, study: Study, repeats: int) -> dict[str, Any]:
    runs: dict[int, list[dict[str, float]]] = {2: [], 1: []}
    for w in runs:
        for _ in range(repeats):
            runs[w].append(on_fresh_cluster(study, w))
            print(f"{name}, {w} worker(s): {runs[w][-1]}", flush=True)
    med = {w: statistics.median(r["seconds"] for r in runs[w]) for w in runs}
    wall, cpu = serial_cpu_per_point(study, study.n_points // 10)
    cpu_med = {w: statistics.median(r["cpu"] for r in runs[w]) for w in runs}
    return {"name": name, "points": study.n_points, "runs": runs, "median": med,
            "cpu_median": cpu_med, "speedup": med[1] / med[2],
            "serial_per_point": wall, "serial_cpu_per_point": cpu}


def design_chart(path: Path) -> dict[str, Any]:
    """Run the design study on a local cluster (2 workers) and draw the chart."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    start = time.perf_counter()
    ds = sweep(DESIGN_STUDY, batch_points=26)
    seconds = time.perf_counter() - start
    shape = json.loads(ds.attrs["grid_shape"])
    modulus = ds.coating_0_modulus.values.reshape(shape)[:, 0]
    scene = json.loads(ds.attrs["base_scene"])
    force = scene["loading"]["force"]
    ecc = ds.loading_moment.values.reshape(shape)[0] / force
    last = -1
    settlement = 1e3 * ds.settlement.values[:, last].reshape(shape)
    tilt = 1e3 * ds.tilt.values[:, last].reshape(shape)
    # the heel has lifted off where the contact set is shorter than the punch (the study's
    # contact width comes from the contact set)
    width = 2.0 * float(scene["punch"]["half_width"])
    lifted = (ds.contact_width.values[:, last] < width * (1.0 - 1e-9)).reshape(shape)
    unmet = ds.flag_tol_not_met.values.reshape(shape)
    failed = ds.failed.values.reshape(shape)
    years = ds.time.values[last] / 365.25
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), constrained_layout=True)
    ee, mm = np.meshgrid(ecc, modulus / 1e6)
    for ax, values, label in ((axes[0], settlement, "settlement [mm]"),
                              (axes[1], tilt, "tilt [mrad]")):
        filled = ax.contourf(ecc, modulus / 1e6, values, levels=14, cmap="viridis")
        lines = ax.contour(ecc, modulus / 1e6, values, levels=7, colors="white",
                           linewidths=0.6)
        labels = ax.clabel(lines, fontsize=7, fmt="%.3g")
        fig.colorbar(filled, ax=ax, label=f"{label}, {years:.0f} years after loading")
        if lifted.any():
            ax.contourf(ecc, modulus / 1e6, lifted.astype(float), levels=[0.5, 1.5],
                        colors="none", hatches=["///"])
            ax.contour(ecc, modulus / 1e6, lifted.astype(float), levels=[0.5], colors="red",
                       linewidths=1.2)
        if unmet.any():
            ax.plot(ee[unmet], mm[unmet], "wx", ms=4, label="tolerance not met")
        if failed.any():
            ax.plot(ee[failed], mm[failed], "rx", ms=4, label="failed")
        if unmet.any() or failed.any():
            ax.legend(loc="upper left", fontsize=7)
        ax.set_yscale("log")
        _drop_edge_labels(ax, labels)
        ax.set_xlabel("eccentricity e = M / P [m]")
        ax.set_ylabel("coating modulus [MPa]")
    axes[0].set_title("hatched, right of the red line: the heel has lifted off (unilateral "
                      "contact)", fontsize=8)
    fig.suptitle(ds.attrs["study"], fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return {"points": int(ds.sizes["point"]), "seconds": seconds,
            "failed": int(failed.sum()), "lifted": int(lifted.sum()),
            "tol_not_met": int(unmet.sum())}


def _drop_edge_labels(ax: Any, labels: list) -> None:
    """Remove the contour labels within 3 % of the axes' frame (in axes coordinates):
    there the frame cut them in half (the "0" of the tilt at its left edge)."""
    to_axes = ax.transData + ax.transAxes.inverted()
    for text in labels:
        u, v = to_axes.transform(text.get_position())
        if not (0.03 < u < 0.97 and 0.03 < v < 0.97):
            text.remove()


def environment() -> str:
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                                capture_output=True, text=True, timeout=10).stdout.strip()
    except OSError:
        commit = "?"
    import dask

    return (f"{os.cpu_count()} cores ({platform.machine()}), Python "
            f"{platform.python_version()}, numpy {np.__version__}, dask {dask.__version__}, "
            f"commit {commit}; the machine was shared with other work, so times are noisy")


def report(results: list[dict[str, Any]], chart: dict[str, Any] | None, command: str,
           repeats: int) -> str:
    lines = ["# Design studies on Dask: measured", "",
             f"Command: `{command}`  ", f"Machine: {environment()}.", "",
             "Each run starts a fresh local cluster (single-threaded worker processes on "
             "127.0.0.1; its start, the workers' warming included, is not counted) so that "
             "no worker begins with the study's caches; median of "
             f"{repeats} run(s). Measured with today's default "
             "solver engine (projection): a faster engine is being introduced, so the "
             "absolute times will change; the batching and the speed-up are what this "
             "measures.", "",
             "| study | points | 2 workers [s] | goal | met | 1 worker [s] | speed-up | "
             "workers' CPU, 2 / 1 workers [s] | serial loop, no Dask, wall / CPU "
             "[ms/point] | cluster start [s] |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in results:
        goal = GOALS.get(r["name"])
        two, one = r["median"][2], r["median"][1]
        start = statistics.median(x["start"] for x in r["runs"][2])
        lines.append(f"| {r['name']} | {r['points']:,} | {two:.1f} | "
                     f"{'' if goal is None else f'<= {goal:g} s'} | "
                     f"{'' if goal is None else ('yes' if two <= goal else 'no')} | "
                     f"{one:.1f} | {r['speedup']:.2f}x | {r['cpu_median'][2]:.1f} / "
                     f"{r['cpu_median'][1]:.1f} | {1e3 * r['serial_per_point']:.2f} / "
                     f"{1e3 * r['serial_cpu_per_point']:.2f} | {start:.1f} |")
    lines += ["", "All runs (seconds, 2 workers then 1):", ""]
    for r in results:
        runs = ", ".join(f"{x['seconds']:.1f}" for x in r["runs"][2]) + " / " + \
            ", ".join(f"{x['seconds']:.1f}" for x in r["runs"][1])
        load = ", ".join(f"{x['load']:.1f}" for w in (2, 1) for x in r["runs"][w])
        lines.append(f"- {r['name']}: {runs} (load average after each: {load}); failed points: "
                     f"{r['runs'][2][0]['failed']}, flagged: {r['runs'][2][0]['flagged']}, "
                     f"batches: {r['runs'][2][0]['batches']}")
    if chart is not None:
        lines += ["", "## Design chart", "",
                  "![design chart](sweep_design_chart.png)", "",
                  f"`{DESIGN_STUDY.relative_to(ROOT)}`: {chart['points']} points in "
                  f"{chart['seconds']:.1f} s on a local cluster (all cores, its start "
                  f"included), {chart['failed']} failed, {chart['lifted']} lifting off, "
                  f"{chart['tol_not_met']} short of their tolerance. The same study from "
                  "the shell: `python -m core sweep "
                  f"{DESIGN_STUDY.relative_to(ROOT)} --output design.nc`."]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small studies, one repeat")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--chart-only", action="store_true")
    parser.add_argument("--point-costs", action="store_true",
                        help="only where the loads study's CPU goes, in this process "
                             "(no Dask, nothing written)")
    parser.add_argument("--memory", type=int, nargs="+", metavar="POINTS",
                        help="only the peak memory of full-contact load studies of these "
                             "sizes (squares of 1,000 forces by POINTS / 1,000 moments) "
                             "on 2 workers, batches streamed to a temporary directory")
    parser.add_argument("--loads-runs", action="store_true",
                        help="only the 10,000-point loads study on fresh warmed clusters of "
                             "2 then 1 workers, --repeats times each, and once cold")
    parser.add_argument("--no-chart", action="store_true",
                        help="measure only; keep the design chart drawn before (it needs "
                             "matplotlib)")
    args = parser.parse_args(argv)
    # `kill -USR1 PID` prints where a run on a loaded machine is waiting
    faulthandler.register(signal.SIGUSR1)
    if args.point_costs:
        print(f"load average {os.getloadavg()[0]:.1f}", flush=True)
        for kind, cost in point_costs(loads_study(45 if args.quick else 100)).items():
            print(f"{kind}: {cost}", flush=True)
        print(f"load average {os.getloadavg()[0]:.1f}")
        return 0
    if args.loads_runs:
        study = loads_study(100)
        for _ in range(args.repeats):
            for w in (2, 1):
                print(f"{w} worker(s), warmed: {on_fresh_cluster(study, w)}", flush=True)
        for w in (2, 1):
            print(f"{w} worker(s), cold: {on_fresh_cluster(study, w, warm=False)}",
                  flush=True)
        return 0
    if args.memory:
        import tempfile

        for points in args.memory:
            with tempfile.TemporaryDirectory(prefix="study-memory-") as work:
                study = full_contact_study(1000, max(1, points // 1000))
                print(f"{study.n_points:,} points: {memory_of_study(study, 2, Path(work))}",
                      flush=True)
        return 0
    out = RESULTS / "quick" if args.quick else RESULTS
    out.mkdir(parents=True, exist_ok=True)
    command = "python -m benchmarks.sweep " + " ".join(argv if argv is not None
                                                        else sys.argv[1:])
    chart = None if args.no_chart else design_chart(out / "sweep_design_chart.png")
    print(f"chart: {chart}", flush=True)
    if args.chart_only:
        return 0
    repeats = 1 if args.quick else args.repeats
    results = []
    for name, study in (("loads", loads_study(45 if args.quick else 100)),
                        ("modulus", modulus_study(200 if args.quick else 1000))):
        results.append(measure(name, study, repeats))
        print(f"{name}: {results[-1]['median']} speed-up {results[-1]['speedup']:.2f}",
              flush=True)
    (out / "sweep.md").write_text(report(results, chart, command.strip(), repeats))
    print((out / "sweep.md").read_text())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
