"""Several rigid punches on one foundation: the default engine's grids, coupled.

Design (dimensionless, elastic base, full contact):

- **Lengths.** Each punch ``p`` keeps its own scaling, that of a single punch of its
  half-width ``a_p`` (:mod:`core.scene.dimensionless`): ``x*_p = (x - e_p) / a_p``,
  ``lam_p = a_p / H``, ``delta*_p = delta_p / a_p``, ``P*_p = 2 (1 - nu^2) P_p / (E a_p)``,
  ``M*_p = 2 (1 - nu^2) M_p / (E a_p^2)`` with ``e_p`` its centre. The dimensionless
  pressure ``q* = 2 (1 - nu^2) q / E`` does not depend on ``a_p``, so it is one field over
  all zones. The common length between punches is the base thickness ``H``: punch ``p``
  covers ``[E_p - lam_p, E_p + lam_p]`` with ``E_p = e_p / H``.
- **Equations.** Divided by ``a_p``, the surface displacement on zone ``p`` reads

      c m_p q_p + F_p q_p + sum_{r != p} (lam_r / lam_p) F_r q_r (x_r)
          = delta_p + alpha_p x - g_p(x),     x_r = (E_p + lam_p x - E_r) / lam_r,

  where ``F_r`` is punch ``r``'s own operator ``int k_pl(lam_r (x - xi)) q(xi) dxi / pi``
  evaluated at the points ``x_r`` of zone ``p`` written in ``r``'s coordinates (outside
  ``[-1, 1]``), and ``int q_p = P_p``, ``int x q_p = M_p`` on each zone.
- **Grids.** Each punch has the graded, adaptively refined grid of a single punch of
  its own geometry (:func:`core.engines.nystrom.prepared_for`, cached: two identical
  punches share one), refined where the coating counts least on a creeping base
  (:func:`core.engines.nystrom.creep_reference`, as for one punch), so each self block
  is exactly the single-punch operator. Where a
  neighbour is closer to an end than that end's panel is wide, the neighbour's edge
  pressure makes the drive on this zone vary on the scale of the gap: the end is graded
  further (``h -> h/4`` a level, :class:`ZoneGrid`) until its panel is no wider than the
  gap (measured on a pair 1e-4 to 1e-2 half-widths apart: without it the error of q grew
  to 1.1e-6 at a gap of 1e-3 and 5e-5 at 1e-4 under an estimate of 1e-7; with it 2.6e-8
  at tol 1e-6 and 1.8e-9 at tol 1e-8, against a reference graded twenty times finer).
- **Coupling blocks.** Rows of ``F_r`` at the nodes of zone ``p`` mapped into ``r``'s
  coordinates (:meth:`PreparedContact.rows`, i.e. :func:`core.discretize.operator_rows`):
  between disjoint intervals the kernel is smooth and the 16-point Gauss rule of the
  source panel is used, except where a target lies within ``NEAR_FIELD`` half-widths of a
  source panel (two punches close against their panel sizes), where the engine's product
  integration of the log part takes over. A block whose zones are further apart than
  :data:`NEGLIGIBLE_GAP` base thicknesses is left out: ``k_pl(s)`` decays like
  ``exp(-2.106 s)`` (model notes), ``|k_pl(s)| < 2 exp(-2.106 s)`` for ``s >= 5`` (measured
  on 5-40 by quadrature of the kernel: at most 1.4 exp(-2.106 s)), below 1e-16 beyond 18.
- **Bordered system.** Unknowns ``[q_1 .. q_n; two scalars per punch]``; rows: the nodal
  equations of every zone, then force and moment balance of every punch. It is factored
  once per (statements, ``c``) and solved for a unit value of each given load of each
  punch and for the gaps together: loads that change in time, or a load change, are a
  combination of those columns (one small matrix product).
- **Between the nodes** q comes from the equation itself (the Nystrom formula), exact in
  ``m`` and ``g`` at jumps as for one punch; the other zones' part of ``F q`` is smooth on
  the zone and is interpolated on its panels from the nodes (the rows of every other
  zone at every point asked for cost as much as the rest of the solve). The check of
  ``q >= 0`` takes the formula on panels ending at +-1 or a jump and the panel
  interpolant elsewhere, as the single punch's check does.
- **Error estimate.** Each punch's grid carries the two-grid estimate of its own
  adaptive refinement (``spatial_error``); the coupling adds to zone ``p`` a drive that is
  smooth on it (analytic where the zones are apart), which the grid's interior panels
  resolve like the ``1, x`` drives the estimate was made with. The estimate of a punch is
  its grid's; the scene's the largest. The tests measure it against refined answers.

Creep and a modulus varying in time: the same coupled operator in modal form
(:mod:`core.engines.nystrom.multi_modal`), stepped by :mod:`core.time`; the time
stepping's estimate is added to the punches' spatial ones. Lift-off is not solved here:
:mod:`core.contact.coupled` runs the single punch's lift-off machinery over the punches
(elastic base; :mod:`core.contact.coupled_creep` its creep march), with the same scaling,
coupling and :func:`interacting` pairs.
"""

