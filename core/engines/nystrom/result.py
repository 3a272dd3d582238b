"""The result object of a prepared (Nystrom) solve: success, message, flags and timings.

Kept apart from :mod:`core.engines.nystrom.prepared`, which computes the answer; this module
only judges it against ``tol`` and packs it like the other engines do (``ContactSolution`` with an
``info`` dict in the spirit of scipy's ``OdeResult``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.creep import FIT_ERROR_SHARE, fit_advice
from core.problem import (
    QUANTITIES,
    UNRESOLVED_ADVICE,
    ContactSolution,
    TimeInputs,
    accepts,
    statement_number,
)

#: Margin of :func:`core.problem.accepts`: the estimate (the two-grid difference of
#: :mod:`core.engines.nystrom.adapt` plus the step-doubling of the time stepping, which
#: read up to ~20x high on decaying creep) is taken as it stands.
SUCCESS_MARGIN = 1.0


@dataclass(frozen=True)
class TimeSide:
    """What the time side of a solve adds: its error estimate, steps and verdict."""

    error: float = 0.0  # estimated relative error of the time stepping and kernel fit
    steps: int = 0
    ok: bool = True
    message: str = "elastic base"
    fit_error: float = 0.0  # the creep kernel's sum-of-exponentials fit (in ``error``)


def nystrom_solution(prepared: Any, inputs: TimeInputs, scalars: dict[str, np.ndarray],
                     pressure: Callable[[np.ndarray], np.ndarray],
                     q_extremes: tuple[float, float], time_side: TimeSide, seconds: float,
                     built: dict[str, int], max_abs_tilt: float, first_solve: bool
                     ) -> ContactSolution:
    """Pack the answer of ``prepared.solve`` (a :class:`core.engines.nystrom.PreparedContact`).

    ``q_extremes``: (min q, max |q|) over the check points and probe times; ``seconds``:
    time of this solve [s]; ``built``: cached members this solve built.
    """
    tol = prepared.geometry.tol
    time_error = time_side.error
    error = float(prepared.spatial_error + time_error)
    success = accepts(error, tol, SUCCESS_MARGIN) and prepared.resolved and time_side.ok
    flags = []
    narrowest = getattr(prepared, "narrowest", False)
    if not prepared.resolved:
        flags.append("unresolved_input")
    if not success:
        flags.append("tol_not_met")
    min_q = float(q_extremes[0])
    q_scale = max(float(q_extremes[1]), 1e-300)
    if min_q < -max(error, 1e-12) * q_scale:
        flags.append("contact_lost")
    grid = prepared.grid
    n = grid.size
    if success:
        message = (f"converged: estimated error {error:.1e} <= tol {tol:.1e} "
                   f"({n} nodes, {grid.panels.n_panels} panels)")
    else:
        reasons = []
        if narrowest:
            # (the edges' grading runs out there whether tol is past what double
            # precision gives, or an undeclared jump inside keeps the estimate up)
            reasons.append(
                "the grading toward the punch's edges and the jumps reached the narrowest "
                "panels double precision resolves, "
                + (f"with estimated error {prepared.spatial_error:.1e} in q: a tol no finer "
                   "than that can be met"
                   if np.isfinite(prepared.spatial_error) else
                   "before an error of q could be estimated: a looser tol")
                + f", unless {UNRESOLVED_ADVICE}")
        elif prepared.spatial_error > tol or not prepared.resolved:
            reasons.append(f"the grid reached {grid.panels.n_panels} panels with "
                           f"estimated error {prepared.spatial_error:.1e} in q"
                           + ("" if prepared.resolved else f" ({UNRESOLVED_ADVICE})"))
        if not time_side.ok:
            reasons.append(f"time stepping: {time_side.message} (estimated error "
                           f"{time_error:.1e})")
        elif time_error > tol:
            # the stepping finished; its estimate holds the creep kernel's fit as well
            reasons.append(f"time stepping: estimated error {time_error:.1e}, of which the "
                           f"creep kernel's exponential fit {time_side.fit_error:.1e}"
                           + (f" ({fit_advice(time_side.fit_error)})"
                              if FIT_ERROR_SHARE * time_side.fit_error > tol else ""))
        message = f"tol {tol:.1e} not met: " + "; ".join(reasons or ["see the estimate"])
    counts = prepared.counts
    info = {
        "method": "nystrom",
        "error_estimate": error,
        "spatial_error_estimate": float(prepared.spatial_error),
        "time_error_estimate": float(time_error),
        # the creep kernel's sum-of-exponentials fit (included in the time estimate)
        "kernel_fit_error": float(time_side.fit_error),
        "seconds": seconds,
        "prepare_seconds": prepared.seconds,
        "flags": flags,
        "success": bool(success),
        "message": message,
        "n_modes": n,
        "n_nodes": n,
        "n_panels": grid.panels.n_panels,
        "n_steps": int(time_side.steps),
        "statement": statement_number(inputs.given),
        "given": sorted(inputs.given),
        # over the output times and the samples between them (HISTORY_SAMPLES)
        "min_pressure": min_q,
        "max_abs_tilt": max_abs_tilt,
        "max_pressure": q_scale,
        "basis": "nystrom",
        "element_ends": list(prepared.element_ends),
        # "grid" is the geometric stage (prepared once); "bordered"/"modal" the
        # factorization of a statement; "cached" says whether this solve built it (on
        # the geometry's first answer, a factorization the contact check before it
        # built counts as built by this request).
        "stages": {"grid": {"seconds": prepared.seconds, "cached": not first_solve},
                   **{k: {"seconds": 0.0,
                          "cached": not first_solve and built.get(k, 0) == 0}
                      for k in ("bordered", "modal") if k in counts},
                   "solve": {"seconds": seconds, "cached": False}},
        "builds": dict(counts),
    }
    return ContactSolution(inputs.times.copy(), *(np.asarray(scalars[q], dtype=float)
                                                  for q in QUANTITIES),
                           info, None, None, None, prepared.geometry.m, prepared.geometry.g,
                           pressure)
