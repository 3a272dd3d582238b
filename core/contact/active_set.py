"""The nodal active set of the unilateral problem at one time, and zone ends from it.

A primal-dual active set on the nodes of a fixed Gauss-Legendre panel rule: each sweep
makes the contact nodes those with ``Q > 0`` (Q the Nystrom pressure of
:mod:`core.contact.step`); it stops when the set repeats. It gives the topology of the
contact set and its ends to within a node (:func:`zones_from_nodes`: the root of the
panel's interpolant of Q between the last contact node and the next), which
:mod:`core.contact.zones` then locates exactly.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass

import numpy as np

from core.contact.step import LoadNotCarried, Step, _bordered_solve, _given_rhs, _Resultants
from core.contact.systems import StepSolver
from core.discretize import BARYCENTRIC_WEIGHTS, GAUSS_NODES, NODES_PER_PANEL, Panels

#: Sweeps of the nodal active set before it is declared cycling.
MAX_SWEEPS = 60



@dataclass
class NodalState(_Resultants):
    """A solution on the nodes of ``panels``: pressure ``q`` (0 off contact), the four
    scalars, the contact nodes ``active`` and the Nystrom pressure ``nystrom`` (Q)."""

    panels: Panels
    q: np.ndarray
    settlement: float
    tilt: float
    active: np.ndarray
    nystrom: np.ndarray


#: The reason of :class:`NoContact` where fewer than three nodes stay in contact.
SHRINKS = "the contact shrinks to a point"


class NoContact(ValueError):
    """The loads leave no contact (the punch is pulled away): ``reason``, what the contact
    did; ``punch``: which punch of several (None for one; the message then names it)."""

    def __init__(self, reason: str, punch: int | None = None) -> None:
        super().__init__(reason if punch is None else f"punches[{punch}]: {reason}")
        self.reason, self.punch = reason, punch

    @property
    def what(self) -> str:
        """What the refusal says happened: the loads pull the punch away, or (where fewer
        than three nodes stay in contact, :data:`SHRINKS`) the zone is narrower than the
        rule resolves; a crown pressed by a small force read "the loads pull the punch
        away"."""
        if self.reason == SHRINKS:
            return "the contact zone is narrower than the solver's rule resolves"
        return "the loads pull the punch away"

    def at(self, time: float, given: Collection[str], message: str) -> LoadNotCarried:
        """This refusal at the solver's time ``time`` as :class:`LoadNotCarried` (its
        ``message`` in the solver's terms), naming :func:`refused_load` of ``given``."""
        return LoadNotCarried(message, refused_load(given), time, self.punch, self.reason)

    def of_punches(self, time: float, givens: Sequence[Collection[str]],
                   message: str) -> ValueError:
        """This refusal among several punches (``givens``: each punch's given quantities):
        :meth:`at` for the punch it names, else (no punch in contact) ``message`` alone."""
        if self.punch is None:
            return ValueError(message)
        return self.at(time, givens[self.punch], message)


def refused_load(given: Collection[str]) -> str:
    """The given load a refusal for no contact names: the force, else the moment, else
    the settlement (``given``: the punch's given quantities)."""
    return next((q for q in ("force", "moment") if q in given), "settlement")


def nodal_active_set(panels: Panels, op: np.ndarray, m: np.ndarray, g: np.ndarray, step: Step,
                     memory: np.ndarray | None = None, start: np.ndarray | None = None,
                     solver: StepSolver | None = None) -> tuple[NodalState, int, bool]:
    """Primal-dual active set on the nodes of ``panels``.

    ``op`` is the Nystrom matrix of F there, ``m``, ``g`` and ``memory`` (e(x)) the node
    values; ``start`` the first guess of the contact nodes (default: all). Returns the
    state, the number of sweeps and whether the set settled (it may cycle between two
    sets on a degenerate node; the last one is kept). Raises :class:`NoContact` when
    no node stays in contact under a given force or moment. With a ``solver`` made for a
    :class:`~core.contact.systems.Mirror` (an even problem) the sets and the pressure
    are exactly even.
    """
    x, w = panels.nodes, panels.weights
    mirror = None if solver is None else solver.mirror
    rhs = _given_rhs(step, x, g, memory)
    active = np.ones(x.size, dtype=bool) if start is None else start.copy()
    if mirror is not None:
        active &= active[::-1]  # a symmetric start (the rounding of its zones' ends aside)
    seen: set[bytes] = set()
    settled = False
    sweeps = 0
    q = np.zeros(x.size)
    delta = step.given.get("settlement", 0.0)
    alpha = step.given.get("tilt", 0.0)
    for _ in range(MAX_SWEEPS):
        sweeps += 1
        idx = np.nonzero(active)[0]
        q = np.zeros(x.size)
        if idx.size == 0:
            if {"force", "moment"} & set(step.given) and any(
                    step.given.get(k, 0.0) != 0.0 for k in ("force", "moment")):
                raise NoContact("no node stays in contact")
        elif idx.size < 3 and not {"settlement", "tilt"} <= set(step.given):
            raise NoContact(SHRINKS)
        else:
            q[idx], delta, alpha = _bordered_solve(op, m, x, w, step, rhs, idx, solver)
        if mirror is None:
            nystrom = (delta + alpha * x - g + (0.0 if memory is None else memory)
                       - step.scale * (op @ q)) / (step.c * m)
        else:
            # on the half x > 0 and mirrored: the contact set stays exactly symmetric
            h = mirror.half
            nystrom = mirror.unfold((delta - g[h:] + (0.0 if memory is None else memory[h:])
                                     - step.scale * mirror.apply(q)) / (step.c * m[h:]))
        # Keep the contact nodes the equation solved exactly (rounding must not flip them).
        nystrom[idx] = q[idx]
        new = nystrom > 0.0
        key = new.tobytes()
        if np.array_equal(new, active):
            settled = True
            break
        if key in seen:
            break
        seen.add(active.tobytes())
        active = new
    return NodalState(panels, q, delta, alpha, active, nystrom), sweeps, settled


