"""Unilateral contact on a creeping base: implicit trapezoid steps with an active set.

At step ``n`` of a time grid the memory ``V q(t_n) = sum_{j<n} w_j K(t_n, t_j) q_j +
(h/2) K(t_n, t_n) q_n`` (trapezoid; the last term implicit) turns the problem into the
elastic one of :mod:`core.contact_zones` with ``scale = 1 - (h/2) K(t_n, t_n)`` on the
current pressure and the memory displacement ``e = F sum_{j<n} w_j K(t_n, t_j) q_j``. The
contact set is found at every step by the nodal active set (warm-started from the step
before), on one fixed panel rule, so the memory of every past pressure lives on the same
nodes. The zone ends of each output time are the roots of the Nystrom pressure's
interpolant on those nodes.

Errors: in time, the grid is halved and the outputs compared (the contact set switches
node by node, so the trapezoid's error expansion is not smooth enough for Richardson);
in space, the first step (t = 1, where V vanishes and the problem is elastic) is
compared with the refined elastic solution of :mod:`core.contact_zones`.
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
    nodal_active_set,
    refine_zone_ends,
    zones_from_nodes,
)
from core.quadrature import base_panels, kernel_operator

#: Nominal steps of the first time grid over [1, t_end] (every output time is a grid
#: point; each interval between output times gets whole steps).
FIRST_STEPS = 32
#: Grid halvings at most (the cost doubles with each).
MAX_HALVINGS = 3


def _zones(state: NodalState) -> tuple[list[tuple[float, float]], list[float]]:
    if not state.active.any():
        return [], []
    ends, _, _ = zones_from_nodes(state)
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
                                                     memory=op @ memory_density, start=active)
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
    return {"states": states, "sweeps": sweeps, "unsettled": unsettled, "steps": steps - 1}


def _outputs(run: dict[str, Any]) -> dict[str, Any]:
    states = run["states"]
    zones, ends = zip(*(_zones(s) for s, _, _ in states), strict=True)
    return {
        "settlement": np.array([s.settlement for s, _, _ in states]),
        "tilt": np.array([s.tilt for s, _, _ in states]),
        "force": np.array([s.force for s, _, _ in states]),
        "moment": np.array([s.moment for s, _, _ in states]),
        "zones": list(zones),
        "ends": list(ends),
    }


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
                res: Resolution) -> dict[str, Any]:
    """Time-step the unilateral problem under creep (see the module notes)."""
    from core.contact import _Snapshot

    base = base_panels(space.lam, space.breakpoints, edge_width=res.edge, max_width=res.width)
    op = kernel_operator(space.lam, base).matrix
    m = space.m(base.nodes)
    g = space.g(base.nodes)
    times = inp.times
    tol = inp.tol
    runs = []
    time_error = end_shift = np.inf
    for level in range(MAX_HALVINGS + 1):
        grid, widths, index = time_grid(times, FIRST_STEPS, level)
        run = _march(space, inp, base, op, m, g, grid, widths, index)
        run["outputs"] = _outputs(run)
        runs.append(run)
        if len(runs) >= 2:
            diff, shift = _distance(runs[-1]["outputs"], runs[-2]["outputs"])
            # Order 2 when smooth (the error of the finer grid ~ a third of the change),
            # but the contact set switches node by node: take the whole change.
            time_error, end_shift = diff, shift
            if time_error <= tol / 3 and end_shift <= ZONE_END_TOL:
                break
    final = runs[-1]
    out = final["outputs"]

    # Space: the first grid point is t = 1, where the problem is elastic.
    space_error, space_shift = _spatial_check(space, base, op, m, g, inp, res, tol)

    error = float(time_error + space_error)
    end_error = float(end_shift + space_shift)
    success = error * 3.0 <= tol and end_error <= ZONE_END_TOL and final["unsettled"] == 0
    flags = [] if success else ["tol_not_met"]
    message = (f"unilateral contact under creep: {final['steps']} steps, estimated error "
               f"{error:.1e} (time {time_error:.1e}, space {space_error:.1e}), zone ends to "
               f"{end_error:.1e} half-widths")
    if not success:
        message += f"; not within tol {tol:.1e} / zone-end tolerance {ZONE_END_TOL:g}"
    snapshots = [_Snapshot(base, state.q, state.settlement, state.tilt, step, zones, memory)
                 for (state, step, memory), zones in zip(final["states"], out["zones"],
                                                         strict=True)]
    info = {
        "contact": "unilateral",
        "error_estimate": error,
        "time_error_estimate": float(time_error),
        "spatial_error_estimate": float(space_error),
        "zone_end_error": end_error,
        "success": bool(success),
        "flags": flags,
        "message": message,
        "n_steps": int(final["steps"]),
        "n_nodes": int(base.size),
        "active_set_sweeps": int(final["sweeps"]),
        "min_pressure": 0.0,
    }
    return {"settlement": out["settlement"], "tilt": out["tilt"], "force": out["force"],
            "moment": out["moment"], "contact_set": [list(z) for z in out["zones"]],
            "snapshots": snapshots, "info": info}


def _spatial_check(space: Space, base, op, m, g, inp: Any, res: Resolution,
                   tol: float) -> tuple[float, float]:
    """Error of the fixed rule at t = 1 against the refined elastic solution there."""
    t1 = np.array([1.0])
    step = Step(float(inp.c(t1)[0]), 1.0,
                {name: float(fn(t1)[0]) for name, fn in inp.loads.items()})
    state, _, _ = nodal_active_set(base, op, m, g, step)
    if not state.active.any():
        return 0.0, 0.0
    ends, pinned, slopes = zones_from_nodes(state)
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
