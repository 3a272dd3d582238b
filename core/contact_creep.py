"""Unilateral contact on a creeping base: implicit steps with an active set at each.

At step ``n`` of a time grid the memory ``V q(t_n) = int_1^t_n K(t_n, tau) q(tau) dtau``
is split into the part of past pressures and the weight ``w_n`` of the current one
(implicit), which turns the problem into the elastic one of :mod:`core.contact_zones`
with ``scale = 1 - w_n`` on the current pressure and the memory displacement
``e = F (memory of q_0 .. q_{n-1})``. For the degenerate kernels of the shipped creep
models the memory is carried by recursion with exponential product integration (q linear
on each step, the kernel integrated exactly against it); any other kernel takes the
trapezoid on ``K q``. Both are of order 2. The contact set is found at every step by the
nodal active set (warm-started from the step before), on one fixed panel rule, so the
memory of every past pressure lives on the same nodes; that rule has fine panels over the
bands the free zone ends sweep (:mod:`core.contact_bands`). The zone ends of each output
time are the roots of the Nystrom pressure's interpolant on those nodes, after the kink
of the pressure at each end is taken out of the panel rule (:mod:`core.contact_kinks`;
the corrections of ``_KINK_BATCH`` output times at once, the roots of all after the
march).

Errors: in time, the grid is halved and the outputs of successive grids extrapolated
(Richardson, ratio 4.0 of successive differences measured on the lift-off preset even as
the zone moves node by node; two grids suffice when the difference of their plain
outputs, which bounds the extrapolated one, meets tol); in space, the rule is compared
with the one of halved panels over a few of the output times (:func:`_select_rule`).
"""


from __future__ import annotations

from typing import Any

import numpy as np

from core.cache import StageCache, fingerprint
from core.collocation import time_grid
from core.contact_bands import BAND_WIDTHS, band_rule, bands_from_ends
from core.contact_kinks import corrected_roots, kinks_corrected
from core.contact_zones import (
    ZONE_END_TOL,
    NoContact,
    NodalState,
    Resolution,
    Space,
    Step,
    StepSolver,
    nodal_active_set,
    zone_kernel_accuracy,
    zones_from_nodes,
)
from core.quadrature import KernelOperator, Panels, kernel_operator

#: Nominal steps of the first time grid over [1, t_end] (every output time is a grid
#: point; each interval between output times gets whole steps).
FIRST_STEPS = 16
#: Grid halvings at most (the cost doubles with each).
MAX_HALVINGS = 4
#: Output times at most on the first grid of the spatial check, and of the march that
#: locates the bands the zone ends sweep (on a rule graded only to ``LOCATE_EDGE``).
CHECK_OUTPUTS = 12
LOCATE_OUTPUTS = 6
LOCATE_EDGE = 0.05
#: Spatial error of a rule per difference from the rule with halved panels. The error
#: fell irregularly with the band panels (it depends on where the ends sit among the
#: nodes): on the preset, with the kink correction of the ends, the largest end error
#: over the output times was 0.73 and 1.31 times the largest difference for bands 0.04
#: and 0.02 wide (against 0.0025; see tests/test_contact.py), and 0.86 to 0.97 times the
#: difference the check takes (against a rule with every panel halved, 100 output
#: times), so 2 leaves a margin of 1.5.
SPACE_FACTOR = 2.0

#: The operators of the stepping's panel rules, keyed by lam and the panel edges (they
#: depend on nothing else): a load-only change (the explorer's eccentricity slider) meets
#: the same base and locating rules again, and band rules that share most panels with one
#: kept here, whose blocks are copied (only the rows and columns of new panels are built).
_RULE_OPERATORS = StageCache("contact_rule_operator", max_items=12, max_bytes=96 * 2**20)


def rule_operator(lam: float, rule: Panels) -> np.ndarray:
    """The Nystrom matrix of F on the nodes of ``rule`` (read-only, cached; see
    ``_RULE_OPERATORS``). ``lam`` = a/H (dimensionless)."""
    key = fingerprint(float(lam), np.asarray(rule.edges, dtype=float))

    def build() -> KernelOperator:
        # the kept operator of this lam sharing most panels with the rule seeds it
        best, shared = None, 0
        for previous in _RULE_OPERATORS.values():
            if previous.lam == lam:
                common = np.intersect1d(previous.panels.edges, rule.edges).size
                if common > shared:
                    best, shared = previous, common
        operator = kernel_operator(lam, rule, previous=best)
        operator.matrix.flags.writeable = False  # shared by every march on this rule
        return operator

    return _RULE_OPERATORS.get_or_compute(key, build)[0].matrix


