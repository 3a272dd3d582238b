"""Prepare once, solve many: the two-stage interface of the default (Nystrom) engine.

    prepared = core.prepare(lam, m, g, breakpoints=..., tol=1e-8)   # geometry: once
    sol = prepared.solve(times, force=P, moment=M, c=..., kernel=...)  # loads: cheap

:func:`prepare` validates the geometry, grades and refines the panels until the pressure
is resolved to ``tol`` (:mod:`core.engines.nystrom.adapt`) and keeps the grid. Everything a
solve needs beyond that is built on first use and kept on the object, keyed by exactly what it
depends on:

==============  ==================================  =========================================
member          depends on                           holds
==============  ==================================  =========================================
``_bordered``   statement, constant ``c``            LU of the bordered matrix, unit responses
``_modal``      statement                            modal decomposition (creep, or c(t))
``_elastic``    statement, constant ``c``            unit responses as arrays, q at points
``_rows``       the evaluation points                rows of F there (Nystrom formula)
==============  ==================================  =========================================

A change of the loads (same statement, same ``c``) is then a few array operations: a
combination of cached unit responses. ``counts`` records how often each member was
built, so tests can check that a load change builds nothing geometric.
"""

from __future__ import annotations

import threading
import time as _time
import weakref
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.cache import KeptValues, StageCache, content_key, fingerprint
from core.creep import integrated_kernel, stepping_kernel
from core.discretize import NODES_PER_PANEL, interpolation_weights, panel_index
from core.engines.nystrom.adapt import adapt
from core.engines.nystrom.bordered import BorderedSystem, touches
from core.engines.nystrom.elastic import ElasticUnits, elastic_answer
from core.engines.nystrom.modal import ModalAnswer, ModalForm
from core.engines.nystrom.result import SUCCESS_MARGIN, TimeSide, nystrom_solution
from core.problem import (
    ContactSolution,
    Geometry,
    Scalar,
    TimeInputs,
    accepts,
    check_held_compliance,
    validate_geometry,
    validate_time_inputs,
)
from core.time import history_key_times
from core.work import one_blas_thread

#: The time stepping aims at least this many times below tol (:func:`time_tolerance`):
#: its step-doubling estimate read up to ~20x the true error on decaying creep (as the
#: projection's, see core/engines/projection/solve.py), so this floor alone was far
#: tighter than tol asked.
TIME_SHARE = 30.0
#: ... and at this share of what the panel rule's and the kernel fit's estimates leave of
#: tol, when that is more: its own estimate adds to theirs in the answer's, which success
#: asks to meet tol, and reads high (measured on the 50-year two-punch preset at tol 1e-4:
#: 1.7e-5 where the settlements and tilts were 1.6e-6 from the answer at tol 1e-7; at
#: tol / 30 alone the stepping took twice the steps, 212 against 106, for 2.2e-6).
TIME_LEFT_SHARE = 0.5


def time_tolerance(tol: float, spatial_error: float, fit_error: float,
                   defect: float = 0.0) -> float:
    """The tolerance of the time stepping (relative, like ``tol``): ``TIME_LEFT_SHARE``
    of what the panel rule's ``spatial_error``, the kernel fit's ``fit_error`` and the
    modes' probe ``defect`` leave of ``tol``, and at least ``tol / TIME_SHARE`` (all
    relative estimates). It depends on the geometry, the statement, the kernel and tol,
    not on the loads: a load change reuses the time responses kept for the geometry
    (unless the answer then misses tol and is stepped again at the floor, loads whose
    responses cancel)."""
    left = tol - spatial_error - fit_error - defect
    floor = tol / TIME_SHARE
    return max(floor, TIME_LEFT_SHARE * left) if np.isfinite(left) else floor


def step_again_at_floor(time_tol: float, tol: float, stepped: bool,
                        parts: Iterable[tuple[float, float]]) -> bool:
    """Whether an answer stepped at the aim ``time_tol`` (:func:`time_tolerance`) is to
    be stepped again at ``tol / TIME_SHARE``: it was aimed above that, its stepping
    finished (one stopped at its step limit would stop there again) and one of ``parts``
    (its whole error estimate, as success sums it, and the tol it must meet) misses:
    responses to loads that cancel, each with its own error, against a small answer."""
    return (time_tol > tol / TIME_SHARE and stepped
            and not all(accepts(error, part_tol, SUCCESS_MARGIN) for error, part_tol in parts))


