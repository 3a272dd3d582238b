"""Time stepping of the collocation cross-check (:mod:`core.engines.collocation.solve`).

One scene on one panel rule (:class:`CollocationSystem`) is marched through a time grid
by the trapezoid rule, one bordered linear system per step (LU factorizations while the
step matrices are few, then one Schur form and O(N^2) per step) on the grids of
:func:`core.time.time_grid` (every requested time a grid point); :func:`fixed_grids` and
:func:`adaptive_grids` combine grids h and h/2 by Richardson extrapolation with an
estimate of the relative error in time. All quantities dimensionless.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.linalg import lu_factor, lu_solve, rsf2csf, schur, solve_triangular

from core.discretize import Panels
from core.time import time_grid

#: Coarsest nominal grid of the automatic time refinement, and the finest allowed.
FIRST_STEPS = 16
MAX_STEPS = 8192
#: The estimate of the newer of two extrapolated results is their distance over this
#: (order 3 assumed; see :func:`adaptive_grids`).
RICHARDSON_DIVISOR = 7.0
#: LU factorizations of distinct step matrices before switching to the Schur form, which
#: costs about 30 LU factorizations once and then O(N^2) per step (measured, N = 560).
LU_LIMIT = 16


@dataclass(frozen=True)
class GridResult:
    """Outputs at the requested times of one time grid; linear in the solution, so grids
    can be combined."""

    delta: np.ndarray
    alpha: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    c: np.ndarray
    effective: np.ndarray  # (N, T): q - V q at the nodes
    nodal: np.ndarray  # (N, T): q at the nodes

    def combine(self, coarse: GridResult) -> GridResult:
        """Richardson extrapolation ``(4 self - coarse) / 3`` (self on the halved grid)."""
        def mix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
            return (4.0 * a - b) / 3.0
        return GridResult(mix(self.delta, coarse.delta), mix(self.alpha, coarse.alpha),
                       mix(self.force, coarse.force), mix(self.moment, coarse.moment),
                       self.c, mix(self.effective, coarse.effective),
                       mix(self.nodal, coarse.nodal))

    def distance(self, other: GridResult) -> float:
        """Largest relative difference over all outputs (each group on its own scale)."""
        def rel(pairs: list[tuple[np.ndarray, np.ndarray]]) -> float:
            scale = max(float(np.max(np.abs(a))) for a, _ in pairs) or 1.0
            return max(float(np.max(np.abs(a - b))) for a, b in pairs) / scale
        return max(rel([(self.delta, other.delta), (self.alpha, other.alpha)]),
                   rel([(self.force, other.force), (self.moment, other.moment)]),
                   rel([(self.nodal, other.nodal)]))


class CollocationSystem:
    """One scene on one panel rule; :meth:`march` solves it on a given time grid."""

    def __init__(self, panels: Panels, op: np.ndarray, m: np.ndarray, g: np.ndarray,
                 given: frozenset[str], loads: dict, c_fn: Callable, kernel: Callable | None):
        self.panels = panels
        self.op = op
        self.m = m
        self.g = g
        self.given = given
        self.loads = loads
        self.c_fn = c_fn
        self.kernel = kernel
        n = panels.size
        x = panels.nodes
        self.unknown_delta = "settlement" not in given
        self.unknown_alpha = "tilt" not in given
        # Border of the augmented system: columns of the unknown ones of delta, alpha, and
        # the equilibrium rows of the given ones of P, M.
        cols = []
        if self.unknown_delta:
            cols.append(-np.ones(n))
        if self.unknown_alpha:
            cols.append(-x)
        rows = []
        if "force" in given:
            rows.append(panels.weights)
        if "moment" in given:
            rows.append(panels.weights * x)
        self.k = len(cols)
        self.border_cols = np.array(cols).T.reshape(n, self.k)
        self.border_rows = np.array(rows).reshape(self.k, n)
        self._lu: dict[tuple[float, float], tuple] = {}
        self._n_factorized = 0
        self._schur: tuple | None = None

    def _matrix(self, c_n: float, scale: float) -> np.ndarray:
        n = self.panels.size
        big = np.zeros((n + self.k, n + self.k))
        big[:n, :n] = scale * self.op
        big[np.arange(n), np.arange(n)] += c_n * self.m
        big[:n, n:] = self.border_cols
        big[n:, :n] = self.border_rows
        return big

    def solve(self, c_n: float, scale: float, rhs: np.ndarray) -> np.ndarray:
        """Solve the bordered step system with block ``c_n diag(m) + scale F``.

        A few distinct matrices (an elastic base, a non-aging kernel on a uniform grid) are
        LU-factorized and kept. Once more than ``LU_LIMIT`` have been needed (aging: the
        diagonal trapezoid weight or ``c`` changes every step) a real Schur form of
        ``E = D^-1/2 F D^-1/2`` (D = diag(m)) is computed once, and every later step costs
        O(N^2): ``c D + s F = s D^1/2 U (T + (c/s) I) U^T D^1/2`` with T triangular. E is
        similar to the positive operator F/m, so ``T + (c/s) I`` is well conditioned for
        ``c/s > 0``; the border (k <= 2 unknowns) is eliminated with its k x k complement.
        """
        key = (c_n, scale)
        lu = self._lu.get(key)
        if lu is None and (self._n_factorized < LU_LIMIT or scale <= 0.0):
            lu = lu_factor(self._matrix(c_n, scale), check_finite=False)
            self._n_factorized += 1
            if len(self._lu) >= 4:
                self._lu.pop(next(iter(self._lu)))
            self._lu[key] = lu
        if lu is not None:
            return lu_solve(lu, rhs, check_finite=False)
        if self._schur is None:
            root = np.sqrt(self.m)
            tri, vecs = schur(self.op / root[:, None] / root[None, :], output="real")
            if np.any(np.diag(tri, -1) != 0.0):
                # Complex eigenvalue pairs leave 2 x 2 blocks: go to the complex form.
                tri, vecs = rsf2csf(tri, vecs)
            self._schur = (tri.copy(), np.diag(tri).copy(), vecs,
                           np.ascontiguousarray(vecs.conj().T), root)
        shifted, diagonal, vecs, vecs_h, root = self._schur
        # Only the diagonal of the triangular factor depends on the step.
        np.fill_diagonal(shifted, diagonal + c_n / scale)

        def inverse(v: np.ndarray) -> np.ndarray:
            y = solve_triangular(shifted, vecs_h @ (v / root[:, None]), check_finite=False)
            return np.real(vecs @ y) / root[:, None] / scale

        if self.k == 0:
            return inverse(rhs[:, None])[:, 0]
        n = self.panels.size
        y = inverse(np.column_stack([rhs[:n], self.border_cols]))
        complement = self.border_rows @ y[:, 1:]
        u = np.linalg.solve(complement, self.border_rows @ y[:, 0] - rhs[n:])
        return np.concatenate([y[:, 0] - y[:, 1:] @ u, u])

    def march(self, grid: np.ndarray, widths: np.ndarray, out_index: np.ndarray) -> GridResult:
        """Step through ``grid`` (step lengths ``widths``); record outputs at ``out_index``."""
        panels = self.panels
        n_nodes = panels.size
        x = panels.nodes
        steps = len(grid)
        c_vals = _eval_time(self.c_fn, grid, "c")
        if np.any(c_vals <= 0.0):
            raise ValueError("c: the relative modulus must be > 0 at every time")
        load = {name: _eval_time(fn, grid, name) for name, fn in self.loads.items()}
        zero = np.zeros(steps)
        delta_given = load.get("settlement", zero)
        alpha_given = load.get("tilt", zero)

        memory = self.kernel is not None
        if memory:
            # Trapezoid weight of node j in int_{t_0}^{t_n} for every j < n.
            inner = np.zeros(steps)
            inner[:-1] += 0.5 * widths
            inner[1:] += 0.5 * widths
            history = np.zeros((n_nodes, steps))

        wanted = {int(i): k for k, i in enumerate(out_index)}
        n_out = len(out_index)
        out = {name: np.zeros(n_out) for name in ("delta", "alpha", "force", "moment", "c")}
        effective = np.zeros((n_nodes, n_out))
        nodal = np.zeros((n_nodes, n_out))

        for n in range(steps):
            vq_past = np.zeros(n_nodes)
            diag_weight = 0.0
            if memory and n > 0:
                kvals = _eval_kernel(self.kernel, grid[n], grid[: n + 1])
                vq_past = history[:, :n] @ (inner[:n] * kvals[:n])
                diag_weight = 0.5 * widths[n - 1] * kvals[n]
            rhs = np.empty(n_nodes + self.k)
            rhs[:n_nodes] = delta_given[n] + alpha_given[n] * x - self.g + self.op @ vq_past
            extra = [load[name][n] for name in ("force", "moment") if name in self.given]
            rhs[n_nodes:] = extra
            sol = self.solve(c_vals[n], 1.0 - diag_weight, rhs)
            q = sol[:n_nodes]
            if memory:
                history[:, n] = q
            if n in wanted:
                k = wanted[n]
                tail = list(sol[n_nodes:])
                d = tail.pop(0) if self.unknown_delta else delta_given[n]
                a = tail.pop(0) if self.unknown_alpha else alpha_given[n]
                out["delta"][k] = d
                out["alpha"][k] = a
                out["force"][k] = load["force"][n] if "force" in load else panels.weights @ q
                out["moment"][k] = (load["moment"][n] if "moment" in load
                                    else (panels.weights * x) @ q)
                out["c"][k] = c_vals[n]
                effective[:, k] = q * (1.0 - diag_weight) - vq_past
                nodal[:, k] = q
        return GridResult(out["delta"], out["alpha"], out["force"], out["moment"], out["c"],
                       effective, nodal)


def fixed_grids(system: CollocationSystem, times: np.ndarray, steps: int,
                richardson: bool, jumps: Sequence[float] = ()) -> tuple[GridResult, float, int]:
    """Solve on ``steps`` nominal steps, and with ``richardson`` on the halved grid too;
    ``jumps``: times where a given history jumps (every grid holds both sides of each).

    Returns the result (extrapolated when ``richardson``), its estimated relative error
    in time (NaN for one grid) and the number of steps of the finest grid.
    """
    grid, widths, index = time_grid(times, steps, jumps=jumps)
    coarse = system.march(grid, widths, index)
    fine_grid, fine_widths, fine_index = time_grid(times, steps, 1, jumps=jumps)
    fine = system.march(fine_grid, fine_widths, fine_index) if richardson else None
    if fine is None:
        return coarse, float("nan"), len(grid) - 1
    # |x_{h/2} - x_h| / 3 estimates the error of x_{h/2}; the extrapolated value is
    # better still, so this is a safe (pessimistic) figure.
    return fine.combine(coarse), fine.distance(coarse) / 3.0, len(fine_grid) - 1


def grids_at(system: CollocationSystem, times: np.ndarray, steps: int, level: int,
             richardson: bool, jumps: Sequence[float] = ()) -> GridResult:
    """The result on the grid of ``steps`` nominal steps halved ``level`` times, with
    ``richardson`` extrapolated from the grid once less halved, as :func:`fixed_grids`
    (``level`` 1) and :func:`adaptive_grids` (its last level) combine them: another rule
    marched on the same time grids errs the same in time, so the two differ by space."""
    grid, widths, index = time_grid(times, steps, level, jumps=jumps)
    result = system.march(grid, widths, index)
    if not richardson or level < 1:
        return result
    grid, widths, index = time_grid(times, steps, level - 1, jumps=jumps)
    return result.combine(system.march(grid, widths, index))


def adaptive_grids(system: CollocationSystem, times: np.ndarray, richardson: bool,
                   tol: float, jumps: Sequence[float] = ()
                   ) -> tuple[GridResult, float, int, bool, int]:
    """Double the grid until the estimated relative error in time is below ``tol``.

    Returns the result, its estimated relative error in time, the number of steps, whether
    the error met ``tol``, and the level (halvings of ``FIRST_STEPS``) of the result."""
    level = 0
    plain: list[GridResult] = []
    extrapolated: list[GridResult] = []
    while True:
        grid, widths, index = time_grid(times, FIRST_STEPS, level, jumps=jumps)
        plain.append(system.march(grid, widths, index))
        n_steps = len(grid) - 1
        error = float("inf")
        if richardson:
            if len(plain) >= 2:
                extrapolated.append(plain[-1].combine(plain[-2]))
            best = extrapolated[-1] if extrapolated else plain[-1]
            if len(extrapolated) >= 2:
                # Order 4 would make the newer extrapolation ~16 times closer than the
                # older one (diff / 15); only order 3 is assumed (diff / 7), as the lift-off
                # march does: with diff / 15 the estimate read 0.69 of the error (the aging
                # concrete kernel under a time-varying force: success at tol 1e-4 with
                # the settlement 1.18e-4 off) and 0.95-0.99 on exponential kernels.
                error = extrapolated[-1].distance(extrapolated[-2]) / RICHARDSON_DIVISOR
        else:
            best = plain[-1]
            if len(plain) >= 2:
                error = plain[-1].distance(plain[-2]) / 3.0
        if error <= tol:
            return best, error, n_steps, True, level
        if 2 * n_steps > MAX_STEPS:
            return best, error, n_steps, False, level
        level += 1


def finite_values(fn: Callable, points: np.ndarray, name: str, refusal: str) -> np.ndarray:
    """``fn(points)`` broadcast to the shape of ``points`` (dimensionless x or t), as a new
    array; a ValueError ``"<name>: <refusal>"`` if any value is not finite."""
    values = np.broadcast_to(np.asarray(fn(points), dtype=float), points.shape)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"{name}: {refusal}")
    return np.array(values)


def _eval_time(fn: Callable, t: np.ndarray, name: str) -> np.ndarray:
    return finite_values(fn, t, name, "values must be finite at every time")


def _eval_kernel(kernel: Callable, t: float, tau: np.ndarray) -> np.ndarray:
    values = np.broadcast_to(np.asarray(kernel(np.full(tau.shape, t), tau), dtype=float),
                             tau.shape)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"kernel: K(t, tau) must be finite; it is not at t = {t!r}")
    return values