def _march(space: Space, inp: Any, base, op: np.ndarray, m: np.ndarray, g: np.ndarray,
           grid: np.ndarray, widths: np.ndarray, out_index: np.ndarray,
           exact_ends: bool = True, first: dict[str, Any] | None = None) -> dict[str, Any]:
    """March over ``grid`` on the rule ``base`` (its Nystrom matrix ``op``, m and g at
    its nodes). ``first`` (shared by the marches of one solve): the zones of the first
    step, at loading, recorded by the first march and the start of the first step of
    the later ones (from full contact it took 4-6 sweeps, each with a new LU)."""
    from core.contact import _check_loads

    # kink rows with kernel values to 1e-4 of the tighter of tol and the zone-end
    # tolerance (as the elastic zone operators): ~15 % less kernel work per correction
    accuracy = zone_kernel_accuracy(inp.tol)
    n_nodes = base.size
    steps = grid.size
    c_vals = inp.c(grid)
    loads = {name: np.asarray(fn(grid), dtype=float) for name, fn in inp.loads.items()}
    _check_loads(inp.given, loads, grid)
    inner = np.zeros(steps)
    inner[:-1] += 0.5 * widths
    inner[1:] += 0.5 * widths
    memory_of = _SeparableMemory(inp.kernel, grid, inner, n_nodes) if _separable(
        inp.kernel) else _HistoryMemory(inp.kernel, grid, inner, n_nodes)
    wanted = {int(i): k for k, i in enumerate(out_index)}
    # per output time: the state, its step, the memory density, the ends, the nodal ends
    states: list[tuple[NodalState, Step, np.ndarray, list[float], list[float]]] = (
        [None] * len(out_index))  # type: ignore
    active = None
    solver = StepSolver()
    pending: list[tuple[int, Any]] = []
    batch: list[tuple[int, tuple]] = []
    sweeps = 0
    unsettled = 0
    for n in range(steps):
        memory_density = np.zeros(n_nodes)
        diag = 0.0
        if n > 0:
            memory_density, diag = memory_of.at(n)
        step = Step(float(c_vals[n]), 1.0 - diag,
                    {name: float(v[n]) for name, v in loads.items()})
        displacement = op @ memory_density
        start = active
        if n == 0 and first is not None and "zones" in first:
            start = _nodes_in(base.nodes, first["zones"])
        try:
            state, count, settled = _step_state(base, op, m, g, step, displacement, start,
                                                solver, retry=n == 0)
        except NoContact as exc:
            name = "force" if "force" in step.given else "moment"
            raise ValueError(f"{name}: the loads pull the punch away at t = {grid[n]:g} "
                             f"({exc})") from None
        if n == 0 and first is not None and "zones" not in first and state.active.any():
            ends = zones_from_nodes(state, space.breakpoints)[0]
            first["zones"] = list(zip(ends[0::2], ends[1::2], strict=True))
        sweeps += count
        unsettled += not settled
        active = state.active
        memory_of.record(n, state.q)
        if n in wanted:
            nodal, pinned = ([], []) if not state.active.any() else zones_from_nodes(
                state, space.breakpoints)[:2]
            if exact_ends and nodal:
                # corrected in batches, each step with its own factors (kept by a
                # snapshot); the roots of all at the end
                batch.append((wanted[n], (step, state, displacement, memory_density,
                                          solver.snapshot(), (nodal, pinned))))
                if len(batch) == _KINK_BATCH:
                    pending += _corrected(space, op, m, g, batch, accuracy)
                    batch = []
            states[wanted[n]] = (state, step, memory_density, nodal, nodal)
    if batch:
        pending += _corrected(space, op, m, g, batch, accuracy)
    if pending:
        roots = corrected_roots(space, [c for _, c in pending], accuracy)
        for (k, _), ends in zip(pending, roots, strict=True):
            states[k] = states[k][:3] + (ends, states[k][4])
    return {"states": states, "sweeps": sweeps, "unsettled": unsettled, "steps": steps - 1,
            "breakpoints": space.breakpoints,
            "factorizations": solver.factorizations,
            "back_substitutions": solver.back_substitutions}


