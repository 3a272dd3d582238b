"""Work-precision diagrams of the projection and collocation solvers on the scene suite.

    python benchmarks/work_precision.py            # full report (about 17 minutes)
    python benchmarks/work_precision.py --quick    # reduced sweeps (about 30 s)

For every scene of :mod:`tests.support.scenes`, and two punches on one base
(:mod:`benchmarks.work_precision_punches`, ``core.solve`` over ``solver.tol``): the error
against a tight reference on the x axis, the run time on the y axis (log-log), one curve
per method swept over its resolution:

* projection over the number of modes (fixed ``n_modes``), one curve per basis kind the
  solver accepts (global, piecewise and graded when present), and over ``tol`` (adaptive);
* collocation over the number of unknowns (``panels_per_unit`` and ``edge_width``);
* on a creeping base also the projection over its time tolerance at a fixed mode count,
  and the collocation over ``time_points``.

Errors (at the final time): settlement and tilt relative to ``max(|delta|, |alpha|)``,
force and moment relative to ``max(|P|, |M|)``, the pressure as the largest difference on
interior sample points (``|x| <= 0.95``, 0.02 away from breakpoints) relative to the
largest reference pressure there; a curve plots the largest of these five.

Times are medians of repeated runs after a warm-up run, cold (``clear_caches()`` before
each run: everything from the panels on is recomputed; imports and the kernel tables are
warm) and warm (the caches hold the scene and only the loads change, a different force
each run). The collocation solver keeps no caches, so its cold and warm times are the same
measurement.

Output: ``benchmarks/results/`` (``--quick``: ``benchmarks/results/quick/``, not kept in
the repository): one PNG per scene, ``work_precision.md`` (tables, the references and
their agreement, the goals) and ``work_precision.json`` (every run).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import subprocess
import sys
import textwrap
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks import work_precision_punches as punches  # noqa: E402
from core.cache import clear_caches  # noqa: E402
from core.engines.collocation.solve import solve_collocation  # noqa: E402
from core.solver import solve_dimensionless  # noqa: E402
from tests.support.scenes import Scene, creep_times, suite  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"
#: Accuracy at which methods are compared (the goals are stated at it).
TARGET = 1e-6
#: Errors below this are drawn at it (an exactly given load has error 0).
ERROR_FLOOR_PLOT = 1e-16
PARTS = ("settlement", "tilt", "force", "moment", "pressure")
#: Mode count of the projection's time-tolerance sweep on creeping scenes.
TIME_SWEEP_MODES = 128


# --------------------------------------------------------------------------- errors


def sample_points(scene: Scene) -> np.ndarray:
    """Interior points where the pressure error is measured (|x| <= 0.95, off the jumps)."""
    xs = np.linspace(-0.95, 0.95, 381)
    for b in scene.breakpoints:
        xs = xs[np.abs(xs - b) > 0.02]
    return xs


@dataclass(frozen=True)
class Snapshot:
    """The final-time answer of one run: the four scalars and q at the sample points."""

    settlement: float
    tilt: float
    force: float
    moment: float
    pressure: np.ndarray

    @classmethod
    def of(cls, solution: Any, xs: np.ndarray) -> Snapshot:
        """Final-time values of a projection or collocation solution."""
        return cls(float(solution.settlement[-1]), float(solution.tilt[-1]),
                   float(solution.force[-1]), float(solution.moment[-1]),
                   np.asarray(solution.pressure(xs))[:, -1].copy())

    def errors(self, ref: Snapshot) -> dict[str, float]:
        """Relative errors against ``ref`` (see the module docstring), by part."""
        kin = max(abs(ref.settlement), abs(ref.tilt))
        dyn = max(abs(ref.force), abs(ref.moment))
        qs = float(np.max(np.abs(ref.pressure)))
        return {
            "settlement": abs(self.settlement - ref.settlement) / kin,
            "tilt": abs(self.tilt - ref.tilt) / kin,
            "force": abs(self.force - ref.force) / dyn,
            "moment": abs(self.moment - ref.moment) / dyn,
            "pressure": float(np.max(np.abs(self.pressure - ref.pressure))) / qs,
        }


# --------------------------------------------------------------------------- timing


@dataclass(frozen=True)
class Timing:
    """How runs are repeated: at most ``repeats`` timed runs, fewer for slow ones."""

    repeats: int
    budget: float  # seconds of timed runs per setting (after at least one)
    warmup_limit: float  # runs slower than this are not repeated nor warmed up


def timed(call: Callable[[], Any], timing: Timing, before: Callable[[int], None] | None = None
          ) -> tuple[Any, float, int]:
    """``(result of the warm-up, median seconds, runs timed)`` of ``call``.

    ``before(k)`` runs untimed before the k-th call (k = 0 is the warm-up). A run slower
    than ``timing.warmup_limit`` is timed once, the warm-up counting as the measurement.
    """
    if before:
        before(0)
    t0 = time.perf_counter()
    result = call()
    first = time.perf_counter() - t0
    if first > timing.warmup_limit:
        return result, first, 1
    samples: list[float] = []
    k = 1
    while len(samples) < timing.repeats and (not samples or sum(samples) < timing.budget):
        if before:
            before(k)
        t0 = time.perf_counter()
        call()
        samples.append(time.perf_counter() - t0)
        k += 1
    return result, float(np.median(samples)), len(samples)


# ------------------------------------------------------------------------------ runs


@dataclass
class Run:
    """One point of a work-precision curve."""

    scene: str
    curve: str
    setting: str
    errors: dict[str, float]
    cold: float
    warm: float | None
    repeats: int
    n_modes: int | None = None
    n_nodes: int | None = None
    n_steps: int | None = None
    estimate: float | None = None
    success: bool | None = None
    flags: list[str] = field(default_factory=list)
    stages: dict[str, float] = field(default_factory=dict)

    @property
    def error(self) -> float:
        """The plotted error: the largest part."""
        return max(self.errors.values())


def projection_run(scene: Scene, curve: str, setting: str, ref: Snapshot, xs: np.ndarray,
                   timing: Timing, *, warm: bool = True, times: np.ndarray | None = None,
                   **options: Any) -> Run:
    """Time the projection solver at one setting, cold and warm; errors against ``ref``."""
    times = scene.times if times is None else times

    def call(scale: float = 1.0) -> Any:
        return solve_dimensionless(scene.lam, scene.m, scene.g, times,
                                   **scene.arguments(scale), **options)

    sol, cold, reps = timed(call, timing, before=lambda _k: clear_caches())
    stages = {name: float(v["seconds"]) for name, v in sol.info["stages"].items()}
    warm_time = None
    if warm:
        call()  # fill the caches for this scene
        counter = iter(range(1, 10**6))
        _, warm_time, _ = timed(lambda: call(1.0 + 1e-3 * next(counter)), timing)
    return Run(scene.key, curve, setting, Snapshot.of(sol, xs).errors(ref), cold, warm_time,
               reps, n_modes=int(sol.info["n_modes"]), n_nodes=int(sol.info["n_nodes"]),
               n_steps=int(sol.info["n_steps"]), estimate=float(sol.info["error_estimate"]),
               success=bool(sol.info["success"]), flags=list(sol.info["flags"]),
               stages=stages)


def collocation_run(scene: Scene, curve: str, ppu: float, edge: float, time_points: int | None,
                    ref: Snapshot, xs: np.ndarray, timing: Timing) -> tuple[Run, Snapshot]:
    """Time the collocation solver at one resolution (it has no caches: cold = warm)."""
    def call() -> Any:
        return solve_collocation(scene.lam, scene.m, scene.g, scene.times,
                                 panels_per_unit=ppu, edge_width=edge,
                                 time_points=time_points, **scene.arguments())

    sol, seconds, reps = timed(call, timing, before=lambda _k: clear_caches())
    snap = Snapshot.of(sol, xs)
    setting = f"ppu={ppu:g}, edge={edge:.0e}"
    if time_points is not None:
        setting += f", time_points={time_points}"
    run = Run(scene.key, curve, setting, snap.errors(ref), seconds, seconds, reps,
              n_nodes=int(sol.info["n_nodes"]), n_steps=int(sol.info["n_steps"]),
              estimate=float(sol.info["error_estimate"]))
    return run, snap


# ------------------------------------------------------------------------ references


@dataclass
class Reference:
    """The reference of a scene and how it was obtained."""

    snapshot: Snapshot
    how: str
    checks: list[tuple[str, dict[str, float]]]  # independent solutions and their agreement
    seconds: float

    @property
    def agreement(self) -> dict[str, float]:
        """Agreement, by part, with the best-agreeing independent check."""
        return min((a for _, a in self.checks), key=lambda a: max(a.values()))

    @property
    def agreement_max(self) -> float:
        """The level down to which an independent method confirms the reference."""
        return max(self.agreement.values())

    @property
    def cross_check(self) -> str:
        return "; ".join(f"{how}: agreement " + ", ".join(f"{p} {a[p]:.1e}" for p in PARTS)
                         for how, a in self.checks)


def reference(scene: Scene, xs: np.ndarray, quick: bool) -> Reference:
    """Collocation at its finest, cross-checked against the projection at its tightest.

    The collocation refinement converges to ~1e-13 in every part on the elastic scenes
    (measured: its two finest levels differ by <= 6e-13), while the projection's pressure
    stalls near 1e-6 at 256 modes; so the collocation answer is the reference and the
    projection's is its independent check. ``--quick`` on a creeping base is the
    exception: a collocation run fine enough in time takes minutes, so there the
    projection is the reference and a coarse collocation run the check.
    """
    ppu, edge, tp = scene.colloc_reference
    if quick:
        ppu, edge = min(ppu, 16), max(edge, 1e-6)
    t0 = time.perf_counter()
    coll = solve_collocation(scene.lam, scene.m, scene.g, scene.times, panels_per_unit=ppu,
                             edge_width=edge, time_points=tp, **scene.arguments())
    coll_seconds = time.perf_counter() - t0
    n_ref = 192 if quick else 256
    proj_tol = 1e-10 if scene.creeping else 1e-12
    coll_how = (f"collocation, panels_per_unit={ppu:g}, edge_width={edge:.0e}"
                + (f", time_points={tp} (+ Richardson)" if tp is not None else "")
                + f": {coll.info['n_nodes']} nodes"
                + (f", {coll.info['n_steps']} steps" if scene.creeping else "")
                + f", {coll_seconds:.1f} s")
    coll_snap = Snapshot.of(coll, xs)
    projections = []
    for kind in (None, "piecewise"):  # the default basis, and piecewise if it is not that
        t0 = time.perf_counter()
        proj = solve_dimensionless(scene.lam, scene.m, scene.g, scene.times, n_modes=n_ref,
                                   tol=proj_tol, **({"basis": kind} if kind else {}),
                                   **scene.arguments())
        seconds = time.perf_counter() - t0
        if kind is not None and proj.info["basis"] == projections[0][2]:
            break
        how = (f"projection, n_modes={n_ref}, basis={proj.info['basis']}"
               f"{' (the default)' if kind is None else ''}, tol={proj_tol:.0e}: estimate "
               f"{proj.info['error_estimate']:.1e}, {seconds:.1f} s")
        projections.append((Snapshot.of(proj, xs), how, proj.info["basis"], seconds))
        if quick:
            break
    if quick and scene.creeping:
        snap, how, _, seconds = projections[0]
        return Reference(snap, how, [(coll_how, coll_snap.errors(snap))], seconds)
    return Reference(coll_snap, coll_how,
                     [(how, snap.errors(coll_snap)) for snap, how, _, _ in projections],
                     coll_seconds)


# ----------------------------------------------------------------------------- sweeps


def basis_kinds() -> tuple[list[str], str]:
    """Basis kinds the solver accepts now (the graded basis may not exist yet) and its
    default kind."""
    kinds = []
    for kind in ("global", "piecewise", "graded"):
        try:
            solve_dimensionless(1.0, 0.1, 0.0, [1.0], force=1.0, moment=0.0, n_modes=8,
                                basis=kind)
        except ValueError:
            continue
        kinds.append(kind)
    default = solve_dimensionless(1.0, 0.1, 0.0, [1.0], force=1.0, moment=0.0, n_modes=8)
    return kinds, str(default.info["basis"])


@dataclass(frozen=True)
class Plan:
    """What to sweep (the full report or the quick one)."""

    quick: bool
    timing: Timing
    kinds: tuple[str, ...]  # swept over n_modes
    tol_kinds: tuple[str, ...]  # swept over tol (adaptive)
    default: str  # the solver's default basis


def quick_scene(scene: Scene) -> Scene:
    """A reduced version of a scene for ``--quick`` (fewer points; shorter creep runs)."""
    n = tuple(k for k in scene.n_sweep if k in (16, 64))
    tols = tuple(t for t in scene.tol_sweep if t in (1e-4, 1e-7))
    colloc = scene.colloc_sweep[1:3] if not scene.creeping else scene.colloc_sweep[:1]
    if scene.creeping:
        days = (scene.times[-1] - 1.0) * 28.0
        count = 20
        return replace(scene, times=creep_times(days, count), n_sweep=n, tol_sweep=tols,
                       colloc_sweep=colloc, time_sweep=(count - 1,),
                       colloc_reference=(4, 1e-3, 2 * (count - 1)))
    return replace(scene, n_sweep=n, tol_sweep=tols, colloc_sweep=colloc)


def sweep_scene(scene: Scene, plan: Plan, log: Callable[[str], None]) -> dict[str, Any]:
    """All runs of one scene, its reference, and the time to reach TARGET per curve."""
    xs = sample_points(scene)
    ref = reference(scene, xs, plan.quick)
    log(f"[{scene.key}] reference: {ref.how}; best agreement of an independent check "
        f"{ref.agreement_max:.1e}")
    runs: list[Run] = []
    timing = plan.timing

    def add(run: Run) -> None:
        runs.append(run)
        warm = f"{run.warm * 1e3:9.2f}" if run.warm is not None else "        -"
        log(f"  {run.curve:<34} {run.setting:<38} err {run.error:8.1e}  "
            f"cold {run.cold * 1e3:9.2f} ms  warm {warm} ms")

    for kind in plan.kinds:
        for n in scene.n_sweep:
            add(projection_run(scene, f"projection n ({kind})", f"n_modes={n}", ref.snapshot,
                               xs, timing, n_modes=n, basis=kind, tol=scene.n_sweep_tol))
    for kind in plan.tol_kinds:
        for tol in scene.tol_sweep:
            add(projection_run(scene, f"projection tol ({kind})", f"tol={tol:.0e}",
                               ref.snapshot, xs, timing, tol=tol, basis=kind))
    if scene.creeping:
        n = min(TIME_SWEEP_MODES, max(scene.n_sweep))
        for tol in scene.tol_sweep + ((1e-11, 1e-12) if not plan.quick else ()):
            add(projection_run(scene, f"projection time tol ({plan.default}, n={n})",
                               f"tol={tol:.0e}",
                               ref.snapshot, xs, timing, tol=tol, n_modes=n))
    space_tp = scene.time_sweep[len(scene.time_sweep) // 2] if scene.creeping else None
    for ppu, edge in scene.colloc_sweep:
        add(collocation_run(scene, "collocation space", ppu, edge, space_tp, ref.snapshot,
                            xs, timing)[0])
    if scene.creeping:
        ppu, edge = scene.colloc_sweep[len(scene.colloc_sweep) // 2]
        for tp in scene.time_sweep:
            if tp == space_tp:
                continue  # already run in the space sweep
            add(collocation_run(scene, "collocation time", ppu, edge, tp, ref.snapshot, xs,
                                timing)[0])
    return {"scene": scene, "reference": ref, "runs": runs}


def two_punch_result(plan: Plan, log: Callable[[str], None]) -> dict[str, Any]:
    """The two-punch entry (:mod:`benchmarks.work_precision_punches`): ``core.solve`` over
    ``solver.tol`` against the scene at the tightest tol, cold and warm."""
    import core

    t0 = time.perf_counter()
    best = core.solve(punches.scene(punches.REFERENCE_TOL))
    seconds = time.perf_counter() - t0
    nodes = " + ".join(str(p.info["n_nodes"]) for p in best.punches)
    how = (f"core.solve at tol={punches.REFERENCE_TOL:.0e}: {nodes} nodes, estimate "
           f"{best.info['error_estimate']:.1e}, {seconds:.1f} s")
    check = core.solve(punches.scene(punches.CHECK_TOL))
    # no second method solves several punches: the check is the engine's own convergence
    ref = Reference(best, how, [(f"core.solve at tol={punches.CHECK_TOL:.0e} "
                                 "(self-convergence)", punches.errors(check, best))], seconds)
    log(f"[{punches.KEY}] reference: {how}; tol={punches.CHECK_TOL:.0e} agrees to "
        f"{ref.agreement_max:.1e}")
    runs = []
    for tol in punches.QUICK_TOLS if plan.quick else punches.TOLS:
        result, cold, repeats = timed(lambda tol=tol: core.solve(punches.scene(tol)),
                                      plan.timing, before=lambda _k: clear_caches())
        core.solve(punches.scene(tol))  # fill the caches for this scene
        counter = iter(range(1, 10**6))
        _, warm, _ = timed(lambda tol=tol, counter=counter: core.solve(
            punches.scene(tol, 1.0 + 1e-3 * next(counter))), plan.timing)
        run = Run(punches.KEY, punches.CURVE, f"tol={tol:.0e}", punches.errors(result, best),
                  cold, warm, repeats,
                  n_nodes=sum(int(p.info["n_nodes"]) for p in result.punches),
                  estimate=float(result.info["error_estimate"]),
                  success=bool(result.info["success"]), flags=list(result.flags))
        log(f"  {run.curve:<34} {run.setting:<38} err {run.error:8.1e}  "
            f"cold {cold * 1e3:9.2f} ms  warm {warm * 1e3:9.2f} ms")
        runs.append(run)
    return {"scene": punches.PunchesEntry(), "reference": ref, "runs": runs}


# ----------------------------------------------------------------------------- goals


def best_time(runs: list[Run], target: float, which: str = "cold",
              parts: tuple[str, ...] = PARTS) -> Run | None:
    """The fastest run whose error (over ``parts``) is at most ``target``."""
    ok = [r for r in runs if max(r.errors[p] for p in parts) <= target
          and getattr(r, which) is not None]
    return min(ok, key=lambda r: getattr(r, which)) if ok else None


def curves_of(runs: list[Run]) -> dict[str, list[Run]]:
    out: dict[str, list[Run]] = {}
    for r in runs:
        out.setdefault(r.curve, []).append(r)
    return out


def aging_100_runs(scene: Scene, ref: Reference, plan: Plan,
                   log: Callable[[str], None]) -> list[Run]:
    """The aging-creep scene with 100 output times (the 20 ms goal).

    The errors are at the final time, which is the same as in the 500-output scene, so
    that scene's reference serves.
    """
    days = (scene.times[-1] - 1.0) * 28.0
    times = creep_times(days, 100)
    small = replace(scene, key=scene.key + "_100")
    xs = sample_points(scene)
    runs = []
    tols = (1e-5, 1e-6, 1e-7, 1e-8) if not plan.quick else (1e-6,)
    for tol in tols:
        run = projection_run(small, "projection tol (default basis)", f"tol={tol:.0e}",
                             ref.snapshot, xs, plan.timing, times=times, tol=tol)
        log(f"  100 outputs, tol={tol:.0e}: err {run.error:.1e} cold {run.cold * 1e3:.1f} ms "
            f"warm {run.warm * 1e3 if run.warm else float('nan'):.1f} ms")
        runs.append(run)
    for n in (16, 32, 64) if not plan.quick else (32,):
        for tol in (1e-6, 1e-7):
            run = projection_run(small, f"projection n={n}", f"n_modes={n}, tol={tol:.0e}",
                                 ref.snapshot, xs, plan.timing, times=times, tol=tol,
                                 n_modes=n)
            log(f"  100 outputs, n={n}, tol={tol:.0e}: err {run.error:.1e} "
                f"cold {run.cold * 1e3:.1f} ms")
            runs.append(run)
    return runs


# ------------------------------------------------------------------------------ plots


STYLE = {
    "projection n (global)": ("tab:gray", "o", "-"),
    "projection n (piecewise)": ("tab:blue", "o", "-"),
    "projection n (graded)": ("tab:green", "o", "-"),
    "projection tol (piecewise)": ("tab:blue", "s", "--"),
    "projection tol (graded)": ("tab:green", "s", "--"),
    "collocation space": ("tab:red", "^", "-"),
    "collocation time": ("tab:orange", "v", "--"),
}


def plot_scene(result: dict[str, Any], path: Path) -> None:
    """Two panels, cold and warm: log10 error on x, log10 seconds on y."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scene: Scene = result["scene"]
    ref: Reference = result["reference"]
    curves = curves_of(result["runs"])
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2), sharey=True)
    for ax, which in zip(axes, ("cold", "warm"), strict=True):
        for name, runs in curves.items():
            pts = [(max(r.error, ERROR_FLOOR_PLOT), getattr(r, which)) for r in runs
                   if getattr(r, which) is not None]
            if not pts:
                continue
            color, marker, line = STYLE.get(name, ("tab:purple", "D", ":"))
            if name.startswith("projection time tol"):
                color, marker, line = "tab:cyan", "P", "-."
            ex, ey = zip(*pts, strict=True)
            ax.plot(ex, ey, line, color=color, marker=marker, label=name, ms=5, lw=1.3)
            # Hollow markers: adaptive runs that report tol_not_met.
            bad = [(max(r.error, ERROR_FLOOR_PLOT), getattr(r, which)) for r in runs
                   if r.success is False and "tol " in name and getattr(r, which) is not None]
            if bad:
                bx, by = zip(*bad, strict=True)
                ax.plot(bx, by, marker, color="white", ms=3, ls="none")
        ax.axvline(TARGET, color="k", lw=0.8, ls=":")
        ax.axvline(max(ref.agreement_max, ERROR_FLOOR_PLOT), color="tab:brown", lw=0.8,
                   ls="--", label="reference cross-check agreement")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlabel("max relative error (delta, alpha, P, M, q) at the final time")
        title = ("cold: clear_caches() before each run" if which == "cold"
                 else "warm: cached scene, only the loads change")
        ax.set_title(title, fontsize=10)
    axes[0].set_ylabel("seconds (median)")
    axes[1].legend(fontsize=8, loc="best")
    fig.suptitle(textwrap.fill(f"{scene.title}: {scene.description}", 160), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ----------------------------------------------------------------------------- report


def fmt_ms(seconds: float | None) -> str:
    if seconds is None:
        return "-"
    ms = seconds * 1e3
    return f"{ms:.3g}" if ms < 1000 else f"{ms:.0f}"


def fmt_e(value: float | None) -> str:
    return "-" if value is None else f"{value:.1e}"


def environment() -> list[str]:
    """Machine, library versions and the code version the report was made with."""
    import scipy

    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                                capture_output=True, text=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "core"], cwd=ROOT,
                               capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        commit, dirty = "unknown", ""
    return [f"- machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
            f"Python {platform.python_version()}, numpy {np.__version__}, "
            f"scipy {scipy.__version__}",
            f"- code: commit {commit or 'unknown'}"
            + (" with uncommitted changes in core/ (work in progress of other engineers)"
               if dirty else ""),
            f"- date: {time.strftime('%Y-%m-%d %H:%M')}; load average at the end "
            f"{os.getloadavg()[0]:.1f} (the machine is shared with other work: timings "
            "carry that noise)"]


