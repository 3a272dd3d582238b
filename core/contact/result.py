"""The answer of a lift-off solve: :class:`UnilateralSolution` and its pressure q(x).

The pressure at any x is the Nystrom formula of :mod:`core.contact.step` on each output
time's panels (0 off the contact set). :func:`contact_set_from_pressure` turns sampled
pressures of any engine into contact sets.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core.contact.step import Space, Step, nystrom_pressure
from core.discretize import Panels
from core.kernel import FULL_ACCURACY
from core.problem import SolveOutcome, pressure_positions

#: The unilateral solvers' ``success_margin`` (:func:`core.problem.accepts`): their
#: Richardson and coarser-rule estimates can read up to ~3x low, as the projection's do.
UNILATERAL_MARGIN = 3.0


def not_within_tol(error: float, end_error: float, tol: float, end_tol: float) -> str:
    """Why a lift-off answer is not a success, for its message: which of its estimate
    (``error``, relative, held to ``tol`` with :data:`UNILATERAL_MARGIN`) and its zone
    ends' (``end_error``, half-widths, held to ``end_tol``) missed, in numbers. An estimate
    below tol but not below tol / 3 reads as a contradiction unless the margin is said."""
    missed = []
    if not error * UNILATERAL_MARGIN <= tol:
        missed.append(f"{UNILATERAL_MARGIN:g} x the estimated error = "
                      f"{UNILATERAL_MARGIN * error:.1e} is over tol {tol:.1e} (these "
                      f"estimates have read up to {UNILATERAL_MARGIN:g}x low)")
    if not end_error <= end_tol:
        missed.append(f"the zone ends' error {end_error:.1e} is over {end_tol:g} half-widths")
    return "; not within tol: " + " and ".join(missed) if missed else ""


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
    # the displacement e(x) the other punches on the base add (core.contact.coupled)
    coupling: Callable[[np.ndarray], np.ndarray] | None = None
    # the contact parts of the panels holding a free end, each one Gauss panel, and the
    # density on them that goes with ``q`` (core.contact.march.kink_correction): q on those
    # panels is the kink-corrected pressure, cut at the nodal end (the interpolant's root;
    # the formula gives q beyond it, up to the zone's reported end)
    cut: Panels | None = None
    cut_q: np.ndarray | None = None

    def displacement(self, lam: float) -> Callable[[np.ndarray], np.ndarray] | None:
        """What the pressure formula adds to ``delta + alpha x - g - s F(q)`` besides the
        rule's own density, as a function of x: the creep memory's e(x), the other
        punches' (``coupling``) and ``s F`` of the cut parts' density (taken off); None
        when nothing."""
        parts: list[Callable[[np.ndarray], np.ndarray]] = []
        if self.coupling is not None:
            parts.append(self.coupling)
        if self.memory is not None or (self.cut is not None and self.cut.n_panels):
            from core.discretize import operator_rows

            if self.memory is not None:
                parts.append(lambda t: operator_rows(lam, self.panels, t) @ self.memory)
            if self.cut is not None and self.cut.n_panels:
                parts.append(lambda t: -self.step.scale * (operator_rows(lam, self.cut, t)
                                                           @ self.cut_q))
        if not parts:
            return None
        return lambda t: sum(part(np.asarray(t, dtype=float)) for part in parts)


# repr=False: the short repr of SolveOutcome, not every array and snapshot
@dataclass(frozen=True, repr=False)
class UnilateralSolution(SolveOutcome):
    """The answer of :func:`solve_unilateral` (dimensionless, like ``ContactSolution``).

    ``times`` (T,); ``settlement`` (delta), ``tilt`` (alpha), ``force`` (P), ``moment`` (M)
    over ``times``; ``contact_set[k]`` the list of ``(start, end)`` intervals of x in
    [-1, 1] where q > 0 at ``times[k]``; ``pressure(x)`` q of shape ``(len(x), T)`` (0 off
    contact); ``info`` with ``error_estimate``, ``zone_end_error`` [half-widths],
    ``success``, ``message``, ``flags``, ``contact`` (``"unilateral"``), ``seconds``; under
    creep also ``time_error_estimate``, ``spatial_error_estimate`` and
    ``zone_end_pressure_error`` (the part of q's error the located free ends make, in
    ``error_estimate``).
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
        x = pressure_positions(x, len(self._snapshots))
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
            if snap.memory is None and snap.coupling is None:
                rules.setdefault(id(snap.panels), []).append(k)
            else:
                out[inside[:, k], k] = self._pressure_one(snap, x[inside[:, k]])
        touched = inside.any(axis=1)
        xi = x[touched]
        if rules:
            m_x = np.broadcast_to(np.asarray(self._space.m(xi), dtype=float), xi.shape)
            g_x = np.broadcast_to(np.asarray(self._space.g(xi), dtype=float), xi.shape)
        for times in rules.values():
            from core.discretize import operator_rows

            snaps = [self._snapshots[k] for k in times]
            rows = operator_rows(self._space.lam, snaps[0].panels, xi,
                                 accuracy=self._kernel_accuracy)
            fq = rows @ np.column_stack([snap.q for snap in snaps])
            cut = [j for j, snap in enumerate(snaps) if snap.cut is not None
                   and snap.cut.n_panels]
            if cut:
                # every cut part of every time in one evaluation (one per time: 10x slower)
                parts = [snaps[j].cut for j in cut]
                joined = Panels.side_by_side(parts)
                cut_rows = operator_rows(self._space.lam, joined, xi,
                                         accuracy=self._kernel_accuracy)
                start = 0
                for j, part in zip(cut, parts, strict=True):
                    stop = start + part.nodes.size
                    fq[:, j] += cut_rows[:, start:stop] @ snaps[j].cut_q
                    start = stop
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
        memory_at = snap.displacement(self._space.lam)
        accuracy = FULL_ACCURACY if snap.coupling is None else self._kernel_accuracy
        # Sample m and g from inside the zone at its ends (they may jump there).
        inward = np.zeros(xi.size)
        for lo, hi in snap.zones:
            inward[xi == lo] = 1.0
            inward[xi == hi] = -1.0
        values = nystrom_pressure(self._space, snap.step, snap.panels, snap.q,
                                  snap.settlement, snap.tilt, xi, inward, memory_at,
                                  accuracy=accuracy)
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
