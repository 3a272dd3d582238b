"""One time march of unilateral contact under creep on a fixed panel rule.

At step ``n`` of a time grid the memory of the past pressures (:mod:`core.contact.memory`)
turns the problem into the elastic one of :mod:`core.contact.zones` with
``scale = 1 - w_n`` on the current pressure and the memory displacement
``e = F (memory of q_0 .. q_{n-1})``. The contact set is found at every step by the nodal
active set (warm-started from the step before), on one panel rule, so the memory of every
past pressure lives on the same nodes (an even problem, on its half x > 0:
:class:`~core.contact.systems.Mirror`). The zone ends of each output time are the roots of
the Nystrom pressure's interpolant on those nodes, after the kink of the pressure at each
end is taken out of the panel rule (:mod:`core.contact.kinks`; the corrections of
``_KINK_BATCH`` output times at once, the roots of all after the march). The error
control over rules and grids is :mod:`core.contact.creep`'s.
"""


from __future__ import annotations

import weakref
from typing import Any

import numpy as np

from core.cache import StageCache, fingerprint
from core.contact.active_set import (
    SHRINKS,
    NoContact,
    NodalState,
    contact_runs,
    nodal_active_set,
    refused_load,
    zones_from_nodes,
)
from core.contact.elastic import pressed_between_nodes
from core.contact.kinks import BATCH_ENTRIES, Corrected, corrected_roots, kinks_corrected
from core.contact.memory import pressure_memory
from core.contact.step import Space, Step, check_loads
from core.contact.systems import Mirror, StepSolver
from core.contact.zones import zone_kernel_accuracy
from core.discretize import (
    BARYCENTRIC_WEIGHTS,
    GAUSS_NODES,
    NODES_PER_PANEL,
    KernelOperator,
    Panels,
    kernel_operator,
)
from core.work import check_work

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


#: The mirrors of even problems' rules (:meth:`Mirror.of` compares F with its mirror image
#: entry by entry, ~30 ms at 2256 nodes), keyed by lam, the panel edges, m and g at the
#: nodes and the operator itself: the marches of one solve (its spatial check, its time
#: grids) share their rules and the rules' operators (:func:`rule_operator`).
_RULE_MIRRORS = StageCache("contact_rule_mirror", max_items=12, max_bytes=48 * 2**20)


def rule_mirror(lam: float, rule: Panels, op: np.ndarray, m: np.ndarray, g: np.ndarray
                ) -> Mirror | None:
    """:meth:`Mirror.of` the rule ``rule`` with its operator ``op`` and m and g at its
    nodes, cached; None when the problem on it is not even."""
    # the operator by identity (its entries hashed would cost as much as the comparison),
    # and a weak reference to it, so that an id reused by another array is not taken
    key = fingerprint(float(lam), np.asarray(rule.edges, dtype=float), np.asarray(m),
                      np.asarray(g), id(op))
    source, mirror = _RULE_MIRRORS.get_or_compute(
        key, lambda: (weakref.ref(op), Mirror.of(rule.nodes, rule.weights, op, m, g)))[0]
    if source() is not op:
        return Mirror.of(rule.nodes, rule.weights, op, m, g)
    return mirror


