"""The seed's projection method: an adaptive mode count over a pipeline of cached stages.

The dimensionless problem (model notes; the seed's (9)-(12)):

    c(t) m(x) q(x,t) + (I - V) F q = delta(t) + alpha(t) x - g(x),   -1 <= x <= 1,  t >= 1,
    int q dx = P(t),   int x q dx = M(t).

With ``m q = -g/c + sum_j a_j(t) p_j(x)`` (the rough part ``g/(c m)`` carried exactly, the
``p_j`` orthonormal for the weight ``1/m``) the Galerkin rows decouple into one scalar
Volterra equation per mode (:mod:`core.problem.statements`, :mod:`core.time`).

Stages and what each depends on (each cached on exactly these inputs, :mod:`core.cache`):

============  ===============================================  ==============================
stage         inputs                                           result
============  ===============================================  ==============================
panels        lam, breakpoints, samples of m and g, basis cap  quadrature panels
operator      lam, panels                                      discrete operator F (N x N)
basis         panels, m at the nodes, breakpoints, kind, cap   orthonormal functions p_j
galerkin      operator, basis                                  R_ij
gap           operator, basis, g at the nodes                  G_i, int g/m, int x g/m
modes         galerkin, statement, n                           eigenpairs of the free block
time          modes, c, K, the loads, times                    a_j(t) and the four scalars
============  ===============================================  ==============================

A change of the loads only re-runs the last stage; an elastic base skips time stepping.
The error estimate compares consecutive mode levels (:mod:`core.engines.projection.levels`).
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from core.creep import fit_advice
from core.engines.projection.levels import (
    _difference,
    _extrapolated_error,
    _LevelResult,
    _relative_residual,
    _Superposition,
)
from core.engines.projection.stages import _discretize, _Inputs, _modes
from core.problem import UNRESOLVED_ADVICE, ContactSolution, accepts, statement_number

Scalar = float | Callable[[np.ndarray], np.ndarray]

#: Mode counts tried in turn; the error estimate compares consecutive levels.
MODE_LEVELS = (4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512)
#: Basis sizes built (a larger one only when a smaller one could not meet tol).
BASIS_CAPS = (128, 256, 512)
#: Below this tol the first basis built is the largest; the graded basis is always built
#: at the largest cap (its first n functions are those of a basis of n, so the levels of
#: one basis of 512 cover every smaller cap). Measured on five scenes (smooth, jump,
#: stepped, thin base, m = 1e-4; new scenes): the sum of CPU at tol 1e-4 / 1e-6 was
#: 2.65 / 3.05 s building 128, 256 then 512 as needed, 2.04 / 2.09 s building 512 at once.
DIRECT_LARGEST_BELOW = 1e-7
#: Quadrature and round-off floor of the relative error (measured: ~1e-13 on the scenes
#: of the test suite; see tests/solver/test_solver.py).
ERROR_FLOOR = 2e-13
#: Success is claimed only when the error estimate is this many times below tol: the
#: estimate itself can read ~3x low (see _extrapolated_error).
SUCCESS_MARGIN = 3.0



def _fast_kernel(inp: _Inputs) -> tuple[_Inputs, float]:
    """The kernel to step with, and the error of its fit (see core.creep.stepping_kernel)."""
    from core.creep import stepping_kernel

    kernel, fit_error = stepping_kernel(inp.kernel, float(inp.times[-1]),
                                        0.5 * inp.tol / SUCCESS_MARGIN)
    return replace(inp, kernel=kernel), fit_error



def check_options(basis: Any, n_modes: Any) -> None:
    """Refuse a ``basis`` or ``n_modes`` the projection does not know, naming it."""
    if basis not in ("piecewise", "global", "graded"):
        raise ValueError(f"basis: must be 'piecewise', 'global' or 'graded', got {basis!r}")
    if n_modes is not None and (isinstance(n_modes, bool) or not isinstance(n_modes, int)
                                or not 2 <= n_modes <= BASIS_CAPS[-1]):
        raise ValueError(f"n_modes: must be an integer in [2, {BASIS_CAPS[-1]}], got {n_modes}")


def solve_projection(inp: _Inputs, basis: str = "graded",
                     n_modes: int | None = None) -> ContactSolution:
    """Solve validated inputs (:func:`validate_inputs`) by the projection method.

    ``basis`` is "graded", "piecewise" or "global"; ``n_modes`` a fixed mode count (else
    adaptive). Returns the full-contact :class:`ContactSolution` (dimensionless).
    """
    t_start = _time.perf_counter()
    tol = inp.tol
    check_options(basis, n_modes)
    inp, kernel_fit_error = _fast_kernel(inp)
    stages: dict[str, dict] = {}
    times_arr = inp.times
    c_t = inp.c(times_arr)
    # Probe times for choosing the mode count: all of them for an elastic base (cheap),
    # else the first, last and a few in between.
    if inp.kernel is None or times_arr.size <= 5:
        probe_idx = np.arange(times_arr.size)
    else:
        probe_idx = np.unique(np.linspace(0, times_arr.size - 1, 5).round().astype(int))
    probe_times = times_arr[probe_idx]
    # Time error budget: the step-doubling estimate adds local errors (an upper bound that
    # read up to ~20x the true error on decaying creep), so the steps aim ten times lower
    # than the share they would need, keeping the reported estimate close to the truth.
    time_tol = tol / 30

    flags: list[str] = []
    chosen: _LevelResult | None = None
    spatial_error = np.inf
    disc = None
    n_used = 0
    # The basis built (and, for the seed's bases, the panels) depends on the cap, so a
    # fixed mode count always uses the same one whatever tol says.
    if n_modes is not None:
        caps = next((cap,) for cap in BASIS_CAPS if n_modes <= cap)
    elif inp.tol < DIRECT_LARGEST_BELOW or basis == "graded":
        caps = BASIS_CAPS[-1:]
    else:
        caps = BASIS_CAPS
    for cap in caps:
        disc = _discretize(inp, cap, basis, stages)
        size = disc.basis.size
        if n_modes is not None:
                        levels = [lv for lv in MODE_LEVELS if lv < min(n_modes, size)][-2:] + [
                min(n_modes, size)]
        else:
            levels = [lv for lv in MODE_LEVELS if lv < size] + [size]
        diffs: list[float] = []
        prev_probe: _LevelResult | None = None
        probe_chain: list[_LevelResult] = []
        c_probe = c_t[probe_idx]
        t_probe = _time.perf_counter()
        probe_stage = _Superposition(replace(inp, kernel=None), disc, probe_times, time_tol)
        for n in levels:
            ms = _modes(disc, inp.given, n, stages)
            res = probe_stage.solve([ms])[0][0]
            if prev_probe is not None:
                diffs.append(_difference(res, prev_probe, disc, c_probe))
            probe_chain.append(res)
            prev_probe = res
            if n_modes is None and len(diffs) >= 2:
                est = max(_extrapolated_error(diffs), ERROR_FLOOR)
                if est <= 0.5 * tol / SUCCESS_MARGIN and _relative_residual(
                        res, disc, inp, probe_times) <= 0.5 * tol / SUCCESS_MARGIN:
                    break
        entry = stages.setdefault("mode_selection", {"seconds": 0.0, "cached": False})
        entry["seconds"] += _time.perf_counter() - t_probe
        est = max(_extrapolated_error(diffs), ERROR_FLOOR,
                  _relative_residual(probe_chain[-1], disc, inp, probe_times))
        n_used = probe_chain[-1].n
        if est <= 0.5 * tol / SUCCESS_MARGIN or n_modes is not None or cap == BASIS_CAPS[-1]:
            spatial_error = est
            n_prev = probe_chain[-2].n if len(probe_chain) > 1 else None
            break

    assert disc is not None
    t_time = _time.perf_counter()
    time_cached = False
    if inp.kernel is None and probe_idx.size == times_arr.size:
        chosen = probe_chain[-1]
    else:
        systems = [_modes(disc, inp.given, n_used, stages)]
        if n_prev is not None and inp.kernel is not None:
            # The spatial estimate above is elastic; check it on the creeping answer.
            systems.append(_modes(disc, inp.given, n_prev, stages))
        results, time_cached = _Superposition(inp, disc, times_arr, time_tol).solve(systems)
        chosen = results[0]
        if len(results) > 1:
            d_creep = _difference(chosen, results[1], disc, c_t)
            creep_diffs = [d_creep * diffs[-2] / diffs[-1], d_creep] if (
                len(diffs) >= 2 and diffs[-1] > 0) else [d_creep]
            spatial_error = max(spatial_error, _extrapolated_error(creep_diffs), ERROR_FLOOR)
    stages["time"] = {"seconds": _time.perf_counter() - t_time, "cached": time_cached}

    error_estimate = float(spatial_error + chosen.time_error + kernel_fit_error)
    success = accepts(error_estimate, tol, SUCCESS_MARGIN) and chosen.time_success
    if not disc.resolved:
        flags.append("unresolved_input")
    if not success:
        flags.append("tol_not_met")
    # Contact: q >= 0 must hold on the whole of [-1, 1] at every time.
    x_check = disc.check_x
    phi_check = disc.check_phi[:, : chosen.n]
    q_check = (phi_check @ chosen.coefficients
               - np.outer(inp.g(x_check), 1.0 / c_t)) / inp.m(x_check)[:, None]
    q_scale = max(float(np.max(np.abs(q_check))), 1e-300)
    min_q = float(np.min(q_check))
    if min_q < -max(error_estimate, 1e-12) * q_scale:
        flags.append("contact_lost")
    if success:
        message = (f"converged: estimated error {error_estimate:.1e} <= tol {tol:.1e}/"
                   f"{SUCCESS_MARGIN:g} with {chosen.n} modes")
    else:
        reasons = []
        if spatial_error * SUCCESS_MARGIN > tol:
            reasons.append(f"the basis reached {chosen.n} modes with estimated error "
                           f"{spatial_error:.1e}")
        if not chosen.time_success:
            reasons.append(f"time stepping: {chosen.time_message} (estimated error "
                           f"{chosen.time_error:.1e})")
        elif chosen.time_error * SUCCESS_MARGIN > tol:
            reasons.append(f"time stepping: estimated error {chosen.time_error:.1e}")
        if kernel_fit_error * SUCCESS_MARGIN > tol:
            reasons.append(f"the creep kernel's exponential fit has error {kernel_fit_error:.1e} "
                           f"({fit_advice(kernel_fit_error)})")
        message = (f"tol {tol:.1e} not met (success needs the estimate below tol/"
                   f"{SUCCESS_MARGIN:g}): " + "; ".join(reasons))
    if not disc.resolved:
        message += f"; {UNRESOLVED_ADVICE}"
    info = {
        "method": "projection",
        "error_estimate": error_estimate,
        "spatial_error_estimate": float(spatial_error),
        "time_error_estimate": float(chosen.time_error),
        "kernel_fit_error": float(kernel_fit_error),
        "seconds": _time.perf_counter() - t_start,
        "flags": flags,
        "success": bool(success),
        "message": message,
        "n_modes": int(chosen.n),
        "n_steps": int(chosen.steps),
        "n_nodes": int(disc.panels.size),
        "statement": statement_number(inp.given),
        "given": sorted(inp.given),
        "min_pressure": min_q,
        "max_pressure": q_scale,
        "basis": disc.basis.kind,
        # Where q may have a kink (element ends of the basis) or a jump (breakpoints).
        "element_ends": sorted(set(disc.cuts) | set(inp.breakpoints)),
        "orthonormality_error": disc.basis.orthonormality_error,
        "stages": stages,
    }
    full = ContactSolution(times_arr.copy(), chosen.settlement, chosen.tilt, chosen.force,
                           chosen.moment, info, disc.basis, chosen.coefficients, c_t, inp.m,
                           inp.g)
    return full
