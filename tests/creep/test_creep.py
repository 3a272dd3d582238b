"""Creep models: analytic kernels, the dimensionless degenerate form, oracles, specs, errors."""

from __future__ import annotations

import json
import math

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import quad

from core.creep import Elastic, UserKernel, creep_model_from_spec
from core.creep.kernels import CausalKernel, DegenerateKernel, RelativeModulus
from core.creep.models import KNOWN_MODELS, Arutyunyan, ExponentialCreep, PronySeries
from core.time import ModalProblem, solve_degenerate

# Concrete-like parameters: E ~ 30 GPa, creep coefficient phi = E C of order 1-3, rates of
# a week to a year, aging term A/tau comparable to C_inf at an age of a month.
E_INF, BETA, ALPHA = 35e9, 0.6, 0.05
C_INF, AGING, GAMMA = 4e-11, 1.2e-9, 0.03
PRONY_TERMS = ((1.5e-11, 4e-10, 0.5), (3e-11, 8e-10, 0.05), (2.5e-11, 0.0, 0.004))


def _ref_prony_c(terms):
    def c(t, tau):
        return mp.fsum((cr + ar / tau) * (1 - mp.exp(-g * (t - tau))) for cr, ar, g in terms)
    return c


# (name, model, E(age), C(t, tau)) with the references written from the definitions in mpmath,
# independently of the module.
CASES = [
    ("elastic", Elastic(30e9), lambda tau: mp.mpf(30e9), lambda t, tau: mp.mpf(0)),
    ("exponential", ExponentialCreep(30e9, 6e-11, 0.05), lambda tau: mp.mpf(30e9),
     lambda t, tau: 6e-11 * (1 - mp.exp(-0.05 * (t - tau)))),
    ("arutyunyan", Arutyunyan(E_INF, BETA, ALPHA, C_INF, AGING, GAMMA),
     lambda tau: E_INF * (1 - BETA * mp.exp(-ALPHA * tau)),
     lambda t, tau: (C_INF + AGING / tau) * (1 - mp.exp(-GAMMA * (t - tau)))),
    ("arutyunyan-fast", Arutyunyan(E_INF, 0.9, 0.5, C_INF, 3 * AGING, 2.0),
     lambda tau: E_INF * (1 - 0.9 * mp.exp(-0.5 * tau)),
     lambda t, tau: (C_INF + 3 * AGING / tau) * (1 - mp.exp(-2.0 * (t - tau)))),
    ("prony", PronySeries(32e9, PRONY_TERMS), lambda tau: mp.mpf(32e9),
     _ref_prony_c(PRONY_TERMS)),
]
IDS = [c[0] for c in CASES]
SERIES_CASES = [c for c in CASES if c[0] != "elastic"]
SERIES_IDS = [c[0] for c in SERIES_CASES]

# Ages (days) with t >= tau >= 3: loading as early as 3 days and up to 10 years of creep.
TAUS = np.array([3.0, 7.0, 28.0, 90.0, 365.0])
LAGS = np.array([0.0, 0.01, 0.5, 5.0, 30.0, 400.0, 3650.0])


def _ref_kernel(e_ref, c_ref, t, tau):
    """E(tau) d/dtau [1/E(tau) + C(t, tau)] by mpmath numerical differentiation."""
    with mp.workdps(40):
        t, tau = mp.mpf(t), mp.mpf(tau)
        return e_ref(tau) * mp.diff(lambda s: 1 / e_ref(s) + c_ref(t, s), tau)


def _kernel_scale(model, tau):
    """A size of the kernel at age tau [1/day] against which errors are measured.

    For the elastic model (K = 0) errors are absolute, in 1/day.
    """
    return abs(float(model.kernel(tau, tau))) or 1.0


# ------------------------------------------------------------- E, C and the analytic kernel