def march(space: Space, inp: Any, base, op: np.ndarray, m: np.ndarray, g: np.ndarray,
           grid: np.ndarray, widths: np.ndarray, out_index: np.ndarray,
           exact_ends: bool = True, first: dict[str, Any] | None = None) -> dict[str, Any]:
    """March over ``grid`` on the rule ``base`` (its Nystrom matrix ``op``, m and g at
    its nodes). ``first`` (shared by the marches of one solve): the zones of the first
    step, at loading, recorded by the first march and the start of the first step of
    the later ones (from full contact it took 4-6 sweeps, each with a new LU)."""
    # kink rows with kernel values to 1e-4 of the tighter of tol and the zone-end
    # tolerance (as the elastic zone operators): ~15 % less kernel work per correction
    accuracy = zone_kernel_accuracy(inp.tol)
    n_nodes = base.size
    steps = grid.size
    c_vals = inp.c(grid)
    loads = {name: np.asarray(fn(grid), dtype=float) for name, fn in inp.loads.items()}
    check_loads(inp.given, loads, grid)
    memory_of = creep_memory(inp.kernel, grid, widths, n_nodes)
    wanted = {int(i): k for k, i in enumerate(out_index)}
    # per output time: the state, its step, the memory density, the ends, the nodal ends
    # and, once corrected, the kink correction (kink_correction)
    states: list[tuple] = [None] * len(out_index)  # type: ignore
    active = None
    # an even problem (symmetric rule, m, g and F, a centred load) on the half x > 0
    mirror = (rule_mirror(space.lam, base, op, m, g) if Mirror.centred(inp.given, loads)
              else None)
    solver = StepSolver(mirror)
    pending: list[tuple[int, Any]] = []
    batch: list[tuple[int, tuple]] = []
    columns = 0  # the batch's cut-part nodes, at most (two parts of a panel per end)
    sweeps = 0
    unsettled = 0
    # the zones at loading, as an earlier march found them, until this one has its own
    zones = len(first["zones"]) if first is not None and "zones" in first else 0
    corners = np.zeros((steps, 2))
    for n in range(steps):
        check_work("following the contact zones under creep step by step", zones)
        memory_density = np.zeros(n_nodes)
        diag = 0.0
        if n > 0:
            memory_density, diag = memory_of.at(n)
        step = Step(float(c_vals[n]), 1.0 - diag,
                    {name: float(v[n]) for name, v in loads.items()})
        displacement = (op @ memory_density if mirror is None
                        else mirror.unfold(mirror.apply(memory_density)))
        start = active
        if n == 0 and first is not None and "zones" in first:
            start = nodes_in(base.nodes, first["zones"])
        try:
            state, count, settled = _step_state(base, op, m, g, step, displacement, start,
                                                solver, retry=n == 0)
            if (not state.active.any() and {"settlement", "tilt"} <= set(step.given)
                    and not np.any(memory_density)
                    and pressed_between_nodes(space, step.given["settlement"],
                                              step.given["tilt"])[0]):
                # it presses in between the nodes: not "no contact" (a crown held 1e-7
                # below its first touch read P = 0 with success); the elastic path
                # answers such a zone, the march refuses it
                raise NoContact(SHRINKS)
        except NoContact as exc:
            raise exc.at(grid[n], step.given, f"{refused_load(step.given)}: {exc.what} "
                         f"at t = {grid[n]:g} ({exc})") from None
        if n == 0 and first is not None and "zones" not in first and state.active.any():
            ends = zones_from_nodes(state, space.breakpoints)[0]
            first["zones"] = list(zip(ends[0::2], ends[1::2], strict=True))
        sweeps += count
        unsettled += not settled
        active = state.active
        corners[n] = corner_pressure(base, state.nystrom)
        zones = contact_runs(active)
        memory_of.record(n, state.q)
        if n in wanted:
            nodal, pinned = ([], []) if not state.active.any() else zones_from_nodes(
                state, space.breakpoints)[:2]
            if exact_ends and nodal:
                # corrected in batches, each step with its own factors (kept by a
                # snapshot), while the batch is small: its cut parts' rows come from one
                # call (core.contact.kinks.BATCH_ENTRIES); many zones on many nodes are
                # corrected at once (ten held steps of a wavy contact of 1700 nodes held
                # 440 MB of factors); the roots of all at the end
                batch.append((wanted[n], (step, state, displacement, memory_density,
                                          solver.snapshot(), (nodal, pinned))))
                columns += 2 * len(nodal) * NODES_PER_PANEL
                if len(batch) == _KINK_BATCH or n_nodes * columns > BATCH_ENTRIES:
                    pending += _corrected(space, op, m, g, batch, accuracy)
                    batch, columns = [], 0
            states[wanted[n]] = (state, step, memory_density, nodal, nodal)
    if batch:
        pending += _corrected(space, op, m, g, batch, accuracy)
    if pending:
        roots = corrected_roots(space, [c for _, c in pending], accuracy)
        for (k, c), ends in zip(pending, roots, strict=True):
            states[k] = states[k][:3] + (ends, states[k][4], kink_correction(states[k][0], c))
    return {"states": states, "sweeps": sweeps, "unsettled": unsettled, "steps": steps - 1,
            "breakpoints": space.breakpoints, "grid": grid, "corner_pressure": corners,
            "factorizations": solver.factorizations,
            "back_substitutions": solver.back_substitutions}


