"""Functions of x or t given by a user: numbers, tables, parametric families, formulas.

Every coating, punch and load input is a :class:`Profile`, an immutable value with a
stable key (``profile_key``) that the stage caches use.

- ``build.py``: ``profile_from_spec`` and ``FAMILIES``, the one registry of the families
  (fields, building, the constant part, the screen's forms ``VARIATIONS``);
- ``base.py``: the ``Profile`` value and the helpers of single families;
- ``families.py``: the builders of the families; ``forms.py``: the screen's forms;
- ``tables.py``: profiles from uploaded CSV tables (``profile_from_csv``);
- ``expressions.py``, ``parser.py``, ``whitelist.py``: the formula parser (tokenizer and
  recursive descent over a whitelist of constants and functions; never ``eval``).
"""

from __future__ import annotations

from core.profiles.base import (
    INTERPOLATIONS,
    MAX_POLYNOMIAL_COEFFICIENTS,
    MAX_TABLE_BYTES,
    MAX_TABLE_ROWS,
    Profile,
    profile_values,
    shifted,
)
from core.profiles.build import (
    FAMILIES,
    HISTORY_FORMS,
    KINDS,
    VARIATIONS,
    check_range,
    history_form_of,
    profile_from_spec,
    variation_of,
    without_offset,
)
from core.profiles.expressions import parse_expression
from core.profiles.tables import profile_from_csv

__all__ = [
    "check_range",
    "FAMILIES",
    "history_form_of",
    "HISTORY_FORMS",
    "INTERPOLATIONS",
    "KINDS",
    "MAX_POLYNOMIAL_COEFFICIENTS",
    "MAX_TABLE_BYTES",
    "MAX_TABLE_ROWS",
    "parse_expression",
    "Profile",
    "profile_from_csv",
    "profile_from_spec",
    "profile_values",
    "shifted",
    "variation_of",
    "VARIATIONS",
    "without_offset",
]