@pytest.mark.parametrize(("name", "model", "e_ref", "c_ref"), CASES, ids=IDS)
def test_modulus_and_compliance_match_definitions(name, model, e_ref, c_ref):
    tt = TAUS[:, None] + LAGS[None, :]
    tau = np.broadcast_to(TAUS[:, None], tt.shape)
    got_c = model.compliance(tt, tau)
    got_e = model.modulus(TAUS)
    assert got_c.shape == tt.shape and got_e.shape == TAUS.shape
    for i, j in np.ndindex(tt.shape):
        with mp.workdps(40):
            want = float(c_ref(mp.mpf(tt[i, j]), mp.mpf(tau[i, j])))
        # measured worst 2.9e-16 relative (expm1 keeps short lags accurate)
        assert abs(got_c[i, j] - want) <= 1e-15 * abs(want)
    for k, age in enumerate(TAUS):
        with mp.workdps(40):
            want = float(e_ref(mp.mpf(age)))
        assert abs(got_e[k] - want) <= 4.5e-16 * want  # measured worst 2.2e-16 (1 ulp)
    # C(t, tau) vanishes for t <= tau
    assert np.all(model.compliance(TAUS - 1.0, TAUS) == 0.0)
    assert np.all(model.compliance(TAUS, TAUS) == 0.0)


@pytest.mark.parametrize(("name", "model", "e_ref", "c_ref"), CASES, ids=IDS)
def test_kernel_is_exact_derivative(name, model, e_ref, c_ref):
    """K against mpmath's numerical tau-derivative of E(tau)(1/E(tau) + C(t, tau))."""
    worst = 0.0
    for tau in TAUS:
        scale = _kernel_scale(model, tau)
        for lag in LAGS:
            got = float(model.kernel(tau + lag, tau))
            want = float(_ref_kernel(e_ref, c_ref, tau + lag, tau))
            worst = max(worst, abs(got - want) / scale)
    # measured worst 1.0e-15 relative to |K(tau, tau)| (rounding in the closed form)
    assert worst <= 4e-15


@pytest.mark.parametrize(("name", "model", "e_ref", "c_ref"), CASES, ids=IDS)
def test_kernel_matches_finite_difference_of_own_functions(name, model, e_ref, c_ref):
    """Consistency of kernel() with the module's own modulus() and compliance()."""

    def g(t, s):
        return 1.0 / model.modulus(s) + model.compliance(t, s)

    worst = 0.0
    for tau in TAUS:
        h = 1e-3 * min(tau, 1.0)
        scale = _kernel_scale(model, tau)
        for lag in LAGS[LAGS >= 0.5]:  # the stencil must not cross t = tau
            t = tau + lag
            # fourth-order central difference
            fd = (-g(t, tau + 2 * h) + 8 * g(t, tau + h) - 8 * g(t, tau - h)
                  + g(t, tau - 2 * h)) / (12 * h) * model.modulus(tau)
            worst = max(worst, abs(float(model.kernel(t, tau)) - float(fd)) / scale)
    # measured worst 3.3e-11 (rounding of the difference quotient, ~eps/h, dominates;
    # the h^4 truncation term is below 1e-12 here)
    assert worst <= 3e-10


@pytest.mark.parametrize(("name", "model", "e_ref", "c_ref"), SERIES_CASES, ids=SERIES_IDS)
def test_degenerate_parts_match_hand_split(name, model, e_ref, c_ref):
    """b(tau) is K for t -> infinity and the a_r are the amplitudes of exp(-gamma_r (t - tau)).

    Recovered from the mpmath reference kernel alone: b = K(tau + huge lag, tau), then the
    a_r from R lags by a linear solve at 40 digits.
    """
    tau0 = 28.0
    kern = model.dimensionless_kernel(tau0)
    gammas = kern.rates / tau0
    for tau in (28.0, 60.0, 400.0):
        with mp.workdps(40):
            huge = 3000.0 / min(gammas)  # exp(-3000): far below 40 digits
            b = _ref_kernel(e_ref, c_ref, tau + huge, tau)
            lags = [1.0 / g for g in gammas]  # one lag per time scale keeps the solve well posed
            mat = mp.matrix([[mp.exp(-g * s) for g in gammas] for s in lags])
            rhs = mp.matrix([_ref_kernel(e_ref, c_ref, tau + s, tau) - b for s in lags])
            amps = mp.lu_solve(mat, rhs)
        scale = _kernel_scale(model, tau) * tau0
        # measured worst 2.7e-18 relative to |K*(tau, tau)|
        assert abs(float(kern.tau_part(tau / tau0)) - tau0 * float(b)) <= 1e-15 * scale
        got = kern.exponential_parts(np.array(tau / tau0))
        for r in range(len(gammas)):
            # measured worst 5.3e-16 relative to |K*(tau, tau)|
            assert abs(got[r] - tau0 * float(amps[r])) <= 4e-15 * scale