from __future__ import annotations

import itertools
import threading
import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.linalg import lu_factor, lu_solve

from core.cache import KeptValues, StageCache, content_key, fingerprint
from core.creep import stepping_kernel
from core.discretize import panel_index
from core.engines.nystrom.adapt import LEVEL_SPLIT, MAX_PANELS, grade
from core.engines.nystrom.bordered import build_grid, touches
from core.engines.nystrom.multi_modal import CoupledModalAnswer, CoupledModalForm
from core.engines.nystrom.prepared import (
    HISTORY_SAMPLES,
    TIME_SHARE,
    PreparedContact,
    creep_reference,
    geometry_key,
    load_shape,
    prepared_for,
    step_again_at_floor,
    time_tolerance,
)
from core.engines.nystrom.result import TimeSide, nystrom_solution
from core.problem import QUANTITIES, ContactSolution, Geometry, TimeInputs
from core.time import history_key_times


@dataclass
class _Part:
    """One time-stepped response of the coupled system (to one given load's shape, or to
    the gaps: ``gap`` 1), with q at each punch's check points (``checks``); ``serial``
    names it among the q kept at points asked for before (see
    :meth:`CoupledPunches._summed_pressure`)."""

    response: CoupledModalAnswer
    gap: float
    checks: list[np.ndarray]
    serial: int = field(default_factory=lambda: next(_SERIALS))

    @property
    def nbytes(self) -> int:
        """Memory of the response and its checks [bytes]."""
        r = self.response
        return int(r.nodal.nbytes + r.effective.nbytes + sum(c.nbytes for c in self.checks)
                   + sum(v.nbytes for s in r.scalars for v in s.values()))


_SERIALS = itertools.count()

#: The most values (points times output times) of one part's q at a set of points that
#: are kept (2 MiB: the plotting grid's 201 points at up to 1300 output times; a larger
#: request takes the Nystrom formula on the summed answer each time), and the bytes all
#: kept values of one set of punches may hold (least recently used dropped first).
PRESSURE_VALUES_KEPT = 2**18
PRESSURES_BYTES = 32 * 2**20

#: Time-stepped responses of the coupled system kept per set of punches, at most this many
#: sets (a load slider alternates among a few shapes) and this many bytes.
RESPONSES_KEPT = 24
RESPONSES_BYTES = 64 * 2**20


@dataclass
class _PartLoads:
    """One punch's loads in one part of a superposed answer (``given`` and ``loads`` as a
    :class:`core.problem.TimeInputs` has them)."""

    given: frozenset[str]
    loads: dict[str, Any]


#: Zones further apart than this many base thicknesses are not coupled (see the notes:
#: 2 exp(-2.106 * 18) = 1.1e-16).
NEGLIGIBLE_GAP = 18.0


#: An end of a zone is graded further while its panel is wider than this many times the
#: gap to the neighbour it faces (see :meth:`CoupledPunches._facing_refined`).
CLOSE_SHARE = 1.0
#: Most extra levels of grading toward a facing end (each cuts the width by 4).
MAX_FACING_LEVELS = 20


class ZoneGrid:
    """A punch's prepared grid refined on its own edges (see ``_facing_refined``), with the
    members of :class:`PreparedContact` the coupled solve uses."""

    def __init__(self, prepared: PreparedContact, edges: np.ndarray) -> None:
        geometry = self.geometry = prepared.geometry
        self.grid = build_grid(geometry.lam, edges, geometry.m, geometry.g, prepared.grid,
                               prepared.grid.kernel_accuracy)
        self.spatial_error, self.resolved = prepared.spatial_error, prepared.resolved
        self.counts, self.seconds = prepared.counts, prepared.seconds
        self.check_x = prepared.check_x
        singular = np.array([-1.0, 1.0, *geometry.breakpoints])
        self.check_formula = touches(self.grid.panels, singular)[
            panel_index(self.grid.panels, self.check_x)]
        self.element_ends = tuple(sorted(set(self.grid.panels.edges[1:-1].tolist())
                                         | set(geometry.breakpoints)))
        self._rows: dict[bytes, np.ndarray] = {}
        self._lock = threading.Lock()

    def rows(self, x: np.ndarray) -> np.ndarray:
        """Rows of the zone's operator at points ``x`` (len(x), N), cached by the points."""
        key = x.tobytes()
        with self._lock:
            found = self._rows.get(key)
        if found is None:
            found = self.grid.rows(x)
            with self._lock:
                self._rows[key] = found
                while len(self._rows) > 8:
                    self._rows.pop(next(iter(self._rows)))
        return found


