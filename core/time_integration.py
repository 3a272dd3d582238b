"""Scalar Volterra equations of the modes, solved in time.

After the modal decomposition (:mod:`core.statements`) every mode ``w_k`` obeys

    d_k(t) w_k(t) - (V w_k)(t) = r_k(t) + sum_j C_kj (V u_j)(t),     t >= 1,
    (V f)(t) = int_1^t K(t, tau) f(tau) dtau,

with ``d_k(t) = 1 + c(t)/gamma_k >= 1`` and a few *known* functions ``u_j(t)`` (the given
force and moment, ``1/c``) whose creep history also drives the modes. Keeping ``V u`` as
a coupling term, rather than substituting ``w = z + u/gamma``, avoids a cancellation that
loses ``log10(c/gamma)`` digits in the modes of small eigenvalue ``gamma``.

The requested times are outputs, not the step: each solver chooses its own steps and
meets ``tol`` at them.

* :func:`solve_degenerate` for ``K(t, tau) = b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))``
  (every shipped creep model). ``V f`` is the sum of states ``S_0' = b f`` and
  ``S_r' = -rate_r S_r + a_r f``, so each mode is a small linear ODE. It is stepped by the
  3-stage Radau IIA collocation method (order 5, L-stable: a fast, stiff exponential costs
  nothing extra), all modes at once, O(1) work per mode and step. The known channels are
  stepped first; the modes then see their stage values (the coupled system is block
  triangular, so this is the exact Radau step of the whole system). Step sizes come from
  step-doubling error estimates; a step may spend its share of the time or of the
  log-time since loading (:data:`LOG_TIME_BUDGET`) or of the steps
  (:data:`STEP_BUDGET`), whichever is largest. A step, both its halves and the side steps
  to the output times inside it read the kernel and the histories once (the batched
  step itself is :mod:`core.radau`).
* :func:`solve_general` for any vectorized ``K(t, tau)``: product trapezoid rule on grids
  containing every requested time, halved until the Richardson estimate meets ``tol``
  (O(steps^2) per mode, as any method for a general kernel must be). The grid's size is
  checked before it is built (:data:`core.limits.MAX_KERNEL_GRID_POINTS`) and the kernel
  matrix is evaluated in blocks of rows, so one solve's memory is bounded.

Both accept ``breaks``: times where a given history (a load) jumps or kinks. The steps
(or grid points) fall exactly on them, and the history is read on the proper side of
each: a step that ends at a jump reads the value just before it, the next one starts
after it. Without them a step straddles the jump and the step-doubling estimate, which
assumes a smooth history, can read far too low.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from core import limits
from core.exponential_steps import solve_exponential
from core.radau import (  # noqa: F401 (RADAU_A, RADAU_C, _radau_step(s): re-exported)
    JUMP_SIDE,
    RADAU_A,
    RADAU_C,
    RADAU_ORDER,
    _advance,
    _radau_step,
    _radau_steps,
    _stage_values,
)

TimeFunction = Callable[[np.ndarray], np.ndarray]

#: The exponential collocation may spend this fraction (1/EXPONENTIAL_SHARE) of the step
#: limit before the adaptive Radau stepping takes over (a history that oscillates fast).
EXPONENTIAL_SHARE = 4

#: Step-doubling differences below this are round-off, not truncation error (~100 ulp).
_ROUNDOFF = 100 * float(np.finfo(float).eps)
#: Log-time share of the error budget: a step may spend ``h / ((t - 1 + h) LOG_TIME_BUDGET)``
#: of it. Summed over steps from the shortest one taken (1e-10 of the span) to the end,
#: ``h / (t - 1 + h)`` adds up to at most ``1 + ln(1e10)``, about 24, so this share adds at
#: most a quarter budget to the share of the time (``h / span``, adding up to 1). Measured:
#: 408 -> 193 steps on the 50-year fib MC2010 preset; 25 (148 steps) let a stiff
#: exponential's transient (tests/test_hard_cases.py) leave 2.6e-11 at 28 relaxation
#: times, where its closed form holds to 7e-13 (100: 3.7e-13).
LOG_TIME_BUDGET = 100.0
#: Each of the first STEP_BUDGET steps may spend at least 1/STEP_BUDGET of the error
#: budget (so this share adds at most one budget): the optimum for the sum of local errors
#: is an equal error per step, which a run of a few hundred steps then nearly has.
#: Measured on the 50-year fib MC2010 preset: 193 -> 147 steps (400: 163, 100: 134); the
#: stiff exponential's closed form (tests/test_hard_cases.py) held to 4.6e-13.
STEP_BUDGET = 200
def _before(t: float) -> float:
    return t - JUMP_SIDE * max(1.0, abs(t))


def _after(t: float) -> float:
    return t + JUMP_SIDE * max(1.0, abs(t))


def _jumps(breaks, start: float, end: float) -> np.ndarray:
    """Sorted distinct ``breaks`` strictly inside ``(start, end)`` (beyond rounding)."""
    try:
        b = np.asarray(list(breaks), dtype=float).ravel()
    except (TypeError, ValueError):
        raise ValueError("breaks: must be a sequence of times") from None
    if not np.all(np.isfinite(b)):
        raise ValueError("breaks: must be finite times")
    b = np.unique(b)
    margin = 4 * JUMP_SIDE
    return b[(b > start + margin * max(1.0, abs(start)))
             & (b < end - margin * max(1.0, abs(end)))]


@dataclass(frozen=True)
class ModalProblem:
    """``d w - V w = r + coupling @ V u`` for ``modes`` unknowns and ``known`` functions u.

    ``d(t)``, ``r(t)`` return arrays (modes, len(t)); ``u(t)`` (known, len(t));
    ``coupling`` is (modes, known). All dimensionless. ``parts``: the modes and the known
    functions are that many equal consecutive groups, independent problems stepped
    together (the same steps for all); their sizes and errors are measured per group.
    """

    d: TimeFunction
    r: TimeFunction
    u: TimeFunction
    coupling: np.ndarray
    parts: int = 1

    @property
    def n_modes(self) -> int:
        return self.coupling.shape[0]

    @property
    def n_known(self) -> int:
        return self.coupling.shape[1]


@dataclass(frozen=True)
class VolterraSolution:
    """Solution at the output times.

    ``w`` and ``vw`` (= ``V w``) have shape (modes, times); ``vu`` (known, times).
    ``error_estimate`` estimates the global error of ``w`` relative to ``max|w|`` (and of
    ``vu`` relative to ``max|u|``); ``steps`` counts accepted steps. ``part_errors``: the
    estimate of each group of :attr:`ModalProblem.parts`, relative to its own size
    (``error_estimate`` is their largest).
    """

    w: np.ndarray
    vw: np.ndarray
    vu: np.ndarray
    error_estimate: float
    steps: int
    rejected: int
    success: bool
    message: str
    part_errors: tuple[float, ...] = ()


def _scales(problem: ModalProblem, t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """Sizes of the unknowns and known functions, for a relative error norm."""
    probe = np.linspace(1.0, t_end, 17)
    w_scale = np.ones(problem.n_modes)
    if problem.n_modes:
        d = problem.d(probe)
        forcing = problem.r(probe)
        if problem.n_known:
            u = problem.u(probe)
            forcing = np.abs(forcing) + np.abs(problem.coupling) @ np.abs(u)
        # one size per group of modes (per problem stepped together)
        size = np.max(np.abs(forcing / d).reshape(problem.parts, -1), axis=1)
        w_scale = np.repeat(np.where(size > 0, size, 1.0), problem.n_modes // problem.parts)
    u_scale = np.ones(problem.n_known)
    if problem.n_known:
        u_scale = np.maximum(np.max(np.abs(problem.u(probe)), axis=1), 1e-300)
    return w_scale, u_scale


def solve_degenerate(kernel, problem: ModalProblem, times: np.ndarray, *, tol: float,
                     max_steps: int = limits.MAX_TIME_STEPS, breaks=(),
                     method: str = "exponential") -> VolterraSolution:
    """Solve ``problem`` at ``times`` (increasing, >= 1) for a degenerate kernel.

    ``kernel`` has ``rates``, ``tau_part(tau)`` and ``exponential_parts(tau)`` (see
    :class:`core.creep.DegenerateKernel`). ``tol`` bounds the global error relative to the
    size of the unknowns. The main steps are chosen for accuracy alone; an output time
    inside a step is reached by a separate, shorter side step from the step's start (its
    error is below that of the accepted step, so it needs no estimate of its own).
    ``breaks``: times (same unit as ``times``) where ``d``, ``r`` or ``u`` jump or kink;
    every step ends on each of them, and an output time on one reports the value after
    the jump. At most ``max_steps`` steps (accepted and rejected) are taken; then the
    times not reached are NaN and the message says which limit stopped it.

    ``method``: ``"exponential"`` (default) tries the exponential collocation of
    :mod:`core.exponential_steps` (exact for the kernel's exponentials, steps fixed in
    advance and refined as a whole) within a share of ``max_steps`` and steps adaptively
    by Radau IIA when that does not meet ``tol``; ``"radau"`` steps adaptively only (the
    independent reference of the tests).
    """
    if method not in ("exponential", "radau"):
        raise ValueError(f"method: must be 'exponential' or 'radau', got {method!r}")
    times = np.asarray(times, dtype=float)
    jumps = _jumps(breaks, 1.0, float(times[-1]))
    jump_set = set(jumps.tolist())
    ns = 1 + len(np.atleast_1d(kernel.rates))
    nm, nk = problem.n_modes, problem.n_known
    s_modes = np.zeros((nm, ns))
    s_known = np.zeros((nk, ns))
    vw_out = np.zeros((nm, len(times)))
    vu_out = np.zeros((nk, len(times)))
    w_scale, u_scale = _scales(problem, float(times[-1]))
    # laid out like the differences below: per group, its modes then its known functions
    scale = np.concatenate([w_scale.reshape(problem.parts, -1),
                            u_scale.reshape(problem.parts, -1)], axis=1)
    span = max(float(times[-1]) - 1.0, 1e-300)
    # A tenth of tol per unit of time, of log-time or per step (LOG_TIME_BUDGET,
    # STEP_BUDGET): the accumulated error stays below tol.
    local_tol = 0.1 * tol

    def record(k: slice | int, vw: np.ndarray, vu: np.ndarray) -> None:
        # V w and V u (sums over the states; (count, channels) for a slice); w itself is
        # formed for all times at once at the end
        vw_out[:, k] = vw.T
        vu_out[:, k] = vu.T

    def finish() -> np.ndarray:
        if not nm:
            return np.zeros((0, len(times)))
        # an output time on a jump reports the value after it
        tt = np.array([_after(t) if t in jump_set else t for t in times.tolist()])
        forcing = problem.r(tt) + (problem.coupling @ vu_out if nk else 0.0)
        return (forcing + vw_out) / problem.d(tt)

    if method == "exponential" and float(times[-1]) > 1.0:
        def unknowns(vw: np.ndarray, vu: np.ndarray) -> np.ndarray:
            # w at (at most 65 of) the output times: a size, not the answer
            pick = np.unique(np.linspace(0, len(times) - 1, min(len(times), 65)).astype(int))
            tt = times[pick]
            forcing = problem.r(tt) + (problem.coupling @ vu[:, pick] if nk else 0.0)
            return (forcing + vw[:, pick]) / problem.d(tt)

        fast = solve_exponential(kernel, problem, times, jumps, tol=tol, w_scale=w_scale,
                                 u_scale=u_scale, max_steps=max_steps // EXPONENTIAL_SHARE,
                                 unknowns=unknowns)
        if fast is not None:
            vw_out[:], vu_out[:], errors, steps = fast
            part_errors = tuple(float(max(e, 1e-15)) for e in errors)
            return VolterraSolution(finish(), vw_out, vu_out, max(part_errors), steps, 0,
                                    True, "ok", part_errors)
    k_out = 0
    while k_out < len(times) and times[k_out] <= 1.0:
        record(k_out, s_modes.sum(axis=1), s_known.sum(axis=1))
        k_out += 1
    h = min(span / 20.0, 0.5)
    t_now = 1.0
    total_error = np.zeros(problem.parts)
    steps = rejected = 0
    t_final = float(times[-1])
    j_next = 0
    while k_out < len(times):
        if steps + rejected > max_steps:
            # No answer is better than a wrong one: the times not reached are NaN.
            w_out = finish()
            w_out[:, k_out:] = vw_out[:, k_out:] = vu_out[:, k_out:] = np.nan
            return VolterraSolution(
                w_out, vw_out, vu_out, np.inf, steps, rejected, False,
                f"time stepping stopped at its limit of {max_steps} steps at t = "
                f"{t_now:.6g} of {t_final:.6g}: the given histories (loads) vary faster "
                "than that many steps can follow")
        while j_next < len(jumps) and jumps[j_next] <= t_now:
            j_next += 1
        t_stop = float(jumps[j_next]) if j_next < len(jumps) else t_final
        # a step that would end within a millionth of its length before a jump takes it
        at_jump = j_next < len(jumps) and h >= (t_stop - t_now) * (1 - 1e-6)
        h_try = t_stop - t_now if at_jump else min(h, t_final - t_now)
        t_next = t_stop if at_jump else t_now + h_try
        if t_final - t_next <= 1e-12 * max(1.0, t_final):
            t_next = t_final
        # output times inside the step: reached by side steps from its start, batched
        # with the step and its first half
        k_end = k_out
        while k_end < len(times) and times[k_end] < t_next - 1e-12 * max(1.0, t_next):
            k_end += 1
        k_side = k_out
        while k_side < k_end and times[k_side] - t_now <= 1e-12 * max(1.0, times[k_side]):
            k_side += 1
        # the step, its halves and the side steps: the kernel and histories read at once;
        # from the start: the first half (its states go on), the whole step and the side
        # steps (their sums over the states are all that is read); last the second half
        sides = times[k_side:k_end] - t_now
        n_batch = 3 + sides.size
        starts = np.full(n_batch, t_now)
        starts[-1] = t_now + h_try / 2
        flags = np.zeros(n_batch, dtype=bool)
        flags[[1, -1]] = at_jump
        stages = _stage_values(kernel, problem, starts,
                               np.concatenate([[h_try / 2, h_try], sides, [h_try / 2]]), flags)
        half_modes, half_known, batch_vw, batch_vu = _advance(
            stages.take(slice(0, n_batch - 1)), problem.coupling, s_modes, s_known, keep=1)
        fine_modes, fine_known, fine_vw, fine_vu = _advance(
            stages.take(slice(n_batch - 1, n_batch)), problem.coupling, half_modes[0],
            half_known[0], keep=1)
        diff = np.concatenate([
            np.abs(fine_vw[0] - batch_vw[1]).reshape(problem.parts, -1),
            np.abs(fine_vu[0] - batch_vu[1]).reshape(problem.parts, -1)], axis=1
        ) / scale
        # Richardson: the two-half-step answer carries 1/(2^p - 1) of the difference.
        errors = np.max(diff, axis=1, initial=0.0) / (2**RADAU_ORDER - 1)
        err = float(np.max(errors))
        # The budget of a step is the largest of its share of the time, of the log-time
        # since loading and of the steps: creep follows log time, so early steps are short
        # and would otherwise be solved to the accuracy per day of the last years.
        share = max(h_try / span, h_try / ((t_now - 1.0 + h_try) * LOG_TIME_BUDGET), 1e-6,
                    1.0 / STEP_BUDGET if steps < STEP_BUDGET else 0.0)
        # Below ~100 ulp the step-doubling difference is round-off, not truncation error.
        allowed = max(local_tol * share, _ROUNDOFF)
        if err > allowed and h_try > 1e-10 * span:
            rejected += 1
            h = h_try * max(0.2, 0.9 * (allowed / err) ** (1 / (RADAU_ORDER + 1)))
            continue
        if k_side > k_out:
            record(slice(k_out, k_side), s_modes.sum(axis=1)[None], s_known.sum(axis=1)[None])
        if k_end > k_side:
            record(slice(k_side, k_end), batch_vw[2:], batch_vu[2:])
        k_out = k_end
        s_modes, s_known = fine_modes[0], fine_known[0]
        t_now = t_next
        total_error += errors
        steps += 1
        while k_out < len(times) and abs(times[k_out] - t_now) <= 1e-12 * max(1.0, t_now):
            record(k_out, fine_vw[0], fine_vu[0])
            k_out += 1
        grow = 4.0 if err == 0 else min(4.0, max(0.5, 0.9 * (allowed / err) ** (
            1 / (RADAU_ORDER + 1))))
        h = h_try * grow
    part_errors = tuple(float(max(e, 1e-15)) for e in total_error)
    return VolterraSolution(finish(), vw_out, vu_out, max(part_errors), steps, rejected,
                            True, "ok", part_errors)


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