def scene_section(result: dict[str, Any], png: str) -> list[str]:
    scene: Scene = result["scene"]
    ref: Reference = result["reference"]
    runs: list[Run] = result["runs"]
    lines = [f"### {scene.title} (`{scene.key}`)", "", scene.description, "",
             f"- reference: {ref.how}",
             f"- cross-checks: {ref.cross_check}",
             f"- verified down to {ref.agreement_max:.1e} by the best-agreeing check (the "
             "brown line)",
             "", f"![{scene.key}]({png})", "",
             f"Time to reach {TARGET:.0e} (fastest run of each curve with max error <= "
             f"{TARGET:.0e}):", "",
             "| curve | setting | max error | cold ms | warm ms |",
             "| --- | --- | --- | --- | --- |"]
    for name, cruns in curves_of(runs).items():
        best = best_time(cruns, TARGET)
        if best is None:
            closest = min(cruns, key=lambda r: r.error)
            lines.append(f"| {name} | not reached (best {closest.error:.1e} at "
                         f"{closest.setting}) | | | |")
        else:
            lines.append(f"| {name} | {best.setting} | {best.error:.1e} | {fmt_ms(best.cold)} "
                         f"| {fmt_ms(best.warm)} |")
    lines += ["", "<details><summary>all runs</summary>", "",
              "| curve | setting | n | nodes | steps | delta | alpha | P | M | q | max | "
              "estimate | success | cold ms | warm ms | runs |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | "
              "--- | --- | --- |"]
    for r in runs:
        e = r.errors
        lines.append(
            f"| {r.curve} | {r.setting} | {r.n_modes or '-'} | {r.n_nodes or '-'} | "
            f"{r.n_steps if r.n_steps is not None else '-'} | {e['settlement']:.1e} | "
            f"{e['tilt']:.1e} | {e['force']:.1e} | {e['moment']:.1e} | {e['pressure']:.1e} | "
            f"{r.error:.1e} | {fmt_e(r.estimate)} | "
            f"{'-' if r.success is None else ('yes' if r.success else 'no')} | "
            f"{fmt_ms(r.cold)} | {fmt_ms(r.warm)} | {r.repeats} |")
    lines += ["", "</details>", ""]
    return lines


