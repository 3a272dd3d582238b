"""The projection solver on the hard cases of the benchmark suite (smaller versions).

For every case: convergence under refinement at an asserted algebraic rate, finite
answers, equilibrium (int q = P, int x q = M), an error estimate that bounds
the error measured against an independent reference, and no claim of success for a
tolerance that was not met. Then: orthonormality of large bases, extreme ``lam``, loads
that reverse sign under creep, and a stiff creep kernel against its closed form.

Errors are measured as the solver defines its tolerance: settlement and tilt relative to
``max(|delta|, |alpha|)``, force and moment relative to ``max(|P|, |M|)``, the pressure
on the whole of [-1, 1] (edges and both sides of every jump approached to 1e-10)
relative to ``max|q|``, the largest over all output times. Every bound below quotes the
value measured with the double-precision kernel; margins leave room for other BLAS
builds.

The pressure was once measured on interior points only (|x| <= 0.95, 0.02 off jumps),
as the solver then promised it: on the whole interval the same answers were 5e-5 to 8e-4
off at the edges while claiming success at tol 1e-6 (the graded mesh stopped at a tenth
of the edge layer). Earlier defects caught here: success claimed on the ten layers at tol
1e-3 (error 2.4e-3, estimate 9.3e-4), on the modulus jump at tol 1e-8 (1.8e-8, estimate
6.0e-9) and for the load reversing sign under creep at tol 1e-4 (1.02e-4, estimate
3.7e-5).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache
from typing import Any

import numpy as np
import pytest

from core.creep.models import ExponentialCreep
from core.discretize import base_panels, build_basis, graded_cuts
from core.engines.collocation.solve import solve_collocation
from core.solver import solve_dimensionless as _solve_dimensionless
from tests.support.points import whole_interval
from tests.support.scenes import CONCRETE, TEN_LAYERS, jump_m, rough_g, smooth_m, stepped_g


def solve_dimensionless(*args: Any, **kwargs: Any):
    """The projection method (this file checks it; tests/engines/test_nystrom.py the default)."""
    return _solve_dimensionless(*args, method="projection", **kwargs)

# ------------------------------------------------------------------------------ cases
# The coatings, gaps and creep of the benchmark suite (tests/support/scenes.py); the ten
# layers here are scaled to a mean m of 0.13 (the benchmark's: 0.08).


def ten_layer_m(x):
    x = np.asarray(x, dtype=float)
    total = np.zeros(x.shape)
    for h0, a, b, e0, e, w, nu in TEN_LAYERS:
        total = total + (1 - nu**2) * h0 * (1 + a * x + b * x**2) / (
            e0 * (1 + e * np.cos(np.pi * w * x)))
    return 0.03 * total  # mean m = 0.13


KERNEL = CONCRETE.dimensionless_kernel(28.0)
C_OF_T = CONCRETE.relative_modulus(28.0)
#: Loading at 28 days, outputs over 1000 days.
CREEP_TIMES = 1.0 + np.linspace(0.0, 1000.0 / 28.0, 12)


@dataclass(frozen=True)
class Case:
    lam: float
    m: Callable | float
    g: Callable | float = 0.0
    breakpoints: tuple[float, ...] = ()
    loads: dict[str, Any] = field(default_factory=lambda: {"force": 1.0, "moment": 0.1})
    # Collocation resolution of the reference (panels_per_unit, edge_width).
    reference: tuple[float, float] = (4, 1e-3)

    def args(self) -> dict[str, Any]:
        return dict(breakpoints=self.breakpoints, **self.loads)


# Reference accuracy (collocation against a 4x finer collocation, measured): modulus jump
# 1.2e-10, stepped 3.2e-11, rough 1.4e-12 (at (8, 1e-4)), thin 7.9e-12, thick 3.3e-11,
# no coating 1.1e-9 (at (8, 1e-4)), ten layers 6.7e-11: far below every error checked.
CASES = {
    "modulus_jump": Case(1.0, jump_m, breakpoints=(0.3,)),
    "stepped_punch": Case(1.0, smooth_m, stepped_g, breakpoints=(-0.5, 0.25)),
    "rough_punch": Case(1.0, smooth_m, rough_g, reference=(8, 1e-4)),
    "thin_base": Case(50.0, smooth_m),
    "thick_base": Case(0.05, smooth_m),
    "no_coating": Case(1.0, 1e-4, reference=(8, 1e-7)),
    "ten_layers": Case(1.0, ten_layer_m),
}

#: Algebraic rate of the error (q on the whole of [-1, 1], edges included) in the number
#: of modes, fitted over n = 64, 128, 256, per basis. Measured, piecewise: modulus jump
#: 2.07, stepped 2.02, rough 2.62, thin 1.99, thick 2.00, no coating 1.19 (square-root
#: edge layers of width 1e-4), ten layers 2.00. Graded: modulus jump 4.56, stepped 3.72,
#: rough 3.97, thin 5.96, thick 6.80, no coating 5.22, ten layers 4.55. (On interior
#: points only the rates were 3.3-3.5 and 4.9-8.3: the edges converge last.)
RATE_COUNTS = (64, 128, 256)
RATES = {
    "piecewise": {"modulus_jump": 1.8, "stepped_punch": 1.7, "rough_punch": 2.2,
                  "thin_base": 1.7, "thick_base": 1.7, "no_coating": 1.0, "ten_layers": 1.7},
    "graded": {"modulus_jump": 3.9, "stepped_punch": 3.2, "rough_punch": 3.4,
               "thin_base": 5.0, "thick_base": 5.8, "no_coating": 4.5, "ten_layers": 3.9},
}


def sample_points(breakpoints=()):
    """The whole of [-1, 1]: 2001 even points, and 25 more toward each edge and each side
    of every jump, from 5e-2 down to 1e-10 away (the solver promises q there too)."""
    return whole_interval(2001, near=25, jumps=breakpoints)


def relative_error(sol, ref, xs) -> float:
    """The solver's error measure of ``sol`` against ``ref`` (over all times)."""
    kin = max(np.max(np.abs(ref.settlement)), np.max(np.abs(ref.tilt)))
    dyn = max(np.max(np.abs(ref.force)), np.max(np.abs(ref.moment)))
    q, q_ref = sol.pressure(xs), ref.pressure(xs)
    return float(max(np.max(np.abs(sol.settlement - ref.settlement)) / kin,
                     np.max(np.abs(sol.tilt - ref.tilt)) / kin,
                     np.max(np.abs(sol.force - ref.force)) / dyn,
                     np.max(np.abs(sol.moment - ref.moment)) / dyn,
                     np.max(np.abs(q - q_ref)) / np.max(np.abs(q_ref))))


