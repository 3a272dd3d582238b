"""Under creep a loose tol locates the zone ends less finely, and buys speed by it."""

from __future__ import annotations

import pytest

from core.contact import ZONE_END_TOL
from core.contact.creep import march_end_tol


def test_the_zone_ends_tolerance_under_creep_follows_a_loose_tol_only() -> None:
    assert march_end_tol(1e-8) == march_end_tol(1e-6) == ZONE_END_TOL
    assert march_end_tol(1e-5) == pytest.approx(ZONE_END_TOL, rel=1e-12)
    assert march_end_tol(1e-4) == pytest.approx(1e-5, rel=1e-12)
    assert march_end_tol(1e-3) == pytest.approx(1e-4, rel=1e-12)


def test_a_growing_eccentricity_at_a_loose_tol_takes_fewer_nodes() -> None:
    """A heel lifting further as the base creeps (e(t) 0.3 -> 0.6 a, an exponential
    kernel), tol 1e-4: with its zone ends located to 1e-6 half-widths whatever tol was, its
    march took 1200 nodes and 5.6 s of CPU for an estimate of 4.4e-7 (the slider-speed
    goal is 1 s). To tol / 10 = 1e-5: 672 nodes, 0.9 s, estimate 8.8e-6, ends to 6.6e-6
    (measured); its largest error against the reference of ``benchmarks/creep_honesty.py``
    (28 s, not run here) is 1.7e-6, its ends 1.3e-7 from the finer answer's."""
    from benchmarks.creep_honesty import cases
    from core.solver import solve_dimensionless

    growing = next(c for c in cases() if c.key == "liftoff_exp_growing")
    answer = solve_dimensionless(tol=1e-4, contact=growing.contact, **growing.at(1e-4))
    info = answer.info
    assert info["success"], info["message"]
    assert info["zone_end_error"] <= march_end_tol(1e-4)
    assert info["n_nodes"] < 1000, info["n_nodes"]  # 1200 with the ends to 1e-6
