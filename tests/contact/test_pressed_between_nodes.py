"""A punch held by its settlement and tilt that presses into the coating on a stretch
narrower than the nodal rule's spacing (core/contact/elastic.py,
``pressed_between_nodes``), and a zone the rule cannot resolve said as such.

A crowned punch (g = 0.1 x^2, m = 0.05, a/H = 1, tilt 0) held 1e-7 below its first
touch presses on +-1e-3, between the nodes of the nodal rule: it was answered "no
contact" (P = 0, q = 0) with success and an estimate of 0 (found by a stress test of the
solver). As the stretch narrows the base's share of the displacement vanishes beside the
coating's, so the force tends to the coating's alone (Winkler): P_w = (4/3) d^1.5 /
(sqrt(0.1) m).
"""

from __future__ import annotations

import numpy as np
import pytest

from core.solver import solve_dimensionless

M = 0.05


def _crown(settlement: float, tol: float = 1e-8):
    return solve_dimensionless(1.0, M, lambda x: 0.1 * x**2, [1.0], settlement=settlement,
                               tilt=0.0, tol=tol)


def _winkler(settlement: float) -> float:
    return 4.0 / 3.0 * settlement**1.5 / (np.sqrt(0.1) * M)


@pytest.mark.parametrize(("settlement", "share"), [(1e-7, (0.90, 0.93)),
                                                   (1e-9, (0.98, 0.995)),
                                                   (1e-10, (0.99, 0.998))])
def test_a_crown_pressed_between_the_nodes_carries_its_force(settlement: float,
                                                             share: tuple) -> None:
    answer = _crown(settlement)
    assert answer.info["success"] and answer.info["contact"] == "unilateral"
    (start, end), = answer.contact_set[0]
    half = np.sqrt(settlement / 0.1)  # where the punch meets the undeformed coating
    assert -half < start < 0.0 < end < half and start == pytest.approx(-end, rel=1e-9)
    # measured P / P_w: 0.913, 0.987, 0.996 (the base's share shrinks as the zone does)
    assert share[0] < answer.force[0] / _winkler(settlement) < share[1]
    assert answer.pressure(np.array([0.0]))[0, 0] > 0.0


def test_the_pressed_crown_converges_with_its_tol() -> None:
    """The answers at tol 1e-6 and 1e-10 agree within 1e-6 (relative, as tol)."""
    coarse, fine = _crown(1e-7, 1e-6), _crown(1e-7, 1e-10)
    assert coarse.info["success"] and fine.info["success"]
    x = np.linspace(-1e-3, 1e-3, 401)
    q = fine.pressure(x)[:, 0]
    assert np.max(np.abs(coarse.pressure(x)[:, 0] - q)) <= 1e-6 * np.max(np.abs(q))
    assert abs(coarse.force[0] - fine.force[0]) <= 1e-6 * abs(fine.force[0])


def test_a_crown_held_above_the_coating_has_no_contact() -> None:
    answer = _crown(-1e-9)
    assert answer.info["success"] and answer.contact_set[0] == []
    assert answer.force[0] == 0.0


def test_a_zone_below_the_rule_is_refused_saying_so() -> None:
    """A small force on a crown leaves fewer than three nodes in contact: refused with
    success False, where the message read "the loads pull the punch away" (the force
    pushes it in)."""
    answer = solve_dimensionless(1.0, M, lambda x: 0.01 * x**2, [1.0], force=1e-6,
                                 moment=2e-7, tol=1e-8)
    assert not answer.info["success"]
    message = answer.info["message"]
    assert "the contact zone is narrower than the solver's rule resolves" in message
    assert "pull the punch away" not in message


def test_two_crests_between_the_samples_are_both_found() -> None:
    """Two equal crests at x = +-0.5001 held 1e-10 below their touch press between the
    even sample's points: only the sample's largest value was looked at more finely, and
    one crest was dropped with success (P half, M not 0; found by a review)."""
    crests = lambda x: 0.1 * (np.abs(x) - 0.5001) ** 2  # noqa: E731
    answer = solve_dimensionless(1.0, M, crests, [1.0], settlement=1e-10, tilt=0.0,
                                 tol=1e-8)
    assert answer.info["success"]
    (a, b), (c, d) = answer.contact_set[0]
    assert a == pytest.approx(-d, rel=1e-9) and b == pytest.approx(-c, rel=1e-9)
    # each crest carries what the single crown does (Winkler share 0.996 at 1e-10)
    assert 0.99 < answer.force[0] / (2 * _winkler(1e-10)) < 0.998
    assert abs(answer.moment[0]) <= 1e-9 * answer.force[0]


def test_a_stretch_at_a_step_of_the_punch_is_pinned_at_its_corner() -> None:
    """g steps from 0.1 to 0 at the declared breakpoint 0.3 and the tilt leaves only
    (0.3, 0.3 + 2e-7) pressing: its left end was a root found inside the jump, not pinned
    at the corner, and the answer carried a negative force (P = -2e-9, success False)."""
    step = lambda x: np.where(np.asarray(x) > 0.3, 0.0, 0.1)  # noqa: E731
    tilt = -0.05
    answer = solve_dimensionless(1.0, M, step, [1.0], settlement=-tilt * (0.3 + 2e-7),
                                 tilt=tilt, tol=1e-8, breakpoints=(0.3,))
    assert answer.info["success"]
    (start, end), = answer.contact_set[0]
    assert start == 0.3 and 0.3 < end < 0.3 + 2e-7
    assert answer.force[0] > 0.0


def test_under_creep_a_stretch_between_the_nodes_is_refused_not_answered_empty() -> None:
    """The march has no start between the nodes: it answered the same crown "no
    contact", P = 0 at every time, with success; it now refuses, saying why."""
    from tests.support.scenes import CONCRETE

    with pytest.raises(ValueError, match="the contact zone is narrower than the solver's "
                                         "rule resolves"):
        solve_dimensionless(1.0, M, lambda x: 0.1 * x**2, [1.0, 2.0, 5.0],
                            settlement=1e-7, tilt=0.0, tol=1e-6,
                            c=CONCRETE.relative_modulus(28.0),
                            kernel=CONCRETE.dimensionless_kernel(28.0), contact="unilateral")