def _nodes_in(x: np.ndarray, zones: list[tuple[float, float]]) -> np.ndarray:
    """The nodes ``x`` inside the ``zones`` (a contact set as a start)."""
    inside = np.zeros(x.size, dtype=bool)
    for lo, hi in zones:
        inside |= (x >= lo) & (x <= hi)
    return inside


def _step_state(base, op: np.ndarray, m: np.ndarray, g: np.ndarray, step: Step,
                displacement: np.ndarray, start: np.ndarray | None, solver: StepSolver,
                retry: bool) -> tuple[NodalState, int, bool]:
    """The nodal active set of one step from ``start``; with ``retry``, a start that
    does not settle (or leaves no contact) is retried from full contact."""
    tried = 0
    if retry and start is not None:
        try:
            state, tried, settled = nodal_active_set(base, op, m, g, step,
                                                     memory=displacement, start=start,
                                                     solver=solver)
            if settled:
                return state, tried, settled
        except NoContact:
            pass
        start = None
    state, count, settled = nodal_active_set(base, op, m, g, step, memory=displacement,
                                             start=start, solver=solver)
    return state, tried + count, settled


#: Output times whose kink corrections are made together (one evaluation of F on their
#: cut parts): each holds its step's LU factors meanwhile (~0.7 MB at 300 contact
#: nodes), so the batch stays short.
_KINK_BATCH = 10


def _corrected(space: Space, op: np.ndarray, m: np.ndarray, g: np.ndarray,
               batch: list[tuple[int, tuple]], accuracy: float) -> list[tuple[int, Any]]:
    done = kinks_corrected(space, op, m, g, [row for _, row in batch], accuracy)
    return [(k, c) for (k, _), c in zip(batch, done, strict=True)]


def _separable(kernel: Any) -> bool:
    return all(hasattr(kernel, name) for name in ("rates", "tau_part", "exponential_parts"))


class _HistoryMemory:
    """The trapezoid memory ``sum_{j<n} w_j K(t_n, t_j) q_j`` of any kernel: O(n N) per step."""

    def __init__(self, kernel: Any, grid: np.ndarray, inner: np.ndarray, n_nodes: int) -> None:
        self.kernel, self.grid, self.inner = kernel, grid, inner
        self.history = np.zeros((n_nodes, grid.size))

    def at(self, n: int) -> tuple[np.ndarray, float]:
        """(memory density at step n without its q_n part, weight of q_n); trapezoid."""
        grid = self.grid
        kv = np.asarray(self.kernel(np.full(n + 1, grid[n]), grid[: n + 1]), dtype=float)
        if not np.all(np.isfinite(kv)):
            raise ValueError(f"kernel: K(t, tau) must be finite; it is not at t = {grid[n]:g}")
        weight = 0.5 * (grid[n] - grid[n - 1]) * float(kv[n])
        return self.history[:, :n] @ (self.inner[:n] * kv[:n]), weight

    def record(self, n: int, q: np.ndarray) -> None:
        self.history[:, n] = q


