"""Lift-off of several punches on one elastic base: the contact set of every punch unknown.

Each punch keeps its own scaling (that of :mod:`core.engines.nystrom.multi`:
``x* = (x - e_p)/a_p``, ``lam_p = a_p/H``, centre ``E_p = e_p/H``), and on its zones the
problem of :mod:`core.contact.step` holds with the other punches' pressures adding the
displacement

    e_p(x) = - s sum_{r != p} (lam_r / lam_p) F_r q_r (x_r),   x_r = (E_p + lam_p x - E_r) / lam_r,

(``s`` the weight of F, 1 on an elastic base). It enters the Nystrom pressure ``Q_p``
exactly as the creep memory enters one punch's (``memory_at`` of
:func:`core.contact.step.nystrom_pressure`), so one punch's machinery serves for all,
generalized over the block system:

1. the nodal active set on every punch's nodal rule at once: one bordered system over all
   contact nodes (the coupled operator, two border unknowns and rows per punch), the
   primal-dual sweeps of :func:`core.contact.active_set.nodal_active_set` over all
   nodes, started from each punch's zones alone on its coarser rule
   (:func:`core.contact.nodal.coarse_start`); each punch's zones and ends to within a
   node by :func:`core.contact.active_set.zones_from_nodes`;
2. the free ends of all punches located together by
   :func:`core.contact.zones.refine_ends` (one quasi-Newton on all ends, the error
   estimate against the next coarser rule of every punch at once): :class:`CoupledEnds`
   is its end problem, the zones of every punch solved together on panels graded to
   their ends;
3. pinned ends checked and each punch's contact set verified with its ``e_p``
   (:func:`core.contact.elastic._bad_pins`, ``_verify``).

Every output time is solved on its own (equal data once). Each punch's answer is a
:class:`core.contact.result.UnilateralSolution` whose snapshots carry ``e_p`` (its
``pressure(x)`` is then the coupled Nystrom formula). A punch's ``error_estimate`` is
the largest change from the coarser rule of its own histories and of those of the
punches that act on it (their errors reach it through the base, times the kernel's bound
at their distance: :meth:`CoupledBase.reach`); the zone ends' estimate is that of all
ends together.

Zones further apart than :data:`core.engines.nystrom.multi.NEGLIGIBLE_GAP` base
thicknesses are not coupled (:func:`core.engines.nystrom.interacting`), as in full
contact. Under creep :mod:`core.contact.coupled_creep` marches the punches over this
module's coupled active set and operator.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.contact.active_set import (
    MAX_SWEEPS,
    SHRINKS,
    NoContact,
    NodalState,
    zones_from_nodes,
)
from core.contact.elastic import _bad_pins, _verify, verdict
from core.contact.nodal import coarse_start, nodal_operator
from core.contact.result import UnilateralSolution, _Snapshot
from core.contact.step import LoadNotCarried, Space, Step, check_loads, nystrom_pressure
from core.contact.systems import BorderedLayout, StepSolver, bordered_operator
from core.contact.unilateral import nodal_resolution, zone_resolution
from core.contact.zones import (
    MAX_LEVELS,
    Resolution,
    ZoneSolution,
    _walls,
    output_error,
    pressure_error,
    refine_ends,
    zone_kernel_accuracy,
    zone_panels,
)
from core.discretize import Panels, kernel_operator, operator_rows
from core.engines.nystrom import PunchGeometry, coupled_x, interacting
from core.kernel import FULL_ACCURACY, KERNEL_DECAY, KERNEL_ENVELOPE
from core.problem import TimeInputs


@dataclass(frozen=True)
class Resolutions:
    """One :class:`core.contact.zones.Resolution` per punch, refined together."""

    levels: tuple[Resolution, ...]

    def finer(self) -> Resolutions:
        return Resolutions(tuple(r.finer() for r in self.levels))

    def coarser(self) -> Resolutions:
        return Resolutions(tuple(r.coarser() for r in self.levels))


class CoupledBase:
    """The punches on one base: each one's :class:`Space` (its own scaling) and
    :class:`core.engines.nystrom.PunchGeometry` (its centre), and which pairs interact."""

    def __init__(self, punches: Sequence[PunchGeometry]) -> None:
        self.punches = tuple(punches)
        self.spaces = tuple(Space(p.geometry.lam, p.geometry.m, p.geometry.g,
                                  tuple(p.geometry.breakpoints)) for p in self.punches)
        n = len(self.punches)
        self.pairs = [[r for r in range(n) if r != p and interacting(self.punches[p],
                                                                     self.punches[r])]
                      for p in range(n)]

    def reach(self, p: int, r: int) -> float:
        """How much of punch ``r``'s relative error reaches punch ``p`` through the base:
        the bound ``KERNEL_ENVELOPE exp(-KERNEL_DECAY s)`` of the kernel (valid for
        ``s >= 2``) at the gap ``s`` between the zones [base thicknesses], 1 closer."""
        (lo_p, hi_p), (lo_r, hi_r) = self.punches[p].span, self.punches[r].span
        gap = max(lo_p, lo_r) - min(hi_p, hi_r)
        return 1.0 if gap < 2.0 else min(1.0, KERNEL_ENVELOPE * np.exp(-KERNEL_DECAY * gap))

    def rows(self, p: int, r: int, panels: Panels, x: np.ndarray,
             accuracy: float = FULL_ACCURACY) -> np.ndarray:
        """``(lam_r / lam_p) F_r`` at points ``x`` of punch ``p`` for the nodes of
        ``panels`` on punch ``r`` (len(x), N_r)."""
        source, target = self.punches[r], self.punches[p]
        mapped = np.ascontiguousarray(coupled_x(source, target, np.asarray(x, dtype=float)))
        return (source.geometry.lam / target.geometry.lam) * operator_rows(
            source.geometry.lam, panels, mapped, accuracy=accuracy)

    def operator(self, panels: Sequence[Panels], own: Sequence[np.ndarray],
                 accuracy: float = FULL_ACCURACY) -> np.ndarray:
        """The coupled operator over the nodes of every punch's ``panels`` (in order):
        ``own[p]`` its own block, the coupling blocks between interacting punches."""
        sizes = [pan.size for pan in panels]
        offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
        out = np.zeros((offsets[-1], offsets[-1]))
        for p, pan in enumerate(panels):
            lo, hi = offsets[p], offsets[p + 1]
            if lo == hi:
                continue
            out[lo:hi, lo:hi] = own[p]
            for r in self.pairs[p]:
                if sizes[r]:
                    out[lo:hi, offsets[r]:offsets[r + 1]] = self.rows(
                        p, r, panels[r], pan.nodes, accuracy)
        return out

    def displacement(self, p: int, parts: Sequence[Any], scale: float,
                     accuracy: float) -> Callable[[np.ndarray], np.ndarray]:
        """``e_p(x)``: the displacement the other punches' pressures (``parts[r].panels``,
        ``parts[r].q``) add on punch ``p`` (its coordinates), F weighted by ``scale``."""
        sources = [(r, parts[r].panels, parts[r].q) for r in self.pairs[p]
                   if parts[r].q.size]

        def e_p(x: np.ndarray) -> np.ndarray:
            x = np.asarray(x, dtype=float)
            out = np.zeros(x.size)
            for r, panels, q in sources:
                out -= scale * (self.rows(p, r, panels, x, accuracy) @ q)
            return out

        return e_p


def coupled_bordered_solve(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray,
                           owner: np.ndarray, step_c: float, scale: float,
                           givens: Sequence[dict[str, float]], rhs: np.ndarray,
                           idx: np.ndarray, solver: CoupledStepSolver | None = None
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`core.contact.systems.bordered_solve` over several punches: the equation on
    the nodes ``idx`` of all punches (``owner`` the punch of every node, ``op`` the
    coupled operator), and per punch the unknown ones of its settlement and tilt as
    border columns on its nodes and its given force and moment as border rows.
    ``solver``: a :class:`CoupledStepSolver` keeping each punch's factors from one creep
    step to the next (None: a direct solve).

    Returns (q on idx, settlement and tilt of every punch).
    """
    if solver is not None:
        return _kept_factors_solve(op, m, x, w, owner, step_c, scale, givens, rhs, idx,
                                   solver)
    n = idx.size
    own = owner[idx]
    xi, wi = x[idx], w[idx]
    cols, names, rows, values, _ = _borders(givens, own, xi, wi)
    k = len(cols)
    a = np.zeros((n + k, n + k))
    a[:n, :n] = op[np.ix_(idx, idx)]
    a[np.arange(n), np.arange(n)] += (step_c / scale) * m[idx]
    if k:
        a[:n, n:] = np.array(cols).T
        a[n:, :n] = np.array(rows)
    b = np.concatenate([rhs[idx] / scale, values])
    sol = np.linalg.solve(a, b)
    return _unpack_all(sol, n, scale, givens, names)


