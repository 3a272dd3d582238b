"""The builders of the profile families, and the constant part each one separates.

One ``_build_<kind>`` per family reads a spec's fields at a place :class:`_At` (field
path, variable, domain) and returns the validated :class:`~core.profiles.Profile`
with its canonical spec, breakpoints and known extremes; one ``_offset_<kind>`` gives
the canonical spec less its exactly separable constant part. The registry that joins
them, :data:`core.profiles.FAMILIES`, and the public entry points are in
:mod:`core.profiles.build`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np

from core.profiles.base import (
    INTERPOLATIONS,
    MAX_POLYNOMIAL_COEFFICIENTS,
    MAX_TABLE_ROWS,
    Profile,
    Spec,
    _constant,
    _fmt,
    _formula_breakpoints,
    _json_type,
    _list,
    _number,
    _numbers,
    _positive,
    _sine_crests,
    _SlopeOverflow,
    _strictly_increasing,
    _table,
)
from core.profiles.expressions import parse_expression


class _At(NamedTuple):
    """Where a spec is read: its field path, its variable and the domain ``(lo, hi)``."""

    field: str
    variable: str
    domain: tuple[float, float]

    def number(self, spec: Mapping[str, Any], key: str) -> float:
        return _number(spec[key], f"{self.field}.{key}")

    def positive(self, spec: Mapping[str, Any], key: str) -> float:
        return _positive(spec[key], f"{self.field}.{key}")


def _build_constant(spec: Mapping[str, Any], at: _At) -> Profile:
    return _constant(at.number(spec, "value"), at.variable, at.domain)


def _build_linear(spec: Mapping[str, Any], at: _At) -> Profile:
    start, end = at.number(spec, "start"), at.number(spec, "end")
    lo, hi = at.domain
    span = hi - lo
    # weights that are exactly 1 and 0 at the ends, so y(lo) = start and y(hi) = end
    return Profile(kind="linear", spec={"kind": "linear", "start": start, "end": end},
                   variable=at.variable, domain=at.domain,
                   evaluate=lambda v: start * ((hi - v) / span) + end * ((v - lo) / span))


def _build_step(spec: Mapping[str, Any], at: _At) -> Profile:
    field, (lo, hi) = at.field, at.domain
    breaks = _numbers(spec["breaks"], f"{field}.breaks", least=0, most=MAX_TABLE_ROWS)
    values = _numbers(spec["values"], f"{field}.values", least=1, most=MAX_TABLE_ROWS + 1)
    if len(values) != len(breaks) + 1:
        raise ValueError(f"{field}.values: must have one entry more than breaks "
                         f"({len(breaks) + 1}), has {len(values)}")
    # In time a step at or after the last output time is a load change that has not come
    # yet: the history holds its earlier value (a scene's times shortened to its first
    # 100 days, or a study's times, refused a step at 365 days). In x a step is a
    # breakpoint of the geometry and must be on the punch.
    later = at.variable == "t"
    for i, b in enumerate(breaks):
        if not (lo < b < hi or (later and b >= hi and math.isfinite(b))):
            where = (f"after the start {_fmt(lo)} of {at.variable}" if later
                     else f"strictly inside the domain ({_fmt(lo)}, {_fmt(hi)}) of "
                     f"{at.variable}")
            raise ValueError(f"{field}.breaks[{i}]: must lie {where}, is {_fmt(b)}")
    _strictly_increasing(breaks, f"{field}.breaks", at.variable, "entry")
    b_arr, y_arr = np.array(breaks), np.array(values)
    return Profile(kind="step", spec={"kind": "step", "values": values, "breaks": breaks},
                   variable=at.variable, domain=at.domain,
                   breakpoints=tuple(b for b in breaks if b < hi),
                   evaluate=lambda v: y_arr[np.searchsorted(b_arr, v, side="right")])


def _build_sine(spec: Mapping[str, Any], at: _At) -> Profile:
    mean, amplitude = at.number(spec, "mean"), at.number(spec, "amplitude")
    wavelength = at.positive(spec, "wavelength")
    phase = _number(spec.get("phase", 0.0), f"{at.field}.phase")
    k = 2 * math.pi / wavelength
    return Profile(kind="sine", spec={"kind": "sine", "mean": mean, "amplitude": amplitude,
                                      "wavelength": wavelength, "phase": phase},
                   variable=at.variable, domain=at.domain,
                   extra=_sine_crests(*at.domain, wavelength, phase),
                   evaluate=lambda v: mean + amplitude * np.sin(k * v + phase))


def _build_polynomial(spec: Mapping[str, Any], at: _At) -> Profile:
    lo, hi = at.domain
    coefficients = _numbers(spec["coefficients"], f"{at.field}.coefficients", least=1,
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
    return Profile(kind="polynomial", spec={"kind": "polynomial", "coefficients": coefficients},
                   variable=at.variable, domain=at.domain, extra=extra,
                   evaluate=lambda v: np.polynomial.polynomial.polyval(v, c))


def _build_bump(spec: Mapping[str, Any], at: _At) -> Profile:
    mean, amplitude = at.number(spec, "mean"), at.number(spec, "amplitude")
    center, width = at.number(spec, "center"), at.positive(spec, "width")
    return Profile(kind="bump", spec={"kind": "bump", "mean": mean, "amplitude": amplitude,
                                      "center": center, "width": width},
                   variable=at.variable, domain=at.domain, extra=(center,),
                   evaluate=lambda v: mean + amplitude * np.exp(-((v - center) / width) ** 2))


def _build_ramp(spec: Mapping[str, Any], at: _At) -> Profile:
    start, end = at.number(spec, "start"), at.number(spec, "end")
    duration = at.positive(spec, "duration")
    lo = at.domain[0]
    return Profile(kind="ramp", spec={"kind": "ramp", "start": start, "end": end,
                                      "duration": duration},
                   variable=at.variable, domain=at.domain, breakpoints=(lo + duration,),
                   evaluate=lambda v: start + (end - start)
                   * np.clip((v - lo) / duration, 0.0, 1.0))


def _build_table(spec: Mapping[str, Any], at: _At) -> Profile:
    field, variable = at.field, at.variable
    rows = _list(spec["points"], f"{field}.points", least=2, most=MAX_TABLE_ROWS, what="rows")
    points: list[tuple[float, float]] = []
    for i, row in enumerate(rows):
        path = f"{field}.points[{i}]"
        if isinstance(row, np.ndarray):
            row = row.tolist()
        if not isinstance(row, (list, tuple)) or len(row) != 2:
            raise ValueError(f"{path}: must be a pair [{variable}, value], "
                             f"not {_json_type(row)}"
                             + (f" of {len(row)}" if isinstance(row, (list, tuple)) else ""))
        points.append((_number(row[0], f"{path}[0]"), _number(row[1], f"{path}[1]")))
    _strictly_increasing([p[0] for p in points], f"{field}.points", variable, "row")
    interpolation = spec.get("interpolation", "linear")
    if not isinstance(interpolation, str) or interpolation not in INTERPOLATIONS:
        shown = (repr(interpolation[:40]) if isinstance(interpolation, str)
                 else _json_type(interpolation))
        raise ValueError(f"{field}.interpolation: must be one of "
                         f"{', '.join(INTERPOLATIONS)}, is {shown}")
    canonical = {"kind": "table", "points": [list(p) for p in points],
                 "interpolation": interpolation}
    try:
        return _table(points, interpolation, variable, at.domain, canonical)
    except _SlopeOverflow:
        raise ValueError(f"{field}.points: the slopes between rows overflow a double "
                         "(rows too close together for 'pchip'); spread them or use "
                         "'linear'") from None


def _build_expr(spec: Mapping[str, Any], at: _At) -> Profile:
    text = spec["expr"]
    if not isinstance(text, str):
        raise ValueError(f"{at.field}.expr: must be a string (a formula in {at.variable}), "
                         f"not {_json_type(text)}")
    expression = parse_expression(text, (at.variable,), field=f"{at.field}.expr")
    breaks = [] if expression.is_constant else _formula_breakpoints(expression, *at.domain)
    return Profile(kind="expr", spec={"kind": "expr", "expr": expression.text},
                   variable=at.variable, domain=at.domain, breakpoints=tuple(breaks),
                   evaluate=expression)


# The constant part each family separates exactly (see without_offset): differences of
# nearby values are exact in floating point, so dropping it loses nothing.

def _offset_none(spec: Spec) -> Spec:
    return 0.0


def _offset_mean(spec: Spec) -> Spec:
    return {**spec, "mean": 0.0}


def _offset_linear(spec: Spec) -> Spec:
    return {**spec, "start": 0.0, "end": spec["end"] - spec["start"]}


def _offset_step(spec: Spec) -> Spec:
    first = spec["values"][0]
    return {**spec, "values": [v - first for v in spec["values"]]}


def _offset_polynomial(spec: Spec) -> Spec:
    return {**spec, "coefficients": [0.0, *spec["coefficients"][1:]]}


def _offset_table(spec: Spec) -> Spec:
    first = spec["points"][0][1]
    return {**spec, "points": [[v, y - first] for v, y in spec["points"]]}

