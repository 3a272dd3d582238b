"""The memory of past pressures in the creep steps of unilateral contact.

At step ``n`` the memory ``V q(t_n) = int_1^t_n K(t_n, tau) q(tau) dtau`` is split into the
part of the past pressures ``q_0 .. q_{n-1}`` (a density on the nodes, dimensionless) and
the weight of the current one, taken implicitly by the step (:mod:`core.contact.march`).
Degenerate kernels (those of the shipped creep models) carry it by recursion with
exponential product integration; any other kernel by the trapezoid on ``K q``. Both are of
order 2 in the step.
"""


from __future__ import annotations

from typing import Any

import numpy as np

from core.time import exponential_moments


def pressure_memory(kernel: Any, grid: np.ndarray, inner: np.ndarray, n_nodes: int
                    ) -> _HistoryMemory | _SeparableMemory:
    """The memory of past pressures on ``grid`` (dimensionless times; ``inner`` the
    trapezoid weights of its points) for ``n_nodes`` nodes: the recursion for a
    degenerate ``kernel``, the trapezoid sum otherwise."""
    if _separable(kernel):
        return _SeparableMemory(kernel, grid, inner, n_nodes)
    return _HistoryMemory(kernel, grid, inner, n_nodes)


def _separable(kernel: Any) -> bool:
    return all(hasattr(kernel, name) for name in ("rates", "tau_part", "exponential_parts"))


class _HistoryMemory:
    """The trapezoid memory ``sum_{j<n} w_j K(t_n, t_j) q_j`` of any kernel: O(n N) per step."""

    def __init__(self, kernel: Any, grid: np.ndarray, inner: np.ndarray, n_nodes: int) -> None:
        self.kernel, self.grid, self.inner = kernel, grid, inner
        self.history = np.zeros((n_nodes, grid.size))

    def at(self, n: int) -> tuple[np.ndarray, float]:
        """(memory density at step n without its q_n part, weight of q_n); trapezoid."""
        grid = self.grid
        kv = np.asarray(self.kernel(np.full(n + 1, grid[n]), grid[: n + 1]), dtype=float)
        if not np.all(np.isfinite(kv)):
            raise ValueError(f"kernel: K(t, tau) must be finite; it is not at t = {grid[n]:g}")
        weight = 0.5 * (grid[n] - grid[n - 1]) * float(kv[n])
        return self.history[:, :n] @ (self.inner[:n] * kv[:n]), weight

    def record(self, n: int, q: np.ndarray) -> None:
        self.history[:, n] = q


class _SeparableMemory:
    """The memory for ``K = b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))`` by recursion,
    O(R N) per step instead of re-summing the whole past.

    Product integration: on each step q is taken linear and everything else (``b``,
    ``a_r`` and the decay ``exp(-rate_r (t_n - tau))``) is integrated against it: ``b``
    by a Gauss rule of ``_GAUSS`` points; each ``a_r`` by its polynomial through
    ``_AMPLITUDE_POINTS`` points of the step, times the hat function, against the decay
    exactly (:func:`core.time.exponential_moments`). The plain trapezoid on ``K q`` read
    2e-4 wrong in the settlement of the lift-off preset (100 output times, 101 steps):
    the aging kernel varies fast just after loading, and log-spaced outputs make late
    steps of ~2 against a decay time of ~1.2. A Gauss rule on the decay too did not
    converge for the fitted design-code laws, whose fastest rates times a step reach
    1e4-1e6: the decay lives in the last 1e-4 of the step, between the Gauss points (the
    50-year fib MC2010 preset, marched in full contact, stayed 1.5e-3 from the modal
    answer on every grid from 124 to 496 steps). This rule's error depends only on how q
    and ``a_r`` curve in time; it is of order 2 in the step (Richardson applies
    unchanged).
    """

    _GAUSS = 8
    #: Points of a step where each ``a_r`` is read (Chebyshev-Lobatto in the step): its
    #: polynomial of degree 4 is exact to ~h^5 a_r^(5), far below the order-2 error in q.
    _AMPLITUDE_POINTS = 5

    def __init__(self, kernel: Any, grid: np.ndarray, inner: np.ndarray, n_nodes: int) -> None:
        rates = np.asarray(kernel.rates, dtype=float).ravel()
        xi, omega = np.polynomial.legendre.leggauss(self._GAUSS)
        h = np.diff(grid)  # (S,)
        s = 0.5 * h[:, None] * (1.0 + xi[None, :])  # (S, G) offsets into each step
        tau = grid[:-1, None] + s
        weight = 0.5 * h[:, None] * omega[None, :]
        rising = s / h[:, None]  # the hat function of the step's end; 1 - it of its start
        b = np.asarray(kernel.tau_part(tau), dtype=float).reshape(tau.shape)
        self.a_old, self.a_new = self._decay_weights(kernel, rates, grid, h)  # (R, S)
        if not (np.all(np.isfinite(b)) and np.all(np.isfinite(self.a_old))
                and np.all(np.isfinite(self.a_new))):
            raise ValueError("kernel: K(t, tau) must be finite on the time grid")
        self.b_old = np.sum(weight * b * (1.0 - rising), axis=1)  # (S,)
        self.b_new = np.sum(weight * b * rising, axis=1)
        self.decay = np.exp(-rates[:, None] * h[None, :])  # (R, S)
        self.aged = np.zeros(n_nodes)  # int b q up to the last step
        self.modes = np.zeros((rates.size, n_nodes))  # each mode up to the last step
        self._last = np.zeros(n_nodes)

    @classmethod
    def _decay_weights(cls, kernel: Any, rates: np.ndarray, grid: np.ndarray,
                       h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``int_step a_r(tau) exp(-rate_r (t_n - tau)) hat(tau) dtau`` for the hat of the
        step's start and of its end, each (R, S): ``a_r`` by its polynomial in ``u = (tau
        - t_{n-1}) / h`` through the step's Chebyshev-Lobatto points, the decay exactly
        (``int_0^1 exp(-x (1 - u)) u^k du``, ``x = rate h``)."""
        p = cls._AMPLITUDE_POINTS
        u = 0.5 * (1.0 - np.cos(np.pi * np.arange(p) / (p - 1)))   # (P,) on [0, 1]
        to_powers = np.linalg.inv(np.vander(u, p, increasing=True))  # values -> c_k
        tau = grid[:-1, None] + h[:, None] * u[None, :]                # (S, P)
        a = np.asarray(kernel.exponential_parts(tau), dtype=float).reshape(
            (rates.size,) + tau.shape)                                 # (R, S, P)
        c = a @ to_powers.T                                            # (R, S, P): u^k
        mu = exponential_moments(rates[:, None] * h[None, :], p + 1)   # (R, S, P + 1)
        rising = np.sum(c * mu[..., 1:], axis=-1)                       # int c(u) u
        whole = np.sum(c * mu[..., :-1], axis=-1)                       # int c(u)
        return h * (whole - rising), h * rising

    def at(self, n: int) -> tuple[np.ndarray, float]:
        """(memory density at step n without its q_n part, weight of q_n); in step order."""
        j = n - 1
        self.modes = self.decay[:, j, None] * self.modes + self.a_old[:, j, None] * \
            self._last[None, :]
        self.aged = self.aged + self.b_old[j] * self._last
        return self.aged + self.modes.sum(axis=0), float(self.b_new[j] + self.a_new[:, j].sum())

    def record(self, n: int, q: np.ndarray) -> None:
        if n > 0:
            j = n - 1
            self.modes = self.modes + self.a_new[:, j, None] * q[None, :]
            self.aged = self.aged + self.b_new[j] * q
        self._last = q