def _crossing(panels: Panels, values: np.ndarray, i: int) -> float:
    """Where the nodal function ``values`` changes sign between nodes i and i + 1."""
    x = panels.nodes
    p, p1 = i // NODES_PER_PANEL, (i + 1) // NODES_PER_PANEL
    fa, fb = float(values[i]), float(values[i + 1])
    linear = float(x[i] - fa * (x[i + 1] - x[i]) / (fb - fa)) if fb != fa else float(x[i])
    if p != p1:
        return linear
    c, h = panels.centers[p], panels.half_widths[p]
    local = values[p * NODES_PER_PANEL:(p + 1) * NODES_PER_PANEL]

    def f(xx: float) -> float:
        # barycentric form of the panel's interpolant: O(16), stable (Gauss nodes)
        d = (xx - c) / h - GAUSS_NODES
        hit = np.nonzero(d == 0.0)[0]
        if hit.size:
            return float(local[hit[0]])
        ratio = BARYCENTRIC_WEIGHTS / d
        return float(ratio @ local / ratio.sum())

    # the interpolant takes the nodal values at the nodes
    if fa == 0.0:
        return float(x[i])
    if fa * fb > 0.0:
        return linear
    return _root_between(f, float(x[i]), float(x[i + 1]), fa, fb)


#: Step of the zone-end root below which the secant has converged (half-widths).
_ROOT_XTOL = 1e-14


def _root_between(f: Callable[[float], float], a: float, b: float, fa: float, fb: float
                  ) -> float:
    """The root of ``f`` in ``[a, b]`` (``fa``, ``fb`` of opposite signs): secant steps
    from the ends, kept inside the bracket (a bisection where one leaves it), until the
    next step would be below ``_ROOT_XTOL``. Between two nodes the interpolant is smooth
    and its root simple: 3-4 evaluations on the lift-off preset, where brentq (closing its
    bracket to the same tolerance) took ~6 and its wrapper's checks."""
    x0, f0, x1, f1 = a, fa, b, fb
    for _ in range(100):
        x = x1 - f1 * (x1 - x0) / (f1 - f0) if f1 != f0 else 0.5 * (a + b)
        if not a < x < b:
            x = 0.5 * (a + b)
        fx = f(x)
        if fx == 0.0:
            return x
        if (fx > 0.0) == (fa > 0.0):
            a, fa = x, fx
        else:
            b, fb = x, fx
        # converged when the next secant step would be below the tolerance
        if b - a <= _ROOT_XTOL or (fx != f1 and abs(fx * (x - x1) / (fx - f1)) <= _ROOT_XTOL):
            return x
        x0, f0, x1, f1 = x1, f1, x, fx
    return 0.5 * (a + b)


def contact_runs(active: np.ndarray) -> int:
    """The runs of contact nodes in the boolean ``active`` (the zones a march follows,
    before their ends are found: what makes a march costly when they are many)."""
    return int(active[0]) + int(np.count_nonzero(active[1:] & ~active[:-1])) \
        if active.size else 0


def zones_from_nodes(state: NodalState, breakpoints: Sequence[float] = ()
                     ) -> tuple[list[float], list[bool], list[float]]:
    """Zone ends from the nodal contact set: (ends, pinned flags, slopes of Q at the ends).

    ``ends`` is sorted, two per zone; an end at a node next to x = -1 or 1 is pinned there,
    and one whose sign change of Q straddles a breakpoint is pinned at the breakpoint (a
    step of the punch: the zone ends at its corner, where Q jumps and has no root).
    """
    cuts = [float(b) for b in sorted(breakpoints)]
    active = state.active
    x = state.panels.nodes
    n = x.size
    ends: list[float] = []
    pinned: list[bool] = []
    slopes: list[float] = []
    # the runs of contact nodes, found at once (a loop over the nodes cost ~0.1 ms per
    # call, paid at every output time of a creep march)
    flips = np.flatnonzero(np.diff(np.concatenate([[0], active.astype(np.int8), [0]])))
    for i, j in zip(flips[0::2], flips[1::2] - 1, strict=True):
        i, j = int(i), int(j)
        for k, side in ((i, -1), (j, 1)):
            if (k == 0 and side < 0) or (k == n - 1 and side > 0):
                ends.append(float(side))
                pinned.append(True)
                slopes.append(0.0)
                continue
            lo = k - 1 if side < 0 else k
            x_lo, x_hi = float(x[lo]), float(x[lo + 1])
            inside = [cut for cut in cuts if x_lo < cut < x_hi]
            if inside:
                ends.append(inside[0])
                pinned.append(True)
                slopes.append(0.0)
                continue
            end = _crossing(state.panels, state.nystrom, lo)
            ends.append(end)
            pinned.append(False)
            slopes.append(float(state.nystrom[lo + 1] - state.nystrom[lo]) / (x_hi - x_lo))
    return ends, pinned, slopes
