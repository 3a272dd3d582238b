"""Validated inputs of the dimensionless problem, split by what they describe.

The geometry (``lam``, ``m``, ``g``, breakpoints, ``tol``) is what an engine prepares once;
the time side (output times, ``c``, the creep kernel, the two given loads) is what a solve
takes. Each check raises ``ValueError`` whose message starts with the argument's name.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core import limits
from core.creep import integrated_kernel
from core.problem.statements import statement_number
from core.validation import MAX_MAGNITUDE

Scalar = float | Callable[[np.ndarray], np.ndarray]
Function = Callable[[np.ndarray], np.ndarray]

#: Accepted relative tolerances.
TOLERANCE_RANGE = (1e-13, 1e-1)
#: Accepted magnitudes of the coefficient functions (m, g: dimensionless; c: relative
#: modulus; the given loads: at most 1e100). Beyond them the operators over- or
#: underflow in double precision (m = 1e200 made the Galerkin matrix singular, m = 1e-300
#: gave NaN); physical scenes are far inside.
VALUE_RANGE = {"m": (1 / MAX_MAGNITUDE, MAX_MAGNITUDE), "g": (0.0, MAX_MAGNITUDE),
               "c": (1 / MAX_MAGNITUDE, MAX_MAGNITUDE)}
#: Accepted a/H (the limits and their measured cost: core/limits.py).
LAM_RANGE = (limits.MIN_LAM, limits.MAX_SOLVER_LAM)


def as_function(value: Scalar, name: str) -> Function:
    """A vectorized callable for a float or callable argument."""
    if callable(value):
        def fn(x: np.ndarray, _f=value) -> np.ndarray:
            with np.errstate(all="ignore"):
                out = np.asarray(_f(np.asarray(x, dtype=float)), dtype=float)
            return np.broadcast_to(out, np.shape(x)).astype(float)
        return fn
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise ValueError(f"{name}: must be a number or a vectorized callable, "
                         f"got {type(value).__name__}")
    v = float(value)
    if not math.isfinite(v):  # a number: math's test is ~20x cheaper than numpy's
        raise ValueError(f"{name}: must be finite, got {v}")
    return lambda x, _v=v: np.full(np.shape(x), _v)


def check_values(values: np.ndarray, name: str, where: np.ndarray, var: str, *,
                 positive: bool = False) -> None:
    """Refuse non-finite values, and non-positive ones if ``positive``, naming the point."""
    lo, hi = VALUE_RANGE.get(name, (0.0, MAX_MAGNITUDE))
    # Accepted values pass one vectorized test (NaN fails every comparison); only a
    # refusal looks for the reason below. A load change validates its histories here.
    magnitude = np.abs(values)
    if positive:
        good = (values > 0.0) & (magnitude >= lo) & (magnitude <= hi)
    else:
        good = magnitude <= hi
    if good.all():
        return
    bad = ~np.isfinite(values)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{name}: must be finite, is {values[i]} at {var} = {where[i]:.6g}")
    if positive and np.any(values <= 0):
        i = int(np.argmin(values))
        raise ValueError(f"{name}: must be > 0, is {values[i]:.6g} at {var} = {where[i]:.6g}")
    if not positive:
        lo = 0.0
    out = (magnitude > hi) | (magnitude < lo)
    if out.any():
        i = int(np.argmax(out))
        raise ValueError(f"{name}: must lie in [{lo:g}, {hi:g}] in magnitude, is "
                         f"{values[i]:.6g} at {var} = {where[i]:.6g}")


@dataclass(frozen=True)
class Geometry:
    """``lam = a/H``, coating compliance ``m(x)``, gap ``g(x)``, jumps, target ``tol``."""

    lam: float
    m: Function
    g: Function
    g_is_zero: bool
    breakpoints: tuple[float, ...]
    tol: float


@dataclass(frozen=True)
class TimeInputs:
    """Output times, relative modulus ``c(t)``, creep kernel and the two given loads."""

    times: np.ndarray
    c: Function
    c_is_constant: bool
    kernel: Any
    loads: dict[str, Function]
    given: frozenset[str]


def validate_geometry(lam: Any, m: Scalar, g: Scalar, breakpoints: Sequence[float],
                      tol: Any) -> Geometry:
    """Check the geometric inputs (dimensionless) and return them as callables."""
    if isinstance(lam, bool) or not isinstance(lam, (int, float, np.floating, np.integer)):
        raise ValueError(f"lam: must be a number, got {type(lam).__name__}")
    lam = float(lam)
    if not np.isfinite(lam) or lam <= 0:
        raise ValueError(f"lam: must be a finite number > 0, got {lam}")
    if not LAM_RANGE[0] <= lam <= LAM_RANGE[1]:
        raise ValueError(f"lam: must be in [{LAM_RANGE[0]:g}, {LAM_RANGE[1]:g}] (a/H), "
                         f"got {lam:g}")
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating)):
        raise ValueError(f"tol: must be a number, got {type(tol).__name__}")
    tol = float(tol)
    if not (TOLERANCE_RANGE[0] <= tol <= TOLERANCE_RANGE[1]):
        raise ValueError(f"tol: must be in [{TOLERANCE_RANGE[0]:g}, {TOLERANCE_RANGE[1]:g}], "
                         f"got {tol:g}")
    try:
        bps = tuple(sorted(float(b) for b in breakpoints))
    except (TypeError, ValueError) as exc:
        raise ValueError("breakpoints: must be a sequence of numbers in (-1, 1)") from exc
    for b in bps:
        if not np.isfinite(b) or not (-1.0 < b < 1.0):
            raise ValueError(f"breakpoints: each must lie in (-1, 1), got {b}")
    bps = tuple(b for i, b in enumerate(bps) if i == 0 or b - bps[i - 1] > 1e-12)
    m_fn = as_function(m, "m")
    g_fn = as_function(g, "g")
    probe = np.linspace(-1.0, 1.0, 257)
    for bp in bps:
        probe = np.concatenate([probe, [bp - 1e-9, bp + 1e-9]])
    check_values(m_fn(probe), "m", probe, "x", positive=True)
    check_values(g_fn(probe), "g", probe, "x")
    return Geometry(lam, m_fn, g_fn, not callable(g) and float(g) == 0.0, bps, tol)


def validate_times(times: Any) -> np.ndarray:
    """Output times as a float array: increasing, finite, the first >= 1 (numbers, not
    text: NumPy would read the string "1.0" as the time 1)."""
    try:
        text = np.asarray(times).dtype.kind in "SU"
    except (TypeError, ValueError):
        text = False  # ragged: refused below
    if text:
        raise ValueError(f"times: must be an array of numbers, got text: {times!r:.60}")
    try:
        t = np.asarray(times, dtype=float).ravel()
    except (TypeError, ValueError) as exc:
        raise ValueError("times: must be an array of numbers") from exc
    if t.size == 0:
        raise ValueError("times: at least one time is needed")
    if t.size > limits.MAX_SOLVER_TIMES:
        raise ValueError(f"times: at most {limits.MAX_SOLVER_TIMES} output times, "
                         f"got {t.size}")
    if not np.all(np.isfinite(t)):
        raise ValueError("times: must be finite")
    if t[0] < 1.0:
        raise ValueError(f"times: must be >= 1 (t = 1 is the moment of loading), got {t[0]:g}")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        raise ValueError("times: must be strictly increasing")
    return t


HELD_CHECKS = 16
"""Output times [-] at which a plain callable's held compliance is checked to be positive
on every solve (~0.8 ms with 16, ~16 ms with all 200 of a page's times, on a code law's
kernel); a kernel with a ``key`` (built from a validated creep law) is not checked here,
and the default engine checks every time (:func:`check_held_compliance`, cached by key)."""


def check_held_compliance(kernel: Callable, times: np.ndarray, held: np.ndarray | None = None,
                          sample: int = 0) -> None:
    """Refuse a creep kernel under which a stress held since loading has no positive
    compliance.

    Parameters
    ----------
    kernel : callable
        The creep kernel ``K(t, tau)`` [-] of the Volterra operator (dimensionless times).
    times : ndarray
        Output times ``t >= 1`` [-].
    held : ndarray, optional
        ``1 - int_1^t K(t, u) du`` at ``times`` if already computed.
    sample : int, optional
        Check only this many of the times, spread over them, the last among them (0: all).

    Raises
    ------
    ValueError
        Naming ``kernel``, where ``1 - int_1^t K(t, u) du`` (the held stress's compliance
        over the elastic one) is not finite and > 0: a kernel that takes it through zero
        describes no material (a kernel of 1e99 failed deep in the default engine as
        "cannot convert float NaN to integer").
    """
    t = np.asarray(times, dtype=float)
    if held is None:
        if 0 < sample < t.size:
            t = t[np.unique(np.linspace(0, t.size - 1, sample).astype(int))]
        held = 1.0 + integrated_kernel(kernel, t, np.ones_like(t))
    held = np.asarray(held, dtype=float)
    bad = np.flatnonzero(~(np.isfinite(held) & (held > 0.0)))
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            "kernel: the compliance of a stress held since loading relative to the elastic "
            f"one, 1 - int_1^t K(t, u) du, must be finite and > 0; it is {held[i]:.3g} at "
            f"t = {t[i]:.6g}")


def validate_time_inputs(times: Any, c: Scalar, kernel: Any,
                         loads: dict[str, Scalar | None]) -> TimeInputs:
    """Check the time side of a solve (dimensionless) and return it as callables."""
    t = validate_times(times)
    c_fn = as_function(c, "c")
    check_values(c_fn(t), "c", t, "t", positive=True)
    given = frozenset(k for k, v in loads.items() if v is not None)
    statement_number(given)
    load_fns = {}
    for name in sorted(given):
        fn = as_function(loads[name], name)
        check_values(fn(t), name, t, "t")
        load_fns[name] = fn
    if kernel is not None:
        if not callable(kernel):
            raise ValueError("kernel: must be None or a vectorized callable K(t, tau)")
        span = float(t[-1]) - 1.0
        if 0.0 < span < limits.MIN_CREEP_SPAN:
            raise ValueError(
                f"times: on a creeping base the last output time must be at loading (t = 1) "
                f"or at least {limits.MIN_CREEP_SPAN:g} after it, got t = {t[-1]:.12g}")
        tt = np.array([t[-1], t[-1], 0.5 * (1 + t[-1])])
        kv = np.asarray(kernel(tt, np.array([1.0, t[-1], 1.0])), dtype=float)
        if kv.shape != (3,) or not np.all(np.isfinite(kv)):
            raise ValueError("kernel: K(t, tau) must return finite values of the shape of "
                             "its (broadcast) arguments")
        if getattr(kernel, "key", None) is None:
            check_held_compliance(kernel, t, sample=HELD_CHECKS)
    return TimeInputs(t, c_fn, not callable(c), kernel, load_fns, given)
