"""The estimate of a lift-off under creep covers q, not only the histories
(core/contact/creep.py: ``_distance``, ``free_end_slope``, ``controlled_march``).

Found by ``benchmarks/creep_honesty.py``: a crown sinking into a creeping base claimed
success at tol 1e-4 with q off by 1.4e-3 beside the edges its zone spread to (the
histories, integrals of q, were within 1.7e-6 and were all the time grids compared); on
an aging base lifting off (e = 0.45) the estimate at tol 1e-6 was 1.8e-7 while q beside
the free end was off by 4.7e-7 (the end off by 2.9e-7 half-widths, q's slope there times
that is not in the histories either).
"""

from __future__ import annotations

import numpy as np
import pytest

from core.contact.creep import free_end_slope
from core.contact.result import UNILATERAL_MARGIN
from core.creep.kernels import DegenerateKernel
from core.solver import solve_dimensionless
from tests.support.creep_laws import sparse_preset
from tests.support.points import whole_interval
from tests.support.scenes import CONCRETE

EXPONENTIAL = DegenerateKernel(age_at_loading=1.0, modulus_final=1.0, beta=0.0, alpha=0.0,
                               terms=((1.5, 0.0, 0.8),))
#: q is compared at every output time on 2001 points of [-1, 1], the ends included
X = np.linspace(-1.0, 1.0, 2001)


def _q_error(answer, reference) -> float:
    exact = reference.pressure(X)
    return float(np.max(np.abs(answer.pressure(X) - exact)) / np.max(np.abs(exact)))


def _crown(tol: float):
    return solve_dimensionless(1.0, 0.05, lambda x: 0.02 * np.asarray(x) ** 2,
                               np.linspace(1.0, 12.0, 12), kernel=EXPONENTIAL, force=0.05,
                               moment=0.0, tol=tol, contact="unilateral")


def test_a_crown_spreading_over_a_creeping_base_is_within_tol_where_it_says_so() -> None:
    answer, reference = _crown(1e-4), _crown(1e-8)
    # the zone spreads from the elastic [-0.861, 0.861] to the whole base by t = 2
    assert answer.contact_set[0][0][0] == pytest.approx(-0.86145, abs=1e-5)
    assert answer.contact_set[1] == [(-1.0, 1.0)]
    assert answer.info["success"]
    # the reference is refused at 1e-8 (q's time grids stop at 6.5e-6: the points the
    # zone sweeps converge at order ~2.3, not the 3 the extrapolation assumes), but its
    # estimate is within a tenth of the tol judged; it is 6.6e-8 from a tol-1e-9 run
    assert reference.info["error_estimate"] <= 1e-5
    error = _q_error(answer, reference)
    # measured 7.5e-7 against the estimate 6.6e-6 (before: 1.4e-3 against 5.6e-6); the
    # same 7.5e-7 against a reference refined beyond the solver's limits
    # (benchmarks/results/creep_honesty.md)
    assert error <= answer.info["error_estimate"] <= 1e-4 / UNILATERAL_MARGIN
    # tol 1e-6 cannot be met on these grids: refused, with the same honest estimate
    tighter = _crown(1e-6)
    assert not tighter.info["success"] and "tol_not_met" in tighter.info["flags"]
    assert tighter.info["error_estimate"] > 1e-6 / UNILATERAL_MARGIN


def _aging(tol: float):
    return solve_dimensionless(1.0, 0.05, 0.0, 1.0 + np.linspace(0.0, 1000.0 / 28.0, 12),
                               c=CONCRETE.relative_modulus(28.0),
                               kernel=CONCRETE.dimensionless_kernel(28.0), force=1.0,
                               moment=0.45, tol=tol, contact="unilateral")


