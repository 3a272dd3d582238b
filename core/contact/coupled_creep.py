"""Lift-off of several punches on one creeping base: one march over all their contact sets.

The single punch's creep lift-off (:mod:`core.contact.creep`, :mod:`core.contact.march`)
over the punches of :mod:`core.contact.coupled`, each in its own scaling:

- **One memory.** V acts on the displacement of the whole surface, so the memory of the
  past pressures of every punch is one density over all their nodes
  (:func:`core.contact.march.creep_memory`), and its displacement on punch ``p`` is the
  coupled operator applied to it: punch ``p``'s own memory through ``F_p`` and its
  neighbours' pressure histories through ``(lam_r / lam_p) F_r`` (the same hereditary
  operator, ``e_p = sum_r A_pr (memory of q_r)``). Each step is then the coupled elastic
  problem with ``scale = 1 - w_n`` and this ``e``: the coupled nodal active set
  (:func:`core.contact.coupled.coupled_active_set`, kept factors from step to step).
- **Rules.** Each punch has its own fixed rule with fine panels over the bands its free
  ends sweep (:func:`core.contact.bands.band_rule`); the band panels of all punches are
  refined together, and all punches share the time grids (:func:`core.contact.creep.
  controlled_march` with :class:`CoupledMarches`: the outputs of two rules or grids are
  compared punch by punch, each relative to its own size, the largest difference
  counts).
- **Zone ends.** At an output time the kink of each punch's pressure at its free ends
  is taken out of the panel rule as for one punch (:mod:`core.contact.kinks`): the
  defects of every punch's cut panels enter the coupled equation (their rows on the
  other punches through the coupling), one coupled solve removes them, and each free end
  is the root of its punch's corrected Nystrom pressure, the neighbours' corrected
  pressures and memories adding their displacement (``Corrected.coupling``).

Every punch's answer carries the one estimate of the scene's march (time and space, the
largest over the punches), as one march serves all. Zones further apart than
:data:`core.engines.nystrom.multi.NEGLIGIBLE_GAP` base thicknesses are not coupled.
"""

from __future__ import annotations

import dataclasses
import time as _time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from core.cache import fingerprint
from core.contact.active_set import NoContact, NodalState, contact_runs, zones_from_nodes
from core.contact.bands import band_rule, bands_from_ends, merge_bands
from core.contact.coupled import (
    CoupledBase,
    CoupledStepSolver,
    Resolutions,
    _given_rhs_all,
    checked_loads,
    coupled_active_set,
    coupled_bordered_solve,
)
from core.contact.creep import (
    FIRST_STEPS,
    LOCATE_EDGE,
    MarchMemo,
    _borrow_corrections,
    _corner_q_between_rules,
    _distance,
    _extrapolate,
    _outside_bands,
    _q_between_rules,
    _zones_of,
    controlled_march,
    corners_refined,
    creep_verdict,
    free_end_residual,
    free_end_slope,
    graded_halvings,
    largest_part,
    output_snapshot,
    transient_windows,
)
from core.contact.kinks import Corrected, _contact_parts, _cut_rule, _part_rows, corrected_roots
from core.contact.march import (
    corner_pressure,
    creep_memory,
    kink_correction,
    nodes_in,
    rule_operator,
)
from core.contact.result import UnilateralSolution
from core.contact.step import LoadNotCarried, Step, check_loads
from core.contact.unilateral import creep_resolution
from core.contact.zones import Resolution, zone_kernel_accuracy
from core.discretize import NODES_PER_PANEL, Panels
from core.engines.nystrom import PunchGeometry
from core.kernel import FULL_ACCURACY
from core.problem import TimeInputs
from core.work import check_work


