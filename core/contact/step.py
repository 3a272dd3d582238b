"""The unilateral problem at one time: its data and the Nystrom pressure.

At one time the unilateral problem (model notes, dimensionless) reads: find ``q >= 0`` and
the contact set ``S`` with

    c m q + s F q = delta + alpha x - g + e(x)   on S   (q > 0: the surfaces touch)
    h(x) = s F q - (delta + alpha x - g + e(x)) >= 0   off S   (q = 0: the gap is open)

and the two given ones of ``delta, alpha, P = int q, M = int x q``. ``s`` weighs the current
pressure (1 elastic; ``1 - K(t, t) dt/2`` in an implicit creep step) and ``e(x)`` is the
displacement of the creep memory (0 elastic). Both conditions are one continuous function,
the *Nystrom pressure*

    Q(x) = [delta + alpha x - g(x) + e(x) - s F q (x)] / (c m(x)),

which equals ``q`` on S and ``-h / (c m)`` off it: S is where ``Q > 0``, and at a free end
of a zone ``Q`` passes through zero (``q`` is continuous and vanishes there: ``h >= 0`` just
outside forces ``q(end) <= 0``, ``q >= 0`` just inside forces ``>= 0``).

:func:`nystrom_pressure` evaluates Q; :func:`_bordered_solve` solves the equation on the
contact nodes with the two given ones of the four scalars. The nodal active set
(:mod:`core.contact.active_set`) and the zone ends (:mod:`core.contact.zones`) are built on
them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from core.contact.systems import StepSolver, bordered_solve
from core.discretize import Panels, operator_rows
from core.kernel import FULL_ACCURACY


@dataclass(frozen=True)
class Space:
    """The scene's functions of x: ``lam`` = a/H, coating compliance ``m`` and gap ``g``
    (vectorized callables on [-1, 1]), and ``breakpoints`` where m or g may jump."""

    lam: float
    m: Callable[[np.ndarray], np.ndarray]
    g: Callable[[np.ndarray], np.ndarray]
    breakpoints: tuple[float, ...]


@dataclass(frozen=True)
class Step:
    """One time's data: relative modulus ``c``, weight ``scale`` of F on the current
    pressure, and the two given ones of settlement, tilt, force, moment (dimensionless)."""

    c: float
    scale: float
    given: dict[str, float]


class _Resultants:
    """Force and moment (dimensionless) of a nodal pressure ``q`` on ``panels``."""

    panels: Panels
    q: np.ndarray

    @property
    def force(self) -> float:
        return float(self.panels.weights @ self.q)

    @property
    def moment(self) -> float:
        return float((self.panels.weights * self.panels.nodes) @ self.q)


def _bordered_solve(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray, step: Step,
                    rhs: np.ndarray, idx: np.ndarray,
                    solver: StepSolver | None = None) -> tuple[np.ndarray, float, float]:
    """:func:`core.contact.systems.bordered_solve` for one :class:`Step`."""
    return bordered_solve(op, m, x, w, step.c, step.scale, step.given, rhs, idx, solver)


def _given_rhs(step: Step, x: np.ndarray, g: np.ndarray, memory: np.ndarray | None) -> np.ndarray:
    rhs = step.given.get("settlement", 0.0) + step.given.get("tilt", 0.0) * x - g
    return rhs if memory is None else rhs + memory


def nystrom_pressure(space: Space, step: Step, panels: Panels, q: np.ndarray, delta: float,
                     alpha: float, targets: np.ndarray, inward: np.ndarray | None = None,
                     memory_at: Callable[[np.ndarray], np.ndarray] | None = None,
                     accuracy: float = FULL_ACCURACY, rows: np.ndarray | None = None
                     ) -> np.ndarray:
    """Q at ``targets`` for the nodal pressure ``q`` on ``panels`` (see the module notes).

    ``inward`` (+-1 per target) says from which side m and g are sampled at a jump;
    ``accuracy`` is the absolute accuracy of the kernel values (default: rounding);
    ``rows``: F's rows at ``targets`` on ``panels`` if already evaluated
    (``operator_rows``; one evaluation then serves several pressures on one rule).
    """
    targets = np.asarray(targets, dtype=float)
    side = targets if inward is None else np.clip(targets + 1e-13 * inward, -1.0, 1.0)
    if rows is None:
        rows = operator_rows(space.lam, panels, targets, accuracy=accuracy)
    fq = rows @ q
    memory = 0.0 if memory_at is None else memory_at(targets)
    return (delta + alpha * targets - space.g(side) + memory - step.scale * fq) / (
        step.c * space.m(side))


class LoadNotCarried(ValueError):
    """A given load no contact can carry at a time the lift-off model steps through: the
    force ``<= 0`` or the resultant outside the punch. ``quantity`` (``"force"`` or
    ``"moment"``) and ``time`` (dimensionless t) let a scene name its field and the day;
    ``punch``: which punch of several (None for one); ``detail``: what the contact did
    (``"the contact shrinks to a point"``), where the loads alone do not say it; the
    message is in the solver's terms."""

    def __init__(self, message: str, quantity: str, time: float,
                 punch: int | None = None, detail: str = "") -> None:
        super().__init__(message)
        self.quantity, self.time, self.punch = quantity, float(time), punch
        self.detail = detail

    def of_punch(self, k: int) -> LoadNotCarried:
        """The same refusal for punch ``k`` of several (its message naming
        ``punches[k]``)."""
        return LoadNotCarried(f"punches[{k}].{self}", self.quantity, self.time, k,
                              self.detail)


def check_loads(statement_given: frozenset[str], loads: dict[str, np.ndarray],
                times: np.ndarray) -> None:
    """Refuse loads that pull the punch away (no contact can carry them):
    :class:`LoadNotCarried`."""
    if "force" in loads:
        bad = loads["force"] <= 0.0
        if bad.any():
            t = times[int(np.argmax(bad))]
            raise LoadNotCarried(f"force: must be > 0 for the punch to touch (a punch pulled "
                                 f"away has no contact), got {loads['force'][bad][0]:.6g} at "
                                 f"t = {t:g}", "force", t)
        if "moment" in loads:
            e = loads["moment"] / loads["force"]
            bad = np.abs(e) >= 1.0
            if bad.any():
                k = int(np.argmax(bad))
                raise LoadNotCarried(f"moment: the eccentricity M/P = {e[k]:.6g} at t = "
                                     f"{times[k]:g} puts the load outside the punch (|M/P| "
                                     "must be < 1 half-width): no contact can carry it",
                                     "moment", times[k])
