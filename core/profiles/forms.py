"""The forms in which the explorer's screen shows a profile, each a few named numbers.

A function of ``x`` is shown as a ``level`` and a variation about it of size
``amplitude``, placed at ``position`` and sized by ``length`` (both in metres) where the
form has them; a load history as a ``value``, a ``second`` value and a ``time`` [days].
Values are in the unit of the quantity. Each form builds the canonical spec from its
numbers and reads them back from a spec of its own form. Which forms show which family
is part of the registry of families (:data:`core.profiles.FAMILIES`); nothing here
validates a spec (:func:`core.profiles.profile_from_spec` does).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

#: The numbers of a form of a function of x, and of a load history.
X_NUMBERS: tuple[str, ...] = ("level", "amplitude", "position", "length")
T_NUMBERS: tuple[str, ...] = ("value", "second", "time")

Numbers = Mapping[str, float]


@dataclass(frozen=True)
class ScreenForm:
    """One form of the screen: ``name`` (the screen's key), ``label`` (its words),
    ``uses`` (the numbers it shows besides the level or value), ``spec(numbers)`` (the
    canonical spec) and ``read(spec)`` (the numbers of a spec of this form, else None)."""

    name: str
    label: str
    uses: tuple[str, ...]
    spec: Callable[[Numbers], Any]
    read: Callable[[Any], dict[str, float] | None]

    def numbers_of(self, spec: Any) -> dict[str, float] | None:
        """:attr:`read`, with a missing field or a value of another type read as None."""
        try:
            return self.read(spec)
        except (KeyError, TypeError, AttributeError):
            return None


def numeric(*values: Any) -> bool:
    """Whether every value is a plain number (a boolean is not)."""
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def _constant(spec: Any) -> float | None:
    if numeric(spec):
        return float(spec)
    # the long form of a constant reads back as the plain number, which is the same
    if set(spec) == {"kind", "value"} and numeric(spec["value"]):
        return float(spec["value"])
    return None


def _pairs(spec: Any, values: int, breaks: int) -> tuple[list, list] | None:
    """A step's values and breaks when it has that many, all numbers."""
    v, b = spec["values"], spec["breaks"]
    if (isinstance(v, list) and isinstance(b, list) and len(v) == values
            and len(b) == breaks and numeric(*v, *b)):
        return v, b
    return None


# ------------------------------------------------------------------- functions of x


def _read_none(spec: Any) -> dict[str, float] | None:
    level = _constant(spec)
    return None if level is None else {"level": level}


def _read_linear(spec: Any) -> dict[str, float] | None:
    start, end = spec["start"], spec["end"]
    if not numeric(start, end):
        return None
    return {"level": 0.5 * (start + end), "amplitude": 0.5 * (end - start)}


def _read_step(spec: Any) -> dict[str, float] | None:
    found = _pairs(spec, 2, 1)
    if found is None:
        return None
    (low, high), (at,) = found
    return {"level": 0.5 * (low + high), "amplitude": 0.5 * (high - low), "position": at}


def _read_patch(spec: Any) -> dict[str, float] | None:
    found = _pairs(spec, 3, 2)
    if found is None or found[0][0] != found[0][2]:
        return None
    (outer, inner, _), (left, right) = found
    return {"level": outer, "amplitude": inner - outer, "position": 0.5 * (left + right),
            "length": right - left}


def _read_sine_x(spec: Any) -> dict[str, float] | None:
    if not numeric(spec["mean"], spec["amplitude"], spec["wavelength"]) \
            or spec.get("phase", 0.0) != 0:
        return None
    return {"level": spec["mean"], "amplitude": spec["amplitude"],
            "length": spec["wavelength"]}


def _read_bump(spec: Any) -> dict[str, float] | None:
    if not numeric(spec["mean"], spec["amplitude"], spec["center"], spec["width"]):
        return None
    return {"level": spec["mean"], "amplitude": spec["amplitude"],
            "position": spec["center"], "length": spec["width"]}


X_NONE = ScreenForm("none", "constant", (), lambda n: n["level"], _read_none)
X_LINEAR = ScreenForm(
    "linear", "linear across the punch", ("amplitude",),
    lambda n: {"kind": "linear", "start": n["level"] - n["amplitude"],
               "end": n["level"] + n["amplitude"]}, _read_linear)
X_STEP = ScreenForm(
    "step", "step at a position", ("amplitude", "position"),
    lambda n: {"kind": "step", "values": [n["level"] - n["amplitude"],
                                          n["level"] + n["amplitude"]],
               "breaks": [n["position"]]}, _read_step)
X_PATCH = ScreenForm(
    "patch", "patch (a band of another value)", ("amplitude", "position", "length"),
    lambda n: {"kind": "step", "values": [n["level"], n["level"] + n["amplitude"], n["level"]],
               "breaks": [n["position"] - 0.5 * n["length"],
                          n["position"] + 0.5 * n["length"]]}, _read_patch)
X_SINE = ScreenForm(
    "sine", "sine (waviness)", ("amplitude", "length"),
    lambda n: {"kind": "sine", "mean": n["level"], "amplitude": n["amplitude"],
               "wavelength": n["length"], "phase": 0.0}, _read_sine_x)
X_BUMP = ScreenForm(
    "bump", "bump (local patch)", ("amplitude", "position", "length"),
    lambda n: {"kind": "bump", "mean": n["level"], "amplitude": n["amplitude"],
               "center": n["position"], "width": n["length"]}, _read_bump)


# ------------------------------------------------------------------- load histories


def _read_constant_t(spec: Any) -> dict[str, float] | None:
    value = _constant(spec)
    return None if value is None else {"value": value}


def _read_ramp(spec: Any) -> dict[str, float] | None:
    if not numeric(spec["start"], spec["end"], spec["duration"]):
        return None
    return {"value": spec["end"], "second": spec["start"], "time": spec["duration"]}


def _read_step_t(spec: Any) -> dict[str, float] | None:
    found = _pairs(spec, 2, 1)
    if found is None:
        return None
    (before, after), (at,) = found
    return {"value": before, "second": after, "time": at}


def _read_sine_t(spec: Any) -> dict[str, float] | None:
    if not numeric(spec["mean"], spec["amplitude"], spec["wavelength"]) \
            or spec.get("phase", 0.0) != 0:
        return None
    return {"value": spec["mean"], "second": spec["amplitude"], "time": spec["wavelength"]}


T_CONSTANT = ScreenForm("constant", "constant", (), lambda n: n["value"], _read_constant_t)
T_RAMP = ScreenForm(
    "ramp", "ramp", ("second", "time"),
    lambda n: {"kind": "ramp", "start": n["second"], "end": n["value"],
               "duration": n["time"]}, _read_ramp)
T_STEP = ScreenForm(
    "step", "step", ("second", "time"),
    lambda n: {"kind": "step", "values": [n["value"], n["second"]], "breaks": [n["time"]]},
    _read_step_t)
T_SINE = ScreenForm(
    "sine", "sine", ("second", "time"),
    lambda n: {"kind": "sine", "mean": n["value"], "amplitude": n["second"],
               "wavelength": n["time"], "phase": 0.0}, _read_sine_t)
