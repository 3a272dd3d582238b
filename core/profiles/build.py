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
    {"kind": "expr", "expr": "..."}  or  {"expr": "..."}       see core.profiles.expressions

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

One registry, :data:`FAMILIES`, holds everything done by family: its fields, how it is
built (canonical spec, breakpoints, known extremes), the constant part it separates
exactly (:func:`without_offset`, for the gap) and the forms in which the explorer's
screen shows a function of ``x`` (:data:`VARIATIONS`, :func:`variation_of`) or a load
history (:data:`HISTORY_FORMS`, :func:`history_form_of`; the forms themselves are in
:mod:`core.profiles.forms`). The
:class:`Profile` value and the helpers of single families are in
:mod:`core.profiles.base`, the builders of the families in :mod:`core.profiles.families`,
CSV uploads in :mod:`core.profiles.tables`.
"""

from __future__ import annotations

import copyreg
import difflib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from core.profiles import forms
from core.profiles.base import (
    RANGE_SAMPLES,
    Profile,
    Spec,
    _check_domain,
    _check_variable,
    _constant,
    _fmt,
    _json_type,
    _number,
)
from core.profiles.families import (
    _At,
    _build_bump,
    _build_constant,
    _build_expr,
    _build_linear,
    _build_polynomial,
    _build_ramp,
    _build_sine,
    _build_step,
    _build_table,
    _offset_linear,
    _offset_mean,
    _offset_none,
    _offset_polynomial,
    _offset_step,
    _offset_table,
)
from core.profiles.forms import ScreenForm
from core.validation import refuse_first

# ----------------------------------------------------------------------------- families


def _check_fields(spec: Mapping[str, Any], kind: str, field: str) -> None:
    required, optional = FAMILIES[kind].required, FAMILIES[kind].optional
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


@dataclass(frozen=True)
class Family:
    """One family of profiles, and everything the program does by family.

    ``kind``: its name in a spec; ``required`` and ``optional``: its fields besides
    ``kind``; ``build(spec, at)``: the validated :class:`Profile` with its canonical spec,
    breakpoints and known extremes; ``offset(spec)``: the canonical spec less a constant
    part that the family separates exactly (``None``: nothing is dropped, as for a
    formula); ``variations`` and ``histories``: the forms in which the explorer's screen
    shows it as a function of ``x`` and as a load history (:mod:`core.profiles.forms`).
    """

    kind: str
    required: tuple[str, ...]
    optional: tuple[str, ...]
    build: Callable[[Mapping[str, Any], _At], Profile]
    offset: Callable[[Spec], Spec] | None = None
    variations: tuple[ScreenForm, ...] = ()
    histories: tuple[ScreenForm, ...] = ()


#: The families of profiles, by kind (the registry: fields, building, offsets, screen).
FAMILIES: Mapping[str, Family] = MappingProxyType({f.kind: f for f in (
    Family("constant", ("value",), (), _build_constant, _offset_none,
           (forms.X_NONE,), (forms.T_CONSTANT,)),
    Family("linear", ("start", "end"), (), _build_linear, _offset_linear, (forms.X_LINEAR,)),
    Family("step", ("values", "breaks"), (), _build_step, _offset_step,
           (forms.X_STEP, forms.X_PATCH), (forms.T_STEP,)),
    Family("sine", ("mean", "amplitude", "wavelength"), ("phase",), _build_sine,
           _offset_mean, (forms.X_SINE,), (forms.T_SINE,)),
    Family("polynomial", ("coefficients",), (), _build_polynomial, _offset_polynomial),
    Family("bump", ("mean", "amplitude", "center", "width"), (), _build_bump, _offset_mean,
           (forms.X_BUMP,)),
    Family("ramp", ("start", "end", "duration"), (), _build_ramp, None, (), (forms.T_RAMP,)),
    Family("table", ("points",), ("interpolation",), _build_table, _offset_table),
    Family("expr", ("expr",), (), _build_expr),
)})

#: The kinds of profiles, in the order the module docstring lists them.
KINDS: tuple[str, ...] = tuple(FAMILIES)

#: The screen's forms of a function of x and of a load history, by name, in the order
#: the screen lists them.
VARIATIONS: Mapping[str, ScreenForm] = MappingProxyType(
    {v.name: v for family in FAMILIES.values() for v in family.variations})
HISTORY_FORMS: Mapping[str, ScreenForm] = MappingProxyType(
    {h.name: h for family in FAMILIES.values() for h in family.histories})


def _form_of(spec: Any, which: str) -> tuple[str, dict[str, float]] | None:
    kind = "constant" if forms.numeric(spec) else (
        spec.get("kind") if isinstance(spec, Mapping) else None)
    family = FAMILIES.get(kind) if isinstance(kind, str) else None
    for form in getattr(family, which, ()):
        numbers = form.numbers_of(spec)
        if numbers is not None:
            return form.name, numbers
    return None


def variation_of(spec: Any) -> tuple[str, dict[str, float]] | None:
    """The screen's form of a function of ``x`` given as a spec, and its numbers
    (``level`` and those the form ``uses`` of amplitude, position, length;
    :mod:`core.profiles.forms`), or ``None`` when no form of the screen shows it (a table,
    a formula, a sine with a phase, ...). The spec is not validated here."""
    return _form_of(spec, "variations")


def history_form_of(spec: Any) -> tuple[str, dict[str, float]] | None:
    """The screen's form of a load history given as a spec, and its numbers (``value``
    and those the form ``uses`` of second, time), or ``None`` when no form shows it."""
    return _form_of(spec, "histories")


def without_offset(profile: Profile) -> Profile:
    """The profile less a constant part that its family separates exactly.

    ``constant`` gives 0; ``sine`` and ``bump`` drop ``mean``, ``polynomial`` its
    constant coefficient, ``linear``, ``step`` and ``table`` their first value (the
    differences of nearby values are exact in floating point). Other families are kept
    as they are. Only differences of the result are meaningful.
    """
    family = FAMILIES.get(profile.kind)  # a shifted profile is no family: kept
    offset = None if family is None else family.offset
    if offset is None:
        return profile
    return profile_from_spec(offset(profile.spec), field="gap", variable=profile.variable,
                             domain=profile.domain)


def profile_from_spec(spec: Any, *, field: str, variable: str = "x",
                      domain: tuple[float, float]) -> Profile:
    """Validate a profile spec (see the module docstring) and build the :class:`Profile`.

    ``variable`` names the variable (``"x"``, metres, or ``"t"``, days) and ``domain``
    is ``(lo, hi)`` in its unit: ``linear`` and ``ramp`` refer to ``lo`` and ``hi``,
    ``step`` breaks must lie strictly inside. Values keep the unit of the quantity.
    Raises ValueError whose message starts with ``field`` (or ``field.sub.path``).
    """
    variable = _check_variable(variable, field)
    domain = _check_domain(domain, field)
    if not isinstance(spec, Mapping):
        if isinstance(spec, (bool, np.bool_)) or not isinstance(
                spec, (int, float, np.integer, np.floating)):
            raise ValueError(f"{field}: must be a number or an object with a 'kind' field, "
                             f"not {_json_type(spec)}")
        return _constant(_number(spec, field), variable, domain)

    if "kind" not in spec and "expr" in spec:
        kind = "expr"
    else:
        if "kind" not in spec:
            raise ValueError(f"{field}: missing field 'kind' (one of {', '.join(KINDS)}), "
                             "or give a number or {'expr': ...}")
        kind = spec["kind"]
        if not isinstance(kind, str):
            raise ValueError(f"{field}.kind: must be a string, not {_json_type(kind)}")
        if kind not in FAMILIES:
            raise ValueError(f"{field}.kind: unknown kind {kind[:40]!r}; "
                             f"known kinds: {', '.join(KINDS)}")
    _check_fields(spec, kind, field)
    return FAMILIES[kind].build(spec, _At(field, variable, domain))


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
    if profile.kind == "constant":
        # one value everywhere: its first sample answers for all of them, with the same
        # message (a load slider's step checked 4097 samples, ~0.6 ms of a load change)
        points = profile.sample_points(domain, 2)[:1]
    else:
        points = profile.sample_points(domain, samples)
    with np.errstate(all="ignore"):
        values = profile(points)
    var = profile.variable
    refuse_first(~np.isfinite(values), lambda i: (
        f"{field}: must be finite, is {values[i]} at {var} = {_fmt(points[i])}"))
    rules = []
    if lower is not None:
        rules.append((values < lower if lower_inclusive else values <= lower,
                      f"{'>=' if lower_inclusive else '>'} {_fmt(lower)}"))
    if upper is not None:
        rules.append((values > upper if upper_inclusive else values >= upper,
                      f"{'<=' if upper_inclusive else '<'} {_fmt(upper)}"))
    for bad, rule in rules:
        refuse_first(bad, lambda i, rule=rule: (
            f"{field}: must be {rule}, is {_fmt(values[i])} at {var} = {_fmt(points[i])}"))


def _rebuild(spec: Any, variable: str, domain: tuple[float, float]) -> Profile:
    return profile_from_spec(spec, field="profile", variable=variable, domain=domain)


def _reduce(profile: Profile) -> tuple[Any, ...]:
    # A profile travels to worker processes as its spec and is built again there, through
    # the same checks. Registered here rather than as Profile.__reduce__ so that the
    # module of the value does not import its builder (which imports it).
    return (_rebuild, (profile.spec, profile.variable, profile.domain))


copyreg.pickle(Profile, _reduce)