#: Points (Chebyshev, plus both sides of every jump) where q >= 0 is checked.
CHECK_POINTS = 401
#: Times per block when the extremes of q over the check points are formed (see _extremes):
#: 401 points x 256 times is 0.8 MB.
CHECK_BLOCK = 256
#: Bound of the cached operator rows at evaluation points [bytes].
ROWS_BYTES = 64 * 2**20
#: Time-stepped responses kept with one prepared geometry for later load changes: at most
#: this many sets (a load slider alternates among a few shapes) and this many bytes (a
#: set of 1300 output times on a 2000-node grid holds ~20 MiB).
RESPONSES_KEPT = 24
RESPONSES_BYTES = 64 * 2**20
#: Samples of the load histories between the output times where the validity of the
#: answer (q >= 0, the tilt) is checked as well, so a peak between outputs is not missed:
#: elastic (a matrix product per sample) and creeping (each sample is an output of the
#: time stepping: 256 took a 100-output aging scene from 89 to 179 ms, 64 to 106 ms).
HISTORY_SAMPLES = {"elastic": 256, "creep": 64}
#: Digits of a load's shape (the history over its peak) that key its cached creep
#: response: far above the rounding of a unit conversion (1e-16), far below any tol, so a
#: load change that only scales a load reuses the response of its shape.
SHAPE_DIGITS = 12


@dataclass(frozen=True)
class _Superposed:
    """A time-stepped answer combined from cached responses (see ``_superposed``)."""

    scalars: dict[str, np.ndarray]
    effective: Callable[[np.ndarray | slice], np.ndarray]  # q - V q at the nodes
    q_extremes: tuple[float, float]  # (min q, max |q|) over the check points and times
    time_error: float
    steps: int
    success: bool
    message: str


def _as_slice(points: np.ndarray) -> np.ndarray | slice:
    """``points`` (increasing indices) as a slice where they are consecutive."""
    if points.size and points[-1] - points[0] == points.size - 1:
        return slice(int(points[0]), int(points[-1]) + 1)
    return points


def _extremes(weights: list[float], checks: list[np.ndarray]) -> tuple[float, float]:
    """(min q, max |q|) of ``sum weights[p] checks[p]`` (each (X, T)), formed a block of
    times at a time: the block stays in the cache (the whole sum at 1064 times, 3.4 MB,
    was written and read again from memory)."""
    lowest, highest = np.inf, -np.inf
    size = checks[0].shape[1]
    for start in range(0, size, CHECK_BLOCK):
        cols = slice(start, min(size, start + CHECK_BLOCK))
        block = weights[0] * checks[0][:, cols]
        for weight, check in zip(weights[1:], checks[1:], strict=True):
            block += weight * check[:, cols]
        lowest, highest = min(lowest, float(block.min())), max(highest, float(block.max()))
    return lowest, max(-lowest, highest)


def _check_points(breakpoints: Sequence[float]) -> np.ndarray:
    bps = np.asarray(breakpoints, dtype=float)
    return np.concatenate([np.cos(np.linspace(0.0, np.pi, CHECK_POINTS)), bps - 1e-9,
                           bps + 1e-9])


