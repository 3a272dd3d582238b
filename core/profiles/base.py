"""What every profile is made of: the :class:`Profile` value, the checks of single spec
entries, and the evaluation helpers of the families that need more than a line (sine
crests, formula switches, tables).

The families themselves (their fields, how each is built, its offset, the screen's
forms) are the registry of :mod:`core.profiles.build`.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from core import limits
from core.immutable import Immutable
from core.profiles.expressions import Expression
from core.profiles.whitelist import ALIASES, CONSTANTS, FUNCTIONS

#: Most rows of a table (and most breaks of a step profile).
MAX_TABLE_ROWS = limits.MAX_TABLE_ROWS
#: Most coefficients of a polynomial (degree 15).
MAX_POLYNOMIAL_COEFFICIENTS = limits.MAX_POLYNOMIAL_COEFFICIENTS
#: Largest CSV table accepted for a profile [bytes] (1 MB).
MAX_TABLE_BYTES = limits.MAX_TABLE_BYTES
#: Samples of the uniform part of :func:`check_range`'s grid.
RANGE_SAMPLES = 4097
#: Samples used to locate the switching points of a formula (see ``Profile.breakpoints``).
FORMULA_BREAK_SAMPLES = 2049

INTERPOLATIONS: tuple[str, ...] = ("linear", "step", "pchip")

Spec = float | dict[str, Any]


# ----------------------------------------------------------------------------- validation


#: :meth:`Profile.jump_points`: a jump changes the value by more than this share of the
#: profile's largest magnitude across a point, read this share of the domain's size either
#: side of it.
JUMP_SHARE = 1e-6
JUMP_PROBE = 1e-9


def _json_type(value: Any) -> str:
    """The JSON name of a value's type, for messages read by scene-file authors."""
    if value is None:
        return "null"
    if isinstance(value, (bool, np.bool_)):
        return "a boolean"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, Mapping):
        return "an object"
    if isinstance(value, (list, tuple)):
        return "a list"
    if isinstance(value, (int, float, np.integer, np.floating)):
        return "a number"
    return f"a {type(value).__name__}"


def _fmt(value: float) -> str:
    return f"{value:.6g}"


def _number(value: Any, field: str) -> float:
    """``value`` as a finite float (``-0.0`` made ``0.0``), or a ValueError naming field."""
    # true/false in a scene file is a mistake, although Python counts bool as an int
    if isinstance(value, (bool, np.bool_)) or not isinstance(
            value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{field}: must be a number, not {_json_type(value)}")
    try:
        x = float(value)
    except OverflowError:
        raise ValueError(f"{field}: must be a finite number, is too large") from None
    if not math.isfinite(x):
        raise ValueError(f"{field}: must be a finite number, is {x}")
    return x + 0.0  # -0.0 + 0.0 == +0.0, so equal profiles have equal specs


def _positive(value: Any, field: str) -> float:
    x = _number(value, field)
    if x <= 0:
        raise ValueError(f"{field}: must be > 0, is {_fmt(x)}")
    return x


def _list(value: Any, field: str, *, least: int, most: int, what: str = "entries") -> list:
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if not isinstance(value, (list, tuple)):
        raise ValueError(f"{field}: must be a list, not {_json_type(value)}")
    if len(value) < least:
        if least == 1:
            raise ValueError(f"{field}: must not be empty")
        raise ValueError(f"{field}: must have at least {least} {what}, has {len(value)}")
    if len(value) > most:
        raise ValueError(f"{field}: must have at most {most} {what}, has {len(value)}")
    return list(value)


def _numbers(value: Any, field: str, *, least: int, most: int, what: str = "entries"
             ) -> list[float]:
    items = _list(value, field, least=least, most=most, what=what)
    return [_number(item, f"{field}[{i}]") for i, item in enumerate(items)]


def _check_domain(domain: Any, field: str) -> tuple[float, float]:
    if not isinstance(domain, (list, tuple)) or len(domain) != 2:
        raise ValueError(f"{field}: domain must be a pair (lo, hi), got {domain!r}")
    lo = _number(domain[0], f"{field}: domain start")
    hi = _number(domain[1], f"{field}: domain end")
    if not lo < hi:
        raise ValueError(f"{field}: domain must have start < end, got ({lo!r}, {hi!r})")
    return lo, hi


def _check_variable(variable: Any, field: str) -> str:
    if (not isinstance(variable, str) or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", variable)
            or variable in CONSTANTS or variable in FUNCTIONS or variable in ALIASES):
        raise ValueError(f"{field}: the variable name {str(variable)[:40]!r} is not allowed "
                         "(a letter then letters, digits or _, and not a function or "
                         "constant of formulas)")
    return variable


def _strictly_increasing(values: list[float], field: str, variable: str, what: str) -> None:
    for i in range(1, len(values)):
        if not values[i] > values[i - 1]:
            raise ValueError(f"{field}: must be strictly increasing in {variable} "
                             f"({what} {i})")


# ----------------------------------------------------------------------------- the profile


def _canonical_json(obj: Any) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=False)