@cache
def reference(name: str):
    case = CASES[name]
    ppu, edge = case.reference
    return solve_collocation(case.lam, case.m, case.g, [1.0], panels_per_unit=ppu,
                             edge_width=edge, **case.args())


@cache
def projection(name: str, *, n_modes: int | None = None, tol: float = 1e-12,
               basis: str | None = None):
    """The projection solution of a case (``basis=None``: the solver's default)."""
    case = CASES[name]
    kind = {} if basis is None else {"basis": basis}
    return solve_dimensionless(case.lam, case.m, case.g, [1.0], n_modes=n_modes, tol=tol,
                               **kind, **case.args())


def error_of(name: str, sol) -> float:
    return relative_error(sol, reference(name), sample_points(CASES[name].breakpoints))


def assert_finite(sol, breakpoints=()) -> None:
    x = np.concatenate([np.linspace(-1.0, 1.0, 201), np.asarray(breakpoints) - 1e-9,
                        np.asarray(breakpoints) + 1e-9])
    for values in (sol.settlement, sol.tilt, sol.force, sol.moment, sol.pressure(x)):
        assert np.all(np.isfinite(values))
    assert np.isfinite(sol.info["error_estimate"])


def integrals(sol, breakpoints=()) -> tuple[np.ndarray, np.ndarray]:
    """``int q dx`` and ``int x q dx`` over [-1, 1] by a fine graded Gauss rule (per time).

    The rule breaks at the element ends of the solution's basis too (white box: the
    basis' pieces): the graded basis has kinks there, which a Gauss panel across them
    integrates only to ~1e-9 (measured).
    """
    ends = {float(e) for e in sol.info["element_ends"]} | {-1.0, 1.0}
    cuts = sorted(e for e in ends if -1.0 < e < 1.0 and min(
        [abs(e - b) for b in breakpoints], default=1.0) > 1e-12)
    rule = base_panels(1.0, breakpoints, edge_width=1e-9, max_width=0.02, soft_cuts=cuts)
    q = sol.pressure(rule.nodes)
    return rule.weights @ q, (rule.weights * rule.nodes) @ q