class PreparedContact:
    """The geometry of one problem, discretized once (see the module notes).

    Attributes: ``geometry`` (validated inputs), ``grid``
    (:class:`core.engines.nystrom.bordered.NystromGrid`),
    ``spatial_error`` (estimated relative error of q), ``resolved``, ``counts``
    (evaluations of each cached member), ``seconds`` (time spent preparing).
    """

    method = "nystrom"

    def __init__(self, geometry: Geometry, c_ref: float = 1.0) -> None:
        """``c_ref``: the relative modulus the grid is refined at (1: the base at loading;
        below 1 for a base whose creep makes the coating count less, see
        :func:`creep_reference`)."""
        t0 = _time.perf_counter()
        self.geometry = geometry
        self.c_ref = float(c_ref)
        self.counts: Counter[str] = Counter()
        adaptive = adapt(geometry.lam, geometry.m, geometry.g, geometry.g_is_zero,
                         geometry.breakpoints, geometry.tol, c_ref=self.c_ref)
        self.counts["grid"] += 1
        self.grid = adaptive.grid
        self.spatial_error = adaptive.spatial_error
        self.resolved = adaptive.resolved
        self.narrowest = adaptive.narrowest
        # LU of c m + A at the modulus the grid was refined at: the bordered system of a
        # statement at that c needs only a 2 x 2 Schur complement on top of it.
        self._factor_c, self._factor = adaptive.c_ref, adaptive.factor
        self._factor_responses = adaptive.responses
        self._bordered: dict[tuple, tuple[BorderedSystem, dict[str, np.ndarray]]] = {}
        self._modal: dict[frozenset[str], ModalForm] = {}
        self._rows: dict[bytes, np.ndarray] = {}
        self._elastic: dict[tuple, ElasticUnits] = {}
        # time-stepped responses of each joint key: [(answer, q at the check points)]
        self._responses = KeptValues(RESPONSES_KEPT, RESPONSES_BYTES, _responses_nbytes)
        self.check_x = _check_points(geometry.breakpoints)
        # Check points on panels ending at +-1 or a jump take the Nystrom formula (q has
        # (x - e) ln|x - e| terms there); elsewhere q is analytic and its panel interpolant
        # is resolved to the refinement's tail bound, so it is interpolated (the formula at
        # all 405 points cost as much as the operator itself).
        singular = np.array([-1.0, 1.0, *geometry.breakpoints])
        panel_of = panel_index(self.grid.panels, self.check_x)
        self.check_formula = touches(self.grid.panels, singular)[panel_of]
        # the interpolation of the other check points, panel by panel: (panel, points,
        # weights (points, NODES_PER_PANEL))
        smooth = np.flatnonzero(~self.check_formula)
        index, weights = interpolation_weights(self.grid.panels, self.check_x[smooth])
        self._check_interpolation = [(int(p), _as_slice(smooth[index == p]),
                                      weights[index == p]) for p in np.unique(index)]
        self.element_ends = tuple(sorted(set(self.grid.panels.edges[1:-1].tolist())
                                         | set(geometry.breakpoints)))
        self._solves = 0
        # Solves of one prepared geometry may run in several threads (the explorer's).
        self._lock = threading.RLock()
        self.seconds = _time.perf_counter() - t0

    # ------------------------------------------------------------- cached members

    def bordered(self, given: frozenset[str], c: float
                 ) -> tuple[BorderedSystem, dict[str, np.ndarray]]:
        """Factorized bordered system and its unit responses for a statement and constant c."""
        key = (given, c)
        with self._lock:
            known = len(self._bordered)
            found = self._bordered_locked(key, given, c)
            grown = len(self._bordered) > known
        if grown:
            PREPARED.resize(self)
        return found

    def _bordered_locked(self, key: tuple, given: frozenset[str], c: float
                         ) -> tuple[BorderedSystem, dict[str, np.ndarray]]:
        if key not in self._bordered:
            same_c = c == self._factor_c
            system = BorderedSystem(self.grid, c, given, self._factor if same_c else None,
                                    self._factor_responses if same_c else None)
            self._bordered[key] = (system, system.unit_responses())
            self.counts["bordered"] += 1
            while len(self._bordered) > 8:  # a few statements and moduli at once
                self._bordered.pop(next(iter(self._bordered)))
        return self._bordered[key]

    def modal(self, given: frozenset[str]) -> ModalForm:
        """Modal decomposition of a statement (for creep or a modulus varying in time)."""
        with self._lock:
            found = self._modal.get(given)
            if found is None:
                found = self._modal[given] = ModalForm(self.grid, given, self.geometry.tol)
                self.counts["modal"] += 1
                built = True
            else:
                built = False
        if built:
            PREPARED.resize(self)
        return found

    def _elastic_units(self, given: frozenset[str], c0: float) -> ElasticUnits:
        """Unit responses of a statement at constant c (see :mod:`core.engines.nystrom.elastic`)."""
        key = (given, c0)
        with self._lock:
            units = self._elastic.get(key)
            if units is None:
                units = self._elastic[key] = ElasticUnits(self, given, c0)
                while len(self._elastic) > 8:  # as many as bordered systems are kept
                    self._elastic.pop(next(iter(self._elastic)))
            return units

    def rows(self, x: np.ndarray) -> np.ndarray:
        """Rows of the operator F at points ``x`` (len(x), N), cached by the points."""
        key = x.tobytes()
        with self._lock:
            return self._rows_locked(key, x)

    def _rows_locked(self, key: bytes, x: np.ndarray) -> np.ndarray:
        if key not in self._rows:
            self._rows[key] = self.grid.rows(x)
            self._rows[key].setflags(write=False)  # returned to every later caller
            self.counts["rows"] += 1
            while sum(r.nbytes for r in self._rows.values()) > ROWS_BYTES and len(
                    self._rows) > 1:
                self._rows.pop(next(iter(self._rows)))
        return self._rows[key]

    def nystrom_pressure(self, x: np.ndarray, drive: np.ndarray, c: np.ndarray,
                         effective: np.ndarray) -> np.ndarray:
        """``q(x, t) = [drive(x, t) - (F (q - V q))(x, t)] / (c(t) m(x))``, shape (len(x), T).

        ``drive = delta + alpha x - g(x)`` at the points, ``effective`` the nodal
        ``q - V q`` (just q for an elastic base).
        """
        x = np.ascontiguousarray(x, dtype=float)
        m_x = self.geometry.m(x)
        return (drive - self.rows(x) @ effective) / (m_x[:, None] * c[None, :])

    @property
    def nbytes(self) -> int:
        """Memory held by the grid and the cached members [bytes] (approximate)."""
        total = self.grid.operator.nbytes * 2
        total += sum(r.nbytes for r in self._rows.values())
        total += sum(2 * self.grid.operator.nbytes for _ in self._bordered)
        total += sum(3 * self.grid.operator.nbytes for _ in self._modal)
        total += self._responses.nbytes
        return int(total)

    # --------------------------------------------------------------------- solve

    @one_blas_thread()
    def solve(self, times: Sequence[float] | np.ndarray, *, c: Scalar = 1.0,
              kernel: Callable | None = None, settlement: Scalar | None = None,
              tilt: Scalar | None = None, force: Scalar | None = None,
              moment: Scalar | None = None, time_breaks: Sequence[float] = ()
              ) -> ContactSolution:
        """Solve for the loads at ``times`` (dimensionless; see ``solve_dimensionless``)."""
        inputs = validate_time_inputs(times, c, kernel, {"settlement": settlement, "tilt": tilt,
                                                         "force": force, "moment": moment})
        return self.solve_validated(inputs, time_breaks)

    def solve_validated(self, inputs: TimeInputs, time_breaks: Sequence[float] = (),
                        *, check_only: bool = False) -> ContactSolution:
        """:meth:`solve` for inputs already checked by :func:`core.problem.validate_time_inputs`.

        ``time_breaks``: times where a given history jumps or kinks (dimensionless).
        ``check_only``: a preliminary solve (the contact check of ``contact="auto"``) that
        leaves the geometry's first solve, and its stage report "grid built", to the
        answer that follows.
        """
        t0 = _time.perf_counter()
        geometry = self.geometry
        times = inputs.times
        built_before = dict(self.counts)
        # (from loading on, t* = 1: a jump before the first output time is marched too;
        # it was dropped from the march and from the key of its response, 1e-3 off at
        # tol 1e-6, a review found)
        breaks = np.array([b for b in np.asarray(time_breaks, dtype=float).ravel()
                           if np.isfinite(b) and 1.0 < b < times[-1]])
        probe = self._history_times(times, "elastic" if inputs.kernel is None else "creep")
        if breaks.size:  # both sides of every jump are checked too
            probe = np.union1d(probe, np.concatenate([breaks * (1 - 1e-12),
                                                      breaks * (1 + 1e-12)]))
        if inputs.kernel is None and inputs.c_is_constant:
            units = self._elastic_units(inputs.given, float(inputs.c(times[:1])[0]))
            answer = elastic_answer(units, inputs, probe)
            scalars, pressure = answer.scalars, answer.pressure
            q_extremes, max_abs_tilt = answer.q_extremes, answer.max_abs_tilt
            time_side = TimeSide()
        else:
            g = self.geometry.g
            form = self.modal(inputs.given)
            merged = np.union1d(times, probe)
            kernel, fit_error = stepping_kernel(inputs.kernel, float(times[-1]),
                                                0.5 * geometry.tol)
            time_tol = time_tolerance(geometry.tol, self.spatial_error, fit_error,
                                      form.mode_defect)
            answer = self._superposed(form, merged, inputs, kernel, time_tol, breaks)
            # (the time side's error as nystrom_solution adds it to the spatial one)
            time_part = answer.time_error + fit_error + form.mode_defect
            if step_again_at_floor(time_tol, geometry.tol, answer.success,
                                   [(self.spatial_error + time_part, geometry.tol)]):
                answer = self._superposed(form, merged, inputs, kernel,
                                          geometry.tol / TIME_SHARE, breaks)
            q_extremes = answer.q_extremes
            c_merged = inputs.c(merged)
            sc = answer.scalars

            def merged_pressure(x: np.ndarray, at: np.ndarray | slice) -> np.ndarray:
                drive = (sc["settlement"][at][None, :] + np.outer(x, sc["tilt"][at])
                         - g(x)[:, None])
                return self.nystrom_pressure(x, drive, c_merged[at],
                                             answer.effective(at))

            at = np.searchsorted(merged, times)
            scalars = {k: v[at] for k, v in sc.items()}
            max_abs_tilt = float(np.max(np.abs(sc["tilt"])))
            # (the modes' probe defect maps every march back: it is the time side's too)
            time_side = TimeSide(answer.time_error + fit_error + form.mode_defect,
                                 answer.steps, answer.success, answer.message, fit_error)

            def pressure(x: np.ndarray) -> np.ndarray:
                return merged_pressure(x, at)
        built = {k: self.counts[k] - built_before.get(k, 0) for k in self.counts}
        first_solve = self._solves == 0
        if not check_only:
            self._solves += 1
        return nystrom_solution(self, inputs, scalars, pressure, q_extremes, time_side,
                                _time.perf_counter() - t0, built, max_abs_tilt, first_solve)

    def _superposed(self, form: ModalForm, times: np.ndarray, inputs: TimeInputs, kernel: Any,
                    time_tol: float, breaks: np.ndarray) -> _Superposed:
        """The time-stepped answer as a sum of cached responses to each load and the gap.

        The problem is linear: each given load is split into its amplitude and its shape
        (normalized to unit peak), and the responses to the shapes (each with the other
        loads zero and no gap; the gap's alone) are stepped in one time march and kept
        together, keyed by the times, c, the kernel and the shapes. A load slider changes
        an amplitude, so it costs a few array operations instead of a time integration.
        """
        kernel_key, identity = content_key(kernel)
        # the shapes and c over the march's span and both sides of its breaks, not at the
        # output times alone: a force rising linearly to 500 kN/m and one held at 500 kN/m
        # were one shape at a single output time, and the second's answer was given for
        # the first (5 % off, found by a review)
        span = history_key_times(times, breaks)
        common = fingerprint("modal", tuple(sorted(inputs.given)), times, kernel_key,
                             time_tol, breaks, inputs.c(span))
        zero = {name: (lambda tt: np.zeros(np.shape(tt))) for name in inputs.loads}
        parts: list[tuple[float, tuple, dict[str, Callable], float]] = []
        for name, fn in sorted(inputs.loads.items()):
            amplitude, shape = load_shape(fn, times, span)
            if amplitude == 0.0:
                continue
            unit = dict(zero)
            unit[name] = lambda tt, f=fn, a=amplitude: f(tt) / a
            parts.append((amplitude, (common, name, fingerprint(shape)), unit, 0.0))
        if not self.geometry.g_is_zero or not parts:
            parts.append((1.0, (common, "gap"), zero, 1.0))
        weighted_error = 0.0
        terms: list[tuple[float, ModalAnswer]] = []
        # All parts are stepped in one time march (force and moment together), so they are
        # cached together: the steps depend on every part, and an answer must not depend
        # on which parts happened to be cached before.
        joint_key = (identity, *(key for _, key, _, _ in parts))
        with self._lock:
            found = self._responses.get(joint_key)
        if found is None:
            answers = form.solve_parts(times, inputs.c, kernel,
                                       [(loads, gap) for _, _, loads, gap in parts],
                                       time_tol, breaks)
            c_t = inputs.c(times)
            found = [(response, self._check_pressure(response, gap, c_t))
                     for (_, _, _, gap), response in zip(parts, answers, strict=True)]
            self.counts["time_response"] += len(found)
            with self._lock:
                self._responses.put(joint_key, found)
            PREPARED.resize(self)  # the kept responses count in the cache's budget
        for (weight, _, _, _), (response, _) in zip(parts, found, strict=True):
            terms.append((weight, response))
            size = max(float(np.max(np.abs(response.scalars["settlement"]))),
                       float(np.max(np.abs(response.scalars["force"]))), 1e-300)
            weighted_error += abs(weight) * response.time_error * size
        scalars = {k: sum(w * r.scalars[k] for w, r in terms) for k in terms[0][1].scalars}
        size = max(float(np.max(np.abs(scalars["settlement"]))),
                   float(np.max(np.abs(scalars["force"]))), 1e-300)
        failed = [r.message for _, r in terms if not r.success]

        def effective(at: np.ndarray | slice) -> np.ndarray:
            # combined only where q is asked for (the output times), not on every sample
            return sum(w * r.effective(at) for w, r in terms)

        q_extremes = _extremes([weight for weight, _, _, _ in parts],
                               [check for _, check in found])
        return _Superposed(scalars, effective, q_extremes, float(weighted_error / size),
                           max(r.steps for _, r in terms), not failed,
                           "; ".join(failed) or terms[0][1].message)

    def _check_pressure(self, response: ModalAnswer, gap: float, c_t: np.ndarray
                        ) -> np.ndarray:
        """q of a time-stepped response at the check points (X, T), as the elastic check
        takes it: the Nystrom formula on panels touching +-1 or a jump, elsewhere the
        panel interpolant of the nodal q (16 nodes a point instead of all N, and the
        operator rows at the formula's points only, which the contact check shares)."""
        x, formula = self.check_x, self.check_formula
        sc = response.scalars
        near = x[formula]
        drive = (sc["settlement"][None, :] + np.outer(near, sc["tilt"])
                 - gap * self.geometry.g(near)[:, None])
        check = np.empty((x.size, c_t.size))
        check[formula] = (drive - response.effective_through(self.rows(near))) / (
            self.geometry.m(near)[:, None] * c_t[None, :])
        nodal = response.nodal.reshape(self.grid.panels.n_panels, NODES_PER_PANEL, -1)
        for panel, points, weights in self._check_interpolation:
            if isinstance(points, slice):  # written in place
                np.matmul(weights, nodal[panel], out=check[points])
            else:
                check[points] = weights @ nodal[panel]
        return check

    def _history_times(self, times: np.ndarray, kind: str) -> np.ndarray:
        """Output times plus samples between them, where the answer's validity is checked.

        No two checked times are further apart than the samples' spacing. Under creep (each
        checked time is an output of the time stepping) a sample is taken only inside a
        gap of the outputs wider than that spacing, which keeps that bound: 100 equally
        spaced outputs need none of the 64 (measured 1.5 ms of a 22 ms new aging scene).
        """
        if times.size == 1:
            return times
        samples = np.linspace(times[0], times[-1], HISTORY_SAMPLES[kind])
        if kind == "creep":
            after = np.minimum(np.searchsorted(times, samples), times.size - 1)
            gap = times[after] - times[np.maximum(after - 1, 0)]
            samples = samples[gap > samples[1] - samples[0]]
        return np.union1d(times, samples)


