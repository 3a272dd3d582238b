"""The Volterra kernels of the creep models, in the solver's dimensionless time.

:class:`DegenerateKernel` is the aging Prony series of :mod:`core.creep.models` in the form
``K*(t*, tau*) = b(tau*) + sum_r a_r(tau*) exp(-rate_r (t* - tau*))`` that the time
stepping integrates exactly (its derivation is in :mod:`core.creep.models`);
:class:`RelativeModulus` is ``c(t*) = E(tau0 t*) / E(tau0)``; :class:`CausalKernel` wraps a
user's ``K(t, tau)``, zero where ``t < tau``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

ArrayLike = Any


def _set(obj: Any, **values: Any) -> None:
    # frozen dataclasses: store the normalized (validated, float) values once
    for name, value in values.items():
        object.__setattr__(obj, name, value)



# ------------------------------------------------------------------ the degenerate kernel


def separable_kernel_value(kernel: Any, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
    """``K(t, tau) = b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))`` [-], 0 where ``t < tau``.

    For any kernel with ``rates`` (R,), ``tau_part(tau)`` (b) and ``exponential_parts(tau)``
    (a_r, shape (R,) + tau.shape): the aging Prony series below and the fitted kernels of
    :mod:`core.creep.kernel_fit` share this one causal evaluation. ``t`` broadcasts against ``tau``.
    """
    t, tau = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(tau, dtype=float))
    lag = np.maximum(t - tau, 0.0)
    rates = kernel.rates.reshape((-1,) + (1,) * lag.ndim)
    value = kernel.tau_part(tau) + np.sum(
        kernel.exponential_parts(tau) * np.exp(-rates * lag[None]), axis=0)
    return np.where(t >= tau, value, 0.0)


@dataclass(frozen=True)
class DegenerateKernel:
    """``K*(t*, tau*) = b(tau*) + sum_r a_r(tau*) exp(-rate_r (t* - tau*))``, aging Prony series.

    The kernel of ``E(age) = modulus_final (1 - beta exp(-alpha age))`` and
    ``C(t, tau) = sum_r (C_r + A_r/tau)(1 - exp(-gamma_r (t - tau)))`` (``terms`` holds the
    triples ``(C_r [1/Pa], A_r [day/Pa], gamma_r [1/day])``), expressed in the time
    ``t* = age / age_at_loading`` [-]. With ``age_at_loading = 1`` it is the kernel in ages
    [1/day]. Built by the creep models; all methods are vectorized.
    """

    age_at_loading: float
    modulus_final: float
    beta: float
    alpha: float
    terms: tuple[tuple[float, float, float], ...]

    def __post_init__(self) -> None:
        # plain floats and tuples, so that equal kernels compare and hash equal
        _set(self, age_at_loading=float(self.age_at_loading),
             modulus_final=float(self.modulus_final), beta=float(self.beta),
             alpha=float(self.alpha),
             terms=tuple((float(c), float(a), float(g)) for c, a, g in self.terms))

    @property
    def rates(self) -> np.ndarray:
        """Dimensionless decay rates ``gamma_r * age_at_loading``, shape (R,)."""
        return np.array([g for _, _, g in self.terms], dtype=float) * self.age_at_loading

    @property
    def key(self) -> tuple:
        """A tuple of plain numbers that identifies the kernel (for cache keys)."""
        return ("degenerate", self.age_at_loading, self.modulus_final, self.beta, self.alpha,
                tuple(self.terms))

    def _age_modulus(self, age: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``E(age)`` [Pa] and ``-E'(age)/E(age)`` [1/day]."""
        decay = self.beta * np.exp(-self.alpha * age)
        return self.modulus_final * (1.0 - decay), -self.alpha * decay / (1.0 - decay)

    def tau_part(self, tau: ArrayLike) -> np.ndarray:
        """``b(tau*)`` [-], the part of the kernel that does not depend on ``t*``; shape of tau."""
        return self.factors(tau)[0]

    def exponential_parts(self, tau: ArrayLike) -> np.ndarray:
        """``a_r(tau*)`` [-], amplitudes of ``exp(-rate_r (t* - tau*))``; shape (R,) + tau.shape."""
        return self.factors(tau)[1]

    def factors(self, tau: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``b(tau*)`` and ``a_r(tau*)`` [-] together (:meth:`tau_part`,
        :meth:`exponential_parts`), the modulus evaluated once."""
        tau0 = self.age_at_loading
        age = tau0 * np.asarray(tau, dtype=float)
        modulus, log_rate = self._age_modulus(age)
        coef = np.array(self.terms, dtype=float).reshape((len(self.terms), 3)
                                                           + (1,) * age.ndim)
        c, a, g = coef[:, 0], coef[:, 1], coef[:, 2]
        aging = sum(a_r for _, a_r, _ in self.terms)
        return (tau0 * (log_rate - modulus * aging / age**2),
                tau0 * modulus * (a / age**2 - g * (c + a / age)))

    def __call__(self, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
        """``K*(t*, tau*)`` [-], broadcasting ``t`` against ``tau``; 0 where ``t < tau``."""
        return separable_kernel_value(self, t, tau)


@dataclass(frozen=True)
class RelativeModulus:
    """``c(t*) = E(tau0 t*) / E(tau0)`` [-] for ``E(age) = E_inf (1 - beta exp(-alpha age))``."""

    age_at_loading: float
    beta: float
    alpha: float

    def __call__(self, t: ArrayLike) -> np.ndarray:
        """The relative modulus at dimensionless times ``t* = age / age_at_loading``."""
        tau0 = self.age_at_loading
        t = np.asarray(t, dtype=float)
        return ((1.0 - self.beta * np.exp(-self.alpha * tau0 * t))
                / (1.0 - self.beta * np.exp(-self.alpha * tau0)))


@dataclass(frozen=True, eq=False)
class CausalKernel:
    """A user kernel ``K(t, tau)`` (any units) made causal: 0 where ``t < tau``.

    The wrapped function is only ever evaluated at ``t >= tau`` (``t`` is raised to
    ``tau`` elsewhere), so a formula such as ``sqrt(t - tau)`` is safe; a non-finite value
    where the kernel is used is an error.
    """

    function: Callable[[np.ndarray, np.ndarray], Any]
    scale: float = 1.0  # K* = scale * K(scale t, scale tau): the age at loading [day]

    def __call__(self, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
        """``scale * K(scale t, scale tau)``, broadcasting; 0 where ``t < tau``."""
        t, tau = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(tau, dtype=float))
        causal = t >= tau
        with np.errstate(all="ignore"):
            raw = self.function(self.scale * np.maximum(t, tau), self.scale * tau)
        value = np.broadcast_to(np.asarray(raw, dtype=float), t.shape)
        bad = causal & ~np.isfinite(value)
        if np.any(bad):
            i = np.argwhere(bad)[0]
            t_bad, tau_bad = float(t[tuple(i)]), float(tau[tuple(i)])
            raise ValueError(
                f"creep kernel: not finite at t = {self.scale * t_bad:g}, "
                f"tau = {self.scale * tau_bad:g} (ages in days)")
        return self.scale * np.where(causal, value, 0.0)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, CausalKernel) and other.function is self.function
                and other.scale == self.scale)

    def __hash__(self) -> int:
        return hash((id(self.function), self.scale))