# ------------------------------------------------------------------ elastic hard cases


@pytest.mark.parametrize("kind", list(RATES))
@pytest.mark.parametrize("name", list(CASES))
def test_converges_at_rate_under_mode_refinement(name, kind):
    counts = RATE_COUNTS
    errors = []
    for n in counts:
        sol = projection(name, n_modes=n, basis=kind)
        assert_finite(sol, CASES[name].breakpoints)
        errors.append(error_of(name, sol))
    errors = np.array(errors)
    assert np.all(np.diff(errors) < 0), errors
    rate = -np.polyfit(np.log(counts), np.log(errors), 1)[0]
    assert rate >= RATES[kind][name], (rate, errors)


@pytest.mark.parametrize("name", list(CASES))
def test_equilibrium_and_finite(name):
    case = CASES[name]
    sol = projection(name, tol=1e-5)
    assert_finite(sol, case.breakpoints)
    p, m = integrals(sol, case.breakpoints)
    scale = max(abs(case.loads["force"]), abs(case.loads["moment"]))
    # Measured |int q - P| / P and |int x q - M| / P <= 6.7e-16 over the cases.
    bound = 1e-13
    assert abs(p[0] - case.loads["force"]) / scale < bound
    assert abs(m[0] - case.loads["moment"]) / scale < bound


#: Adaptive tolerances the default solver should meet on every case.
REACHABLE = (1e-3, 1e-4, 1e-5)


@pytest.mark.parametrize("tol", REACHABLE)
@pytest.mark.parametrize("name", list(CASES))
def test_error_estimate_bounds_the_error(name, tol):
    # Measured estimate / error (q on the whole of [-1, 1]) at tol 1e-3, 1e-4, 1e-5 (graded
    # default): modulus jump 8.2, 22, 4.3; stepped 1.5, 7.2, 7.2; rough 4.4, 20, 20; thin
    # 2.2, 1.5, 6.1; thick 6.3, 1.8, 25; no coating 7.1, 66, 7.1; ten layers 8.2, 4.5, 17.
    # The estimate is floored at the last level difference (the basis converges in steps),
    # so it reads high rather than low: it bounds the error (the lowest ratio measured in
    # this file is 1.5).
    sol = projection(name, tol=tol)
    measured = error_of(name, sol)
    ratio = sol.info["error_estimate"] / measured
    assert 1.0 <= ratio <= 100.0, (sol.info["error_estimate"], measured, sol.info["n_modes"])


@pytest.mark.parametrize("tol", (1e-3, 1e-4, 1e-5, 1e-6, 1e-8))
@pytest.mark.parametrize("name", list(CASES))
def test_success_only_when_tol_met(name, tol):
    # Measured failures (reported): ten layers at 1e-3 (error 2.4e-3, estimate 9.3e-4,
    # 48 modes); modulus jump at 1e-8 (1.8e-8, estimate 6.0e-9, 256 modes). Rough: tol
    # 1e-5 and below are out of reach (1.6e-5 at 256 modes, estimate 1.7e-5, reported).
    sol = projection(name, tol=tol)
    measured = error_of(name, sol)
    if sol.info["success"]:
        assert measured <= tol, (measured, sol.info["error_estimate"], sol.info["n_modes"])
        assert "tol_not_met" not in sol.info["flags"]
    else:
        assert "tol_not_met" in sol.info["flags"]
        assert "not met" in sol.info["message"]


def test_beyond_reach_says_so():
    # No coating at 1e-9: the edge layers of width 1e-4 hold the graded basis at a measured
    # 4.7e-9 with 512 modes (estimate 3.3e-8).
    sol = projection("no_coating", tol=1e-9)
    assert not sol.info["success"]
    assert "tol_not_met" in sol.info["flags"]
    assert error_of("no_coating", sol) > 1e-9
    assert sol.info["error_estimate"] > 1e-9
    # The rough punch at 1e-6 (graded default): measured 2.1e-6 at 512 modes (estimate
    # 9.6e-6).
    sol = projection("rough_punch", tol=1e-6)
    assert not sol.info["success"] and "tol_not_met" in sol.info["flags"]
    assert error_of("rough_punch", sol) > 1e-6
    assert sol.info["error_estimate"] > 1e-6
    # The piecewise basis on the rough punch at 1e-8: measured 1.5e-4 at 512 modes
    # (estimate 4.1e-5).
    sol = projection("rough_punch", tol=1e-8, basis="piecewise")
    assert not sol.info["success"] and "tol_not_met" in sol.info["flags"]
    assert error_of("rough_punch", sol) > 1e-8
    assert sol.info["error_estimate"] > 1e-8