def load_shape(fn: Callable[[np.ndarray], np.ndarray], times: np.ndarray,
               span: np.ndarray) -> tuple[float, np.ndarray]:
    """A given load's amplitude (its value of largest size at ``times``) and its shape,
    the load over the amplitude at ``span`` (:func:`core.time.history_key_times` of
    ``times``, which holds them) to :data:`SHAPE_DIGITS` digits: the key of its cached
    creep response, so that a load that only scales reuses it (one in other units, a force
    in N turned dimensionless, differs by rounding alone). The shape is None where the
    amplitude is 0 (the load is left out)."""
    values = np.broadcast_to(np.asarray(fn(span), dtype=float), span.shape)
    at_times = values[np.searchsorted(span, times)]
    amplitude = float(at_times[np.argmax(np.abs(at_times))])
    if amplitude == 0.0:
        return 0.0, None
    return amplitude, np.round(values / amplitude, SHAPE_DIGITS) + 0.0


@one_blas_thread()
def prepare(lam: float, m: Scalar, g: Scalar, *, breakpoints: Sequence[float] = (),
            tol: float = 1e-8, method: str = "nystrom") -> Any:
    """Discretize the geometry once (dimensionless); ``.solve(times, ...)`` takes the loads.

    ``lam = a/H``; ``m(x) > 0`` the coating compliance; ``g(x) >= 0`` the gap; jumps of m
    or g declared in ``breakpoints``; ``tol`` the relative accuracy target of delta,
    alpha, P, M and of q on the whole of [-1, 1]. This is the Nystrom engine's prepared
    form (``method="nystrom"`` only); the engines of :data:`core.engines.ENGINES` all
    ``prepare`` a validated geometry the same way.
    """
    if method != "nystrom":
        raise ValueError(f"method: prepare supports 'nystrom' only, got {method!r}")
    return PreparedContact(validate_geometry(lam, m, g, breakpoints, tol))


