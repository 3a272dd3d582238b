"""Functions of position or time given as numbers, parametric families, tables or formulas.

Scene files and explorer widgets describe, for instance, a coating thickness as a
function of ``x`` (metres from the punch centre, on ``[-a, a]``) or a load factor as a
function of ``t`` (days after loading, on ``[0, t_end]``). :func:`profile_from_spec`
validates such a description and returns a :class:`Profile`: an immutable, vectorized
callable that also knows its canonical JSON form (``.spec``) and the points where its
value or slope may jump (``.breakpoints``), where the solver breaks its quadrature.

Spec forms (``v`` is the variable, ``[lo, hi]`` the domain; values keep the unit of the
quantity described, positions the unit of the variable)::

    3.5                                                   constant
    {"kind": "constant", "value": v}
    {"kind": "linear", "start": y(lo), "end": y(hi)}
    {"kind": "step", "values": [y0, ..., yk], "breaks": [b1, ..., bk]}   y_i on [b_i, b_i+1)
    {"kind": "sine", "mean": m, "amplitude": A, "wavelength": L, "phase": phi (rad, 0)}
    {"kind": "polynomial", "coefficients": [c0, c1, ...]}                 at most 16
    {"kind": "bump", "mean": m, "amplitude": A, "center": v0, "width": w}
    {"kind": "ramp", "start": y0, "end": y1, "duration": d}   y0 at lo, y1 from lo + d on
    {"kind": "table", "points": [[v0, y0], ...], "interpolation": "linear"|"step"|"pchip"}
    {"kind": "expr", "expr": "..."}  or  {"expr": "..."}       see core.expressions

``phase`` defaults to 0 and ``interpolation`` to ``"linear"``; a table is held constant
outside its rows (pchip included). Breakpoints, kept only where strictly inside the
domain: the step breaks; the ramp corner ``lo + d``; for tables every row ("linear":
the end rows are kinks too, where the held value begins), every row but the first
("step"), the two end rows ("pchip", which is smooth between them); for formulas the
sign changes of the arguments of ``abs``, ``sign``, ``heaviside`` and of the difference
of the arguments of ``min``/``max``, found on a grid of :data:`FORMULA_BREAK_SAMPLES`
points and refined by bisection (two switches closer than the grid spacing, or a zero
touched without a sign change, can be missed). Sine, bump and polynomial have none.

Every refusal is a ValueError whose message starts with the full field path, e.g.
``coating[1].modulus.points: must be strictly increasing in x (row 3)``. List indices in
paths and in "row"/"entry" are 0-based, as in the JSON file; line numbers of uploaded
CSV files are 1-based, as an editor shows them.
"""

from __future__ import annotations

import difflib
import hashlib
import json
import math
import re
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from core import limits
from core.expressions import ALIASES, CONSTANTS, FUNCTIONS, Expression, parse_expression
from core.immutable import Immutable

#: Most rows of a table (and most breaks of a step profile).
MAX_TABLE_ROWS = limits.MAX_TABLE_ROWS
#: Most coefficients of a polynomial (degree 15).
MAX_POLYNOMIAL_COEFFICIENTS = limits.MAX_POLYNOMIAL_COEFFICIENTS
#: Samples of the uniform part of :func:`check_range`'s grid.
RANGE_SAMPLES = 4097
#: Samples used to locate the switching points of a formula (see ``Profile.breakpoints``).
FORMULA_BREAK_SAMPLES = 2049

KINDS: tuple[str, ...] = ("constant", "linear", "step", "sine", "polynomial", "bump", "ramp",
                          "table", "expr")
INTERPOLATIONS: tuple[str, ...] = ("linear", "step", "pchip")

# (required, optional) fields of each kind, besides "kind"
_FIELDS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "constant": (("value",), ()),
    "linear": (("start", "end"), ()),
    "step": (("values", "breaks"), ()),
    "sine": (("mean", "amplitude", "wavelength"), ("phase",)),
    "polynomial": (("coefficients",), ()),
    "bump": (("mean", "amplitude", "center", "width"), ()),
    "ramp": (("start", "end", "duration"), ()),
    "table": (("points",), ("interpolation",)),
    "expr": (("expr",), ()),
}

Spec = float | dict[str, Any]


# ----------------------------------------------------------------------------- validation


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