# ---------------------------------------------------------------------------- bases


def _bases_at(count: int):
    bps = (0.3,)
    panels = base_panels(1.0, bps, max_width=0.1)
    m_nodes = jump_m(panels.nodes)
    for kind in ("global", "piecewise"):
        yield kind, build_basis(panels, m_nodes, count, breakpoints=bps, kind=kind)
    cuts = graded_cuts(bps, 1.0, jump_m)
    graded_panels = base_panels(1.0, bps, max_width=0.1, soft_cuts=cuts)
    yield "graded", build_basis(graded_panels, jump_m(graded_panels.nodes), count,
                                breakpoints=bps, kind="graded", cuts=cuts)


def test_basis_orthonormal_to_machine_precision_at_160_modes():
    # Measured max |G - I|: global 1.6e-15, piecewise 1.3e-15, graded 1.7e-15 (896 nodes;
    # m jumps at 0.3).
    for kind, basis in _bases_at(160):
        assert basis.size >= 100, kind
        assert basis.orthonormality_error < 2e-14, (kind, basis.orthonormality_error)


# ------------------------------------------------------------------ extremes of lam


def test_tiny_and_huge_lam_in_one_run():
    xs = sample_points()
    for lam, n_measured in ((0.01, 256), (100.0, 256)):
        sol = solve_dimensionless(lam, 0.1, 0.0, [1.0], force=1.0, moment=0.1, tol=1e-5)
        ref = solve_collocation(lam, 0.1, 0.0, [1.0], force=1.0, moment=0.1,
                                panels_per_unit=4, edge_width=1e-3)
        assert_finite(sol)
        measured = relative_error(sol, ref, xs)
        # Measured: lam 0.01: error 1.9e-8, estimate 4.7e-7, 256 modes; lam 100: error
        # 2.1e-8, estimate 1.3e-7, 256 modes (references within 6e-10 and 5e-10 of the
        # Nystrom answer at tol 1e-11, edges included).
        assert sol.info["success"] and measured <= 1e-5
        assert 1.0 <= sol.info["error_estimate"] / measured <= 100.0
        assert sol.info["n_modes"] <= 2 * n_measured
        p, m = integrals(sol)
        assert abs(p[0] - 1.0) < 1e-13 and abs(m[0] - 0.1) < 1e-13  # measured <= 4.4e-16
    # lam = 100 is nearly Winkler: delta -> P (m + 1/(2 lam))/2, q(0) -> P/2; measured
    # relative differences 4.6e-5 and 4.7e-5 (the nonlocal correction, O(1/lam^2)).
    assert abs(sol.settlement[0] / (0.5 * (0.1 + 1 / 200)) - 1.0) < 2e-4
    assert abs(sol.pressure([0.0])[0, 0] / 0.5 - 1.0) < 2e-4


# ------------------------------------------------------------------------ creep cases


@cache
def creep_reference(loads_key: str):
    """Tight projection at the first and last output times.

    512 modes (estimate 2.1e-9 aging, 2.4e-9 cyclic load, measured); time tol 1e-8
    (aging: the settlement differs from tol 1e-10 by 4e-12 relative).
    """
    return solve_dimensionless(1.0, smooth_m, 0.0, CREEP_TIMES[[0, -1]], c=C_OF_T,
                               kernel=KERNEL, n_modes=512, tol=1e-8, **CREEP_LOADS[loads_key])


def cyclic_force(t):
    return 1.0 + 0.5 * np.sin(0.5 * np.pi * (np.asarray(t, dtype=float) - 1.0))


def cyclic_moment(t):
    t = np.asarray(t, dtype=float)
    return cyclic_force(t) * (0.05 + 0.15 * (1.0 - np.exp(-(t - 1.0) / 3.0)))


