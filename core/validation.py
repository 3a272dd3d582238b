"""Checks of single numbers given by a user, with messages that start with the field.

The scene loader (:mod:`core.scene`) and the creep models (:mod:`core.creep`) refuse the
same values: anything that is not a real number (strings, ``null``/``None``, lists,
objects), booleans, NaN, infinities and integers too large for a double. They word the
refusal for different readers, so each check takes a :class:`Style`:

- :data:`JSON_STYLE` quotes values as a scene file writes them (``true``, ``null``,
  ``1e+06``, "a list") and asks for "a finite number";
- :data:`PYTHON_STYLE` quotes Python reprs (``True``, ``None``, ``1000000.0``) for models
  built in Python code, and asks for "finite".
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

#: Integers with more digits are quoted by their first digits and their length, so that a
#: 4000-digit integer (valid JSON) still gives a one-line message.
MAX_QUOTED_DIGITS = 40
#: Largest magnitude of a dimensionless input the solver computes with (coefficients and
#: loads). Beyond it the Galerkin matrix over- or underflows in double precision
#: (m = 1e200 made it singular); physical scenes are far inside.
MAX_MAGNITUDE = 1e100


class NumberTooLarge(ValueError, OverflowError):
    """An integer beyond the range of a double.

    Also an :class:`OverflowError`, the error ``float()`` gives for it, so that callers
    which already turned that error into their own message keep doing so.
    """


def _integer_text(value: int) -> str:
    try:
        text = str(value)
    except ValueError:  # past sys.get_int_max_str_digits(): Python refuses to print it
        return "an integer too long to print"
    if len(text) <= MAX_QUOTED_DIGITS:
        return text
    return f"{text[:12]}... ({len(text)} digits)"


#: The longest repr of a value a message echoes (a string or an object), in characters.
SHOWN_REPR = 80


def show_value(value: Any) -> str:
    """``value`` as a scene file would write it, short enough for a one-line message."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, numbers.Integral):
        return _integer_text(int(value))
    if isinstance(value, numbers.Real):
        return f"{float(value):.6g}"
    # a whole object or list echoed back would bury the message
    if isinstance(value, Mapping):
        return "an object"
    if isinstance(value, (list, tuple)):
        return "a list"
    text = repr(value)
    # (an object's repr can hold a whole scene: 11 kB of one line, measured)
    return text if len(text) <= SHOWN_REPR else f"{text[:SHOWN_REPR - 3]}..."


def show_python(value: Any) -> str:
    """``value`` as Python code would write it (numpy scalars as plain numbers)."""
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        return _integer_text(int(value))
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return repr(float(value))
    return repr(value)


@dataclass(frozen=True)
class Style:
    """The wording of a family of messages.

    ``show`` renders the offending value; ``finite`` completes "must be ..." for NaN,
    infinities and integers too large for a double.
    """

    show: Callable[[Any], str]
    finite: str


JSON_STYLE = Style(show_value, "a finite number")
PYTHON_STYLE = Style(show_python, "finite")


def finite_number(value: Any, field: str, *, style: Style = JSON_STYLE) -> float:
    """``value`` as a finite float, else a ValueError whose message starts with ``field``.

    Raises :class:`NumberTooLarge` (a ValueError) for an integer beyond the doubles.
    """
    # bool is an int to Python, but true/false where a number belongs is a mistake
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{field}: must be a number, got {style.show(value)}")
    try:
        x = float(value)
    except OverflowError:
        # a JSON integer of 400 digits is valid JSON, but no double
        raise NumberTooLarge(f"{field}: must be {style.finite}, got an integer too large "
                             "for a double") from None
    if not math.isfinite(x):
        raise ValueError(f"{field}: must be {style.finite}, got {style.show(value)}")
    return x


def positive_number(value: Any, field: str, *, style: Style = JSON_STYLE,
                    unit: str = "") -> float:
    """:func:`finite_number`, and > 0; ``unit`` (e.g. ``"m"``, ``"days"``) follows both
    numbers of the message, as the JSON Schema's check words it."""
    x = finite_number(value, field, style=style)
    if x <= 0:
        after = f" {unit}" if unit else ""
        raise ValueError(f"{field}: must be > 0{after}, got {style.show(value)}{after}")
    return x


def nonnegative_number(value: Any, field: str, *, style: Style = JSON_STYLE) -> float:
    """:func:`finite_number`, and >= 0."""
    x = finite_number(value, field, style=style)
    if x < 0:
        raise ValueError(f"{field}: must be >= 0, got {style.show(value)}")
    return x


def bounded_list(value: Any, field: str, *, least: int, most: int, what: str,
                 style: Style = JSON_STYLE) -> list | tuple:
    """``value`` if it is a list (or tuple) of ``least`` to ``most`` entries, else a
    ValueError starting with ``field`` (``what`` names the entries: "layers", "terms")."""
    # a string is a sequence to Python, but a list of its characters is never meant
    if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple)):
        raise ValueError(f"{field}: must be a list of {what}, got {style.show(value)}")
    if not least <= len(value) <= most:
        raise ValueError(f"{field}: must hold {least} to {most} {what}, got {len(value)}")
    return value


def refuse_first(bad: Any, message: Callable[[int], str]) -> None:
    """Raise ``ValueError(message(i))`` for the first (flat) index ``i`` where the boolean
    array ``bad`` is true; nothing when it is false everywhere. ``message`` names the
    field and quotes the values at ``i``."""
    flags = np.asarray(bad, dtype=bool).ravel()
    if flags.any():
        raise ValueError(message(int(np.argmax(flags))))
