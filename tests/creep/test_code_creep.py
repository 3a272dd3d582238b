"""Creep of concrete by the design codes (core/creep/design_codes.py) and fitted kernels
(core/creep/kernel_fit.py).

Hand values follow fib Model Code 2010 (2013) and EN 1992-1-1:2004, equation numbers in
the comments. Tolerances are set from measured errors (written next to them).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from core.creep import creep_coefficient_curve, creep_model_from_spec
from core.creep.design_codes import RESOLUTION, CodeCreep
from core.creep.kernel_fit import fit_kernel, nonpositive_violation
from core.creep.models import Arutyunyan
from core.scene import scene_from_dict, solve
from core.solver import solve_dimensionless
from core.time import ModalProblem, solve_degenerate
from core.time.product_quadrature import _trapezoid_solve
from tests.conftest import scene_file

C30 = {"strength_class": "C30/37", "cement": "N", "relative_humidity": 60.0,
       "notional_size": 300.0}
#: t_T / t at 20 deg C (MC2010 5.1-85, EN 1992-1-1 B.10)
F20 = math.exp(13.65 - 4000.0 / 293.0)


def mc2010_phi_by_hand(t: float, t0: float, fcm: float, rh: float, h: float,
                       alpha: float) -> float:
    """fib MC2010 creep coefficient at 20 deg C, written out equation by equation."""
    t0_t = t0 * F20                                                      # 5.1-85
    t0_adj = max(t0_t * (9.0 / (2.0 + t0_t**1.2) + 1.0) ** alpha, 0.5)   # 5.1-73
    phi_bc = 1.8 / fcm**0.7 * math.log((30.0 / t0_adj + 0.035) ** 2 * (t - t0) + 1.0)
    # ^ 5.1-64, 5.1-65, 5.1-66
    alpha_fcm = math.sqrt(35.0 / fcm)                                    # 5.1-71d
    beta_h = min(1.5 * h + 250.0 * alpha_fcm, 1500.0 * alpha_fcm)        # 5.1-71c
    gamma = 1.0 / (2.3 + 3.5 / math.sqrt(t0_adj))                        # 5.1-71b
    phi_dc = (412.0 / fcm**1.4                                           # 5.1-68
              * (1.0 - rh / 100.0) / (0.1 * h / 100.0) ** (1.0 / 3.0)    # 5.1-69
              / (0.1 + t0_adj**0.2)                                      # 5.1-70
              * ((t - t0) / (beta_h + t - t0)) ** gamma)                 # 5.1-71a
    return phi_bc + phi_dc                                               # 5.1-63, 5.1-67


def ec2_phi_by_hand(t: float, t0: float, fcm: float, rh: float, h0: float,
                    alpha: float) -> float:
    """EN 1992-1-1 Annex B creep coefficient at 20 deg C, equation by equation."""
    a1, a2, a3 = (35 / fcm) ** 0.7, (35 / fcm) ** 0.2, (35 / fcm) ** 0.5  # B.8c
    if fcm <= 35:
        phi_rh = 1 + (1 - rh / 100) / (0.1 * h0 ** (1 / 3))             # B.3a
        beta_h = min(1.5 * (1 + (0.012 * rh) ** 18) * h0 + 250, 1500)    # B.8a
    else:
        phi_rh = (1 + (1 - rh / 100) / (0.1 * h0 ** (1 / 3)) * a1) * a2  # B.3b
        beta_h = min(1.5 * (1 + (0.012 * rh) ** 18) * h0 + 250 * a3, 1500 * a3)  # B.8b
    t0_t = t0 * F20                                                      # B.10
    t0_mod = max(t0_t * (9 / (2 + t0_t**1.2) + 1) ** alpha, 0.5)         # B.9
    phi_0 = phi_rh * 16.8 / math.sqrt(fcm) / (0.1 + t0_mod**0.20)        # B.2, B.4, B.5
    return phi_0 * ((t - t0) / (beta_h + t - t0)) ** 0.3                 # B.1, B.7


@pytest.mark.parametrize(("spec", "alpha"), [
    (dict(C30), 0.0),
    ({"fcm": 25.0, "cement": "S", "relative_humidity": 45.0, "notional_size": 100.0}, -1.0),
    ({"fcm": 70.0, "cement": "R", "relative_humidity": 85.0, "notional_size": 800.0}, 1.0),
])
def test_creep_coefficients_by_hand(spec, alpha):
    fcm = spec.get("fcm", 38.0)
    rh, h = spec["relative_humidity"], spec["notional_size"]
    mc = CodeCreep("fib_mc2010", spec)
    ec = CodeCreep("eurocode2", spec)
    for t0 in (1.0, 3.0, 28.0, 365.0):
        for d in (0.1, 10.0, 365.0, 18262.5):
            want_mc = mc2010_phi_by_hand(t0 + d, t0, fcm, rh, h, alpha)
            want_ec = ec2_phi_by_hand(t0 + d, t0, fcm, rh, h, alpha)
            # the same formulas in another order: agreement to rounding (measured 4e-16)
            assert mc.creep_coefficient(t0 + d, t0) == pytest.approx(want_mc, rel=1e-13)
            assert ec.creep_coefficient(t0 + d, t0) == pytest.approx(want_ec, rel=1e-13)
    if spec == C30:
        # worked example, C30/37 (fcm 38), N, RH 60 %, h 300 mm, t0 = 28 d, 50 years:
        # MC2010: t0_adj = 27.9475; beta_bc(fcm) = 0.141067, beta_bc(t,t0) = 10.01856,
        # phi_bc = 1.41328; beta_dc(fcm) = 2.53046, beta(RH) = 0.597521,
        # beta_dc(t0) = 0.488624, beta_h = 689.929, gamma = 0.337603,
        # beta_dc(t,t0) = 0.987559, phi_dc = 0.729610; phi = 2.14289.
        assert mc.creep_coefficient(28 + 18262.5, 28) == pytest.approx(2.14289, abs=1e-5)
        # EC2: phi_RH = 1.53858, beta(fcm) = 2.72532, beta(t0) = 0.488624,
        # beta_H = 691.145, beta_c = 0.988918; phi = 2.02615 (Figure 3.1 reads ~2.0
        # between its inside (50 %) and outside (80 %) curves for C30/37, h0 300, t0 28)
        assert ec.creep_coefficient(28 + 18262.5, 28) == pytest.approx(2.02615, abs=1e-5)


def test_moduli_by_hand_and_the_codes_tables():
    mc = CodeCreep("fib_mc2010", C30)
    ec = CodeCreep("eurocode2", C30)
    # MC2010 Table 5.1-7: E_ci = 33.6 GPa for C30 (5.1-21: 21.5 (38/10)^(1/3) GPa)
    assert mc.modulus(28.0 / F20) / 1e9 == pytest.approx(33.6, abs=0.05)
    # EN 1992-1-1 Table 3.1: E_cm = 33 GPa for C30/37; E_c = 1.05 E_cm (3.1.4(2))
    assert ec.modulus(28.0) / 1.05 / 1e9 == pytest.approx(33.0, abs=0.2)
    for age in (1.0, 3.0, 7.0, 90.0, 3650.0):
        beta_cc_mc = math.exp(0.25 * (1 - math.sqrt(28 / (age * F20))))      # 5.1-51
        e_mc = 21500 * 3.8 ** (1 / 3) * math.sqrt(beta_cc_mc)             # 5.1-56/57
        beta_cc_ec = math.exp(0.25 * (1 - math.sqrt(28 / age)))              # 3.2
        e_ec = 1.05 * 22000 * 3.8**0.3 * beta_cc_ec**0.3                     # 3.5
        assert mc.modulus(age) == pytest.approx(1e6 * e_mc, rel=1e-13)
        assert ec.modulus(age) == pytest.approx(1e6 * e_ec, rel=1e-13)


@pytest.mark.parametrize("temperature", [5.0, 20.0, 30.0])
def test_the_compliance_divides_phi_by_the_codes_28_day_modulus(temperature):
    """MC2010 5.1-61: J = 1/E_ci(t0) + phi/E_ci, E_ci = 21500 (fcm/10)^(1/3) MPa (5.1-21)
    whatever the temperature (it enters through the ages only); EN 1992-1-1: phi/E_c,
    E_c = 1.05 E_cm at 28 days. Dividing by the temperature-adjusted modulus at 28 days
    made the creep part 5.7 % larger at 5 C (and 1.2e-4 at 20 C)."""
    spec = dict(C30, temperature=temperature)
    mc = CodeCreep("fib_mc2010", spec)
    t, t0 = np.array([100.0, 18262.5]), 28.0
    e_ci = 1e6 * 21500 * 3.8 ** (1 / 3)
    np.testing.assert_allclose(mc.compliance(t, t0), mc.creep_coefficient(t, t0) / e_ci,
                               rtol=1e-14)
    ec = CodeCreep("eurocode2", dict(C30, temperature=temperature))
    e_c = 1e6 * 1.05 * 22000 * 3.8**0.3
    np.testing.assert_allclose(ec.compliance(t, t0), ec.creep_coefficient(t, t0) / e_c,
                               rtol=1e-14)


@pytest.mark.parametrize("name", ["fib_mc2010", "eurocode2"])
def test_fitted_compliance_within_its_reported_error(name):
    model = CodeCreep(name, C30)
    tau0 = 7.0
    kernel = model.dimensionless_kernel(tau0)
    rng = np.random.default_rng(1)
    tau = np.exp(rng.random(4000) * np.log(kernel.end))
    low, high = np.log(RESOLUTION / tau0), np.log(kernel.end - 1.0)
    t = np.minimum(tau + np.exp(low + rng.random(4000) * (high - low)), kernel.end)
    e0 = model.modulus(tau0)
    exact = e0 * (1 / model.modulus(tau0 * tau) + model.compliance(tau0 * t, tau0 * tau))
    error = np.max(np.abs(kernel.compliance(t, tau) - exact) / exact)
    # the finest fit: measured 2.1e-9 (MC2010) and 2.7e-10 (EC2) against reported 2.6e-9
    # and 3.2e-10 (200,000 random pairs: at most 0.87 of the reported error)
    assert error <= kernel.fit_error
    assert kernel.fit_error < 3e-9  # core.creep.design_codes.FIT_LEVELS
    # the kernel is the exact derivative of the fitted compliance (K = e dJ/dtau)
    s = np.array([1.5, 30.0, 400.0])
    tt = np.array([2.0, 100.0, 2000.0])
    h = 1e-6 * s
    dj = (kernel.compliance(tt, s + h) - kernel.compliance(tt, s - h)) / (2 * h)
    e = model.modulus(tau0 * s) / e0
    # central difference, measured 1e-9 relative
    assert kernel(tt, s) == pytest.approx(e * dj, rel=1e-6)


@pytest.mark.parametrize("name", ["fib_mc2010", "eurocode2"])
def test_the_held_compliance_is_integrated_over_the_whole_age_range(name):
    """``1 - int_1^t K(t, u) du`` by quadrature (:func:`core.creep.integrated_kernel`, what
    the solver refines its grid for and checks a kernel by) against the same held
    compliance written as ``J~(t, 1) + int_1^t e'(u) J~(t, u) du`` (``K = e dJ~/du``,
    integrated by parts: a smooth integrand, by scipy's adaptive quadrature). Graded
    toward ``u = t`` alone, the rule left the early ages to six nodes: it read 26 % (fib
    MC2010) and 24 % (Eurocode 2) low for this concrete loaded at 28 days."""
    from scipy.integrate import quad

    from core.creep import integrated_kernel

    kernel = CodeCreep(name, C30).dimensionless_kernel(28.0)
    assert kernel.modulus is not None  # an aging modulus: e' does not vanish

    def e_slope(u: float) -> float:
        at = np.array([u])
        return float(np.asarray(kernel.log_slope(at))[0] * np.asarray(kernel.modulus(at))[0])

    times = np.array([1.001, 1.5, 5.0, 50.0, 500.0, kernel.end])
    held = 1.0 + integrated_kernel(kernel, times, np.ones_like(times))
    for t, value in zip(times, held, strict=True):
        parts = quad(lambda u, t=t: e_slope(u) * kernel.compliance(np.array([t]),
                                                                   np.array([u]))[0],
                     1.0, t, limit=800, epsabs=1e-14, epsrel=1e-13)[0]
        exact = kernel.compliance(np.array([t]), np.array([1.0]))[0] + parts
        # measured 1.9e-7 (MC2010) and 4.1e-7 (EC2): the grading toward u = t bounds it
        assert value == pytest.approx(exact, rel=1e-6), t


@pytest.mark.parametrize("name", ["fib_mc2010", "eurocode2"])
@pytest.mark.parametrize("spec", [
    {"fcm": 20.0, "cement": "S", "relative_humidity": 40.0, "notional_size": 50.0,
     "temperature": 5.0},
    {"fcm": 98.0, "cement": "R", "relative_humidity": 100.0, "notional_size": 1500.0},
])
@pytest.mark.parametrize("tau0", [1.0, 3650.0])
def test_the_base_creeps_at_the_corners_of_the_ranges(name, spec, tau0):
    spec = dict(spec)
    if name == "eurocode2" and spec.get("temperature") == 5.0:
        spec["temperature"] = -40.0
    kernel = CodeCreep(name, spec).dimensionless_kernel(tau0)
    # K <= 0 everywhere sampled (measured largest K/max|K| -6.7e-11 .. -2.6e-2)
    assert nonpositive_violation(kernel) <= 0.0
    assert kernel.fit_error < 2e-3  # measured at most 1.3e-3 (MC2010, fcm 20, 1 day)


def _scalar_problem(c):
    """``(1 + c/gamma) w - V w = 1``: one mode of a creeping base under constant load."""
    gamma = 0.5
    return ModalProblem(d=lambda t: 1.0 + np.atleast_2d(c(t)) / gamma,
                        r=lambda t: np.ones((1, np.size(t))),
                        u=lambda t: np.zeros((0, np.size(t))), coupling=np.zeros((1, 0)))


def test_fitted_stepping_against_product_quadrature():
    """The general kernel of an aging material, given as a plain callable: the O(1)-per-step
    stepping of its exponential fit against the product trapezoid rule on the kernel
    itself, which converges at order 2 to the same answer (to the fit error)."""
    model = Arutyunyan(3e10, 0.5, 0.03, 0.9e-11, 4.8e-10, 0.03)
    exact = model.dimensionless_kernel(28.0)
    c = model.relative_modulus(28.0)

    def plain(t, tau):
        return exact(t, tau)

    end = 1.0 + 1000.0 / 28.0
    fitted = fit_kernel(plain, end=end)
    problem = _scalar_problem(c)
    times = 1.0 + (end - 1.0) * np.array([0.0, 1 / 32, 1 / 4, 1.0])  # nodes of every grid
    fast = solve_degenerate(fitted, problem, times, tol=1e-11).w[0]
    answers = []
    for n in (32, 64, 128, 256, 512):
        grid = np.linspace(1.0, end, n + 1)
        w, _, _ = _trapezoid_solve(plain, problem, grid, grid)
        answers.append(w[0, np.searchsorted(grid, times)])
    changes = [np.max(np.abs(a - b)) for a, b in zip(answers[:-1], answers[1:], strict=True)]
    ratios = np.array(changes[:-1]) / np.array(changes[1:])
    # measured ratios 3.63, 3.87, 3.96: order 2, reached asymptotically
    assert abs(ratios[-1] - 4.0) < 0.1 and np.all(np.diff(ratios) > 0), ratios
    richardson = (4 * answers[-1] - answers[-2]) / 3
    error = np.max(np.abs(richardson - fast)) / np.max(np.abs(fast))
    # measured 1.4e-6 relative against a fit error of 2.9e-6
    assert error <= fitted.fit_error


def test_thin_base_settlement_follows_the_compliance():
    """Thin base (Winkler limit, lam large): the pressure is uniform and the settlement
    under a constant force is ``m P/2 + P E0 J(t, t0) / (4 lam)``; the creeping part
    relative to its value at loading is ``E0 J(t, t0)`` up to the effect of the edges."""
    model = CodeCreep("fib_mc2010", C30)
    tau0 = 7.0
    kernel = model.dimensionless_kernel(tau0)
    c = model.relative_modulus(tau0)
    times = np.concatenate([[1.0], 1.0 + np.geomspace(1.0, 18262.5, 3) / tau0])
    j_exact = 1.0 + model.modulus(tau0) * model.compliance(tau0 * times, tau0)
    m = 0.01
    deviations = []
    for lam in (25.0, 100.0):
        sol = solve_dimensionless(lam, m, 0.0, times, c=c, kernel=kernel,
                                  force=lambda t: 1.0 / c(t), moment=0.0, tol=1e-4)
        ratio = (sol.settlement - m / 2) / (sol.settlement[0] - m / 2)
        deviations.append(np.max(np.abs(ratio - j_exact) / j_exact))
    # measured 7.3e-4 at lam 25 and 1.3e-4 at lam 100 (1.4e-3, 3.3e-4 at 12.5, 50): the
    # edge layers of width 1/lam shrink and the settlement follows J(t, t0)
    assert deviations[1] < 2e-4
    assert deviations[0] / deviations[1] > 4.0


def test_plain_callable_kernel_is_stepped_through_its_fit():
    model = Arutyunyan(3e10, 0.5, 0.03, 0.9e-11, 4.8e-10, 0.03)
    exact = model.dimensionless_kernel(28.0)
    c = model.relative_modulus(28.0)
    times = np.linspace(1.0, 1.0 + 1000.0 / 28.0, 40)
    args = dict(c=c, force=1.0, moment=0.0, tol=1e-4)
    reference = solve_dimensionless(0.5, 0.05, 0.0, times, kernel=exact, **args)
    sol = solve_dimensionless(0.5, 0.05, 0.0, times, kernel=lambda t, s: exact(t, s), **args)
    assert 0.0 < sol.info["kernel_fit_error"] < 1e-4  # measured 2.9e-6
    assert sol.info["success"]
    error = np.max(np.abs(sol.settlement - reference.settlement)) / np.max(
        np.abs(reference.settlement))
    # measured 2.5e-6 against an estimate of 6e-6
    assert error <= sol.info["error_estimate"]


def test_preset_scene_solves_with_the_fit_error_in_its_estimate():
    data = scene_file("young_concrete_50_years")
    scene = scene_from_dict(data)
    assert scene.times.size == 200 and scene.times[-1] == pytest.approx(50 * 365.25)
    result = solve(scene)
    info = result.info if hasattr(result, "info") else result.solution.info
    assert info["success"]
    assert 0.0 < info["kernel_fit_error"] <= info["error_estimate"]
    settlement = np.asarray(result.settlement)
    # creep keeps growing for decades (measured +15 % from 1 to 10 years, +11 % from 5 to
    # 50 years), where the shipped exponential models level off within months
    i1, i5, i10 = (int(np.searchsorted(scene.times, y * 365.25)) for y in (1, 5, 10))
    assert settlement[i10] > 1.1 * settlement[i1]
    assert settlement[-1] > 1.08 * settlement[i5]


@pytest.mark.parametrize(("change", "field"), [
    ({"relative_humidity": 30.0}, "base.creep.relative_humidity"),
    ({"relative_humidity": float("nan")}, "base.creep.relative_humidity"),
    ({"notional_size": 20.0}, "base.creep.notional_size"),
    ({"strength_class": "C8/10"}, "base.creep.strength_class"),
    ({"strength_class": "strong"}, "base.creep.strength_class"),
    ({"fcm": 40.0}, "base.creep"),  # both fcm and strength_class
    ({"cement": "X"}, "base.creep.cement"),
    ({"temperature": 60.0}, "base.creep.temperature"),
    ({"colour": "grey"}, "base.creep.colour"),
])
def test_bad_inputs_are_named(change, field):
    spec = {"model": "fib_mc2010", **C30, **change}
    with pytest.raises(ValueError) as info:
        creep_model_from_spec(spec, field="base.creep")
    assert str(info.value).startswith(field + ":"), str(info.value)


def test_ages_outside_the_range_are_named():
    data = scene_file("young_concrete_50_years")
    data["base"]["age_at_loading"] = 0.5
    with pytest.raises(ValueError, match=r"^base\.age_at_loading: must be in \[1, 3650\]"):
        scene_from_dict(data)
    data["base"]["age_at_loading"] = 7.0
    data["times"]["end"] = 40000.0  # beyond the 100 years the code kernels are fitted for
    # named as the output time it is, in days (it named base.creep in dimensionless ages)
    with pytest.raises(ValueError, match=r"^times\.end: must be <= 36525 days after loading "
                                         r"\(100 years"):
        scene_from_dict(data)
    model = CodeCreep("eurocode2", C30)
    with pytest.raises(ValueError, match="durations"):
        creep_coefficient_curve({"model": "eurocode2", **C30}, 28.0, [-1.0])
    with pytest.raises(ValueError, match="creep kernel: fitted for dimensionless ages"):
        model.dimensionless_kernel(28.0)(np.array([2e3]), np.array([2e3]))


def test_spec_round_trip_and_plot_curve():
    spec = {"model": "eurocode2", **C30, "temperature": 20.0}
    model = creep_model_from_spec(spec)
    assert model.spec == spec
    assert creep_model_from_spec(model.spec) == model
    d = np.array([0.0, 1.0, 100.0])
    assert np.allclose(creep_coefficient_curve(spec, 28.0, d),
                       [ec2_phi_by_hand(28 + x, 28, 38.0, 60.0, 300.0, 0.0) if x else 0.0
                        for x in d], rtol=1e-13)


@pytest.mark.parametrize("name", ["fib_mc2010", "eurocode2"])
@pytest.mark.parametrize("tol", [1e-6, 1e-8])
def test_a_bare_base_settles_as_the_codes_own_compliance(name, tol):
    """An independent reference: on the bare base (no coating) creep and space commute,
    so under a constant force the settlement is the elastic one at loading times
    ``E(t0) J(t, t0)``, with ``J`` from the code's formulas (not from the fit). Over 50
    years the answer meets tol 1e-6 and 1e-8, within its estimate (measured: MC2010
    5.2e-9 and 9.2e-11, EC2 1.5e-8 and 1.5e-10, against estimates 3.4e-8, 2.7e-9,
    2.6e-8, 3.4e-10; with the fit of the time, 1.6e-5, neither was met)."""
    data = scene_file("young_concrete_50_years")
    data["coating"] = []
    data["base"]["creep"]["model"] = name
    data["times"] = {"end": 18262.5, "count": 12, "spacing": "log"}
    data["solver"] = {"tol": tol}
    result = solve(data)
    assert result.info["success"] and not result.flags, result.info["message"]
    model = CodeCreep(name, {k: v for k, v in data["base"]["creep"].items() if k != "model"})
    tau0 = data["base"]["age_at_loading"]
    exact = model.modulus(tau0) * (1 / model.modulus(tau0)
                                   + model.compliance(tau0 + result.times, tau0))
    error = np.max(np.abs(result.settlement / result.settlement[0] - exact) / exact)
    assert error <= result.info["error_estimate"] <= tol