CREEP_LOADS = {"aging": {"force": 1.0, "moment": 0.1},
               "eccentric": {"force": cyclic_force, "moment": cyclic_moment}}


def test_creep_reference_agrees_with_collocation():
    # Independent check of the creep reference: collocation (2 panels per unit, 128 time
    # points + Richardson) differs by 6.9e-6, its own time error (9.7e-5 at 64 points,
    # order 4).
    ref = creep_reference("aging")
    coll = solve_collocation(1.0, smooth_m, 0.0, CREEP_TIMES[[0, -1]], c=C_OF_T, kernel=KERNEL,
                             panels_per_unit=2, edge_width=1e-2, time_points=128,
                             **CREEP_LOADS["aging"])
    assert relative_error(coll, ref, sample_points()) < 2e-5


#: Time tolerance of the tight run each time sweep is measured against. For the cyclic
#: load tol = 1e-12 is out of reach (the step control asks for local errors below
#: round-off: 20000 steps, then it stops), 1e-10 takes ~1000 steps.
ORDER_IN_TIME = {"aging": 4.5, "eccentric": 4.5}
PESSIMISM_IN_TIME = {"aging": 10.0, "eccentric": 50.0}
TIGHT_TIME_TOL = {"aging": 1e-11, "eccentric": 1e-10}


@pytest.mark.parametrize("loads_key", list(CREEP_LOADS))
def test_creep_converges_in_time_at_high_order(loads_key):
    # At fixed n = 32, error against the tight run over the time tolerance (tol 1e-3 to
    # 1e-6; the steps aim at tol/30). Measured, aging: steps 16, 25, 38, 59 -> errors
    # 5.5e-7, 7.0e-8, 6.8e-9, 4.9e-10, order 5.4 in the number of steps (3-stage Radau
    # IIA, order 5), time estimate / error 0.54, 0.81, 1.3, 2.4. Cyclic load: steps
    # 64, 102, 161, 254 -> 4.8e-7, 1.4e-8, 1.8e-9, 5.1e-11, order 6.4; estimate / error
    # 3.3, 12, 9.5, 33: the estimate adds up local error estimates, which the oscillating
    # load makes cancel.
    kw = dict(c=C_OF_T, kernel=KERNEL, n_modes=32, **CREEP_LOADS[loads_key])
    xs = sample_points()
    tight = solve_dimensionless(1.0, smooth_m, 0.0, CREEP_TIMES, tol=TIGHT_TIME_TOL[loads_key],
                                **kw)
    assert tight.info["time_error_estimate"] < 1e-10
    steps, errors = [], []
    for tol in (1e-3, 1e-4, 1e-5, 1e-6):
        sol = solve_dimensionless(1.0, smooth_m, 0.0, CREEP_TIMES, tol=tol, **kw)
        assert_finite(sol)
        err = relative_error(sol, tight, xs)
        ratio = sol.info["time_error_estimate"] / err
        assert 0.5 <= ratio <= PESSIMISM_IN_TIME[loads_key], (tol, err, ratio)
        steps.append(sol.info["n_steps"])
        errors.append(err)
    order = -np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert order >= ORDER_IN_TIME[loads_key], (steps, errors)


@pytest.mark.parametrize("loads_key", list(CREEP_LOADS))
def test_creep_converges_in_modes(loads_key):
    # Error at the first and last times against the tight reference (graded default).
    # Measured, n = 64, 128, 256: aging 2.4e-4, 1.1e-5, 1.8e-8 (rate 6.8; estimate /
    # error 1.9, 1.8, 26); cyclic load 2.5e-4, 1.2e-5, 1.9e-8 (rate 6.8; 1.9, 1.8, 26).
    counts = (64, 128, 256)
    ref = creep_reference(loads_key)
    errors = []
    for n in counts:
        sol = solve_dimensionless(1.0, smooth_m, 0.0, CREEP_TIMES[[0, -1]], c=C_OF_T,
                                  kernel=KERNEL, n_modes=n, tol=1e-8,
                                  **CREEP_LOADS[loads_key])
        assert_finite(sol)
        errors.append(relative_error(sol, ref, sample_points()))
        assert 1.0 <= sol.info["error_estimate"] / errors[-1] <= 100.0
    rate = -np.polyfit(np.log(counts), np.log(errors), 1)[0]
    assert rate >= 5.8, errors


