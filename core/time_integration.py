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
  log-time since loading (:data:`LOG_TIME_BUDGET`), whichever is larger. A step, its
  first half and the side steps to the output times inside it are one batched call.
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
# inv(I + x A) = adj(I + x A) / det(I + x A) with, for a 3x3 matrix (Cayley-Hamilton),
# adj(I + x A) = I + x P1 + x^2 P2, P1 = a I - A, P2 = (a^2 - b)/2 I - a A + A^2
# (a = tr A, b = tr A^2), and det = 1 + a x + (a^2 - b)/2 x^2 + det(A) x^3, whose
# coefficients are positive (the eigenvalues of A have positive real parts): no
# cancellation for any x >= 0. _Q = _P A gives inv A = (A + x Q1 + x^2 Q2) / det.
_TR, _TR2 = float(np.trace(RADAU_A)), float(np.trace(RADAU_A @ RADAU_A))
_P1 = _TR * np.eye(3) - RADAU_A
_P2 = 0.5 * (_TR**2 - _TR2) * np.eye(3) - _TR * RADAU_A + RADAU_A @ RADAU_A
_Q1, _Q2 = _P1 @ RADAU_A, _P2 @ RADAU_A
_P1_ROWS, _P2_ROWS = _P1.sum(axis=1), _P2.sum(axis=1)
_DET = (_TR, 0.5 * (_TR**2 - _TR2), float(np.linalg.det(RADAU_A)))
#: Step-doubling differences below this are round-off, not truncation error (~100 ulp).
_ROUNDOFF = 100 * float(np.finfo(float).eps)
#: h * decay beyond which a state is fully relaxed within a step (inv ~ 1/x): capped so
#: that x^3 stays finite
_X_MAX = 1e60
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
    if hasattr(kernel, "factors"):  # b and a_r in one evaluation (a fitted kernel)
        b, a = kernel.factors(t_stage)
    else:
        b, a = kernel.tau_part(t_stage), kernel.exponential_parts(t_stage)
    beta = np.concatenate([np.asarray(b, dtype=float)[None, :],
                           np.asarray(a, dtype=float).reshape(len(rates), -1)], axis=0)
    return beta, np.concatenate([[0.0], rates])


@dataclass(frozen=True)
class _Stages:
    """What B Radau steps read at their stage times: step lengths ``hs`` (B,), kernel
    factors ``beta`` (B, states, 3) and decay rates (states,), the histories ``d``, ``r``
    (B, modes, 3) and ``u`` (B, known, 3) (None where there are no modes or knowns)."""

    hs: np.ndarray
    beta: np.ndarray
    decay: np.ndarray
    d: np.ndarray | None
    r: np.ndarray | None
    u: np.ndarray | None

    def take(self, which) -> _Stages:
        """The steps ``which`` (an index array or slice) of these."""
        return _Stages(self.hs[which], self.beta[which], self.decay,
                       *(None if v is None else v[which] for v in (self.d, self.r, self.u)))


def _stage_values(kernel, problem: ModalProblem, starts: np.ndarray, hs: np.ndarray,
                  before_jump: np.ndarray | None = None) -> _Stages:
    """Kernel and histories at the stage times of steps ``starts`` -> ``starts + hs``.

    All steps are read in one evaluation of the kernel and of the histories, whatever
    their starts: a step, its two halves and the side steps to the output times inside it
    cost one set of calls. ``before_jump`` (B,) bools: that step ends where a history
    jumps, so its last stage reads the history just before it.
    """
    hs = np.asarray(hs, dtype=float)
    n_steps = hs.size
    ts = np.asarray(starts, dtype=float)[:, None] + hs[:, None] * RADAU_C[None, :]  # (B, 3)
    if before_jump is not None and np.any(before_jump):
        ends = ts[before_jump, -1]
        ts[before_jump, -1] = ends - JUMP_SIDE * np.maximum(1.0, np.abs(ends))
    flat = ts.ravel()
    beta, decay = _kernel_factors(kernel, flat)             # (states, 3B), (states,)
    beta = beta.reshape(decay.size, n_steps, 3).transpose(1, 0, 2)   # (B, states, 3)

    def read(fn) -> np.ndarray:
        return fn(flat).reshape(-1, n_steps, 3).transpose(1, 0, 2)

    u = read(problem.u) if problem.n_known else None
    d = read(problem.d) if problem.n_modes else None
    r = read(problem.r) if problem.n_modes else None
    return _Stages(hs, beta, decay, d, r, u)


