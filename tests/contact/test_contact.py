"""Unilateral contact (core.contact): limits, a second method, refinement, creep, the API.

Every tolerance is a measured error with a margin; the measured value is quoted next to
it (double-precision kernel, OPENBLAS_NUM_THREADS=1).
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest

from core import scene_from_dict, solve, solve_dimensionless
from core.contact import Resolution, Space, solve_unilateral
from core.contact.active_set import nodal_active_set, zones_from_nodes
from core.contact.result import contact_set_from_pressure
from core.contact.step import Step
from core.contact.unilateral import FULL_CONTACT
from core.contact.zones import refine_zone_ends, solve_on_zones
from core.discretize import base_panels, kernel_operator
from tests.conftest import scene_file


def worn_patch(x):
    """A gap bump in the middle (a worn coating patch): contact in two pieces."""
    return 0.01 * np.exp(-(np.asarray(x) / 0.2) ** 2)


def constant(value):
    return lambda x: np.full(np.shape(x), float(value))


# ---------------------------------------------------------------------- the limits


def test_winkler_limit_of_a_compliant_coating():
    # Winkler bed (c m q = delta + alpha x): q = P/2 + 3 M x / 2 in full contact, zero at
    # x = -1 when e = M/P = 1/3; beyond it q = k (x - x0) on [x0, 1] with the centroid
    # x0 + 2 (1 - x0)/3 = e, so the contact length is 1 - x0 = 3 (1 - e) and k = 2 P/L^2.
    # A compliant coating (m >> the base's compliance ~1) approaches it like 1/m:
    # measured end errors 4.61e-4 (m = 100) and 4.62e-5 (m = 1000).
    e = 0.5
    x0 = 1.0 - 3.0 * (1.0 - e)
    errors = []
    for m in (100.0, 1000.0):
        r = solve_unilateral(1.0, m, 0.0, [1.0], force=1.0, moment=e)
        (zone,) = r.contact_set[0]
        assert zone[1] == 1.0
        errors.append(abs(zone[0] - x0))
        assert r.success, r.message
    assert errors[1] < 1e-4
    assert 8.0 < errors[0] / errors[1] < 12.0  # first order in 1/m (measured 9.98)
    # the triangular pressure (measured max deviation 1.4e-4 of the peak at m = 1000)
    x = np.linspace(-1.0, 1.0, 401)
    length = 1.0 - x0
    triangle = np.where(x > x0, 2.0 / length**2 * (x - x0), 0.0)
    q = r.pressure(x)[:, 0]
    assert np.max(np.abs(q - triangle)) < 1e-3 * np.max(triangle)


def test_winkler_threshold_one_third():
    # Full contact holds up to e = 1/3 (+ O(1/m)); "auto" switches to the unilateral
    # model only past it. m = 1000: measured lift-off end -0.98006 at e = 0.34
    # (Winkler: 1 - 3 * 0.66 = -0.98; 5.5e-5 off).
    below = solve_dimensionless(1.0, 1000.0, 0.0, [1.0], force=1.0, moment=0.33)
    assert below.info["contact"] == "full"
    assert below.contact_set == [FULL_CONTACT]
    above = solve_dimensionless(1.0, 1000.0, 0.0, [1.0], force=1.0, moment=0.34)
    assert above.info["contact"] == "unilateral"
    assert "contact_lost" in above.info["full_contact"]["flags"]
    (zone,) = above.contact_set[0]
    assert abs(zone[0] - (1.0 - 3.0 * 0.66)) < 1e-3


def _lift_off_threshold(lam: float, m: float) -> float:
    """e = M/P at which the full-contact pressure vanishes at x = -1."""
    space = Space(lam, constant(m), constant(0.0), ())
    res = Resolution(0.25, min(1e-3, m / 4))
    q_force = solve_on_zones(space, Step(1.0, 1.0, {"force": 1.0, "moment": 0.0}),
                             [-1.0, 1.0], res).end_values[0]
    q_moment = solve_on_zones(space, Step(1.0, 1.0, {"force": 0.0, "moment": 1.0}),
                              [-1.0, 1.0], res).end_values[0]
    return -q_force / q_moment


def test_half_space_limit_threshold_and_contact_length():
    # Thick base (lam = 0.01, kernel -ln|x - xi|/pi + const + O(lam^2)), thin coating:
    # full contact q = [P/pi + 2 M x/pi]/sqrt(1 - x^2) loses contact at e = 1/2. Past it
    # the bounded-at-the-free-end solution on [b, 1] is q = C sqrt((x - b)/(1 - x)) with
    # e = 1 - (1 - b)/4: contact length 4 (1 - e).
    # Thresholds measured 0.498771 (m = 1e-3) and 0.499817 (m = 1e-4).
    thresholds = [_lift_off_threshold(0.01, m) for m in (1e-3, 1e-4)]
    assert 0.5 - thresholds[0] < 2e-3
    assert 0.5 - thresholds[1] < 3e-4
    assert 0.0 < 0.5 - thresholds[1] < 0.5 - thresholds[0]
    # Contact length at e = 0.7: ends measured -0.19549 (m = 1e-3), -0.19938 (1e-4).
    e = 0.7
    exact = 1.0 - 4.0 * (1.0 - e)
    errors = []
    for m in (1e-3, 1e-4):
        r = solve_unilateral(0.01, m, 0.0, [1.0], force=1.0, moment=e)
        (zone,) = r.contact_set[0]
        errors.append(abs(zone[0] - exact))
        assert r.success, r.message
    assert errors[1] < 1e-3
    assert errors[0] / errors[1] > 5.0  # measured 7.3


def test_rounded_punch_against_the_half_space_contact_width():
    # 2D Hertz for the model's kernel as lam -> 0: (1/pi) PV int q/(x - xi) = g' = x/R
    # gives q = (b/R) sqrt(1 - x^2/b^2) and P = pi b^2/(2R), so b = sqrt(2 R P/pi).
    # R = 1 (g = x^2/2), P = 0.2: b = 0.356825; measured 0.357137 with m = 1e-4
    # (3.1e-4 off; 2.4e-3 with m = 1e-3: the coating's share shrinks like m).
    radius, force = 1.0, 0.2
    b = math.sqrt(2.0 * radius * force / math.pi)
    r = solve_unilateral(0.01, 1e-4, lambda x: x**2 / (2 * radius), [1.0], force=force,
                         moment=0.0)
    (zone,) = r.contact_set[0]
    assert abs(zone[1] - b) < 1e-3
    assert abs(zone[0] + zone[1]) < 1e-9  # symmetric (measured 2e-14)
    assert r.success, r.message


# ------------------------------------------------------------- a second method


def _fischer_burmeister(op, m, g, x, w, force, moment):
    """Semismooth Newton on phi(q, h) = q + h - sqrt(q^2 + h^2) = 0 (statement 4).

    An independent unilateral method on the same nodes: no active set, every node's
    complementarity is one smooth-almost-everywhere equation, with the equilibrium rows.
    """
    n = x.size
    a = np.diag(m) + op

    def residual(z):
        q, delta, alpha = z[:n], z[n], z[n + 1]
        h = a @ q - delta - alpha * x + g
        r = np.sqrt(q * q + h * h)
        return np.concatenate([q + h - r, [w @ q - force, (w * x) @ q - moment]]), q, h, r

    z = np.concatenate([np.full(n, force / 2.0), [0.0, 0.0]])
    for _ in range(200):
        phi, q, h, r = residual(z)
        norm = float(np.linalg.norm(phi))
        if norm < 1e-15:
            break
        safe = np.where(r > 0.0, r, 1.0)
        dq = np.where(r > 0.0, 1.0 - q / safe, 1.0 - 1.0 / math.sqrt(2.0))
        dh = np.where(r > 0.0, 1.0 - h / safe, 1.0 - 1.0 / math.sqrt(2.0))
        jac = np.zeros((n + 2, n + 2))
        jac[:n, :n] = np.diag(dq) + dh[:, None] * a
        jac[:n, n] = -dh
        jac[:n, n + 1] = -dh * x
        jac[n, :n] = w
        jac[n + 1, :n] = w * x
        step = np.linalg.solve(jac, -phi)
        t = 1.0
        while t > 1e-8 and np.linalg.norm(residual(z + t * step)[0]) > (1 - 1e-4 * t) * norm:
            t *= 0.5
        z = z + t * step
    return z[:n], z[n], z[n + 1]


@pytest.mark.parametrize("moment", [0.0, 0.002])
def test_active_set_agrees_with_a_complementarity_solver(moment):
    # Two contact zones around a worn patch. Measured differences: q 2.8e-15 and 2.3e-14
    # of max q, delta and alpha below 3e-18 (delta ~ 3e-3); 4 sweeps.
    panels = base_panels(1.0, (), edge_width=1e-2, max_width=0.25)
    op = kernel_operator(1.0, panels).matrix
    x, w = panels.nodes, panels.weights
    m = np.full(x.size, 0.05)
    g = worn_patch(x)
    step = Step(1.0, 1.0, {"force": 0.01, "moment": moment})
    state, sweeps, settled = nodal_active_set(panels, op, m, g, step)
    assert settled and sweeps < 10
    q_ref, delta_ref, alpha_ref = _fischer_burmeister(op, m, g, x, w, 0.01, moment)
    scale = np.max(q_ref)
    assert np.max(np.abs(state.q - q_ref)) < 1e-11 * scale
    assert abs(state.settlement - delta_ref) < 1e-12
    assert abs(state.tilt - alpha_ref) < 1e-12
    ends, _, _ = zones_from_nodes(state)
    assert len(ends) == 4  # two zones


def test_two_zones_meet_the_contact_conditions():
    # The refined answer: q >= 0 on the zones, q(end) = 0 at the free ends, equilibrium,
    # and the gap open between the zones. Measured: Q(end) 0 (clipped) to 1.7e-15 of
    # max q; end error estimate 1.5e-10; force and
    # moment by the trapezoid rule on 2001 points 1.5e-5 / 3.0e-5 off (the rule's error).
    r = solve_unilateral(1.0, 0.05, worn_patch, [1.0], force=0.01, moment=0.002)
    zones = r.contact_set[0]
    assert len(zones) == 2 and zones[0][0] == -1.0 and zones[1][1] == 1.0
    assert r.success and r.flags == []
    assert r.info["zone_end_error"] < 1e-6  # measured 1.5e-10
    x = np.linspace(-1.0, 1.0, 2001)
    q = r.pressure(x)[:, 0]
    assert np.all(q >= 0.0)
    gap = (x > zones[0][1]) & (x < zones[1][0])
    assert np.all(q[gap] == 0.0)
    inner_ends = [zones[0][1], zones[1][0]]
    assert np.max(r.pressure(inner_ends)) < 1e-9 * np.max(q)
    assert abs(np.trapezoid(q, x) - 0.01) < 1e-4 * 0.01
    assert abs(np.trapezoid(x * q, x) - 0.002) < 1e-3 * 0.002


def test_four_statements_agree():
    # Statement 4 (P, M given) gives delta and alpha; statements 1-3 given the matching
    # pairs must find the same contact zone and loads. Measured: zone ends within 1.3e-10,
    # P, M, delta within 1.4e-10 (the error estimate of each solve is ~1e-7).
    ref = solve_unilateral(1.0, 0.05, 0.0, [1.0], force=1.0, moment=0.45, tol=1e-8)
    d, a = float(ref.settlement[0]), float(ref.tilt[0])
    for given in ({"settlement": d, "tilt": a}, {"settlement": d, "moment": 0.45},
                  {"tilt": a, "force": 1.0}):
        r = solve_unilateral(1.0, 0.05, 0.0, [1.0], tol=1e-8, **given)
        assert r.flags == [], r.message
        (zone,) = r.contact_set[0]
        assert abs(zone[0] - ref.contact_set[0][0][0]) < 1e-8 and zone[1] == 1.0
        for name, value in (("settlement", d), ("tilt", a), ("force", 1.0),
                            ("moment", 0.45)):
            assert abs(getattr(r, name)[0] - value) < 1e-8 * max(abs(value), 1e-3), name


def test_stepped_punch_zone_ends_at_the_step_corner():
    # A punch whose middle protrudes by 0.01 (g jumps at x = +-0.4): pressed by less than
    # the step, it touches on the middle only and the zone ends at the corners (q > 0
    # there, the gap open outside); pressed harder with a moment, the outer parts touch
    # too, with free ends. Both pass the final check of the contact conditions.
    def step_gap(x):
        return np.where(np.abs(np.asarray(x)) > 0.4, 0.01, 0.0)

    kw = dict(breakpoints=(-0.4, 0.4), tol=1e-8)
    middle = solve_unilateral(1.0, 0.05, step_gap, [1.0], settlement=0.008, moment=0.0, **kw)
    assert middle.contact_set[0] == [(-0.4, 0.4)] and middle.flags == []
    assert np.min(middle.pressure([-0.4, 0.4])) > 0.0
    both = solve_unilateral(1.0, 0.05, step_gap, [1.0], settlement=0.0133, moment=0.002,
                            **kw)
    zones = both.contact_set[0]
    assert both.flags == [], both.message
    # three zones: the middle one pinned at the corners, two outer ones with free ends
    # (measured [-1, -0.7932], [-0.4, 0.4], [0.6868, 1]: the moment makes them unequal)
    assert len(zones) == 3 and zones[1] == (-0.4, 0.4)
    assert zones[0][0] == -1.0 and -1.0 < zones[0][1] < -0.4
    assert zones[2][1] == 1.0 and 0.4 < zones[2][0] < 1.0
    assert abs(zones[0][1] + zones[2][0]) > 0.05
    assert both.info["zone_end_error"] < 1e-6


# ------------------------------------------------------------------- refinement


def test_zone_end_converges_under_refinement_and_the_estimate_holds():
    # One free end (e = 0.45, m = 0.05): the end found on successively finer rules
    # (panels halved, end grading quartered). Measured ends differ from the finest by
    # 4.4e-9, 2.7e-10, 1.6e-11 against estimates (each level against the coarser one)
    # 6.7e-8, 4.1e-9, 2.6e-10: safe by the convergence ratio of a level, ~16.
    space = Space(1.0, constant(0.05), constant(0.0), ())
    step = Step(1.0, 1.0, {"force": 1.0, "moment": 0.45})
    res = Resolution(0.5, 1e-2)
    panels = base_panels(1.0, (), edge_width=res.edge, max_width=res.width)
    op = kernel_operator(1.0, panels).matrix
    state, _, _ = nodal_active_set(panels, op, np.full(panels.size, 0.05),
                                   np.zeros(panels.size), step)
    ends, pinned, slopes = zones_from_nodes(state)
    found, estimates = [], []
    for _ in range(4):
        refined = refine_zone_ends(space, step, ends, pinned, slopes, res, tol=1e-8,
                                   max_levels=1)
        assert refined.converged
        found.append(refined.solution.ends[0])
        estimates.append(refined.end_error)
        res = res.finer()
    diffs = np.abs(np.array(found[:-1]) - found[-1])
    assert np.all(np.diff(diffs) < 0.0), diffs
    assert diffs[-1] < 1e-8
    for k in range(len(diffs)):
        assert diffs[k] <= estimates[k], (diffs, estimates)


# --------------------------------------------------------------------------- creep


def _preset_problem(**changes):
    scene = scene_file("eccentric_footing_liftoff")
    scene["times"] = {"end": 1000.0, "count": 5, "spacing": "log"}
    for key, value in changes.items():
        scene["loading"][key] = value
    return scene_from_dict(scene).dimensionless


def _creep_args(problem):
    return dict(c=problem.c, kernel=problem.kernel, breakpoints=problem.breakpoints,
                **problem.loads)


def test_creep_in_full_contact_agrees_with_the_projection_method():
    # e = 0.1 m: no lift-off, so the unilateral stepping must reproduce the full-contact
    # projection method (an independent discretization in space and time). Measured
    # relative difference 1.2e-6 in settlement and tilt, against an estimate of 2.2e-6.
    pb = _preset_problem(moment=8.0e4)
    uni = solve_unilateral(pb.lam, pb.m, pb.g, pb.times, tol=1e-5, **_creep_args(pb))
    full = solve_dimensionless(pb.lam, pb.m, pb.g, pb.times, tol=1e-8, contact="full",
                               **_creep_args(pb))
    assert uni.contact_set == [FULL_CONTACT] * pb.times.size
    scale = np.max(np.abs(full.settlement))
    diff = max(np.max(np.abs(uni.settlement - full.settlement)),
               np.max(np.abs(uni.tilt - full.tilt))) / scale
    assert diff < 3.0 * uni.info["error_estimate"]
    assert diff < 1e-4


def test_creep_lift_off_zone_moves_and_two_time_resolutions_agree():
    # The preset (e = 0.6 m): the zone end moves from -0.306 to -0.349 half-widths over
    # 1000 days as the base creeps. At the preset's tol = 1e-4 the ends still have their
    # own budget, 1e-6: two first grids (8 and 16 nominal steps) must give ends within
    # the sum of their estimates, each <= 1e-6 (measured: 5.5e-7 apart, estimates 5.1e-7
    # and 3.3e-7); the motion is far larger. Force by the trapezoid rule on 4001
    # points: 1.1e-6 off.
    pb = _preset_problem()
    runs = [solve_unilateral(pb.lam, pb.m, pb.g, pb.times, tol=1e-4, time_steps=steps,
                             **_creep_args(pb)) for steps in (8, 16)]
    ends = [np.array([zones[0][0] for zones in r.contact_set]) for r in runs]
    for r in runs:
        assert all(len(z) == 1 and z[0][1] == 1.0 for z in r.contact_set)
        assert r.info["contact"] == "unilateral"
    motion = abs(ends[1][-1] - ends[1][0])
    assert motion > 0.03
    gap = float(np.max(np.abs(ends[0] - ends[1])))
    assert all(r.info["zone_end_error"] <= 1e-6 for r in runs), [r.message for r in runs]
    assert gap <= runs[0].info["zone_end_error"] + runs[1].info["zone_end_error"], gap
    # equilibrium holds at every time (statement 4: P and M are given)
    x = np.linspace(-1.0, 1.0, 4001)
    q = runs[1].pressure(x)
    assert np.all(q >= 0.0)
    force = np.trapezoid(q, x, axis=0)
    assert np.max(np.abs(force - runs[1].force) / runs[1].force) < 1e-3


def _creep_rule_march(pb, tol, rule_for, level=0):
    """Zone ends and outputs of the creep stepping on the rule ``rule_for(space, res)``."""
    from core.contact.march import march, march_outputs
    from core.engines.projection import validate_inputs
    from core.time import time_grid

    inp = validate_inputs(pb.lam, pb.m, pb.g, pb.times, pb.c, pb.kernel,
                    {"settlement": None, "tilt": None, **pb.loads}, pb.breakpoints, tol)
    space = Space(inp.lam, inp.m, inp.g, inp.breakpoints)
    edge = min(1e-2, 0.25 * float(np.min(inp.m(np.linspace(-1.0, 1.0, 257)))))
    rule = rule_for(space, Resolution(min(0.5, 3.0 / inp.lam), edge))
    grid, widths, index = time_grid(inp.times, 16, level)
    op = kernel_operator(space.lam, rule).matrix
    out = march_outputs(march(space, inp, rule, op, space.m(rule.nodes), space.g(rule.nodes),
                              grid, widths, index))
    return np.array([e[0] for e in out["ends"]]), out


def test_band_rule_covers_the_bands_finely_and_keeps_the_breaks():
    from core.contact.bands import band_rule, bands_from_ends

    space = Space(1.0, constant(0.05), constant(0.0), (-0.5, 0.3))
    res = Resolution(0.5, 1e-2)
    # ends pinned at +-1 and at the breakpoints need no band; free ones get one each,
    # merged where their margins overlap
    bands = bands_from_ends([[-1.0, -0.31, 0.3, 0.97], [-1.0, -0.30, 0.3, 0.985]],
                            space.breakpoints)
    assert len(bands) == 2 and bands[0][0] < -0.31 and bands[0][1] > -0.30
    assert bands[1][1] == 1.0
    panels = band_rule(space, res, bands, 0.02)
    edges = panels.edges
    assert edges[0] == -1.0 and edges[-1] == 1.0 and np.all(np.diff(edges) > 0.0)
    for b in space.breakpoints:
        assert np.any(edges == b)
    widths = np.diff(edges)
    centres = 0.5 * (edges[1:] + edges[:-1])
    for lo, hi in bands:
        inside = (centres > lo) & (centres < hi)
        assert inside.any() and np.all(widths[inside] <= 0.02 + 1e-12)
    # the edge grading at +-1 survives next to a band
    assert widths[-1] <= 1e-2 + 1e-12 and widths[0] <= 1e-2 + 1e-12
    assert abs(np.sum(panels.weights) - 2.0) < 1e-13


def test_a_band_covers_the_way_an_end_went_to_a_corner():
    from core.contact.bands import bands_from_ends

    # A crown's zone spreading to full contact between two times (the crowned default,
    # R = 20 km): its ends went from +-0.944 to the corners, and the steps between put
    # their kinks on that way. Without it in the band an end strayed out and the rule was
    # chosen again (2.9 s instead of 1.5 s).
    bands = bands_from_ends([[-0.90, 0.90], [-0.944, 0.944], [-1.0, 1.0]])
    assert bands == [(-1.0, pytest.approx(-0.88)), (pytest.approx(0.88), 1.0)]
    # and an end leaving a corner (lift-off starting after loading)
    assert bands_from_ends([[-1.0, 1.0], [-0.8, 1.0]]) == [(-1.0, pytest.approx(-0.78))]


def test_creep_zone_ends_converge_over_the_band_and_the_space_estimate_holds():
    # The preset at 5 output times, one time grid: the free end on rules with panels
    # 0.04, 0.02, 0.01 wide over the band it sweeps, against 0.0025. Measured largest
    # errors over the times 1.4e-7, 5.9e-8, 1.8e-8 with the kink correction
    # (core/contact/kinks.py), 2.2e-6, 6.0e-7, 3.4e-7 where the nodal Q changes sign;
    # largest differences from the rule with halved panels 1.9e-7 (w = 0.04) and 4.5e-8
    # (0.02), which SPACE_FACTOR = 2 turns into estimates 3.8e-7 and 9.0e-8 above the
    # errors (1.5 times the worst ratio). Panels 0.125 wide everywhere (the former fixed
    # rule): 6.9e-5 off.
    from core.contact.bands import band_rule, bands_from_ends
    from core.contact.creep import SPACE_FACTOR

    pb = _preset_problem()
    first, _ = _creep_rule_march(pb, 1e-6, lambda sp, res: band_rule(sp, res, [], 0.0))
    bands = bands_from_ends([[e, 1.0] for e in first], pb.breakpoints)
    assert len(bands) == 1 and bands[0][0] < first.min() < first.max() < bands[0][1]
    runs = {w: _creep_rule_march(pb, 1e-6, lambda sp, res, w=w: band_rule(sp, res, bands,
                                                                          w))
            for w in (0.04, 0.02, 0.01, 0.0025)}
    ends = {w: run[0] for w, run in runs.items()}
    nodal = {w: np.array([e[0] for e in run[1]["nodal_ends"]]) for w, run in runs.items()}
    errors = [float(np.max(np.abs(ends[w] - ends[0.0025]))) for w in (0.04, 0.02, 0.01)]
    nodal_errors = [float(np.max(np.abs(nodal[w] - ends[0.0025]))) for w in (0.04, 0.02, 0.01)]
    assert errors[0] > errors[1] > errors[2], errors
    assert errors[0] < 5e-7, errors  # the ends' tolerance is 1e-6
    assert nodal_errors[0] > 1e-6, nodal_errors  # what the correction takes out
    for k, (w, half) in enumerate(((0.04, 0.02), (0.02, 0.01))):
        estimate = SPACE_FACTOR * float(np.max(np.abs(ends[w] - ends[half])))
        assert errors[k] <= estimate, (w, errors[k], estimate)


@pytest.mark.slow
def test_creep_zone_ends_to_1e_6_at_two_time_resolutions():
    # tol = 1e-6 asks the zone ends for 1e-6 too: the band panels are refined to meet it
    # and two first time grids (8 and 16 nominal steps) must agree within the sum of
    # their estimates. Measured: ends 4.9e-10 apart, their estimates 3.9e-8 and 4.8e-8
    # half-widths; the rest of each estimate meets tol (time 3.4e-8: the aging law's
    # decay, rate 0.84, is stepped at most a decay time apart while it lasts,
    # core.contact.creep.transient_windows; before, the 5 output times left steps of ~2
    # decay times, the run from 8 steps stopped at 2.3e-6 and its ends were 2.5e-7 from
    # the other's). Both are refused at tol 1e-6 by q beside the free end: the pressure
    # the answer gives at its reported end is ~2e-7 of max q (free_end_residual; q's part
    # 2.2e-7 of the estimate 4.0e-7, against tol / 3).
    pb = _preset_problem()
    runs = [solve_unilateral(pb.lam, pb.m, pb.g, pb.times, tol=1e-6, time_steps=steps,
                             **_creep_args(pb)) for steps in (8, 16)]
    ends = [np.array([zones[0][0] for zones in r.contact_set]) for r in runs]
    for r in runs:
        rest = r.info["error_estimate"] - r.info["zone_end_pressure_error"]
        assert rest <= 1e-6 / 3, r.message
        assert r.info["zone_end_error"] <= 1e-6, r.message
    gap = float(np.max(np.abs(ends[0] - ends[1])))
    assert gap <= runs[0].info["zone_end_error"] + runs[1].info["zone_end_error"], gap


def test_creep_zone_opening_late_gets_its_band():
    # The eccentricity grows from 0.3 to 0.5 over the first 20 time units: full contact
    # first, lift-off later, the free end travelling from -1 inward. Every free end at
    # every output time must lie in a finely paneled band (else the spatial estimate
    # would not hold there and the run is flagged).
    scene = scene_file("eccentric_footing_liftoff")
    scene["times"] = {"end": 1000.0, "count": 12, "spacing": "log"}
    pb = scene_from_dict(scene).dimensionless
    force = pb.loads["force"]

    def moment(t):
        return (0.3 + 0.2 * np.clip((np.asarray(t) - 1.0) / 20.0, 0.0, 1.0)) * force(t)

    r = solve_unilateral(pb.lam, pb.m, pb.g, pb.times, c=pb.c, kernel=pb.kernel,
                         tol=1e-4, force=force, moment=moment)
    assert r.success, r.message
    assert r.contact_set[0] == [(-1.0, 1.0)]
    assert r.contact_set[-1][0][0] > -0.9
    for zones in r.contact_set:
        for lo, _ in zones:
            if lo > -1.0:
                assert any(a <= lo <= b for a, b in r.info["end_bands"]), (lo, r.info)


def test_separable_memory_agrees_with_the_general_kernel_path():
    # The aging kernel as a plain callable takes the trapezoid on K q (O(n) per step);
    # as a degenerate kernel, the recursion with exponential product integration. Both
    # converge to the same answer: measured 3.6e-6 apart in settlement (the estimates
    # 1.3e-5 each) and 2.8e-6 in the ends (estimates 7.1e-6 and 6.2e-6).
    pb = _preset_problem()
    kernel = pb.kernel

    def plain(t, tau):
        return kernel(t, tau)

    args = _creep_args(pb)
    fast = solve_unilateral(pb.lam, pb.m, pb.g, pb.times, tol=1e-4, **args)
    args["kernel"] = plain
    slow = solve_unilateral(pb.lam, pb.m, pb.g, pb.times, tol=1e-4, **args)
    scale = np.max(np.abs(fast.settlement))
    diff = np.max(np.abs(fast.settlement - slow.settlement)) / scale
    assert diff <= fast.info["error_estimate"] + slow.info["error_estimate"], diff
    ends = [np.array([z[0][0] for z in r.contact_set]) for r in (fast, slow)]
    assert np.max(np.abs(ends[0] - ends[1])) <= (fast.info["zone_end_error"]
                                                 + slow.info["zone_end_error"])


def test_auto_goes_straight_to_lift_off_when_the_first_time_loses_contact():
    # The preset lifts off at loading: the full-contact check at t = 1 decides, and the
    # full-contact stepping is never run (its info would carry "n_modes" or "stages").
    pb = _preset_problem()
    result = solve_dimensionless(pb.lam, pb.m, pb.g, pb.times, tol=1e-4, contact="auto",
                                 **_creep_args(pb))
    assert result.info["contact"] == "unilateral"
    assert result.info["full_contact"]["checked_at"] == 1.0
    assert "contact_lost" in result.info["full_contact"]["flags"]
    # elastic and a new geometry: the geometry is prepared for the check (the full-contact
    # answer would need it anyway) and the full-contact model's own flag decides
    from core.cache import clear_caches

    clear_caches()
    elastic = solve_dimensionless(1.0, 0.05, 0.0, [1.0], force=1.0, moment=0.45, tol=1e-6)
    assert elastic.info["contact"] == "unilateral"
    assert "contact_lost" in elastic.info["full_contact"]["flags"]
    assert elastic.info["full_contact"]["min_pressure"] < -1e-3
    # well inside full contact (the threshold is e = 0.38692 for lam = 1, m = 0.05)
    inside = solve_dimensionless(1.0, 0.05, 0.0, [1.0], force=1.0, moment=0.2, tol=1e-6)
    assert inside.info["contact"] == "full"
    # just past it q dips by ~4e-5 of its peak: the full-contact model flags contact_lost,
    # and the free end comes out 3e-5 from the edge (the lifted length grows like
    # 3 (e - threshold); measured -0.99997007)
    near = solve_dimensionless(1.0, 0.05, 0.0, [1.0], force=1.0, moment=0.38693158,
                               tol=1e-6)
    assert near.info["contact"] == "unilateral"
    assert near.success, near.message
    assert -1.0 + 2e-5 < near.contact_set[0][0][0] < -1.0 + 4e-5
    # e = 0.1 m keeps full contact: the check passes and the full model answers
    kept = _preset_problem(moment=8.0e4)
    full = solve_dimensionless(kept.lam, kept.m, kept.g, kept.times, tol=1e-4,
                               contact="auto", **_creep_args(kept))
    assert full.info["contact"] == "full"


# ----------------------------------------------------------------- the interface


def test_contact_argument_and_refusals():
    with pytest.raises(ValueError, match="contact: must be one of"):
        solve_dimensionless(1.0, 0.05, 0.0, [1.0], force=1.0, moment=0.0, contact="half")
    with pytest.raises(ValueError, match="^force: must be > 0"):
        solve_dimensionless(1.0, 0.05, 0.0, [1.0], force=0.0, moment=0.0,
                            contact="unilateral")
    with pytest.raises(ValueError, match="^moment: the eccentricity"):
        solve_unilateral(1.0, 0.05, 0.0, [1.0], force=1.0, moment=-1.0)
    with pytest.raises(ValueError, match="^time_steps"):
        solve_unilateral(1.0, 0.05, 0.0, [1.0], force=1.0, moment=0.0, time_steps=0)


@pytest.mark.parametrize("contact", ["unilateral", "auto"])
def test_loads_leaving_no_contact_are_refused_by_the_contact_models(contact):
    """A pulled punch or a resultant outside it has no answer in a contact model: the
    dimensionless API refuses it naming the load, as the dimensional one does."""
    def solve(**loads):
        return solve_dimensionless(1.0, 0.05, 0.0, [1.0, 2.0], contact=contact, **loads)

    with pytest.raises(ValueError, match=r"^force: the punch is pulled away \(P = -1 at"):
        solve(force=-1.0, moment=0.0)
    with pytest.raises(ValueError, match=r"^force: the punch is pulled away"):
        solve(force=-1.0, tilt=0.0)  # a mixed statement: pulled all the same
    with pytest.raises(ValueError, match=r"^force: must be > 0 .*P = 0 at every time"):
        solve(force=0.0, moment=0.0)
    with pytest.raises(ValueError, match=r"^moment: the eccentricity M/P = 1 at t = 1"):
        solve(force=1.0, moment=1.0)
    with pytest.raises(ValueError, match=r"^moment: the eccentricity M/P = -1.5 at t = 2"):
        solve(force=1.0, moment=lambda t: -0.75 * t)
    with pytest.raises(ValueError, match=r"^moment: M = 0.1 with no force"):
        solve(force=lambda t: t - 1.0, moment=0.1)
    # a creeping base remembers the loads between output times: a pull there is refused
    with pytest.raises(ValueError, match=r"^force: the punch is pulled away \(P = -1 at t = 1\.49"):
        solve_dimensionless(1.0, 0.05, 0.0, [1.0, 2.0], contact=contact,
                            kernel=lambda t, tau: 0.1 * np.exp(-(t - tau)),
                            force=lambda t: np.where(np.abs(t - 1.5) < 0.01, -1.0, 1.0),
                            moment=0.0)
    # a given settlement and tilt may leave the punch above the surface: not refused here
    lifted = solve(settlement=-1.0, tilt=0.0)
    assert lifted.contact_set == [[], []]


def test_the_full_contact_model_answers_any_load_with_its_flag():
    """contact="full" is the linear full-contact equation (the seed's model problem): a
    pull or a resultant outside the punch is answered, flagged contact_lost."""
    for loads in ({"force": -1.0, "moment": 0.0}, {"force": 1.0, "moment": 1.0}):
        r = solve_dimensionless(1.0, 0.05, 0.0, [1.0, 2.0], contact="full", **loads)
        assert r.info["contact"] == "full" and "contact_lost" in r.flags
        assert np.isfinite(r.settlement).all() and np.isfinite(r.tilt).all()


def test_full_contact_result_carries_the_whole_base():
    r = solve_dimensionless(1.0, 0.05, 0.0, [1.0, 2.0], force=1.0, moment=0.45,
                            contact="full")
    assert r.info["contact"] == "full" and "contact_lost" in r.flags
    assert r.contact_set == [[(-1.0, 1.0)], [(-1.0, 1.0)]]
    auto = solve_dimensionless(1.0, 0.05, 0.0, [1.0, 2.0], force=1.0, moment=0.45)
    assert auto.info["contact"] == "unilateral" and auto.flags == []
    assert len(auto.contact_set) == 2 and auto.contact_set[0] == auto.contact_set[1]


def test_contact_set_from_pressure():
    x = np.linspace(-1.0, 1.0, 5)
    q = np.column_stack([[1.0, 1.0, 1.0, 1.0, 1.0], [-1.0, 1.0, -1.0, -1.0, 1.0]])
    full, split = contact_set_from_pressure(x, q)
    assert full == [(-1.0, 1.0)]
    assert split == [(-0.75, -0.25), (0.75, 1.0)]
    with pytest.raises(ValueError, match="^x:"):
        contact_set_from_pressure(x[::-1], q)


# ---------------------------------------------------------------------- scenes, CLI


def _elastic_preset(contact: str | None = None) -> dict:
    scene = scene_file("eccentric_footing_liftoff")
    scene["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    scene["times"] = [0.0, 10.0]
    if contact is not None:
        scene["solver"]["contact"] = contact
    return scene


def test_scene_contact_field_and_dimensional_contact_set():
    bad = _elastic_preset("sometimes")
    with pytest.raises(ValueError, match="^solver.contact: must be one of"):
        scene_from_dict(bad)
    assert "contact" not in scene_from_dict(_elastic_preset()).to_dict()["solver"]
    assert scene_from_dict(_elastic_preset("full")).to_dict()["solver"]["contact"] == "full"
    full = solve(_elastic_preset("full"))
    assert full.contact_lost and full.contact_set == [[(-1.0, 1.0)]] * 2
    result = solve(_elastic_preset())
    assert result.info["contact"] == "unilateral" and result.flags == []
    (zone,) = result.contact_set[0]
    a = result.scene.half_width
    assert zone[1] == a and -a < zone[0] < 0.0
    # the zone in metres is the dimensionless zone times a
    assert zone[0] == pytest.approx(a * result.dimensionless.contact_set[0][0][0], rel=1e-15)
    data = result.to_dict()
    assert data["contact_set"][0] == [list(zone)]
    lines = result.to_csv(header=False).splitlines()
    assert lines[0].endswith(",contact_length_m,zone1_start_m,zone1_end_m")
    row = [float(v) for v in lines[1].split(",")]
    assert row[-3] == pytest.approx(zone[1] - zone[0]) and row[-2:] == list(zone)


def test_cli_writes_the_contact_set(tmp_path: Path):
    from core.cli import main

    scene_path = tmp_path / "scene.json"
    scene_path.write_text(json.dumps(_elastic_preset()))
    out = tmp_path / "out.json"
    assert main(["solve", str(scene_path), "--output", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["info"]["contact"] == "unilateral"
    assert len(data["contact_set"]) == 2 and len(data["contact_set"][0]) == 1
    csv = tmp_path / "out.csv"
    assert main(["solve", str(scene_path), "--output", str(csv)]) == 0
    # the table after the "# key: value" lines of what made it, and its header
    table = [line for line in csv.read_text().splitlines() if not line.startswith("#")]
    rows = np.loadtxt(table, delimiter=",", skiprows=1)
    assert rows.shape == (2, 8)


def test_lift_off_preset_lifts_off_and_meets_its_tolerance():
    scene = copy.deepcopy(scene_file("eccentric_footing_liftoff"))
    scene["times"] = {"end": 1000.0, "count": 5, "spacing": "log"}
    result = solve(scene)
    assert result.info["contact"] == "unilateral"
    assert result.flags == [], result.flag_messages
    assert all(len(z) == 1 and z[0][0] > -result.scene.half_width
               for z in result.contact_set)


@pytest.mark.parametrize("gap, loads", [
    (0.0, {"force": 1.0, "moment": 0.45}),
    ("worn", {"force": 0.01, "moment": 0.002}),
])
def test_kink_corrected_ends_on_a_fixed_rule(gap, loads):
    """The ends a creep step reports (core/contact/kinks.py) on a fixed rule of 0.04-wide
    panels, against the elastic solver's ends refined on graded panels (to ~1e-10):
    measured 3.7e-8 (footing) and 7.3e-8 (worn patch, two ends) from 2.4e-6 and 1.8e-6
    where the nodal Q's interpolant changes sign; 1e-6 is the ends' own tolerance."""
    from core.contact.kinks import corrected_ends

    g = worn_patch if gap == "worn" else constant(gap)
    ref = solve_unilateral(1.0, 0.05, g, [1.0], tol=1e-10, **loads)
    ref_ends = [e for zone in ref.contact_set[0] for e in zone if abs(abs(e) - 1.0) > 1e-12]
    space = Space(1.0, constant(0.05), g, ())
    step = Step(1.0, 1.0, loads)
    panels = base_panels(1.0, (), edge_width=1e-2, max_width=0.04)
    op = kernel_operator(1.0, panels).matrix
    m, g_nodes = np.full(panels.size, 0.05), g(panels.nodes)
    state, _, _ = nodal_active_set(panels, op, m, g_nodes, step)
    ends = [e for e in corrected_ends(space, step, state, op, m, g_nodes)
            if abs(abs(e) - 1.0) > 1e-12]
    nodal = [e for e, pinned in zip(*zones_from_nodes(state)[:2], strict=True) if not pinned]
    assert len(ends) == len(ref_ends) == len(nodal)
    assert np.max(np.abs(np.subtract(ends, ref_ends))) < 2e-7
    assert np.max(np.abs(np.subtract(nodal, ref_ends))) > 1e-6  # what it corrects


@pytest.mark.parametrize("gap, loads", [
    (0.0, {"force": 1.0, "moment": 0.45}),
    ("worn", {"force": 0.01, "moment": 0.002}),
])
def test_kink_corrections_batched_with_kept_factors_equal_the_exact_solve(gap, loads):
    """The march's way (the change solved with a snapshot of the step's factors, several
    steps' cut parts in one evaluation, all roots in one secant) against the plain one
    (the corrected system solved anew, one step at a time): the change is refined to
    1e-9 of itself, so the ends agree far below their 1e-6 (measured: at most 6.7e-16
    on the footing, 4.7e-12 on the worn patch; 5e-11 leaves a margin of 10)."""
    from core.contact.kinks import corrected_ends, corrected_roots, kinks_corrected
    from core.contact.systems import StepSolver

    g = worn_patch if gap == "worn" else constant(gap)
    space = Space(1.0, constant(0.05), g, ())
    panels = base_panels(1.0, (), edge_width=1e-2, max_width=0.04)
    op = kernel_operator(1.0, panels).matrix
    m, g_nodes = np.full(panels.size, 0.05), g(panels.nodes)
    batch, plain = [], []
    solver = StepSolver()
    for scale in (1.0, 0.97, 0.9):  # three steps with their own c/s, one solver
        step = Step(1.0, scale, loads)
        state, _, _ = nodal_active_set(panels, op, m, g_nodes, step, solver=solver)
        plain.append(corrected_ends(space, step, state, op, m, g_nodes))
        batch.append((step, state, None, None, solver.snapshot(),
                      tuple(zones_from_nodes(state)[:2])))
    batched = corrected_roots(space, kinks_corrected(space, op, m, g_nodes, batch))
    for a, b in zip(batched, plain, strict=True):
        assert len(a) == len(b)
        assert np.max(np.abs(np.subtract(a, b))) < 5e-11, (a, b)


def test_elastic_answer_does_not_depend_on_earlier_solves():
    """The nodal active set starts from the zones of the coarser rule, found from full
    contact there: a scene's digits are the same whatever was solved before it."""
    args = dict(force=1.0, moment=0.45, tol=1e-6)
    first = solve_unilateral(1.0, 0.05, 0.0, [1.0], **args)
    for moment in (0.6, 0.3, 0.8):  # other loads on the same geometry
        solve_unilateral(1.0, 0.05, 0.0, [1.0], force=1.0, moment=moment, tol=1e-6)
    solve_unilateral(1.0, 0.05, worn_patch, [1.0], force=0.01, moment=0.0)
    again = solve_unilateral(1.0, 0.05, 0.0, [1.0], **args)
    assert again.contact_set == first.contact_set
    assert again.settlement[0] == first.settlement[0] and again.tilt[0] == first.tilt[0]


@pytest.mark.parametrize("gap, loads", [
    (0.0, {"force": 1.0, "moment": 0.6}), (0.0, {"force": 1.0, "moment": 0.8}),
    ("worn", {"force": 0.01, "moment": 0.0}), ("worn", {"force": 0.01, "moment": 0.002})])
def test_coarse_start_settles_on_the_set_found_from_full_contact(gap, loads):
    """Only the start changes: the settled nodal set is the one found from full contact
    (the discrete problem has one solution), in fewer sweeps on the fine rule."""
    from core.contact.nodal import coarse_start, nodal_operator
    from core.contact.unilateral import nodal_resolution

    g = worn_patch if gap == "worn" else constant(gap)
    space = Space(1.0, constant(0.05), g, ())
    res = nodal_resolution(1.0, constant(0.05))
    base, op = nodal_operator(1.0, (), res)
    m, g_nodes = np.full(base.size, 0.05), g(base.nodes)
    step = Step(1.0, 1.0, loads)
    full, full_sweeps, _ = nodal_active_set(base, op, m, g_nodes, step)
    start = coarse_start(space, step, base, res)
    assert start is not None
    state, sweeps, settled = nodal_active_set(base, op, m, g_nodes, step, start=start)
    assert settled and np.array_equal(state.active, full.active)
    assert sweeps < full_sweeps


class _BandStub:
    """Marches whose checks never agree on the zone ends (and on the outputs and q off
    the bands where ``outputs`` is not 0), on a band 0.1 wide: a rule is its band width,
    its nodes 16 per panel over the band."""

    def __init__(self, outputs: float = 0.0) -> None:
        self.marched: list[float] = []
        self.outputs = outputs

    def rule(self, res, bands, width):
        return width

    @staticmethod
    def halved(res):
        return res

    edges_halved = halved

    @staticmethod
    def nodes(rule) -> int:
        return int(round(16 * 0.1 / rule))

    def run(self, rule, grid, widths, index, exact_ends=True, first=None):
        self.marched.append(rule)
        return {"rule": rule}, None

    @staticmethod
    def distance(a, b):
        return 1.0, 1.0

    def rule_distance(self, rule, a, finer, b, bands):
        return self.outputs, 1.0, np.zeros(1), np.ones(1, dtype=bool)

    @staticmethod
    def banded(bands) -> bool:
        return bool(bands)


def test_band_panels_finer_than_0_005_are_a_last_resort(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from core.contact import creep

    def select(slope: float, outputs: float = 0.0) -> tuple[float, list[float]]:
        stub = _BandStub(outputs)
        rule, *_ = creep._select_rule(stub, np.array([1.0, 2.0]), None, 4, 1e-6, 1e-6,
                                      bands=[(0.0, 0.1)], slope=slope)
        return rule, stub.marched

    # where the ends' error through q's slope would alone fail tol: every width, the last
    # (0.0025) checked against 0.00125 (1280 nodes)
    assert select(1.0) == (0.0025, [0.02, 0.01, 0.005, 0.0025, 0.00125])
    assert creep.BAND_WIDTHS[-1] == 0.0025 < creep.LAST_RESORT_BELOW == 0.005
    # where it would not (no free end: slope 0), 0.005 stays the last
    assert select(0.0) == (0.005, [0.02, 0.01, 0.005, 0.0025])
    # ... unless the outputs or q off the bands miss their share: the finer rule, whose
    # base is finer too, is taken
    assert select(0.0, outputs=1.0) == (0.0025, [0.02, 0.01, 0.005, 0.0025, 0.00125])
    # a check of more nodes than allowed is not marched
    monkeypatch.setattr(creep, "MAX_CHECK_NODES", 700)
    assert select(1.0) == (0.005, [0.02, 0.01, 0.005, 0.0025])
    # the widths down to 0.005 are tried whatever their checks cost (as before 0.0025)
    monkeypatch.setattr(creep, "MAX_CHECK_NODES", 100)
    assert select(1.0) == (0.005, [0.02, 0.01, 0.005, 0.0025])