class Profile(Immutable):
    """A validated function of one variable: an immutable, vectorized callable.

    ``profile(values)`` takes an array of positions [m] or times [day] (the unit of the
    variable) and returns a new float array of the same shape, in the unit of the
    quantity described; NaN inputs give NaN. Attributes: ``kind``, ``spec`` (canonical
    JSON-able form), ``breakpoints`` (sorted points strictly inside the domain where the
    value or its slope may jump), ``variable``, ``domain``. Profiles compare and hash by
    (spec, variable, domain); :func:`profile_key` gives a stable string key.
    """

    __slots__ = ("_kind", "_json", "_variable", "_domain", "_breakpoints", "_extra",
                 "_evaluate", "_key")

    def __init__(self, *, kind: str, spec: Spec, variable: str, domain: tuple[float, float],
                 evaluate: Callable[[np.ndarray], Any], breakpoints: tuple[float, ...] = (),
                 extra: tuple[float, ...] = ()) -> None:
        """Internal: use :func:`profile_from_spec` or :func:`profile_from_csv`."""
        text = _canonical_json(spec)
        # a digest rather than the JSON itself: a 10000-row table would double its memory
        key = hashlib.sha256(_canonical_json(
            {"spec": spec, "variable": variable, "domain": list(domain)}).encode()).hexdigest()
        lo, hi = domain
        inside = sorted({float(b) for b in breakpoints if lo < b < hi})
        for name, value in (("_kind", kind), ("_json", text), ("_variable", variable),
                            ("_domain", (float(lo), float(hi))),
                            ("_breakpoints", tuple(inside)), ("_extra", tuple(extra)),
                            ("_evaluate", evaluate), ("_key", key)):
            object.__setattr__(self, name, value)

    @property
    def kind(self) -> str:
        """The family: one of :data:`KINDS`."""
        return self._kind

    @property
    def spec(self) -> Spec:
        """Canonical JSON-able form (a new object each time; a float for constants)."""
        return json.loads(self._json)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Sorted points strictly inside the domain (unit of the variable) where the value
        or the slope may be discontinuous."""
        return self._breakpoints

    def nonsmooth_points(self, lo: float | None = None,
                         hi: float | None = None) -> tuple[float, ...]:
        """Sorted points strictly inside ``(lo, hi)`` (default: the domain; unit of the
        variable) where the value or the slope may jump: step breaks, the ramp's corner,
        table rows (all for "linear", all but the first for "step", the end rows for
        "pchip"), the switches of a formula.

        For a load history these are the times the time stepper must land on exactly
        (``breaks`` of :func:`core.time.solve_degenerate`): a step across a
        jump loses the method's order and fools its error estimate.
        """
        low = self._domain[0] if lo is None else float(lo)
        high = self._domain[1] if hi is None else float(hi)
        return tuple(b for b in self._breakpoints if low < b < high)

    def jump_points(self, lo: float | None = None,
                    hi: float | None = None) -> tuple[float, ...]:
        """The :meth:`nonsmooth_points` in ``(lo, hi)`` where the value itself jumps, not
        only the slope: the change across the point, read :data:`JUMP_PROBE` of the
        domain's size either side, is over :data:`JUMP_SHARE` of the profile's largest
        magnitude on its :meth:`sample_points`, and holds as that distance grows tenfold
        (a kink's change grows with it: a ramp of 14 days to 600 kN/m over 50 years
        changed by 0.8 N/m across the probe, over the share, and read as a jump)."""
        points = self.nonsmooth_points(lo, hi)
        if not points:
            return ()
        b = np.asarray(points, dtype=float)
        h = JUMP_PROBE * max(abs(self._domain[0]), abs(self._domain[1]), 1.0)
        near = np.abs(self(b + h) - self(b - h))
        far = np.abs(self(b + 10.0 * h) - self(b - 10.0 * h))
        size = max(float(np.max(np.abs(self(self.sample_points())), initial=0.0)), 1e-300)
        return tuple(float(v) for v in b[(near > JUMP_SHARE * size) & (near > 0.5 * far)])

    @property
    def variable(self) -> str:
        """Name of the variable (``"x"`` or ``"t"``)."""
        return self._variable

    @property
    def domain(self) -> tuple[float, float]:
        """The domain ``(lo, hi)`` the spec refers to (unit of the variable)."""
        return self._domain

    def __call__(self, values: Any) -> np.ndarray:
        """Values of the profile at ``values`` (unit of the variable); same shape, float."""
        v = np.asarray(values, dtype=float)
        with np.errstate(all="ignore"):
            out = np.array(np.broadcast_to(self._evaluate(v), v.shape), dtype=float)
        nan = np.isnan(v)
        if nan.any():
            out[nan] = np.nan
        return out

    def sample_points(self, domain: tuple[float, float] | None = None,
                      samples: int = RANGE_SAMPLES) -> np.ndarray:
        """Sorted points of ``domain`` (default: the profile's) at which sampling sees the
        profile's extremes: a uniform grid, both ends, both sides of every breakpoint,
        and the known interior extremes of the family (bump centre, sine crests,
        polynomial turning points, table rows). Unit of the variable."""
        lo, hi = self._domain if domain is None else _check_domain(domain, "sample_points")
        grid = [np.linspace(lo, hi, max(int(samples), 2))]
        if self._breakpoints:
            b = np.asarray(self._breakpoints)
            grid += [b, np.nextafter(b, -np.inf), np.nextafter(b, np.inf)]
        if self._extra:
            grid.append(np.asarray(self._extra))
        points = np.unique(np.concatenate(grid))
        return points[(points >= lo) & (points <= hi)]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Profile):
            return NotImplemented
        return self._key == other._key

    def __hash__(self) -> int:
        return hash(self._key)

    def __repr__(self) -> str:
        text = self._json if len(self._json) <= 120 else self._json[:117] + "..."
        return (f"Profile(kind={self._kind!r}, spec={text}, variable={self._variable!r}, "
                f"domain={self._domain!r})")


def profile_values(profile: Profile, x: np.ndarray) -> np.ndarray:
    """A profile's values at ``x`` as a float array of x's shape (a new array)."""
    out = profile(x)
    if isinstance(out, np.ndarray) and out.dtype == np.float64 and out.shape == np.shape(x):
        # a profile's own answer already has x's shape: skip the broadcast (a solve calls
        # this ~30 times); the copy keeps callers free to write into the result
        return out.copy()
    return np.broadcast_to(np.asarray(out, dtype=float), np.shape(x)).astype(float)


def shifted(profile: Profile, by: float, domain: tuple[float, float]) -> Profile:
    """``profile`` read from a point ``by`` further on: ``shifted(p, c, d)(x) = p(x + c)``
    on ``domain`` (unit of the variable), its breakpoints and known extremes moved with it.

    A profile of the global x [m] seen from a punch centred at ``c``. Its kind is
    ``"shifted"`` and its spec names the profile and the shift; it is built here only (a
    spec of that kind is not read back: it is no family of :data:`KINDS`).
    """
    by = float(by)
    spec = {"kind": "shifted", "profile": profile.spec, "by": by,
            "domain": list(profile.domain)}
    return Profile(kind="shifted", spec=spec, variable=profile.variable,
                   domain=(float(domain[0]), float(domain[1])),
                   evaluate=lambda v: profile(v + by),
                   breakpoints=tuple(b - by for b in profile.breakpoints),
                   extra=tuple(e - by for e in profile._extra))


def profile_key(profile: Profile) -> str:
    """A stable hex key of a profile: the SHA-256 of the canonical JSON of its spec,
    variable and domain (same for equal profiles, across processes and runs)."""
    return profile._key


# ----------------------------------------------------------------------------- families


def _constant(value: float, variable: str, domain: tuple[float, float]) -> Profile:
    return Profile(kind="constant", spec=value, variable=variable, domain=domain,
                   evaluate=lambda v: np.full(v.shape, value))


def _sine_crests(lo: float, hi: float, wavelength: float, phase: float) -> tuple[float, ...]:
    # crests and troughs where 2 pi v / L + phi = pi/2 + k pi; beyond the first few the
    # domain holds full periods and both extremes have been seen already
    first = (2 * math.pi * lo / wavelength + phase - math.pi / 2) / math.pi
    if not math.isfinite(first) or abs(first) > 1e15:
        # crests too dense to place (the values there are noise anyway); the grid decides
        return ()
    ks = math.ceil(first) + np.arange(8)
    with np.errstate(all="ignore"):  # a huge wavelength overflows: such points are dropped
        v = (math.pi / 2 + ks * math.pi - phase) * wavelength / (2 * math.pi)
    return tuple(float(p) for p in v if lo <= p <= hi)


def _formula_breakpoints(expression: Expression, lo: float, hi: float) -> list[float]:
    """Where the formula's switching functions change sign (see
    ``Expression.switching_functions``): zeros at grid points that border a non-zero
    sample, and sign changes between samples located by bisection."""
    grid = np.linspace(lo, hi, FORMULA_BREAK_SAMPLES)
    found: list[float] = []
    seen: set[str] = set()
    for g in expression.switching_functions:
        if g.text in seen:
            continue
        seen.add(g.text)
        values = g(grid)
        zero = values == 0
        # a zero run (min(x, x), ...) switches nothing inside, only where it starts or ends
        border = np.zeros_like(zero)
        border[1:] |= ~zero[:-1]
        border[:-1] |= ~zero[1:]
        found.extend(grid[1:-1][(zero & border)[1:-1]].tolist())
        s = np.sign(values)
        change = np.isfinite(values[:-1]) & np.isfinite(values[1:]) & (s[:-1] * s[1:] < 0)
        index = np.nonzero(change)[0]
        if index.size == 0:
            continue
        a, b = grid[index].copy(), grid[index + 1].copy()
        sa = s[index]
        # bisection needs only a sign change, so it also finds jumps of g; it stops when
        # every bracket is down to adjacent floating-point numbers
        for _ in range(64):
            mid = 0.5 * (a + b)
            open_ = (mid > a) & (mid < b)
            if not open_.any():
                break
            same = np.sign(g(mid)) == sa
            a = np.where(open_ & same, mid, a)
            b = np.where(open_ & ~same, mid, b)
        found.extend(b.tolist())
    return found


class _SlopeOverflow(Exception):
    """A table's pchip slopes are not finite (caught and named by the caller)."""