def _check_fields(spec: Mapping[str, Any], kind: str, field: str) -> None:
    required, optional = _FIELDS[kind]
    # "kind" stays allowed in the short form too, so a misspelt "kind" gets its hint
    allowed = set(required) | set(optional) | {"kind"}
    for key in spec:
        if not isinstance(key, str):
            raise ValueError(f"{field}: field names must be strings, not {_json_type(key)}")
        if key not in allowed:
            message = f"{field}: unknown field {key[:40]!r}"
            close = difflib.get_close_matches(key[:40], sorted(allowed), n=1, cutoff=0.6)
            if close:
                message += f"; did you mean {close[0]!r}?"
            else:
                message += f" for kind {kind!r}; allowed: {', '.join(sorted(allowed))}"
            raise ValueError(message)
    for key in required:
        if key not in spec:
            raise ValueError(f"{field}: missing field {key!r} (required for kind {kind!r})")


def _check_domain(domain: Any, field: str) -> tuple[float, float]:
    if not isinstance(domain, (list, tuple)) or len(domain) != 2:
        raise ValueError(f"{field}: domain must be a pair (lo, hi), got {domain!r}")
    lo = _number(domain[0], f"{field}: domain start")
    hi = _number(domain[1], f"{field}: domain end")
    if not lo < hi:
        raise ValueError(f"{field}: domain must have start < end, got ({lo!r}, {hi!r})")
    return lo, hi


