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
    ``a_r`` and the decay ``exp(-rate_r (t_n - tau))``) is integrated against it by a
    Gauss rule of ``_GAUSS`` points. The plain trapezoid on ``K q`` read 2e-4 wrong in the
    settlement of the lift-off preset (100 output times, 101 steps): the aging kernel
    varies fast just after loading, and log-spaced outputs make late steps of ~2 against
    a decay time of ~1.2. This rule's error depends only on how q curves in time; it is
    still of order 2 in the step (Richardson applies unchanged).
    """

    _GAUSS = 8

    def __init__(self, kernel: Any, grid: np.ndarray, inner: np.ndarray, n_nodes: int) -> None:
        rates = np.asarray(kernel.rates, dtype=float).ravel()
        xi, omega = np.polynomial.legendre.leggauss(self._GAUSS)
        h = np.diff(grid)  # (S,)
        s = 0.5 * h[:, None] * (1.0 + xi[None, :])  # (S, G) offsets into each step
        tau = grid[:-1, None] + s
        weight = 0.5 * h[:, None] * omega[None, :]
        rising = s / h[:, None]  # the hat function of the step's end; 1 - it of its start
        b = np.asarray(kernel.tau_part(tau), dtype=float).reshape(tau.shape)
        a = np.asarray(kernel.exponential_parts(tau), dtype=float).reshape(
            (rates.size,) + tau.shape) * np.exp(-rates[:, None, None] * (h[:, None] - s))
        if not (np.all(np.isfinite(b)) and np.all(np.isfinite(a))):
            raise ValueError("kernel: K(t, tau) must be finite on the time grid")
        self.b_old = np.sum(weight * b * (1.0 - rising), axis=1)  # (S,)
        self.b_new = np.sum(weight * b * rising, axis=1)
        self.a_old = np.sum(weight * a * (1.0 - rising), axis=2)  # (R, S)
        self.a_new = np.sum(weight * a * rising, axis=2)
        self.decay = np.exp(-rates[:, None] * h[None, :])  # (R, S)
        self.aged = np.zeros(n_nodes)  # int b q up to the last step
        self.modes = np.zeros((rates.size, n_nodes))  # each mode up to the last step
        self._last = np.zeros(n_nodes)

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