@pytest.mark.parametrize("tol", (1e-3, 1e-4, 1e-5))
@pytest.mark.parametrize("loads_key", list(CREEP_LOADS))
def test_creep_success_only_when_tol_met(loads_key, tol):
    # Measured (graded default), tol 1e-3, 1e-4, 1e-5: aging 96, 128, 256 modes, errors
    # 3.2e-5, 1.1e-5, 3.5e-8, estimates 2.0e-4, 2.1e-5, 5.7e-7; cyclic load 3.5e-5,
    # 1.2e-5, 2.3e-8, estimates 2.2e-4, 2.2e-5, 5.0e-7. Equilibrium defects <= 1.6e-15.
    sol = solve_dimensionless(1.0, smooth_m, 0.0, CREEP_TIMES[[0, -1]], c=C_OF_T,
                              kernel=KERNEL, tol=tol, **CREEP_LOADS[loads_key])
    measured = relative_error(sol, creep_reference(loads_key), sample_points())
    assert 1.0 <= sol.info["error_estimate"] / measured <= 100.0
    if sol.info["success"]:
        assert measured <= tol, (measured, sol.info["error_estimate"], sol.info["n_modes"])
    # Equilibrium at every time.
    p, m = integrals(sol)
    loads = CREEP_LOADS[loads_key]
    force = np.broadcast_to(np.asarray(loads["force"](sol.times) if callable(loads["force"])
                                       else loads["force"]), sol.times.shape)
    moment = np.broadcast_to(np.asarray(loads["moment"](sol.times)
                                        if callable(loads["moment"]) else loads["moment"]),
                             sol.times.shape)
    assert np.max(np.abs(p - force)) / np.max(np.abs(force)) < 1e-13
    assert np.max(np.abs(m - moment)) / np.max(np.abs(force)) < 1e-13


REVERSING_TIMES = np.linspace(1.0, 8.0, 15)
REVERSING = dict(c=C_OF_T, kernel=KERNEL, force=np.cos, moment=0.0)


@cache
def reversing_reference():
    """512 modes, time tol 1e-8 (estimate 1.9e-9, measured)."""
    return solve_dimensionless(1.0, smooth_m, 0.0, REVERSING_TIMES, n_modes=512, tol=1e-8,
                               contact="full", **REVERSING)


def test_reversing_load_reference_agrees_with_collocation():
    # Measured 7.0e-6: the collocation's time error at 28 time points (3.0e-6 at 56).
    coll = solve_collocation(1.0, smooth_m, 0.0, REVERSING_TIMES, panels_per_unit=2,
                             edge_width=1e-2, time_points=28, **REVERSING)
    assert relative_error(coll, reversing_reference(), sample_points()) < 2e-5


@pytest.mark.parametrize("tol", (1e-3, 1e-4, 1e-5))
def test_load_reversing_sign_under_creep(tol):
    # Measured error / estimate (graded default), tol 1e-3, 1e-4, 1e-5: 3.0e-5 / 1.9e-4,
    # 1.1e-5 / 1.9e-5, 3.9e-8 / 5.3e-7 (once 1.02e-4 / 3.7e-5 at tol 1e-4: success
    # claimed, reported).
    # the full-contact model answers a pull (flagged); the contact models refuse it
    sol = solve_dimensionless(1.0, smooth_m, 0.0, REVERSING_TIMES, tol=tol, contact="full",
                              **REVERSING)
    assert_finite(sol)
    # A pulling punch is not contact: the flag must say so.
    assert "contact_lost" in sol.info["flags"]
    p, _ = integrals(sol)
    assert np.max(np.abs(p - np.cos(REVERSING_TIMES))) < 1e-13  # measured <= 1.2e-15
    assert np.all(np.sign(sol.force[[0, 4, 9]]) == [1, -1, 1])
    assert sol.settlement[0] > 0 > sol.settlement[4] and sol.settlement[9] > 0
    measured = relative_error(sol, reversing_reference(), sample_points())
    assert 1.0 <= sol.info["error_estimate"] / measured <= 100.0
    if sol.info["success"]:
        assert measured <= tol, (measured, sol.info["error_estimate"], sol.info["n_modes"])


def _stiff_kernel():
    modulus = 3.0e10
    return ExponentialCreep(modulus, 1.0 / modulus, 1000.0).dimensionless_kernel(28.0)


