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
  step-doubling error estimates with error per unit step control.
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

TimeFunction = Callable[[np.ndarray], np.ndarray]

_S6 = np.sqrt(6.0)
RADAU_C = np.array([(4 - _S6) / 10, (4 + _S6) / 10, 1.0])
RADAU_A = np.array([
    [(88 - 7 * _S6) / 360, (296 - 169 * _S6) / 1800, (-2 + 3 * _S6) / 225],
    [(296 + 169 * _S6) / 1800, (88 + 7 * _S6) / 360, (-2 - 3 * _S6) / 225],
    [(16 - _S6) / 36, (16 + _S6) / 36, 1 / 9],
])
RADAU_ORDER = 5
#: Relative distance from a jump at which a history is read on the side before it (and,
#: at an output time on a jump, after it): far above the rounding of converting times
#: (days to the dimensionless time and back), far below any tolerance.
JUMP_SIDE = 1e-12


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
    ``coupling`` is (modes, known). All dimensionless.
    """

    d: TimeFunction
    r: TimeFunction
    u: TimeFunction
    coupling: np.ndarray

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
    ``vu`` relative to ``max|u|``); ``steps`` counts accepted steps.
    """

    w: np.ndarray
    vw: np.ndarray
    vu: np.ndarray
    error_estimate: float
    steps: int
    rejected: int
    success: bool
    message: str


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
        w_scale = np.full(problem.n_modes, float(np.max(np.abs(forcing / d))) or 1.0)
    u_scale = np.ones(problem.n_known)
    if problem.n_known:
        u_scale = np.maximum(np.max(np.abs(problem.u(probe)), axis=1), 1e-300)
    return w_scale, u_scale