def ratio_line(result: dict[str, Any]) -> tuple[str, float | None, float | None]:
    """Collocation time over projection time at the tightest common accuracy level."""
    runs = result["runs"]
    proj = [r for r in runs if r.curve.startswith("projection")]
    coll = [r for r in runs if r.curve.startswith("collocation")]
    for level in (1e-6, 1e-5, 1e-4, 1e-3):
        bp, bc = best_time(proj, level), best_time(coll, level)
        if bp and bc:
            return (f"{level:.0e}", bc.cold / bp.cold,
                    bc.cold / bp.warm if bp.warm else None)
    return "-", None, None


def goals_section(results: list[dict[str, Any]], aging100: list[Run]) -> list[str]:
    by_key = {r["scene"].key: r for r in results}
    lines = ["## Goals: where we stand", ""]
    smooth = by_key.get("smooth")
    if smooth:
        runs = [r for r in smooth["runs"] if r.curve.startswith("projection")]
        bc = best_time(runs, TARGET, "cold")
        bw = best_time(runs, TARGET, "warm")
        scal = ("settlement", "tilt", "force", "moment")
        sc_cold = best_time(runs, TARGET, "cold", scal)
        sc_warm = best_time(runs, TARGET, "warm", scal)
        best = min(runs, key=lambda r: r.error)
        lines.append("1. **Elastic scene (smooth) to 1e-6: <= 5 ms for a new scene (cold), "
                     "<= 0.5 ms when only the loads change (warm).**")
        if bc:
            lines.append(f"   - reached: cold {fmt_ms(bc.cold)} ms ({bc.curve}, {bc.setting}), "
                         f"warm {fmt_ms(bw.warm) if bw else '-'} ms"
                         f" -> {'MET' if bc.cold <= 5e-3 else 'MISSED'} (cold), "
                         f"{'MET' if bw and bw.warm <= 5e-4 else 'MISSED'} (warm).")
        else:
            lines.append(f"   - MISSED: no projection run reaches {TARGET:.0e} in all five "
                         f"parts; the best is {best.error:.1e} ({best.curve}, {best.setting}; "
                         f"the pressure part: {best.errors['pressure']:.1e}).")
        if sc_cold:
            lines.append(f"   - the four scalars alone (delta, alpha, P, M) reach {TARGET:.0e} "
                         f"in {fmt_ms(sc_cold.cold)} ms cold ({sc_cold.curve}, "
                         f"{sc_cold.setting}) and {fmt_ms(sc_warm.warm) if sc_warm else '-'} "
                         f"ms warm ({sc_warm.curve if sc_warm else '-'}, "
                         f"{sc_warm.setting if sc_warm else '-'}).")
    if aging100:
        ok = [r for r in aging100 if r.error <= TARGET]
        lines.append("2. **Aging creep with 100 output times to 1e-6: <= 20 ms.**")
        if ok:
            bc = min(ok, key=lambda r: r.cold)
            bw = min((r for r in ok if r.warm is not None), key=lambda r: r.warm, default=None)
            lines.append(f"   - fastest run with error <= 1e-6: cold {fmt_ms(bc.cold)} ms "
                         f"({bc.curve}, {bc.setting}, error {bc.error:.1e}), warm "
                         f"{fmt_ms(bw.warm) if bw else '-'} ms -> "
                         f"{'MET' if bc.cold <= 0.02 else 'MISSED'} (cold), "
                         f"{'MET' if bw and bw.warm <= 0.02 else 'MISSED'} (warm).")
        else:
            best = min(aging100, key=lambda r: r.error)
            lines.append(f"   - MISSED: no run reached 1e-6; best {best.error:.1e} "
                         f"({best.curve}, {best.setting}, cold {fmt_ms(best.cold)} ms; "
                         f"pressure part {best.errors['pressure']:.1e}).")
        lines.append("   - all runs: " + "; ".join(
            f"{r.curve} {r.setting}: err {r.error:.1e} (delta {r.errors['settlement']:.1e}), "
            f"cold {fmt_ms(r.cold)} ms, warm {fmt_ms(r.warm)} ms, {r.n_steps} steps"
            for r in aging100))
    lines.append("3. **Projection >= 30x faster than collocation at equal accuracy on smooth "
                 "scenes** (collocation time / projection time, > 1 when the projection is "
                 "faster, at the tightest accuracy level of 1e-6, 1e-5, 1e-4, 1e-3 both "
                 "reach; the projection cold, and warm):")
    for r in results:
        if not r["scene"].smooth:
            continue
        level, cold_ratio, warm_ratio = ratio_line(r)
        verdict = "-" if cold_ratio is None else ("MET" if cold_ratio >= 30 else "MISSED")
        lines.append(f"   - {r['scene'].key}: at {level}: {cold_ratio or float('nan'):.1f}x "
                     f"(cold), {warm_ratio or float('nan'):.1f}x (projection warm) -> "
                     f"{verdict}")
    jump = by_key.get("modulus_jump")
    if jump:
        lines.append("4. **Modulus jump to 1e-8 with <= 64 basis functions.**")
        for r in jump["runs"]:
            if r.curve.startswith("projection n") and r.setting == "n_modes=64":
                scal = max(r.errors[p] for p in ("settlement", "tilt", "force", "moment"))
                lines.append(f"   - {r.curve}: delta/alpha/P/M {scal:.1e}, pressure "
                             f"{r.errors['pressure']:.1e} -> scalars "
                             f"{'MET' if scal <= 1e-8 else 'MISSED'}, pressure "
                             f"{'MET' if r.errors['pressure'] <= 1e-8 else 'MISSED'}")
        fewest = {}
        for r in jump["runs"]:
            if r.curve.startswith("projection n") and r.error <= 1e-8:
                fewest.setdefault(r.curve, r)
        for name, r in fewest.items():
            lines.append(f"   - {name} first reaches 1e-8 in all parts at {r.setting}")
    lines.append("")
    return lines


