"""The cost of a new geometry on the exact layered path, and what it gives up.

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.layered_speed [--study]   # writes
                                                 # benchmarks/results/layered_speed.md

A geometry or material change of a uniform coating builds the stack's kernel table and
Galerkin matrix again (:mod:`core.engines.layered.cache`); a load change reuses them. Measured here,
in this process, each solve a new geometry (``core.solve`` on a scene dict, validation
included):

* the preset ``rounded_graded`` (three layers, elastic base), one slider at a time: ten
  steps of 1 % each of the top layer's thickness, the middle layer's modulus, the top
  layer's Poisson ratio, the punch's half-width, the base's thickness, and the crown (a gap
  change: the stack is reused); the median CPU time of this process per step and the
  median ``info["seconds"]`` (wall) the explorer compares with its live-drag bound;
* the benchmark study's scene (``benchmarks.sweep.elastic_scene``: uniform_flat on an
  elastic base) over 100 coating moduli, 50 MPa to 20 GPa: CPU time per point;
* with ``--study``: the 1,000-point coating-modulus study of ``benchmarks/sweep.py``
  (:func:`benchmarks.sweep.modulus_study`) on a fresh local Dask cluster of 2 workers
  (:func:`benchmarks.sweep.on_fresh_cluster`): wall seconds and the workers' CPU seconds;
* the price: settlement, tilt, force and moment of the default tolerance (1e-6, the
  coarser rules of :mod:`core.engines.layered.galerkin`) against tol 1e-12 (the finest), over the
  same slider steps.

CPU times are of this process (``time.process_time``); the machine's load average is
written beside them: on a shared machine both CPU and wall times grow with the load.
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from core import solve

ROOT = Path(__file__).resolve().parent.parent
STEPS = 10
QUANTITIES = ("settlement", "tilt", "force", "moment")


def rounded_graded() -> dict[str, Any]:
    """The preset as shipped (an elastic base)."""
    return json.loads((ROOT / "core" / "presets" / "scenes" / "rounded_graded.json").read_text())


def _step(d: dict[str, Any], name: str, k: int) -> dict[str, Any]:
    """``d`` with the slider ``name`` moved by ``k`` %."""
    e = copy.deepcopy(d)
    factor = 1.0 + 0.01 * k
    if name == "top thickness":
        e["coating"][0]["thickness"] *= factor
    elif name == "middle modulus":
        e["coating"][1]["modulus"] *= factor
    elif name == "top Poisson ratio":
        e["coating"][0]["poisson"] /= factor
    elif name == "half-width":
        e["punch"]["half_width"] *= factor
    elif name == "base thickness":
        e["base"]["thickness"] *= factor
    elif name == "crown (gap only)":
        e["punch"]["shape"]["coefficients"][2] *= factor
    return e


SLIDERS = ("top thickness", "middle modulus", "top Poisson ratio", "half-width",
           "base thickness", "crown (gap only)")


def slider_costs() -> list[str]:
    """Median CPU and wall seconds per step of each slider, and the largest relative
    change of the default answer from the finest."""
    base = rounded_graded()
    solve(base)  # imports and the Chebyshev rows of the preset, as in a served page
    rows = []
    for name in SLIDERS:
        cpu, wall, diffs = [], [], []
        for k in range(1, STEPS + 1):
            d = _step(base, name, k)
            start = time.process_time()
            result = solve(d)
            cpu.append(time.process_time() - start)
            wall.append(result.info["seconds"])
            fine = copy.deepcopy(d)
            fine.setdefault("solver", {})["tol"] = 1e-12
            ref = solve(fine)
            a = d["punch"]["half_width"]
            sizes = {q: float(np.max(np.abs(getattr(ref, q)))) for q in QUANTITIES}
            # as the solver measures: kinematics against max(|delta|, a |alpha|), statics
            # against max(|P|, |M| / a) (a zero tilt or moment has no relative error)
            kinematic = max(sizes["settlement"], a * sizes["tilt"])
            static = max(sizes["force"], sizes["moment"] / a)
            for q, scale in (("settlement", kinematic), ("tilt", kinematic / a),
                             ("force", static), ("moment", static * a)):
                change = float(np.max(np.abs(getattr(result, q) - getattr(ref, q))))
                diffs.append(change / scale)
        rows.append(f"| {name} | {result.info['coating_model']} | {result.info['n_modes']} | "
                    f"{result.info['n_nodes']} | {1e3 * np.median(cpu):.1f} | "
                    f"{1e3 * np.median(wall):.1f} | {max(diffs):.1e} |")
        print(rows[-1], flush=True)
    return rows


def modulus_series(points: int = 100) -> str:
    """CPU seconds per point of a serial loop over the coating modulus."""
    from benchmarks.sweep import elastic_scene

    base = elastic_scene()
    solve(base)
    start = time.process_time()
    for modulus in np.geomspace(5e7, 2e10, points):
        d = copy.deepcopy(base)
        d["coating"][0]["modulus"] = float(modulus)
        solve(d)
    per_point = (time.process_time() - start) / points
    return (f"{points} coating moduli (50 MPa to 20 GPa) on the study scene of "
            f"`benchmarks/sweep.py` (uniform_flat, elastic base), serial in this process: "
            f"**{1e3 * per_point:.1f} ms of CPU per point** (1,000 points: "
            f"{per_point * 1000:.0f} s of CPU, {per_point * 500:.0f} s on each of 2 workers).")


def cluster_study(workers: int = 2) -> str:
    """The 1,000-point coating-modulus study of ``benchmarks/sweep.py`` on ``workers``."""
    from benchmarks.sweep import modulus_study, on_fresh_cluster

    run = on_fresh_cluster(modulus_study(1000), workers)
    return (f"The 1,000-point coating-modulus study of `benchmarks/sweep.py` on a fresh "
            f"cluster of {workers} workers: **{run['seconds']:.1f} s wall, {run['cpu']:.1f} s "
            f"of the workers' CPU** (goal: 30 s on 2 cores; load average {run['load']:.1f} "
            f"after it, cluster start {run['start']:.1f} s, {run['failed']} points failed).")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--study", action="store_true",
                        help="also run the 1,000-point modulus study on 2 Dask workers")
    args = parser.parse_args(argv)
    load_before = os.getloadavg()[0]
    rows = slider_costs()
    series = modulus_series()
    if args.study:
        series += "\n\n" + cluster_study()
    print(series, flush=True)
    load_after = os.getloadavg()[0]
    lines = [
        "# A new geometry on the exact layered path", "",
        "Made by `OPENBLAS_NUM_THREADS=1 python -m benchmarks.layered_speed"
        + (" --study" if args.study else "") + "` (see its "
        f"docstring). Load average (1 min) {load_before:.1f} at the start, "
        f"{load_after:.1f} at the end, on a shared 2-core machine: CPU times are of this "
        "process, wall times (`info[\"seconds\"]`) include the time others held the cores.",
        "", "Before (commit 0127960: the symbol from one linear system per wavenumber, a "
        "finer u-rule and the finest table and quadrature at every tolerance): a new "
        "rounded_graded coating ~550 ms of CPU (0.75 s of it the stack's table), the "
        "study scene 149 ms of CPU per modulus (same loop, load average 6.3).",
        "", "## rounded_graded, one slider at a time (10 steps of 1 %)", "",
        "| slider | model | modes | nodes | CPU per step [ms] | info seconds [ms] | "
        "default vs finest |", "| --- | --- | --- | --- | --- | --- | --- |", *rows, "",
        "`default vs finest`: the largest change of settlement, tilt, force and moment "
        "between tol 1e-6 (coarser table and quadrature) and tol 1e-12, relative to "
        "max(|delta|, a |alpha|) and max(|P|, |M| / a).", "",
        "## Coating modulus series", "", series, ""]
    out = ROOT / "benchmarks" / "results" / "layered_speed.md"
    out.write_text("\n".join(lines))
    print(out.read_text())


if __name__ == "__main__":
    main()
