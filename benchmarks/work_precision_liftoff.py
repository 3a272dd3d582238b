"""Work-precision of partial contact: zone ends and q against resolution and time.

    OPENBLAS_NUM_THREADS=1 python benchmarks/work_precision_liftoff.py
    # writes benchmarks/results/work_precision_liftoff.md (~3 min)

Four scenes past lift-off (dimensionless, core.contact.solve_unilateral):

* eccentric footing, elastic: lam = 1, m = 0.05, P = 1, M = 0.45 (e = 0.45, the edge
  x = -1 lifts off: one free end);
* worn patch, elastic: the same coating with a gap bump 0.01 exp(-(x/0.2)^2) in the
  middle, P = 0.01, M = 0.002 (contact in two pieces: two free ends between them);
* eccentric footing under creep: the lift-off preset (core/presets/scenes/
  eccentric_footing_liftoff.json) with 20 log-spaced output times over 1000 days;
* eccentric footing on young concrete: the preset young_concrete_50_years (fib MC2010,
  loaded at 7 days) with its force at e = a/2 and 20 log-spaced output times over 50
  years (a design code's law: 36 exponentials, the fastest decaying ~1e6 times faster
  than a step).

Elastic curves: the solver swept over ``tol`` (zone ends refined as roots of Q(end) = 0 on
panels graded toward them), and, for comparison, the nodal active set alone (ends where
the nodal Q changes sign, no refinement) on finer and finer fixed rules. Reference: the
root-find on a rule 16 times finer than the solver's first (panels <= 1/32, grading to
1e-2/4^4), whose own estimate is quoted. Creep: the solver swept over ``tol``; reference
its run at tol = 1e-7, cross-checked (the lift-off preset) against the general-kernel
path (trapezoid on K q, an independent time discretization) at tol = 1e-6.

Errors: zone ends, the largest shift of a free end [half-widths]; q, the largest
difference on 381 points of [-0.95, 0.95] relative to the largest reference q (all
output times under creep); outputs, settlement and tilt relative to max(|delta|,
|alpha|). Times: medians of repeated runs after a warm-up, this process's CPU time next
to the wall clock (the machine is shared), with the load average.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.liftoff import PRESET, RESULTS, constant, nodal_start  # noqa: E402
from core import scene_from_dict  # noqa: E402
from core.contact import solve_unilateral  # noqa: E402
from core.contact.step import Space, Step, nystrom_pressure  # noqa: E402
from core.contact.zones import Resolution, refine_zone_ends  # noqa: E402
from core.presets import read_preset  # noqa: E402

XS = np.linspace(-0.95, 0.95, 381)


def worn_patch(x):
    return 0.01 * np.exp(-(np.asarray(x) / 0.2) ** 2)


def timed(fn, repeats: int) -> tuple[float, float, object]:
    """Median (wall, CPU) seconds of ``repeats`` calls after a warm-up, and the answer."""
    result = fn()
    wall, cpu = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        result = fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return float(np.median(wall)), float(np.median(cpu)), result


def free_ends(zones: list[tuple[float, float]]) -> np.ndarray:
    return np.array([e for z in zones for e in z if abs(abs(e) - 1.0) > 1e-12])


# -------------------------------------------------------------------------- elastic


ELASTIC = {
    "eccentric footing (elastic)": (constant(0.0), {"force": 1.0, "moment": 0.45}),
    "worn patch (elastic)": (worn_patch, {"force": 0.01, "moment": 0.002}),
}


def elastic_reference(g, loads) -> dict:
    space = Space(1.0, constant(0.05), g, ())
    step = Step(1.0, 1.0, loads)
    _, _, (ends, pinned, slopes) = nodal_start(space, step)
    res = Resolution(0.5, 1e-2)
    for _ in range(4):
        res = res.finer()
    refined = refine_zone_ends(space, step, ends, pinned, slopes, res, tol=1e-12,
                               max_levels=1)
    sol = refined.solution
    q = nystrom_pressure(space, step, sol.panels, sol.q, sol.settlement, sol.tilt, XS)
    inside = np.zeros(XS.size, dtype=bool)
    for k in range(len(sol.ends) // 2):
        inside |= (XS >= sol.ends[2 * k]) & (XS <= sol.ends[2 * k + 1])
    return {"ends": free_ends([(sol.ends[2 * k], sol.ends[2 * k + 1])
                               for k in range(len(sol.ends) // 2)]),
            "q": np.where(inside, np.maximum(q, 0.0), 0.0), "settlement": sol.settlement,
            "tilt": sol.tilt, "estimate": refined.end_error, "nodes": sol.panels.size}


def nodal_only(g, loads, width: float):
    """The nodal active set on one fixed rule: ends where the nodal Q changes sign."""
    space = Space(1.0, constant(0.05), g, ())
    step = Step(1.0, 1.0, loads)
    panels, state, (ends, _, _) = nodal_start(space, step, width)
    zones = [(ends[2 * k], ends[2 * k + 1]) for k in range(len(ends) // 2)]
    q = nystrom_pressure(space, step, panels, state.q, state.settlement, state.tilt, XS)
    inside = np.zeros(XS.size, dtype=bool)
    for lo, hi in zones:
        inside |= (XS >= lo) & (XS <= hi)
    return {"zones": zones, "q": np.where(inside, np.maximum(q, 0.0), 0.0),
            "settlement": state.settlement, "tilt": state.tilt, "nodes": panels.size}


def elastic_rows(name: str, g, loads) -> tuple[list[str], dict]:
    ref = elastic_reference(g, loads)
    q_scale = float(np.max(np.abs(ref["q"])))
    kin = max(abs(ref["settlement"]), abs(ref["tilt"]))
    rows = []

    def errors(zones, q, settlement, tilt):
        ends = free_ends(zones)
        end_err = (float(np.max(np.abs(ends - ref["ends"]))) if ends.size == ref["ends"].size
                   else float("inf"))
        return (end_err, float(np.max(np.abs(q - ref["q"]))) / q_scale,
                max(abs(settlement - ref["settlement"]), abs(tilt - ref["tilt"])) / kin)

    for tol in (1e-4, 1e-6, 1e-8, 1e-10):
        def run(tol=tol):
            return solve_unilateral(1.0, 0.05, g, [1.0], tol=tol, **loads)
        wall, cpu, r = timed(run, 5)
        e_end, e_q, e_out = errors(r.contact_set[0], r.pressure(XS)[:, 0],
                                   r.settlement[0], r.tilt[0])
        rows.append(f"| solver, tol = {tol:g} | {r.info['n_nodes']} | {e_end:.1e} | "
                    f"{r.info['zone_end_error']:.1e} | {e_q:.1e} | {e_out:.1e} | "
                    f"{r.info['error_estimate']:.1e} | {cpu * 1e3:.1f} | {wall * 1e3:.1f} |")
    for width in (0.25, 0.125, 0.0625, 0.03125):
        wall, cpu, r = timed(lambda width=width: nodal_only(g, loads, width), 3)
        e_end, e_q, e_out = errors(r["zones"], r["q"], r["settlement"], r["tilt"])
        rows.append(f"| nodal active set only, panels <= {width:g} | {r['nodes']} | "
                    f"{e_end:.1e} | - | {e_q:.1e} | {e_out:.1e} | - | {cpu * 1e3:.1f} | "
                    f"{wall * 1e3:.1f} |")
    return rows, ref


# ---------------------------------------------------------------------------- creep


def creep_problem():
    scene = json.loads(PRESET.read_text())
    scene["times"] = {"end": 1000.0, "count": 20, "spacing": "log"}
    return scene_from_dict(scene).dimensionless


def code_creep_problem():
    """The 50-year fib MC2010 preset with its force at e = a / 2, 20 output times."""
    scene = read_preset("young_concrete_50_years")
    scene["loading"]["moment"] = 0.5 * scene["loading"]["force"]
    scene["times"] = {"end": 18262.5, "count": 20, "spacing": "log"}
    return scene_from_dict(scene).dimensionless


def creep_solve(pb, tol: float, kernel=None):
    return solve_unilateral(pb.lam, pb.m, pb.g, pb.times, c=pb.c,
                            kernel=pb.kernel if kernel is None else kernel, tol=tol,
                            breakpoints=pb.breakpoints, **pb.loads)


def creep_rows(pb, cross_check: bool = True) -> tuple[list[str], list[str]]:
    ref = creep_solve(pb, 1e-7)
    q_ref = ref.pressure(XS)
    q_scale = float(np.max(np.abs(q_ref)))
    kin = max(np.max(np.abs(ref.settlement)), np.max(np.abs(ref.tilt)))
    ref_ends = np.array([free_ends(z) for z in ref.contact_set])

    def errors(r):
        ends = np.array([free_ends(z) for z in r.contact_set])
        end_err = (float(np.max(np.abs(ends - ref_ends))) if ends.shape == ref_ends.shape
                   else float("inf"))
        return (end_err, float(np.max(np.abs(r.pressure(XS) - q_ref))) / q_scale,
                max(np.max(np.abs(r.settlement - ref.settlement)),
                    np.max(np.abs(r.tilt - ref.tilt))) / kin)

    rows = []
    for tol in (1e-3, 1e-4, 1e-5, 1e-6):
        wall, cpu, r = timed(lambda tol=tol: creep_solve(pb, tol), 3 if tol >= 1e-5 else 1)
        e_end, e_q, e_out = errors(r)
        rows.append(f"| solver, tol = {tol:g} | {r.info['n_nodes']} | "
                    f"{r.info['band_panel_width']:g} | {r.info['n_steps']} | {e_end:.1e} | "
                    f"{r.info['zone_end_error']:.1e} | {e_q:.1e} | {e_out:.1e} | "
                    f"{r.info['error_estimate']:.1e} | {cpu * 1e3:.0f} | {wall * 1e3:.0f} |")
    notes = [f"Reference: the solver at tol = 1e-7 ({ref.info['n_nodes']} nodes, band panels "
             f"{ref.info['band_panel_width']:g}, {ref.info['n_steps']} steps; its estimates: "
             f"zone ends {ref.info['zone_end_error']:.1e}, outputs "
             f"{ref.info['error_estimate']:.1e})."]
    if cross_check:
        kernel = pb.kernel

        def plain(t, tau):
            return kernel(t, tau)

        check = creep_solve(pb, 1e-6, kernel=plain)
        e_end, e_q, e_out = errors(check)
        notes[0] += (f" Cross-check: the general-kernel path (trapezoid on K q) at tol = "
                     f"1e-6 differs from it by {e_end:.1e} in the ends, {e_q:.1e} in q and "
                     f"{e_out:.1e} in the outputs (its estimates "
                     f"{check.info['zone_end_error']:.1e}, "
                     f"{check.info['error_estimate']:.1e}).")
    else:
        notes[0] += (" (The general-kernel path has no use here: the trapezoid on K q "
                     "follows a decay 1e6 times faster than a step only with steps "
                     "~1e6 times shorter.)")
    return rows, notes


def main() -> None:
    started = time.perf_counter()
    sections = []
    for name, (g, loads) in ELASTIC.items():
        rows, ref = elastic_rows(name, g, loads)
        sections += [f"## {name}", "",
                     f"Reference: {ref['nodes']} nodes on the contact set, free ends "
                     f"{', '.join(f'{e:.12f}' for e in ref['ends'])} (its own estimate "
                     f"{ref['estimate']:.1e}).", "",
                     "| method | nodes | end error | end estimate | q error | "
                     "settlement, tilt error | estimate | CPU ms | wall ms |",
                     "| --- | --- | --- | --- | --- | --- | --- | --- | --- |", *rows, ""]
    for title, pb, cross_check in (
            ("eccentric footing under creep (the lift-off preset, 20 output times)",
             creep_problem(), True),
            ("eccentric footing on young concrete (fib MC2010, e = a/2, 20 output times "
             "over 50 years)", code_creep_problem(), False)):
        rows, notes = creep_rows(pb, cross_check)
        sections += [f"## {title}", "", *notes, "",
                     "| method | nodes | band panels | steps | end error | end estimate | "
                     "q error | settlement, tilt error | estimate | CPU ms | wall ms |",
                     "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
                     *rows, ""]
    load = os.getloadavg()[0]
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, cwd=ROOT).stdout.strip()
    doc = (__doc__ or "").split("Four scenes", 1)[1]
    text = "\n".join([
        "# Work-precision: partial contact (lift-off)", "", "Made with:", "", "```",
        "OPENBLAS_NUM_THREADS=1 python benchmarks/work_precision_liftoff.py", "```", "",
        f"- machine: {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, numpy {np.__version__}",
        f"- code: commit {commit}; {time.perf_counter() - started:.0f} s",
        f"- load average at the end: {load:.1f} (shared machine: the CPU-time column, this "
        "process's own, is the steadier figure)", "",
        "Four scenes" + doc.rstrip(), "", *sections])
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "work_precision_liftoff.md").write_text(text)
    print(text)


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    main()