def test_arutyunyan_parts_closed_form():
    """The formulas of the report, evaluated literally."""
    m = CASES[2][1]
    tau0, tau_star = 28.0, np.array([1.0, 2.5, 13.0])
    tau = tau0 * tau_star
    e = E_INF * (1 - BETA * np.exp(-ALPHA * tau))
    de = E_INF * BETA * ALPHA * np.exp(-ALPHA * tau)
    b = tau0 * (-de / e - e * AGING / tau**2)
    a = tau0 * e * (AGING / tau**2 - GAMMA * (C_INF + AGING / tau))
    k = m.dimensionless_kernel(tau0)
    np.testing.assert_allclose(k.tau_part(tau_star), b, rtol=1e-14, atol=0)  # measured 2e-16
    np.testing.assert_allclose(k.exponential_parts(tau_star)[0], a, rtol=1e-14, atol=0)
    np.testing.assert_allclose(k.rates, [GAMMA * tau0], rtol=1e-15)


# ----------------------------------------------------------------- the dimensionless kernel


@pytest.mark.parametrize(("name", "model", "e_ref", "c_ref"), SERIES_CASES, ids=SERIES_IDS)
@pytest.mark.parametrize("tau0", [3.0, 28.0, 365.0])
def test_dimensionless_kernel_scaling(name, model, e_ref, c_ref, tau0):
    kern = model.dimensionless_kernel(tau0)
    assert isinstance(kern, DegenerateKernel)
    ts = np.array([0.5, 1.0, 1.0 + 1e-6, 1.3, 2.0, 7.0, 40.0])
    taus = np.array([1.0, 1.2, 3.0, 20.0])
    got = kern(ts[:, None], taus[None, :])
    assert got.shape == (len(ts), len(taus))
    want = tau0 * model.kernel(tau0 * ts[:, None], tau0 * taus[None, :])
    # Relative to the kernel's size |K*(tau, tau)|: the two round the lag differently
    # (t* - tau* against tau0 t* - tau0 tau*), an error ~ eps rate t in the exponent;
    # measured worst 3.6e-14 (arutyunyan-fast at tau0 = 365, rate* = 730).
    size = np.abs(kern(taus, taus))[None, :]
    assert np.all(np.abs(got - want) <= 1e-13 * size)
    assert np.all(got[ts[:, None] < taus[None, :]] == 0.0)
    assert np.all(got[ts[:, None] >= taus[None, :]] != 0.0)
    # the README interface: b + sum_r a_r exp(-rate_r (t - tau)) on t >= tau
    t, tau = 5.0, np.array([1.0, 2.0, 5.0])
    explicit = kern.tau_part(tau) + np.sum(
        kern.exponential_parts(tau) * np.exp(-kern.rates[:, None] * (t - tau)), axis=0)
    np.testing.assert_allclose(kern(t, tau), explicit, rtol=1e-15, atol=0)  # measured 0


def test_degenerate_kernel_shapes():
    kern = CASES[4][1].dimensionless_kernel(28.0)
    assert kern.rates.shape == (3,)
    np.testing.assert_array_equal(kern.rates, [0.5 * 28.0, 0.05 * 28.0, 0.004 * 28.0])
    tau = np.linspace(1.0, 3.0, 6).reshape(2, 3)
    assert kern.tau_part(tau).shape == (2, 3)
    assert kern.exponential_parts(tau).shape == (3, 2, 3)
    assert kern.exponential_parts(2.0).shape == (3,)
    assert np.shape(kern(2.0, 1.0)) == ()
    assert kern(np.ones((4, 1, 1)) * 3.0, tau).shape == (4, 2, 3)
    assert kern(1.0, 2.0) == 0.0
    assert kern == CASES[4][1].dimensionless_kernel(28.0)  # comparable, hashable
    assert hash(kern) == hash(CASES[4][1].dimensionless_kernel(28.0))


