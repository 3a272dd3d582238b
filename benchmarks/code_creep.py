"""Speed and accuracy of creep by the design codes over 50 years (fitted kernels).

Run from the repository root:

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.code_creep [--repeats 5]

Reports, for the preset ``core/presets/scenes/young_concrete_50_years.json`` (fib MC2010 and
EN 1992-1-1, 200 output times over 50 years, tol 1e-4):

* the kernel fit alone (cold, median), a new scene (caches cleared: fit, geometry and
  time stepping) and a load change (everything cached but the loads' response);
* the error of the settlement against a tighter reference: the same scene with a finer
  fit of the code's compliance (6 retardation times a decade, 80 ages: finer than the
  finest of ``core.creep.design_codes.FIT_LEVELS``) solved at tol 1e-9, relative to the
  largest settlement;
* a plain callable kernel (Arutyunyan, 100 output times over 1000 days, tol 1e-4):
  stepped through its exponential fit against the product-quadrature path.

Timings are medians of ``--repeats`` runs on a shared machine: noisy; the CPU time of the
process is printed next to the wall time (it is inflated far less by other work).
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import numpy as np

from benchmarks.creep_goals import timed
from core.cache import clear_caches
from core.creep.code_formulas import _FORMULAS, clamp_age
from core.creep.design_codes import MAX_DURATION, RESOLUTION, CodeCreep
from core.creep.kernel_fit import fit_compliance
from core.creep.models import Arutyunyan
from core.scene import scene_from_dict
from core.solver import solve_dimensionless

PRESET = Path(__file__).resolve().parents[1] / "core" / "presets" / "scenes" / \
    "young_concrete_50_years.json"


def _timed(fn, repeats: int, before=None) -> tuple[float, object]:
    """Median wall time [s] of ``repeats`` runs after a warm-up and the last answer (CPU
    time in ``_timed.cpu``: on a shared machine it is inflated far less than the wall
    time); see :func:`benchmarks.creep_goals.timed`."""
    cpu_ms, wall_ms, out = timed(fn, repeats, before)
    _timed.cpu = cpu_ms / 1e3
    return wall_ms / 1e3, out


def _fine_kernel(model: CodeCreep, tau0: float):
    """The code's compliance fitted more finely than the default (the reference)."""
    inputs = model.inputs
    modulus, phi = _FORMULAS[inputs.model]
    c = model.relative_modulus(tau0)
    scale = float(modulus(inputs, tau0) / modulus(inputs, 28.0))
    return fit_compliance(
        lambda t, tau: scale * phi(inputs, tau0 * t, tau0 * tau),
        end=1.0 + MAX_DURATION / tau0, resolution=RESOLUTION / tau0, modulus=c,
        log_slope=c.log_slope, breaks=(clamp_age(inputs) / tau0,), key=("fine", inputs, tau0),
        per_decade=6, age_nodes=80)


def code_scene(model_name: str, repeats: int) -> dict:
    data = json.loads(PRESET.read_text())
    data["base"]["creep"]["model"] = model_name
    scene = scene_from_dict(data)
    model, tau0 = scene.creep, scene.age_at_loading

    fit_s, _ = _timed(lambda: model.dimensionless_kernel(tau0, tol=scene.tol), repeats,
                      clear_caches)
    new_s, result = _timed(lambda: scene_from_dict(data).dimensionless.solve(), repeats,
                           clear_caches)
    new_cpu = _timed.cpu
    # one more than the runs: the warm-up takes the first
    loads = [dict(data, loading={"force": 6.0e5 * (1 + 0.01 * (k + 1)), "moment": 0.0})
             for k in range(repeats + 1)]
    problems = [scene_from_dict(d).dimensionless for d in loads]
    it = iter(problems)
    load_s, _ = _timed(lambda: next(it).solve(), repeats)
    load_cpu = _timed.cpu

    problem = scene.dimensionless
    reference = solve_dimensionless(problem.lam, problem.m, problem.g, problem.times,
                                    c=problem.c, kernel=_fine_kernel(model, tau0),
                                    tol=1e-9, **problem.loads)
    size = float(np.max(np.abs(reference.settlement)))
    error = float(np.max(np.abs(result.settlement - reference.settlement))) / size
    return {"model": model_name, "fit_ms": 1e3 * fit_s, "new_scene_ms": 1e3 * new_s,
            "load_change_ms": 1e3 * load_s,
            "new_scene_cpu_ms": 1e3 * new_cpu, "load_change_cpu_ms": 1e3 * load_cpu,
            "settlement_error": error,
            "error_estimate": result.info["error_estimate"],
            "kernel_fit_error": result.info["kernel_fit_error"],
            "steps": result.info["n_steps"], "reference_success": reference.info["success"]}


