"""A zone that shrinks toward the corner keeps an estimate of its error
(core/contact/zones.py: ``_moved_ends_error``).

At e = 0.99 a and 0.999 a the zone is 0.03 and 0.003 half-widths wide, narrower than the
panels of the rules whose difference is the estimate: both rules held the same panels on
it, and the estimate read exactly 0.0 while the settlement was 4.8e-12 and 1.2e-9 off.
"""

from __future__ import annotations

import numpy as np
import pytest

from core.contact.result import UNILATERAL_MARGIN
from core.solver import solve_dimensionless

X = np.linspace(-1.0, 1.0, 20001)


def _solve(e: float, tol: float):
    return solve_dimensionless(1.0, 0.05, 0.0, [1.0], force=1.0, moment=e, tol=tol)


@pytest.mark.parametrize(("e", "width"), [(0.99, 0.0307), (0.999, 0.0030)])
def test_a_narrow_zone_has_a_nonzero_estimate_that_covers_its_error(e: float,
                                                                    width: float) -> None:
    answer, reference = _solve(e, 1e-6), _solve(e, 1e-10)
    assert answer.info["success"] and answer.info["contact"] == "unilateral"
    (start, end), = answer.contact_set[0]
    assert end == 1.0 and 1.0 - start == pytest.approx(width, rel=0.02)
    estimate = answer.info["error_estimate"]
    assert estimate > 0.0
    kin = max(abs(reference.settlement[0]), abs(reference.tilt[0]))
    q_ref = reference.pressure(X)
    errors = [abs(answer.settlement[0] - reference.settlement[0]) / kin,
              abs(answer.tilt[0] - reference.tilt[0]) / kin,
              float(np.max(np.abs(answer.pressure(X) - q_ref)) / np.max(np.abs(q_ref)))]
    # The reference's rule is no finer on a zone this narrow (its own estimate: 2.5e-12
    # and 4.9e-10); measured: 4.8e-12 / 1.2e-9 (settlement, tilt) and 2.5e-12 / 6.3e-10
    # (q) against the estimates 3.9e-12 / 7.0e-10: 1.2 and 1.75 times the estimate,
    # within the margin success allows the unilateral estimates (UNILATERAL_MARGIN: they
    # may read up to ~3x low). With numpy 2.4 and scipy 1.17 the narrower zone's errors
    # are 3.8e-12 and its estimate read 2.6e-13 before the rounding floor
    # (core.contact.zones.ZONE_ROUNDING, 3e-12): the errors are rounding there.
    assert max(errors) <= UNILATERAL_MARGIN * estimate


def _wavy_scene(half_width: float) -> dict:
    """A punch with a 5 um wave of 0.5 m on a 2 m elastic base: it touches at its crests
    (12 zones, 22 free ends, at a half-width of 3 m)."""
    return {"schema_version": 1, "name": "wavy",
            "punch": {"half_width": half_width,
                      "shape": {"kind": "sine", "mean": 0.0, "amplitude": 5e-6,
                                "wavelength": 0.5, "phase": 0.0}},
            "coating": [{"thickness": 0.01, "modulus": 2e8, "poisson": 0.3}],
            "base": {"thickness": 2.0, "poisson": 0.2, "age_at_loading": 28.0,
                     "creep": {"model": "elastic", "modulus": 3e10}},
            "loading": {"force": 5e5, "moment": 0.0},
            "times": {"end": 365.0, "count": 3, "spacing": "linear"},
            "solver": {"tol": 1e-3}}


def test_many_free_ends_are_moved_on_a_sample_whose_bound_covers_the_sum(monkeypatch) -> None:
    """Moving every one of many free ends cost a solve each (the explorer's half-width
    slider on the wavy punch at 9.2 m: 73 ends, 32 s). Where a sample's bound is
    negligible against tol it stands for the sum, which it must not under-read; the
    answer itself does not change."""
    from core.contact import zones
    from core.scene import solve

    seen: list[tuple[int, float, int]] = []
    measure = zones._moved_ends_error

    def recorded(*args, **kwargs):
        value, made = measure(*args, **kwargs)
        seen.append((len(args[3]), value, made))
        return value, made

    monkeypatch.setattr(zones, "_moved_ends_error", recorded)
    # measured whatever the rules' difference reads (q's change between the rules now
    # outweighs these ends' error, so the estimate would not move them)
    monkeypatch.setattr(zones.OnePunch, "needs_moved",
                        staticmethod(lambda error, end_error: end_error < np.inf))
    sampled = solve(_wavy_scene(3.0))
    sample = zones.MOVED_SAMPLE
    monkeypatch.setattr(zones, "MOVED_SAMPLE", 10**6)
    exact = solve(_wavy_scene(3.0))
    (ends, bound, made), (ends_all, total, made_all) = seen
    assert ends == ends_all == 22
    assert made == sample and made_all == 22
    # measured: the bound 7.4e-14, the sum of the 22 changes 1.3e-14
    assert total <= bound <= zones.MOVED_NEGLIGIBLE * 1e-3
    assert sampled.info["success"] and len(sampled.contact_set[0]) == 12
    np.testing.assert_array_equal(sampled.settlement, exact.settlement)
    np.testing.assert_array_equal(sampled.pressure_on_grid, exact.pressure_on_grid)
