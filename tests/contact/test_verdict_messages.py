"""A lift-off answer flagged ``tol_not_met`` says what missed, in numbers.

Its estimate is held to tol with a margin of 3 (``UNILATERAL_MARGIN``): an estimate of
5.4e-7 at tol 1e-6 was flagged while its message said only "estimated error 5.4e-07 ...;
not within tol 1.0e-06", which read as a contradiction.
"""

from __future__ import annotations

from core.contact import ZONE_END_TOL
from core.contact.elastic import verdict
from core.contact.result import UNILATERAL_MARGIN, not_within_tol


def test_an_estimate_inside_tol_but_not_its_third_says_the_margin() -> None:
    text = not_within_tol(5.4e-7, 4.8e-8, 1e-6, ZONE_END_TOL)
    assert "3 x the estimated error = 1.6e-06 is over tol 1.0e-06" in text
    assert "zone ends" not in text


def test_the_zone_ends_are_named_when_they_miss() -> None:
    text = not_within_tol(1e-9, 2.5e-6, 1e-6, ZONE_END_TOL)
    assert text == "; not within tol: the zone ends' error 2.5e-06 is over 1e-06 half-widths"


def test_a_success_has_nothing_to_say() -> None:
    assert not_within_tol(1e-7, 1e-8, 1e-6, ZONE_END_TOL) == ""
    assert UNILATERAL_MARGIN * 1e-7 <= 1e-6


def test_the_elastic_verdict_carries_it() -> None:
    info = verdict(5.4e-7, 4.8e-8, True, True, 1e-6, "elastic")
    assert not info["success"] and info["flags"] == ["tol_not_met"]
    assert info["message"].endswith("(these estimates have read up to 3x low)")
    converged = verdict(1e-9, 1e-9, True, False, 1e-6, "elastic")
    assert converged["message"].endswith("; the zone ends did not converge")