#: Prepared geometries kept for :func:`solve_with_prepared` (LRU, safe across threads,
#: cleared by core.cache.clear_caches). A grid of 128 panels holds a 2048^2 operator
#: (32 MiB, more with its factorizations); typical ones hold 0.5-5 MiB.
PREPARED_BYTES = 256 * 2**20
PREPARED = StageCache("prepared", max_items=32, max_bytes=PREPARED_BYTES,
                      sizeof=lambda prepared: prepared.nbytes)


def geometry_key(geometry: Geometry) -> str:
    """The key of a validated geometry in :data:`PREPARED` (its values on 2049 Chebyshev
    points and both sides of each jump), worked out once per geometry object: the
    contact check of ``contact="auto"`` and the answer after it prepare the same one
    (~0.6 ms a key, a tenth of a load change's solve)."""
    from core.cache import fingerprint

    found = _GEOMETRY_KEYS.get(id(geometry))
    if found is not None and found[0]() is geometry:
        return found[1]
    probe = np.cos(np.linspace(0.0, np.pi, 2049))
    bps = np.asarray(geometry.breakpoints, dtype=float)
    probe = np.concatenate([probe, bps - 1e-9, bps + 1e-9])
    key = fingerprint("nystrom", geometry.lam, geometry.breakpoints, geometry.tol,
                      geometry.m(probe), geometry.g(probe))
    # by identity, not equality: an equal geometry made later (the same callables) is
    # sampled again, as before
    _GEOMETRY_KEYS[id(geometry)] = (weakref.ref(geometry), key)
    weakref.finalize(geometry, _GEOMETRY_KEYS.pop, id(geometry), None)
    return key


