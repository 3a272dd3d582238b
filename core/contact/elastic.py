"""Lift-off on an elastic base: every output time solved on its own.

At each time the nodal active set (:mod:`core.contact.nodal`) gives the zones to within a
node, their free ends are then located exactly (:func:`core.contact.refine_zone_ends`),
ends pinned at +-1 or a breakpoint are checked to be corners indeed, and the answer is
checked against the contact conditions on the nodal rule.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from core.contact.active_set import NoContact, refused_load, zones_from_nodes
from core.contact.nodal import nodal_operator, nodal_state
from core.contact.result import UNILATERAL_MARGIN, _Snapshot, not_within_tol
from core.contact.step import Space, Step, nystrom_pressure
from core.contact.zones import ZONE_END_TOL, Resolution, refine_zone_ends, zone_kernel_accuracy
from core.discretize import Panels
from core.problem import accepts


def _solve_elastic(space: Space, c_t: np.ndarray, loads: dict[str, np.ndarray],
                   times: np.ndarray, nodal_res: Resolution, res: Resolution,
                   tol: float) -> dict[str, Any]:
    """Every time on its own (equal data solved once)."""
    base, op = nodal_operator(space.lam, space.breakpoints, nodal_res)
    m_nodes = space.m(base.nodes)
    g_nodes = space.g(base.nodes)
    results: dict[tuple, tuple] = {}
    per_time = []
    for k in range(times.size):
        given = {name: float(v[k]) for name, v in loads.items()}
        key = (float(c_t[k]),) + tuple(sorted(given.items()))
        if key not in results:
            step = Step(float(c_t[k]), 1.0, given)
            try:
                results[key] = _solve_one(space, step, base, op, m_nodes, g_nodes, res, tol,
                                          nodal_res)
            except NoContact as exc:
                raise exc.at(times[k], given, f"{refused_load(given)}: the loads pull the "
                             f"punch away ({exc}) at t = {times[k]:g}") from None
        per_time.append(results[key])
    snapshots = [r[0] for r in per_time]
    end_error = max(r[1]["zone_end_error"] for r in per_time)
    error = max(r[1]["error_estimate"] for r in per_time)
    verified = all(r[1]["verified"] for r in per_time)
    converged = all(r[1]["converged"] for r in per_time)
    info = {
        **verdict(error, end_error, verified, converged, tol, "elastic"),
        "n_steps": int(times.size),
        "n_solves": len(results),
        "n_nodes": max(int(r[0].panels.size) for r in per_time),
        "operator_builds": sum(r[1]["builds"] for r in results.values()),
        "min_pressure": 0.0,
    }
    return {
        # q(x) to the kernel accuracy of the zone operators (the solve's own error is
        # larger): 201 rows of the study's outputs 2.3 -> 1.6 ms CPU (measured)
        "kernel_accuracy": zone_kernel_accuracy(tol),
        "settlement": np.array([s.settlement for s in snapshots]),
        "tilt": np.array([s.tilt for s in snapshots]),
        "force": np.array([r[1]["force"] for r in per_time]),
        "moment": np.array([r[1]["moment"] for r in per_time]),
        "contact_set": [list(s.zones) for s in snapshots],
        "snapshots": snapshots,
        "info": info,
    }


def _solve_one(space: Space, step: Step, base: Panels, op: np.ndarray, m_nodes: np.ndarray,
               g_nodes: np.ndarray, res: Resolution, tol: float,
               nodal_res: Resolution | None = None) -> tuple[_Snapshot, dict]:
    state = nodal_state(space, step, base, op, m_nodes, g_nodes, nodal_res)
    if not state.active.any():
        # Only a given settlement and tilt can leave the punch above the surface.
        zero = np.zeros(state.q.size)
        snap = _Snapshot(state.panels, zero, state.settlement, state.tilt, step, [])
        return snap, {"zone_end_error": 0.0, "error_estimate": 0.0, "verified": True,
                      "converged": True, "builds": 0, "force": 0.0, "moment": 0.0}
    ends, pinned, slopes = zones_from_nodes(state, space.breakpoints)
    refined = refine_zone_ends(space, step, ends, pinned, slopes, res, tol=tol)
    sol = refined.solution
    bad_pin = _bad_pins(space, step, sol, pinned)
    if bad_pin:
        ends = list(sol.ends)
        for k in bad_pin:
            pinned[k] = False
            if abs(ends[k]) == 1.0:
                ends[k] = float(np.sign(ends[k]) * (1.0 - 1e-6))
            slopes[k] = (1.0 if k % 2 == 0 else -1.0) * sol.q_scale * 1e3
        refined = refine_zone_ends(space, step, ends, pinned, slopes, res, tol=tol)
        sol = refined.solution
    zones = [(float(sol.ends[2 * i]), float(sol.ends[2 * i + 1]))
             for i in range(len(sol.ends) // 2)]
    verified = _verify(space, step, sol, base, zones, zone_kernel_accuracy(tol))
    snap = _Snapshot(sol.panels, sol.q, sol.settlement, sol.tilt, step, zones)
    return snap, {"zone_end_error": refined.end_error, "error_estimate": refined.output_error,
                  "verified": verified, "converged": refined.converged,
                  "builds": refined.builds, "force": sol.force, "moment": sol.moment}


def _bad_pins(space: Space, step: Step, sol, pinned: list[bool],
              memory_at: Callable[[np.ndarray], np.ndarray] | None = None) -> list[int]:
    """Pinned ends that are free ends in fact.

    At +-1 or a breakpoint the zone may end with q > 0 (a corner of the punch); it must
    not end with Q < 0 inside (the zone is shorter: a free end within a node of it) nor
    with Q > 0 just outside (the surfaces would overlap there: the zone is longer).
    ``memory_at``: the displacement e(x) the rest of the base adds (other punches).
    """
    bad = []
    scale = 1e-9 * sol.q_scale
    for k, is_pinned in enumerate(pinned):
        if not is_pinned:
            continue
        if sol.end_values[k] < -scale:
            bad.append(k)
            continue
        end = sol.ends[k]
        if abs(end) < 1.0:
            outward = -1.0 if k % 2 == 0 else 1.0
            outside = nystrom_pressure(space, step, sol.panels, sol.q, sol.settlement,
                                       sol.tilt, np.array([end]), np.array([outward]),
                                       memory_at)[0]
            if outside > scale:
                bad.append(k)
    return bad


def _verify(space: Space, step: Step, sol, base: Panels, zones, accuracy: float,
            memory_at: Callable[[np.ndarray], np.ndarray] | None = None) -> bool:
    """q >= 0 on the zones and the gap open (Q <= 0) at the base nodes off them (the
    kernel values to ``accuracy``, far below the check's 1e-8 of max q); ``memory_at``
    as in :func:`_bad_pins`."""
    scale = sol.q_scale
    if np.min(sol.q) < -1e-8 * scale:
        return False
    x = base.nodes
    inside = np.zeros(x.size, dtype=bool)
    for lo, hi in zones:
        inside |= (x >= lo) & (x <= hi)
    off = x[~inside]
    if off.size == 0:
        return True
    values = nystrom_pressure(space, step, sol.panels, sol.q, sol.settlement, sol.tilt, off,
                              memory_at=memory_at, accuracy=accuracy)
    return bool(np.max(values) <= 1e-8 * scale)


def verdict(error: float, end_error: float, verified: bool, converged: bool, tol: float,
            what: str) -> dict[str, object]:
    """The verdict of an elastic unilateral answer as its info entries (``contact``,
    ``error_estimate``, ``zone_end_error``, ``success``, ``flags``, ``message``): from its
    estimated error of q and the scalars (``error``, relative), of the zone ends
    (``end_error``, half-widths), whether its contact set passed its check and the zone
    ends converged; ``what`` names the problem in the message (``"elastic"``, ``"elastic,
    2 punches"``)."""
    success = (accepts(error, tol, UNILATERAL_MARGIN) and end_error <= ZONE_END_TOL
               and verified and converged)
    flags = [] if success else ["tol_not_met"]
    if not verified:
        flags.append("contact_set_unverified")
    message = (f"unilateral contact ({what}): estimated error {error:.1e}, zone ends to "
               f"{end_error:.1e} half-widths")
    if not success:
        message += (not_within_tol(error, end_error, tol, ZONE_END_TOL)
                    + ("" if converged else "; the zone ends did not converge")
                    + ("" if verified else "; the contact set failed its check (q < 0 on "
                       "it or the surfaces overlap off it)"))
    return {"contact": "unilateral", "error_estimate": float(error),
            "zone_end_error": float(end_error), "success": bool(success), "flags": flags,
            "message": message}