def _table(points: list[tuple[float, float]], interpolation: str, variable: str,
           domain: tuple[float, float], spec: dict[str, Any]) -> Profile:
    xs = np.array([p[0] for p in points])
    ys = np.array([p[1] for p in points])
    lo, hi = domain
    evaluate: Callable[[np.ndarray], Any]
    if interpolation == "linear":
        def evaluate(v: np.ndarray) -> Any:
            return np.interp(v, xs, ys)
        # the table's own ends are kinks too when inside the domain (held constant beyond)
        breaks: tuple[float, ...] = tuple(xs.tolist())
        extra: tuple[float, ...] = ()
    elif interpolation == "step":
        def evaluate(v: np.ndarray) -> Any:
            index = np.clip(np.searchsorted(xs, v, side="right") - 1, 0, len(xs) - 1)
            return ys[index]
        breaks = tuple(xs[1:].tolist())
        extra = ()
    else:
        with np.errstate(all="ignore"):
            try:
                # imported here: scipy.interpolate is 2/3 of a cold CLI start's imports
                from scipy.interpolate import PchipInterpolator

                interpolant = PchipInterpolator(xs, ys, extrapolate=False)
            except ValueError:
                # SciPy refuses slopes that overflow (rows ~1e-300 apart): refused here
                # with the field named by the caller
                raise _SlopeOverflow from None
        x0, x1 = float(xs[0]), float(xs[-1])

        y0, y1 = float(ys[0]), float(ys[-1])

        def evaluate(v: np.ndarray) -> Any:
            # the last piece evaluated at its right end is off by rounding; hold exact ends
            inner = interpolant(np.clip(v, x0, x1))
            return np.where(v <= x0, y0, np.where(v >= x1, y1, inner))
        # pchip is C1 between its ends; it is monotone between rows, so its extremes
        # lie at rows
        breaks = (x0, x1)
        extra = tuple(float(p) for p in xs if lo <= p <= hi)
    return Profile(kind="table", spec=spec, variable=variable, domain=domain,
                   evaluate=evaluate, breakpoints=breaks, extra=extra)