def _responses_nbytes(found: list[tuple[ModalAnswer, np.ndarray]]) -> int:
    """Memory of one set of kept time-stepped responses and their checks [bytes] (their
    modes' basis is the modal form's)."""
    return sum(sum(a.nbytes for a in response.modal_effective) + check.nbytes
               + sum(v.nbytes for v in response.scalars.values()) for response, check in found)


#: :func:`geometry_key`'s keys of the geometry objects alive: id -> (weak reference, key).
_GEOMETRY_KEYS: dict[int, tuple[weakref.ref, str]] = {}


def solve_with_prepared(lam: float, m: Scalar, g: Scalar, times: Any, *, c: Scalar = 1.0,
                        kernel: Callable | None = None, settlement: Scalar | None = None,
                        tilt: Scalar | None = None, force: Scalar | None = None,
                        moment: Scalar | None = None, breakpoints: Sequence[float] = (),
                        tol: float = 1e-8, time_breaks: Sequence[float] = (),
                        check_only: bool = False) -> ContactSolution:
    """The Nystrom engine on raw arguments: validate, prepare (or reuse) the geometry, solve.

    ``check_only``: see :meth:`PreparedContact.solve_validated`.

    Geometries are recognised by their values on 2049 Chebyshev points (and both sides of
    each jump), so a repeated call with only other loads reuses the prepared grid.
    """
    geometry = validate_geometry(lam, m, g, breakpoints, tol)
    inputs = validate_time_inputs(times, c, kernel, {"settlement": settlement, "tilt": tilt,
                                                     "force": force, "moment": moment})
    return prepared_for(geometry).solve_validated(inputs, time_breaks, check_only=check_only)