@dataclass(frozen=True)
class PunchGeometry:
    """One punch of a coupled problem: its own validated ``geometry`` (``lam = a/H``,
    ``m``, ``g``, jumps and ``tol`` in its coordinates ``x* = (x - e)/a``) and its centre
    ``center = e / H`` (base thicknesses)."""

    geometry: Geometry
    center: float

    @property
    def span(self) -> tuple[float, float]:
        """The zone in base thicknesses, ``(E - lam, E + lam)``."""
        lam = self.geometry.lam
        return (self.center - lam, self.center + lam)


def coupled_x(source: PunchGeometry, target: PunchGeometry, x: np.ndarray) -> np.ndarray:
    """Points ``x`` of ``target``'s coordinates written in ``source``'s."""
    return (target.center + target.geometry.lam * x - source.center) / source.geometry.lam


def interacting(a: PunchGeometry, b: PunchGeometry) -> bool:
    """Whether the zones of ``a`` and ``b`` are close enough to act on each other (closer
    than :data:`NEGLIGIBLE_GAP` base thicknesses)."""
    (lo_a, hi_a), (lo_b, hi_b) = a.span, b.span
    return max(lo_a, lo_b) - min(hi_a, hi_b) < NEGLIGIBLE_GAP


class CoupledPunches:
    """The coupled discretization of several punches (see the module notes).

    ``punches``: the punches in the order of the answer; ``prepared``: each one's grid
    (:class:`PreparedContact`); ``blocks[p][r]``: the coupling block (N_p, N_r) of ``r``
    on ``p``'s nodes, or None when negligible.
    """

    def __init__(self, punches: Sequence[PunchGeometry],
                 prepared: Sequence[PreparedContact] | None = None) -> None:
        """``prepared``: each punch's prepared grid, if known (else found or built by
        :func:`core.engines.nystrom.prepared_for`)."""
        t0 = _time.perf_counter()
        self.punches = tuple(punches)
        found = tuple(prepared if prepared is not None else
                      (prepared_for(p.geometry) for p in self.punches))
        self.prepared: tuple[PreparedContact | ZoneGrid, ...] = tuple(
            self._facing_refined(p, pc) for p, pc in enumerate(found))
        self.sizes = [pc.grid.size for pc in self.prepared]
        self.offsets = np.concatenate([[0], np.cumsum(self.sizes)]).astype(int)
        n = len(self.punches)
        self.blocks: list[list[np.ndarray | None]] = [[None] * n for _ in range(n)]
        for p in range(n):
            for r in range(n):
                if p != r and self.coupled(p, r):
                    self.blocks[p][r] = self.coupling_rows(p, r, self.prepared[p].grid.nodes)
        # bordered systems (LU, unit responses, names) and modal forms, by statements
        self._systems: dict[tuple, Any] = {}
        # time-stepped responses to each load shape and the gap, by their joint key
        self._responses = KeptValues(RESPONSES_KEPT, RESPONSES_BYTES,
                                     lambda parts: sum(part.nbytes for part in parts))
        # q of the kept parts at points asked for before: (part's serial, punch, points,
        # output columns) -> (X, T)
        self._pressures = KeptValues(2**31, PRESSURES_BYTES)
        #: what the solves built: time-stepped responses of the coupled system
        self.counts = {"time_response": 0}
        self._lock = threading.Lock()
        self.seconds = _time.perf_counter() - t0

    def _facing_refined(self, p: int, prepared: PreparedContact
                        ) -> PreparedContact | ZoneGrid:
        """Punch ``p``'s grid, graded further toward an end that faces a neighbour closer
        than :data:`CLOSE_SHARE` times the end panel's width (the neighbour's pressure makes
        the drive on this zone vary on the scale of the gap there)."""
        lo_p, hi_p = self.punches[p].span
        lam = self.punches[p].geometry.lam
        left = min((lo_p - hi for r, (lo, hi) in enumerate(q.span for q in self.punches)
                    if r != p and hi <= lo_p), default=np.inf) / lam
        right = min((lo - hi_p for r, (lo, hi) in enumerate(q.span for q in self.punches)
                     if r != p and lo >= hi_p), default=np.inf) / lam
        edges = prepared.grid.panels.edges
        levels = 0
        for end, gap in ((-1.0, left), (1.0, right)):
            for _ in range(MAX_FACING_LEVELS):
                width = edges[1] - edges[0] if end < 0 else edges[-1] - edges[-2]
                if width <= gap / CLOSE_SHARE or len(edges) - 1 >= MAX_PANELS:
                    break
                edges = grade(edges, np.array([end]), 1, LEVEL_SPLIT)
                levels += 1
        return prepared if not levels else ZoneGrid(prepared, edges)

    def coupled(self, p: int, r: int) -> bool:
        """Whether zones ``p`` and ``r`` are close enough to act on each other."""
        return interacting(self.punches[p], self.punches[r])

    def coupling_rows(self, p: int, r: int, x: np.ndarray) -> np.ndarray:
        """``(lam_r / lam_p) F_r`` at points ``x`` of zone ``p`` (len(x), N_r)."""
        source, target = self.punches[r], self.punches[p]
        mapped = np.ascontiguousarray(coupled_x(source, target, np.asarray(x, dtype=float)))
        scale = source.geometry.lam / target.geometry.lam
        return scale * self.prepared[r].rows(mapped)

    @property
    def nbytes(self) -> int:
        """Memory of the coupling blocks, the factored systems and the time-stepped
        responses kept [bytes] (the grids are counted by
        :data:`core.engines.nystrom.PREPARED`)."""
        blocks = sum(b.nbytes for row in self.blocks for b in row if b is not None)
        systems = sum(entry[0][0].nbytes + entry[1].nbytes + sum(c.nbytes for c in entry[3])
                      for key, entry in self._systems.items() if key[0] != "modal")
        modal = sum(3 * entry.q.nbytes for key, entry in self._systems.items()
                    if key[0] == "modal")
        return int(blocks + systems + modal + self._responses.nbytes + self._pressures.nbytes)

    @property
    def size(self) -> int:
        """Nodes of all zones."""
        return int(self.offsets[-1])

    # ------------------------------------------------------------------ bordered

    def _system(self, givens: tuple[frozenset[str], ...], c: float
                ) -> tuple[tuple, np.ndarray, list[str]]:
        """LU of the bordered matrix and its unit responses (nodes + 2 n, K): columns named
        ``"p:quantity"`` for every given load of every punch, then ``"gap"``."""
        key = (givens, c)
        with self._lock:
            found = self._systems.get(key)
        if found is not None:
            return found
        n_p = len(self.punches)
        n = self.size
        total = n + 2 * n_p
        matrix = np.zeros((total, total))
        names: list[str] = []
        rhs_columns: list[np.ndarray] = []
        gap = np.zeros(total)
        for p, prepared in enumerate(self.prepared):
            grid = prepared.grid
            lo, hi = self.offsets[p], self.offsets[p + 1]
            block = matrix[lo:hi, lo:hi]
            block[...] = grid.operator
            block.flat[::hi - lo + 1] += c * grid.m
            for r in range(n_p):
                coupling = self.blocks[p][r]
                if coupling is not None:
                    matrix[lo:hi, self.offsets[r]:self.offsets[r + 1]] = coupling
            force_row, moment_row = n + 2 * p, n + 2 * p + 1
            matrix[force_row, lo:hi] = grid.panels.weights
            matrix[moment_row, lo:hi] = grid.panels.weights * grid.nodes
            unknown = [q for q in QUANTITIES if q not in givens[p]]
            for k, name in enumerate(unknown):
                column = n + 2 * p + k
                if name == "settlement":
                    matrix[lo:hi, column] = -1.0
                elif name == "tilt":
                    matrix[lo:hi, column] = -grid.nodes
                else:
                    matrix[force_row if name == "force" else moment_row, column] = -1.0
            for name in sorted(givens[p]):
                column = np.zeros(total)
                if name == "settlement":
                    column[lo:hi] = 1.0
                elif name == "tilt":
                    column[lo:hi] = grid.nodes
                else:
                    column[force_row if name == "force" else moment_row] = 1.0
                names.append(f"{p}:{name}")
                rhs_columns.append(column)
            gap[lo:hi] = -grid.g
        names.append("gap")
        rhs_columns.append(gap)
        lu = lu_factor(matrix, overwrite_a=True, check_finite=False)
        units = lu_solve(lu, np.column_stack(rhs_columns), check_finite=False)
        # q of each unit response at each punch's check points (X_p, K): a load change then
        # checks q >= 0 with one small matrix product per punch
        gap_weight = np.array([1.0 if name == "gap" else 0.0 for name in names])
        checks = []
        for p, prepared in enumerate(self.prepared):
            lo, hi = self.offsets[p], self.offsets[p + 1]
            unknown = [q for q in QUANTITIES if q not in givens[p]]
            scalars = {q: units[n + 2 * p + unknown.index(q)] if q in unknown else
                       np.array([1.0 if name == f"{p}:{q}" else 0.0 for name in names])
                       for q in ("settlement", "tilt")}
            checks.append(self._pressure(
                p, prepared.check_x, units[lo:hi], units[lo:hi],
                self._coupling_at_nodes(p, units[:n]), scalars, np.full(len(names), c),
                prepared.check_formula, gap_weight))
        found = (lu, units, names, checks)
        with self._lock:
            self._systems[key] = found
            while len(self._systems) > 8:
                self._systems.pop(next(iter(self._systems)))
        return found

    # --------------------------------------------------------------------- solve

    def solve(self, inputs: Sequence[TimeInputs], time_breaks: Sequence[float] = ()
              ) -> list[ContactSolution]:
        """The full-contact answer of every punch (dimensionless, each in its own scaling),
        in the order of the punches.

        ``inputs``: each punch's validated time side; all share the times, ``c`` and the
        creep kernel (one base). An elastic base of constant modulus is answered by the
        bordered system's unit responses, creep or a varying modulus in modal form
        (:mod:`core.engines.nystrom.multi_modal`). ``time_breaks``: times where a given
        history jumps or kinks.
        """
        t0 = _time.perf_counter()
        if len(inputs) != len(self.punches):
            raise ValueError(f"inputs: {len(inputs)} time sides for {len(self.punches)} punches")
        first = inputs[0]
        times = first.times
        for k, one in enumerate(inputs):
            if not np.array_equal(one.times, times):
                raise ValueError(f"punches[{k}]: all punches share the output times")
            if (one.kernel is None) != (first.kernel is None) or (
                    one.c_is_constant != first.c_is_constant):
                raise ValueError(f"punches[{k}]: all punches stand on one base")
        givens = tuple(one.given for one in inputs)
        n = self.size
        if first.kernel is None and first.c_is_constant:
            c = float(first.c(times[:1])[0])
            _, units, names, unit_checks = self._system(givens, c)
            # loads at the output times and samples between them (q >= 0 is checked there)
            probe = (times if times.size == 1 else np.union1d(
                times, np.linspace(times[0], times[-1], HISTORY_SAMPLES["elastic"])))
            weights = np.ones((len(names), probe.size))
            for k, name in enumerate(names[:-1]):
                p, quantity = name.split(":")
                weights[k] = np.broadcast_to(inputs[int(p)].loads[quantity](probe),
                                             probe.shape)
            solved = units @ weights  # (nodes + 2 n, probe)
            nodal = effective = solved[:n]
            checks = [check @ weights for check in unit_checks]
            scalars_all = []
            for p in range(len(self.punches)):
                scalars: dict[str, np.ndarray] = {}
                unknown = [q for q in QUANTITIES if q not in givens[p]]
                for k, name in enumerate(unknown):
                    scalars[name] = solved[n + 2 * p + k]
                for name in givens[p]:
                    scalars[name] = np.broadcast_to(inputs[p].loads[name](probe),
                                                    probe.shape).astype(float)
                scalars_all.append(scalars)
            c_probe = np.full(probe.size, c)
            time_sides = [TimeSide(message="elastic base, several punches")] * len(self.punches)
            terms = None
        else:
            probe = (times if times.size == 1 else np.union1d(
                times, np.linspace(times[0], times[-1], HISTORY_SAMPLES["creep"])))
            tol = min(pc.geometry.tol for pc in self.prepared)
            kernel, fit_error = stepping_kernel(first.kernel, float(times[-1]), 0.5 * tol)
            # (from loading on, as for one punch)
            breaks = [b for b in time_breaks if 1.0 < b < times[-1]]
            c_probe = np.asarray(first.c(probe), dtype=float)
            # what the most demanding punch's panel rule leaves to the time stepping
            time_tol = time_tolerance(tol, max(pc.spatial_error for pc in self.prepared),
                                      fit_error)
            form = self.modal(givens, tol)
            answer, checks, terms = self._superposed(form, inputs, probe, first.c, c_probe,
                                                     kernel, time_tol, breaks)
            errors = answer.time_errors or (answer.time_error,) * len(self.punches)
            if step_again_at_floor(time_tol, tol, answer.success, [
                    (pc.spatial_error + (error + fit_error), pc.geometry.tol)
                    for pc, error in zip(self.prepared, errors, strict=True)]):
                # (a light punch beside a heavy one: its answer small beside its parts')
                answer, checks, terms = self._superposed(
                    form, inputs, probe, first.c, c_probe, kernel, tol / TIME_SHARE, breaks)
            nodal, effective, scalars_all = answer.nodal, answer.effective, answer.scalars
            # each punch's time error its own (a far neighbour's march does not count)
            time_sides = [TimeSide(error + fit_error, answer.steps, answer.success,
                                   answer.message, fit_error)
                          for error in (answer.time_errors
                                        or (answer.time_error,) * len(self.punches))]
        at = np.searchsorted(probe, times)
        answers = []
        for p, prepared in enumerate(self.prepared):
            lo, hi = self.offsets[p], self.offsets[p + 1]
            scalars = scalars_all[p]
            coupling = self._coupling_at_nodes(p, effective[:, at])
            q_extremes = (float(checks[p].min()), float(np.max(np.abs(checks[p]))))
            out = {k: v[at] for k, v in scalars.items()}
            pressure = self._pressure_function(p, nodal[lo:hi, at], effective[lo:hi, at],
                                               coupling, out, c_probe[at])
            if terms is not None:
                pressure = self._summed_pressure(p, terms, at, c_probe[at], pressure)
            built = dict(prepared.counts)
            solution = nystrom_solution(
                prepared, inputs[p], out, pressure, q_extremes, time_sides[p],
                _time.perf_counter() - t0, {k: 0 for k in built},
                float(np.max(np.abs(scalars["tilt"]))), False)
            solution.info["punches"] = len(self.punches)
            solution.info["coupling_seconds"] = self.seconds
            solution.info["coupled_builds"] = dict(self.counts)
            solution.contact_set.extend([[(-1.0, 1.0)] for _ in range(times.size)])
            answers.append(solution)
        return answers

    def _superposed(self, form: CoupledModalForm, inputs: Sequence[TimeInputs],
                    times: np.ndarray, c: Any, c_t: np.ndarray, kernel: Any, time_tol: float,
                    breaks: Sequence[float]
                    ) -> tuple[CoupledModalAnswer, list[np.ndarray],
                               list[tuple[float, _Part]] | None]:
        """The time-stepped answer as a sum of cached responses to each given load's shape
        and to the gaps, as one punch's is (:meth:`PreparedContact._superposed`), q of
        each punch at its check points over ``times`` (X_p, T), summed likewise from each
        response's checks, kept with it (``c_t``: c at ``times``), and, where the
        responses were kept from an earlier solve, the terms of the sum, ``(weight,
        part)`` (:class:`_Part`; None for new responses).

        The coupled equations are linear: each given load of each punch is split into its
        amplitude and its shape (normalized to unit peak), and the responses to the shapes
        (each with every other load zero and no gap; the gaps' alone) are stepped in one
        time march and kept together, keyed by the times, ``c``, the kernel and the shapes.
        A load slider of any punch then changes an amplitude: a few array operations
        instead of a time integration of the coupled system.
        """
        kernel_key, identity = content_key(kernel)
        givens = tuple(tuple(sorted(one.given)) for one in inputs)
        # (the shapes and c over the march's span and both sides of its breaks, as for
        # one punch: a temporary overload took another's answer, 1.3 % off, a review found)
        span = history_key_times(times, breaks)
        common = fingerprint("coupled modal", givens, times, kernel_key, time_tol,
                             tuple(float(b) for b in breaks), c(span))

        def zero(tt: np.ndarray) -> np.ndarray:
            return np.zeros(np.shape(tt))

        def quiet() -> list[_PartLoads]:
            return [_PartLoads(one.given, {name: zero for name in one.loads})
                    for one in inputs]

        parts: list[tuple[float, tuple, list[_PartLoads], float]] = []
        for p, one in enumerate(inputs):
            for name in sorted(one.given):
                fn = one.loads[name]
                amplitude, shape = load_shape(fn, times, span)
                if amplitude == 0.0:
                    continue
                loads = quiet()
                loads[p].loads[name] = lambda tt, f=fn, a=amplitude: f(tt) / a
                parts.append((amplitude, (common, p, name, fingerprint(shape)), loads, 0.0))
        if form.has_gap or not parts:
            parts.append((1.0, (common, "gap"), quiet(), 1.0))
        joint_key = (identity, *(key for _, key, _, _ in parts))
        with self._lock:
            found = self._responses.get(joint_key)
        reused = found is not None
        if found is None:
            responses = form.solve_parts([(loads, gap) for _, _, loads, gap in parts], times,
                                         c, kernel, time_tol, breaks)
            # q >= 0 is checked on the sum: each response's checks, summed like the answer
            found = [_Part(r, gap, self._checks(r, gap, c_t))
                     for r, (_, _, _, gap) in zip(responses, parts, strict=True)]
            with self._lock:
                self.counts["time_response"] += len(found)
                dropped = {part.serial for parts in self._responses.put(joint_key, found)
                           for part in parts}
                if dropped:  # their q at points goes with them
                    self._pressures.drop(lambda key: key[0] not in dropped)
            COUPLED.resize(self)  # the kept responses count in the cache's budget
        weights = [weight for weight, _, _, _ in parts]
        checks = [sum(w * part.checks[p] for w, part in zip(weights, found, strict=True))
                  for p in range(len(inputs))]
        # q between the nodes as a sum of the parts' once loads change (a new response's
        # first answer takes the formula on the sum: one evaluation, not one a part)
        terms = list(zip(weights, found, strict=True)) if reused else None
        found = [part.response for part in found]
        nodal = sum(w * r.nodal for w, r in zip(weights, found, strict=True))
        effective = sum(w * r.effective for w, r in zip(weights, found, strict=True))
        scalars = []
        for p, one in enumerate(inputs):
            combined = {q: sum(w * r.scalars[p][q] for w, r in zip(weights, found,
                                                                   strict=True))
                        for q in QUANTITIES}
            for name in one.given:  # exactly the loads given
                combined[name] = np.broadcast_to(np.asarray(one.loads[name](times),
                                                            dtype=float), times.shape).copy()
            scalars.append(combined)
        # each part's error is relative to its own size; on punch p it counts by the size
        # of the part's answer there (a far neighbour's load moves p by nothing, and its
        # error with it), against the size of p's whole answer
        def size_at(s: dict[str, np.ndarray]) -> float:
            return max(float(np.max(np.abs(s["settlement"]))),
                       float(np.max(np.abs(s["force"]))), 1e-300)

        errors = tuple(
            sum(abs(w) * r.time_error * size_at(r.scalars[p])
                for w, r in zip(weights, found, strict=True)) / size_at(scalars[p])
            for p in range(len(inputs)))
        failed = [r.message for r in found if not r.success]
        return CoupledModalAnswer(nodal, effective, scalars, max(errors),
                                  max(r.steps for r in found), not failed,
                                  "; ".join(failed) or found[0].message, errors), checks, terms

    def _checks(self, response: CoupledModalAnswer, gap: float, c_t: np.ndarray
                ) -> list[np.ndarray]:
        """q of one time-stepped response at each punch's check points (X_p, T), with the
        gap weighted by ``gap`` (the Nystrom formula is linear in the response and the
        gap: the checks of a sum are the sum of the checks)."""
        nodal, effective = response.nodal, response.effective
        return [self._pressure(p, pc.check_x, nodal[self.offsets[p]:self.offsets[p + 1]],
                               effective[self.offsets[p]:self.offsets[p + 1]],
                               self._coupling_at_nodes(p, effective), response.scalars[p],
                               c_t, pc.check_formula, np.full(c_t.size, gap))
                for p, pc in enumerate(self.prepared)]

    def modal(self, givens: tuple[frozenset[str], ...], tol: float) -> CoupledModalForm:
        """The modal form of the coupled equations for the punches' statements (cached)."""
        key = ("modal", givens, tol)
        with self._lock:
            found = self._systems.get(key)
        if found is None:
            n = self.size
            operator = np.zeros((n, n))
            for p, prepared in enumerate(self.prepared):
                lo, hi = self.offsets[p], self.offsets[p + 1]
                operator[lo:hi, lo:hi] = prepared.grid.operator
                for r, block in enumerate(self.blocks[p]):
                    if block is not None:
                        operator[lo:hi, self.offsets[r]:self.offsets[r + 1]] = block
            grids = [pc.grid for pc in self.prepared]
            found = CoupledModalForm(
                operator, np.concatenate([g.m for g in grids]),
                np.concatenate([g.panels.weights for g in grids]),
                np.concatenate([g.nodes for g in grids]),
                np.concatenate([g.g for g in grids]), self.offsets, givens, tol)
            with self._lock:
                self._systems[key] = found
        return found

    def _coupling_at_nodes(self, p: int, solved: np.ndarray) -> np.ndarray:
        """The other zones' part of ``F q`` at zone ``p``'s nodes (N_p, T); ``solved``
        holds the nodal q (or q - V q) of all zones (rows) at the T times."""
        out = np.zeros((self.sizes[p], solved.shape[1]))
        for r, block in enumerate(self.blocks[p]):
            if block is not None:
                out += block @ solved[self.offsets[r]:self.offsets[r + 1]]
        return out

    def _pressure(self, p: int, x: np.ndarray, nodal: np.ndarray, effective: np.ndarray,
                  coupling: np.ndarray, scalars: dict[str, np.ndarray], c: np.ndarray,
                  formula: np.ndarray | None = None, gap: np.ndarray | None = None
                  ) -> np.ndarray:
        """q on zone ``p`` at points ``x`` (its coordinates), shape (len(x), T).

        The Nystrom formula ``q = [delta + alpha x - g - F (q - V q)] / (c m)`` with the
        zone's own rows; the other zones' part of ``F (q - V q)`` (``coupling``, at the
        nodes) is smooth on the zone and taken from its panel interpolant (rows of every
        other zone at every point cost as much as the rest of the solve). ``formula``:
        where the formula is needed (None: everywhere); elsewhere q is interpolated from
        the nodes as the single-punch check does. ``c`` (T,): c at the times; ``gap``
        (T,): the gap's weight in each column (default 1).
        """
        prepared = self.prepared[p]
        grid = prepared.grid
        x = np.ascontiguousarray(x, dtype=float)
        out = np.empty((x.size, nodal.shape[1]))
        near = np.ones(x.size, dtype=bool) if formula is None else formula
        xs = np.ascontiguousarray(x[near])
        if xs.size:
            applied = prepared.rows(xs) @ effective + grid.interpolate(xs, coupling)
            g_x = prepared.geometry.g(xs)[:, None]
            drive = (scalars["settlement"][None, :] + np.outer(xs, scalars["tilt"])
                     - (g_x if gap is None else g_x * gap[None, :]))
            out[near] = (drive - applied) / (prepared.geometry.m(xs)[:, None] * c[None, :])
        if not near.all():
            out[~near] = grid.interpolate(x[~near], nodal)
        return out

    def _summed_pressure(self, p: int, terms: list[tuple[float, _Part]], at: np.ndarray,
                         c: np.ndarray, direct: Callable[[np.ndarray], np.ndarray]
                         ) -> Callable[[np.ndarray], np.ndarray]:
        """q of zone ``p`` at points ``x`` over the output columns ``at`` of the stepped
        times: the weighted sum of each response's q there (the Nystrom formula is linear
        in the response and the gap), each kept for later load changes (at most
        :data:`PRESSURE_VALUES_KEPT` values a set, :data:`PRESSURES_BYTES` in all, least
        recently used dropped first), so that a load change reads the plotting grid as a
        sum. A set too large to keep takes ``direct`` (the formula on the summed answer:
        one evaluation, not one a part). ``c`` (T,): c at those columns."""
        lo, hi = self.offsets[p], self.offsets[p + 1]
        geometry = self.prepared[p].geometry
        # the gap's weight in the sum: 1 unless no part carries the gap (its values at the
        # nodes all zero), when -g/(c m) between the nodes is added to the sum
        missing_gap = 1.0 - sum(weight * part.gap for weight, part in terms)

        def part_pressure(part: _Part, x: np.ndarray) -> np.ndarray:
            r = part.response
            return self._pressure(p, x, r.nodal[lo:hi, at], r.effective[lo:hi, at],
                                  self._coupling_at_nodes(p, r.effective[:, at]),
                                  {k: v[at] for k, v in r.scalars[p].items()}, c, None,
                                  np.full(at.size, part.gap))

        def pressure(x: np.ndarray) -> np.ndarray:
            x = np.ascontiguousarray(x, dtype=float)
            if x.size * at.size > PRESSURE_VALUES_KEPT:
                return direct(x)
            place = (p, x.tobytes(), at.tobytes())
            total = np.zeros((x.size, at.size))
            grown = False
            for weight, part in terms:
                key = (part.serial, *place)
                with self._lock:
                    q = self._pressures.get(key)
                if q is None:
                    q = part_pressure(part, x)
                    with self._lock:
                        self._pressures.put(key, q)
                    grown = True
                total += weight * q
            if grown:
                COUPLED.resize(self)
            if missing_gap != 0.0:
                total -= missing_gap * (geometry.g(x) / geometry.m(x))[:, None] / c[None, :]
            return total

        return pressure

    def _pressure_function(self, p: int, nodal: np.ndarray, effective: np.ndarray,
                           coupling: np.ndarray, scalars: dict[str, np.ndarray],
                           c: np.ndarray):  # noqa: ANN202

        def pressure(x: np.ndarray) -> np.ndarray:
            return self._pressure(p, x, nodal, effective, coupling, scalars, c)

        return pressure


