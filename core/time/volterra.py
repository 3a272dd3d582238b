"""The modal Volterra problem and its solution, shared by the time steppers.

``d w - V w = r + coupling @ V u`` for the modes ``w`` and the known functions ``u`` (see
:mod:`core.time.integration`), with the sides of the jumps of a history and the sizes the
steppers measure their errors against.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from core.time.radau import JUMP_SIDE

TimeFunction = Callable[[np.ndarray], np.ndarray]


def _before(t: float) -> float:
    return t - JUMP_SIDE * max(1.0, abs(t))


def _after(t: float) -> float:
    return t + JUMP_SIDE * max(1.0, abs(t))


def _jumps(breaks, start: float, end: float) -> np.ndarray:
    """Sorted distinct ``breaks`` strictly inside ``(start, end)`` (beyond rounding)."""
    try:
        b = np.asarray(list(breaks), dtype=float).ravel()
    except (TypeError, ValueError):
        raise ValueError("breaks: must be a sequence of times") from None
    if not np.all(np.isfinite(b)):
        raise ValueError("breaks: must be finite times")
    b = np.unique(b)
    margin = 4 * JUMP_SIDE
    return b[(b > start + margin * max(1.0, abs(start)))
             & (b < end - margin * max(1.0, abs(end)))]


@dataclass(frozen=True)
class ModalProblem:
    """``d w - V w = r + coupling @ V u`` for ``modes`` unknowns and ``known`` functions u.

    ``d(t)``, ``r(t)`` return arrays (modes, len(t)); ``u(t)`` (known, len(t));
    ``coupling`` is (modes, known). All dimensionless. ``parts``: the modes and the known
    functions are that many equal consecutive groups, independent problems stepped
    together (the same steps for all); their sizes and errors are measured per group.
    """

    d: TimeFunction
    r: TimeFunction
    u: TimeFunction
    coupling: np.ndarray
    parts: int = 1

    @property
    def n_modes(self) -> int:
        return self.coupling.shape[0]

    @property
    def n_known(self) -> int:
        return self.coupling.shape[1]


@dataclass(frozen=True)
class VolterraSolution:
    """Solution at the output times.

    ``w`` and ``vw`` (= ``V w``) have shape (modes, times); ``vu`` (known, times).
    ``error_estimate`` estimates the global error of ``w`` relative to ``max|w|`` (and of
    ``vu`` relative to ``max|u|``); ``steps`` counts accepted steps. ``part_errors``: the
    estimate of each group of :attr:`ModalProblem.parts`, relative to its own size
    (``error_estimate`` is their largest).
    """

    w: np.ndarray
    vw: np.ndarray
    vu: np.ndarray
    error_estimate: float
    steps: int
    rejected: int
    success: bool
    message: str
    part_errors: tuple[float, ...] = ()


def _scales(problem: ModalProblem, t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """Sizes of the unknowns and known functions, for a relative error norm."""
    probe = np.linspace(1.0, t_end, 17)
    w_scale = np.ones(problem.n_modes)
    if problem.n_modes:
        d = problem.d(probe)
        forcing = problem.r(probe)
        if problem.n_known:
            u = problem.u(probe)
            forcing = np.abs(forcing) + np.abs(problem.coupling) @ np.abs(u)
        # one size per group of modes (per problem stepped together)
        size = np.max(np.abs(forcing / d).reshape(problem.parts, -1), axis=1)
        w_scale = np.repeat(np.where(size > 0, size, 1.0), problem.n_modes // problem.parts)
    u_scale = np.ones(problem.n_known)
    if problem.n_known:
        u_scale = np.maximum(np.max(np.abs(problem.u(probe)), axis=1), 1e-300)
    return w_scale, u_scale