def _radau_step(kernel, problem: ModalProblem, t0: float, h: float,
                s_modes: np.ndarray, s_known: np.ndarray, *, before_jump: bool = False
                ) -> tuple[np.ndarray, np.ndarray]:
    """One Radau IIA step of all channels. Returns the new mode and known-channel states.

    ``s_modes`` (modes, states), ``s_known`` (known, states). ``before_jump``: the step
    ends where a history jumps, so its last stage (at the step's end) reads the history
    just before the jump. See :func:`_radau_steps`, of which this is the case of one step.
    """
    modes, known = _radau_steps(kernel, problem, t0, np.array([float(h)]), s_modes, s_known,
                                before_jump=np.array([before_jump]))
    return modes[0], known[0]


def _radau_steps(kernel, problem: ModalProblem, t0: float, hs: np.ndarray,
                 s_modes: np.ndarray, s_known: np.ndarray, *,
                 before_jump: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Radau IIA steps of lengths ``hs`` (B,), all from ``t0`` and the same states, at once.

    Returns the new states, (B, modes, states) and (B, known, states); see
    :func:`_stage_values` for ``before_jump`` and :func:`_advance` for the step.
    """
    hs = np.asarray(hs, dtype=float)
    stages = _stage_values(kernel, problem, np.full(hs.size, float(t0)), hs, before_jump)
    new_modes, new_known, _, _ = _advance(stages, problem.coupling, s_modes, s_known)
    return new_modes, new_known


def _advance(stages: _Stages, coupling: np.ndarray, s_modes: np.ndarray,
             s_known: np.ndarray, keep: int | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The Radau IIA steps ``stages`` from the states ``s_modes`` (modes, states) and
    ``s_known`` (known, states).

    Returns the new states of the first ``keep`` steps (all: None), (keep, modes, states)
    and (keep, known, states), and the sums over the states (``V w``, ``V u``) at the end
    of every step, (B, modes) and (B, known): a step that only reports (a side step to an
    output time, the full step of step doubling) needs no more than these.

    The states of one channel couple only through their sum ``V w``: a state obeys
    ``S_s' = -decay_s S_s + beta_s(t) z(t)`` with ``z = (r + V w)/d`` shared by all of them.
    Eliminating the states, whose stage operator ``I + h decay_s A`` is the same for every
    mode, leaves one 3x3 system in the stage values of ``z`` per mode: a step costs
    O(modes) small operations instead of a (3 states)^2 solve per mode.
    """
    hs, beta, decay = stages.hs, stages.beta, stages.decay
    n_steps = hs.size
    # inv(I + x A), x = h decay_s, for every step and state, by the adjugate (module
    # constants): (I + x P1 + x^2 P2) / det(x), det with positive coefficients
    x = np.minimum(hs[:, None] * decay[None, :], _X_MAX)     # (B, states)
    x2 = x * x
    det = 1.0 + x * _DET[0] + x2 * _DET[1] + x2 * x * _DET[2]
    carry = (1.0 + x[..., None] * _P1_ROWS + x2[..., None] * _P2_ROWS) / det[..., None]
    # inv h A diag(beta_s): forcing of the stages of state s by z at the stages
    scaled = beta / det[..., None]                           # (B, states, 3)
    g0 = scaled.sum(axis=1)                                  # (B, 3)
    g1 = (x[:, None, :] @ scaled)[:, 0, :]
    g2 = (x2[:, None, :] @ scaled)[:, 0, :]
    h3 = hs[:, None, None]
    total = h3 * (RADAU_A[None] * g0[:, None, :] + _Q1[None] * g1[:, None, :]
                  + _Q2[None] * g2[:, None, :])              # (B, 3, 3): over the states
    last_carry = carry[:, :, 2]                              # (B, states): step's end
    last_drive = h3 * (RADAU_A[2] + x[..., None] * _Q1[2] + x2[..., None] * _Q2[2]) * scaled
    kept = slice(None) if keep is None else slice(0, keep)
    n_kept = len(range(n_steps)[kept])
    drive_sum = last_drive.sum(axis=1)                       # (B, 3)
    known_stage_sums = None
    if stages.u is None:  # no known channels: nothing to step
        new_known = np.zeros((n_kept,) + s_known.shape)
        known_sums = np.zeros((n_steps, s_known.shape[0]))
    else:
        # known channels: z = u, given
        u = stages.u                                         # (B, known, 3)
        known_stage_sums = s_known @ carry + u @ total.transpose(0, 2, 1)  # V u at stages
        new_known = (s_known[None] * last_carry[kept, None, :]
                     + u[kept] @ last_drive[kept].transpose(0, 2, 1))
        known_sums = last_carry @ s_known.T + (u @ drive_sum[:, :, None])[..., 0]
    if stages.d is None:  # no modes
        new_modes = np.zeros((n_kept,) + s_modes.shape)
        mode_sums = np.zeros((n_steps, s_modes.shape[0]))
    else:
        r = stages.r
        if known_stage_sums is not None:
            r = r + coupling[None] @ known_stage_sums
        # V w = d z - r at the stages, and V w = s @ carry + total z: solve for z
        z = _solve_stages(stages.d, total, s_modes @ carry + r)
        new_modes = (s_modes[None] * last_carry[kept, None, :]
                     + z[kept] @ last_drive[kept].transpose(0, 2, 1))
        mode_sums = last_carry @ s_modes.T + (z @ drive_sum[:, :, None])[..., 0]
    return new_modes, new_known, mode_sums, known_sums


def _solve_stages(d: np.ndarray, total: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve ``(diag(d[b, k]) - total[b]) z[b, k] = rhs[b, k]`` for every step b and mode k.

    ``d``, ``rhs`` (B, modes, 3), ``total`` (B, 3, 3). Cramer's rule over the arrays, which
    avoids a LAPACK call per system: the systems are well conditioned (``d >= 1`` on the
    diagonal, ``total`` the creep of one step), checked against the full stage system in
    tests/test_time_integration.py.
    """
    t = total[:, None]                                       # (B, 1, 3, 3)
    m00, m11, m22 = d[..., 0] - t[..., 0, 0], d[..., 1] - t[..., 1, 1], d[..., 2] - t[..., 2, 2]
    m01, m02, m10 = -t[..., 0, 1], -t[..., 0, 2], -t[..., 1, 0]
    m12, m20, m21 = -t[..., 1, 2], -t[..., 2, 0], -t[..., 2, 1]
    # the adjugate (cofactors, transposed) and the determinant by the first row; written
    # out entry by entry: gathering them with index tables was 5x slower on 6000 systems
    c00, c01, c02 = m11 * m22 - m12 * m21, m02 * m21 - m01 * m22, m01 * m12 - m02 * m11
    c10, c11, c12 = m12 * m20 - m10 * m22, m00 * m22 - m02 * m20, m02 * m10 - m00 * m12
    c20, c21, c22 = m10 * m21 - m11 * m20, m01 * m20 - m00 * m21, m00 * m11 - m01 * m10
    det = m00 * c00 + m01 * c10 + m02 * c20
    r0, r1, r2 = rhs[..., 0], rhs[..., 1], rhs[..., 2]
    return np.stack([c00 * r0 + c01 * r1 + c02 * r2, c10 * r0 + c11 * r1 + c12 * r2,
                     c20 * r0 + c21 * r1 + c22 * r2], axis=-1) / det[..., None]


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
    vw_out = np.zeros((nm, len(times)))
    vu_out = np.zeros((nk, len(times)))
    w_scale, u_scale = _scales(problem, float(times[-1]))
    scale = np.concatenate([w_scale, u_scale])
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

    k_out = 0
    while k_out < len(times) and times[k_out] <= 1.0:
        record(k_out, s_modes.sum(axis=1), s_known.sum(axis=1))
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
        diff = np.concatenate([np.abs(fine_vw[0] - batch_vw[1]),
                               np.abs(fine_vu[0] - batch_vu[1])]) / scale
        # Richardson: the two-half-step answer carries 1/(2^p - 1) of the difference.
        err = float(np.max(diff, initial=0.0)) / (2**RADAU_ORDER - 1)
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
        total_error += err
        steps += 1
        while k_out < len(times) and abs(times[k_out] - t_now) <= 1e-12 * max(1.0, t_now):
            record(k_out, fine_vw[0], fine_vu[0])
            k_out += 1
        grow = 4.0 if err == 0 else min(4.0, max(0.5, 0.9 * (allowed / err) ** (
            1 / (RADAU_ORDER + 1))))
        h = h_try * grow
    est = max(total_error, 1e-15)
    return VolterraSolution(finish(), vw_out, vu_out, est, steps, rejected, True, "ok")


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