def test_relative_modulus():
    aging = CASES[2][1]
    c = aging.relative_modulus(28.0)
    assert isinstance(c, RelativeModulus)
    t = np.array([1.0, 1.5, 10.0])
    np.testing.assert_allclose(c(t), aging.modulus(28.0 * t) / aging.modulus(28.0),
                               rtol=1e-15)
    assert c(1.0) == 1.0
    for _, model, _, _ in CASES:
        if not isinstance(model, Arutyunyan):
            assert model.relative_modulus(28.0) == 1.0
            assert isinstance(model.relative_modulus(28.0), float)
    # an Arutyunyan model without aging of the modulus lets the solver skip the work
    assert Arutyunyan(E_INF, 0.0, ALPHA, C_INF, AGING, GAMMA).relative_modulus(7.0) == 1.0
    assert Arutyunyan(E_INF, BETA, 0.0, C_INF, AGING, GAMMA).relative_modulus(7.0) == 1.0


def test_elastic_has_no_operator():
    model = Elastic(30e9)
    assert model.dimensionless_kernel(28.0) is None
    assert model.kernel(np.ones(3), np.ones((2, 1))).shape == (2, 3)
    assert not np.any(model.kernel(np.ones(3), np.ones((2, 1))))


# ------------------------------------------------------------ constant-stress creep oracle
#
# A stress sigma applied at age tau0 and held gives eps(t) = sigma (1/E(tau0) + C(t, tau0)).
# The creep law eps(t) = sigma(t)/E(t) - int sigma(tau) d/dtau[1/E + C] dtau is, with
# s(tau) = sigma(tau)/E(tau) and d/dtau[1/E + C] = K/E, eps = s - int K s dtau = (I - V) s.
# In dimensionless time (s* = sigma/E(tau0 t*) * E0/sigma = 1/c(t*)):
#     1/c(t*) - int_1^t* K*(t*, tau*) / c(tau*) dtau* = 1 + E0 C(tau0 t*, tau0).


def _layer(kern, t, start):
    """Break points for quad: a fast exponential is a boundary layer at tau = t that
    adaptive quadrature can step over unseen (0.45 relative error measured without them)."""
    if kern is None:
        return None
    width = 1.0 / float(np.max(kern.rates))
    pts = [t - k * width for k in (1.0, 5.0, 40.0)]
    return [p for p in pts if start < p < t] or None


def _inverse_c(model, tau0):
    c = model.relative_modulus(tau0)
    if isinstance(c, float):
        return lambda t: 1.0 / c + 0.0 * np.asarray(t, dtype=float)
    return lambda t: 1.0 / c(t)


@pytest.mark.parametrize(("name", "model", "e_ref", "c_ref"), CASES, ids=IDS)
@pytest.mark.parametrize("tau0", [3.0, 28.0, 180.0])
def test_constant_stress_oracle(name, model, e_ref, c_ref, tau0):
    kern = model.dimensionless_kernel(tau0)
    inv_c = _inverse_c(model, tau0)
    e0 = float(model.modulus(tau0))
    worst = 0.0
    for t in (1.0, 1.01, 1.5, 3.0, 20.0, 100.0):
        vs = 0.0
        if kern is not None and t > 1.0:
            vs, _ = quad(lambda tau, t=t: float(kern(t, tau)) * float(inv_c(tau)), 1.0, t,
                         epsabs=0.0, epsrel=1e-13, limit=200, points=_layer(kern, t, 1.0))
        lhs = float(inv_c(t)) - vs
        rhs = 1.0 + e0 * float(model.compliance(tau0 * t, tau0))
        worst = max(worst, abs(lhs - rhs) / rhs)
    # measured worst 2.8e-13 (quad with epsrel=1e-13; 5e-14 or less for the slow models)
    assert worst <= 1e-12