def _prepared_key(geometry: Geometry, c_ref: float) -> Any:
    return geometry_key(geometry) if c_ref == 1.0 else (geometry_key(geometry), float(c_ref))


def prepared_for(geometry: Geometry, c_ref: float = 1.0) -> PreparedContact:
    """The prepared form of a validated geometry, refined at relative modulus ``c_ref``:
    from :data:`PREPARED` when a geometry of the same values was prepared before, else
    prepared now and kept there."""
    prepared, _ = PREPARED.get_or_compute(_prepared_key(geometry, c_ref),
                                          lambda: PreparedContact(geometry, c_ref))
    return prepared


def cached_prepared(geometry: Geometry, c_ref: float = 1.0) -> PreparedContact | None:
    """:func:`prepared_for` when :data:`PREPARED` holds it, else None (nothing is built)."""
    return PREPARED.get(_prepared_key(geometry, c_ref))


#: Steps per octave of the relative modulus a creeping problem's grid is refined at: a
#: creep parameter moved a little keeps its grid (rounded down: the finer side).
REFERENCE_STEPS_PER_OCTAVE = 4
#: A creep that lowers ``c / F`` by less than this share keeps the grid refined at
#: loading: its coating counts as much to well within the estimate, and a vanishing creep
#: is then answered on the elastic base's grid (rounded down, any creep took the next
#: step, 2^-1/4, and another grid: answers ~5e-8 apart at tol 1e-6 for a creep
#: coefficient of 1e-9).
REFERENCE_UNMOVED = 1e-6