def plain_callable(repeats: int, count: int) -> dict:
    material = Arutyunyan(3e10, 0.5, 0.03, 0.9e-11, 4.8e-10, 0.03)
    exact = material.dimensionless_kernel(28.0)
    c = material.relative_modulus(28.0)
    times = np.linspace(1.0, 1.0 + 1000.0 / 28.0, count)
    args = dict(c=c, force=1.0, moment=0.0, tol=1e-4)
    reference = solve_dimensionless(0.5, 0.05, 0.0, times, kernel=exact,
                                    **dict(args, tol=1e-9))
    size = float(np.max(np.abs(reference.settlement)))
    import core.engines.nystrom.prepared as prepared
    import core.engines.projection.solve as solver

    def plain(t: np.ndarray, s: np.ndarray) -> np.ndarray:
        return exact(t, s)

    def run() -> object:
        return solve_dimensionless(0.5, 0.05, 0.0, times, kernel=plain, **args)

    out = {}
    for name in ("fitted, cold", "fitted, load change", "product quadrature"):
        keep, keep_prepared = solver._fast_kernel, prepared.stepping_kernel
        if name == "product quadrature":
            # the path a plain callable took before: keep the kernel from being fitted
            # (in both engines)
            solver._fast_kernel = lambda inp: (inp, 0.0)
            prepared.stepping_kernel = lambda kernel, t_end, budget: (kernel, 0.0)
        # a load change keeps the fit (cached on the kernel's values)
        before = None if name == "fitted, load change" else clear_caches
        try:
            seconds, sol = _timed(run, repeats if count <= 100 or name != "product quadrature"
                                  else 1, before)
        finally:
            solver._fast_kernel, prepared.stepping_kernel = keep, keep_prepared
        out[name] = {"ms": 1e3 * seconds, "cpu_ms": 1e3 * _timed.cpu,
                     "error": float(np.max(np.abs(
            sol.settlement - reference.settlement))) / size,
            "estimate": sol.info["error_estimate"]}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"50 years, 200 output times, tol 1e-4 (medians of {args.repeats} runs; load "
          f"average {os.getloadavg()[0]:.1f}); wall and CPU ms")
    print(f"{'model':12s} {'fit ms':>8s} {'new ms':>8s} {'new cpu':>8s} {'load ms':>8s} "
          f"{'load cpu':>8s} {'error':>9s} {'estimate':>9s} {'fit err':>9s} {'steps':>6s}")
    for name in ("fib_mc2010", "eurocode2"):
        r = code_scene(name, args.repeats)
        print(f"{r['model']:12s} {r['fit_ms']:8.1f} {r['new_scene_ms']:8.0f} "
              f"{r['new_scene_cpu_ms']:8.0f} {r['load_change_ms']:8.1f} "
              f"{r['load_change_cpu_ms']:8.1f} {r['settlement_error']:9.1e} "
              f"{r['error_estimate']:9.1e} {r['kernel_fit_error']:9.1e} {r['steps']:6d}")
    for count in (100, 1000):
        print(f"\nplain callable kernel (Arutyunyan), {count} output times over 1000 days, "
              "tol 1e-4")
        for name, r in plain_callable(args.repeats, count).items():
            print(f"{name:20s} {r['ms']:8.1f} ms (cpu {r['cpu_ms']:8.1f})  error "
                  f"{r['error']:.1e}  "
                  f"estimate {r['estimate']:.1e}")
    print(f"load average at the end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