class _SeparableMemory:
    """The memory for ``K = b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))`` by recursion,
    O(R N) per step instead of re-summing the whole past.

    Product integration: on each step q is taken linear and everything else (``b``,
    ``a_r`` and the decay ``exp(-rate_r (t_n - tau))``) is integrated against it by a
    Gauss rule of ``_GAUSS`` points. The plain trapezoid on ``K q`` read 2e-4 wrong in the
    settlement of the lift-off preset (100 output times, 101 steps): the aging kernel
    varies fast just after loading, and log-spaced outputs make late steps of ~2 against
    a decay time of ~1.2. This rule's error depends only on how q curves in time; it is
    still of order 2 in the step (Richardson applies unchanged).
    """

    _GAUSS = 8

    def __init__(self, kernel: Any, grid: np.ndarray, inner: np.ndarray, n_nodes: int) -> None:
        rates = np.asarray(kernel.rates, dtype=float).ravel()
        xi, omega = np.polynomial.legendre.leggauss(self._GAUSS)
        h = np.diff(grid)  # (S,)
        s = 0.5 * h[:, None] * (1.0 + xi[None, :])  # (S, G) offsets into each step
        tau = grid[:-1, None] + s
        weight = 0.5 * h[:, None] * omega[None, :]
        rising = s / h[:, None]  # the hat function of the step's end; 1 - it of its start
        b = np.asarray(kernel.tau_part(tau), dtype=float).reshape(tau.shape)
        a = np.asarray(kernel.exponential_parts(tau), dtype=float).reshape(
            (rates.size,) + tau.shape) * np.exp(-rates[:, None, None] * (h[:, None] - s))
        if not (np.all(np.isfinite(b)) and np.all(np.isfinite(a))):
            raise ValueError("kernel: K(t, tau) must be finite on the time grid")
        self.b_old = np.sum(weight * b * (1.0 - rising), axis=1)  # (S,)
        self.b_new = np.sum(weight * b * rising, axis=1)
        self.a_old = np.sum(weight * a * (1.0 - rising), axis=2)  # (R, S)
        self.a_new = np.sum(weight * a * rising, axis=2)
        self.decay = np.exp(-rates[:, None] * h[None, :])  # (R, S)
        self.aged = np.zeros(n_nodes)  # int b q up to the last step
        self.modes = np.zeros((rates.size, n_nodes))  # each mode up to the last step
        self._last = np.zeros(n_nodes)

    def at(self, n: int) -> tuple[np.ndarray, float]:
        """(memory density at step n without its q_n part, weight of q_n); in step order."""
        j = n - 1
        self.modes = self.decay[:, j, None] * self.modes + self.a_old[:, j, None] * \
            self._last[None, :]
        self.aged = self.aged + self.b_old[j] * self._last
        return self.aged + self.modes.sum(axis=0), float(self.b_new[j] + self.a_new[:, j].sum())

    def record(self, n: int, q: np.ndarray) -> None:
        if n > 0:
            j = n - 1
            self.modes = self.modes + self.a_new[:, j, None] * q[None, :]
            self.aged = self.aged + self.b_new[j] * q
        self._last = q


def _outputs(run: dict[str, Any]) -> dict[str, Any]:
    """The outputs of one march, with what the pressure needs (all linear in the steps)."""
    states = run["states"]
    return {
        "settlement": np.array([row[0].settlement for row in states]),
        "tilt": np.array([row[0].tilt for row in states]),
        "force": np.array([row[0].force for row in states]),
        "moment": np.array([row[0].moment for row in states]),
        # without the kink defect (core/contact_kinks.py) when the march corrected them
        "ends": [list(row[3]) for row in states],
        "nodal_ends": [list(row[4]) for row in states],
        # Q(x) = [delta + alpha x - g - F(effective)(x)] / (c m), effective = s q - memory
        "effective": np.column_stack([row[1].scale * row[0].q - row[2] for row in states]),
        "c": np.array([row[1].c for row in states]),
    }


