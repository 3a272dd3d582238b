"""Unilateral contact on a creeping base: the error control of the time stepping.

Each march (:mod:`core.contact.march`) takes implicit steps on a time grid with the
contact set found at every step, on one fixed panel rule with fine panels over the bands
the free zone ends sweep (:mod:`core.contact.bands`); the memory of past pressures is
:mod:`core.contact.memory`'s. This module chooses the rule and the grids and assembles
the result.

Errors: in time, the grid is halved and the outputs of successive grids extrapolated
(Richardson, ratio 4.0 of successive differences measured on the lift-off preset even as
the zone moves node by node; two grids suffice when the difference of their plain
outputs, which bounds the extrapolated one, meets tol); in space, the rule is compared
with the one of halved panels over a few of the output times (:func:`_select_rule`).
Where a corner of the punch touches down or lifts off between two steps, q has a kink
in time there: the grids are made again landing on it (:func:`corner_contact_changes`).
"""


from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from core.contact.bands import (
    BAND_WIDTHS,
    LAST_RESORT_BELOW,
    MAX_CHECK_NODES,
    band_rule,
    bands_from_ends,
    even_rule,
    merge_bands,
    mirrored_bands,
    pinned_end,
)
from core.contact.march import march, march_outputs, nodes_in, rule_operator
from core.contact.result import UNILATERAL_MARGIN, _Snapshot, not_within_tol
from core.contact.step import Space, Step, nystrom_pressure
from core.contact.systems import Mirror
from core.contact.zones import ZONE_END_TOL, Resolution
from core.discretize import (
    NODES_PER_PANEL,
    Panels,
    even_overall,
    even_per_node,
    operator_rows,
    panel_index,
)
from core.problem import accepts
from core.time import time_grid

#: Nominal steps of the first time grid over [1, t_end] (every output time is a grid
#: point; each interval between output times gets whole steps).
FIRST_STEPS = 16
#: Grid halvings at most (the cost doubles with each).
MAX_HALVINGS = 4
#: Most times the first interval after loading and after each load jump is halved toward
#: its start, the steps growing geometrically out of it (``time_grid(..., graded=)``; see
#: :func:`graded_halvings`): a design code's creep runs like ``(t - t0)^0.3`` just after a
#: load, which equal steps followed slowly. The 50-year fib MC2010 preset lifting off
#: (e = a / 2, 200 outputs) ran to 3184 steps and was refused (zone ends 4e-6
#: half-widths); graded ten times it took 836 steps and met tol 1e-4 with 4.6e-7 (zone
#: ends 1.9e-7).
GRADED_HALVINGS = 10
#: The move of a corner's change (:func:`corner_contact_changes`) between where it was
#: located before the time grids and where their finest march puts it, in steps of that
#: grid there, above which the grids are made again landing on the latter. A crown
#: spreading to +-1 on a fast creeping base (kernel (4, 2), tol 1e-6; touchdown at
#: t = 1.0718050) had it 0.0017 off (5 % of a step) before the grids, 8.5e-5 off on grids
#: landing there: the grids again moved q by 2.5e-8 (its error 5.6e-7 -> 5.3e-7).
KINK_MOVE = 0.1
#: Where a corner's change is located before the time grids (:func:`_corner_kinks`): on
#: the grid of this many halvings of the first, then again with the step that holds it
#: split into this many. Measured (the crown above; a heel lifting off as its
#: eccentricity grows, at t = 2.2425): 0.0017 and 0.0003 off, for 10-15 % more work than
#: the time grids alone (two halvings and 16 parts: 8.4e-5 and 0.0003, 25-30 %).
KINK_LEVEL = 1
KINK_ZOOM_STEPS = 8
#: A corner whose Nystrom pressure stays within this fraction of tol (of the largest
#: pressure at a corner) on both sides of a sign change has no kink to land on: it hovers
#: at contact, and its kink moves q by about as little.
KINK_FLOOR = 1e-3


def graded_halvings(kernel: Any, times: np.ndarray) -> int:
    """How many times the first interval is halved toward its start: until its first
    part is within the kernel's fastest decay time (``1 / max rate``), at most
    :data:`GRADED_HALVINGS` (and that for a kernel without rates). A slow kernel (the
    lift-off preset's aging law: rate 0.84 against a first interval of 0.036) is not
    graded."""
    rates = getattr(kernel, "rates", None)
    later = times[times > 1.0]
    if rates is None or not later.size:
        return GRADED_HALVINGS
    scale = float(later[0] - 1.0) * float(np.max(np.asarray(rates, dtype=float), initial=0.0))
    return int(np.clip(np.ceil(np.log2(max(scale, 1.0))), 0, GRADED_HALVINGS))


#: Where the steps are at most how long: (from, to, longest step) (``time_grid``).
Windows = Sequence[tuple[float, float, float]]
#: The longest step while a decay lasts [its decay time ``1 / rate``]
#: (:func:`transient_windows`).
TRANSIENT_STEP = 1.0
#: The least share of the kernel's decaying compliance whose decay gets a window. The
#: fitted design-code laws spread theirs over ~35 rates, each below 1.5 % apart from two
#: slower than 50 years; together their decays run smoothly in log time, which the graded
#: first interval follows (the fib MC2010 footing lifting off, 20 output times: ratios of
#: successive differences 3.95), and a window for each cost 1.5-2.3 times the CPU.
TRANSIENT_SHARE = 0.05


def transient_windows(kernel: Any, times: np.ndarray, jumps: Sequence[float], tol: float
                      ) -> tuple[tuple[float, float, float], ...]:
    """Where each decay of the kernel is stepped finely while it lasts, after loading and
    after each load jump: (from, to, longest step) (``time_grid(..., windows=)``).

    A rate ``r`` whose share ``f`` of the kernel's decaying compliance (``|a_r| / r`` of
    ``exponential_parts`` at the start, over their sum) is above ``tol`` and
    :data:`TRANSIENT_SHARE` is stepped at most :data:`TRANSIENT_STEP` ``/ r`` apart until
    ``f exp(-r s)`` falls below ``tol`` (``s`` = ``ln(f / tol) / r`` after the start; a load
    jump starts every decay again, so a window stops there). Why: steps much longer than ``1
    / r`` leave the halved grids outside their asymptotic range, so their differences shrink
    slower than order 2 and Richardson's estimate reads low. Measured on the design chart's
    aging law (Arutyunyan, one rate of 0.84, outputs at loading and 50 years only, full
    contact marched): errors 7.6, 6.4, 4.7, 2.9, 1.3 (x1e-7 of a settlement of 7.4e-5) over
    grids of 18 to 273 points, the estimate 6 times below the error; with steps at most one
    decay time for 14 of them, 2.3, 0.65, 0.17, 0.042, 0.011, ratios 3.6 to 4.0, the
    estimate 2 times above it. Half a decay time did no better on the whole: the design
    chart's lift-off points met tol with a halving less, the crowned default (R = 10 km, tol
    1e-6) took 8.9 s instead of 6.8. A kernel without rates gets none."""
    rates = getattr(kernel, "rates", None)
    parts = getattr(kernel, "exponential_parts", None)
    if rates is None or parts is None or not times.size:
        return ()
    rates = np.asarray(rates, dtype=float)
    end = float(times[-1])
    starts = [1.0] + sorted(float(j) for j in jumps if 1.0 < float(j) < end)
    windows: list[tuple[float, float, float]] = []
    for start, stop in zip(starts, starts[1:] + [end], strict=True):
        weight = np.abs(np.asarray(parts(np.array([start])), dtype=float)[:, 0]) / rates
        share = weight / max(float(weight.sum()), 1e-300)
        for rate, part in zip(rates, share, strict=True):
            if part > max(tol, TRANSIENT_SHARE) and rate > 0.0:
                lasts = float(np.log(part / tol)) / float(rate)
                windows.append((start, min(start + lasts, stop), TRANSIENT_STEP / float(rate)))
    return tuple(windows)


