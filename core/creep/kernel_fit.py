"""Creep kernels fitted by a sum of exponentials, so that time stepping costs O(1) per step.

The time stepping of :mod:`core.time.integration` is fast for a kernel of the form

    K(t, tau) = b(tau) + sum_r a_r(tau) exp(-(t - tau)/theta_r)            (t >= tau)

(every state obeys a linear ODE). A concrete creep function from a design code, or a
kernel given as a plain formula, is not of that form. This module fits one to it.

Method (the continuous retardation spectrum / Dirichlet series of concrete creep):
the compliance, in the solver's dimensionless time and relative to the modulus at loading,

    J(t, tau) = 1/e(tau) + C(t, tau)        (e = E(tau)/E(tau0), C the creep part)

is approximated by

    J~(t, tau) = 1/e(tau) + sum_r A_r(tau) (1 - exp(-(t - tau)/theta_r))

with retardation times ``theta_r`` spaced geometrically (``per_decade`` a decade) from
far below the shortest duration that is claimed (``resolution``) to three times the
longest. At each of ``age_nodes`` Chebyshev nodes in ``ln tau`` the amplitudes
``A_r >= 0`` are a non-negative least-squares fit of ``C`` at geometrically spaced
durations from :data:`FIT_FROM_RESOLUTION` of ``resolution`` on, each row weighted by
``1/J`` (relative error). Between the nodes ``A_r(tau)``
is the Chebyshev interpolant in ``ln tau``: smooth, with an exact derivative. The kernel
``K = e(tau) d/dtau J(t, tau)`` then follows analytically:

    b(tau)   = -e'(tau)/e(tau) + e(tau) sum_r A_r'(tau),
    a_r(tau) = -e(tau) (A_r'(tau) + A_r(tau)/theta_r).

Why the compliance and not the kernel is fitted: integrating the creep operator by parts,
``V f (t) = [D(t, s) f(s)] - int D(t, s) f'(s) ds`` with
``D(t, s) = -int_s^t K(t, u) du = e(s) J(t, s) - 1 + int_s^t e'(u) J(t, u) du``,
so an error ``dJ`` in the compliance changes ``V f`` by at most
``max_u e(u) |dJ(t, u)|`` times the variation of ``f``: the error of the compliance, not
of its derivative, is what reaches the answer.

Error: ``fit_error`` is the largest relative error ``|J~ - J| / J`` on an independent
grid (ages half-way between the nodes and at the ends; durations between the fitted
ones, from ``resolution`` to the end), the number the solver adds to its estimate.
Durations shorter than ``resolution`` are not claimed: a creep law with a power-law cusp
at zero duration (``(t - t0)^0.3`` in both codes) cannot be followed there by a finite
sum, and the effect on an answer is at most that error times the relative change of the
stress within ``resolution`` before the output time.

A general kernel ``K(t, tau)`` (a plain callable) is fitted the same way, with ``e = 1``
and ``J(t, tau) = 1 - int_tau^t K(t, u) du`` computed by Gauss-Legendre quadrature on
panels graded toward ``u = t`` (where a weakly singular kernel lives).
Fits are cached on their inputs. The fitted value, :class:`FittedKernel`, and the
quadrature :func:`integrated_kernel` are in :mod:`core.creep.fitted_kernel`.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Any

import numpy as np
from numpy.polynomial import chebyshev as cheb

from core.cache import StageCache, fingerprint
from core.creep.fitted_kernel import FittedKernel, integrated_kernel

#: Retardation times per decade of duration (a general kernel's fit; a compliance fit is
#: given its own, see :data:`core.creep.design_codes.FIT_LEVELS`).
PER_DECADE = 3
#: Chebyshev nodes in ln(age) for the amplitudes (likewise).
AGE_NODES = 24
#: The shortest duration a compliance is fitted at, as a fraction of ``resolution``. The
#: fit once reached 1e-4 of it, where a power-law cusp (``(t - t0)^0.2`` in the drying
#: creep of both codes) cannot be followed: its residual there (7e-4 of J) held the error
#: at the claimed durations at 1.6e-5 whatever the number of terms; from 1e-2 of
#: ``resolution`` on, 3, 4, 5 retardation times a decade reach 3e-7, 2e-8, 1e-9 at one
#: age of the fib MC2010 compliance (measured).
FIT_FROM_RESOLUTION = 1e-2
#: The reported error of a compliance fit over the largest on its test grid: over
#: 200,000 random pairs of ages and durations the largest error was at most 1.09 times
#: the grid's (fib MC2010 and Eurocode 2, C30/37, 7 days, each fit level).
FIT_ERROR_MARGIN = 1.25
#: The shortest retardation time, as a fraction of ``resolution``.
THETA_BELOW_RESOLUTION = 1e-3
#: Ridge weight of the direct fit of a general kernel, relative to its weighted rows.
RIDGE = 1e-6

_FITS = StageCache("kernel_fit", max_items=64, max_bytes=64 * 2**20)


def _grids(end: float, resolution: float, per_decade: float,
           fit_from: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Retardation times, fitted durations (from ``fit_from``, default a tenth of the
    shortest retardation time) and test durations (dimensionless)."""
    span = end - 1.0
    theta_min = THETA_BELOW_RESOLUTION * resolution
    decades = np.log10(3.0 * span / theta_min)
    thetas = np.geomspace(theta_min, 3.0 * span, int(np.ceil(decades * per_decade)) + 1)
    first = 0.1 * theta_min if fit_from is None else fit_from
    n_fit = int(np.ceil(np.log10(span / first) * 3 * per_decade)) + 1
    durations = np.geomspace(first, span, n_fit)
    n_test = int(np.ceil(np.log10(span / resolution) * 5)) + 2
    test = np.geomspace(resolution, span, n_test)
    # between the fitted durations (except the last, the end itself)
    test[1:-1] *= (durations[1] / durations[0]) ** 0.5
    return thetas, durations, np.minimum(test, span)