def _borrow_corrections(coarse: dict[str, Any], fine: dict[str, Any]) -> None:
    """Give the uncorrected ends of ``coarse`` the kink corrections of ``fine`` (the same
    output times on a grid of halved steps), in place.

    The correction is a spatial effect of where an end sits in its panel, nearly the
    same on two time grids: on the 100-time preset with band panels 0.04 / 0.02 the
    corrections (up to 5.6e-6 / 2.3e-6) differed between the grids of 101 and 202 steps
    by 1.8e-8 / 2.3e-8, which enters the extrapolated ends divided by 3. So one set
    serves both members of a Richardson pair and the coarser march skips them. Times
    whose ends differ in number keep theirs (the time estimate then calls the topology
    unresolved)."""
    for k, (ends, nodal, exact) in enumerate(zip(coarse["nodal_ends"], fine["nodal_ends"],
                                                 fine["ends"], strict=True)):
        if len(ends) == len(nodal) == len(exact):
            coarse["ends"][k] = [e + (x - n) for e, n, x in zip(ends, nodal, exact,
                                                                  strict=True)]


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
    (their difference / 7 is the estimate) or ``MAX_HALVINGS`` is reached.
    """
    from core.contact import _Snapshot

    times = inp.times
    tol = inp.tol
    # The zone ends have their own budget whatever tol is (issue 13): half of it for the
    # panel rule (core/contact_kinks.py takes the kinks at the ends out of its error), the
    # rest, or at least the other half, for the time grid; likewise tol / 3 of the outputs
    # (success asks the sum of the two parts to meet it).
    end_tol = ZONE_END_TOL
    # the zones at loading found by the first march start the first step of the others
    first: dict[str, Any] = {}
    base, space_error, space_shift, band_note = _select_rule(space, inp, res, first_steps,
                                                             tol, end_tol, first=first)
    out, time_error, end_shift, run = _in_time(
        space, inp, base, first_steps, max(tol / 3 - space_error, tol / 6),
        max(end_tol - space_shift, end_tol / 2), first)
    strays = _outside_bands(out["ends"], band_note["bands"], space.breakpoints)
    if strays:
        # An end went where the first march did not see it (between its few times, or as
        # a zone opening late): the bands of every output time, and everything again.
        bands = _merge(band_note["bands"] + bands_from_ends(out["ends"], space.breakpoints))
        base, space_error, space_shift, band_note = _select_rule(
            space, inp, res, first_steps, tol, end_tol, bands=bands, first=first)
        out, time_error, end_shift, run = _in_time(
            space, inp, base, first_steps, max(tol / 3 - space_error, tol / 6),
            max(end_tol - space_shift, end_tol / 2), first)
        strays = _outside_bands(out["ends"], band_note["bands"], space.breakpoints)
    unsettled, sweeps, steps = run["unsettled"], run["sweeps"], run["steps"]

    error = float(time_error + space_error)
    end_error = float(end_shift + space_shift)
    success = (error * 3.0 <= tol and end_error <= end_tol and unsettled == 0
               and not strays)
    flags = [] if success else ["tol_not_met"]
    message = (f"unilateral contact under creep: {steps} steps, estimated error "
               f"{error:.1e} (time {time_error:.1e}, space {space_error:.1e}), zone ends to "
               f"{end_error:.1e} half-widths")
    if strays:
        message += (f"; a zone end left the finely paneled band around the ends at "
                    f"{strays} time(s), its estimate does not hold there")
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
        "end_bands": band_note["bands"],
        "band_panel_width": band_note["width"],
        "min_pressure": 0.0,
    }
    return {"settlement": out["settlement"], "tilt": out["tilt"], "force": out["force"],
            "moment": out["moment"], "contact_set": zones, "snapshots": snapshots,
            "info": info}


def _in_time(space: Space, inp: Any, base: Panels, first_steps: int, budget: float,
             end_budget: float, first: dict[str, Any] | None = None
             ) -> tuple[dict[str, Any], float, float, dict[str, Any]]:
    """March on halved grids until the time estimate meets ``budget`` (what the panel
    rule left of tol / 3) and that of the zone ends ``end_budget`` (module notes):
    (outputs, their time error, the zone ends' time error, the last march)."""
    op = rule_operator(space.lam, base)
    m = space.m(base.nodes)
    g = space.g(base.nodes)
    plain: list[dict[str, Any]] = []
    extrapolated: list[dict[str, Any]] = []
    time_error = end_shift = np.inf
    for level in range(MAX_HALVINGS + 1):
        grid, widths, index = time_grid(inp.times, first_steps, level)
        # the first grid borrows the kink corrections of the second (_borrow_corrections)
        run = _march(space, inp, base, op, m, g, grid, widths, index, exact_ends=level > 0,
                     first=first)
        plain.append(_outputs(run))
        if level == 1:
            _borrow_corrections(plain[0], plain[1])
        if len(plain) >= 2:
            extrapolated.append(_extrapolate(plain[-1], plain[-2]))
        if len(plain) == 2:
            # Two grids: the extrapolated outputs are reported, with the error of the finer
            # plain ones, |fine - coarse| / 3 (order 2), as a conservative estimate.
            diff, shift = _distance(plain[-1], plain[-2])
            time_error, end_shift = diff / 3.0, shift / 3.0
            if time_error <= budget and end_shift <= end_budget:
                break
        if len(extrapolated) >= 2:
            diff, shift = _distance(extrapolated[-1], extrapolated[-2])
            # Order 4 after one extrapolation would make the newer one ~16 times closer;
            # measured in full contact against the projection method (tests/test_contact):
            # the error was 1.17 times diff / 15, so only order 3 (diff / 7) is assumed.
            time_error, end_shift = diff / 7.0, shift / 7.0
            if time_error <= budget and end_shift <= end_budget:
                break
    out = extrapolated[-1] if extrapolated else plain[-1]
    return out, float(time_error), float(end_shift), run


def _merge(bands: list[tuple[float, float]]) -> list[tuple[float, float]]:
    merged: list[list[float]] = []
    for lo, hi in sorted(bands):
        if merged and lo <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], hi)
        else:
            merged.append([lo, hi])
    return [(float(lo), float(hi)) for lo, hi in merged]