#: Output times at most on the first grid of the spatial check, and of the march that
#: locates the bands the zone ends sweep (on a rule graded only to ``LOCATE_EDGE``).
CHECK_OUTPUTS = 12
LOCATE_OUTPUTS = 6
LOCATE_EDGE = 0.05
#: Spatial error of a rule per difference from the rule with halved panels. The error
#: fell irregularly with the band panels (it depends on where the ends sit among the
#: nodes): on the preset, with the kink correction of the ends, the largest end error
#: over the output times was 0.73 and 1.31 times the largest difference for bands 0.04
#: and 0.02 wide (against 0.0025; see tests/contact/test_contact.py), and 0.86 to 0.97 times the
#: difference the check takes (against a rule with every panel halved, 100 output
#: times), so 2 leaves a margin of 1.5.
SPACE_FACTOR = 2.0


def _borrow_corrections(coarse: dict[str, Any], fine: dict[str, Any]) -> None:
    """Give the uncorrected ends of ``coarse`` the kink corrections of ``fine`` (the same
    output times on a grid of halved steps), in place.

    The correction is a spatial effect of where an end sits in its panel, nearly the
    same on two time grids: on the 100-time preset with band panels 0.04 / 0.02 the
    corrections (up to 5.6e-6 / 2.3e-6) differed between the grids of 101 and 202 steps
    by 1.8e-8 / 2.3e-8, which enters the extrapolated ends divided by 3. So one set
    serves both members of a Richardson pair and the coarser march skips them. Times
    whose ends differ in number keep theirs (the time estimate then calls the topology
    unresolved)."""
    for k, (ends, nodal, exact) in enumerate(zip(coarse["nodal_ends"], fine["nodal_ends"],
                                                 fine["ends"], strict=True)):
        if len(ends) == len(nodal) == len(exact):
            coarse["ends"][k] = [e + (x - n) for e, n, x in zip(ends, nodal, exact,
                                                                  strict=True)]


def _extrapolate(fine: dict[str, Any], coarse: dict[str, Any]) -> dict[str, Any]:
    """Richardson ``(4 fine - coarse) / 3`` (the trapezoid is of order 2: measured ratio
    4.0 of successive differences on the lift-off preset, zone ends included). Zone ends
    are extrapolated where both grids found the same number of ends."""
    def mix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return (4.0 * np.asarray(a) - np.asarray(b)) / 3.0
    ends = [list(mix(ef, ec)) if len(ef) == len(ec) and ef else list(ef)
            for ef, ec in zip(fine["ends"], coarse["ends"], strict=True)]
    out = {key: mix(fine[key], coarse[key]) for key in ("settlement", "tilt", "force",
                                                        "moment", "effective", "q")}
    out["ends"] = ends
    out["c"] = fine["c"]
    # The kink correction is spatial: the finer grid's serves the extrapolated outputs, as
    # its end shifts serve the coarser grid's ends (_borrow_corrections, where those shifts
    # were measured the same on both grids to ~2e-8). The pressure it leaves at the
    # extrapolated ends is measured (free_end_residual): ~1e-8 of the largest q.
    out["corrections"] = fine.get("corrections")
    return out


def _distance(a: dict[str, Any], b: dict[str, Any]) -> tuple[float, float]:
    """(relative difference of the four histories and, on one panel rule, of q at the
    nodes at every output time; largest shift of a zone end).

    q is compared where both marches ran on the same rule (the time grids of one rule):
    the four histories are integrals of q and miss a local error of it, such as that of
    the points a zone sweeps as it spreads, whose pressure starts between two steps (a
    crown sinking into a creeping base: q off by 1.4e-3 at tol 1e-4, settlement 1.7e-6,
    ``benchmarks/creep_honesty.py``)."""
    kin = max(np.max(np.abs(a["settlement"])), np.max(np.abs(a["tilt"])), 1e-300)
    dyn = max(np.max(np.abs(a["force"])), np.max(np.abs(a["moment"])), 1e-300)
    outputs = max(np.max(np.abs(a["settlement"] - b["settlement"])) / kin,
                  np.max(np.abs(a["tilt"] - b["tilt"])) / kin,
                  np.max(np.abs(a["force"] - b["force"])) / dyn,
                  np.max(np.abs(a["moment"] - b["moment"])) / dyn)
    if a["q"].shape == b["q"].shape:
        scale = max(float(np.max(np.abs(a["q"]))), 1e-300)
        outputs = max(outputs, float(np.max(np.abs(a["q"] - b["q"]))) / scale)
    shift = 0.0
    for ea, eb in zip(a["ends"], b["ends"], strict=True):
        if len(ea) != len(eb):
            return float(outputs), np.inf  # the topology differs: not resolved in time
        if ea:
            shift = max(shift, float(np.max(np.abs(np.subtract(ea, eb)))))
    return float(outputs), shift


#: The other punches' part of q's formula at points ``x`` of one punch (several punches
#: on one base): for each, its rows there and its effective densities over the output
#: times, ``(rows (len(x), N_r), effective (N_r, times))``.
Others = Callable[[np.ndarray], Sequence[tuple[np.ndarray, np.ndarray]]]


def _q_between_rules(space: Space, rule: Panels, out: dict[str, Any], finer: Panels,
                     finer_out: dict[str, Any],
                     bands: Sequence[tuple[float, float]] = (),
                     others: Others | None = None) -> float:
    """The largest change of q at the nodes of ``rule`` (the march ``out`` on it) from the
    pressure formula of the march ``finer_out`` on the rule ``finer`` there
    (:func:`nystrom_pressure` of its effective density), relative to the largest q, at
    the output times where neither march has a free end (an end inside (-1, 1) off the
    breakpoints); nodes whose panel on either rule meets a band the free ends sweep
    (``bands``) are left out too (q kinks where the ends have been).

    The histories compared alone missed q's error at the punch's edges: 1.1e-6 at x =
    0.999995 on a creeping base at tol 1e-6, estimated 1.1e-7 (a flat punch in full
    contact, ``contact="unilateral"``). The finer rule's formula, not its panels'
    polynomials: those read q's log-like edge layer to O(h) only (5.5e-5 against 6.9e-6
    as the edge panels were halved, where the answers were within 7.6e-7 and 2e-8).
    Where a free end is, the nodal q of the marches carries the end's kink through the
    whole zone until the kink correction takes it out of the answer
    (core/contact/kinks.py): compared there it read 5.8e-7 at x = -0.455 on a crowned
    punch whose answer was within 5.8e-8 (and took the rule from 1056 to 1760 nodes);
    there the ends' error times q's slope beside them is q's estimate
    (``controlled_march``).

    ``others``: the other punches on the base push this one's surface too; their part
    of the formula (:data:`Others`, from the finer march)."""
    q = out["q"]
    times = [k for k in range(q.shape[1])
             if not _free_end_at(space, out, finer_out, k)]
    if q.size == 0 or not times or q.shape[1] != finer_out["q"].shape[1]:
        return 0.0
    x = rule.nodes
    own = np.repeat(np.arange(rule.n_panels), NODES_PER_PANEL)
    index = panel_index(finer, x)
    kept = np.ones(x.size, dtype=bool)
    for lo, hi in ((rule.centers[own] - rule.half_widths[own],
                    rule.centers[own] + rule.half_widths[own]),
                   (finer.centers[index] - finer.half_widths[index],
                    finer.centers[index] + finer.half_widths[index])):
        for a, b in bands:
            kept &= ~((lo <= b) & (a <= hi))
    if not kept.any():
        return 0.0
    x = x[kept]
    rows = operator_rows(space.lam, finer, x)
    pushing = () if others is None else others(x)
    worst = 0.0
    for k in times:
        # where both marches touch (zones may end at a step of the punch: off them q is 0
        # and the formula gives the gap's pull)
        inside = np.ones(x.size, dtype=bool)
        for ends in (out["ends"][k], finer_out["ends"][k]):
            inside &= nodes_in(x, list(zip(ends[0::2], ends[1::2], strict=True)))
        if not inside.any():
            continue
        push = sum((-(r[inside] @ effective[:, k]) for r, effective in pushing),
                   np.zeros(int(inside.sum())))
        formula = nystrom_pressure(
            space, Step(float(finer_out["c"][k]), 1.0, {}), finer,
            finer_out["effective"][:, k], float(finer_out["settlement"][k]),
            float(finer_out["tilt"][k]), x[inside], rows=rows[inside],
            memory_at=lambda _, push=push: push)
        worst = max(worst, float(np.max(np.abs(q[kept, k][inside] - formula))))
    return worst / max(float(np.max(np.abs(q))), 1e-300)


