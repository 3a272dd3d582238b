"""Zone ends of a creep step without the kink error of the fixed panel rule.

Under creep the contact set is found on the nodes of one fixed panel rule
(:mod:`core.contact.march`). At a free zone end the pressure ``q = max(Q, 0)`` has a kink
inside a panel, and that panel's Gauss rule integrates ``F q`` and the resultants only to
a low order: on the lift-off preset with 0.04-wide band panels this left the ends ~4e-6
half-widths off, and only ~0.005-wide panels (8 times the cost) met 1e-6 that way.

The Nystrom pressure ``Q`` itself is smooth across the end (it is ``q`` on the zone and
``-gap / (c m)`` off it), so on the panel holding an end the pressure is the panel's
interpolant of the nodal ``Q`` cut at its root, ``q = P_Q`` on the contact part. Its
integrals there are taken exactly by a Gauss rule of that part alone (with the product
weights of the log kernel where a node is near), and the difference from the panel's
rule is a defect of the discrete equation. One solve with the step's kept factors
(:class:`core.contact.StepSolver`) removes it, and each free end is then the root
of that solution's Nystrom pressure evaluated by its formula (the panel interpolant of
the nodal Q errs near the end, see :func:`corrected_ends`).

Measured on the preset (20 output times, two time grids Richardson-extrapolated), with
0.04 / 0.02 / 0.005 band panels: the nodal ends were 3.8e-6 / 8.7e-7 / 3.4e-7 from the
solver at tol = 1e-7; the corrected ones are 4.3e-7 / 8.9e-8 / 2.8e-10 from each output
time re-solved on panels graded toward its end (same memory and time grid). What is left
is the kinks of past pressures in the creep memory, which this leaves (it falls with
the band panels). Elastic, on uniform 0.04 panels: 3.7e-8 from the refined ends, where
the nodal ones were 2.4e-6 off (tests/contact/test_contact.py).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from core.contact.active_set import NodalState, zones_from_nodes
from core.contact.step import Space, Step
from core.contact.systems import StepSolver, bordered_change, bordered_solve
from core.contact.zones import CORRECTING_ZONE_ENDS, ZONE_END_TOL
from core.discretize import (
    BARYCENTRIC_WEIGHTS,
    GAUSS_NODES,
    GAUSS_WEIGHTS,
    NEAR_FIELD,
    NODES_PER_PANEL,
    VALUES_TO_LEGENDRE,
    Panels,
    operator_rows_from_pairs,
)
from core.kernel import FULL_ACCURACY, legendre_log_moments
from core.work import check_work

#: Log moments at targets just off a part (1.05 < |z| <= NEAR_FIELD in its coordinate)
#: by a 64-point Gauss rule: ln|z - t| is analytic within the ellipse through z (rho >=
#: 1.37), so the rule errs like rho^(15 - 128) < 1e-15 against P_15's growth (rows
#: equal to operator_rows' to 2e-17, measured). The exact moments there need Miller's
#: backward recurrence (~90 steps): 0.29 ms a call against 0.20 at 224 targets.
_OVER_T, _OVER_W = np.polynomial.legendre.leggauss(64)
_OVER_P = np.polynomial.legendre.legvander(_OVER_T, NODES_PER_PANEL - 1)


def _part_rows(lam: float, part: Panels, targets: np.ndarray,
               accuracy: float = FULL_ACCURACY) -> np.ndarray:
    """Rows of F (len(targets) x 16 P) on the panels ``part``: as
    :func:`core.discretize.operator_rows`, its near-field moments computed as above.
    ``accuracy``: absolute accuracy of the kernel values."""
    z = (targets[:, None] - part.centers[None, :]) / part.half_widths[None, :]
    near = np.abs(z) <= NEAR_FIELD
    near_t, near_s = np.nonzero(near)
    zn = z[near_t, near_s]
    moments = np.empty((zn.size, NODES_PER_PANEL))
    inner = np.abs(zn) <= 1.05
    if inner.any():
        moments[inner] = legendre_log_moments(zn[inner], NODES_PER_PANEL - 1)
    if (~inner).any():
        outer = zn[~inner]
        moments[~inner] = (np.log(np.abs(outer[:, None] - _OVER_T[None, :]))
                           * _OVER_W[None, :]) @ _OVER_P
    h = part.half_widths[near_s][:, None]
    log_weights = h * (np.log(h) * GAUSS_WEIGHTS[None, :] + moments @ VALUES_TO_LEGENDRE)
    return operator_rows_from_pairs(lam, part, targets, np.arange(part.n_panels), near_t,
                                    near_s, log_weights, accuracy)


def _interpolation(center: float, half: float, targets: np.ndarray) -> np.ndarray:
    """Rows mapping a panel's 16 nodal values to ``targets`` (its barycentric form)."""
    d = (targets - center) / half
    diff = d[:, None] - GAUSS_NODES[None, :]
    rows = np.zeros((targets.size, GAUSS_NODES.size))
    hit = diff == 0.0
    exact = hit.any(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = BARYCENTRIC_WEIGHTS[None, :] / diff
    rows[~exact] = ratio[~exact] / ratio[~exact].sum(axis=1, keepdims=True)
    rows[exact] = hit[exact].astype(float)
    return rows


def _contact_parts(panels: Panels, zones: list[tuple[float, float]], free: list[float]
                   ) -> dict[int, list[tuple[float, float]]]:
    """For every panel holding a free end: the parts of it inside the zones."""
    lo_edges = panels.centers - panels.half_widths
    hi_edges = panels.centers + panels.half_widths
    parts: dict[int, list[tuple[float, float]]] = {}
    for end in free:
        p = int(np.clip(np.searchsorted(hi_edges, end), 0, panels.n_panels - 1))
        if p in parts:
            continue
        a, b = float(lo_edges[p]), float(hi_edges[p])
        parts[p] = [(max(a, lo), min(b, hi)) for lo, hi in zones
                    if min(b, hi) > max(a, lo)]
    return parts


def _defect(step: Step, state: NodalState, op: np.ndarray, cut: Panels,
            values: np.ndarray, parts: dict[int, list[tuple[float, float]]],
            idx: np.ndarray, cut_rows: np.ndarray) -> tuple[np.ndarray, float, float]:
    """(defect of s F q at the nodes ``idx``, 0 elsewhere; of the force; of the moment):
    the exact integrals of the cut interpolant (``values`` on the rule ``cut``, whose
    rows of F at the nodes ``idx`` are ``cut_rows``) less the panels' Gauss sums. Only
    the contact nodes carry the equation, so only they need it."""
    panels = state.panels
    cols = np.concatenate([np.arange(p * NODES_PER_PANEL, (p + 1) * NODES_PER_PANEL)
                           for p in parts])
    q_cols = state.q[cols]
    defect = np.zeros(panels.size)
    defect[idx] = cut_rows @ values - op[np.ix_(idx, cols)] @ q_cols
    force = float(cut.weights @ values - panels.weights[cols] @ q_cols)
    moment = float((cut.weights * cut.nodes) @ values
                   - (panels.weights[cols] * panels.nodes[cols]) @ q_cols)
    return step.scale * defect, force, moment


def corrected_ends(space: Space, step: Step, state: NodalState, op: np.ndarray,
                   m: np.ndarray, g: np.ndarray, memory: np.ndarray | None = None,
                   memory_density: np.ndarray | None = None,
                   solver: StepSolver | None = None) -> list[float]:
    """The zone ends of a step, sorted, two per zone, with the kink defect removed.

    ``state`` from :func:`core.contact.nodal_active_set` on the rule whose Nystrom
    matrix is ``op``; ``m``, ``g`` at its nodes; ``memory`` the memory displacement e at
    the nodes and ``memory_density`` the density it is F of (None for an elastic step).
    The contact nodes are kept and the step solved again with the defect; each free end
    is then the root of that solution's Nystrom pressure Q(x), evaluated by its formula
    (the interpolant of the nodal Q errs there: F of the kinked q puts a
    ``(x - end)^2 ln|x - end|`` term into Q, which 16-point panels read ~1e-4 wrong).
    Ends at +-1 or at breakpoints are kept (dimensionless throughout). The two halves,
    :func:`kink_corrected` and :func:`corrected_roots`, let a march correct every output
    time as it passes and find all the roots at once at its end.
    """
    if not state.active.any():
        return []
    return corrected_roots(space, [kink_corrected(space, step, state, op, m, g, memory,
                                                  memory_density, solver)])[0]


@dataclass
class Corrected:
    """One step's corrected solution, waiting for its roots (:func:`corrected_roots`):
    the nodal ends and which are free, the density on ``panels`` (the nodal rule) and on
    ``cut`` (the contact parts of the end panels), the memory density on ``panels``, and
    the step's scalars."""

    ends: list[float]
    free: list[int]
    panels: Panels
    cut: Panels
    density: np.ndarray
    cut_density: np.ndarray
    memory_density: np.ndarray | None
    delta: float
    alpha: float
    step: Step
    # the displacement e(x) other punches on the base add (their corrected pressures and
    # memories: core.contact.coupled_creep); None for one punch
    coupling: Callable[[np.ndarray], np.ndarray] | None = None


def kink_corrected(space: Space, step: Step, state: NodalState, op: np.ndarray,
                   m: np.ndarray, g: np.ndarray, memory: np.ndarray | None = None,
                   memory_density: np.ndarray | None = None,
                   solver: StepSolver | None = None,
                   nodal: tuple[list[float], list[bool]] | None = None) -> Corrected:
    """The step solved again with the kink defect (see :func:`corrected_ends`, same
    arguments; ``nodal`` the (ends, pinned) of :func:`zones_from_nodes` if known)."""
    if nodal is None:
        nodal = tuple(zones_from_nodes(state, space.breakpoints)[:2])  # type: ignore
    return kinks_corrected(space, op, m, g, [(step, state, memory, memory_density, solver,
                                              nodal)])[0]


def kinks_corrected(space: Space, op: np.ndarray, m: np.ndarray, g: np.ndarray,
                    steps: list[tuple], accuracy: float = FULL_ACCURACY) -> list[Corrected]:
    """:func:`kink_corrected` for several steps on one rule, each given as
    (step, state, memory, memory_density, solver, (ends, pinned)). Each step's
    ``solver`` must still hold that step's factors (:meth:`StepSolver.snapshot`).
    ``accuracy``: absolute accuracy of the kernel values in those rows."""
    prepared = []
    for step, state, memory, memory_density, solver, (ends, pinned) in steps:
        ends = list(ends)
        free = [k for k, p in enumerate(pinned) if not p]
        idx = np.nonzero(state.active)[0]
        zones = [(ends[2 * i], ends[2 * i + 1]) for i in range(len(ends) // 2)]
        parts = _contact_parts(state.panels, zones, [ends[k] for k in free]) if free else {}
        cut, values = _cut_rule(state.panels, state, parts)
        prepared.append((step, state, memory, memory_density, solver, ends, free, idx,
                         parts, cut, values))
    cuts = [row[9] for row in prepared]
    out: list[Corrected] = []
    if not any(c.n_panels for c in cuts):
        return [Corrected(row[5], [], row[1].panels, row[9], row[1].q, np.zeros(0), None,
                          row[1].settlement, row[1].tilt, row[0]) for row in prepared]
    panels = prepared[0][1].panels
    bounds = np.cumsum([0] + [c.nodes.size for c in cuts])
    # few steps and parts (the lift-off preset: ~100k entries): every node against every
    # step's cut parts in one call, each step reading its own columns (a call costs
    # ~0.6 ms of overhead); many (a wavy punch, 50 zones: 430 MB for a 1/20 share read):
    # each step's own parts at its own contact nodes
    joint = (_part_rows(space.lam, Panels.side_by_side(cuts), panels.nodes,
                        accuracy=accuracy)
             if panels.size * int(bounds[-1]) <= BATCH_ENTRIES else None)
    for k, (step, state, memory, memory_density, solver, ends, free, idx, parts, cut,
            values) in enumerate(prepared):
        if not free:
            out.append(Corrected(ends, [], panels, cut, state.q, np.zeros(0), None,
                                 state.settlement, state.tilt, step))
            continue
        x, w = panels.nodes, panels.weights
        if joint is not None:
            cut_rows = joint[np.ix_(idx, np.arange(bounds[k], bounds[k + 1]))]
        else:
            cut_rows = (_part_rows(space.lam, cut, x[idx], accuracy=accuracy)
                        if cut.n_panels else np.zeros((idx.size, 0)))
        defect, d_force, d_moment = _defect(step, state, op, cut, values, parts, idx,
                                            cut_rows)
        if solver is None:
            given = dict(step.given)
            if "force" in given:
                given["force"] -= d_force
            if "moment" in given:
                given["moment"] -= d_moment
            rhs = (step.given.get("settlement", 0.0) + step.given.get("tilt", 0.0) * x - g
                   - defect)
            if memory is not None:
                rhs = rhs + memory
            q_active, delta, alpha = bordered_solve(op, m, x, w, step.c, step.scale, given,
                                                    rhs, idx)
        else:
            # The system is linear and the state solves it without the defect: only the
            # change is solved, with the step's kept factors (and its state left for the
            # next step).
            change = {name: {"force": -d_force, "moment": -d_moment}.get(name, 0.0)
                      for name in step.given}
            dq, d_delta, d_alpha = bordered_change(op, m, x, w, step.c, step.scale, change,
                                                   -defect, idx, solver)
            q_active = state.q[idx] + dq
            delta, alpha = state.settlement + d_delta, state.tilt + d_alpha
        density = np.zeros(x.size)
        density[idx] = q_active
        # the cut panels' Gauss sums taken off with the pressure the defect took them with
        for p in parts:
            cols = slice(p * NODES_PER_PANEL, (p + 1) * NODES_PER_PANEL)
            density[cols] -= state.q[cols]
        out.append(Corrected(ends, free, panels, cut, density, values, memory_density,
                             delta, alpha, step))
    return out


def corrected_roots(space: Space, steps: list[Corrected], accuracy: float = FULL_ACCURACY
                    ) -> list[list[float]]:
    """The ends of each of ``steps`` (all on one nodal rule), free ones moved to the roots
    of their corrected Nystrom pressure Q: a secant from the interpolant's roots (within
    ~1e-4 of the true ones), all ends of all steps at once (F on the nodal rule and on
    every cut part evaluated at every end in one go; the kernel values to ``accuracy``,
    absolute)."""
    owner = np.array([s for s, c in enumerate(steps) for _ in c.free], dtype=int)
    out = [list(c.ends) for c in steps]
    if owner.size == 0:
        return out
    panels = steps[0].panels
    density = np.stack([c.density for c in steps])[owner]  # (ends, N)
    memory = None
    if any(c.memory_density is not None for c in steps):
        memory = np.stack([np.zeros(panels.size) if c.memory_density is None
                           else c.memory_density for c in steps])[owner]
    delta = np.array([steps[s].delta for s in owner])
    alpha = np.array([steps[s].alpha for s in owner])
    scale = np.array([steps[s].step.scale for s in owner])
    c_val = np.array([steps[s].step.c for s in owner])
    coupled = any(c.coupling is not None for c in steps)
    owners = np.unique(owner)
    zones = max(len(c.ends) for c in steps) // 2
    doing = f"{CORRECTING_ZONE_ENDS} {zones} contact zone(s) under creep"
    # few ends and parts: all in one call per evaluation, the other steps' columns
    # masked off (a call per step cost the lift-off preset 18 of its 26 ms of roots)
    cutting = [int(s) for s in owners if steps[int(s)].cut.n_panels]
    columns = sum(steps[s].cut.size for s in cutting)
    batched = None
    if cutting and 2 * owner.size * columns <= BATCH_ENTRIES:
        batched = (Panels.side_by_side([steps[s].cut for s in cutting]),
                   np.concatenate([np.full(steps[s].cut.size, s) for s in cutting]),
                   np.concatenate([steps[s].cut_density for s in cutting]))

    def nystrom(t: np.ndarray, rep: int) -> np.ndarray:
        check_work(doing, zones)
        base_rows = _part_rows(space.lam, panels, t, accuracy=accuracy)
        # each of the rep blocks of targets against the same ends' densities (tiled
        # copies of (ends, N) cost 150 MB each for a wavy punch's 2700 ends)
        blocks = base_rows.reshape(rep, owner.size, -1)
        fq = np.einsum("rij,ij->ri", blocks, density).ravel()
        # each end needs F of its own step's cut parts only: one block per step (every
        # end against every step's parts, then masked, was the steps' count times the
        # work and memory: 1.8 GB and 26 s of one call for a wavy punch's 1288 ends)
        of = np.tile(owner, rep)
        if batched is not None:
            joined, column_owner, joined_density = batched
            rows = _part_rows(space.lam, joined, t, accuracy=accuracy)
            rows[column_owner[None, :] != of[:, None]] = 0.0
            fq += rows @ joined_density
        else:
            for s in owners:
                cut = steps[s].cut
                if cut.n_panels:
                    at = of == s
                    fq[at] += _part_rows(space.lam, cut, t[at], accuracy=accuracy) \
                        @ steps[s].cut_density
        e = 0.0 if memory is None else np.einsum("rij,ij->ri", blocks, memory).ravel()
        if coupled:
            e = e + _couplings(steps, np.tile(owner, rep), t)
        return ((np.tile(delta, rep) + np.tile(alpha, rep) * t - space.g(t) + e
                 - np.tile(scale, rep) * fq) / (np.tile(c_val, rep) * space.m(t)))

    inward = np.array([1.0 if k % 2 == 0 else -1.0 for c in steps for k in c.free])
    a = np.array([c.ends[k] for c in steps for k in c.free])
    b = a + 1e-6 * inward
    both = nystrom(np.concatenate([a, b]), 2)
    fa, fb = both[:a.size], both[a.size:]
    for _ in range(_SECANT_STEPS):
        with np.errstate(divide="ignore", invalid="ignore"):  # an end already met: 0 / 0
            slope = (fb - fa) / (b - a)
        ok = np.isfinite(slope) & (slope != 0.0)
        step_x = np.where(ok, -fb / np.where(ok, slope, 1.0), 0.0)
        a, fa = b, fb
        b = b + step_x
        # a step below 1e-8 leaves ~1e-14 (the secant converges superlinearly from ~1e-4)
        if np.max(np.abs(step_x)) < 1e-2 * ZONE_END_TOL:
            break
        fb = nystrom(b, 1)
    widest = 2.0 * panels.half_widths.max()
    j = 0
    for s, c in enumerate(steps):
        ends = c.ends
        for k in c.free:
            lo = -1.0 if k == 0 else ends[k - 1]
            hi = 1.0 if k == len(ends) - 1 else ends[k + 1]
            # a root that ran off (a degenerate slope) keeps the interpolant's end
            if lo < b[j] < hi and abs(b[j] - ends[k]) < widest:
                out[s][k] = float(b[j])
            j += 1
    return out


def _couplings(steps: list[Corrected], owner: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The other punches' displacement at the points ``t``, each from its own step
    (``owner``)."""
    out = np.zeros(t.size)
    for s in np.unique(owner):
        coupling = steps[int(s)].coupling
        if coupling is not None:
            at = owner == s
            out[at] = coupling(t[at])
    return out


#: Entries (targets x cut-part columns) up to which the rows of F on the cut parts of
#: several steps come from one call (8 MB): a call's overhead dominates below, the work
#: discarded with the other steps' columns above.
BATCH_ENTRIES = 2**20
#: Secant steps on the Nystrom pressure at most (quadratic-like convergence from ~1e-4).
_SECANT_STEPS = 6


def _cut_rule(panels: Panels, state: NodalState,
              parts: dict[int, list[tuple[float, float]]]) -> tuple[Panels, np.ndarray]:
    """One Gauss panel on every contact part, and there the values of the interpolant of
    the nodal Q of its panel (the pressure cut at its root)."""
    pieces = [(p, lo, hi) for p, spans in parts.items() for lo, hi in spans]
    rule = Panels.side_by_side([Panels.from_edges(np.array([lo, hi])) for _, lo, hi in pieces])
    values = np.concatenate([
        _interpolation(panels.centers[p], panels.half_widths[p],
                       rule.nodes[k * NODES_PER_PANEL:(k + 1) * NODES_PER_PANEL])
        @ state.nystrom[p * NODES_PER_PANEL:(p + 1) * NODES_PER_PANEL]
        for k, (p, _, _) in enumerate(pieces)]) if pieces else np.zeros(0)
    return rule, values
