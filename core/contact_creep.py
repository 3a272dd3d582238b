"""Unilateral contact on a creeping base: implicit trapezoid steps with an active set.

At step ``n`` of a time grid the memory ``V q(t_n) = sum_{j<n} w_j K(t_n, t_j) q_j +
(h/2) K(t_n, t_n) q_n`` (trapezoid; the last term implicit) turns the problem into the
elastic one of :mod:`core.contact_zones` with ``scale = 1 - (h/2) K(t_n, t_n)`` on the
current pressure and the memory displacement ``e = F sum_{j<n} w_j K(t_n, t_j) q_j``. The
contact set is found at every step by the nodal active set (warm-started from the step
before), on one fixed panel rule, so the memory of every past pressure lives on the same
nodes. The zone ends of each output time are the roots of the Nystrom pressure's
interpolant on those nodes.

Errors: in time, the grid is halved and the outputs of successive grids extrapolated
(Richardson; the error ratio of the trapezoid measured 4.0 on the lift-off preset even as
the zone moves node by node); in space, the first step (t = 1, where V vanishes and the
problem is elastic) is compared with the refined elastic solution of
:mod:`core.contact_zones`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from core.collocation import time_grid
from core.contact_zones import (
    ZONE_END_TOL,
    NoContact,
    NodalState,
    Resolution,
    Space,
    Step,
    StepSolver,
    nodal_active_set,
    refine_zone_ends,
    zones_from_nodes,
)
from core.quadrature import base_panels, kernel_operator

#: Nominal steps of the first time grid over [1, t_end] (every output time is a grid
#: point; each interval between output times gets whole steps).
FIRST_STEPS = 16
#: Grid halvings at most (the cost doubles with each).
MAX_HALVINGS = 4


def _zones(state: NodalState, breakpoints: tuple[float, ...]
           ) -> tuple[list[tuple[float, float]], list[float]]:
    if not state.active.any():
        return [], []
    ends, _, _ = zones_from_nodes(state, breakpoints)
    return [(ends[2 * i], ends[2 * i + 1]) for i in range(len(ends) // 2)], ends


def _march(space: Space, inp: Any, base, op: np.ndarray, m: np.ndarray, g: np.ndarray,
           grid: np.ndarray, widths: np.ndarray, out_index: np.ndarray) -> dict[str, Any]:
    from core.contact import _check_loads

    n_nodes = base.size
    steps = grid.size
    c_vals = inp.c(grid)
    loads = {name: np.asarray(fn(grid), dtype=float) for name, fn in inp.loads.items()}
    _check_loads(inp.given, loads, grid)
    inner = np.zeros(steps)
    inner[:-1] += 0.5 * widths
    inner[1:] += 0.5 * widths
    history = np.zeros((n_nodes, steps))
    wanted = {int(i): k for k, i in enumerate(out_index)}
    states: list[tuple[NodalState, Step, np.ndarray]] = [None] * len(out_index)  # type: ignore
    active = None
    solver = StepSolver()
    sweeps = 0
    unsettled = 0
    for n in range(steps):
        memory_density = np.zeros(n_nodes)
        diag = 0.0
        if n > 0:
            kv = np.asarray(inp.kernel(np.full(n + 1, grid[n]), grid[: n + 1]), dtype=float)
            if not np.all(np.isfinite(kv)):
                raise ValueError(f"kernel: K(t, tau) must be finite; it is not at t = "
                                 f"{grid[n]:g}")
            memory_density = history[:, :n] @ (inner[:n] * kv[:n])
            diag = 0.5 * widths[n - 1] * kv[n]
        step = Step(float(c_vals[n]), 1.0 - diag,
                    {name: float(v[n]) for name, v in loads.items()})
        try:
            state, count, settled = nodal_active_set(base, op, m, g, step,
                                                     memory=op @ memory_density, start=active,
                                                     solver=solver)
        except NoContact as exc:
            name = "force" if "force" in step.given else "moment"
            raise ValueError(f"{name}: the loads pull the punch away at t = {grid[n]:g} "
                             f"({exc})") from None
        sweeps += count
        unsettled += not settled
        active = state.active
        history[:, n] = state.q
        if n in wanted:
            states[wanted[n]] = (state, step, memory_density)
    return {"states": states, "sweeps": sweeps, "unsettled": unsettled, "steps": steps - 1,
            "breakpoints": space.breakpoints,
            "factorizations": solver.factorizations}


def _outputs(run: dict[str, Any]) -> dict[str, Any]:
    """The outputs of one march, with what the pressure needs (all linear in the steps)."""
    states = run["states"]
    zones, ends = zip(*(_zones(s, run["breakpoints"]) for s, _, _ in states), strict=True)
    return {
        "settlement": np.array([s.settlement for s, _, _ in states]),
        "tilt": np.array([s.tilt for s, _, _ in states]),
        "force": np.array([s.force for s, _, _ in states]),
        "moment": np.array([s.moment for s, _, _ in states]),
        "ends": [list(e) for e in ends],
        # Q(x) = [delta + alpha x - g - F(effective)(x)] / (c m), effective = s q - memory
        "effective": np.column_stack([step.scale * s.q - memory for s, step, memory in states]),
        "c": np.array([step.c for _, step, _ in states]),
    }


def _extrapolate(fine: dict[str, Any], coarse: dict[str, Any]) -> dict[str, Any]:
    """Richardson ``(4 fine - coarse) / 3`` (the trapezoid is of order 2: measured ratio
    4.0 of successive differences on the lift-off preset, zone ends included). Zone ends
    are extrapolated where both grids found the same number of ends."""
    def mix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return (4.0 * np.asarray(a) - np.asarray(b)) / 3.0
    ends = [list(mix(ef, ec)) if len(ef) == len(ec) and ef else list(ef)
            for ef, ec in zip(fine["ends"], coarse["ends"], strict=True)]
    out = {key: mix(fine[key], coarse[key]) for key in ("settlement", "tilt", "force",
                                                        "moment", "effective")}
    out["ends"] = ends
    out["c"] = fine["c"]
    return out


def _distance(a: dict[str, Any], b: dict[str, Any]) -> tuple[float, float]:
    """(relative difference of the four histories, largest shift of a zone end)."""
    kin = max(np.max(np.abs(a["settlement"])), np.max(np.abs(a["tilt"])), 1e-300)
    dyn = max(np.max(np.abs(a["force"])), np.max(np.abs(a["moment"])), 1e-300)
    outputs = max(np.max(np.abs(a["settlement"] - b["settlement"])) / kin,
                  np.max(np.abs(a["tilt"] - b["tilt"])) / kin,
                  np.max(np.abs(a["force"] - b["force"])) / dyn,
                  np.max(np.abs(a["moment"] - b["moment"])) / dyn)
    shift = 0.0
    for ea, eb in zip(a["ends"], b["ends"], strict=True):
        if len(ea) != len(eb):
            return float(outputs), np.inf  # the topology differs: not resolved in time
        if ea:
            shift = max(shift, float(np.max(np.abs(np.subtract(ea, eb)))))
    return float(outputs), shift


def solve_creep(space: Space, inp: Any, c_t: np.ndarray, loads: dict[str, np.ndarray],
                res: Resolution, first_steps: int = FIRST_STEPS) -> dict[str, Any]:
    """Time-step the unilateral problem under creep (see the module notes).

    ``first_steps`` nominal steps on the first grid; the grid is halved until the
    Richardson-extrapolated outputs of two successive pairs of grids agree to ``tol``/3
    (their difference / 15 is the estimate) or ``MAX_HALVINGS`` is reached.
    """
    from core.contact import _Snapshot

    base = base_panels(space.lam, space.breakpoints, edge_width=res.edge, max_width=res.width)
    op = kernel_operator(space.lam, base).matrix
    m = space.m(base.nodes)
    g = space.g(base.nodes)
    times = inp.times
    tol = inp.tol
    end_tol = max(ZONE_END_TOL, tol)
    plain: list[dict[str, Any]] = []
    extrapolated: list[dict[str, Any]] = []
    time_error = end_shift = np.inf
    unsettled = 0
    sweeps = steps = 0
    for level in range(MAX_HALVINGS + 1):
        grid, widths, index = time_grid(times, first_steps, level)
        run = _march(space, inp, base, op, m, g, grid, widths, index)
        unsettled, sweeps, steps = run["unsettled"], run["sweeps"], run["steps"]
        plain.append(_outputs(run))
        if len(plain) >= 2:
            extrapolated.append(_extrapolate(plain[-1], plain[-2]))
        if len(extrapolated) >= 2:
            diff, shift = _distance(extrapolated[-1], extrapolated[-2])
            # Order 4 after one extrapolation: the newer one ~16 times closer.
            time_error, end_shift = diff / 15.0, shift / 15.0
            if time_error <= tol / 3 and end_shift <= end_tol / 3:
                break
    out = extrapolated[-1] if extrapolated else plain[-1]

    # Space: the first grid point is t = 1, where the problem is elastic.
    space_error, space_shift = _spatial_check(space, base, op, m, g, inp, res, tol)

    error = float(time_error + space_error)
    end_error = float(end_shift + space_shift)
    success = error * 3.0 <= tol and end_error <= end_tol and unsettled == 0
    flags = [] if success else ["tol_not_met"]
    message = (f"unilateral contact under creep: {steps} steps, estimated error "
               f"{error:.1e} (time {time_error:.1e}, space {space_error:.1e}), zone ends to "
               f"{end_error:.1e} half-widths")
    if not success:
        message += f"; not within tol {tol:.1e} (zone ends: {end_tol:g})"
    zones = [[(float(e[2 * i]), float(e[2 * i + 1])) for i in range(len(e) // 2)]
             for e in out["ends"]]
    snapshots = [
        _Snapshot(base, out["effective"][:, k], float(out["settlement"][k]),
                  float(out["tilt"][k]), Step(float(out["c"][k]), 1.0, {}), zones[k])
        for k in range(times.size)]
    info = {
        "contact": "unilateral",
        "error_estimate": error,
        "time_error_estimate": float(time_error),
        "spatial_error_estimate": float(space_error),
        "zone_end_error": end_error,
        "success": bool(success),
        "flags": flags,
        "message": message,
        "n_steps": int(steps),
        "n_nodes": int(base.size),
        "active_set_sweeps": int(sweeps),
        "min_pressure": 0.0,
    }
    return {"settlement": out["settlement"], "tilt": out["tilt"], "force": out["force"],
            "moment": out["moment"], "contact_set": zones, "snapshots": snapshots,
            "info": info}


def _spatial_check(space: Space, base, op, m, g, inp: Any, res: Resolution,
                   tol: float) -> tuple[float, float]:
    """Error of the fixed rule at t = 1 against the refined elastic solution there."""
    t1 = np.array([1.0])
    step = Step(float(inp.c(t1)[0]), 1.0,
                {name: float(fn(t1)[0]) for name, fn in inp.loads.items()})
    state, _, _ = nodal_active_set(base, op, m, g, step)
    if not state.active.any():
        return 0.0, 0.0
    ends, pinned, slopes = zones_from_nodes(state, space.breakpoints)
    refined = refine_zone_ends(space, step, ends, pinned, slopes, res, tol=tol)
    sol = refined.solution
    if len(sol.ends) != len(ends):
        return np.inf, np.inf
    kin = max(abs(sol.settlement), abs(sol.tilt), 1e-300)
    dyn = max(abs(sol.force), abs(sol.moment), 1e-300)
    outputs = max(abs(state.settlement - sol.settlement) / kin,
                  abs(state.tilt - sol.tilt) / kin,
                  abs(state.force - sol.force) / dyn, abs(state.moment - sol.moment) / dyn)
    shift = float(np.max(np.abs(np.subtract(ends, sol.ends))))
    return float(outputs + refined.output_error), shift + refined.end_error