def corner_pressure(panels: Panels, nystrom: np.ndarray) -> np.ndarray:
    """The Nystrom pressure Q of a step (:class:`NodalState`) at x = -1 and +1, from the
    interpolant of the first and the last panel's nodes [dimensionless, like q].

    Q is one smooth function across a free end: q inside the zone, minus the gap over
    c m outside it. So it is positive where a corner is in contact and negative where it
    has lifted, and it passes through zero, smoothly in time, where the corner touches
    down or lifts off: the root between two steps of opposite signs locates that time
    (:func:`core.contact.creep.corner_contact_changes`), which the march's trapezoid
    steps must land on (a kink of q in time; inside a step Richardson's estimate read a
    crown's q at 1/5 of its error)."""
    values = np.empty(2)
    for side, (panel, end) in enumerate(((0, -1.0), (panels.n_panels - 1, 1.0))):
        local = nystrom[panel * NODES_PER_PANEL:(panel + 1) * NODES_PER_PANEL]
        # the barycentric form holds off the nodes too: its value at the panel's end
        ratio = BARYCENTRIC_WEIGHTS / (end - GAUSS_NODES)
        values[side] = ratio @ local / ratio.sum()
    return values


def creep_memory(kernel: Any, grid: np.ndarray, widths: np.ndarray, n_nodes: int) -> Any:
    """The memory of past pressures (:func:`core.contact.memory.pressure_memory`) of a
    march over ``grid`` (steps ``widths``) on ``n_nodes`` nodes: its trapezoid weights."""
    inner = np.zeros(grid.size)
    inner[:-1] += 0.5 * widths
    inner[1:] += 0.5 * widths
    return pressure_memory(kernel, grid, inner, n_nodes)


def nodes_in(x: np.ndarray, zones: list[tuple[float, float]]) -> np.ndarray:
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


#: Output times whose kink corrections are made together at most (one evaluation of F on
#: their cut parts while small): each holds its step's LU factors meanwhile (~0.7 MB at
#: 300 contact nodes), so the batch stays short.
_KINK_BATCH = 10


def _corrected(space: Space, op: np.ndarray, m: np.ndarray, g: np.ndarray,
               batch: list[tuple[int, tuple]], accuracy: float) -> list[tuple[int, Any]]:
    done = kinks_corrected(space, op, m, g, [row for _, row in batch], accuracy)
    return [(k, c) for (k, _), c in zip(batch, done, strict=True)]


def kink_correction(state: NodalState, corrected: Corrected) -> dict[str, Any]:
    """What the kink-corrected solution of an output time adds to its nodal state
    (:mod:`core.contact.kinks`), in the terms of :func:`march_outputs`: to the effective
    density on the rule (``effective``), the density on the cut parts of the end panels
    (``cut``, ``cut_effective``; none without a free end) and to the settlement and tilt.
    The pressure formula with it vanishes at the corrected zone ends; with the nodal state
    alone it does not quite (the end panel's Gauss rule across the kink). A punch of several
    whose own ends are all pinned still has one where a neighbour's were corrected (the
    coupled solve moves its density too); for one punch it is then zero."""
    scale = corrected.step.scale
    return {
        # the end panels' Gauss sums of the nodal q are taken off in ``density``
        "effective": scale * (corrected.density - state.q),
        "cut": corrected.cut,
        "cut_effective": scale * corrected.cut_density,
        "settlement": corrected.delta - state.settlement,
        "tilt": corrected.alpha - state.tilt,
    }


def march_outputs(run: dict[str, Any]) -> dict[str, Any]:
    """The outputs of one march, with what the pressure needs (all linear in the steps)."""
    states = run["states"]
    return {
        "settlement": np.array([row[0].settlement for row in states]),
        "tilt": np.array([row[0].tilt for row in states]),
        "force": np.array([row[0].force for row in states]),
        "moment": np.array([row[0].moment for row in states]),
        # without the kink defect (core/contact/kinks.py) when the march corrected them
        "ends": [list(row[3]) for row in states],
        "nodal_ends": [list(row[4]) for row in states],
        # Q(x) = [delta + alpha x - g - F(effective)(x)] / (c m), effective = s q - memory
        "effective": np.column_stack([row[1].scale * row[0].q - row[2] for row in states]),
        # the pressure at the nodes, for the time estimate of q (grids on one rule)
        "q": np.column_stack([row[0].q for row in states]),
        "c": np.array([row[1].c for row in states]),
        # the kink corrections (kink_correction), None where not made
        "corrections": [row[5] if len(row) > 5 else None for row in states],
    }