def _age_nodes(lo: float, hi: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev nodes x in [-1, 1] and their ages, geometric between ``lo`` and ``hi``."""
    x = np.cos(np.pi * (np.arange(n) + 0.5) / n)
    return x, np.exp(np.log(lo) + 0.5 * (x + 1.0) * np.log(hi / lo))


def _test_points(x_nodes: np.ndarray, parts: int = 2) -> np.ndarray:
    """Both ends and the points dividing each gap of [-1, nodes, 1] into ``parts`` (2: the
    points half-way between neighbours)."""
    xs = np.concatenate([[-1.0], np.sort(x_nodes), [1.0]])
    inner = [xs[:-1] + (xs[1:] - xs[:-1]) * k / parts for k in range(1, parts)]
    return np.concatenate([[-1.0], np.sort(np.concatenate(inner)), [1.0]])


def _fit(creep: Callable, modulus: Callable | None, log_slope: Callable | None, end: float,
         breaks: tuple[float, ...], resolution: float, per_decade: float, age_nodes: int,
         key: tuple) -> FittedKernel:
    from scipy.optimize import nnls  # only a fit needs it (scipy's import is slow)

    thetas, durations, test = _grids(end, resolution, per_decade,
                                     FIT_FROM_RESOLUTION * resolution)
    basis = -np.expm1(-durations[:, None] / thetas[None, :])
    edges = np.array([1.0] + [b for b in sorted(breaks) if 1.0 < b < end] + [end])
    coef = np.zeros((edges.size - 1, age_nodes, thetas.size))
    dcoef = np.zeros_like(coef)
    age_test = []
    for p in range(edges.size - 1):
        x_nodes, ages = _age_nodes(edges[p], edges[p + 1], age_nodes)
        inv_e = (1.0 / np.asarray(modulus(ages), dtype=float) if modulus is not None
                 else np.ones_like(ages))
        creep_values = np.asarray(creep(ages[:, None] + durations[None, :], ages[:, None]),
                                  dtype=float)
        if not np.all(np.isfinite(creep_values)):
            raise ValueError("creep kernel: the compliance is not finite where it is fitted")
        amplitudes = np.zeros((age_nodes, thetas.size))
        for j in range(age_nodes):
            weight = 1.0 / np.maximum(np.abs(inv_e[j] + creep_values[j]), 1e-300)
            amplitudes[j], _ = nnls(basis * weight[:, None], creep_values[j] * weight,
                                    maxiter=50 * thetas.size)
        coef[p] = cheb.chebfit(x_nodes, amplitudes, age_nodes - 1)
        dcoef[p, :-1] = cheb.chebder(coef[p])
        # independent check: ages a quarter, a half and three quarters of the way
        # between the nodes (in x) and at both ends (half-way alone read 0.8 of the
        # largest error of 200,000 random pairs)
        x_test = _test_points(x_nodes, parts=4)
        age_test.append(np.exp(np.log(edges[p]) + 0.5 * (x_test + 1.0)
                               * np.log(edges[p + 1] / edges[p])))
    fitted = FittedKernel(thetas, edges, coef, dcoef, modulus, log_slope, np.inf,
                          float(resolution), key)
    age_test = np.concatenate(age_test)
    # every duration half-way (geometrically) between two fitted ones from the resolution
    # on, and the last one an age reaches (t = end): with 5 retardation times a decade a
    # sparser grid of 5 durations a decade read a tenth of the largest error (measured on
    # 200,000 random pairs of fib MC2010)
    lags = np.concatenate([durations[:-1] * (durations[1:] / durations[:-1]) ** share
                           for share in (0.25, 0.5, 0.75)])
    lags = lags[(lags >= resolution) & (lags <= end - 1.0)]
    tau_test = np.broadcast_to(age_test[:, None], (age_test.size, lags.size + 1))
    # durations past the end are not claimed, and one of at least ``resolution`` ends there
    last = np.maximum(end, age_test + resolution)
    t_test = np.concatenate([age_test[:, None] + lags[None, :], last[:, None]], axis=1)
    keep = t_test <= end * (1.0 + 1e-15)
    # the shared durations on their grid, the last one age by age
    fitted_values = np.concatenate([fitted.compliance_grid(age_test, lags),
                                    fitted.compliance(last, age_test)[:, None]], axis=1)
    inv_e_ages = (1.0 / np.asarray(modulus(age_test), dtype=float) if modulus is not None
                  else np.ones_like(age_test))
    exact = (np.broadcast_to(inv_e_ages[:, None], keep.shape)[keep]
             + np.asarray(creep(t_test[keep], tau_test[keep]), dtype=float))
    error = FIT_ERROR_MARGIN * float(np.max(np.abs(fitted_values[keep] - exact)
                                            / np.abs(exact)))
    if not np.isfinite(error):
        error = np.inf
    return FittedKernel(thetas, edges, coef, dcoef, modulus, log_slope, error,
                        float(resolution), key)


def fit_compliance(creep: Callable[[np.ndarray, np.ndarray], np.ndarray], *, end: float,
                   resolution: float, key: Hashable,
                   modulus: Callable[[np.ndarray], np.ndarray] | None = None,
                   log_slope: Callable[[np.ndarray], np.ndarray] | None = None,
                   breaks: tuple[float, ...] = (), per_decade: float = PER_DECADE,
                   age_nodes: int = AGE_NODES) -> FittedKernel:
    """Fit the kernel of the compliance ``J(t, tau) = 1/e(tau) + creep(t, tau)`` (cached).

    All in the solver's dimensionless time (ages over the age at loading): ``creep`` the
    creep part of the compliance relative to ``1/E(tau0)``, vectorized over ``t >= tau``;
    ``modulus`` ``e(tau) = E(tau)/E(tau0)`` and ``log_slope`` ``e'(tau)/e(tau)`` (None: a
    constant modulus); ``end`` > 1 the last age the kernel is needed at; ``resolution``
    the shortest duration the error claim covers; ``breaks`` ages where ``J`` is not
    smooth in ``tau`` (the amplitudes are fitted piecewise between them). ``key`` must
    identify the functions (it keys the cache with the other arguments).
    """
    breaks = tuple(float(b) for b in breaks)
    full_key = ("compliance", key, float(end), breaks, float(resolution), float(per_decade),
                int(age_nodes))
    fitted, _ = _FITS.get_or_compute(full_key, lambda: _fit(
        creep, modulus, log_slope, float(end), breaks, float(resolution), per_decade,
        age_nodes, full_key))
    return fitted


def _fit_direct(kernel: Callable, end: float, resolution: float, per_decade: float,
                age_nodes: int, key: tuple) -> FittedKernel:
    """Least-squares fit of ``K(tau + d, tau)`` over durations d at Chebyshev ages."""
    thetas, durations, test = _grids(end, resolution, per_decade)
    # rows weighted by the duration they stand for (the integral of K is what counts);
    # no row at zero duration, where a weakly singular kernel is infinite
    weight = durations
    columns = np.hstack([np.ones((durations.size, 1)),
                         np.exp(-durations[:, None] / thetas[None, :])])
    x_nodes, ages = _age_nodes(1.0, end, age_nodes)
    # every age sees the same durations (up to the whole span, past the end for late
    # ages), so the fit is one linear map of smooth data and smooth in the age
    shape = (ages.size, durations.size)
    values = np.broadcast_to(np.asarray(kernel(ages[:, None] + durations[None, :],
                                               np.broadcast_to(ages[:, None], shape)),
                                        dtype=float), shape)
    if not np.all(np.isfinite(values)):
        raise ValueError("creep kernel: not finite where it is fitted")
    rows = columns * weight[:, None]
    lhs = np.vstack([rows, RIDGE * float(np.linalg.norm(rows)) * np.eye(thetas.size + 1)])
    rhs = np.vstack([(values * weight[None, :]).T, np.zeros((thetas.size + 1, age_nodes))])
    parts = np.linalg.lstsq(lhs, rhs, rcond=None)[0].T
    coef = cheb.chebfit(x_nodes, parts, age_nodes - 1)[None]
    fitted = FittedKernel(thetas, np.array([1.0, end]), coef, np.zeros_like(coef), None,
                          None, np.inf, float(resolution), key, direct=True)
    x_test = _test_points(x_nodes)
    age_test = np.exp(0.5 * (x_test + 1.0) * np.log(end))
    t_test = np.minimum(age_test[:, None] + test[None, :], end)
    tau_test = np.broadcast_to(age_test[:, None], t_test.shape)
    exact = 1.0 + integrated_kernel(kernel, t_test, tau_test)
    error = float(np.max(np.abs(fitted.compliance(t_test, tau_test) - exact) / np.abs(exact)))
    return FittedKernel(thetas, np.array([1.0, end]), coef, np.zeros_like(coef), None, None,
                        error if np.isfinite(error) else np.inf, float(resolution), key,
                        direct=True)


def fit_kernel(kernel: Callable[[np.ndarray, np.ndarray], np.ndarray], *, end: float,
               resolution: float | None = None, key: Hashable | None = None,
               per_decade: float = PER_DECADE, age_nodes: int = AGE_NODES) -> FittedKernel:
    """Fit a general dimensionless kernel ``K(t, tau)`` on ``1 <= tau <= t <= end`` (cached).

    The kernel itself is fitted (``b(tau)`` and ``a_r(tau)`` by least squares in the
    duration at Chebyshev nodes in ``ln tau``, interpolated between them): its compliance
    ``J = 1 - int K`` need not grow monotonically (an aging modulus inside ``K`` bends it
    back), so the non-negative spectrum of :func:`fit_compliance` does not apply, and an
    unconstrained fit of ``J`` has rough amplitudes whose age slopes would spoil ``K``.
    ``fit_error`` is the relative error of ``J`` on the independent grid, both ``J`` by
    graded quadrature. ``resolution`` defaults to ``1e-6 (end - 1)``; ``key`` identifies
    the kernel (default: a fingerprint of its values on 529 fixed pairs).
    """
    span = float(end) - 1.0
    if not span > 0:
        raise ValueError(f"end: must be > 1, got {end!r}")
    res = 1e-6 * span if resolution is None else float(resolution)
    if key is None:
        # identified by its values on a fixed set of pairs (a plain callable has no
        # content to hash, and its id may be reused once it is gone)
        u = np.linspace(0.0, 1.0, 23)
        tau_probe = 1.0 + span * u[:, None] ** 2
        t_probe = tau_probe + (end - tau_probe) * u[None, :] ** 3
        key = fingerprint(np.asarray(kernel(t_probe, np.broadcast_to(tau_probe, t_probe.shape)),
                                     dtype=float))
    full_key = ("kernel", key, float(end), res, float(per_decade), int(age_nodes))
    fitted, _ = _FITS.get_or_compute(full_key, lambda: _fit_direct(
        kernel, float(end), res, per_decade, age_nodes, full_key))
    return fitted


def nonpositive_violation(fitted: FittedKernel, samples: int = 41) -> float:
    """Largest ``K(t, tau) / max|K|`` over a grid of ``1 <= tau <= t <= end`` (<= 0: creeps).

    The ages are geometric in ``tau`` and the lags geometric from the resolution to the
    end, so both the fast and the slow terms are seen.
    """
    if fitted.key is None:
        return _nonpositive_violation(fitted, samples)
    # a scene's kernel is checked at every solve (a load slider): once per fit
    return _VIOLATIONS.get_or_compute((fitted.key, samples),
                                      lambda: _nonpositive_violation(fitted, samples))[0]


#: :func:`nonpositive_violation` of the fits met so far, by their keys.
_VIOLATIONS = StageCache("kernel_sign", max_items=64, max_bytes=2**16, sizeof=lambda _: 8)


def _nonpositive_violation(fitted: FittedKernel, samples: int) -> float:
    _, ages = _age_nodes(1.0, fitted.end, samples)
    ages = np.unique(np.concatenate([ages, fitted.edges]))
    lags = np.concatenate([[0.0], np.geomspace(fitted.resolution, fitted.end - 1.0, samples)])
    t = ages[:, None] + lags[None, :]
    tau = np.broadcast_to(ages[:, None], t.shape)
    keep = t <= fitted.end
    k = fitted(t[keep], tau[keep])
    scale = float(np.max(np.abs(k))) or 1.0
    return float(np.max(k)) / scale


def stepping_kernel(kernel: Any, t_end: float, budget: float) -> tuple[Any, float]:
    """The kernel to step a solve with, and the relative error of its fit (0 if exact).

    A kernel with ``rates`` is stepped as it is (a fitted one brings its ``fit_error``).
    A plain callable ``K(t, tau)`` is replaced by its sum-of-exponentials fit (cached) when
    the fit error is within ``budget``, so the stepping costs O(1) per step; otherwise, or
    if it cannot be fitted, it keeps the product-quadrature path, which is exact in the
    limit of refinement. ``t_end`` is the last dimensionless time of the solve.
    """
    if kernel is None:
        return None, 0.0
    if hasattr(kernel, "rates") and hasattr(kernel, "exponential_parts"):
        return kernel, float(getattr(kernel, "fit_error", 0.0))
    if t_end <= 1.0:
        return kernel, 0.0
    try:
        with np.errstate(all="ignore"):
            fitted = fit_kernel(kernel, end=t_end)
    except (ValueError, FloatingPointError, ZeroDivisionError):
        return kernel, 0.0
    if not fitted.fit_error <= budget:
        return kernel, 0.0
    return fitted, float(fitted.fit_error)
