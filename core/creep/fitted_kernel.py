"""The fitted kernel: a sum of exponentials with amplitudes smooth in the age.

:class:`FittedKernel` evaluates ``K(t, tau) = b(tau) + sum_r a_r(tau) exp(-rate_r (t -
tau))`` and the compliance it stands for from Chebyshev coefficients of the amplitudes in
``ln tau``; :func:`integrated_kernel` is the graded quadrature of ``-int_tau^t K(t, u)
du`` (the creep part of the compliance of a general kernel). How the coefficients are
fitted, and their error, is in :mod:`core.creep.kernel_fit`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.polynomial import chebyshev as cheb

from core.creep.kernels import separable_kernel_value

ArrayLike = Any

#: Relative allowance of the age range (the solver's stage times may round past the end).
_AGE_SLACK = 1e-9


@dataclass(frozen=True, eq=False)
class FittedKernel:
    """``K(t, tau) = b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))``, fitted (dimensionless).

    Valid for ``1 <= tau <= t <= end``. ``fit_error`` is the relative error of the
    compliance it stands for (module docstring); ``resolution`` the shortest duration
    that error covers. ``key`` identifies the fit for caches. All methods are vectorized.
    """

    thetas: np.ndarray                 # (R,) retardation times
    edges: np.ndarray                  # (S + 1,) ages where the pieces of A_r(tau) meet
    coef: np.ndarray                   # (S, n, R) Chebyshev coefficients of A_r in x
    dcoef: np.ndarray                  # (S, n, R) those of dA_r/dx
    modulus: Callable[[np.ndarray], np.ndarray] | None      # e(tau); None: 1
    log_slope: Callable[[np.ndarray], np.ndarray] | None    # e'/e; None: 0
    fit_error: float
    resolution: float
    key: tuple
    direct: bool = False               # coef holds b (column 0) and a_r, not A_r

    @property
    def rates(self) -> np.ndarray:
        """Dimensionless decay rates ``1/theta_r``, shape (R,)."""
        return 1.0 / self.thetas

    @property
    def end(self) -> float:
        """The last age the kernel is fitted for (dimensionless)."""
        return float(self.edges[-1])

    def amplitudes(self, tau: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``A_r(tau)`` and ``dA_r/dtau``, each of shape (R,) + tau.shape (for a direct
        fit: ``b`` and the ``a_r`` stacked, and zeros)."""
        tau = np.asarray(tau, dtype=float)
        # the time stepping asks for b and a_r at the same stage times, one after the other
        memo = self.__dict__.get("_last")
        token = (tau.shape, tau.tobytes())
        if memo is not None and memo[0] == token:
            return memo[1]
        result = self._amplitudes(tau)
        for part in result:  # handed to every caller asking at the same tau: never written
            part.setflags(write=False)
        object.__setattr__(self, "_last", (token, result))
        return result

    def _amplitudes(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        flat = tau.ravel()
        lo, hi = 1.0 - _AGE_SLACK, self.end * (1.0 + _AGE_SLACK)
        bad = ~((flat >= lo) & (flat <= hi))
        if bad.any():
            raise ValueError(f"creep kernel: fitted for dimensionless ages 1 to {self.end:.6g} "
                             f"(age over the age at loading), asked at {flat[bad][0]:.6g}: "
                             "the times reach beyond the range it was fitted for")
        n_pieces = self.coef.shape[0]
        piece = np.clip(np.searchsorted(self.edges, flat, side="right") - 1, 0, n_pieces - 1)
        amp = np.empty((flat.size, self.coef.shape[2]))
        slope = np.empty_like(amp)
        for p in range(n_pieces):
            sel = piece == p if n_pieces > 1 else slice(None)
            a, b = np.log(self.edges[p]), np.log(self.edges[p + 1])
            x = np.clip(2.0 * (np.log(np.clip(flat[sel], self.edges[p], self.edges[p + 1]))
                               - a) / (b - a) - 1.0, -1.0, 1.0)
            if x.size <= 64:
                # T_k(x) = cos(k arccos x): one call where chebvander's loop would dominate
                vander = np.cos(np.arccos(x)[:, None] * np.arange(self.coef.shape[1])[None, :])
            else:
                vander = cheb.chebvander(x, self.coef.shape[1] - 1)
            amp[sel] = vander @ self.coef[p]
            if self.direct:  # a direct fit reads no slope (its dcoef is zero)
                slope[sel] = 0.0
                continue
            slope[sel] = (vander @ self.dcoef[p]) * (2.0 / (b - a) / np.maximum(
                flat[sel], 1.0))[:, None]
        shape = (self.coef.shape[2],) + tau.shape
        return amp.T.reshape(shape), slope.T.reshape(shape)

    def _modulus(self, tau: np.ndarray) -> tuple[np.ndarray | float, np.ndarray | float]:
        if self.modulus is None:
            return 1.0, 0.0
        return np.asarray(self.modulus(tau), dtype=float), np.asarray(self.log_slope(tau),
                                                                        dtype=float)

    def tau_part(self, tau: ArrayLike) -> np.ndarray:
        """``b(tau)`` [-], the part of the kernel that does not depend on ``t``."""
        tau = np.asarray(tau, dtype=float)
        if self.direct:
            return self.amplitudes(tau)[0][0]
        _, slope = self.amplitudes(tau)
        e, log_slope = self._modulus(tau)
        return -log_slope + e * slope.sum(axis=0)

    def factors(self, tau: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``b(tau)`` and ``a_r(tau)`` [-] together (:meth:`tau_part`,
        :meth:`exponential_parts`), the amplitudes and the modulus evaluated once."""
        tau = np.asarray(tau, dtype=float)
        amp, slope = self.amplitudes(tau)
        if self.direct:
            return amp[0], amp[1:]
        e, log_slope = self._modulus(tau)
        theta = self.thetas.reshape((-1,) + (1,) * tau.ndim)
        return -log_slope + e * slope.sum(axis=0), -e * (slope + amp / theta)

    def exponential_parts(self, tau: ArrayLike) -> np.ndarray:
        """``a_r(tau)`` [-], amplitudes of ``exp(-rate_r (t - tau))``; shape (R,) + tau.shape."""
        tau = np.asarray(tau, dtype=float)
        amp, slope = self.amplitudes(tau)
        if self.direct:
            return amp[1:]
        e, _ = self._modulus(tau)
        theta = self.thetas.reshape((-1,) + (1,) * tau.ndim)
        return -e * (slope + amp / theta)

    def __call__(self, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
        """``K(t, tau)`` [-], broadcasting ``t`` against ``tau``; 0 where ``t < tau``."""
        return separable_kernel_value(self, t, tau)

    def compliance(self, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
        """The fitted ``J~(t, tau) = 1/e(tau) + sum_r A_r(tau)(1 - exp(-(t - tau)/theta_r))``
        (for a direct fit ``1 - int_tau^t K~(t, u) du`` by quadrature)."""
        t, tau = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(tau, dtype=float))
        if self.direct:
            return 1.0 + integrated_kernel(self, t, tau)
        lag = np.maximum(t - tau, 0.0)
        amp, _ = self.amplitudes(tau)
        e, _ = self._modulus(tau)
        theta = self.thetas.reshape((-1,) + (1,) * lag.ndim)
        return 1.0 / e - np.sum(amp * np.expm1(-lag[None] / theta), axis=0)

    def compliance_grid(self, ages: ArrayLike, lags: ArrayLike) -> np.ndarray:
        """:meth:`compliance` at every age of ``ages`` (A,) after every duration of
        ``lags`` (L,), shape (A, L): the amplitudes once per age, the exponentials once
        per duration, one product (a fit's own check asks ~150 ages x ~100 durations;
        point by point it was ~30 ms of a 40 ms fit of fib MC2010). Not for a direct fit."""
        ages = np.asarray(ages, dtype=float)
        amp, _ = self.amplitudes(ages)                                   # (R, A)
        e, _ = self._modulus(ages)
        decay = -np.expm1(-np.asarray(lags, dtype=float)[None, :] / self.thetas[:, None])
        return (1.0 / np.broadcast_to(e, ages.shape))[:, None] + amp.T @ decay


# 6-point Gauss-Legendre on [0, 1]
_GL_X, _GL_W = np.polynomial.legendre.leggauss(6)
_GL_X, _GL_W = 0.5 * (_GL_X + 1.0), 0.5 * _GL_W
#: Panels of the later half of the lag (``u`` from the middle to ``t``), graded by 1/4
#: toward the singular end ``u = t``: down to 5e-13 of the lag.
_GRADING, _PANELS = 0.25, 20
#: Panels of the earlier half (``u`` from ``tau`` to the middle), equal in ``ln u``: the
#: amplitudes and an aging modulus vary on the scale of the age itself. Graded toward
#: ``u = t`` alone, the rule left ``u`` from ``tau`` to ``t - lag / 4`` to six nodes: the
#: held compliance of the ``young_concrete_50_years`` preset (fib MC2010, loaded at 28
#: days) was 38 % low at 50 years (1.4 % at 3.8 years). With these, 1.6e-7 off (the later
#: half's grading then bounds it; against ``J~(t, 1) + int e'(u) J~(t, u) du`` by an
#: independent adaptive quadrature: tests/creep/test_code_creep.py).
_AGE_PANELS = 8


def _rule_on(edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the 6-point Gauss-Legendre rule on each panel between
    ``edges``."""
    width = np.diff(edges)
    nodes = (edges[:-1, None] + width[:, None] * _GL_X[None, :]).ravel()
    weights = (width[:, None] * _GL_W[None, :]).ravel()
    return nodes, weights


#: lag fractions ``s = (t - u) / (t - tau)`` of the later half, and ``y`` of the earlier
#: one (``u = tau (mid / tau)^y``)
_LAG_NODES, _LAG_WEIGHTS = _rule_on(np.concatenate(
    [[0.0], 0.5 * _GRADING ** np.arange(_PANELS, -1, -1)]))
_AGE_NODES, _AGE_WEIGHTS = _rule_on(np.linspace(0.0, 1.0, _AGE_PANELS + 1))


def integrated_kernel(kernel: Callable, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
    """``-int_tau^t K(t, u) du`` by Gauss-Legendre quadrature (creep part of J): the later
    half of the lag on panels graded toward ``u = t`` (a weakly singular kernel, the
    short decay times), the earlier half on panels equal in ``ln u`` (equal in ``u`` where
    an age is not above zero); 2e-7 to 4e-7 relative on the design codes' fitted kernels
    over 50 years."""
    t, tau = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(tau, dtype=float))
    lag = np.maximum(t - tau, 0.0)
    mid = tau + 0.5 * lag
    u_late = t[..., None] - lag[..., None] * _LAG_NODES
    positive = tau > 0.0
    ratio = np.log(np.where(positive, mid, 1.0) / np.where(positive, tau, 1.0))
    u_early = np.where(positive[..., None],
                       np.where(positive, tau, 1.0)[..., None]
                       * np.exp(ratio[..., None] * _AGE_NODES),
                       tau[..., None] + (0.5 * lag)[..., None] * _AGE_NODES)
    # du = u ln(mid / tau) dy on the log map, (mid - tau) dy on the linear one
    early_weight = np.where(positive[..., None], u_early * ratio[..., None],
                            (0.5 * lag)[..., None]) * _AGE_WEIGHTS
    u = np.concatenate([u_late, u_early], axis=-1)
    values = np.broadcast_to(np.asarray(kernel(np.broadcast_to(t[..., None], u.shape), u),
                                        dtype=float), u.shape)
    late, early = values[..., :_LAG_NODES.size], values[..., _LAG_NODES.size:]
    # nodes closer to t than rounding can tell apart see t - u = 0 (where a weakly singular
    # kernel is infinite): they are left out, a part of the integral of the order of
    # K times 1e-15 t
    resolved = lag[..., None] * _LAG_NODES > 8.0 * np.finfo(float).eps * np.maximum(
        np.abs(t[..., None]), 1.0)
    return -(lag * (np.where(resolved, late, 0.0) @ _LAG_WEIGHTS)
             + np.sum(early * early_weight, axis=-1))