class CoupledRules:
    """The punches' fixed rules on one base: their coupled operator (own blocks the
    single punch's cached ones, :func:`core.contact.march.rule_operator`), and their
    nodes, weights, m and g in one vector (punch by punch)."""

    def __init__(self, base: CoupledBase, rules: Sequence[Panels]) -> None:
        self.rules = tuple(rules)
        own = [rule_operator(space.lam, rule) for space, rule in zip(base.spaces, rules,
                                                                    strict=True)]
        self.op = base.operator(self.rules, own)
        sizes = [rule.size for rule in rules]
        self.offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
        self.owner = np.repeat(np.arange(len(rules)), sizes)
        self.x = np.concatenate([rule.nodes for rule in rules])
        self.w = np.concatenate([rule.weights for rule in rules])
        self.m = np.concatenate([s.m(r.nodes) for s, r in zip(base.spaces, rules, strict=True)])
        self.g = np.concatenate([s.g(r.nodes) for s, r in zip(base.spaces, rules, strict=True)])

    def part(self, p: int) -> slice:
        """Punch ``p``'s nodes in the joint vectors."""
        return slice(int(self.offsets[p]), int(self.offsets[p + 1]))


class CoupledMarches:
    """The marches of several punches as :func:`core.contact.creep.controlled_march` asks
    for them (:class:`core.contact.creep.OnePunchMarches` says what): a rule is one
    :class:`~core.discretize.Panels` per punch, a resolution a
    :class:`core.contact.coupled.Resolutions`, outputs and bands one per punch."""

    def __init__(self, base: CoupledBase, inputs: Sequence[TimeInputs],
                 loads: Sequence[dict[str, Callable]], tol: float) -> None:
        self.base, self.inp, self.loads, self.tol = base, inputs[0], tuple(loads), tol
        self.givens = tuple(one.given for one in inputs)
        self._systems: dict[str, CoupledRules] = {}
        self._memo = MarchMemo()

    def system(self, rules: Sequence[Panels]) -> CoupledRules:
        key = fingerprint(*(np.asarray(rule.edges, dtype=float) for rule in rules))
        if key not in self._systems:
            # the rules of one solve: the locating, the check pairs and the chosen one
            self._systems[key] = CoupledRules(self.base, rules)
        return self._systems[key]

    def rule(self, res: Resolutions, bands: Sequence[list[tuple[float, float]]],
             width: float) -> tuple[Panels, ...]:
        return tuple(band_rule(space, r, b, width) for space, r, b
                     in zip(self.base.spaces, res.levels, bands, strict=True))

    @staticmethod
    def halved(res: Resolutions) -> Resolutions:
        return Resolutions(tuple(Resolution(r.width / 2.0, r.edge / 2.0) for r in res.levels))

    @staticmethod
    def edges_halved(res: Resolutions) -> Resolutions:
        return Resolutions(tuple(Resolution(r.width, r.edge / 2.0) for r in res.levels))

    @staticmethod
    def nodes(rule: tuple[Panels, ...]) -> int:
        """How many nodes the coupled marches on ``rule`` are dense in (all punches')."""
        return int(sum(panels.nodes.size for panels in rule))

    def locating(self, res: Resolutions) -> tuple[Panels, ...]:
        return tuple(band_rule(space, Resolution(r.width, max(r.edge, LOCATE_EDGE)), [], 0.0)
                     for space, r in zip(self.base.spaces, res.levels, strict=True))

    def run(self, rules: Sequence[Panels], grid: np.ndarray, widths: np.ndarray,
            index: np.ndarray, exact_ends: bool = True, first: dict[str, Any] | None = None
            ) -> tuple[list[dict[str, Any]], dict[str, Any]]:
        def make() -> tuple[list[dict[str, Any]], dict[str, Any]]:
            run = march_punches(self, self.system(rules), grid, widths, index, exact_ends,
                                first)
            return punch_outputs(run), run

        return self._memo.get(tuple(rules), grid, widths, index, exact_ends, make)

    def keep(self, *rules: Sequence[Panels]) -> None:
        """Forget the marches on any rules but ``rules`` (one rule per punch each)."""
        self._memo.keep(*(tuple(one) for one in rules))

    @staticmethod
    def distance(a: list[dict[str, Any]], b: list[dict[str, Any]]) -> tuple[float, float]:
        """The largest over the punches of :func:`core.contact.creep._distance` (each
        punch's histories relative to its own size)."""
        pairs = [_distance(one, two) for one, two in zip(a, b, strict=True)]
        return max(d for d, _ in pairs), max(s for _, s in pairs)

    def rule_distance(self, rules: Sequence[Panels], a: list[dict[str, Any]],
                      finer: Sequence[Panels], b: list[dict[str, Any]],
                      bands: Sequence[list[tuple[float, float]]]
                      ) -> tuple[float, float, np.ndarray, np.ndarray]:
        """:meth:`distance`, and q between the rules punch by punch as one punch compares
        it (:func:`core.contact.creep._q_between_rules`: the finer march's formula at the
        coarser nodes, off the bands and at the times that punch has no free end; and
        :func:`core.contact.creep._corner_q_between_rules` at its corners), each punch's
        formula with the others' push (their effective densities). The histories alone
        missed q at the edges: two punches on a creeping base (EC2), q 5.5e-7 off at x =
        0.992 with a spatial estimate of 2e-9. The third and fourth values: each corner's
        part and whether it is refined (:func:`core.contact.creep.corners_refined`), punch
        by punch."""
        outputs, shift = self.distance(a, b)
        corners, refined = [], []
        for p, space in enumerate(self.base.spaces):
            def pushing(rules_of: Sequence[Panels], answers: list[dict[str, Any]],
                        p: int = p) -> Callable[[np.ndarray], list]:
                def others(x: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
                    return [(self.base.rows(p, r, rules_of[r], x), answers[r]["effective"])
                            for r in self.base.pairs[p] if rules_of[r].size]
                return others

            outputs = max(outputs, _q_between_rules(space, rules[p], a[p], finer[p], b[p],
                                                    bands[p], pushing(finer, b)))
            corners.append(_corner_q_between_rules(
                space, rules[p], a[p], finer[p], b[p], (pushing(rules, a), pushing(finer, b))))
            refined.append(corners_refined(space, rules[p], finer[p]))
        parts = np.concatenate(corners)
        return (max(outputs, largest_part(parts)), shift, parts, np.concatenate(refined))

    @staticmethod
    def banded(bands: Sequence[list[tuple[float, float]]]) -> bool:
        """Whether the punches' rules on ``bands`` have band panels."""
        return any(bool(b) for b in bands)

    def end_slope(self, rules: Sequence[Panels], out: list[dict[str, Any]]) -> float:
        """The largest over the punches of :func:`core.contact.creep.free_end_slope`."""
        return max(free_end_slope(rule.nodes, one["q"], one["ends"], space.breakpoints)
                   for rule, one, space in zip(rules, out, self.base.spaces, strict=True))

    @staticmethod
    def extrapolate(fine: list[dict[str, Any]], coarse: list[dict[str, Any]]
                    ) -> list[dict[str, Any]]:
        return [_extrapolate(f, c) for f, c in zip(fine, coarse, strict=True)]

    @staticmethod
    def borrow(coarse: list[dict[str, Any]], fine: list[dict[str, Any]]) -> None:
        for c, f in zip(coarse, fine, strict=True):
            _borrow_corrections(c, f)

    def bands(self, out: list[dict[str, Any]],
              bands: Sequence[list[tuple[float, float]]] | None = None
              ) -> list[list[tuple[float, float]]]:
        found = [bands_from_ends(one["ends"], space.breakpoints)
                 for one, space in zip(out, self.base.spaces, strict=True)]
        if bands is None:
            return found
        return [merge_bands(list(old) + new) for old, new in zip(bands, found, strict=True)]

    def strays(self, out: list[dict[str, Any]],
               bands: Sequence[list[tuple[float, float]]]) -> int:
        """How many output times have a free end of some punch outside its bands."""
        count = 0
        for k in range(len(out[0]["ends"])):
            count += any(_outside_bands([one["ends"][k]], b, space.breakpoints)
                         for one, b, space in zip(out, bands, self.base.spaces, strict=True))
        return count


def march_punches(marches: CoupledMarches, system: CoupledRules, grid: np.ndarray,
                  widths: np.ndarray, out_index: np.ndarray, exact_ends: bool = True,
                  first: dict[str, Any] | None = None) -> dict[str, Any]:
    """March every punch over ``grid`` on the rules of ``system`` (see the module notes
    and :func:`core.contact.march.march`; ``first`` holds each punch's zones at loading
    from the first march)."""
    base, inp = marches.base, marches.inp
    accuracy = zone_kernel_accuracy(marches.tol)
    op = system.op
    steps = grid.size
    c_vals = inp.c(grid)
    loads = []
    for k, (given, one) in enumerate(zip(marches.givens, marches.loads, strict=True)):
        values = {name: np.broadcast_to(np.asarray(fn(grid), dtype=float),
                                        grid.shape).astype(float) for name, fn in one.items()}
        try:
            check_loads(given, values, grid)
        except LoadNotCarried as exc:
            raise exc.of_punch(k) from None
        loads.append(values)
    memory_of = creep_memory(inp.kernel, grid, widths, system.x.size)
    wanted = {int(i): k for k, i in enumerate(out_index)}
    outputs: list[tuple] = [None] * len(out_index)  # type: ignore
    active = None
    solver = CoupledStepSolver()
    unsettled = 0
    zones = 0  # the most runs of contact nodes under one punch, at the last step
    # each punch's Nystrom pressure at its corners, every step (where one touches down)
    corners = np.zeros((steps, 2 * len(system.rules)))
    for n in range(steps):
        check_work("following the contact zones of several punches under creep step by step",
                   zones)
        memory_density = np.zeros(system.x.size)
        diag = 0.0
        if n > 0:
            memory_density, diag = memory_of.at(n)
        step_data = [Step(float(c_vals[n]), 1.0 - diag,
                          {name: float(v[n]) for name, v in one.items()}) for one in loads]
        displacement = op @ memory_density
        start = active
        if n == 0 and first is not None and "zones" in first:
            start = np.concatenate([nodes_in(rule.nodes, zones) for rule, zones
                                    in zip(system.rules, first["zones"], strict=True)])
        try:
            states, settled = _step_states(base, system, step_data, displacement, start,
                                           solver, retry=n == 0)
        except NoContact as exc:
            raise exc.of_punches(grid[n], marches.givens,
                                 f"{exc}: {exc.what} at t = {grid[n]:g}") from None
        if n == 0 and first is not None and "zones" not in first and any(
                s.active.any() for s in states):
            zones = []
            for state, space in zip(states, base.spaces, strict=True):
                ends = zones_from_nodes(state, space.breakpoints)[0] if state.active.any() \
                    else []
                zones.append(list(zip(ends[0::2], ends[1::2], strict=True)))
            first["zones"] = zones
        unsettled += not settled
        corners[n] = np.concatenate([corner_pressure(rule, s.nystrom)
                                     for rule, s in zip(system.rules, states, strict=True)])
        zones = max(contact_runs(s.active) for s in states)
        active = np.concatenate([s.active for s in states])
        memory_of.record(n, np.concatenate([s.q for s in states]))
        if n in wanted:
            nodal = [zones_from_nodes(s, space.breakpoints)[:2] if s.active.any() else
                     ([], []) for s, space in zip(states, base.spaces, strict=True)]
            corrected = None
            if exact_ends and any(ends for ends, _ in nodal):
                corrected = _corrected(base, system, step_data, states, displacement,
                                       memory_density, nodal, accuracy, solver)
            outputs[wanted[n]] = (states, step_data, memory_density, nodal, corrected)
    # each punch's free ends, the roots of its corrected Q, all output times at once
    ends = [[list(nodal[p][0]) for p in range(len(base.punches))]
            for _, _, _, nodal, _ in outputs]
    for p, space in enumerate(base.spaces):
        batch = [(k, row[4][p]) for k, row in enumerate(outputs) if row[4] is not None
                 and row[4][p].free]
        if batch:
            roots = corrected_roots(space, [c for _, c in batch], accuracy)
            for (k, _), found in zip(batch, roots, strict=True):
                ends[k][p] = found
    return {"outputs": outputs, "ends": ends, "unsettled": unsettled, "steps": steps - 1,
            "system": system, "grid": grid, "corner_pressure": corners,
            "factorizations": solver.factorizations, "iterations": solver.iterations,
            "direct_solves": solver.direct}


def _step_states(base: CoupledBase, system: CoupledRules, steps: Sequence[Step],
                 displacement: np.ndarray, start: np.ndarray | None, solver: CoupledStepSolver,
                 retry: bool) -> tuple[list[NodalState], bool]:
    """The coupled nodal active set of one step from ``start``; with ``retry``, a start
    that does not settle (or leaves a punch no contact) is retried from full contact (as
    :func:`core.contact.march._step_state`)."""
    if retry and start is not None:
        try:
            states, settled = coupled_active_set(base, system.rules, system.op, steps, start,
                                                 memory=displacement, solver=solver)
            if settled:
                return states, settled
        except NoContact:
            pass
        start = None
    return coupled_active_set(base, system.rules, system.op, steps, start,
                              memory=displacement, solver=solver)


def _corrected(base: CoupledBase, system: CoupledRules, steps: Sequence[Step],
               states: Sequence[NodalState], displacement: np.ndarray,
               memory_density: np.ndarray, nodal: Sequence[tuple[list[float], list[bool]]],
               accuracy: float, solver: CoupledStepSolver) -> list[Corrected]:
    """Every punch's step solved again without the kink defect of its free ends
    (:func:`core.contact.kinks.kinks_corrected` over the coupled system): each punch's
    :class:`core.contact.kinks.Corrected`, its ``coupling`` the displacement its
    neighbours' corrected pressures and memories add."""
    n_punches = len(states)
    x, w = system.x, system.w
    scale = steps[0].scale
    q_all = np.concatenate([s.q for s in states])
    active = np.concatenate([s.active for s in states])
    cuts, parts_of, free_of = [], [], []
    for state, (ends, pinned) in zip(states, nodal, strict=True):
        free = [k for k, pin in enumerate(pinned) if not pin]
        zones = [(ends[2 * i], ends[2 * i + 1]) for i in range(len(ends) // 2)]
        parts = _contact_parts(state.panels, zones, [ends[k] for k in free]) if free else {}
        cut, values = _cut_rule(state.panels, state, parts)
        cuts.append((cut, values))
        parts_of.append(parts)
        free_of.append(free)
    defect = np.zeros(x.size)
    givens = [dict(s.given) for s in steps]
    for p, ((cut, values), parts) in enumerate(zip(cuts, parts_of, strict=True)):
        if not cut.n_panels:
            continue
        cols = system.offsets[p] + np.concatenate([
            np.arange(k * NODES_PER_PANEL, (k + 1) * NODES_PER_PANEL) for k in parts])
        for t in (p, *base.pairs[p]):
            idx = system.offsets[t] + np.nonzero(states[t].active)[0]
            if not idx.size:
                continue
            rows = (_part_rows(base.spaces[p].lam, cut, x[idx], accuracy=accuracy) if t == p
                    else base.rows(t, p, cut, x[idx], accuracy))
            defect[idx] += rows @ values - op_block(system.op, idx, cols) @ q_all[cols]
        # the force and moment the cut parts carry beyond the panels' Gauss sums
        if "force" in givens[p]:
            givens[p]["force"] -= float(cut.weights @ values - w[cols] @ q_all[cols])
        if "moment" in givens[p]:
            givens[p]["moment"] -= float((cut.weights * cut.nodes) @ values
                                         - (w[cols] * x[cols]) @ q_all[cols])
    rhs = _given_rhs_all(steps, system.owner, x, system.g) + displacement - scale * defect
    idx = np.nonzero(active)[0]
    q_new = np.zeros(x.size)
    q_new[idx], delta, alpha = coupled_bordered_solve(system.op, system.m, x, w, system.owner,
                                                      steps[0].c, scale, givens, rhs, idx,
                                                      solver)
    densities = []
    for p, (state, parts) in enumerate(zip(states, parts_of, strict=True)):
        density = q_new[system.part(p)].copy()
        # the cut panels' Gauss sums taken off with the pressure the defect took them with
        for k in parts:
            cols = slice(k * NODES_PER_PANEL, (k + 1) * NODES_PER_PANEL)
            density[cols] -= state.q[cols]
        densities.append(density)
    out = []
    for p in range(n_punches):
        sources = [(r, system.rules[r], memory_density[system.part(r)] - scale * densities[r],
                    cuts[r][0], -scale * cuts[r][1]) for r in base.pairs[p]]
        out.append(Corrected(list(nodal[p][0]), free_of[p], states[p].panels, cuts[p][0],
                             densities[p], cuts[p][1], memory_density[system.part(p)],
                             float(delta[p]), float(alpha[p]), steps[p],
                             _coupling(base, p, sources, accuracy) if sources else None))
    return out


def op_block(op: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """``op`` on the nodes ``rows`` x ``cols``."""
    return op[np.ix_(rows, cols)]


def _coupling(base: CoupledBase, p: int, sources: list[tuple], accuracy: float
              ) -> Callable[[np.ndarray], np.ndarray]:
    """The displacement on punch ``p`` of ``sources``: per neighbour ``r`` a density on
    its rule and one on its cut parts (None: none; each already signed and weighted)."""

    def e_p(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        out = np.zeros(t.size)
        for r, rule, density, cut, cut_density in sources:
            out += base.rows(p, r, rule, t, accuracy) @ density
            if cut is not None and cut.n_panels:
                out += base.rows(p, r, cut, t, accuracy) @ cut_density
        return out

    return e_p


def punch_outputs(run: dict[str, Any]) -> list[dict[str, Any]]:
    """Each punch's outputs of one march (as :func:`core.contact.march.march_outputs`)."""
    system = run["system"]
    rows = run["outputs"]
    out = []
    for p in range(len(system.rules)):
        part = system.part(p)
        states = [row[0][p] for row in rows]
        out.append({
            "settlement": np.array([s.settlement for s in states]),
            "tilt": np.array([s.tilt for s in states]),
            "force": np.array([s.force for s in states]),
            "moment": np.array([s.moment for s in states]),
            "ends": [list(ends[p]) for ends in run["ends"]],
            "nodal_ends": [list(row[3][p][0]) for row in rows],
            # Q_p = [delta + alpha x - g - sum_r A_pr (effective_r)] / (c m), as one punch
            "effective": np.column_stack([row[1][p].scale * row[0][p].q
                                          - row[2][part] for row in rows]),
            "q": np.column_stack([row[0][p].q for row in rows]),
            "c": np.array([row[1][p].c for row in rows]),
            # the kink corrections (core.contact.march.kink_correction), None where not made
            "corrections": [None if row[4] is None else kink_correction(row[0][p], row[4][p])
                            for row in rows],
        })
    return out


def solve_creep_punches(punches: Sequence[PunchGeometry], inputs: Sequence[TimeInputs],
                        first_steps: int = FIRST_STEPS,
                        time_breaks: Sequence[float] = ()) -> list[UnilateralSolution]:
    """Lift-off of several punches on one creeping base (see the module notes).

    ``punches`` and ``inputs`` as for :func:`core.contact.solve_unilateral_punches`, on
    one creeping base (every ``kernel`` set; the same times, ``c`` and kernel).
    ``first_steps``: nominal steps of the first time grid; ``time_breaks``: times where a
    given load of any punch jumps (no time step straddles one). Returns one
    :class:`core.contact.result.UnilateralSolution` per punch (its own scaling,
    ``contact_set`` in its own coordinates). Raises ValueError naming ``punches[k]``
    when its loads leave it no contact.
    """
    started = _time.perf_counter()
    base = CoupledBase(punches)
    times = inputs[0].times
    for k, one in enumerate(inputs):
        if one.kernel is None:
            raise ValueError(f"punches[{k}]: the creep lift-off of several punches needs a "
                             "creeping base")
        if not np.array_equal(one.times, times):
            raise ValueError(f"punches[{k}]: all punches share the output times")
    checked_loads(inputs, times)
    tol = min(p.geometry.tol for p in base.punches)
    res = Resolutions(tuple(creep_resolution(s.lam, s.m) for s in base.spaces))
    marches = CoupledMarches(base, inputs, [one.loads for one in inputs], tol)
    (rules, out, run, band_note, strays, error, end_error, time_error,
     space_error, end_q_error) = controlled_march(marches, times, tol, res, first_steps,
                                                  tuple(float(b) for b in time_breaks),
                                                  graded_halvings(inputs[0].kernel, times),
                                                  transient_windows(inputs[0].kernel, times,
                                                                  time_breaks, tol))
    zones_of, snapshots_of = [], []
    for p, mine in enumerate(out):
        zones = _zones_of(mine)
        snapshots = []
        for k in range(times.size):
            # each punch's pressure as one punch's (kink-corrected where made, see
            # core.contact.creep.output_snapshot), its neighbours' in its formula the same way
            own = output_snapshot(rules[p], mine, k, zones[k])
            sources = []
            for r in base.pairs[p]:
                other = output_snapshot(rules[r], out[r], k, [])
                sources.append((r, rules[r], -other.q, other.cut,
                                None if other.cut_q is None else -other.cut_q))
            snapshots.append(dataclasses.replace(
                own, coupling=_coupling(base, p, sources, FULL_ACCURACY) if sources else None))
        zones_of.append(zones)
        snapshots_of.append(snapshots)
    # q at each punch's own free ends, of its own largest q (as for one punch)
    residual = max(free_end_residual(space, snapshots, float(np.max(np.abs(mine["q"]),
                                                                    initial=0.0)))
                   for space, mine, snapshots in zip(base.spaces, out, snapshots_of,
                                                     strict=True))
    error, end_q_error = error + residual, end_q_error + residual
    success, flags, message = creep_verdict(error, end_error, time_error, space_error, run,
                                            strays, tol,
                                            f"under creep ({len(base.punches)} punches)",
                                            end_q_error)
    seconds = _time.perf_counter() - started
    answers = []
    for p, (space, mine) in enumerate(zip(base.spaces, out, strict=True)):
        zones, snapshots = zones_of[p], snapshots_of[p]
        info = {
            "contact": "unilateral",
            "error_estimate": error,
            "time_error_estimate": time_error,
            "spatial_error_estimate": space_error,
            "zone_end_error": end_error,
            "zone_end_pressure_error": float(end_q_error),
            "success": bool(success),
            "flags": list(flags),
            "message": message,
            "n_steps": int(run["steps"]),
            "n_nodes": int(rules[p].size),
            "end_bands": band_note["bands"][p],
            "band_panel_width": band_note["width"],
            "min_pressure": 0.0,
            "punches": len(base.punches),
            "seconds": seconds,
        }
        answers.append(UnilateralSolution(
            times.copy(), mine["settlement"], mine["tilt"], mine["force"], mine["moment"],
            zones, info, space, snapshots, FULL_ACCURACY))
    return answers
