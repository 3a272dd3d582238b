"""The inputs of the design codes' creep models, validated in the codes' units.

Strength (``fcm`` [MPa] or a class ``"C30/37"``), cement class, relative humidity [%],
notional size [mm] and temperature [deg C], each checked against the range its code covers
(:data:`RANGES`, with the clause the bound comes from) and gathered in :class:`CodeInputs`.
Inputs outside the ranges are refused with a ValueError naming the field and the range;
nothing is clipped.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from core.validation import PYTHON_STYLE, finite_number, show_python

#: alpha of 5.1-73 / B.9 and s of Table 5.1-9 / 3.1.2(6), by cement class.
CEMENT_CLASSES: dict[str, tuple[float, float]] = {"S": (-1.0, 0.38), "N": (0.0, 0.25),
                                                  "R": (1.0, 0.20)}
#: fcm = fck + DELTA_F [MPa] (MC2010 5.1-1, EN 1992-1-1 Table 3.1).
DELTA_F = 8.0
#: Accepted ranges of the inputs: (low, high, where the bound comes from).
RANGES: dict[str, dict[str, tuple[float, float, str]]] = {
    "fib_mc2010": {
        "fcm": (20.0, 130.0, "fib MC2010 5.1.9.4.2"),
        "relative_humidity": (40.0, 100.0, "fib MC2010 5.1.9.4.2"),
        "notional_size": (50.0, 1500.0, "this project: the range of the codes' tables; "
                          "the formulas state no bound"),
        "temperature": (5.0, 30.0, "fib MC2010 5.1.9.4.2; other temperatures need 5.1.10"),
        "age_at_loading": (1.0, 3650.0, "fib MC2010 5.1.9.4.2 (>= 1 day); at most 10 years "
                           "(this project)"),
    },
    "eurocode2": {
        "fcm": (20.0, 98.0, "EN 1992-1-1 Table 3.1: C12/15 to C90/105"),
        "relative_humidity": (40.0, 100.0, "EN 1992-1-1 3.1.4(2)"),
        "notional_size": (50.0, 1500.0, "this project: Figure 3.1 covers 100 to 1500 mm; "
                          "the formulas of Annex B state no bound"),
        "temperature": (-40.0, 40.0, "EN 1992-1-1 3.1.4(2)"),
        "age_at_loading": (1.0, 3650.0, "EN 1992-1-1 Figure 3.1 starts at 1 day; at most "
                           "10 years (this project)"),
    },
}

#: A strength class, "C<fck>/<fck,cube>" (MPa; "c30/37" too).
STRENGTH_CLASS = re.compile(r"^\s*[Cc]\s*(\d{2,3})\s*/\s*(\d{2,3})\s*$")
#: The classes' cube strength by cylinder strength [MPa] (EN 1992-1-1 Table 3.1, and fib
#: MC2010 Table 5.1-1 to C120/140): a class is a pair of them ("C30/99" read as C30/37).
CUBE_STRENGTHS: dict[int, int] = {12: 15, 16: 20, 20: 25, 25: 30, 30: 37, 35: 45, 40: 50,
                                  45: 55, 50: 60, 55: 67, 60: 75, 70: 85, 80: 95, 90: 105,
                                  100: 115, 110: 130, 120: 140}


def _in_range(value: Any, model: str, name: str, field: str) -> float:
    x = finite_number(value, field, style=PYTHON_STYLE)
    low, high, source = RANGES[model][name]
    if not low <= x <= high:
        raise ValueError(f"{field}: must be in [{low:g}, {high:g}] ({source}), got "
                         f"{show_python(value)}")
    return x


def mean_strength(fcm: Any, strength_class: Any, model: str, field: str) -> float:
    """``fcm`` [MPa] from exactly one of ``fcm`` [MPa] and ``strength_class`` ("C30/37")."""
    if (fcm is None) == (strength_class is None):
        raise ValueError(f"{field}: give exactly one of fcm (mean cylinder strength, MPa) "
                         "and strength_class (e.g. 'C30/37')")
    if fcm is not None:
        return _in_range(fcm, model, "fcm", f"{field}.fcm")
    match = STRENGTH_CLASS.match(strength_class) if isinstance(strength_class, str) else None
    if match is None:
        raise ValueError(f"{field}.strength_class: must look like 'C30/37' (cylinder/cube "
                         f"strength in MPa), got {show_python(strength_class)}")
    fck, cube = int(match.group(1)), int(match.group(2))
    if CUBE_STRENGTHS.get(fck) != cube:
        known = ", ".join(f"C{a}/{b}" for a, b in CUBE_STRENGTHS.items())
        raise ValueError(f"{field}.strength_class: {show_python(strength_class)} is not a "
                         f"strength class ({known}); give fcm [MPa] for another concrete")
    low, high, source = RANGES[model]["fcm"]
    if not low <= fck + DELTA_F <= high:
        raise ValueError(f"{field}.strength_class: fcm = fck + {DELTA_F:g} MPa must be in "
                         f"[{low:g}, {high:g}] ({source}), got {fck + DELTA_F:g} MPa for "
                         f"{show_python(strength_class)}")
    return fck + DELTA_F


def _cement(value: Any, field: str) -> str:
    if not isinstance(value, str) or value not in CEMENT_CLASSES:
        raise ValueError(f"{field}: must be one of 'S' (slow), 'N' (normal), 'R' (rapid "
                         f"hardening), got {show_python(value)}")
    return value


@dataclass(frozen=True)
class CodeInputs:
    """Validated inputs shared by the code models (code units)."""

    model: str
    fcm: float                 # MPa
    cement: str                # S, N or R
    relative_humidity: float   # %
    notional_size: float       # mm
    temperature: float         # deg C
    strength_class: str | None = None


def check_inputs(model: str, spec: dict, field: str) -> CodeInputs:
    """Validate the fields of a code model (see ``RANGES``); ValueErrors name the field."""
    fcm = mean_strength(spec.get("fcm"), spec.get("strength_class"), model, field)
    return CodeInputs(
        model=model, fcm=fcm,
        cement=_cement(spec.get("cement", "N"), f"{field}.cement"),
        relative_humidity=_in_range(spec["relative_humidity"], model, "relative_humidity",
                                    f"{field}.relative_humidity"),
        notional_size=_in_range(spec["notional_size"], model, "notional_size",
                                f"{field}.notional_size"),
        temperature=_in_range(spec.get("temperature", 20.0), model, "temperature",
                              f"{field}.temperature"),
        strength_class=spec.get("strength_class"))