#: A creep law's held compliance ``F`` (a kernel with a ``key``, checked where it was
#: made) is evaluated at up to twice this many of the output times (spread evenly over
#: their indices and geometrically, the first and the last among them), then at every
#: other time where ``c / F`` can still be smaller (:func:`_smallest_ratio`). At all 262
#: output times of the two-footing preset it took 51 ms of a 190 ms new scene (36
#: exponentials, amplitudes varying with the age); sampled, the scene 154 ms, the same
#: smallest ratio (342 scenes of the four creep laws, to 2.8e-16).
REFERENCE_SAMPLES = 24


def _smallest_ratio(t: np.ndarray, c_t: np.ndarray,
                    held: Callable[[np.ndarray], np.ndarray]) -> float:
    """The smallest ``c_t / held(t)`` over the times ``t`` (``c_t`` at all of them), with
    ``held`` (the held compliance ``F``, which grows with time under a creep law) read at
    a sample of the times and wherever the bound ``c(t) / F(next sampled time)`` is below
    the smallest so far: exact where ``F`` does not decrease, whatever ``c`` does. Where
    the sampled ``F`` decreases, every time is read."""
    n = t.size
    pick = np.union1d(np.geomspace(1, n, REFERENCE_SAMPLES).round().astype(int) - 1,
                      np.linspace(0, n - 1, REFERENCE_SAMPLES).round().astype(int))
    sampled = held(t[pick])
    if np.any(np.diff(sampled) < 0.0):
        return float(np.min(c_t / held(t)))
    best = float(np.min(c_t[pick] / sampled))
    # F(t) <= F at the next sampled time: c / that bounds c / F(t) from below
    bound = c_t / sampled[np.searchsorted(pick, np.arange(n))]
    rest = np.setdiff1d(np.flatnonzero(bound < best), pick)
    if rest.size:
        best = min(best, float(np.min(c_t[rest] / held(t[rest]))))
    return best


_REFERENCES = StageCache("creep_reference", max_items=256, max_bytes=2**16,
                         sizeof=lambda _: 8)


def creep_reference(inputs: TimeInputs) -> float:
    """The relative modulus [-] a creeping problem's grid is refined at: the smallest of
    ``c(t) / F(t)`` over the output times, ``F(t) = 1 - int_1^t K(t, u) du`` the compliance
    of a stress held since loading relative to the elastic one (rounded down to
    :data:`REFERENCE_STEPS_PER_OCTAVE` steps an octave); 1 without creep or where it is
    not below ``1 - REFERENCE_UNMOVED``.

    The coating's term is ``c(t) m q`` against the base's ``(I - V) A q``: as the base
    creeps its compliance grows by about ``F``, so the coating counts as ``m c / F`` and
    the pressure at the punch's edges sharpens. A grid refined at loading (``c = 1``) then
    misses ``tol`` at late times: measured on ``lam = 1, m = 0.1, g = 0.01 x^2`` with an
    exponential kernel (``F`` up to 2.5), the error of q at ``x = 1`` grew from 1.9e-7 at
    loading to 1.6e-6 at ``t = 12`` under an estimate of 9.0e-7 (tol 1e-6).
    """
    if inputs.kernel is None:
        return 1.0
    key = getattr(inputs.kernel, "key", None)

    def held(t: np.ndarray) -> np.ndarray:
        f = 1.0 + integrated_kernel(inputs.kernel, t, np.ones_like(t))
        # a compliance through zero made the ratio's log NaN
        check_held_compliance(inputs.kernel, t, f)
        return f

    def compute() -> float:
        t = np.asarray(inputs.times, dtype=float)
        c_t = np.asarray(inputs.c(t), dtype=float)
        if key is None or t.size <= 2 * REFERENCE_SAMPLES:
            # every output time: the solve's inputs checked only a sample of a plain
            # callable's compliance
            ratio = float(np.min(c_t / held(t)))
        else:
            ratio = _smallest_ratio(t, c_t, held)
        if not ratio < 1.0 - REFERENCE_UNMOVED:
            return 1.0
        steps = REFERENCE_STEPS_PER_OCTAVE
        return float(2.0 ** (np.floor(steps * np.log2(ratio)) / steps))

    if key is None:  # a plain callable: no content to key it by
        return compute()
    # a fitted kernel's key holds the creep law's inputs (a dataclass): its repr is its
    # content
    cache_key = fingerprint("creep reference", repr(key), inputs.times,
                            np.asarray(inputs.c(inputs.times), dtype=float))
    return _REFERENCES.get_or_compute(cache_key, compute)[0]