def _unpack_all(sol: np.ndarray, n: int, scale: float, givens: Sequence[dict[str, float]],
                names: Sequence[tuple[int, str]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    delta = np.array([given.get("settlement", 0.0) for given in givens])
    alpha = np.array([given.get("tilt", 0.0) for given in givens])
    for (p, name), value in zip(names, sol[n:] * scale, strict=True):
        (delta if name == "settlement" else alpha)[p] = value
    return sol[:n], delta, alpha


class CoupledStepSolver:
    """Solves the coupled bordered systems of a creep march (:func:`coupled_bordered_solve`
    with ``solver``), keeping factors from step to step.

    A new contact set of any punch would make a new factorization of the whole system
    (O(N^3) in all the punches' nodes; at each step where a zone end crosses a node:
    on a mirrored pair of 960 nodes each, 279 of them took 17 of the marches' 29 s, 21 s
    this way). Above ``WHOLE_SIZE`` unknowns each punch's
    own bordered block (its nodes, its border unknowns and rows) is factored and kept
    while its contact nodes and statement stay, and the coupled system is solved by
    GMRES preconditioned with those blocks (the coupling is what is left, a smooth
    operator between disjoint zones), to a residual of ``RESIDUAL`` of the right-hand
    side as :class:`core.contact.systems.StepSolver`'s refinement. The blocks are
    refactored after a solve that needed more than ``REFRESH_AFTER`` iterations (c/s
    has drifted); a solve that does not converge is made directly.
    """

    RESIDUAL = 1e-13
    REFRESH_AFTER = 12
    MAX_ITERATIONS = 60
    #: Systems of at most this many unknowns are solved as one punch's are (the whole
    #: system's factors kept, :class:`core.contact.systems.StepSolver`): there a new
    #: factorization costs less than GMRES's iterations and overhead (measured on two
    #: punches of 256 and 224 nodes lifting off under creep: 1.6 s by GMRES, 0.6 s so).
    WHOLE_SIZE = 1000

    def __init__(self) -> None:
        self._whole = StepSolver()
        self._blocks: dict[int, tuple[tuple, Any]] = {}
        self.factorizations = 0
        self.iterations = 0
        self.direct = 0

    def submatrix(self, op: np.ndarray, idx: np.ndarray, key: tuple) -> np.ndarray:
        """``op`` on the nodes ``idx`` (kept while the contact nodes stay)."""
        return self._whole.submatrix(op, idx, key)

    def solve(self, build: Callable[[], np.ndarray], apply: Callable[[np.ndarray], np.ndarray],
              b: np.ndarray, blocks: Sequence[tuple[tuple, np.ndarray, np.ndarray]],
              layout: BorderedLayout | None = None) -> np.ndarray:
        """Solve ``A x = b`` for the matrix ``build()`` whose product is ``apply``;
        ``blocks`` per punch: (key, its rows, its columns) in ``A``; ``layout``: the
        system over all nodes (the whole system's factors then serve nearby contact
        sets)."""
        from scipy.linalg import lu_factor, lu_solve
        from scipy.sparse.linalg import LinearOperator, gmres

        if b.size <= self.WHOLE_SIZE:
            before = self._whole.factorizations
            x = self._whole.solve(build, apply, b, layout)
            self.factorizations += self._whole.factorizations - before
            return x
        full: list[np.ndarray] = []

        def matrix() -> np.ndarray:
            if not full:
                full.append(build())
            return full[0]

        for p, (key, rows, cols) in enumerate(blocks):
            kept = self._blocks.get(p)
            if kept is None or kept[0] != key:
                if rows.size:
                    self._blocks[p] = (key, lu_factor(matrix()[np.ix_(rows, cols)],
                                                      check_finite=False))
                    self.factorizations += 1
                else:
                    self._blocks[p] = (key, None)

        def precondition(r: np.ndarray) -> np.ndarray:
            z = np.zeros(r.size)
            for p, (_, rows, cols) in enumerate(blocks):
                lu = self._blocks[p][1]
                if lu is not None:
                    z[cols] = lu_solve(lu, r[rows], check_finite=False)
            return z

        size = b.size
        scale = max(float(np.abs(b).max()), 1e-300)
        counted = [0]

        def count(_: Any) -> None:
            counted[0] += 1

        # right preconditioning: the residual GMRES sees is the system's own
        operator = LinearOperator((size, size), matvec=lambda y: apply(precondition(y)),
                                  dtype=float)
        x = np.zeros(size)
        r = b.copy()
        for _ in range(3):
            y, info = gmres(operator, r, rtol=0.1 * self.RESIDUAL * scale / max(
                float(np.linalg.norm(r)), 1e-300), atol=0.0, restart=self.MAX_ITERATIONS,
                maxiter=1, callback=count, callback_type="pr_norm")
            x = x + precondition(y)
            r = b - apply(x)
            if float(np.abs(r).max()) <= self.RESIDUAL * scale:
                break
        else:
            self.direct += 1
            self._blocks.clear()
            return np.linalg.solve(matrix(), b)
        self.iterations += counted[0]
        if counted[0] > self.REFRESH_AFTER:
            self._blocks.clear()  # c/s has drifted: new factors next time
        return x


def checked_loads(inputs: Sequence[TimeInputs], times: np.ndarray
                  ) -> list[dict[str, np.ndarray]]:
    """Every punch's given loads at ``times``, checked as one punch's are (a load no
    contact can carry is refused naming ``punches[k].loading.<quantity>``)."""
    loads = []
    for k, one in enumerate(inputs):
        values = {name: np.broadcast_to(np.asarray(fn(times), dtype=float),
                                        times.shape).astype(float)
                  for name, fn in one.loads.items()}
        try:
            check_loads(one.given, values, times)
        except LoadNotCarried as exc:
            raise exc.of_punch(k) from None
        loads.append(values)
    return loads


def _borders(givens: Sequence[dict[str, float]], own: np.ndarray, xi: np.ndarray,
             wi: np.ndarray) -> tuple[list, list, list, list, list]:
    """The border of the coupled system on the nodes kept: per punch, a column of each
    unknown settlement (``-1`` on its nodes) and tilt (``-x``), named ``(p, quantity)``,
    and a row of each given force (the weights ``w``) and moment (``w x``) with its value
    and its punch. ``own``, ``xi``, ``wi``: the owner, x and weight of each node kept."""
    cols, names, rows, values, row_owner = [], [], [], [], []
    for p, given in enumerate(givens):
        on = (own == p).astype(float)
        if "settlement" not in given:
            cols.append(-on)
            names.append((p, "settlement"))
        if "tilt" not in given:
            cols.append(-xi * on)
            names.append((p, "tilt"))
        for name, weight in (("force", wi), ("moment", wi * xi)):
            if name in given:
                rows.append(weight * on)
                values.append(given[name])
                row_owner.append(p)
    return cols, names, rows, values, row_owner


def _kept_factors_solve(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray,
                        owner: np.ndarray, step_c: float, scale: float,
                        givens: Sequence[dict[str, float]], rhs: np.ndarray, idx: np.ndarray,
                        solver: CoupledStepSolver
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`coupled_bordered_solve` by ``solver`` (the system of
    :func:`core.contact.systems.bordered_solve`, divided by ``scale`` likewise: the
    factors of one step precondition the next up to the change of c/s)."""
    n = idx.size
    own = owner[idx]
    # the border on every node: the system over all of them (a layout) lets the kept
    # factors of other contact nodes serve (core.contact.systems.StepSolver)
    cols, names, rows, values, row_owner = _borders(givens, owner, x, w)
    k = len(cols)
    all_cols = np.array(cols).T.reshape(x.size, k)
    all_rows = np.array(rows).reshape(k, x.size)
    border_cols, border_rows = all_cols[idx], all_rows[:, idx]
    key = (idx.tobytes(), tuple(tuple(sorted(given)) for given in givens))
    sub = solver.submatrix(op, idx, key)
    diagonal = (step_c / scale) * m[idx]
    col_owner = np.array([p for p, _ in names], dtype=int)
    row_owner_arr = np.array(row_owner, dtype=int)
    blocks = []
    for p, given in enumerate(givens):
        mine = np.nonzero(own == p)[0]
        blocks.append(((idx[mine].tobytes(), tuple(sorted(given))),
                       np.concatenate([mine, n + np.nonzero(row_owner_arr == p)[0]]),
                       np.concatenate([mine, n + np.nonzero(col_owner == p)[0]])))

    build, apply = bordered_operator(sub, diagonal, border_cols, border_rows)
    layout = BorderedLayout(op, (step_c / scale) * m, all_cols, all_rows, idx)
    b = np.concatenate([rhs[idx] / scale, values])
    return _unpack_all(solver.solve(build, apply, b, blocks, layout), n, scale, givens,
                       names)


@dataclass
class CoupledZones:
    """The zones of every punch solved together: ``parts[p]`` punch ``p``'s
    :class:`core.contact.zones.ZoneSolution` (Q at its ends with its ``e_p``), and the
    ends of all punches in order with Q there (``end_values``) and the q that makes it
    relative (``scales``, its punch's largest q)."""

    parts: list[ZoneSolution]
    end_values: np.ndarray
    scales: np.ndarray
    couplings: list[Callable[[np.ndarray], np.ndarray]]


class CoupledEnds:
    """The end problem of :func:`core.contact.zones.refine_ends` for several punches at
    one time: ``counts[p]`` ends of punch ``p`` (two per zone, its own coordinates),
    which of them are ``pinned``; ``steps[p]`` its data."""

    def __init__(self, base: CoupledBase, steps: Sequence[Step], counts: Sequence[int],
                 pinned: Sequence[bool], accuracy: float) -> None:
        self.base, self.steps, self.accuracy = base, tuple(steps), accuracy
        self.owner = np.repeat(np.arange(len(counts)), counts)
        self.offsets = np.concatenate([[0], np.cumsum(counts)]).astype(int)
        self.free_owner = self.owner[[k for k, p in enumerate(pinned) if not p]]
        self.errors: list[float] = []

    def split(self, ends: Sequence[float]) -> list[list[float]]:
        return [list(ends[self.offsets[p]:self.offsets[p + 1]])
                for p in range(len(self.steps))]

    def solve(self, ends: Sequence[float], res: Resolutions, probes: np.ndarray | None = None
              ) -> tuple[CoupledZones, np.ndarray] | CoupledZones:
        base, steps = self.base, self.steps
        per = self.split(ends)
        panels = [zone_panels(space, e, r) for space, e, r
                  in zip(base.spaces, per, res.levels, strict=True)]
        own = [kernel_operator(space.lam, pan, accuracy=self.accuracy).matrix
               if pan.size else np.zeros((0, 0)) for space, pan in zip(base.spaces, panels,
                                                                         strict=True)]
        op = base.operator(panels, own, self.accuracy)
        x = np.concatenate([pan.nodes for pan in panels])
        w = np.concatenate([pan.weights for pan in panels])
        owner = np.repeat(np.arange(len(panels)), [pan.size for pan in panels])
        m = np.concatenate([space.m(pan.nodes) for space, pan in zip(base.spaces, panels,
                                                                      strict=True)])
        g = np.concatenate([space.g(pan.nodes) for space, pan in zip(base.spaces, panels,
                                                                      strict=True)])
        rhs = _given_rhs_all(steps, owner, x, g)
        q, delta, alpha = coupled_bordered_solve(
            op, m, x, w, owner, steps[0].c, steps[0].scale, [s.given for s in steps], rhs,
            np.arange(x.size))
        parts = [ZoneSolution(per[p], panels[p], q[owner == p], float(delta[p]),
                              float(alpha[p]), np.zeros(0), 1e-300)
                 for p in range(len(panels))]
        couplings = [base.displacement(p, parts, steps[p].scale, self.accuracy)
                     for p in range(len(parts))]
        extra = np.zeros(0) if probes is None else np.asarray(probes, dtype=float)
        at_probes = np.zeros(extra.size)
        for p, part in enumerate(parts):
            ends_p = np.asarray(per[p], dtype=float)
            mine = (self.free_owner == p) if extra.size else np.zeros(0, dtype=bool)
            if not ends_p.size and not mine.any():
                continue
            inward = np.tile([1.0, -1.0], ends_p.size // 2)
            values = nystrom_pressure(base.spaces[p], steps[p], part.panels, part.q,
                                      part.settlement, part.tilt,
                                      np.concatenate([ends_p, extra[mine]]),
                                      np.concatenate([inward, np.zeros(int(mine.sum()))]),
                                      couplings[p], self.accuracy)
            part.end_values = values[:ends_p.size]
            part.q_scale = max(float(np.max(np.abs(part.q))) if part.q.size else 0.0, 1e-300)
            at_probes[mine] = values[ends_p.size:]
        sol = CoupledZones(parts, np.concatenate([p.end_values for p in parts]),
                           np.array([parts[p].q_scale for p in self.owner]), couplings)
        return sol if probes is None else (sol, at_probes)

    @staticmethod
    def scale(sol: CoupledZones) -> np.ndarray:
        return sol.scales

    def walls(self, ends: list[float], k: int) -> tuple[float, float]:
        p = int(self.owner[k])
        lo = self.offsets[p]
        lower, upper = _walls(self.split(ends)[p], [], k - lo)
        return lower, upper

    def edge(self, res: Resolutions) -> np.ndarray:
        return np.array([res.levels[p].edge for p in self.owner])

    def output_error(self, sol: CoupledZones, fine: CoupledZones) -> float:
        """The largest of the punches' output and q errors (each punch's kept in
        ``errors``; :func:`core.contact.zones.pressure_error` with the others' push)."""
        self.errors = [max(output_error(a, b),
                           pressure_error(space, step, a, b, self.accuracy, coupling))
                       for a, b, space, step, coupling in zip(
                           sol.parts, fine.parts, self.base.spaces, self.steps,
                           fine.couplings, strict=True)]
        return max(self.errors)

    def moved_error(self, moved: CoupledZones, sol: CoupledZones) -> float:
        """The largest of the punches' output changes when an end moves by its error
        (each punch's added to its part of ``errors``)."""
        parts = [output_error(a, b) for a, b in zip(moved.parts, sol.parts, strict=True)]
        self.errors = [e + d for e, d in zip(self.errors, parts, strict=True)]
        return max(parts)

    def needs_moved(self, error: float, end_error: float) -> bool:
        """As :meth:`core.contact.zones.OnePunch.needs_moved`, for the part of any punch
        with a free end."""
        return end_error < np.inf and any(self.errors[int(p)] < end_error
                                          for p in set(self.free_owner.tolist()))


def _given_rhs_all(steps: Sequence[Step], owner: np.ndarray, x: np.ndarray,
                   g: np.ndarray) -> np.ndarray:
    """``delta + alpha x - g`` at the nodes of every punch, with its given ones (0 for the
    unknown ones), as :func:`core.contact.step._given_rhs` per punch."""
    delta = np.array([s.given.get("settlement", 0.0) for s in steps])
    alpha = np.array([s.given.get("tilt", 0.0) for s in steps])
    return delta[owner] + alpha[owner] * x - g


def coupled_state(base: CoupledBase, rules: Sequence[Panels], op: np.ndarray,
                  steps: Sequence[Step], nodal_res: Sequence[Resolution]
                  ) -> list[NodalState]:
    """The coupled nodal active set (:func:`coupled_active_set`), started from each
    punch's zones alone on its next coarser rule (:func:`core.contact.nodal.coarse_start`,
    full contact where it has none): they depend on the scene and the loads alone, and
    the coupling moves them little. A start that does not settle is retried from full
    contact, which raises :class:`NoContact` when the loads leave a punch none."""
    starts = [coarse_start(space, step, rule, res) for space, step, rule, res
              in zip(base.spaces, steps, rules, nodal_res, strict=True)]
    if any(start is not None for start in starts):
        start = np.concatenate([np.ones(rule.size, dtype=bool) if one is None else one
                                for one, rule in zip(starts, rules, strict=True)])
        try:
            states, settled = coupled_active_set(base, rules, op, steps, start)
            if settled:
                return states
        except NoContact:
            pass
    return coupled_active_set(base, rules, op, steps)[0]


def coupled_active_set(base: CoupledBase, rules: Sequence[Panels], op: np.ndarray,
                       steps: Sequence[Step], start: np.ndarray | None = None,
                       memory: np.ndarray | None = None, solver: CoupledStepSolver | None = None
                       ) -> tuple[list[NodalState], bool]:
    """The primal-dual active set of :func:`core.contact.active_set.nodal_active_set` on
    the nodes of every punch's ``rules`` at once (``op`` their coupled operator), from
    the contact nodes ``start`` (default: all). ``memory``: the displacement e of a
    creep step's memory at all nodes (None: elastic); ``solver`` keeps the factors
    between steps. Returns each punch's :class:`NodalState` and whether the set
    settled. Raises :class:`NoContact` (its message naming ``punches[k]``) when a punch
    with a given force or moment keeps no node in contact, or fewer than three."""
    sizes = [r.size for r in rules]
    owner = np.repeat(np.arange(len(rules)), sizes)
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    x = np.concatenate([r.nodes for r in rules])
    w = np.concatenate([r.weights for r in rules])
    m = np.concatenate([s.m(r.nodes) for s, r in zip(base.spaces, rules, strict=True)])
    g = np.concatenate([s.g(r.nodes) for s, r in zip(base.spaces, rules, strict=True)])
    rhs = _given_rhs_all(steps, owner, x, g)
    if memory is not None:
        rhs = rhs + memory
    c, scale = steps[0].c, steps[0].scale
    givens = [s.given for s in steps]
    active = np.ones(x.size, dtype=bool) if start is None else start.copy()
    seen: set[bytes] = set()
    settled = False
    q = np.zeros(x.size)
    delta = np.array([s.get("settlement", 0.0) for s in givens])
    alpha = np.array([s.get("tilt", 0.0) for s in givens])
    nystrom = np.zeros(x.size)
    for _ in range(MAX_SWEEPS):
        touching = bool(active.any())
        for p, given in enumerate(givens):
            count = int(np.count_nonzero(active[offsets[p]:offsets[p + 1]]))
            # (a punch without contact whose settlement or tilt is unknown beside one in
            # contact: nothing determines them, the coupled system would be singular;
            # with no punch in contact nothing is solved, as for one punch: no_contact)
            if count == 0 and (any(given.get(k, 0.0) != 0.0 for k in ("force", "moment"))
                               or (touching and not {"settlement", "tilt"} <= set(given))):
                raise NoContact("no node stays in contact", p)
            if 0 < count < 3 and not {"settlement", "tilt"} <= set(given):
                raise NoContact(SHRINKS, p)
        idx = np.nonzero(active)[0]
        q = np.zeros(x.size)
        if idx.size:
            q[idx], delta, alpha = coupled_bordered_solve(op, m, x, w, owner, c, scale,
                                                          givens, rhs, idx, solver)
        if memory is None:
            nystrom = (delta[owner] + alpha[owner] * x - g - scale * (op @ q)) / (c * m)
        else:
            nystrom = (delta[owner] + alpha[owner] * x - g + memory - scale * (op @ q)) / (
                c * m)
        # Keep the contact nodes the equation solved exactly (rounding must not flip them).
        nystrom[idx] = q[idx]
        new = nystrom > 0.0
        if np.array_equal(new, active):
            settled = True
            break
        if new.tobytes() in seen:
            break
        seen.add(active.tobytes())
        active = new
    return [NodalState(rules[p], q[lo:hi], float(delta[p]), float(alpha[p]), active[lo:hi],
                       nystrom[lo:hi])
            for p, (lo, hi) in enumerate(zip(offsets[:-1], offsets[1:], strict=True))], settled


def _solve_one(base: CoupledBase, steps: Sequence[Step], rules: Sequence[Panels],
               op: np.ndarray, nodal_res: Sequence[Resolution], res: Resolutions, tol: float
               ) -> dict[str, Any]:
    """Every punch's zones at one time (see the module notes)."""
    states = coupled_state(base, rules, op, steps, nodal_res)
    ends, pinned, slopes, counts = [], [], [], []
    for space, state in zip(base.spaces, states, strict=True):
        e, p, s = zones_from_nodes(state, space.breakpoints) if state.active.any() else \
            ([], [], [])
        ends += e
        pinned += p
        slopes += s
        counts.append(len(e))
    if not ends:
        # only given settlements and tilts can hold every punch above the surface
        out = [(_Snapshot(state.panels, np.zeros(state.q.size), state.settlement,
                          state.tilt, step, []),
                {"error_estimate": 0.0, "verified": True, "force": 0.0, "moment": 0.0})
               for state, step in zip(states, steps, strict=True)]
        return {"punches": out, "zone_end_error": 0.0, "converged": True, "builds": 0,
                "n_nodes": 0}
    accuracy = zone_kernel_accuracy(tol)
    problem = CoupledEnds(base, steps, counts, pinned, accuracy)
    refined = refine_ends(problem, ends, pinned, slopes, res, tol=tol, max_levels=MAX_LEVELS)
    sol = refined.solution
    bad = []
    for p, part in enumerate(sol.parts):
        lo = problem.offsets[p]
        bad += [lo + k for k in _bad_pins(base.spaces[p], steps[p], part,
                                          pinned[lo:lo + counts[p]], sol.couplings[p])]
    if bad:
        ends = [float(e) for part in sol.parts for e in part.ends]
        for k in bad:
            p = int(problem.owner[k])
            pinned[k] = False
            if abs(ends[k]) == 1.0:
                ends[k] = float(np.sign(ends[k]) * (1.0 - 1e-6))
            slopes[k] = (1.0 if (k - problem.offsets[p]) % 2 == 0 else -1.0) * \
                sol.parts[p].q_scale * 1e3
        problem = CoupledEnds(base, steps, counts, pinned, accuracy)
        refined = refine_ends(problem, ends, pinned, slopes, res, tol=tol,
                              max_levels=MAX_LEVELS)
        sol = refined.solution
    out = []
    for p, part in enumerate(sol.parts):
        zones = [(float(part.ends[2 * i]), float(part.ends[2 * i + 1]))
                 for i in range(len(part.ends) // 2)]
        verified = _verify(base.spaces[p], steps[p], part, rules[p], zones, accuracy,
                           sol.couplings[p]) if part.q.size else True
        snap = _Snapshot(part.panels, part.q, part.settlement, part.tilt, steps[p], zones,
                         coupling=sol.couplings[p])
        out.append((snap, {"error_estimate": problem.errors[p], "verified": verified,
                           "force": part.force, "moment": part.moment}))
    return {"punches": out, "zone_end_error": refined.end_error,
            "converged": refined.converged, "builds": refined.builds,
            "n_nodes": sum(part.panels.size for part in sol.parts)}


def solve_unilateral_punches(punches: Sequence[PunchGeometry], inputs: Sequence[TimeInputs]
                             ) -> list[UnilateralSolution]:
    """Lift-off of several punches on one elastic base (see the module notes).

    ``punches``: each punch's validated geometry and centre (as for
    :func:`core.engines.nystrom.solve_punches`); ``inputs``: each one's validated time
    side, all on one elastic base (``kernel`` None; the same times and ``c``). Returns
    one :class:`core.contact.result.UnilateralSolution` per punch, in its own scaling,
    ``contact_set`` in its own coordinates. Raises ValueError naming ``punches[k]``
    when its loads leave it no contact.
    """
    started = _time.perf_counter()
    base = CoupledBase(punches)
    times = inputs[0].times
    for k, one in enumerate(inputs):
        if one.kernel is not None:
            raise ValueError(f"punches[{k}]: lift-off of several punches is solved on an "
                             "elastic base only")
        if not np.array_equal(one.times, times):
            raise ValueError(f"punches[{k}]: all punches share the output times")
    loads = checked_loads(inputs, times)
    c_t = np.broadcast_to(np.asarray(inputs[0].c(times), dtype=float), times.shape)
    tol = min(p.geometry.tol for p in base.punches)
    res = Resolutions(tuple(zone_resolution(s.lam, s.m) for s in base.spaces))
    nodal_res = [nodal_resolution(s.lam, s.m) for s in base.spaces]
    rules = [nodal_operator(s.lam, s.breakpoints, r) for s, r in zip(base.spaces, nodal_res,
                                                                       strict=True)]
    op = base.operator([r[0] for r in rules], [r[1] for r in rules])
    results: dict[tuple, dict[str, Any]] = {}
    per_time = []
    for k in range(times.size):
        givens = [{name: float(v[k]) for name, v in one.items()} for one in loads]
        key = (float(c_t[k]),) + tuple(tuple(sorted(g.items())) for g in givens)
        if key not in results:
            steps = [Step(float(c_t[k]), 1.0, g) for g in givens]
            try:
                results[key] = _solve_one(base, steps, [r[0] for r in rules], op, nodal_res,
                                          res, tol)
            except NoContact as exc:
                raise exc.of_punches(times[k], givens,
                                     f"{exc}: {exc.what}") from None
        per_time.append(results[key])
    seconds = _time.perf_counter() - started
    end_error = max(r["zone_end_error"] for r in per_time)
    converged = all(r["converged"] for r in per_time)
    answers = []
    for p, space in enumerate(base.spaces):
        mine = [r["punches"][p] for r in per_time]
        snapshots = [s for s, _ in mine]
        # A neighbour's error reaches this punch through the base: measured at a gap of
        # 1e-3 m (tests/scene/test_punches_liftoff.py), the q of a punch that kept full
        # contact erred by 3.4e-9 where its own histories changed by 7.1e-10 from the
        # coarser rule, its neighbour's by 3.7e-9.
        error = max(r["punches"][k][1]["error_estimate"] * (1.0 if k == p else
                                                            base.reach(p, k))
                    for r in per_time for k in (p, *base.pairs[p]))
        verified = all(i["verified"] for _, i in mine)
        info = {
            **verdict(error, end_error, verified, converged, tol,
                      f"elastic, {len(base.punches)} punches"),
            "n_steps": int(times.size),
            "n_solves": len(results),
            "n_nodes": max(int(r["n_nodes"]) for r in per_time),
            "operator_builds": sum(r["builds"] for r in results.values()),
            "min_pressure": 0.0,
            "punches": len(base.punches),
            "seconds": seconds,
        }
        answers.append(UnilateralSolution(
            times.copy(), np.array([s.settlement for s in snapshots]),
            np.array([s.tilt for s in snapshots]), np.array([i["force"] for _, i in mine]),
            np.array([i["moment"] for _, i in mine]), [list(s.zones) for s in snapshots],
            info, space, snapshots, zone_kernel_accuracy(tol)))
    return answers