def _free_end_at(space: Space, out: dict[str, Any], finer_out: dict[str, Any], k: int
                 ) -> bool:
    """Whether either march has a free end (inside (-1, 1), off the breakpoints) at output
    time ``k``."""
    fixed = np.asarray(space.breakpoints, dtype=float)
    return any(-1.0 < e < 1.0 and not np.any(np.abs(fixed - e) <= 1e-12)
               for e in (*out["ends"][k], *finer_out["ends"][k]))


def corner_points(breakpoints: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """The punch's corners as (points, inward): +-1 from inside, each breakpoint from
    both sides (q may jump there) [half-widths]."""
    inner = [float(b) for b in breakpoints if -1.0 < float(b) < 1.0]
    points = np.array([-1.0, 1.0, *inner, *inner])
    inward = np.array([1.0, -1.0, *([-1.0] * len(inner)), *([1.0] * len(inner))])
    return points, inward


def _corner_q_between_rules(space: Space, rule: Panels, out: dict[str, Any],
                            finer: Panels, finer_out: dict[str, Any],
                            others: tuple[Others, Others] | None = None) -> np.ndarray:
    """The largest change of q at each of the punch's corners (:func:`corner_points`, a
    side in contact in both marches) between the answers of marches on two rules at every
    output time, each the kink-corrected pressure of :func:`output_snapshot`, relative to
    the largest q (NaN where never compared: no side of it in contact in both).

    :func:`_q_between_rules` leaves out the times with a free end, where the nodal q
    carries the end's kink: under lift-off, all of them, and q at the toe of a heel
    lifting off under strong creep was 3.85e-7 off (tol 1e-6, against a reference graded
    eight times finer there) with a spatial estimate of 7.8e-9. The corrected answers
    compared at the corners, where q is steepest and the grading there tells, read 1.1e-6,
    2.9e-7 and 7.6e-8 as the edge panels went from 0.01 to 0.0025 (measured). At the
    other times its nodes stop short of the corners: a crown spread over the whole punch
    on a fast-creeping base had q 1.3e-5 off at x = -0.999995 at tol 1e-4, estimated
    1.4e-6 (an auditor's find).

    ``others``: the other punches on the base push this one's surface too
    (:data:`Others`: of the march ``out``, then of ``finer_out``)."""
    points, inward = corner_points(space.breakpoints)
    scale = max(float(np.max(np.abs(out["q"]), initial=0.0)), 1e-300)
    worst = np.full(points.size, np.nan)
    if out["q"].size == 0 or out["q"].shape[1] != finer_out["q"].shape[1]:
        return worst
    answers = [(rule, out, operator_rows(space.lam, rule, points)),
               (finer, finer_out, operator_rows(space.lam, finer, points))]
    pushes = ((), ()) if others is None else (others[0](points), others[1](points))
    beside = points + 1e-9 * inward  # (a side in contact: a point just beside it in a zone)
    for k in range(out["q"].shape[1]):
        zones = [_ends_zones(answer["ends"][k]) for _, answer, _ in answers]
        inside = nodes_in(beside, zones[0]) & nodes_in(beside, zones[1])
        if not inside.any():
            continue
        values = []
        for (panels, answer, rows), mine, pushing in zip(answers, zones, pushes, strict=True):
            snap = output_snapshot(panels, answer, k, mine)
            own = snap.displacement(space.lam)
            push = sum((-(r[inside] @ effective[:, k]) for r, effective in pushing),
                       np.zeros(int(inside.sum())))

            def displacement(t: np.ndarray, own: Any = own, push: Any = push) -> np.ndarray:
                return push if own is None else own(t) + push

            values.append(nystrom_pressure(space, snap.step, snap.panels, snap.q,
                                           snap.settlement, snap.tilt, points[inside],
                                           inward[inside], displacement,
                                           rows=rows[inside]))
        worst[inside] = np.fmax(worst[inside], np.abs(values[0] - values[1]))
    return worst / scale


def largest_part(parts: np.ndarray) -> float:
    """The largest of the corners' parts, those never compared (NaN) aside; 0 if none."""
    parts = np.asarray(parts, dtype=float)
    return float(np.nanmax(parts)) if np.isfinite(parts).any() else 0.0


def corners_refined(space: Space, rule: Panels, finer: Panels) -> np.ndarray:
    """Whether ``finer``'s panel beside each corner (:func:`corner_points`, on its side)
    is narrower than ``rule``'s: the grading at +-1 and the breakpoints halved, or band
    panels over a breakpoint narrowed. Where it is not, the two rules' q there differs by
    next to nothing, whatever either's error."""
    points, inward = corner_points(space.breakpoints)
    beside = points + 1e-9 * inward
    return (finer.half_widths[panel_index(finer, beside)]
            < (1.0 - 1e-9) * rule.half_widths[panel_index(rule, beside)])


def _ends_zones(ends: Sequence[float]) -> list[tuple[float, float]]:
    """A time's zone ends (start, end, start, ...) as its zones."""
    return [(float(ends[2 * i]), float(ends[2 * i + 1])) for i in range(len(ends) // 2)]


def _rule_distance(space: Space, rule: Panels, out: dict[str, Any], finer: Panels,
                   finer_out: dict[str, Any], bands: Sequence[tuple[float, float]] = ()
                   ) -> tuple[float, float, np.ndarray, np.ndarray]:
    """:func:`_distance` of marches on two panel rules (``rule``, and every panel finer,
    ``finer``), q compared too where no free end is (:func:`_q_between_rules`) and at the
    punch's corners (:func:`_corner_q_between_rules`): (the largest relative difference,
    the largest shift of a zone end, each corner's part, whether ``finer`` is graded finer
    there, :func:`corners_refined`)."""
    outputs, shift = _distance(out, finer_out)
    corners = _corner_q_between_rules(space, rule, out, finer, finer_out)
    return (max(outputs, _q_between_rules(space, rule, out, finer, finer_out, bands),
                largest_part(corners)), shift, corners, corners_refined(space, rule, finer))


#: Under creep the zone ends are located to the larger of ``ZONE_END_TOL`` and this share
#: of tol [half-widths] (:func:`march_end_tol`), or finer where q beside them asks for it
#: (:func:`end_tol_for_q`).
END_TOL_SHARE = 0.1


def march_end_tol(tol: float) -> float:
    """The zone ends' own tolerance [half-widths] of a march under creep at ``tol``:
    ``ZONE_END_TOL`` (1e-6) at tol 1e-5 and finer, ``tol / 10`` above. A loose tol buys
    speed: at 1e-6 whatever tol was, the growing eccentricity of
    ``benchmarks/creep_liftoff_speed.py`` (tol 1e-4) took 1200 nodes and 5.6 s of CPU for
    an estimate of 4.4e-7; at 1e-5, 672 nodes and 0.85 s for 8.8e-6, its ends 1.3e-7 and
    its settlement 5e-8 from the finer answer's (measured)."""
    return max(ZONE_END_TOL, END_TOL_SHARE * tol)


#: The finest the zone ends are asked to for q beside them [half-widths]. What they
#: reach is set by the finest band panels: 7e-8 to 3e-7 measured on the scenes of
#: benchmarks/creep_honesty.py with panels 0.005 wide, 9e-9 with 0.0025 on the stepped
#: punch lifting beside its steps (``MAX_CHECK_NODES`` bounds how fine wide bands go).
MIN_END_TOL = 1e-8
#: Points of a zone nearer its free end than this [half-widths] do not give the slope of q
#: there: q at them is the nodal error as much as the slope times the distance.
SLOPE_NEAREST = 1e-3
#: ... nor do points farther than this (q bends away from its slope at the end).
SLOPE_REACH = 0.05


def free_end_slope(nodes: np.ndarray, q: np.ndarray, ends: Sequence[Sequence[float]],
                   breakpoints: Sequence[float]) -> float:
    """The largest slope of q at a free zone end over the output times, relative to the
    largest |q| [per half-width].

    q vanishes at a free end, so an end off by ``d`` moves q beside it by the slope times
    ``d``: the part of q's error the zone ends make (the four outputs, integrals of q, see
    only ``d^2``). The slope is the largest secant ``q(x) / |x - end|`` over the nodes
    ``x`` of the end's own zone within :data:`SLOPE_NEAREST` to :data:`SLOPE_REACH` of
    the end: where q rises steeply and then bends (a soft coating), the nearest secant is
    the steepest. A rise steeper still within SLOPE_NEAREST of the end (a boundary layer
    thinner than that) would be read low. Ends at +-1 or at a breakpoint (where q need not
    vanish: :func:`core.contact.bands.pinned_end`) are not free.

    ``nodes`` (N,) of the rule, ``q`` (N, T) its nodal pressure, ``ends[k]`` the zone ends
    at time k in pairs (start, end)."""
    scale = float(np.max(np.abs(q), initial=0.0))
    if scale == 0.0:
        return 0.0
    slope = 0.0
    for k, zone_ends in enumerate(ends):
        for j, end in enumerate(zone_ends):
            if pinned_end(end, breakpoints):
                continue
            start, stop = zone_ends[j - j % 2], zone_ends[j - j % 2 + 1]
            inward = (nodes - end) * (1.0 if j % 2 == 0 else -1.0)
            near = ((inward >= SLOPE_NEAREST) & (inward <= SLOPE_REACH)
                    & (nodes >= start) & (nodes <= stop))
            if near.any():
                slope = max(slope, float(np.max(np.abs(q[near, k]) / inward[near])))
    return slope / scale


def free_end_residual(space: Space, snapshots: Sequence[_Snapshot], scale: float) -> float:
    """The largest pressure the answer's own formula gives at its free zone ends over the
    output times, relative to ``scale`` (the largest |q|) [-].

    q vanishes at a free end. The ends reported are the roots of the kink-corrected
    pressure (:mod:`core.contact.kinks`), extrapolated in time, and q on the panels holding
    them is that corrected pressure from the finer time grid (:func:`output_snapshot`), cut
    at that grid's nodal end and given by the formula beyond it: what is left at a reported
    end is the two ends' difference times q's slope, ~1e-8 of the largest q (measured on
    the scenes of ``benchmarks/creep_honesty.py``). It is q's error beside the end on top of
    what the end's own error makes (:func:`free_end_slope`). With q on the end panel's
    Gauss rule across the kink it was 2.2e-7 on the aging base lifting off (e = 0.45, tol
    1e-6) and 2.0e-6 on the design chart's stiff coat. Ends at +-1 or at a breakpoint are
    not free. The snapshots share one panel rule: F's rows at every end are evaluated once.
    A snapshot's ``coupling`` (the other punches' displacement on one of several punches,
    :mod:`core.contact.coupled_creep`) and its cut parts are part of its formula."""
    found = [(k, end, inward) for k, snap in enumerate(snapshots) for lo, hi in snap.zones
             for end, inward in ((lo, 1.0), (hi, -1.0))
             if not pinned_end(end, space.breakpoints)]
    if scale <= 0.0 or not found:
        return 0.0
    owner = np.array([k for k, _, _ in found])
    at = np.array([end for _, end, _ in found])
    inward = np.array([side for _, _, side in found])
    rows = operator_rows(space.lam, snapshots[0].panels, at)
    worst = 0.0
    for k in np.unique(owner):
        mine = owner == k
        snap = snapshots[k]
        values = nystrom_pressure(space, snap.step, snap.panels, snap.q, snap.settlement,
                                  snap.tilt, at[mine], inward[mine],
                                  snap.displacement(space.lam), rows=rows[mine])
        worst = max(worst, float(np.max(np.abs(values))))
    return worst / scale


def end_tol_for_q(tol: float, slope: float, rest: float = 0.0) -> float:
    """The zone-end tolerance [half-widths] that leaves q beside the free ends (slope
    ``slope``, :func:`free_end_slope`) a third of what success allows of the estimate, or
    half of what the rest of it (``rest``) leaves, at most down to :data:`MIN_END_TOL`."""
    allowed = min(tol / 3.0, 0.5 * (tol - UNILATERAL_MARGIN * rest)) / UNILATERAL_MARGIN
    return max(allowed / slope, MIN_END_TOL)


def output_snapshot(base: Panels, out: dict[str, Any], k: int,
                    zones: list[tuple[float, float]]) -> _Snapshot:
    """The pressure of output time ``k`` of the outputs ``out`` on the rule ``base``: the
    kink-corrected solution where the march made the correction (the nodal one
    extrapolated in time plus the finer grid's correction, which is spatial), so that q
    vanishes at the free ends it reports; else the nodal one."""
    effective = out["effective"][:, k]
    delta, alpha = float(out["settlement"][k]), float(out["tilt"][k])
    corrections = out.get("corrections")
    change = None if corrections is None else corrections[k]
    if change is None:
        return _Snapshot(base, effective, delta, alpha, Step(float(out["c"][k]), 1.0, {}),
                         zones)
    cut = change["cut"] if change["cut"].n_panels else None
    return _Snapshot(base, effective + change["effective"], delta + change["settlement"],
                     alpha + change["tilt"], Step(float(out["c"][k]), 1.0, {}), zones,
                     cut=cut, cut_q=None if cut is None else change["cut_effective"])


def solve_creep(space: Space, inp: Any, c_t: np.ndarray, loads: dict[str, np.ndarray],
                res: Resolution, first_steps: int = FIRST_STEPS,
                jumps: Sequence[float] = ()) -> dict[str, Any]:
    """Time-step the unilateral problem under creep (see the module notes).

    ``first_steps`` nominal steps on the first grid; the grid is halved until the
    Richardson-extrapolated outputs of two successive pairs of grids agree to ``tol``/3
    (their difference / 7 is the estimate) or ``MAX_HALVINGS`` is reached. ``jumps``:
    times where a given load jumps (no step straddles one, :func:`time_grid`).
    """
    times = inp.times
    tol = inp.tol
    marches = OnePunchMarches(space, inp, even_problem(space, inp, loads))
    (base, out, run, band_note, strays, error, end_error, time_error,
     space_error, end_q_error) = controlled_march(marches, times, tol, res, first_steps,
                                                  jumps, graded_halvings(inp.kernel, times),
                                                  transient_windows(inp.kernel, times, jumps,
                                                                  tol))
    sweeps, steps = run["sweeps"], run["steps"]
    zones = _zones_of(out)
    snapshots = marches.snapshots(base, out)
    residual = marches.residual(base, out)
    error, end_q_error = error + residual, end_q_error + residual
    success, flags, message = creep_verdict(error, end_error, time_error, space_error, run,
                                            strays, tol, "under creep", end_q_error)
    info = {
        "contact": "unilateral",
        "error_estimate": error,
        "time_error_estimate": float(time_error),
        "spatial_error_estimate": float(space_error),
        "zone_end_error": end_error,
        "zone_end_pressure_error": float(end_q_error),
        "success": bool(success),
        "flags": flags,
        "message": message,
        "n_steps": int(steps),
        "n_nodes": int(base.size),
        "active_set_sweeps": int(sweeps),
        "end_bands": band_note["bands"],
        "band_panel_width": band_note["width"],
        "min_pressure": 0.0,
    }
    return {"settlement": out["settlement"], "tilt": out["tilt"], "force": out["force"],
            "moment": out["moment"], "contact_set": zones, "snapshots": snapshots,
            "info": info}


def _zones_of(out: dict[str, Any]) -> list[list[tuple[float, float]]]:
    """The contact zones of each output time of a march's outputs ``out``."""
    return [_ends_zones(ends) for ends in out["ends"]]


#: Points x > 0 at which :func:`even_problem` compares m and g with their mirror images
#: (the march compares them at its rule's nodes again before it folds the problem).
_EVEN_PROBES = np.linspace(0.0, 1.0, 203)[1:]


def even_problem(space: Space, inp: Any, loads: dict[str, np.ndarray]) -> bool:
    """Whether the problem is even in x: a centred load (moment or tilt 0 at the output
    times ``inp.times``, whose ``loads`` these are), breakpoints, m and g symmetric about
    0 (to :data:`~core.discretize.MIRROR_TOL`). Only the rules follow it: each march
    folds the problem only where its own grid's loads and its rule's nodes are even
    (:class:`~core.contact.systems.Mirror`)."""
    if not Mirror.centred(inp.given, loads):
        return False
    points = np.sort(np.asarray(space.breakpoints, dtype=float))
    if not even_overall(points, -points[::-1]):
        return False
    x = _EVEN_PROBES
    return (even_per_node(space.m(x), space.m(-x))
            and even_overall(space.g(x), space.g(-x)))


class MarchMemo:
    """The marches of one solve, each kept by its rules and time grid: a run again of the
    rule selection (its last comparison) or of the time grids (their coarser levels, on
    one rule) reads them instead of marching again (``liftoff_mc2010`` of
    ``benchmarks/creep_honesty.py``, fib MC2010 lifting off, tol 1e-6: nine of the
    fourteen marches of its end re-location, 3.5 of 7.8 s of CPU). The marches of one
    solve start from the same zones at loading (``first``), so one rule and grid give one
    march. Each read gets its own list of zone ends, which :func:`_borrow_corrections`
    changes in place. Once a rule is chosen, only the marches on it and on its check
    are kept (:meth:`keep`): the others cannot be asked again."""

    def __init__(self) -> None:
        self._kept: dict[tuple, tuple[Any, dict[str, Any]]] = {}

    @staticmethod
    def _rules_key(rules: Sequence[Panels]) -> tuple[bytes, ...]:
        return tuple(np.asarray(rule.edges, dtype=float).tobytes() for rule in rules)

    def get(self, rules: tuple[Panels, ...], grid: np.ndarray, widths: np.ndarray,
            index: np.ndarray, exact_ends: bool,
            make: Callable[[], tuple[Any, dict[str, Any]]]) -> tuple[Any, dict[str, Any]]:
        """(outputs, the march) on ``rules`` and the grid, made by ``make`` the first time;
        the outputs: a dict, or a list of dicts (one per punch)."""
        key = (self._rules_key(rules), np.asarray(grid, dtype=float).tobytes(),
               np.asarray(widths).tobytes(), np.asarray(index).tobytes(), bool(exact_ends))
        if key not in self._kept:
            self._kept[key] = make()
        outputs, run = self._kept[key]
        return _own_ends(outputs), run

    def keep(self, *rules: tuple[Panels, ...]) -> None:
        """Forget every march but those on one of ``rules`` (each one rule per punch)."""
        wanted = {self._rules_key(one) for one in rules}
        self._kept = {key: value for key, value in self._kept.items() if key[0] in wanted}


def _own_ends(outputs: Any) -> Any:
    """``outputs`` (a dict, or a list of them) with lists of zone ends of their own."""
    if isinstance(outputs, list):
        return [_own_ends(one) for one in outputs]
    return {**outputs, "ends": [list(ends) for ends in outputs["ends"]]}


class OnePunchMarches:
    """What the error control (:func:`controlled_march`) asks of the marches of one
    punch: its panel rules, a march on one of them, and the comparison of two marches'
    outputs. Several punches on one base answer the same for all of them at once
    (:class:`core.contact.coupled_creep.CoupledMarches`). ``even``: the problem is even
    in x (:func:`even_problem`), its rules are made symmetric about 0."""

    def __init__(self, space: Space, inp: Any, even: bool = False) -> None:
        self.space, self.inp, self.even = space, inp, even
        self._snapshots: tuple[dict[str, Any], list[_Snapshot]] | None = None
        self._memo = MarchMemo()

    def rule(self, res: Resolution, bands: list[tuple[float, float]], width: float) -> Panels:
        if self.even:
            return even_rule(band_rule(self.space, res, mirrored_bands(bands), width))
        return band_rule(self.space, res, bands, width)

    @staticmethod
    def halved(res: Resolution) -> Resolution:
        """The base width halved, and its grading at +-1 and the breakpoints too."""
        return Resolution(res.width / 2.0, res.edge / 2.0)

    @staticmethod
    def edges_halved(res: Resolution) -> Resolution:
        """The grading at +-1 and the breakpoints halved, the base width kept."""
        return Resolution(res.width, res.edge / 2.0)

    @staticmethod
    def nodes(rule: Panels) -> int:
        """How many nodes the marches on ``rule`` are dense in."""
        return int(rule.nodes.size)

    def locating(self, res: Resolution) -> Panels:
        """The rule of the march that locates the bands (graded only to ``LOCATE_EDGE``)."""
        rule = band_rule(self.space, Resolution(res.width, max(res.edge, LOCATE_EDGE)), [],
                         0.0)
        return even_rule(rule) if self.even else rule

    def run(self, rule: Panels, grid: np.ndarray, widths: np.ndarray, index: np.ndarray,
            exact_ends: bool = True, first: dict[str, Any] | None = None
            ) -> tuple[dict[str, Any], dict[str, Any]]:
        """(outputs, the march) of a march on ``rule`` (once per rule and grid:
        :class:`MarchMemo`)."""
        def make() -> tuple[dict[str, Any], dict[str, Any]]:
            space = self.space
            op = rule_operator(space.lam, rule)
            run = march(space, self.inp, rule, op, space.m(rule.nodes), space.g(rule.nodes),
                        grid, widths, index, exact_ends=exact_ends, first=first)
            return march_outputs(run), run

        return self._memo.get((rule,), grid, widths, index, exact_ends, make)

    def keep(self, *rules: Panels) -> None:
        """Forget the marches on any rule but ``rules`` (:meth:`MarchMemo.keep`)."""
        self._memo.keep(*((rule,) for rule in rules))

    distance = staticmethod(_distance)
    extrapolate = staticmethod(_extrapolate)
    borrow = staticmethod(_borrow_corrections)

    def rule_distance(self, rule: Panels, out: dict[str, Any], finer: Panels,
                      finer_out: dict[str, Any], bands: list[tuple[float, float]]
                      ) -> tuple[float, float, np.ndarray, np.ndarray]:
        """:func:`_rule_distance` of this punch."""
        return _rule_distance(self.space, rule, out, finer, finer_out, bands)

    @staticmethod
    def banded(bands: list[tuple[float, float]]) -> bool:
        """Whether a rule on ``bands`` has band panels (the band width changes it)."""
        return bool(bands)

    def bands(self, out: dict[str, Any], bands: list[tuple[float, float]] | None = None
              ) -> list[tuple[float, float]]:
        """The bands the free ends of ``out`` sweep (merged with ``bands`` if given)."""
        found = bands_from_ends(out["ends"], self.space.breakpoints)
        if self.even:
            found = mirrored_bands(found)  # (those the rules are made on)
        return found if bands is None else merge_bands(bands + found)

    def strays(self, out: dict[str, Any], bands: list[tuple[float, float]]) -> int:
        return _outside_bands(out["ends"], bands, self.space.breakpoints)

    def end_slope(self, rule: Panels, out: dict[str, Any]) -> float:
        """:func:`free_end_slope` of the outputs ``out`` of a march on ``rule``."""
        return free_end_slope(rule.nodes, out["q"], out["ends"], self.space.breakpoints)

    def snapshots(self, rule: Panels, out: dict[str, Any]) -> list[_Snapshot]:
        """:func:`output_snapshot` of each output time of ``out`` (a march on ``rule``),
        kept for the last ``out`` asked: the error control's last look and the answer
        read the same ones."""
        if self._snapshots is None or self._snapshots[0] is not out:
            zones = _zones_of(out)
            self._snapshots = (out, [output_snapshot(rule, out, k, zones[k])
                                     for k in range(len(zones))])
        return self._snapshots[1]

    def residual(self, rule: Panels, out: dict[str, Any]) -> float:
        """:func:`free_end_residual` of the outputs ``out`` of a march on ``rule`` (what
        :func:`solve_creep` adds to the estimate)."""
        return free_end_residual(self.space, self.snapshots(rule, out),
                                 float(np.max(np.abs(out["q"]), initial=0.0)))


def controlled_march(marches: Any, times: np.ndarray, tol: float, res: Any,
                     first_steps: int, jumps: Sequence[float] = (), graded: int = 0,
                     windows: Windows = ()) -> tuple:
    """The panel rule and time grids of the marches of ``marches`` (module notes), with
    their estimates: (rule, extrapolated outputs, last march, band note, output times
    with an end outside the bands, error of the outputs and q, of the zone ends, the
    time and space parts of the former and the part of q the zone ends make
    (:func:`free_end_slope`); ``jumps``: times where a given load jumps, on which every
    time grid lands; ``graded``: halvings of each first interval toward its start;
    ``windows``: where steps are shorter still, :func:`transient_windows`)."""
    # the zones at loading found by the first march start the first step of the others
    first: dict[str, Any] = {}
    # where a corner touches down or lifts off, once located: every later grid lands there
    kinks: list[float] = []
    sought = False

    def time_budget(space_error: float) -> float:
        """What the panel rule's ``space_error`` leaves of tol / 3 to the time grids."""
        return max(tol / UNILATERAL_MARGIN - space_error, tol / 6)

    def in_time(base: Any, space_error: float, space_shift: float, end_tol: float
                ) -> tuple[dict[str, Any], float, float, dict[str, Any]]:
        """:func:`_in_time` on ``base`` with what its rule left of the budgets."""
        nonlocal sought
        if not sought:
            sought = True
            kinks[:] = _corner_kinks(marches, times, base, first_steps, first, jumps,
                                     graded, windows, KINK_FLOOR * tol)
        return _in_time(marches, times, base, first_steps, time_budget(space_error),
                        max(end_tol - space_shift, end_tol / 2), first, jumps, graded,
                        windows, kinks)

    def rule_and_march(end_tol: float, bands: Any = None, slope: float = 0.0,
                       start: dict[str, Any] | None = None) -> tuple:
        """The rule (its bands located first unless given, with q's ``slope`` at the free
        ends; from the last comparison ``start`` of an earlier run) and the time grids on it."""
        base, space_error, space_shift, band_note = _select_rule(
            marches, times, res, first_steps, tol, end_tol, bands=bands, first=first,
            jumps=jumps, graded=graded, windows=windows, slope=slope,
            start=start)
        end_tol = band_note["end_tol"]  # finer where q beside the ends asks for it
        marches.keep(*band_note["start"]["rules"])  # (what a run again may read)
        out, time_error, end_shift, run = in_time(base, space_error, space_shift, end_tol)
        return (base, space_error, space_shift, band_note, out, time_error, end_shift, run,
                marches.strays(out, band_note["bands"]))

    # The zone ends have their own budget (march_end_tol: ZONE_END_TOL, or tol / 10 at
    # a looser tol; finer where q beside them asks for it): half of it for the panel rule
    # (core/contact/kinks.py takes the kinks at the ends out of its error), the rest, or
    # at least the other half, for the time grid; likewise tol / 3 of the outputs
    # (success asks the sum of the two parts to meet it).
    (base, space_error, space_shift, band_note, out, time_error, end_shift, run,
     strays) = rule_and_march(march_end_tol(tol))
    if strays:
        # An end went where the first march did not see it (between its few times, or as
        # a zone opening late): the bands of every output time, and everything again.
        (base, space_error, space_shift, band_note, out, time_error, end_shift, run,
         strays) = rule_and_march(band_note["end_tol"],
                                  marches.bands(out, band_note["bands"]), band_note["slope"])
    located = _landing(corner_contact_changes(run, KINK_FLOOR * tol), times, first_steps,
                       jumps, graded, windows)
    if time_error <= time_budget(space_error) and _kinks_moved(kinks, located, run):
        # the finest grids put a corner's change elsewhere than the coarse march located
        # it (or where it saw none): the grids again, landing there; not where they ran
        # out of halvings, which refuses the answer whatever they land on (a heel lifting
        # off each half period at tol 1e-6: 26 s of CPU with the grids made again, 16
        # without, refused at 3.2e-5 either way)
        kinks[:] = located
        out, time_error, end_shift, run = in_time(base, space_error, space_shift,
                                                  band_note["end_tol"])
        strays = marches.strays(out, band_note["bands"])
    end_error = float(end_shift + space_shift)
    slope = marches.end_slope(base, out)
    rest = float(time_error + space_error)
    # (an end unresolved, end_error inf, where q has no free end to slope: nothing of q)
    end_q_error = end_error * slope if slope > 0.0 else 0.0
    if (slope > 0.0 and np.isfinite(end_error) and not strays
            and not accepts(rest + end_q_error, tol, UNILATERAL_MARGIN)
            and (accepts(rest, tol, UNILATERAL_MARGIN) or end_q_error > rest)):
        # q beside a free end is what misses tol (or the most of it): the ends are
        # located again (at tol 1e-6 on the aging base, e = 0.45: ends 4.8e-7 -> ~1e-7
        # half-widths, q's error 4.7e-7 -> 5.4e-8)
        end_tol = end_tol_for_q(tol, slope, rest)
        # only when it asks more than the last run did (at MIN_END_TOL the finest bands
        # have been tried: the same run again would give the same ends), or when q's
        # slope, read now on the chosen rule, makes the last resort of the band widths
        # worth trying where the locating march's did not (LAST_RESORT_BELOW)
        last_resort = (band_note["width"] >= LAST_RESORT_BELOW
                       and slope > band_note["slope"]
                       and not accepts(space_shift * slope, tol, UNILATERAL_MARGIN))
        if end_tol < min(end_error, 0.5 * band_note["end_tol"]) or last_resort:
            (base, space_error, space_shift, band_note, out, time_error, end_shift, run,
             strays) = rule_and_march(min(end_tol, band_note["end_tol"]), band_note["bands"],
                                      slope, band_note["start"])
            end_error = float(end_shift + space_shift)
            slope = marches.end_slope(base, out)
    end_q_error = end_error * slope if slope > 0.0 else 0.0
    error = float(time_error + space_error + end_q_error)
    # (what the caller adds for q at the free ends, where the marches say: only near tol)
    residual = marches.residual(base, out) if (
        hasattr(marches, "residual") and np.isfinite(error)
        and error > 0.5 * tol / UNILATERAL_MARGIN and error <= tol) else 0.0
    shortfall = error + residual - tol / UNILATERAL_MARGIN
    if (not strays and np.isfinite(error)
            and 0.0 < shortfall < time_error <= time_budget(space_error)):
        # Each part met its own budget, their sum misses (q beside the free ends takes
        # its share after the time grids are chosen, and the caller adds q's residue at
        # them, ``marches.residual``): the time grids alone can mend it,
        # so they are asked for the shortfall too, on the same rule. An exponential
        # kernel's force step into lift-off at tol 1e-6 was refused at 3.44e-7 (3 x it
        # over tol; time 1.09e-7, space 1.52e-7, q at the ends 8.3e-8), its answer
        # 1.2e-7 off (a researcher's audit). Only where the grids met their budget (not
        # ran out of halvings): a run again could not do better then.
        retried = _in_time(marches, times, base, first_steps, time_error - 1.5 * shortfall,
                           max(band_note["end_tol"] - space_shift, band_note["end_tol"] / 2),
                           first, jumps, graded, windows, kinks)
        if np.isfinite(retried[1]) and retried[1] < time_error:
            out, time_error, end_shift, run = retried
            end_error = float(end_shift + space_shift)
            slope = marches.end_slope(base, out)
            end_q_error = end_error * slope if slope > 0.0 else 0.0
            error = float(time_error + space_error + end_q_error)
    return (base, out, run, band_note, strays, error, end_error, float(time_error),
            float(space_error), float(end_q_error))


def _in_time(marches: Any, times: np.ndarray, base: Any, first_steps: int, budget: float,
             end_budget: float, first: dict[str, Any] | None = None,
             jumps: Sequence[float] = (), graded: int = 0, windows: Windows = (),
             kinks: Sequence[float] = ()
             ) -> tuple[dict[str, Any], float, float, dict[str, Any]]:
    """March on halved grids until the time estimate meets ``budget`` (what the panel
    rule left of tol / 3) and that of the zone ends ``end_budget`` (module notes):
    (outputs, their time error, the zone ends' time error, the last march). ``kinks``:
    times every grid lands on (:func:`corner_contact_changes`)."""
    plain: list[dict[str, Any]] = []
    extrapolated: list[dict[str, Any]] = []
    plain_diffs: list[float] = []  # marches.distance of successive plain grids' outputs
    time_error = end_shift = np.inf
    asymptotic = True
    for level in range(MAX_HALVINGS + 1):
        grid, widths, index = time_grid(times, first_steps, level, jumps, graded, windows,
                                        kinks)
        # the first grid borrows the kink corrections of the second (_borrow_corrections)
        outputs, run = marches.run(base, grid, widths, index, exact_ends=level > 0,
                                   first=first)
        plain.append(outputs)
        if level == 1:
            marches.borrow(plain[0], plain[1])
        if len(plain) >= 2:
            extrapolated.append(marches.extrapolate(plain[-1], plain[-2]))
            diff, shift = marches.distance(plain[-1], plain[-2])
            plain_diffs.append(diff)
        if len(plain) == 2:
            # Two grids: the extrapolated outputs are reported, with the error of the finer
            # plain ones, |fine - coarse| / 3 (order 2), as a conservative estimate.
            time_error, end_shift = diff / 3.0, shift / 3.0
            if time_error <= budget and end_shift <= end_budget:
                break
        if len(extrapolated) >= 2:
            diff, shift = marches.distance(extrapolated[-1], extrapolated[-2])
            # Order 4 after one extrapolation would make the newer one ~16 times closer;
            # measured in full contact against the projection method (tests/test_contact):
            # the error was 1.17 times diff / 15, so only order 3 (diff / 7) is assumed.
            time_error, end_shift = diff / 7.0, shift / 7.0
            # the ratio of the last two differences of the plain grids: ~4 at order 2
            last = plain_diffs[-1]
            ratio = plain_diffs[-2] / last if last > 0.0 else np.inf
            asymptotic = ratio >= ASYMPTOTIC_RATIO
            if not asymptotic:
                # the grids are not yet where the error falls as the step squared: no
                # extrapolation, and the plain error from the ratio the grids show
                time_error = last / (max(ratio, MIN_RATIO) - 1.0)
            if time_error <= budget and end_shift <= end_budget:
                break
    out = extrapolated[-1] if extrapolated and asymptotic else plain[-1]
    return out, float(time_error), float(end_shift), run


def corner_contact_changes(run: dict[str, Any], floor: float = 1e-9) -> list[float]:
    """The times where a corner of the punch (x = -1 or +1) touches down or lifts off
    between two steps of the march ``run``: the root of the line through its Nystrom
    pressure at the two (:func:`core.contact.march.corner_pressure`; dimensionless t,
    sorted; the two corners of an even problem, a few roundings apart, give one). On a
    grid that lands near such a time the step beside it is short, so the line's error,
    of the order of the step times its distance to the root, shrinks as the grids are
    made again there. A sign change between two values within ``floor`` of the largest
    pressure at a corner is none (a corner hovering at contact: its kink is as small). A
    march of several punches keeps two corners for each (one grid lands on every
    punch's changes)."""
    corners, grid = run.get("corner_pressure"), run.get("grid")
    if corners is None or corners.size == 0:
        return []
    floor = floor * max(float(np.max(corners)), 0.0)
    found: set[float] = set()
    for values in corners.T:
        for i in np.flatnonzero((values[1:] > 0.0) != (values[:-1] > 0.0)):
            a, b = float(values[i]), float(values[i + 1])
            if max(abs(a), abs(b)) <= floor:
                continue
            found.add(float(grid[i] - a * (grid[i + 1] - grid[i]) / (b - a)))
    times = sorted(found)
    return [t for k, t in enumerate(times) if k == 0 or t - times[k - 1] > 1e-9 * t]


def _corner_kinks(marches: Any, times: np.ndarray, base: Any, first_steps: int,
                  first: dict[str, Any], jumps: Sequence[float], graded: int,
                  windows: Windows, floor: float) -> list[float]:
    """Where a corner touches down or lifts off (:func:`corner_contact_changes`): seen on
    the march that checked the rule ``base`` (:func:`_select_rule`'s, kept), located on
    the time grid ``KINK_LEVEL`` halvings finer than the first (the march's own error
    before the change shrinks with its steps: on the first grid a heel lifting off as its
    eccentricity grew was 0.0036 off), then on that grid with ``KINK_ZOOM_STEPS`` steps
    in the step holding each (the line through a step's ends is off by about the step
    times its distance to the root). Those marches stop at the last change. ``floor``:
    that of :func:`corner_contact_changes`."""
    grid, widths, index = time_grid(_check_times(times), first_steps, 0, jumps, graded,
                                    windows)
    _, run = marches.run(base, grid, widths, index, first=first)
    located = corner_contact_changes(run, floor)
    zoom, starts = list(windows), []
    for zoomed in (False, True):
        located = _landing(located, times, first_steps, jumps, graded, windows)
        if not located:
            break
        brackets = []
        for t in located:
            i = int(np.clip(np.searchsorted(run["grid"], t), 1, run["grid"].size - 1))
            brackets.append((float(run["grid"][i - 1]), float(run["grid"][i])))
        if zoomed:
            zoom += [(a, b, 2**KINK_LEVEL * (b - a) / KINK_ZOOM_STEPS) for a, b in brackets]
            starts += [a for a, _ in brackets]
        grid, widths, _ = time_grid(times, first_steps, KINK_LEVEL, jumps, graded, zoom,
                                    starts)
        end = max(b for _, b in brackets)
        last = min(int(np.searchsorted(grid, end * (1.0 - 1e-12))), grid.size - 1)
        _, run = marches.run(base, grid[:last + 1], widths[:last], np.array([last]),
                             exact_ends=False, first=first)
        located = corner_contact_changes(run, floor) or located
    return _landing(located, times, first_steps, jumps, graded, windows)


def _landing(located: list[float], times: np.ndarray, first_steps: int,
             jumps: Sequence[float], graded: int, windows: Windows) -> list[float]:
    """Those of the ``located`` changes the time grids would not land on without them
    (:func:`time_grid`'s ``kinks``): not one on a load jump or on an output time, which
    every grid holds, nor one beside them."""
    if not located:
        return located
    plain = time_grid(times, first_steps, 0, jumps, graded, windows)[0]
    grid = time_grid(times, first_steps, 0, jumps, graded, windows, located)[0]
    return [t for t in located if np.any(grid == t) and not np.any(plain == t)]


def _kinks_moved(kinks: Sequence[float], located: Sequence[float], run: dict[str, Any]
                 ) -> bool:
    """Whether the ``located`` times (:func:`corner_contact_changes` of the march
    ``run``) differ from the ``kinks`` its grids landed on: another count, or one moved
    by more than ``KINK_MOVE`` of the steps of its grid there."""
    if len(kinks) != len(located):
        return True
    if not kinks:
        return False
    grid = run["grid"]
    steps = np.diff(grid)
    for old, new in zip(kinks, located, strict=True):
        # the grid's steps there (the longest of two each side: a kink splits a step into
        # a sliver and the rest)
        i = int(np.searchsorted(grid, new))
        if abs(new - old) > KINK_MOVE * float(np.max(steps[max(i - 2, 0):i + 2])):
            return True
    return False


#: A rule without band panels (full contact) is compared down to this "width": one
#: halving of its base more than ``BAND_WIDTHS`` give a banded rule. With q compared at the
#: corners, full contact at tol 1e-7 missed tol by 2 % when the widths ran out, and one
#: finer rule met it (1184 nodes, 2.7 s of CPU against 0.8); unbounded, two footings in
#: full contact at tol 1e-7 refined on to 32 s of CPU (11 s before) for an estimate of
#: 1.5e-8 where 2.4e-8 had met tol.
UNBANDED_LAST = BAND_WIDTHS[-1] / 2.0


#: The least ratio of successive differences of three grids (each of half the steps of
#: the last) at which their outputs are taken to converge at order 2 (ratio 4) and are
#: extrapolated. Below it the error of the finest is ``last difference / (ratio - 1)``
#: (a geometric tail), the ratio taken at least ``MIN_RATIO``: that estimate read 5 times
#: the error where steps of ~40 decay times made the ratios 0.7 to 1.1 (the design chart
#: without :func:`transient_windows`), where Richardson's read 1/6 of it.
ASYMPTOTIC_RATIO = 3.0
MIN_RATIO = 1.25


def _check_times(times: np.ndarray, count: int = 0) -> np.ndarray:
    """At most ``count`` (default ``CHECK_OUTPUTS``) of the output times, spread over them
    (the first and last kept)."""
    count = count or CHECK_OUTPUTS
    if times.size <= count:
        return times
    return times[np.unique(np.linspace(0, times.size - 1, count).round().astype(int))]


def _select_rule(marches: Any, times: np.ndarray, res: Any, first_steps: int, tol: float,
                 end_tol: float, bands: Any = None, first: dict[str, Any] | None = None,
                 jumps: Sequence[float] = (), graded: int = 0, windows: Windows = (),
                 slope: float = 0.0, start: dict[str, Any] | None = None
                 ) -> tuple[Any, float, float, dict[str, Any]]:
    """The panel rule of the stepping and its spatial error (outputs, zone ends).

    On the first time grid of a few of the output times: a march on the base rule finds
    the bands the free ends sweep (unless ``bands`` are given); then a rule with band
    panels ``w`` is compared with one where every panel is finer (``w / 2`` over the
    bands, half the base width and half its grading at +-1 and the breakpoints, so that
    a rule without bands is checked too), halving ``w`` until ``SPACE_FACTOR`` times
    their difference meets a sixth of ``tol`` and half the zone-end tolerance (half of
    what success asks; or ``BAND_WIDTHS`` run out, for a rule without bands one halving
    past them, :data:`UNBANDED_LAST`; below ``LAST_RESORT_BELOW`` only where
    the ends' error times q's ``slope`` beside them would alone fail tol, and while the
    next check's rule has at most ``MAX_CHECK_NODES`` nodes). Where q at the punch's
    corners is what misses (:func:`_corner_q_between_rules`), the grading there is halved
    with the bands' panels, which do not reach it; at a corner where the two rules of a
    comparison have one panel (:func:`corners_refined`), its part is the one of the last
    comparison that refined it (its error is at most that). ``slope``
    (:func:`free_end_slope`): the caller's, or the locating march's where it locates the
    bands. ``start``: the band note of an earlier run on the same bands, whose last
    comparison (its rules, the corners' parts) this run starts from (a run asking finer
    ends would not stop at a coarser rule).
    """
    check = _check_times(times)
    grid, widths, index = time_grid(check, first_steps, 0, jumps, graded, windows)

    def check_march(rule: Any) -> dict[str, Any]:
        return marches.run(rule, grid, widths, index, first=first)[0]

    # The bands need the ends only to well within their margin: fewer times and a
    # coarser grading at the edges do (ends within ~1e-4 of the finer rules' on the
    # preset), at a quarter of the cost of a check march.
    if bands is None:
        locate = _check_times(times, LOCATE_OUTPUTS)
        grid_l, widths_l, index_l = time_grid(locate, first_steps, 0, jumps, graded, windows)
        locating = marches.locating(res)
        located = marches.run(locating, grid_l, widths_l, index_l, exact_ends=False,
                              first=first)[0]
        bands = marches.bands(located)
        # Where q rises steeply from a free end, the ends are asked finely enough for a
        # third of what success allows of q beside them (controlled_march), from the
        # start: the crowned default (R = 20 km, tol 1e-6) located them twice, 2.7 s.
        slope = marches.end_slope(locating, located)
        if slope > 0.0:
            end_tol = min(end_tol, end_tol_for_q(tol, slope))
    if start is None:
        # every panel finer: the base width halved, its grading at +-1 and the breakpoints
        # too
        base, finer, width = res, marches.halved(res), BAND_WIDTHS[0]
        kept = None  # each corner's part, as the last comparison refining it read it
    else:
        # A run again starts from the earlier run's last comparison. Built on ``res``
        # instead, a lift-off of the heel under strong creep took panels twice as wide at
        # +-1 as the rule checked before, q at the toe 1.5e-6 off at tol 1e-6 with an
        # estimate of 2.2e-7 (the check compares the histories, which the edge barely
        # moves).
        base, finer = start["bases"]
        width, kept = start["width"], start["corners"]
    rule = marches.rule(base, bands, width)
    current = check_march(rule)
    half = marches.rule(finer, bands, width / 2.0)
    half_base = finer
    while True:
        halved = check_march(half)
        diff, shift, corners, refined = marches.rule_distance(rule, current, half, halved,
                                                              bands)
        # (a corner not compared, NaN, keeps what was measured of it before)
        measured = SPACE_FACTOR * np.asarray(corners, dtype=float)
        kept = measured if kept is None else np.where(
            np.asarray(refined) & np.isfinite(measured), measured, np.fmax(kept, measured))
        corner_error = largest_part(kept)
        error = max(SPACE_FACTOR * diff, corner_error)
        end_error = SPACE_FACTOR * shift
        last = {"bases": (base, half_base), "width": width, "corners": kept,
                "rules": (rule, half)}
        if (error <= tol / 6 and end_error <= end_tol / 2) or width / 2.0 < (
                BAND_WIDTHS[-1] if marches.banded(bands) else UNBANDED_LAST):
            break
        if not marches.banded(bands):
            # no band panels, which the width would refine: the base is refined instead
            # (the same rule, compared with itself, read 1e-14 with q 3e-7 off at tol 1e-7),
            # once more than the band widths allow (UNBANDED_LAST), while its check has at
            # most MAX_CHECK_NODES nodes
            finer = marches.halved(finer)
        elif corner_error > tol / 6:
            # (q at the toe of a heel lifting off under strong creep: 1.1e-6 with the edge
            # panels 0.01 wide, the bands' panels halved to 0.005 left it there)
            finer = marches.edges_halved(finer)
        checking = marches.rule(finer, bands, width / 4.0)
        # (q off the bands missing its share asks the finer rule, whose base is finer too)
        if width / 2.0 < LAST_RESORT_BELOW and (
                (error <= tol / 6 and accepts(end_error * slope, tol, UNILATERAL_MARGIN))
                or marches.nodes(checking) > MAX_CHECK_NODES):
            break
        # The halved rule becomes the candidate (its base is already the finer one).
        width /= 2.0
        base, half_base = half_base, finer
        rule, current, half = half, halved, checking
    return rule, float(error), float(end_error), {"bands": bands, "width": width,
                                                  "end_tol": end_tol, "slope": slope,
                                                  "start": last}


def _outside_bands(ends: list[list[float]], bands: list[tuple[float, float]],
                   breakpoints: tuple[float, ...]) -> int:
    """How many times have a free end outside every band."""
    count = 0
    for row in ends:
        free = bands_from_ends([row], breakpoints, margin=0.0)
        if any(not any(lo <= a and b <= hi for lo, hi in bands) for a, b in free):
            count += 1
    return count


def creep_verdict(error: float, end_error: float, time_error: float, space_error: float,
                  run: dict, strays: int, tol: float, what: str, end_q_error: float = 0.0
                  ) -> tuple[bool, list[str], str]:
    """Success, flags and message of a lift-off answer under creep: its estimated error
    (``error``, of which ``time_error``, ``space_error`` and ``end_q_error``, q's error
    beside the free ends as they are located, relative), of the zone ends
    (``end_error``, half-widths), the march's report ``run`` (``steps``, ``unsettled``
    steps) and the steps whose zone end left the band of fine panels (``strays``);
    ``what`` names the problem in the message (``"under creep"``, ``"under creep (2
    punches)"``)."""
    success = (accepts(error, tol, UNILATERAL_MARGIN) and end_error <= march_end_tol(tol)
               and run["unsettled"] == 0 and not strays)
    flags = [] if success else ["tol_not_met"]
    message = (f"unilateral contact {what}: {run['steps']} steps, estimated error "
               f"{error:.1e} (time {time_error:.1e}, space {space_error:.1e}, q at the zone "
               f"ends {end_q_error:.1e}), zone ends to {end_error:.1e} half-widths")
    if strays:
        message += (f"; a zone end left the finely paneled band around the ends at "
                    f"{strays} time(s), its estimate does not hold there")
    if not success:
        message += not_within_tol(error, end_error, tol, march_end_tol(tol)) + (
            f"; {run['unsettled']} step(s) with an unsettled contact set"
            if run["unsettled"] else "")
    return success, flags, message
