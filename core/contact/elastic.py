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

from core.contact.active_set import SHRINKS, NoContact, refused_load, zones_from_nodes
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
                raise exc.at(times[k], given, f"{refused_load(given)}: {exc.what} ({exc}) "
                             f"at t = {times[k]:g}") from None
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
    if state.active.any():
        ends, pinned, slopes = zones_from_nodes(state, space.breakpoints)
    else:
        # Only a given settlement and tilt can leave the punch above the surface; where it
        # still presses into it between the nodes, the zones start from there
        ends, pinned, slopes = pressed_between_nodes(space, state.settlement, state.tilt)
        if not ends:
            zero = np.zeros(state.q.size)
            snap = _Snapshot(state.panels, zero, state.settlement, state.tilt, step, [])
            return snap, {"zone_end_error": 0.0, "error_estimate": 0.0, "verified": True,
                          "converged": True, "builds": 0, "force": 0.0, "moment": 0.0}
        try:
            return _zones_from(space, step, base, ends, pinned, slopes, res, tol)
        except (ArithmeticError, np.linalg.LinAlgError):
            # (a stretch 1e-10 wide left the zone's rule a panel of no width)
            raise NoContact(SHRINKS) from None
    return _zones_from(space, step, base, ends, pinned, slopes, res, tol)


def _zones_from(space: Space, step: Step, base: Panels, ends: list[float],
                pinned: list[bool], slopes: list[float], res: Resolution, tol: float
                ) -> tuple[_Snapshot, dict]:
    """The zones refined from their first ``ends`` (:func:`refine_zone_ends`), checked."""
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


#: Points of the even sample on which a punch held by its settlement and tilt is checked
#: for pressing into the coating where no node of the nodal rule is in contact.
PRESS_SAMPLES = 8193
#: Local maxima of that sample looked at more finely, at most.
MAX_CRESTS = 256


def pressed_between_nodes(space: Space, settlement: float, tilt: float
                          ) -> tuple[list[float], list[bool], list[float]]:
    """The stretches where a punch at ``settlement`` and ``tilt`` (given) presses into the
    coating, ``p(x) = delta + alpha x - g(x) > 0``: the zones a contact starts from when no
    node of the nodal rule is in contact (ends, pinned flags, slopes of Q as
    :func:`~core.contact.active_set.zones_from_nodes`); none where it presses nowhere.

    ``p`` is read on an even sample of [-1, 1] (:data:`PRESS_SAMPLES`), and 1024 times
    finer between the neighbours of each of its local maxima that the sample's curvature
    allows to rise above 0 between samples (two equal crests: both). Each stretch's ends
    are its roots; an end whose bracket holds a breakpoint (a step of g) is pinned there,
    as :func:`~core.contact.active_set.zones_from_nodes` pins it. The contact lies within
    these stretches (the coating and the base give way). A crowned punch (g = 0.1 x^2,
    m = 0.05) held 1e-7 below its first touch presses on +-1e-3, between the nodes: it
    was answered "no contact", P = 0, with success and an estimate of 0.
    """
    from scipy.optimize import brentq

    def pressed(x: np.ndarray) -> np.ndarray:
        return settlement + tilt * x - np.asarray(space.g(x), dtype=float) * np.ones(x.size)

    x = np.linspace(-1.0, 1.0, PRESS_SAMPLES)
    p = pressed(x)
    samples = [(x, p)]
    # local maxima below 0 that a parabola through them and their neighbours lifts above
    inner = np.arange(1, x.size - 1)
    bend = np.abs(p[:-2] - 2.0 * p[1:-1] + p[2:])
    crests = inner[(p[1:-1] >= p[:-2]) & (p[1:-1] >= p[2:]) & (p[1:-1] <= 0.0)
                   & (p[1:-1] + 0.5 * bend > 0.0)]
    for k in crests[:MAX_CRESTS]:
        fine = np.linspace(x[k - 1], x[k + 1], 1025)
        samples.append((fine, pressed(fine)))
    cuts = sorted(float(b) for b in space.breakpoints)
    found: list[tuple[float, bool, float]] = []
    for xs, ps in samples:
        inside = ps > 0.0
        flips = np.flatnonzero(np.diff(np.concatenate([[0], inside.astype(np.int8), [0]])))
        for i, j in zip(flips[0::2], flips[1::2] - 1, strict=True):
            for k, side in ((int(i), -1), (int(j), 1)):
                outer = k + side
                if outer < 0 or outer >= xs.size:
                    found.append((float(xs[k]), abs(float(xs[k])) == 1.0, 0.0))
                    continue
                lo, hi = sorted((float(xs[outer]), float(xs[k])))
                step = [b for b in cuts if lo <= b <= hi]
                if step:  # (p jumps there: the zone ends at the step's corner)
                    found.append((step[0], True, 0.0))
                    continue
                end = float(brentq(lambda t: float(pressed(np.array([t]))[0]), lo, hi,
                                   xtol=1e-15))
                inward = -1e-9 * side  # into the stretch
                rise = float(pressed(np.array([end + inward]))[0]) / abs(inward)
                m_end = float(np.asarray(space.m(np.array([end])), dtype=float).ravel()[0])
                # Q rises into the zone: > 0 at its start, < 0 at its end
                found.append((end, False, -side * abs(rise) / m_end))
    # (each fine sample lies between two points of the even one that do not press: its
    # stretches are apart from the even sample's)
    found.sort(key=lambda item: item[0])
    ends = [e for e, _, _ in found]
    if len(ends) % 2 or any(b <= a for a, b in zip(ends[0::2], ends[1::2], strict=True)):
        raise NoContact(SHRINKS)  # (stretches the samples did not part cleanly)
    return ends, [f for _, f, _ in found], [s for _, _, s in found]


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
