"""The modal Volterra equations for any kernel: product trapezoid rule with Richardson.

:func:`solve_general` solves the problem of :mod:`core.time.integration` for any
vectorized ``K(t, tau)``: product trapezoid rule on grids containing every requested
time, halved until the Richardson estimate meets ``tol`` (O(steps^2) per mode, as any
method for a general kernel must be). The grid's size is checked before it is built
(:data:`core.limits.MAX_KERNEL_GRID_POINTS`) and the kernel matrix is evaluated in blocks
of rows, so one solve's memory is bounded.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from core import limits
from core.time.volterra import ModalProblem, VolterraSolution, _before, _jumps, _scales
from core.work import check_work


def _trapezoid_weights(grid: np.ndarray, i: int) -> np.ndarray:
    """Weights of the trapezoid rule for int_{grid[0]}^{grid[i]} on the nodes 0..i."""
    h = np.diff(grid[: i + 1])
    om = np.zeros(i + 1)
    om[:-1] += h / 2
    om[1:] += h / 2
    return om


def _kernel_matrix(kernel: Callable, grid: np.ndarray) -> np.ndarray:
    """``K(grid_i, grid_j)`` for ``j <= i``, 0 above the diagonal.

    Evaluated in blocks of rows of at most :data:`core.limits.KERNEL_BLOCK_ELEMENTS`
    values (only the columns a block's rows need), so a formula kernel's temporaries
    stay small whatever the grid.
    """
    n = len(grid)
    kmat = np.zeros((n, n))
    rows = max(1, limits.KERNEL_BLOCK_ELEMENTS // n)
    for start in range(0, n, rows):
        stop = min(n, start + rows)
        block = np.broadcast_to(np.asarray(kernel(grid[start:stop, None],
                                                  grid[None, :stop]), dtype=float),
                                (stop - start, stop))
        block = np.tril(block, start)
        if not np.all(np.isfinite(block)):
            raise ValueError("kernel: returned non-finite values K(t, tau) for "
                             "1 <= tau <= t")
        kmat[start:stop, :stop] = block
    return kmat


def _trapezoid_solve(kernel: Callable, problem: ModalProblem, grid: np.ndarray,
                     at: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Product trapezoid rule on ``grid`` (which starts at 1). Values on the grid.

    ``at``: where ``d``, ``r``, ``u`` are read for each node (``grid``, but just before
    a jump for the first of the two nodes a jump has).
    """
    n = len(grid)
    kmat = _kernel_matrix(kernel, grid)
    nm, nk = problem.n_modes, problem.n_known
    vu = np.zeros((nk, n))
    if nk:
        u = problem.u(at)
        for i in range(1, n):
            vu[:, i] = u[:, : i + 1] @ (kmat[i, : i + 1] * _trapezoid_weights(grid, i))
    w = np.zeros((nm, n))
    vw = np.zeros((nm, n))
    if nm:
        d = problem.d(at)
        r = problem.r(at) + (problem.coupling @ vu if nk else 0.0)
        w[:, 0] = r[:, 0] / d[:, 0]
        for i in range(1, n):
            kw = kmat[i, : i + 1] * _trapezoid_weights(grid, i)
            hist = w[:, :i] @ kw[:i]
            w[:, i] = (r[:, i] + hist) / (d[:, i] - kw[i])
            vw[:, i] = hist + kw[i] * w[:, i]
    return w, vw, vu


def _general_grid(anchors: np.ndarray, sub: np.ndarray,
                  jumps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The grid (``sub[k]`` equal intervals between consecutive anchors) and where each
    node reads the histories. A jump is two nodes at the same time: the first reads the
    value just before it, the second the value from it on; the zero-width interval
    between them has no weight, so the quadrature of each side stays exact."""
    grid = np.concatenate([[anchors[0]]] + [
        np.linspace(a, b, s + 1)[1:] for a, b, s in zip(anchors[:-1], anchors[1:], sub,
                                                       strict=True)])
    if not jumps.size:
        return grid, grid
    position = np.searchsorted(grid, jumps)
    grid = np.insert(grid, position, jumps)
    at = grid.copy()
    first = position + np.arange(len(position))
    at[first] = [_before(t) for t in grid[first]]
    return grid, at


def _grid_points(sub: np.ndarray, jumps: np.ndarray) -> int:
    return 1 + int(sub.sum()) + len(jumps)


def solve_general(kernel: Callable, problem: ModalProblem, times: np.ndarray, *, tol: float,
                  max_points: int = limits.MAX_KERNEL_GRID_POINTS,
                  breaks=()) -> VolterraSolution:
    """Same problem as :func:`solve_degenerate` for any vectorized kernel ``K(t, tau)``.

    Trapezoid product quadrature on a grid containing every output time and every
    ``breaks`` time (where a history jumps or kinks), refined by halving; Richardson
    extrapolation of the last two grids gives the answer and the difference of the last
    two extrapolations the error estimate. A grid of more than ``max_points`` is never
    built: if the first one would be, ``ValueError`` (naming ``times``); else the finest
    affordable answer is returned, with the estimate of its last two grids when only two
    fitted (the error of the finer trapezoid answer, an upper bound of the extrapolated
    one's in practice).
    """
    times = np.asarray(times, dtype=float)
    jumps = _jumps(breaks, 1.0, float(times[-1]))
    anchors = np.unique(np.concatenate([[1.0], times, jumps]))
    span = max(anchors[-1] - 1.0, 1e-300)
    sub = np.maximum(1, np.ceil(np.diff(anchors) / (span / 16)).astype(int))
    size = _grid_points(sub, jumps)
    if size > max_points:
        jump_text = f" and {len(jumps)} jumps of the loads" if len(jumps) else ""
        raise ValueError(
            f"times: {len(times)} output times{jump_text} need a time grid of at least "
            f"{size} points with a general creep kernel (the grid holds every output "
            f"time), more than the {max_points} allowed: ask for fewer output times")
    w_scale, u_scale = _scales(problem, float(anchors[-1]))

    def difference(a, b) -> float:
        err_w = (float(np.max(np.abs(a[0] - b[0]) / w_scale[:, None]))
                 if problem.n_modes else 0.0)
        err_u = (float(np.max(np.abs(a[2] - b[2]) / u_scale[:, None]))
                 if problem.n_known else 0.0)
        return max(err_w, err_u)

    answers: list[tuple[np.ndarray, ...]] = []
    extrapolated: list[tuple[np.ndarray, ...]] = []
    while True:
        check_work("refining the time grid of the creep kernel")
        grid, at = _general_grid(anchors, sub, jumps)
        # the last node at a time: after a jump when an output time is on one
        idx = np.searchsorted(grid, times, side="right") - 1
        w, vw, vu = _trapezoid_solve(kernel, problem, grid, at)
        answers.append((w[:, idx], vw[:, idx], vu[:, idx]))
        if len(answers) >= 2:
            # Error c h^2 + d h^4: (4 fine - coarse)/3 removes the h^2 term.
            extrapolated.append(tuple((4 * c - p) / 3 for c, p in zip(
                answers[-1], answers[-2], strict=True)))
        if len(extrapolated) >= 2:
            # Two extrapolations differ by 15x the finer one's O(h^4) error.
            est = difference(extrapolated[-1], extrapolated[-2]) / 15
            if est <= tol:
                return VolterraSolution(*extrapolated[-1], max(est, 1e-15), len(grid) - 1,
                                        0, True, "ok")
        if _grid_points(2 * sub, jumps) <= max_points:
            sub = sub * 2
            continue
        if len(extrapolated) >= 2:
            best = extrapolated[-1]
        elif extrapolated:
            # the fine trapezoid answer's own error: the coarse one's is 4x larger
            est = difference(answers[-1], answers[-2]) / 3
            best = extrapolated[-1]
        else:
            est, best = np.inf, answers[-1]
        ok = est <= tol
        message = "ok" if ok else (
            f"general-kernel time stepping reached {len(grid)} points (at most "
            f"{max_points}) with estimated error {est:.1e}")
        return VolterraSolution(*best, max(est, 1e-15), len(grid) - 1, 0, ok, message)