def test_q_beside_a_free_end_is_in_the_estimate_and_the_end_located_for_it() -> None:
    answer, reference = _aging(1e-6), _aging(1e-9)
    assert answer.info["zone_end_pressure_error"] > 0.0
    # the ends were located finer than the 1e-6 asked of them otherwise: measured 1.2e-7
    # (before: 4.8e-7, and q beside them 4.7e-7 off under an estimate of 1.8e-7)
    assert answer.info["zone_end_error"] < 2.5e-7
    # Within tol 1e-6: q on the panels holding the free ends is the kink-corrected
    # pressure, cut at the ends (core.contact.march.kink_correction), so it vanishes at
    # them. Measured: estimate 1.8e-7, q 4.6e-8 off against a reference refined beyond the
    # solver's limits (benchmarks/results/creep_honesty.md), 4.3e-8 against the one here
    # (tol 1e-9, the same finest band panels, its estimate 8.7e-8). With q taken on the
    # end panel's Gauss rule across the kink, it gave 2.2e-7 of max q at its own ends, q
    # was 2.3e-7 off, and the answer was refused (estimate 4.0e-7 against tol / 3).
    assert answer.info["success"] and not answer.info["flags"]
    assert answer.info["error_estimate"] <= 1e-6 / 3
    assert reference.info["error_estimate"] <= 2e-7
    error = _q_error(answer, reference)
    assert error <= answer.info["error_estimate"] + reference.info["error_estimate"]
    # q at the reported free ends: it vanishes there to the ends' own shift between the
    # time grids (the correction is the finer grid's)
    scale = float(np.max(np.abs(answer.pressure(np.linspace(-1.0, 1.0, 2001)))))
    for k, zones in enumerate(answer.contact_set):
        for lo, hi in zones:
            free = [end for end in (lo, hi) if abs(end) < 1.0]
            assert np.all(answer.pressure(free)[:, k] <= 1e-8 * scale), (k, free)


def test_the_slope_at_a_free_end_is_read_from_the_nodes_inside_the_zone() -> None:
    nodes = np.linspace(-1.0, 1.0, 2001)
    # q = 3 (x - c) on [c, 1], 0 off it, at two times with different free ends
    ends = [[-0.5, 1.0], [-0.2, 1.0]]
    q = np.column_stack([np.where(nodes >= c, 3.0 * (nodes - c), 0.0) for c, _ in ends])
    slope = free_end_slope(nodes, q, ends, ())
    assert slope == pytest.approx(3.0 / np.max(q), rel=1e-9)
    # an end at a corner or at a breakpoint is not free (q need not vanish there)
    assert free_end_slope(nodes, q, [[-1.0, 1.0], [-1.0, 1.0]], ()) == 0.0
    assert free_end_slope(nodes, q, ends, (-0.5, -0.2)) == 0.0
    # a zone's right end: the slope is read on its left
    q_right = np.where(nodes <= 0.4, 2.0 * (0.4 - nodes), 0.0)[:, None]
    assert free_end_slope(nodes, q_right, [[-1.0, 0.4]], ()) == pytest.approx(
        2.0 / np.max(q_right), rel=1e-9)


def _beside_step(tol: float, modulus: float = 1.0e9):
    """The stepped punch preset with a 1 GPa coating (``modulus`` [Pa]), twelve output
    times: as the base relaxes under the held settlement its outer parts lift off beside
    the steps, with free ends 0.0004-0.0027 half-widths outside the breakpoints at +-0.4."""
    from core.presets import read_preset
    from core.scene import scene_from_dict
    from core.scene.dimensionless import to_dimensionless

    data = read_preset("stepped_punch")
    data["coating"][0]["modulus"] = modulus
    data["times"] = {"end": 365.0, "count": 12, "spacing": "log"}
    data["solver"]["tol"] = tol
    problem = to_dimensionless(scene_from_dict(data))
    return solve_dimensionless(problem.lam, problem.m, problem.g, problem.times,
                               c=problem.c, kernel=problem.kernel,
                               breakpoints=problem.breakpoints, tol=tol,
                               contact="unilateral", **problem.loads)


def _within_reference(answer, reference) -> None:
    """q and the zone ends of ``answer`` within its estimate and the reference's."""
    error = _q_error(answer, reference)
    assert error <= answer.info["error_estimate"] + reference.info["error_estimate"]
    for mine, exact in zip(answer.contact_set, reference.contact_set, strict=True):
        assert len(mine) == len(exact)
        ends = np.subtract(np.ravel(mine), np.ravel(exact))
        assert np.max(np.abs(ends)) <= (answer.info["zone_end_error"]
                                        + reference.info["zone_end_error"])


def test_a_free_end_beside_a_step_is_located_with_band_panels_finer_than_0_005(
        monkeypatch: pytest.MonkeyPatch) -> None:
    answer = _beside_step(1e-6)
    # Before, the band panels stopped at 0.005 wide, where the check left these ends
    # 9.4e-8 off against the 2e-8 that q beside them asks (its slope is steep beside the
    # step): refused, estimate 5.7e-7 (q at the ends 5.5e-7) against tol / 3. With
    # 0.0025: ends to 8.8e-9, estimate 7.4e-8.
    assert answer.info["success"] and not answer.info["flags"]
    assert answer.info["zone_end_error"] <= 2e-8
    assert any(abs(abs(lo) - 0.4) < 3e-3 and abs(lo) > 0.4
               for zones in answer.contact_set for lo, _ in zones)
    # a reference with band panels down to 0.00125 (as benchmarks/creep_honesty.py
    # refines its own): estimate 4.6e-8, ends to 7.4e-9
    monkeypatch.setattr("core.contact.creep.BAND_WIDTHS",
                        (0.02, 0.01, 0.005, 0.0025, 0.00125))
    reference = _beside_step(1e-9)
    assert reference.info["error_estimate"] <= 1e-7
    _within_reference(answer, reference)


