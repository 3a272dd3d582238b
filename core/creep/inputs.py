"""Checked inputs of the creep models of :mod:`core.creep.models`: numbers, rates, Prony terms.

Every message names the field and the reason; models are built from Python as often as
from scene files, so the messages quote Python reprs.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import partial
from typing import Any

from core.validation import (
    PYTHON_STYLE,
    bounded_list,
    finite_number,
    nonnegative_number,
    positive_number,
    show_python,
)

#: Largest accepted creep rate [1/day]. Faster creep is instantaneous on any time scale
#: the model is meant for, and would only make the modal equations needlessly stiff.
MAX_RATE = 1e6

#: Largest number of Prony terms.
MAX_TERMS = 12

# ----------------------------------------------------------------------------- validation


# Models are built from Python as often as from scene files: their messages quote reprs.
_number = partial(finite_number, style=PYTHON_STYLE)
_positive = partial(positive_number, style=PYTHON_STYLE)
_nonnegative = partial(nonnegative_number, style=PYTHON_STYLE)


def _creep_coefficient(value: Any, field: str) -> float:
    x = _number(value, field)
    if x < 0:
        raise ValueError(
            f"{field}: must be >= 0, got {show_python(value)}: a negative value makes the "
            "compliance decrease in time, which is not creep")
    return x


def _rate(value: Any, field: str) -> float:
    x = _positive(value, field)
    if x > MAX_RATE:
        raise ValueError(f"{field}: must be <= {MAX_RATE:g} per day, got {show_python(value)}")
    return x


def _beta(value: Any, field: str) -> float:
    x = _number(value, field)
    if not 0 <= x < 1:
        raise ValueError(
            f"{field}: must be >= 0 and < 1 (the modulus at age 0 is "
            f"modulus_final (1 - beta)), got {show_python(value)}")
    return x


def _age_at_loading(value: Any, field: str) -> float:
    return _positive(value, field)


Terms = tuple[tuple[float, float, float], ...]


def _check_exponential(values: Mapping[str, Any], field: str) -> dict[str, float]:
    return {"modulus": _positive(values["modulus"], f"{field}.modulus"),
            "compliance": _creep_coefficient(values["compliance"], f"{field}.compliance"),
            "rate": _rate(values["rate"], f"{field}.rate")}


def _check_arutyunyan(values: Mapping[str, Any], field: str) -> dict[str, float]:
    return {"modulus_final": _positive(values["modulus_final"], f"{field}.modulus_final"),
            "beta": _beta(values["beta"], f"{field}.beta"),
            "alpha": _nonnegative(values["alpha"], f"{field}.alpha"),
            "compliance_final": _creep_coefficient(values["compliance_final"],
                                                   f"{field}.compliance_final"),
            "aging": _creep_coefficient(values["aging"], f"{field}.aging"),
            "rate": _rate(values["rate"], f"{field}.rate")}


def _check_terms(terms: Any, field: str) -> Terms:
    """Prony terms as a tuple of (C_r, A_r, gamma_r) float triples, validated."""
    terms = bounded_list(terms, field, least=1, most=MAX_TERMS, what="terms", style=PYTHON_STYLE)
    checked = []
    for r, term in enumerate(terms):
        where = f"{field}[{r}]"
        if isinstance(term, (str, bytes)) or not isinstance(term, (list, tuple)) \
                or len(term) != 3:
            raise ValueError(f"{where}: must be a (compliance, aging, rate) triple, "
                             f"got {show_python(term)}")
        checked.append((_creep_coefficient(term[0], f"{where}.compliance"),
                        _creep_coefficient(term[1], f"{where}.aging"),
                        _rate(term[2], f"{where}.rate")))
    return tuple(checked)