def _check_times(times: np.ndarray, count: int = 0) -> np.ndarray:
    """At most ``count`` (default ``CHECK_OUTPUTS``) of the output times, spread over them
    (the first and last kept)."""
    count = count or CHECK_OUTPUTS
    if times.size <= count:
        return times
    return times[np.unique(np.linspace(0, times.size - 1, count).round().astype(int))]


def _select_rule(space: Space, inp: Any, res: Resolution, first_steps: int, tol: float,
                 end_tol: float, bands: list[tuple[float, float]] | None = None,
                 first: dict[str, Any] | None = None
                 ) -> tuple[Panels, float, float, dict[str, Any]]:
    """The panel rule of the stepping and its spatial error (outputs, zone ends).

    On the first time grid of a few of the output times: a march on the base rule finds
    the bands the free ends sweep (unless ``bands`` are given); then a rule with band
    panels ``w`` is compared with one where every panel is finer (``w / 2`` over the
    bands, half the base width and half its grading at +-1 and the breakpoints, so that
    a rule without bands is checked too), halving ``w`` until ``SPACE_FACTOR`` times
    their difference meets a sixth of ``tol`` and half the zone-end tolerance (half of
    what success asks; or ``BAND_WIDTHS`` run out).
    """
    check = _check_times(inp.times)
    grid, widths, index = time_grid(check, first_steps, 0)

    def march(rule: Panels) -> dict[str, Any]:
        op = rule_operator(space.lam, rule)
        run = _march(space, inp, rule, op, space.m(rule.nodes), space.g(rule.nodes), grid,
                     widths, index, first=first)
        return _outputs(run)

    # The bands need the ends only to well within their margin: fewer times and a
    # coarser grading at the edges do (ends within ~1e-4 of the finer rules' on the
    # preset), at a quarter of the cost of a check march.
    if bands is None:
        locate = _check_times(inp.times, LOCATE_OUTPUTS)
        grid_l, widths_l, index_l = time_grid(locate, first_steps, 0)
        coarse = band_rule(space, Resolution(res.width, max(res.edge, LOCATE_EDGE)), [],
                           0.0)
        op_l = rule_operator(space.lam, coarse)
        located = _march(space, inp, coarse, op_l, space.m(coarse.nodes),
                         space.g(coarse.nodes), grid_l, widths_l, index_l, exact_ends=False,
                         first=first)
        bands = bands_from_ends(_outputs(located)["ends"], space.breakpoints)
    # every panel finer: the base width halved, its grading at +-1 and the breakpoints too
    finer = Resolution(res.width / 2.0, res.edge / 2.0)
    width = BAND_WIDTHS[0]
    rule = band_rule(space, res, bands, width)
    current = march(rule)
    while True:
        half = band_rule(space, finer, bands, width / 2.0)
        halved = march(half)
        diff, shift = _distance(current, halved)
        error, end_error = SPACE_FACTOR * diff, SPACE_FACTOR * shift
        if (error <= tol / 6 and end_error <= end_tol / 2) or width / 2.0 < BAND_WIDTHS[-1]:
            break
        # The halved rule becomes the candidate (its base is already the finer one).
        width /= 2.0
        rule, current = half, halved
    return rule, float(error), float(end_error), {"bands": bands, "width": width}


def _outside_bands(ends: list[list[float]], bands: list[tuple[float, float]],
                   breakpoints: tuple[float, ...]) -> int:
    """How many times have a free end outside every band."""
    count = 0
    for row in ends:
        free = bands_from_ends([row], breakpoints, margin=0.0)
        if any(not any(lo <= a and b <= hi for lo, hi in bands) for a, b in free):
            count += 1
    return count