@pytest.mark.slow
def test_a_steeper_end_beside_a_step_is_located_again_when_its_slope_asks(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # At 1.5 GPa the locating march reads q's slope beside the ends too low for the last
    # resort of the band widths (0.0025): the first run stops at 0.005 with the ends
    # 5.7e-8 off and q beside them 4.8e-7 (refused before, estimate 5.1e-7 against
    # tol / 3). The slope read on the chosen rule asks for 0.0025, and the ends are located
    # again from 0.005: estimate 8.1e-8, q 1.6e-8 and the ends 2.3e-9 off the reference.
    widths: list[float] = []
    from core.contact import creep

    select = creep._select_rule

    def spy(*args, **kwargs):
        answer = select(*args, **kwargs)
        widths.append(answer[3]["width"])
        return answer

    monkeypatch.setattr(creep, "_select_rule", spy)
    answer = _beside_step(1e-6, 1.5e9)
    assert widths == [0.005, 0.0025]
    assert answer.info["success"] and not answer.info["flags"]
    monkeypatch.setattr(creep, "BAND_WIDTHS", (0.02, 0.01, 0.005, 0.0025, 0.00125))
    reference = _beside_step(1e-9, 1.5e9)
    assert reference.info["error_estimate"] <= 1e-7
    _within_reference(answer, reference)


#: q at the punch's edges, where the rules' check missed it: the last 1e-2 of [-1, 1]
#: on a geometric grid down to 1e-10 from +-1, with the 2001 points
EDGES = whole_interval(2001, near=40, farthest=1e-2)


@pytest.mark.parametrize("tol", [1e-6, 1e-7])
def test_q_at_the_edges_is_in_the_estimate_of_the_rules(tol: float) -> None:
    """The rules' check compared the four histories only: a flat punch in full contact on
    a creeping base, answered by the lift-off solver, claimed success at tol 1e-6 with q
    off by 1.1e-6 at x = 0.999995 (estimate 1.1e-7); with q compared but the base not
    refined (no band panels to narrow, the same rule was compared with itself) tol 1e-7
    claimed success 2.9e-7 off (estimate 6.3e-9). Its reference: the full-contact answer
    at tol 1e-11 (its distance to tol 1e-10: 2.6e-12)."""
    args = dict(lam=1.0, m=0.05, g=0.0, times=np.linspace(1.0, 12.0, 9), kernel=EXPONENTIAL,
                force=1.0, moment=0.1)
    answer = solve_dimensionless(tol=tol, contact="unilateral", **args)
    reference = solve_dimensionless(tol=1e-11, contact="full", **args)
    exact = reference.pressure(EDGES)
    error = float(np.max(np.abs(answer.pressure(EDGES) - exact)) / np.max(np.abs(exact)))
    assert answer.info["success"] and answer.contact_set[-1] == [(-1.0, 1.0)]
    # measured: 7.7e-8 (estimate 1.8e-7) at tol 1e-6, 2.0e-8 (estimate 2.7e-8) at 1e-7
    assert error <= tol
    assert error <= UNILATERAL_MARGIN * answer.info["error_estimate"]


@pytest.mark.slow
def test_two_punches_under_creep_estimate_q_at_their_edges() -> None:
    # The preset's two footings (fib MC2010), six log-spaced outputs, answered by the
    # lift-off solver (both stay in full contact): the full-contact answer at tol 1e-8
    # (estimate 6.0e-9) is the reference. The rules' check compared the histories only:
    # at tol 1e-7, success with q 1.9e-7 off at x = -0.999995 (estimate 1.2e-8). With q
    # compared between the rules, each punch's formula with the other's push: measured
    # 2.2e-8 against an estimate of 2.4e-8.
    exact = sparse_preset("new_footing_beside_old", "full", 1e-8)
    assert exact.info["success"] and not exact.flags
    answer = sparse_preset("new_footing_beside_old", "unilateral", 1e-7)
    assert answer.info["success"]
    for k, punch in enumerate(answer.punches):
        at = EDGES + punch.center  # (half-widths of 1 m)
        reference = exact.punches[k].pressure_at(at)
        error = np.max(np.abs(punch.pressure_at(at) - reference)) / np.max(np.abs(reference))
        assert error <= UNILATERAL_MARGIN * answer.info["error_estimate"] <= 1e-7, k


def _heel(tol: float):
    return solve_dimensionless(1.0, 0.05, 0.0, np.linspace(1.0, 12.0, 12), kernel=EXPONENTIAL,
                               force=1.0, moment=0.5, tol=tol, contact="unilateral")


@pytest.mark.slow
def test_q_at_the_toe_of_a_heel_lifting_off_is_in_the_estimate(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Under lift-off every time has a free end, and the rules' check compared q at none
    of them (the nodal q carries the end's kink there): the heel of ``liftoff_exp_PM`` in
    ``benchmarks/creep_honesty.py`` (e = 0.5) claimed success at tol 1e-6 with an
    estimate of 2.1e-7 and q at the toe 2.9e-7 off (against a tol-1e-9 answer with the
    finest band panels, made the new way; the benchmark's own reference had been as blind
    there). The rules' answers are now compared at the corners in contact too (their
    kink-corrected formulas at +-1), and the grading there halved while that misses:
    measured 7.4e-8 against an estimate of 3.0e-7 (before: 2.9e-7 against 2.1e-7; the
    reference graded 4, 16 or 64 times finer: the same to 2e-9)."""
    answer = _heel(1e-6)
    assert answer.info["success"] and answer.contact_set[0][0][0] > -1.0
    # The reference: tol 1e-8 (refused there, estimate ~7e-8) on a base rule graded 16
    # times finer at +-1 than the solver's (whatever its check says of the corners)
    from core.contact import unilateral
    from core.contact.zones import Resolution

    coarse = unilateral.creep_resolution

    def graded(lam, m):
        res = coarse(lam, m)
        return Resolution(res.width, res.edge / 16.0)

    monkeypatch.setattr(unilateral, "creep_resolution", graded)
    reference = _heel(1e-8)
    toe = np.concatenate([[1.0], 1.0 - np.geomspace(1e-10, 1e-2, 40)])
    exact = reference.pressure(toe)
    error = float(np.max(np.abs(answer.pressure(toe) - exact))
                  / np.max(np.abs(reference.pressure(X))))
    assert error <= answer.info["error_estimate"] <= 1e-6 / UNILATERAL_MARGIN


@pytest.mark.slow
def test_q_at_the_corners_a_spreading_crown_reaches_is_in_the_estimate(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A crown on a fast-creeping base (kernel (8, 3)) spreads from +-0.86 to the whole
    punch by t = 2; afterwards no time has a free end, and the rules' check compared q at
    the nodes only: success at tol 1e-4 with an estimate of 1.4e-6 and q 1.3e-5 off at
    x = -0.999995 (an auditor's find, against references graded 16 and 64 times finer at
    the corners and at tol 1e-8 and 1e-9, which agree). The corners in contact are now
    compared at every time (and a rule without band panels refined on while it misses,
    up to MAX_CHECK_NODES): estimate 6.1e-6, q at the corners 3.7e-6 off."""
    from core.contact import creep, unilateral
    from core.contact.zones import Resolution
    from core.creep.kernels import DegenerateKernel

    fast = DegenerateKernel(age_at_loading=1.0, modulus_final=1.0, beta=0.0, alpha=0.0,
                            terms=((8.0, 0.0, 3.0),))

    def crown(tol: float):
        return solve_dimensionless(1.0, 0.05, lambda x: 0.02 * np.asarray(x) ** 2,
                                   np.linspace(1.0, 12.0, 12), kernel=fast, force=0.05,
                                   moment=0.0, tol=tol, contact="unilateral")

    answer = crown(1e-4)
    assert answer.info["success"] and answer.contact_set[-1] == [(-1.0, 1.0)]
    coarse = unilateral.creep_resolution

    def graded(lam, m):
        res = coarse(lam, m)
        return Resolution(res.width, res.edge / 16.0)

    monkeypatch.setattr(unilateral, "creep_resolution", graded)
    monkeypatch.setattr(creep, "MAX_HALVINGS", 6)
    reference = crown(1e-8)
    near = np.geomspace(1e-10, 1e-2, 40)
    corners = np.concatenate([[-1.0, 1.0], -1.0 + near, 1.0 - near])
    error = float(np.max(np.abs(answer.pressure(corners) - reference.pressure(corners)))
                  / np.max(np.abs(reference.pressure(X))))
    assert error <= answer.info["error_estimate"] <= 1e-4 / UNILATERAL_MARGIN


FAST = DegenerateKernel(age_at_loading=1.0, modulus_final=1.0, beta=0.0, alpha=0.0,
                        terms=((4.0, 0.0, 2.0),))


def _fast_crown(tol: float, force: float = 0.05):
    return solve_dimensionless(1.0, 0.05, lambda x: 0.02 * np.asarray(x) ** 2,
                               np.linspace(1.0, 12.0, 12), kernel=FAST, force=force,
                               moment=0.0, tol=tol, contact="unilateral")


@pytest.mark.slow
def test_a_corner_touching_down_between_steps_is_stepped_on() -> None:
    """A crown on a fast-creeping base (kernel (4, 2)) spreads to the whole punch at
    t = 1.0718050, inside the first step of every grid: q has a kink in time there, and
    Richardson's estimate of the grids read it low: success at tol 1e-4, estimate 1.6e-5,
    q 8.0e-5 off at x = -0.984, t = 2 (an auditor's find). The touchdown is now located
    (from the Nystrom pressure at the corners, on finer grids up to it) and every grid
    lands there: estimate 1.1e-5, q 4.2e-6 off (against a tol-1e-9 answer graded 64
    times finer at the corners, on grids landing there). The reference here: the answer
    at tol 1e-6 (refused at an estimate of 9.6e-7, 5.3e-7 off against that one)."""
    from core.contact import creep

    located: list[list[float]] = []
    changes = creep.corner_contact_changes

    def spy(run, floor=1e-9):
        located.append(changes(run, floor))
        return located[-1]

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(creep, "corner_contact_changes", spy)
        answer = _fast_crown(1e-4)
    assert answer.info["success"] and answer.contact_set[0] != [(-1.0, 1.0)]
    assert answer.contact_set[1] == [(-1.0, 1.0)]
    # the rule's check march put it at 1.2132, the finer grids up to it at 1.1388 and
    # 1.0735 (where the time grids land), their finest march at 1.07203 (measured: the
    # line through its steps beside it, 0.009 apart)
    assert located[0] == [pytest.approx(1.2132, abs=1e-3)]
    assert located[-2] == [pytest.approx(1.0735, abs=1e-3)]
    assert located[-1] == [pytest.approx(1.0718050, abs=3e-4)]
    reference = _fast_crown(1e-6)
    assert reference.info["error_estimate"] <= 1e-6
    points = np.concatenate([X, -1.0 + np.geomspace(1e-10, 1e-2, 40),
                             1.0 - np.geomspace(1e-10, 1e-2, 40)])
    exact = reference.pressure(points)
    error = float(np.max(np.abs(answer.pressure(points) - exact)) / np.max(np.abs(exact)))
    assert error <= answer.info["error_estimate"] <= 1e-4 / UNILATERAL_MARGIN


def test_both_corners_of_an_even_problem_touching_down_are_one_time() -> None:
    """The two corners of an even problem change sign at once, their values a few
    roundings apart (summed in opposite orders): located as two times 2e-16 apart, the
    grids made a step of zero width and the march read "the loads pull the punch away"
    (a reviewer's find, forces 0.048846 and 0.058846 of the crown above)."""
    for force in (0.045 + 0.015 * 10 / 39, 0.045 + 0.015 * 36 / 39):
        answer = _fast_crown(1e-4, force)
        assert answer.info["success"] and answer.contact_set[-1] == [(-1.0, 1.0)]
    from core.contact.creep import corner_contact_changes

    run = {"grid": np.array([1.0, 2.0]),
           "corner_pressure": np.array([[-0.3, -0.30000000000000016], [0.7, 0.7]])}
    # (their lines' roots: 1.3 and 1.3000000000000003)
    assert corner_contact_changes(run) == [1.3]


def test_a_corner_contact_change_is_the_root_of_its_nystrom_pressure() -> None:
    """The Nystrom pressure at +-1 (a panel's interpolant at its end, off the nodes) and
    the root of its line between the two steps where it changes sign."""
    from core.contact.creep import corner_contact_changes
    from core.contact.march import corner_pressure
    from core.discretize import Panels

    panels = Panels.from_edges(np.array([-1.0, -0.9, 0.0, 0.95, 1.0]))
    cubic = 0.3 - 0.2 * panels.nodes + 0.7 * panels.nodes**3
    assert corner_pressure(panels, cubic) == pytest.approx([-0.2, 0.8], abs=1e-13)
    grid = np.array([1.0, 1.5, 2.0, 3.0])
    # the left corner lifts off between 2 and 3 (root 2.25), the right touches down
    # between 1 and 1.5 (root 1.1); a flicker within rounding of zero is none
    corners = np.array([[0.3, 0.2, 0.1, -0.3], [-0.1, 0.4, 0.5, 0.6]])
    run = {"grid": grid, "corner_pressure": corners.T}
    assert corner_contact_changes(run) == pytest.approx([1.1, 2.25], abs=1e-14)
    run["corner_pressure"] = np.array([[1.0, 1e-12, -1e-12, 1e-12], [1.0] * 4]).T
    assert corner_contact_changes(run) == []
    # a corner hovering at contact within the floor asked (the solve's: 1e-3 tol)
    run["corner_pressure"] = np.array([[1.0, 5e-8, -5e-8, 5e-8], [1.0] * 4]).T
    assert corner_contact_changes(run, 1e-7) == []
    assert len(corner_contact_changes(run, 1e-8)) == 2
    assert corner_contact_changes({"grid": grid}) == []


def test_a_corner_change_is_located_on_finer_grids_up_to_it_and_not_on_an_output() -> None:
    """:func:`core.contact.creep._corner_kinks` on stand-in marches whose Nystrom pressure
    at +1 is ``d (1 + d / 2)``, ``d = t - t0`` (a simple root at t0): seen on the rule's
    check march, located on the grid one halving finer and then zoomed, each march
    stopping at the step that holds it; at an output time (which every grid holds) or
    within a sliver of one, none, and no march beyond the check."""
    from core.contact.creep import _corner_kinks

    class StandIn:
        def __init__(self, t0: float) -> None:
            self.t0, self.grids = t0, []

        def run(self, base, grid, widths, index, exact_ends=True, first=None):
            self.grids.append(grid)
            d = grid - self.t0
            corners = np.column_stack([np.ones(grid.size), d * (1.0 + 0.5 * d)])
            return None, {"grid": grid, "corner_pressure": corners}

    times = np.linspace(1.0, 12.0, 12)
    for t0 in (3.0, 3.0 + 1e-6):
        marches = StandIn(t0)
        assert _corner_kinks(marches, times, None, 16, {}, (), 0, (), 1e-9) == []
        assert len(marches.grids) == 1
    marches = StandIn(3.3)
    # (its other root, t0 - 2 = 1.3, is a change too)
    located = _corner_kinks(marches, times, None, 16, {}, (), 0, (), 1e-9)
    assert located == [pytest.approx(1.3, abs=2e-4), pytest.approx(3.3, abs=2e-4)]
    # measured 1.2e-4 off: the zoom's steps 0.043, the root's curvature f''/f' = 1
    # the check march's step [3, 3.5] holds it: the finer grid's march stops at 3.5,
    # and the zoom's splits its step [3.25, 3.5] in eight
    check, finer, zoomed = marches.grids
    assert finer[-1] == zoomed[-1] == 3.5 and np.diff(finer).max() == 0.25
    assert np.allclose(np.diff(zoomed[zoomed >= 3.25]), 0.03125, rtol=1e-12, atol=0.0)


@pytest.mark.slow
def test_grids_that_ran_out_of_halvings_are_not_made_again_on_a_moved_change(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Where the finest grid puts a corner's change elsewhere than it was located, the
    grids are made again landing there, but not where they ran out of halvings: the
    answer is refused whatever they land on (a heel lifting off each half period at tol
    1e-6 took 26 s of CPU with them made again, 16 without, refused at 3.2e-5 either
    way). Forced here to read "moved" on the crown above: at tol 1e-4 (the grids met
    their part) they are made again, at tol 1e-7 (refused at 9.8e-7) not."""
    from core.contact import creep

    asked: list[float] = []
    in_time = creep._in_time

    def counted(*args, **kwargs):
        asked.append(args[4])
        return in_time(*args, **kwargs)

    monkeypatch.setattr(creep, "_in_time", counted)
    monkeypatch.setattr(creep, "_kinks_moved", lambda *args: True)
    assert _fast_crown(1e-4).info["success"] and len(asked) == 2
    asked.clear()
    refused = _fast_crown(1e-7)
    assert not refused.info["success"] and len(asked) == 1
    assert refused.info["time_error_estimate"] > 1e-7 / 6