def _check_variable(variable: Any) -> str:
    if (not isinstance(variable, str) or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", variable)
            or variable in CONSTANTS or variable in FUNCTIONS or variable in ALIASES):
        raise ValueError(f"variable name {variable!r} is not allowed")
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
        (``breaks`` of :func:`core.time_integration.solve_degenerate`): a step across a
        jump loses the method's order and fools its error estimate.
        """
        low = self._domain[0] if lo is None else float(lo)
        high = self._domain[1] if hi is None else float(hi)
        return tuple(b for b in self._breakpoints if low < b < high)

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

    def __reduce__(self) -> tuple[Any, ...]:
        return (_rebuild, (self.spec, self._variable, self._domain))


def _rebuild(spec: Spec, variable: str, domain: tuple[float, float]) -> Profile:
    return profile_from_spec(spec, field="profile", variable=variable, domain=domain)


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


def profile_from_spec(spec: Any, *, field: str, variable: str = "x",
                      domain: tuple[float, float]) -> Profile:
    """Validate a profile spec (see the module docstring) and build the :class:`Profile`.

    ``variable`` names the variable (``"x"``, metres, or ``"t"``, days) and ``domain``
    is ``(lo, hi)`` in its unit: ``linear`` and ``ramp`` refer to ``lo`` and ``hi``,
    ``step`` breaks must lie strictly inside. Values keep the unit of the quantity.
    Raises ValueError whose message starts with ``field`` (or ``field.sub.path``).
    """
    variable = _check_variable(variable)
    domain = _check_domain(domain, field)
    lo, hi = domain
    if not isinstance(spec, Mapping):
        if isinstance(spec, (bool, np.bool_)) or not isinstance(
                spec, (int, float, np.integer, np.floating)):
            raise ValueError(f"{field}: must be a number or an object with a 'kind' field, "
                             f"not {_json_type(spec)}")
        return _constant(_number(spec, field), variable, domain)

    short = "kind" not in spec and "expr" in spec
    if short:
        kind = "expr"
    else:
        if "kind" not in spec:
            raise ValueError(f"{field}: missing field 'kind' (one of {', '.join(KINDS)}), "
                             "or give a number or {'expr': ...}")
        kind = spec["kind"]
        if not isinstance(kind, str):
            raise ValueError(f"{field}.kind: must be a string, not {_json_type(kind)}")
        if kind not in _FIELDS:
            raise ValueError(f"{field}.kind: unknown kind {kind[:40]!r}; "
                             f"known kinds: {', '.join(KINDS)}")
    _check_fields(spec, kind, field)

    def num(key: str) -> float:
        return _number(spec[key], f"{field}.{key}")

    if kind == "constant":
        return _constant(num("value"), variable, domain)

    if kind == "linear":
        start, end = num("start"), num("end")
        span = hi - lo
        # weights that are exactly 1 and 0 at the ends, so y(lo) = start and y(hi) = end
        return Profile(kind=kind, spec={"kind": kind, "start": start, "end": end},
                       variable=variable, domain=domain,
                       evaluate=lambda v: start * ((hi - v) / span) + end * ((v - lo) / span))

    if kind == "step":
        breaks = _numbers(spec["breaks"], f"{field}.breaks", least=0, most=MAX_TABLE_ROWS)
        values = _numbers(spec["values"], f"{field}.values", least=1,
                          most=MAX_TABLE_ROWS + 1)
        if len(values) != len(breaks) + 1:
            raise ValueError(f"{field}.values: must have one entry more than breaks "
                             f"({len(breaks) + 1}), has {len(values)}")
        for i, b in enumerate(breaks):
            if not lo < b < hi:
                raise ValueError(f"{field}.breaks[{i}]: must lie strictly inside the domain "
                                 f"({_fmt(lo)}, {_fmt(hi)}) of {variable}, is {_fmt(b)}")
        _strictly_increasing(breaks, f"{field}.breaks", variable, "entry")
        b_arr, y_arr = np.array(breaks), np.array(values)
        return Profile(kind=kind, spec={"kind": kind, "values": values, "breaks": breaks},
                       variable=variable, domain=domain, breakpoints=tuple(breaks),
                       evaluate=lambda v: y_arr[np.searchsorted(b_arr, v, side="right")])

    if kind == "sine":
        mean, amplitude = num("mean"), num("amplitude")
        wavelength = _positive(spec["wavelength"], f"{field}.wavelength")
        phase = _number(spec.get("phase", 0.0), f"{field}.phase")
        k = 2 * math.pi / wavelength
        return Profile(kind=kind, spec={"kind": kind, "mean": mean, "amplitude": amplitude,
                                        "wavelength": wavelength, "phase": phase},
                       variable=variable, domain=domain,
                       extra=_sine_crests(lo, hi, wavelength, phase),
                       evaluate=lambda v: mean + amplitude * np.sin(k * v + phase))

    if kind == "polynomial":
        coefficients = _numbers(spec["coefficients"], f"{field}.coefficients", least=1,
                                most=MAX_POLYNOMIAL_COEFFICIENTS, what="coefficients")
        c = np.array(coefficients)
        extra: tuple[float, ...] = ()
        with np.errstate(all="ignore"):  # coefficients near the float limit overflow: NaN
            derivative = np.polynomial.polynomial.polyder(c)
        if np.all(np.isfinite(derivative)) and np.any(derivative != 0):
            try:
                with np.errstate(all="ignore"):
                    roots = np.polynomial.polynomial.polyroots(np.trim_zeros(derivative, "b"))
            except np.linalg.LinAlgError:
                # extreme coefficient ratios overflow the companion matrix; the grid decides
                roots = np.array([])
            real = roots.real[np.abs(roots.imag) <= 1e-9 * (1 + np.abs(roots.real))]
            extra = tuple(float(r) for r in real if lo <= r <= hi)
        return Profile(kind=kind, spec={"kind": kind, "coefficients": coefficients},
                       variable=variable, domain=domain, extra=extra,
                       evaluate=lambda v: np.polynomial.polynomial.polyval(v, c))

    if kind == "bump":
        mean, amplitude, center = num("mean"), num("amplitude"), num("center")
        width = _positive(spec["width"], f"{field}.width")
        return Profile(kind=kind, spec={"kind": kind, "mean": mean, "amplitude": amplitude,
                                        "center": center, "width": width},
                       variable=variable, domain=domain, extra=(center,),
                       evaluate=lambda v: mean + amplitude * np.exp(-((v - center) / width)
                                                                    ** 2))

    if kind == "ramp":
        start, end = num("start"), num("end")
        duration = _positive(spec["duration"], f"{field}.duration")
        return Profile(kind=kind, spec={"kind": kind, "start": start, "end": end,
                                        "duration": duration},
                       variable=variable, domain=domain, breakpoints=(lo + duration,),
                       evaluate=lambda v: start + (end - start)
                       * np.clip((v - lo) / duration, 0.0, 1.0))

    if kind == "table":
        rows = _list(spec["points"], f"{field}.points", least=2, most=MAX_TABLE_ROWS,
                     what="rows")
        points: list[tuple[float, float]] = []
        for i, row in enumerate(rows):
            path = f"{field}.points[{i}]"
            if isinstance(row, np.ndarray):
                row = row.tolist()
            if not isinstance(row, (list, tuple)) or len(row) != 2:
                raise ValueError(f"{path}: must be a pair [{variable}, value], "
                                 f"not {_json_type(row)}"
                                 + (f" of {len(row)}" if isinstance(row, (list, tuple))
                                    else ""))
            points.append((_number(row[0], f"{path}[0]"), _number(row[1], f"{path}[1]")))
        _strictly_increasing([p[0] for p in points], f"{field}.points", variable, "row")
        interpolation = spec.get("interpolation", "linear")
        if not isinstance(interpolation, str) or interpolation not in INTERPOLATIONS:
            shown = (repr(interpolation[:40]) if isinstance(interpolation, str)
                     else _json_type(interpolation))
            raise ValueError(f"{field}.interpolation: must be one of "
                             f"{', '.join(INTERPOLATIONS)}, is {shown}")
        canonical = {"kind": kind, "points": [list(p) for p in points],
                     "interpolation": interpolation}
        try:
            return _table(points, interpolation, variable, domain, canonical)
        except _SlopeOverflow:
            raise ValueError(f"{field}.points: the slopes between rows overflow a double "
                             "(rows too close together for 'pchip'); spread them or use "
                             "'linear'") from None

    # kind == "expr"
    text = spec["expr"]
    if not isinstance(text, str):
        raise ValueError(f"{field}.expr: must be a string (a formula in {variable}), "
                         f"not {_json_type(text)}")
    expression = parse_expression(text, (variable,), field=f"{field}.expr")
    if expression.is_constant:
        breaks_found: list[float] = []
    else:
        breaks_found = _formula_breakpoints(expression, lo, hi)
    return Profile(kind="expr", spec={"kind": "expr", "expr": expression.text},
                   variable=variable, domain=domain, breakpoints=tuple(breaks_found),
                   evaluate=expression)


# ----------------------------------------------------------------------------- range check


def check_range(profile: Profile, *, field: str, domain: tuple[float, float] | None = None,
                lower: float | None = None, upper: float | None = None,
                lower_inclusive: bool = False, upper_inclusive: bool = False,
                samples: int = RANGE_SAMPLES) -> None:
    """Refuse a profile whose values leave ``(lower, upper)`` (or are not finite) on
    ``domain`` (default: the profile's).

    Bounds are in the unit of the quantity, ``domain`` in the unit of the variable; a
    bound is exclusive unless its ``*_inclusive`` flag is set. The profile is sampled on
    :meth:`Profile.sample_points` (a uniform grid of ``samples`` points, both ends, both
    sides of each breakpoint and the family's known extremes). Raises ValueError naming
    the first offending point, e.g. ``coating[0].thickness: must be > 0, is -0.001 at
    x = 0.12``. A formula is only checked at the samples: a spike narrower than the grid
    spacing can pass.
    """
    points = profile.sample_points(domain, samples)
    with np.errstate(all="ignore"):
        values = profile(points)
    var = profile.variable
    bad = ~np.isfinite(values)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{field}: must be finite, is {values[i]} at {var} = "
                         f"{_fmt(points[i])}")
    if lower is not None:
        bad = values < lower if lower_inclusive else values <= lower
        if bad.any():
            i = int(np.argmax(bad))
            op = ">=" if lower_inclusive else ">"
            raise ValueError(f"{field}: must be {op} {_fmt(lower)}, is {_fmt(values[i])} at "
                             f"{var} = {_fmt(points[i])}")
    if upper is not None:
        bad = values > upper if upper_inclusive else values >= upper
        if bad.any():
            i = int(np.argmax(bad))
            op = "<=" if upper_inclusive else "<"
            raise ValueError(f"{field}: must be {op} {_fmt(upper)}, is {_fmt(values[i])} at "
                             f"{var} = {_fmt(points[i])}")


# ----------------------------------------------------------------------------- CSV upload

# Unambiguous (no nested quantifiers), so matching is linear in the cell length.
_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


def _split(line: str, separator: str | None) -> list[str]:
    if separator is None:
        cells = line.split()
    else:
        cells = [c.strip() for c in line.split(separator)]
        while cells and cells[-1] == "":  # spreadsheets often end rows with a separator
            cells.pop()
    if separator == ";":
        # semicolon files come from locales that write a decimal comma
        cells = [c.replace(",", ".") for c in cells]
    return cells


def _cell_number(cell: str) -> float | None:
    if len(cell) > 400 or not _NUMBER.fullmatch(cell):
        return None
    return float(cell)


#: Largest CSV table accepted for a profile [bytes] (1 MB).
MAX_TABLE_BYTES = limits.MAX_TABLE_BYTES


def profile_from_csv(data: bytes | str, *, field: str, variable: str = "x",
                     domain: tuple[float, float], interpolation: str = "linear",
                     max_bytes: int = MAX_TABLE_BYTES, max_rows: int = MAX_TABLE_ROWS,
                     max_breakpoints: int | None = None) -> Profile:
    """A table profile from an uploaded CSV file of two numeric columns.

    Columns: the variable (unit of the variable) and the value (unit of the quantity).
    Cells are separated by commas, semicolons (then a decimal comma is accepted) or
    white space; one header line is allowed; blank lines are skipped. The result is the
    ``table`` profile with ``interpolation``. Raises ValueError naming ``field`` and the
    1-based line for: a file over ``max_bytes`` bytes, over ``max_rows`` data rows, fewer
    than 2 rows, a wrong number of columns, a cell that is not a number, values not
    strictly increasing in the variable; and naming the limit for a table with more
    than ``max_breakpoints`` points inside the domain where its value or slope jumps
    (default: :data:`core.limits.MAX_BREAKPOINTS` for an x-profile, which the solver
    allows for a whole scene, so such a table could never be solved; none for ``t``).
    """
    if isinstance(data, (bytes, bytearray, memoryview)):
        raw = bytes(data)
        if len(raw) > max_bytes:
            raise ValueError(f"{field}: file is too large ({len(raw)} bytes, at most "
                             f"{max_bytes})")
        if b"\x00" in raw:
            raise ValueError(f"{field}: file is not text (upload a plain CSV file)")
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            # only the header can hold non-ASCII text, and it is not used
            text = raw.decode("latin-1")
    elif isinstance(data, str):
        if len(data) > max_bytes or len(data.encode("utf-8", "replace")) > max_bytes:
            raise ValueError(f"{field}: file is too large (more than {max_bytes} bytes)")
        text = data.removeprefix("\ufeff")
    else:
        raise ValueError(f"{field}: file content must be bytes or text, not "
                         f"{_json_type(data)}")

    lines = [(n, line.strip()) for n, line in enumerate(text.splitlines(), start=1)]
    lines = [(n, line) for n, line in lines if line]
    if not lines:
        raise ValueError(f"{field}: file is empty")
    first = lines[0][1]
    separator = ";" if ";" in first else "," if "," in first else None
    first_cells = _split(first, separator)
    if not first_cells or any(_cell_number(c) is None for c in first_cells):
        lines = lines[1:]  # a header; later lines must all be data
        if lines:
            first = lines[0][1]
            separator = ";" if ";" in first else "," if "," in first else None
    if len(lines) > max_rows:
        raise ValueError(f"{field}: file has too many rows ({len(lines)}, at most "
                         f"{max_rows})")
    if len(lines) < 2:
        raise ValueError(f"{field}: file needs at least 2 data rows, has {len(lines)}")

    points: list[list[float]] = []
    for n, line in lines:
        cells = _split(line, separator)
        row = []
        for column, cell in enumerate(cells, start=1):
            value = _cell_number(cell)
            if value is None:
                shown = cell if len(cell) <= 40 else cell[:40] + "..."
                raise ValueError(f"{field}: line {n}, column {column}: {shown!r} is not a "
                                 "number")
            if not math.isfinite(value):
                raise ValueError(f"{field}: line {n}, column {column}: {cell[:40]!r} is out "
                                 "of range")
            row.append(value)
        if len(row) != 2:
            shown = "white space" if separator is None else repr(separator)
            raise ValueError(f"{field}: line {n}: expected 2 columns separated by {shown}, "
                             f"found {len(row)}")
        if points and not row[0] > points[-1][0]:
            raise ValueError(f"{field}: {variable} values must be strictly increasing "
                             f"(line {n}: {_fmt(row[0])} after {_fmt(points[-1][0])})")
        points.append(row)
    profile = profile_from_spec({"kind": "table", "points": points,
                                 "interpolation": interpolation},
                                field=field, variable=variable, domain=domain)
    if max_breakpoints is None and variable == "x":
        max_breakpoints = limits.MAX_BREAKPOINTS
    jumps = len(profile.breakpoints)
    if max_breakpoints is not None and jumps > max_breakpoints:
        raise ValueError(
            f"{field}: a table of {len(points)} rows with {interpolation!r} interpolation "
            f"has {jumps} points inside the domain where its value or slope jumps, more "
            f"than the {max_breakpoints} the solver allows in a whole scene: use at most "
            f"{max_breakpoints} rows inside the domain, or 'pchip' interpolation (smooth "
            "between its end rows)")
    return profile
