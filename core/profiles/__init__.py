"""core.profiles.build."""

from __future__ import annotations

from core.profiles.base import MAX_TABLE_BYTES, Profile
from core.profiles.build import (
    HISTORY_FORMS,
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
    "history_form_of",
    "HISTORY_FORMS",
    "MAX_TABLE_BYTES",
    "parse_expression",
    "Profile",
    "profile_from_csv",
    "profile_from_spec",
    "variation_of",
    "VARIATIONS",
    "without_offset",
]