def _kernel_factors(kernel, t_stage: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``beta`` (states, stages): forcing factors; ``decay`` (states,): state decay rates."""
    rates = np.asarray(kernel.rates, dtype=float)
    beta = np.concatenate([np.asarray(kernel.tau_part(t_stage), dtype=float)[None, :],
                           np.asarray(kernel.exponential_parts(t_stage),
                                      dtype=float).reshape(len(rates), -1)], axis=0)
    return beta, np.concatenate([[0.0], rates])


def _radau_step(kernel, problem: ModalProblem, t0: float, h: float,
                s_modes: np.ndarray, s_known: np.ndarray, *, before_jump: bool = False
                ) -> tuple[np.ndarray, np.ndarray]:
    """One Radau IIA step of all channels. Returns the new mode and known-channel states.

    ``s_modes`` (modes, states), ``s_known`` (known, states). ``before_jump``: the step
    ends where a history jumps, so its last stage (at the step's end) reads the history
    just before the jump.

    The states of one channel couple only through their sum ``V w``: a state obeys
    ``S_s' = -decay_s S_s + beta_s(t) z(t)`` with ``z = (r + V w)/d`` shared by all of them.
    Eliminating the states, whose stage operator ``I + h decay_s A`` is the same for every
    mode, leaves one 3x3 system in the stage values of ``z`` per mode: the step costs
    O(modes) small operations instead of a (3 states)^2 solve per mode.
    """
    ts = t0 + RADAU_C * h
    if before_jump:
        ts[-1] = _before(t0 + h)
    beta, decay = _kernel_factors(kernel, ts)               # (states, 3), (states,)
    hA = h * RADAU_A
    # inv(I + h decay_s A) for every state s: (states, 3, 3)
    inv = np.linalg.inv(np.eye(3)[None] + decay[:, None, None] * hA[None])
    carry = inv.sum(axis=2)                                  # (states, 3): inv_s @ 1
    # forcing of the stages of state s by z at the stages: inv_s h A diag(beta_s)
    drive = (inv @ hA) * beta[:, None, :]                    # (states, 3, 3)
    total = drive.sum(axis=0)                                # (3, 3): sum over the states
    last_carry = carry[:, 2]                                 # the step's end (c_3 = 1)
    last_drive = drive[:, 2, :]                              # (states, 3)
    new_known = s_known
    known_stage_sums = None
    if problem.n_known:
        # known channels: z = u, given
        u = problem.u(ts)                                    # (known, 3)
        known_stage_sums = s_known @ carry + u @ total.T     # V u at the stage times
        new_known = s_known * last_carry[None, :] + u @ last_drive.T
    new_modes = s_modes
    if problem.n_modes:
        d = problem.d(ts)                                    # (modes, 3)
        r = problem.r(ts)
        if known_stage_sums is not None:
            r = r + problem.coupling @ known_stage_sums
        # V w = d z - r at the stages, and V w = s @ carry + total z: solve for z
        system = np.zeros((problem.n_modes, 3, 3))
        system[:, [0, 1, 2], [0, 1, 2]] = d
        system -= total[None]
        z = np.linalg.solve(system, (s_modes @ carry + r)[:, :, None])[:, :, 0]
        new_modes = s_modes * last_carry[None, :] + z @ last_drive.T
    return new_modes, new_known


def solve_degenerate(kernel, problem: ModalProblem, times: np.ndarray, *, tol: float,
                     max_steps: int = limits.MAX_TIME_STEPS, breaks=()) -> VolterraSolution:
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
    """
    times = np.asarray(times, dtype=float)
    jumps = _jumps(breaks, 1.0, float(times[-1]))
    jump_set = set(jumps.tolist())
    ns = 1 + len(np.atleast_1d(kernel.rates))
    nm, nk = problem.n_modes, problem.n_known
    s_modes = np.zeros((nm, ns))
    s_known = np.zeros((nk, ns))
    w_out = np.zeros((nm, len(times)))
    vw_out = np.zeros((nm, len(times)))
    vu_out = np.zeros((nk, len(times)))
    w_scale, u_scale = _scales(problem, float(times[-1]))
    scale = np.concatenate([w_scale, u_scale])
    span = max(float(times[-1]) - 1.0, 1e-300)
    # A tenth of tol per unit of time, so the accumulated error stays below tol.
    local_tol = 0.1 * tol

    def record(k: int, t: float, sm: np.ndarray, sk: np.ndarray) -> None:
        vu = sk.sum(axis=1)
        vu_out[:, k] = vu
        if nm:
            tt = np.array([_after(t) if t in jump_set else t])
            vw = sm.sum(axis=1)
            forcing = problem.r(tt)[:, 0] + (problem.coupling @ vu if nk else 0.0)
            w_out[:, k] = (forcing + vw) / problem.d(tt)[:, 0]
            vw_out[:, k] = vw

    k_out = 0
    while k_out < len(times) and times[k_out] <= 1.0:
        record(k_out, 1.0, s_modes, s_known)
        k_out += 1
    h = min(span / 20.0, 0.5)
    t_now = 1.0
    total_error = 0.0
    steps = rejected = 0
    t_final = float(times[-1])
    j_next = 0
    while k_out < len(times):
        if steps + rejected > max_steps:
            # No answer is better than a wrong one: the times not reached are NaN.
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
        full = _radau_step(kernel, problem, t_now, h_try, s_modes, s_known,
                           before_jump=at_jump)
        half = _radau_step(kernel, problem, t_now, h_try / 2, s_modes, s_known)
        fine = _radau_step(kernel, problem, t_now + h_try / 2, h_try / 2, *half,
                           before_jump=at_jump)
        diff = np.concatenate([np.abs(fine[0].sum(axis=1) - full[0].sum(axis=1)),
                               np.abs(fine[1].sum(axis=1) - full[1].sum(axis=1))]) / scale
        # Richardson: the two-half-step answer carries 1/(2^p - 1) of the difference.
        err = float(np.max(diff, initial=0.0)) / (2**RADAU_ORDER - 1)
        # Below ~100 ulp the step-doubling difference is round-off, not truncation error.
        allowed = max(local_tol * max(h_try / span, 1e-6), 100 * np.finfo(float).eps)
        if err > allowed and h_try > 1e-10 * span:
            rejected += 1
            h = h_try * max(0.2, 0.9 * (allowed / err) ** (1 / (RADAU_ORDER + 1)))
            continue
        t_next = t_stop if at_jump else t_now + h_try
        if t_final - t_next <= 1e-12 * max(1.0, t_final):
            t_next = t_final
        while k_out < len(times) and times[k_out] < t_next - 1e-12 * max(1.0, t_next):
            tk = float(times[k_out])
            if tk - t_now <= 1e-12 * max(1.0, tk):
                record(k_out, tk, s_modes, s_known)
            else:
                record(k_out, tk, *_radau_step(kernel, problem, t_now, tk - t_now, s_modes,
                                               s_known))
            k_out += 1
        s_modes, s_known = fine
        t_now = t_next
        total_error += err
        steps += 1
        while k_out < len(times) and abs(times[k_out] - t_now) <= 1e-12 * max(1.0, t_now):
            record(k_out, t_now, s_modes, s_known)
            k_out += 1
        grow = 4.0 if err == 0 else min(4.0, max(0.5, 0.9 * (allowed / err) ** (
            1 / (RADAU_ORDER + 1))))
        h = h_try * grow
    est = max(total_error, 1e-15)
    return VolterraSolution(w_out, vw_out, vu_out, est, steps, rejected, True, "ok")


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