@pytest.mark.parametrize(("name", "model", "e_ref", "c_ref"), CASES, ids=IDS)
def test_constant_stress_oracle_in_ages(name, model, e_ref, c_ref):
    """Same oracle in days and pascals: eps/sigma = 1/E(t) - int K(t,tau)/E(tau) dtau."""
    tau0 = 28.0
    for t in (28.0, 35.0, 400.0, 5000.0):
        integral, _ = quad(lambda s, t=t: float(model.kernel(t, s) / model.modulus(s)), tau0,
                           t, epsabs=0.0, epsrel=1e-13, limit=200,
                           points=_layer(model.dimensionless_kernel(1.0), t, tau0)
                           ) if t > tau0 else (0.0, 0)
        eps = 1.0 / float(model.modulus(t)) - integral
        want = 1.0 / float(model.modulus(tau0)) + float(model.compliance(t, tau0))
        # measured worst 1.7e-14 relative (quad with epsrel=1e-13)
        assert abs(eps - want) <= 1e-13 * want


@pytest.mark.parametrize(("name", "model", "e_ref", "c_ref"), SERIES_CASES, ids=SERIES_IDS)
def test_kernel_drives_the_degenerate_volterra_solver(name, model, e_ref, c_ref):
    """The kernel through core.time.integration: V(1/c) by the ODE states, and the inverse
    problem (creep strain given, constant stress recovered)."""
    tau0 = 28.0
    kern = model.dimensionless_kernel(tau0)
    inv_c = _inverse_c(model, tau0)
    e0 = float(model.modulus(tau0))
    times = np.array([1.0, 1.5, 4.0, 30.0])

    def strain(t):
        return 1.0 + e0 * model.compliance(tau0 * np.asarray(t), tau0)

    def none(t):
        return np.zeros((0, len(t)))

    known_only = ModalProblem(d=none, r=none, u=lambda t: inv_c(t)[None, :],
                              coupling=np.zeros((0, 1)))
    sol = solve_degenerate(kern, known_only, times, tol=1e-10)
    # tol=1e-10 is the solver's own target; measured worst 1.6e-13 relative to the oracle
    # (adaptive Radau IIA); 1.3e-11 (arutyunyan) with the default exponential collocation
    np.testing.assert_allclose(inv_c(times) - sol.vu[0], strain(times), rtol=1e-10, atol=0)

    inverse = ModalProblem(d=lambda t: np.ones((1, len(t))), r=lambda t: strain(t)[None, :],
                           u=none, coupling=np.zeros((1, 0)))
    sol = solve_degenerate(kern, inverse, times, tol=1e-10)
    # measured worst 1.2e-12 relative (arutyunyan-fast, adaptive Radau IIA), within the
    # target tol=1e-10; 8.0e-12 (prony) with the default exponential collocation
    np.testing.assert_allclose(sol.w[0], inv_c(times), rtol=1e-10, atol=0)


# ---------------------------------------------------------------------------- user kernel


def test_user_kernel_equals_the_model_it_copies():
    model = CASES[1][1]
    user = UserKernel(30e9, lambda t, tau: -30e9 * 0.05 * 6e-11 * np.exp(-0.05 * (t - tau)))
    ts, taus = np.array([[1.0], [2.0], [9.0]]), np.array([1.0, 1.5, 3.0])
    kd = model.dimensionless_kernel(28.0)
    ku = user.dimensionless_kernel(28.0)
    assert isinstance(ku, CausalKernel) and not isinstance(ku, DegenerateKernel)
    # The lag is rounded differently (28 t - 28 tau against t - tau), an error ~ eps times
    # the exponent (8.4 here): measured worst 1.8e-15 relative.
    np.testing.assert_allclose(ku(ts, taus), kd(ts, taus), rtol=1e-14, atol=0)
    # same lags in days: measured worst 1.7e-16
    np.testing.assert_allclose(user.kernel(28.0 * ts, 28.0 * taus),
                               model.kernel(28.0 * ts, 28.0 * taus), rtol=1e-15, atol=0)
    assert user.relative_modulus(28.0) == 1.0
    assert float(user.modulus(100.0)) == 30e9


