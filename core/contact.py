"""Unilateral contact: the punch may lift off, and the contact set is part of the answer.

:func:`solve_unilateral` solves the dimensionless problem of ``core/README.md`` with
``q >= 0`` and an unknown contact set ``S(t)`` in [-1, 1] (may have several pieces):

    c m q + (I - V) F q = delta + alpha x - g   on S(t),  q > 0 there,
    (I - V) F q >= delta + alpha x - g          off S(t), q = 0 there (the gap is open),
    int q dx = P,  int x q dx = M               (two of delta, alpha, P, M given).

Elastic base (``kernel=None``): each time is solved on its own, the zone ends located to
``ZONE_END_TOL`` by :mod:`core.contact_zones`. Creep: implicit stepping with the active
set found at every step, on a rule refined where the zone ends travel
(:mod:`core.contact_creep`, :mod:`core.contact_bands`).

:func:`contact_set_from_pressure` turns sampled pressures of any engine into contact
sets; :mod:`core.contact_model` holds the ``contact=`` switch of
:func:`core.solver.solve_dimensionless`.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core.contact_nodal import nodal_operator, nodal_state
from core.contact_solution import SolveOutcome
from core.contact_zones import (
    ZONE_END_TOL,
    NoContact,
    Resolution,
    Space,
    Step,
    nystrom_pressure,
    refine_zone_ends,
    zone_kernel_accuracy,
    zones_from_nodes,
)
from core.kernel_values import FULL_ACCURACY
from core.quadrature import Panels

#: The contact models of ``solve_dimensionless(..., contact=...)``.
CONTACT_MODELS = ("full", "unilateral", "auto")
#: The contact set of full contact.
FULL_CONTACT: list[tuple[float, float]] = [(-1.0, 1.0)]
#: Panels of the nodal active set (at most ``_NODAL_WIDTH`` wide: it must see every zone)
#: and of the first refinement level (at most ``_WIDTH``), graded to at most ``_EDGE`` at
#: +-1, breakpoints and zone ends (finer when the coating is thinner: its boundary layer
#: is ~m wide). Measured on four lift-off cases: the first level already meets 1e-6 for
#: the ends (estimates 1e-10 to 6e-9); tighter tol refines further.
_NODAL_WIDTH = 0.25
_WIDTH = 0.5
_EDGE = 1e-2
#: The base of the fixed rule of creep steps: panels at most this wide, graded to this
#: width at +-1 and the breakpoints (finer for a thin coating); the bands the zone ends
#: sweep get finer panels (core/contact_bands.py: outside them 0.5 and 0.0625 gave the
#: same ends to 1e-14 on the lift-off preset).
_CREEP_WIDTH = 0.5
_CREEP_EDGE = 1e-2

Scalar = float | Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class _Snapshot:
    """What the pressure at one output time needs: the Nystrom pressure on ``panels``."""

    panels: Panels
    q: np.ndarray
    settlement: float
    tilt: float
    step: Step
    zones: list[tuple[float, float]]
    memory: np.ndarray | None = None  # creep memory density at the nodes (F of it is e(x))


@dataclass(frozen=True)
class UnilateralSolution(SolveOutcome):
    """The answer of :func:`solve_unilateral` (dimensionless, like ``ContactSolution``).

    ``times`` (T,); ``settlement`` (delta), ``tilt`` (alpha), ``force`` (P), ``moment`` (M)
    over ``times``; ``contact_set[k]`` the list of ``(start, end)`` intervals of x in
    [-1, 1] where q > 0 at ``times[k]``; ``pressure(x)`` q of shape ``(len(x), T)`` (0 off
    contact); ``info`` with ``error_estimate``, ``zone_end_error`` [half-widths],
    ``success``, ``message``, ``flags``, ``contact`` (``"unilateral"``), ``seconds``.
    """

    times: np.ndarray
    settlement: np.ndarray
    tilt: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    contact_set: list[list[tuple[float, float]]]
    info: dict[str, Any]
    _space: Space = field(repr=False)
    _snapshots: list[_Snapshot] = field(repr=False)
    # absolute accuracy of the kernel values in the rows of q(x) (those of the solve)
    _kernel_accuracy: float = field(default=FULL_ACCURACY, repr=False)

    def pressure(self, x: Sequence[float] | np.ndarray) -> np.ndarray:
        """Contact pressure q(x, t) at points of [-1, 1], shape ``(len(x), len(times))``.

        The Nystrom formula on the contact set, exactly 0 off it (dimensionless).
        """
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if x.ndim != 1 or np.any(~np.isfinite(x)) or np.any(np.abs(x) > 1.0):
            raise ValueError("x: pressure is defined on [-1, 1] only")
        count = len(self._snapshots)
        out = np.zeros((x.size, count))
        inside = np.zeros((x.size, count), dtype=bool)
        at_end = np.zeros((x.size, count), dtype=bool)
        for k, snap in enumerate(self._snapshots):
            for lo, hi in snap.zones:
                inside[:, k] |= (x >= lo) & (x <= hi)
                at_end[:, k] |= (x == lo) | (x == hi)
        # Snapshots on one panel rule (every time of a creep solve) share the rows of F
        # at x, and m and g at x: one evaluation of them and one matrix product for all
        # times (per time they cost 2.5 times the rows on the 100-time lift-off preset).
        rules: dict[int, list[int]] = {}
        for k, snap in enumerate(self._snapshots):
            if not inside[:, k].any():
                continue
            if snap.memory is None:
                rules.setdefault(id(snap.panels), []).append(k)
            else:
                out[inside[:, k], k] = self._pressure_one(snap, x[inside[:, k]])
        touched = inside.any(axis=1)
        xi = x[touched]
        if rules:
            m_x = np.broadcast_to(np.asarray(self._space.m(xi), dtype=float), xi.shape)
            g_x = np.broadcast_to(np.asarray(self._space.g(xi), dtype=float), xi.shape)
        for times in rules.values():
            from core.quadrature import operator_rows

            snaps = [self._snapshots[k] for k in times]
            rows = operator_rows(self._space.lam, snaps[0].panels, xi,
                                 accuracy=self._kernel_accuracy)
            fq = rows @ np.column_stack([snap.q for snap in snaps])
            delta, alpha, scale, c = (np.array(v, dtype=float)[None, :] for v in zip(
                *((snap.settlement, snap.tilt, snap.step.scale, snap.step.c)
                  for snap in snaps), strict=True))
            values = (delta + alpha * xi[:, None] - g_x[:, None] - scale * fq) / (
                c * m_x[:, None])
            block = np.where(inside[np.ix_(touched, times)], np.maximum(values, 0.0), 0.0)
            out[np.ix_(touched, times)] = block
            # m and g sampled from inside the zone where it ends on a jump of them
            at_break = at_end & np.isin(x, self._space.breakpoints)[:, None]
            for k, snap in zip(times, snaps, strict=True):
                if at_break[:, k].any():
                    out[at_break[:, k], k] = self._pressure_one(snap, x[at_break[:, k]])
        return out

    def _pressure_one(self, snap: _Snapshot, xi: np.ndarray) -> np.ndarray:
        memory_at = None
        if snap.memory is not None:
            from core.quadrature import operator_rows

            def memory_at(t, _v=snap.memory, _p=snap.panels):
                return operator_rows(self._space.lam, _p, t) @ _v
        # Sample m and g from inside the zone at its ends (they may jump there).
        inward = np.zeros(xi.size)
        for lo, hi in snap.zones:
            inward[xi == lo] = 1.0
            inward[xi == hi] = -1.0
        values = nystrom_pressure(self._space, snap.step, snap.panels, snap.q,
                                  snap.settlement, snap.tilt, xi, inward, memory_at)
        return np.maximum(values, 0.0)


def contact_set_from_pressure(x: Sequence[float] | np.ndarray, q: np.ndarray, *,
                              threshold: float = 0.0) -> list[list[tuple[float, float]]]:
    """Contact sets from sampled pressures: intervals of x where ``q > threshold``.

    ``x`` sorted points of [-1, 1] (dimensionless), ``q`` of shape ``(len(x),)`` or
    ``(len(x), T)``. Each interval's ends are interpolated linearly where q crosses the
    threshold between samples and are +-1 where the samples reach the edges with
    ``q > threshold``. Returns one list per column of ``q`` (usable with any engine's
    ``pressure``; its accuracy is that of the sampling).
    """
    x = np.asarray(x, dtype=float)
    values = np.asarray(q, dtype=float)
    if values.ndim == 1:
        values = values[:, None]
    if x.ndim != 1 or values.shape[0] != x.size or np.any(np.diff(x) <= 0):
        raise ValueError("x: must be increasing points matching the rows of q")
    sets: list[list[tuple[float, float]]] = []
    for col in values.T:
        on = col > threshold
        zones: list[tuple[float, float]] = []
        i = 0
        while i < x.size:
            if not on[i]:
                i += 1
                continue
            j = i
            while j + 1 < x.size and on[j + 1]:
                j += 1
            lo = x[i] if i == 0 else _cross(x[i - 1], x[i], col[i - 1], col[i], threshold)
            hi = x[j] if j == x.size - 1 else _cross(x[j], x[j + 1], col[j], col[j + 1],
                                                     threshold)
            if i == 0 and x[0] <= -1.0 + 1e-12:
                lo = -1.0
            if j == x.size - 1 and x[-1] >= 1.0 - 1e-12:
                hi = 1.0
            zones.append((float(lo), float(hi)))
            i = j + 1
        sets.append(zones)
    return sets


def _cross(xa: float, xb: float, fa: float, fb: float, level: float) -> float:
    return xa + (level - fa) * (xb - xa) / (fb - fa) if fb != fa else xa


# ----------------------------------------------------------------------- the solver


def _function(value: Any, name: str) -> Callable[[np.ndarray], np.ndarray]:
    if callable(value):
        def fn(x, _f=value):
            out = np.asarray(_f(np.asarray(x, dtype=float)), dtype=float)
            return np.broadcast_to(out, np.shape(x)).astype(float)
        return fn
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name}: must be a number or a vectorized callable")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name}: must be finite, got {v}")
    return lambda x, _v=v: np.full(np.shape(x), _v)


def _check_loads(statement_given: frozenset[str], loads: dict[str, np.ndarray],
                 times: np.ndarray) -> None:
    """Refuse loads that pull the punch away (no contact can carry them)."""
    if "force" in loads:
        bad = loads["force"] <= 0.0
        if bad.any():
            t = times[int(np.argmax(bad))]
            raise ValueError(f"force: must be > 0 for the punch to touch (a punch pulled away "
                             f"has no contact), got {loads['force'][bad][0]:.6g} at t = {t:g}")
        if "moment" in loads:
            e = loads["moment"] / loads["force"]
            bad = np.abs(e) >= 1.0
            if bad.any():
                k = int(np.argmax(bad))
                raise ValueError(f"moment: the eccentricity M/P = {e[k]:.6g} at t = "
                                 f"{times[k]:g} puts the load outside the punch (|M/P| must "
                                 "be < 1 half-width): no contact can carry it")


def solve_unilateral(lam: float, m: Scalar, g: Scalar, times: Sequence[float] | np.ndarray,
                     *, c: Scalar = 1.0, kernel: Callable | None = None,
                     settlement: Scalar | None = None, tilt: Scalar | None = None,
                     force: Scalar | None = None, moment: Scalar | None = None,
                     breakpoints: Sequence[float] = (), tol: float = 1e-8,
                     time_steps: int | None = None) -> UnilateralSolution:
    """Solve the dimensionless problem with unilateral contact (the punch may lift off).

    Arguments as :func:`core.solver.solve_dimensionless` (all dimensionless): ``lam`` =
    a/H; ``m(x) > 0`` coating compliance; ``g(x)`` gap; ``times`` >= 1 increasing; ``c(t)``
    relative modulus; ``kernel`` K(t, tau) of V or None (elastic); exactly two of
    ``settlement`` (delta), ``tilt`` (alpha), ``force`` (P), ``moment`` (M); ``breakpoints``
    where m or g may jump; ``tol`` for delta, alpha, P, M (relative, as in the solver).
    ``time_steps``: nominal steps of the first creep grid over ``[1, times[-1]]`` (default
    ``core.contact_creep.FIRST_STEPS``; the grid is then halved until ``tol`` is met).

    Returns a :class:`UnilateralSolution` whose ``contact_set`` gives the contact zones
    at each time (free ends located to ``ZONE_END_TOL`` half-widths on an elastic base).
    Raises ``ValueError`` naming the argument on bad input and naming the load when the
    loads pull the punch away (``force <= 0`` in statement 4 or 3, ``|moment/force| >= 1``).
    """
    from core.solver import _validate  # one source of truth for the input rules

    started = _time.perf_counter()
    if time_steps is not None and (isinstance(time_steps, bool) or not isinstance(
            time_steps, (int, np.integer)) or not 1 <= time_steps <= 4096):
        raise ValueError(f"time_steps: must be an integer in [1, 4096], got {time_steps!r}")
    inp = _validate(lam, m, g, times, c, kernel,
                    {"settlement": settlement, "tilt": tilt, "force": force,
                     "moment": moment}, breakpoints, tol)
    times_arr = inp.times
    c_t = inp.c(times_arr)
    loads = {name: np.asarray(fn(times_arr), dtype=float) for name, fn in inp.loads.items()}
    _check_loads(inp.given, loads, times_arr)
    space = Space(inp.lam, inp.m, inp.g, inp.breakpoints)
    m_probe = inp.m(np.linspace(-1.0, 1.0, 257))
    res = Resolution(min(_WIDTH, 3.0 / inp.lam), min(_EDGE, 0.25 * float(np.min(m_probe))))
    nodal_res = nodal_resolution(inp.lam, inp.m)
    if inp.kernel is None:
        out = _solve_elastic(space, c_t, loads, times_arr, nodal_res, res, inp.tol)
    else:
        from core.contact_creep import solve_creep

        creep_res = Resolution(min(_CREEP_WIDTH, 3.0 / inp.lam), max(res.edge, min(
            _CREEP_EDGE, 0.25 * float(np.min(m_probe)))))
        out = solve_creep(space, inp, c_t, loads, creep_res,
                          **({} if time_steps is None else {"first_steps": time_steps}))
    out["info"]["seconds"] = _time.perf_counter() - started
    return UnilateralSolution(times_arr.copy(), out["settlement"], out["tilt"], out["force"],
                              out["moment"], out["contact_set"], out["info"], space,
                              out["snapshots"], out.get("kernel_accuracy", FULL_ACCURACY))


def nodal_resolution(lam: float, m: Callable[[np.ndarray], np.ndarray]) -> Resolution:
    """The rule of the nodal active set: panels at most ``_NODAL_WIDTH`` (and 3/lam)
    wide, graded to ``_EDGE`` at +-1 and the breakpoints, finer for a thin coating."""
    m_probe = m(np.linspace(-1.0, 1.0, 257))
    return Resolution(min(_NODAL_WIDTH, 3.0 / lam), min(_EDGE, 0.25 * float(np.min(m_probe))))


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
            results[key] = _solve_one(space, step, base, op, m_nodes, g_nodes, res, tol,
                                      nodal_res)
        per_time.append(results[key])
    snapshots = [r[0] for r in per_time]
    end_error = max(r[1]["zone_end_error"] for r in per_time)
    error = max(r[1]["error_estimate"] for r in per_time)
    verified = all(r[1]["verified"] for r in per_time)
    converged = all(r[1]["converged"] for r in per_time)
    success = error * 3.0 <= tol and end_error <= ZONE_END_TOL and verified and converged
    flags = [] if success else ["tol_not_met"]
    if not verified:
        flags.append("contact_set_unverified")
    message = (f"unilateral contact (elastic): estimated error {error:.1e}, zone ends to "
               f"{end_error:.1e} half-widths")
    if not success:
        message += (f"; not within tol {tol:.1e} / zone-end tolerance {ZONE_END_TOL:g}"
                    + ("" if verified else "; the contact set failed its check (q < 0 on "
                       "it or the surfaces overlap off it)"))
    info = {
        "contact": "unilateral",
        "error_estimate": float(error),
        "zone_end_error": float(end_error),
        "success": bool(success),
        "flags": flags,
        "message": message,
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
    try:
        state = nodal_state(space, step, base, op, m_nodes, g_nodes, nodal_res)
    except NoContact as exc:
        name = "force" if "force" in step.given else "moment" if "moment" in step.given \
            else "settlement"
        raise ValueError(f"{name}: the loads pull the punch away ({exc})") from None
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


def _bad_pins(space: Space, step: Step, sol, pinned: list[bool]) -> list[int]:
    """Pinned ends that are free ends in fact.

    At +-1 or a breakpoint the zone may end with q > 0 (a corner of the punch); it must
    not end with Q < 0 inside (the zone is shorter: a free end within a node of it) nor
    with Q > 0 just outside (the surfaces would overlap there: the zone is longer).
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
                                       sol.tilt, np.array([end]), np.array([outward]))[0]
            if outside > scale:
                bad.append(k)
    return bad


def _verify(space: Space, step: Step, sol, base: Panels, zones, accuracy: float) -> bool:
    """q >= 0 on the zones and the gap open (Q <= 0) at the base nodes off them (the
    kernel values to ``accuracy``, far below the check's 1e-8 of max q)."""
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
                              accuracy=accuracy)
    return bool(np.max(values) <= 1e-8 * scale)
