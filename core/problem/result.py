"""The result type of every engine: :class:`ContactSolution`, its ``info`` schema, and the
one acceptance rule :func:`accepts`.

Every engine of :mod:`core.engines` answers the full-contact problem with a
:class:`ContactSolution` whose ``info`` dict (in the spirit of SciPy's ``OdeResult``)
holds at least the keys of :data:`INFO_KEYS`:

========================== ===================================================================
key                        meaning
========================== ===================================================================
``method``                 the engine that answered: ``"nystrom"``, ``"projection"``,
                           ``"collocation"``, ``"layered"``
``success``                whether the answer meets ``tol``: :func:`accepts` of
                           ``error_estimate`` with the engine's margin, and the engine's own
                           conditions (input resolved, time stepping finished)
``message``                one line saying how the solve went (why ``tol`` was missed)
``flags``                  validity flags: ``tol_not_met``, ``contact_lost`` (q < 0
                           somewhere), ``unresolved_input`` (m or g finer than the grid)
``error_estimate``         estimated relative error of delta, alpha (relative to
                           ``max(|delta|, |alpha|)``), P, M (to ``max(|P|, |M|)``) and q (to
                           ``max|q|``): the parts below added (a part the engine does not
                           estimate is NaN and left out)
``spatial_error_estimate`` its part from the discretization in x
``time_error_estimate``    its part from the time stepping (0 on an elastic base)
``kernel_fit_error``       its part from the creep kernel's sum-of-exponentials fit (the
                           Nystrom engine counts it in the time part)
``seconds``                wall time of the solve [s]
``n_modes``                unknowns in x: basis functions, or nodes for a nodal engine
``n_nodes``                quadrature or collocation nodes in x
``n_steps``                time steps (0 or the number of times on an elastic base)
``statement``              1-4, which two of delta, alpha, P, M were given
                           (:data:`core.problem.STATEMENTS`)
``given``                  the names of those two, sorted
``min_pressure``           least q over the engine's check points and times (< 0: lift-off)
``max_pressure``           largest |q| there (the scale of ``contact_lost``)
``basis``                  how q is represented in x (``"nystrom"``, the projection's basis
                           kind, ``"collocation"``, ``"chebyshev"``)
``element_ends``           points of (-1, 1) where q may kink or jump (panel or element
                           ends, breakpoints)
``stages``                 ``{stage: {"seconds": s, "cached": bool}}``: what the solve built
                           and what it found cached
========================== ===================================================================

:func:`core.solver.solve_dimensionless` adds ``contact`` (``"full"``; the unilateral model's
answer, :class:`core.contact.result.UnilateralSolution`, has an ``info`` of its own), when
the default engine declined and the next one answered, ``fallback`` (why), and, under creep,
``time_breaks_found``: the times where a history given as a callable jumps and that
``time_breaks`` did not hold (:func:`core.time.undeclared_jumps`; the steps landed on them).

Engine-specific keys: nystrom ``n_panels``, ``prepare_seconds`` (the geometry's
preparation, done once), ``max_abs_tilt`` (largest |alpha| between the output times too),
``builds`` (how often each cached member was built); projection ``orthonormality_error``;
collocation ``richardson``, ``nodes`` and ``nodal_pressure`` (arrays: the collocation
solution itself); layered (a scene-level engine, :mod:`core.engines.layered`)
``max_abs_tilt``, ``coating_model``, ``layered_model_error``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core import limits
from core.discretize import Basis
from core.validation import show_value

#: The ``info`` keys every engine's answer carries (see the module notes).
INFO_KEYS = ("method", "success", "message", "flags", "error_estimate",
             "spatial_error_estimate", "time_error_estimate", "kernel_fit_error", "seconds",
             "n_modes", "n_nodes", "n_steps", "statement", "given", "min_pressure",
             "max_pressure", "basis", "element_ends", "stages")


#: What a message says where the flag ``unresolved_input`` is raised (m or g has a feature
#: the engine's discretization does not resolve), the same for every engine and for a
#: lift-off answer the full-contact model sent on.
UNRESOLVED_ADVICE = ("m or g has a feature the panels do not resolve: give the x of a jump "
                     "or kink in breakpoints (a roughness finer than the panels stays "
                     "unresolved: a looser tol, or a smoother profile)")


def accepts(error_estimate: float, tol: float, margin: float = 1.0) -> bool:
    """The one acceptance rule of every engine: ``margin * error_estimate <= tol``.

    ``error_estimate`` and ``tol`` are relative errors (``info["error_estimate"]`` and the
    requested ``tol``); ``margin`` >= 1 is the engine's ``success_margin``: how far its
    estimate may read low (1 for an estimate that bounds the error, 3 for the projection's
    extrapolated level differences, which read up to ~3x low). A NaN estimate (none
    made) is never accepted.
    """
    return bool(error_estimate * margin <= tol)


class SolveOutcome:
    """How a solve went, read from its ``info`` dict: shared by the result types of both
    contact models (:class:`ContactSolution`, :class:`core.contact.result.UnilateralSolution`)."""

    info: dict[str, Any]

    @property
    def success(self) -> bool:
        """Whether the error estimates meet the requested tolerance."""
        return bool(self.info["success"])

    @property
    def message(self) -> str:
        """A one-line account of how the solve went."""
        return str(self.info["message"])

    @property
    def flags(self) -> list[str]:
        """Validity flags: ``tol_not_met``, and per contact model ``contact_lost``,
        ``unresolved_input`` (full) or ``contact_set_unverified`` (unilateral)."""
        return list(self.info["flags"])

    def __repr__(self) -> str:
        """One line: the engine, the output times, the last values of delta, alpha, P, M
        (dimensionless), the error estimate and the flags (the arrays would fill pages)."""
        times = getattr(self, "times", ())
        engine = self.info.get("method") or f"{self.info.get('contact', '')} contact"
        last = ", ".join(f"{name} {float(getattr(self, name)[-1]):.6g}"
                         for name in ("settlement", "tilt", "force", "moment")) \
            if len(times) else "no times"
        t_end = f" to t = {float(times[-1]):.6g}" if len(times) else ""
        return (f"<{type(self).__name__} {engine}, dimensionless: {len(times)} times{t_end}; "
                f"{last}; "
                f"error estimate {float(self.info.get('error_estimate', float('nan'))):.2g}"
                f"; flags: {', '.join(self.flags) or 'none'}>")


def positions(x: Any, times: int, unit: str = "") -> np.ndarray:
    """``x`` as positions where a pressure is asked at ``times`` output times: a number or
    a 1-D list of finite numbers, at most :data:`core.limits.MAX_PRESSURE_VALUES` values in
    all (5e6 points at one time took 94 s). ValueError naming ``x`` (and ``unit``, "m" for
    a scene's) otherwise: a text, a 2-D array or NaN gave NumPy's own messages."""
    written = f" [{unit}]" if unit else ""
    try:
        xs = np.atleast_1d(np.asarray(x, dtype=float))
    except (TypeError, ValueError):
        raise ValueError(f"x: positions must be numbers{written}, got {show_value(x)}"
                         ) from None
    if xs.ndim != 1:
        raise ValueError(f"x: a number or a list of positions{written} (one dimension), got "
                         f"an array of shape {xs.shape}; pass x.ravel() and reshape the rows")
    if xs.size * max(times, 1) > limits.MAX_PRESSURE_VALUES:
        raise ValueError(f"x: {xs.size} points at {times} times are more than the "
                         f"{limits.MAX_PRESSURE_VALUES} pressure values one call may "
                         "compute; ask for fewer points (or in several calls)")
    if not np.all(np.isfinite(xs)):
        raise ValueError(f"x: positions must be finite numbers{written}")
    return xs


def pressure_positions(x: Any, times: int) -> np.ndarray:
    """:func:`positions` of the dimensionless answers, on [-1, 1]."""
    xs = positions(x, times)
    if np.any(np.abs(xs) > 1.0):
        raise ValueError("x: pressure is defined on [-1, 1] only")
    return xs


# repr=False: the short repr of SolveOutcome, not every array and the whole info
@dataclass(frozen=True, repr=False)
class ContactSolution(SolveOutcome):
    """The answer of every engine, full contact (all quantities dimensionless).

    ``times`` (T,), ``settlement`` (delta), ``tilt`` (alpha), ``force`` (P), ``moment`` (M)
    as arrays over ``times``; ``pressure(x)`` gives q at points of [-1, 1] (shape
    ``(len(x), T)``); ``info`` holds the keys of :data:`INFO_KEYS` (the module notes
    give their meaning) and the engine's own. ``contact_set`` holds, per time, the
    intervals of x where q > 0: ``[(-1.0, 1.0)]`` (full contact is assumed).

    A projection answer evaluates q from its basis and coefficients; a nodal engine
    (Nystrom, collocation, layered) passes ``_evaluate`` instead.
    """

    times: np.ndarray
    settlement: np.ndarray
    tilt: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    info: dict[str, Any]
    _basis: Basis = field(repr=False)
    _coefficients: np.ndarray = field(repr=False)  # a_j(t), shape (n, T)
    _c: np.ndarray = field(repr=False)  # c(t) at the times
    _m: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    _g: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    #: q(x) at points x, shape (len(x), T), for engines without a basis (Nystrom).
    _evaluate: Callable[[np.ndarray], np.ndarray] | None = field(default=None, repr=False)
    contact_set: list[list[tuple[float, float]]] = field(default_factory=list)

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """Contact pressure q(x, t) at points ``x`` of [-1, 1], shape ``(len(x), len(times))``.

        ``q = (-g(x)/c(t) + sum_j a_j(t) p_j(x)) / m(x)`` (dimensionless, the seed's (18)).
        """
        x = pressure_positions(x, len(self.times))
        if self._evaluate is not None:
            return self._evaluate(x)
        phi = self._basis.evaluate(x, self._coefficients.shape[0])
        mq = phi @ self._coefficients - np.outer(self._g(x), 1.0 / self._c)
        return mq / self._m(x)[:, None]