def test_user_kernel_is_causal_and_checked():
    user = UserKernel(30e9, lambda t, tau: -np.sqrt(t - tau) * 1e-3)
    k = user.kernel(np.array([1.0, 2.0, 5.0]), 2.0)
    assert k[0] == 0.0 and k[1] == 0.0 and k[2] < 0
    const = UserKernel(30e9, lambda t, tau: -0.01)  # a scalar result is broadcast
    assert const.dimensionless_kernel(10.0)(np.array([1.0, 2.0]), 1.5).tolist() == [0.0, -0.1]
    bad = UserKernel(30e9, lambda t, tau: -1.0 / (tau - 50.0))
    with pytest.raises(ValueError, match=r"creep kernel: not finite at t = 60, tau = 50"):
        bad.kernel(np.array([60.0]), np.array([50.0]))
    with pytest.raises(ValueError, match="has no JSON form"):
        _ = user.spec
    f = lambda t, tau: 0.0 * t  # noqa: E731
    assert UserKernel(1.0, f) == UserKernel(1.0, f)
    assert UserKernel(1.0, f) != UserKernel(1.0, lambda t, tau: 0.0 * t)


# ------------------------------------------------------------------------------ specs


SPECS = [
    {"model": "elastic", "modulus": 30e9},
    {"model": "exponential", "modulus": 30e9, "compliance": 6e-11, "rate": 0.05},
    {"model": "arutyunyan", "modulus_final": E_INF, "beta": BETA, "alpha": ALPHA,
     "compliance_final": C_INF, "aging": AGING, "rate": GAMMA},
    {"model": "prony", "modulus": 32e9,
     "terms": [{"compliance": c, "aging": a, "rate": g} for c, a, g in PRONY_TERMS]},
]


@pytest.mark.parametrize("spec", SPECS, ids=[s["model"] for s in SPECS])
def test_spec_round_trip(spec):
    model = creep_model_from_spec(spec)
    assert model.spec == spec
    again = creep_model_from_spec(json.loads(json.dumps(model.spec)))
    assert again == model and hash(again) == hash(model)


def test_spec_matches_python_api_and_defaults():
    assert creep_model_from_spec(SPECS[1]) == CASES[1][1]
    assert creep_model_from_spec(SPECS[2]) == CASES[2][1]
    assert creep_model_from_spec(SPECS[3]) == CASES[4][1]
    prony = creep_model_from_spec({"model": "prony", "modulus": 30000000000,
                                   "terms": [{"compliance": 1e-11, "rate": 1}]})
    assert prony.terms == ((1e-11, 0.0, 1.0),)  # aging defaults to 0, ints become floats
    assert isinstance(prony.spec["modulus"], float)


def test_kernel_spec_round_trip():
    spec = {"model": "kernel", "modulus": 30e9, "expr": "-0.003 * exp(-0.05 * (t - tau))"}
    model = creep_model_from_spec(spec)
    assert isinstance(model, UserKernel) and model.spec == spec
    assert creep_model_from_spec(json.loads(json.dumps(model.spec))) == model
    want = -0.003 * math.exp(-0.05 * 10.0)
    assert float(model.kernel(40.0, 30.0)) == pytest.approx(want, rel=1e-15)  # measured 0
    assert float(model.dimensionless_kernel(10.0)(4.0, 3.0)) == pytest.approx(10 * want,
                                                                               rel=1e-15)
    assert float(model.kernel(30.0, 40.0)) == 0.0


@pytest.mark.parametrize("text", ["t +* 2", "x + t", "__import__('os')"])
def test_kernel_formula_errors_name_the_field(text):
    with pytest.raises(ValueError, match=r"^base\.creep\.expr: "):
        creep_model_from_spec({"model": "kernel", "modulus": 1.0, "expr": text})


# ------------------------------------------------------------------------- validation

ARU = SPECS[2]
EXP = SPECS[1]
PRONY = SPECS[3]


def _with(base, **changes):
    spec = dict(base)
    for key, value in changes.items():
        if value is _DROP:
            del spec[key]
        else:
            spec[key] = value
    return spec


def _term(r, **changes):
    spec = json.loads(json.dumps(PRONY))
    for key, value in changes.items():
        if value is _DROP:
            del spec["terms"][r][key]
        else:
            spec["terms"][r][key] = value
    return spec


_DROP = object()
DECREASE = ": a negative value makes the compliance decrease in time, which is not creep"
KNOWN = ("known models: arutyunyan, elastic, eurocode2, exponential, fib_mc2010, kernel, "
         "prony")