def summary_table(results: list[dict[str, Any]]) -> list[str]:
    lines = [f"## Summary: time to reach {TARGET:.0e}", "",
             "Fastest run of each method family with max error <= 1e-6 (cold / warm ms), "
             "and the collocation-to-projection time ratio at the tightest common level.",
             "",
             "| scene | reference agreement | projection best error | projection cold ms | "
             "projection warm ms | collocation best error | collocation ms | ratio (level) |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for res in results:
        runs = res["runs"]
        proj = [r for r in runs if r.curve.startswith("projection")]
        coll = [r for r in runs if r.curve.startswith("collocation")]
        bpc = best_time(proj, TARGET, "cold")
        bpw = best_time(proj, TARGET, "warm")
        bcc = best_time(coll, TARGET, "cold")
        level, ratio, _ = ratio_line(res)
        lines.append(
            f"| {res['scene'].key} | {res['reference'].agreement_max:.1e} | "
            f"{min(r.error for r in proj):.1e} | {fmt_ms(bpc.cold) if bpc else 'not reached'} | "
            f"{fmt_ms(bpw.warm) if bpw else 'not reached'} | "
            f"{min(r.error for r in coll):.1e} | {fmt_ms(bcc.cold) if bcc else 'not reached'} | "
            f"{'-' if ratio is None else f'{ratio:.1f}x ({level})'} |" if coll else
            # no collocation solver of several punches
            f"| {res['scene'].key} | {res['reference'].agreement_max:.1e} | "
            f"{min(r.error for r in proj):.1e} | {fmt_ms(bpc.cold) if bpc else 'not reached'} | "
            f"{fmt_ms(bpw.warm) if bpw else 'not reached'} | - | - | - |")
    lines.append("")
    return lines


#: Partial contact has its own report (the scenes above are in full contact).
PARTIAL_CONTACT = [
    "## Partial contact (lift-off)", "",
    "Scenes past lift-off (an eccentric footing and a worn patch on an elastic base, the "
    "lift-off preset under creep): zone ends, q and the outputs against resolution and "
    "time, the solver swept over tol against a finer reference and against the nodal "
    "active set without refinement of the ends, in "
    "[work_precision_liftoff.md](work_precision_liftoff.md) "
    "(`OPENBLAS_NUM_THREADS=1 python benchmarks/work_precision_liftoff.py`).", ""]


#: The code-creep scene (50 years, 200 outputs) is timed against a finer fit of its
#: kernel in its own report; its figures are copied here by hand after each run of it.
CODE_CREEP = [
    "## Code creep over 50 years (`young_concrete_50_years`)", "",
    "The preset footing on young concrete (fib Model Code 2010 or EN 1992-1-1 creep and "
    "aging fitted by a sum of exponentials, 200 output times over 50 years, tol 1e-4), "
    "the default engine against the same scene with a finer fit solved at tol 1e-7, in "
    "[code_creep.md](code_creep.md) (`OPENBLAS_NUM_THREADS=1 python -m "
    "benchmarks.code_creep --repeats 3`). Run F there (load average 3.6, CPU time):", "",
    "| model | new scene, CPU ms | load change, CPU ms | settlement error | estimate "
    "| kernel fit error | steps |",
    "| --- | --- | --- | --- | --- | --- | --- |",
    "| fib_mc2010 | 63 | 1.7 | 4.8e-07 | 1.7e-05 | 1.5e-05 | 125 |",
    "| eurocode2 | 42 | 1.7 | 1.5e-06 | 1.2e-05 | 9.3e-06 | 63 |", ""]


def write_report(results: list[dict[str, Any]], aging100: list[Run], plan: Plan, out: Path,
                 command: str, elapsed: float) -> None:
    lines = ["# Work-precision report", "",
             "Made with:", "", "```", command, "```", "",
             f"({elapsed / 60:.1f} min; {'quick: reduced sweeps' if plan.quick else 'full'})",
             "", *environment(),
             f"- basis kinds found in the solver: {', '.join(plan.kinds)} (default: "
             f"{plan.default})", "",
             "## How to read it", "",
             "- x axis: the largest of the relative errors at the final time of settlement and "
             "tilt (relative to max(|delta|, |alpha|)), force and moment (relative to "
             "max(|P|, |M|)) and pressure (max over 381 points of |x| <= 0.95, 0.02 away "
             "from breakpoints, relative to max|q|); a given load has error 0 (drawn at "
             "1e-16). The parts are in the tables.",
             "- y axis: median seconds of repeated runs after a warm-up "
             f"(up to {plan.timing.repeats} runs or {plan.timing.budget:g} s; runs slower than "
             f"{plan.timing.warmup_limit:g} s are timed once). Cold: `clear_caches()` before "
             "each run (panels, operator, basis, Galerkin matrices, modes recomputed; "
             "imports and kernel tables warm). Warm: the scene is cached and only the loads "
             "change (force and moment scaled by 1 + 1e-3 k in run k), the interactive case. "
             "Collocation has no caches: one measurement serves both.",
             "- references: collocation at its finest resolution (it converges to ~1e-13 "
             "on the elastic scenes), cross-checked against the projection at "
             f"{192 if plan.quick else 256} modes with the default basis and with the "
             "piecewise one (the best agreement is the brown dashed line; below it the "
             "curves are not verified by an independent method). Projection "
             "errors are therefore measured against an independent method; collocation "
             "errors against its own finest run (self-convergence), which the projection "
             "confirms down to the agreement."
             + (" Quick mode, creeping base: the projection is the reference and a coarse "
                "collocation run the check." if plan.quick else ""),
             "- projection curves: `n` = fixed `n_modes` sweep (time tol of the creep scenes "
             "1e-10), `tol` = adaptive (hollow markers: the solver reported tol_not_met); "
             f"`time tol (default basis, n={TIME_SWEEP_MODES})` = tol swept at fixed "
             "n_modes (creep). "
             "Collocation `space` = (panels_per_unit, edge_width) sweep (creep: at fixed "
             "time_points), `time` = time_points sweep at fixed panels.", ""]
    lines += summary_table(results)
    lines += goals_section(results, aging100)
    lines += PARTIAL_CONTACT
    lines += CODE_CREEP
    lines += ["## Scenes", ""]
    for res in results:
        lines += scene_section(res, f"{res['scene'].key}.png")
    (out / "work_precision.md").write_text("\n".join(lines))


def dump_json(results: list[dict[str, Any]], aging100: list[Run], out: Path) -> None:
    def run_dict(r: Run) -> dict[str, Any]:
        d = dict(r.__dict__)
        d["error"] = r.error
        return d

    data = {res["scene"].key: {
        "description": res["scene"].description,
        "reference": {"how": res["reference"].how, "cross_check": res["reference"].cross_check,
                      "agreement": res["reference"].agreement},
        "runs": [run_dict(r) for r in res["runs"]]} for res in results}
    data["aging_creep_100_outputs"] = {"runs": [run_dict(r) for r in aging100]}
    (out / "work_precision.json").write_text(json.dumps(data, separators=(",", ":")))


# ------------------------------------------------------------------------------- main


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="reduced sweeps, one timed run each (under a minute)")
    parser.add_argument("--scenes", nargs="*", default=None,
                        help="only these scene keys (default: all)")
    parser.add_argument("--out", type=Path, default=None, help="output folder")
    args = parser.parse_args(argv)
    try:
        import core.kernel.plane  # noqa: F401
    except ImportError:
        print("core/kernel/plane.py is missing: the figures must be made with the real kernel",
              file=sys.stderr)
        return 2
    out = args.out or (RESULTS / "quick" if args.quick else RESULTS)
    out.mkdir(parents=True, exist_ok=True)
    timing = (Timing(repeats=1, budget=0.0, warmup_limit=0.05) if args.quick
              else Timing(repeats=7, budget=1.0, warmup_limit=3.0))
    kinds, default = basis_kinds()
    # The adaptive solver is for the breakpoint-aware bases (not the seed's global one);
    # --quick sweeps tol for the default basis only.
    tol_kinds = ((default,) if args.quick
                 else tuple(k for k in kinds if k != "global"))
    if args.quick:  # the seed's global basis only in the full report
        kinds = [k for k in kinds if k != "global"]
    plan = Plan(args.quick, timing, tuple(kinds), tol_kinds, default)
    started = time.perf_counter()

    def log(text: str) -> None:
        print(f"{time.perf_counter() - started:7.1f}s {text}", flush=True)

    scenes = suite()
    with_punches = not args.scenes or punches.KEY in args.scenes
    if args.scenes:
        unknown = set(args.scenes) - {s.key for s in scenes} - {punches.KEY}
        if unknown:
            parser.error(f"unknown scenes: {', '.join(sorted(unknown))}")
        scenes = [s for s in scenes if s.key in args.scenes]
    if args.quick:
        scenes = [quick_scene(s) for s in scenes]
    log(f"basis kinds: {', '.join(plan.kinds)} (default {plan.default}); "
        f"{len(scenes) + with_punches} scenes")
    results = []
    aging100: list[Run] = []
    for scene in scenes:
        res = sweep_scene(scene, plan, log)
        results.append(res)
        plot_scene(res, out / f"{scene.key}.png")
        if scene.key == "aging_creep":
            aging100 = aging_100_runs(scene, res["reference"], plan, log)
    if with_punches:
        res = two_punch_result(plan, log)
        results.append(res)
        plot_scene(res, out / f"{punches.KEY}.png")
    command = "python benchmarks/work_precision.py" + "".join(
        " " + shlex.quote(a) for a in (sys.argv[1:] if argv is None else argv))
    elapsed = time.perf_counter() - started
    write_report(results, aging100, plan, out, command, elapsed)
    dump_json(results, aging100, out)
    log(f"wrote {out / 'work_precision.md'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