STIFF_TIMES = np.array([1.0, 1.001, 1.01, 1.5, 3.0])


def test_stiff_exponential_creep_matches_closed_form():
    # ExponentialCreep with rate 1000/day, loaded at 28 days: dimensionless rate 28000.
    # With C_inf = 1/E, for t - 1 >> 1/28000 the base acts as an elastic one of half the
    # modulus: (I - V) q -> 2 q, so q(t) is the elastic answer for m/2, delta(t) twice its
    # delta (exp(-28000 * 0.001) = 7e-13: relaxed already at the second time); at t = 1 it
    # is the elastic answer for m. The piecewise basis for m and for m/2 spans the same
    # space, so the identity holds to round-off at a fixed mode count. Measured (256
    # modes, 45 steps at tol 1e-3, time estimate 1.3e-8; the piecewise basis stalls at
    # 6.5e-5 on the whole of [-1, 1], so tol 1e-4 is out of its reach): t = 1: 0 and
    # 1.5e-15 (q); later: settlement 1.4e-13, tilt 1.2e-13, q 8.4e-14.
    kw = dict(kernel=_stiff_kernel(), force=1.0, moment=0.1, basis="piecewise")
    sol = solve_dimensionless(1.0, smooth_m, 0.0, STIFF_TIMES, tol=1e-3, **kw)
    assert_finite(sol)
    assert sol.info["success"] and sol.info["n_steps"] < 1000
    n = sol.info["n_modes"]
    del kw["kernel"]
    initial = solve_dimensionless(1.0, smooth_m, 0.0, [1.0], n_modes=n, **kw)
    relaxed = solve_dimensionless(1.0, lambda x: 0.5 * smooth_m(x), 0.0, [1.0], n_modes=n,
                                  **kw)
    xs = sample_points()
    q = sol.pressure(xs)
    scale = np.max(np.abs(q))
    assert abs(sol.settlement[0] / initial.settlement[0] - 1.0) < 1e-11
    assert np.max(np.abs(q[:, 0] - initial.pressure(xs)[:, 0])) / scale < 1e-11
    for k in range(1, len(STIFF_TIMES)):
        assert abs(sol.settlement[k] / (2.0 * relaxed.settlement[0]) - 1.0) < 1e-11
        assert abs(sol.tilt[k] / (2.0 * relaxed.tilt[0]) - 1.0) < 1e-11
        assert np.max(np.abs(q[:, k] - relaxed.pressure(xs)[:, 0])) / scale < 1e-11


def test_stiff_exponential_creep_default_basis():
    # The same against tight elastic solves (tol 1e-10, which they do not reach: estimates
    # 1.3e-9 and 2.3e-9) with the default basis. Measured: 384 modes, 60 steps, error
    # 2.7e-9, estimate 2.2e-8.
    sol = solve_dimensionless(1.0, smooth_m, 0.0, STIFF_TIMES, kernel=_stiff_kernel(),
                              force=1.0, moment=0.1, tol=1e-6)
    assert_finite(sol)
    assert sol.info["success"] and sol.info["n_steps"] < 1000
    initial = solve_dimensionless(1.0, smooth_m, 0.0, [1.0], force=1.0, moment=0.1, tol=1e-10)
    relaxed = solve_dimensionless(1.0, lambda x: 0.5 * smooth_m(x), 0.0, [1.0], force=1.0,
                                  moment=0.1, tol=1e-10)
    xs = sample_points()
    q = sol.pressure(xs)
    scale = np.max(np.abs(q))
    errors = [abs(sol.settlement[0] - initial.settlement[0]) / sol.settlement[0],
              np.max(np.abs(q[:, 0] - initial.pressure(xs)[:, 0])) / scale]
    for k in range(1, len(STIFF_TIMES)):
        errors += [abs(sol.settlement[k] - 2.0 * relaxed.settlement[0]) / sol.settlement[k],
                   abs(sol.tilt[k] - 2.0 * relaxed.tilt[0]) / sol.settlement[k],
                   np.max(np.abs(q[:, k] - relaxed.pressure(xs)[:, 0])) / scale]
    measured = max(errors)
    assert measured <= 1e-6
    assert 1.0 <= sol.info["error_estimate"] / measured <= 100.0