BAD_SPECS = [
    (_with(EXP, rate=-1), "base.creep.rate: must be > 0, got -1"),
    (_with(EXP, rate=0.0), "base.creep.rate: must be > 0, got 0.0"),
    (_with(EXP, rate=2e6), "base.creep.rate: must be <= 1e+06 per day, got 2000000.0"),
    (_with(EXP, modulus=0), "base.creep.modulus: must be > 0, got 0"),
    (_with(EXP, modulus=-3e10), "base.creep.modulus: must be > 0, got -30000000000.0"),
    (_with(EXP, modulus="3e10"), "base.creep.modulus: must be a number, got '3e10'"),
    (_with(EXP, modulus=True), "base.creep.modulus: must be a number, got True"),
    (_with(EXP, modulus=None), "base.creep.modulus: must be a number, got None"),
    (_with(EXP, modulus=[1.0]), "base.creep.modulus: must be a number, got [1.0]"),
    (_with(EXP, modulus=math.nan), "base.creep.modulus: must be finite, got nan"),
    (_with(EXP, rate=math.inf), "base.creep.rate: must be finite, got inf"),
    (_with(EXP, compliance=-1e-11), "base.creep.compliance: must be >= 0, got -1e-11" + DECREASE),
    (_with(ARU, beta=1.0), "base.creep.beta: must be >= 0 and < 1 (the modulus at age 0 is "
     "modulus_final (1 - beta)), got 1.0"),
    (_with(ARU, beta=-0.1), "base.creep.beta: must be >= 0 and < 1 (the modulus at age 0 is "
     "modulus_final (1 - beta)), got -0.1"),
    (_with(ARU, alpha=-0.01), "base.creep.alpha: must be >= 0, got -0.01"),
    (_with(ARU, compliance_final=-4e-11),
     "base.creep.compliance_final: must be >= 0, got -4e-11" + DECREASE),
    (_with(ARU, aging=-1e-9), "base.creep.aging: must be >= 0, got -1e-09" + DECREASE),
    (_with(ARU, modulus_final=0.0), "base.creep.modulus_final: must be > 0, got 0.0"),
    (_with(ARU, rate=0), "base.creep.rate: must be > 0, got 0"),
    (_term(1, compliance=-3e-11),
     "base.creep.terms[1].compliance: must be >= 0, got -3e-11" + DECREASE),
    (_term(0, aging=-4e-10), "base.creep.terms[0].aging: must be >= 0, got -4e-10" + DECREASE),
    (_term(2, rate=0), "base.creep.terms[2].rate: must be > 0, got 0"),
    (_term(2, rate=1e7), "base.creep.terms[2].rate: must be <= 1e+06 per day, got 10000000.0"),
    (_term(0, rate="fast"), "base.creep.terms[0].rate: must be a number, got 'fast'"),
    (_term(0, rate=_DROP),
     "base.creep.terms[0].rate: missing (required for a Prony term)"),
    (_term(0, shape=2.0),
     "base.creep.terms[0].shape: unknown field for a Prony term; allowed: aging, compliance, "
     "rate"),
    (_with(PRONY, terms=[]), "base.creep.terms: must hold 1 to 12 terms, got 0"),
    (_with(PRONY, terms=[{"compliance": 1e-11, "rate": 1.0}] * 13),
     "base.creep.terms: must hold 1 to 12 terms, got 13"),
    (_with(PRONY, terms={"compliance": 1e-11, "rate": 1.0}),
     "base.creep.terms: must be a list of terms, got {'compliance': 1e-11, 'rate': 1.0}"),
    (_with(PRONY, terms=[[1e-11, 0.0, 1.0]]),
     "base.creep.terms[0]: must be an object with compliance, aging, rate; "
     "got [1e-11, 0.0, 1.0]"),
    (_with(EXP, shape=1.0),
     "base.creep.shape: unknown field for model 'exponential'; allowed: compliance, "
     "modulus, rate"),
    (_with(EXP, rate=_DROP), "base.creep.rate: missing (required for model 'exponential')"),
    (_with(ARU, alpha=_DROP), "base.creep.alpha: missing (required for model 'arutyunyan')"),
    ({"model": "elastic"}, "base.creep.modulus: missing (required for model 'elastic')"),
    ({"model": "maxwell", "modulus": 1.0}, f"base.creep.model: unknown model 'maxwell'; {KNOWN}"),
    ({"model": 3}, f"base.creep.model: unknown model 3; {KNOWN}"),
    ({"modulus": 1.0}, f"base.creep.model: missing; {KNOWN}"),
    ("elastic", "base.creep: must be an object with a 'model' field, got 'elastic'"),
    ({"model": "kernel", "modulus": 1.0, "expr": 3},
     "base.creep.expr: must be a formula in t and tau, got 3"),
    ({"model": "kernel", "modulus": 1.0, "expr": "  "},
     "base.creep.expr: must be a formula in t and tau, got '  '"),
    ({"model": "kernel", "modulus": 1.0}, "base.creep.expr: missing (required for model "
     "'kernel')"),
    ({"model": "kernel", "modulus": 1.0, "formula": "t"}, "base.creep.formula: unknown field "
     "for model 'kernel'; allowed: expr, modulus"),
    ({"model": "kernel", "modulus": -1.0, "expr": "t"}, "base.creep.modulus: must be > 0, "
     "got -1.0"),
]