#: Coupled discretizations kept for a later solve of the same punches (a load change):
#: LRU by the punches' geometries and centres.
COUPLED = StageCache("coupled_punches", max_items=8, max_bytes=256 * 2**20,
                     sizeof=lambda coupled: coupled.nbytes)


def coupled_for(punches: Sequence[PunchGeometry], c_ref: float = 1.0) -> CoupledPunches:
    """The coupled discretization of ``punches``, each punch's grid refined at the
    relative modulus ``c_ref`` (:func:`core.engines.nystrom.creep_reference` of a creeping
    base, as for one punch): from :data:`COUPLED` when the same geometries at the same
    centres were coupled before at that modulus, else built now and kept."""
    keys = [geometry_key(p.geometry) for p in punches]

    def build() -> CoupledPunches:
        return CoupledPunches(punches, [prepared_for(p.geometry, c_ref) for p in punches])

    key = fingerprint("coupled", *[(k, p.center) for k, p in zip(keys, punches, strict=True)],
                      float(c_ref))
    coupled, _ = COUPLED.get_or_compute(key, build)
    return coupled


def solve_punches(punches: Sequence[PunchGeometry], inputs: Sequence[TimeInputs],
                  time_breaks: Sequence[float] = ()) -> list[ContactSolution]:
    """The coupled full-contact answer of several punches on one base (see the module
    notes); one :class:`core.problem.ContactSolution` per punch, in its own scaling
    (``x* = (x - e)/a``). On a creeping base every punch's grid is refined at the
    modulus where the coating counts least (:func:`creep_reference`; the punches share
    the base and the times)."""
    c_ref = creep_reference(inputs[0]) if inputs else 1.0
    return coupled_for(punches, c_ref).solve(inputs, time_breaks)
