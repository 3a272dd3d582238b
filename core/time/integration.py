"""Scalar Volterra equations of the modes, solved in time.

After the modal decomposition (:mod:`core.problem.statements`) every mode ``w_k`` obeys

    d_k(t) w_k(t) - (V w_k)(t) = r_k(t) + sum_j C_kj (V u_j)(t),     t >= 1,
    (V f)(t) = int_1^t K(t, tau) f(tau) dtau,

with ``d_k(t) = 1 + c(t)/gamma_k >= 1`` and a few *known* functions ``u_j(t)`` (the given
force and moment, ``1/c``) whose creep history also drives the modes. Keeping ``V u`` as
a coupling term, rather than substituting ``w = z + u/gamma``, avoids a cancellation that
loses ``log10(c/gamma)`` digits in the modes of small eigenvalue ``gamma``.

The requested times are outputs, not the step: each solver chooses its own steps and
meets ``tol`` at them.

* :func:`solve_degenerate` for ``K(t, tau) = b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))``
  (every shipped creep model, every fitted kernel). ``V f`` is the sum of states
  ``S_0' = b f`` and ``S_r' = -rate_r S_r + a_r f``, so each mode is a small linear ODE.
  By default it is stepped by exponential collocation (:mod:`core.time.exponential`:
  the exponentials integrated exactly, grids fixed in advance and refined as a whole,
  all steps' factors computed at once); where that would need more than a share of the
  step limit (:data:`EXPONENTIAL_SHARE`), and with ``method="radau"`` (the reference),
  by the 3-stage Radau IIA collocation method (order 5, L-stable), all modes at once,
  O(1) work per mode and step. The known channels are stepped first; the modes then see
  their stage values (the coupled system is block triangular, so this is the exact Radau
  step of the whole system). Step sizes come from step-doubling error estimates; a step
  may spend its share of the time or of the log-time since loading
  (:data:`LOG_TIME_BUDGET`) or of the steps (:data:`STEP_BUDGET`), whichever is largest.
  A step, both its halves and the side steps to the output times inside it read the
  kernel and the histories once (the batched step itself is :mod:`core.time.radau`).
* :func:`solve_general` (:mod:`core.time.product_quadrature`) for any vectorized
  ``K(t, tau)``: product trapezoid rule on grids containing every requested time, halved
  until the Richardson estimate meets ``tol``.

The problem and solution types are in :mod:`core.time.volterra`.

Both accept ``breaks``: times where a given history (a load) jumps or kinks. The steps
(or grid points) fall exactly on them, and the history is read on the proper side of
each: a step that ends at a jump reads the value just before it, the next one starts
after it. Without them a step straddles the jump and the step-doubling estimate, which
assumes a smooth history, can read far too low.
"""

from __future__ import annotations

import numpy as np

from core import limits
from core.time.exponential import solve_exponential
from core.time.radau import RADAU_ORDER, _advance, _stage_values
from core.time.volterra import ModalProblem, VolterraSolution, _after, _jumps, _scales
from core.work import check_work

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
#: exponential's transient (tests/engines/test_hard_cases.py) leave 2.6e-11 at 28 relaxation
#: times, where its closed form holds to 7e-13 (100: 3.7e-13).
LOG_TIME_BUDGET = 100.0
#: Each of the first STEP_BUDGET steps may spend at least 1/STEP_BUDGET of the error
#: budget (so this share adds at most one budget): the optimum for the sum of local errors
#: is an equal error per step, which a run of a few hundred steps then nearly has.
#: Measured on the 50-year fib MC2010 preset: 193 -> 147 steps (400: 163, 100: 134); the
#: stiff exponential's closed form (tests/engines/test_hard_cases.py) held to 4.6e-13.
STEP_BUDGET = 200


def solve_degenerate(kernel, problem: ModalProblem, times: np.ndarray, *, tol: float,
                     max_steps: int = limits.MAX_TIME_STEPS, breaks=(),
                     method: str = "exponential") -> VolterraSolution:
    """Solve ``problem`` at ``times`` (increasing, >= 1) for a degenerate kernel.

    ``kernel`` has ``rates``, ``tau_part(tau)`` and ``exponential_parts(tau)`` (see
    :class:`core.creep.models.DegenerateKernel`). ``tol`` bounds the global error relative to the
    size of the unknowns. The main steps are chosen for accuracy alone; an output time
    inside a step is reached by a separate, shorter side step from the step's start (its
    error is below that of the accepted step, so it needs no estimate of its own).
    ``breaks``: times (same unit as ``times``) where ``d``, ``r`` or ``u`` jump or kink;
    every step ends on each of them, and an output time on one reports the value after
    the jump. At most ``max_steps`` steps (accepted and rejected) are taken; then the
    times not reached are NaN and the message says which limit stopped it.

    ``method``: ``"exponential"`` (default) tries the exponential collocation of
    :mod:`core.time.exponential` (exact for the kernel's exponentials, steps fixed in
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
        check_work("stepping the creep in time")
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