@pytest.mark.parametrize(("spec", "message"), BAD_SPECS, ids=[m for _, m in BAD_SPECS])
def test_bad_spec_is_refused(spec, message):
    with pytest.raises(ValueError) as err:
        creep_model_from_spec(spec)
    assert str(err.value) == message


def test_field_prefix_is_the_callers():
    with pytest.raises(ValueError) as err:
        creep_model_from_spec(_with(EXP, rate=-1), field="scene.base.creep")
    assert str(err.value) == "scene.base.creep.rate: must be > 0, got -1"


BAD_CALLS = [
    (lambda: Elastic(-1.0), "Elastic.modulus: must be > 0, got -1.0"),
    (lambda: ExponentialCreep(30e9, -1e-11, 0.1),
     "ExponentialCreep.compliance: must be >= 0, got -1e-11" + DECREASE),
    (lambda: Arutyunyan(E_INF, 1.5, ALPHA, C_INF, AGING, GAMMA),
     "Arutyunyan.beta: must be >= 0 and < 1 (the modulus at age 0 is modulus_final "
     "(1 - beta)), got 1.5"),
    (lambda: Arutyunyan(E_INF, BETA, ALPHA, C_INF, AGING, np.float64(-2.0)),
     "Arutyunyan.rate: must be > 0, got -2.0"),
    (lambda: PronySeries(30e9, ((1e-11, 0.0),)),
     "PronySeries.terms[0]: must be a (compliance, aging, rate) triple, got (1e-11, 0.0)"),
    (lambda: PronySeries(30e9, ((1e-11, 0.0, 1.0),) * 13),
     "PronySeries.terms: must hold 1 to 12 terms, got 13"),
    (lambda: UserKernel(30e9, 3.0), "UserKernel.kernel: must be callable, got 3.0"),
    (lambda: UserKernel(0.0, np.exp), "UserKernel.modulus: must be > 0, got 0.0"),
    (lambda: CASES[2][1].dimensionless_kernel(0.0), "age_at_loading: must be > 0, got 0.0"),
    (lambda: CASES[2][1].relative_modulus(-28), "age_at_loading: must be > 0, got -28"),
    (lambda: CASES[0][1].dimensionless_kernel(math.inf), "age_at_loading: must be finite, "
     "got inf"),
    (lambda: CASES[4][1].dimensionless_kernel(math.nan, field="loading.age"),
     "loading.age: must be finite, got nan"),
    (lambda: UserKernel(1.0, np.maximum).relative_modulus("28"),
     "age_at_loading: must be a number, got '28'"),
]


@pytest.mark.parametrize(("call", "message"), BAD_CALLS, ids=[m for _, m in BAD_CALLS])
def test_bad_python_call_is_refused(call, message):
    with pytest.raises(ValueError) as err:
        call()
    assert str(err.value) == message


def test_known_models_listed():
    assert KNOWN_MODELS == ("arutyunyan", "elastic", "eurocode2", "exponential", "fib_mc2010",
                            "kernel", "prony")
