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
  (O(steps^2) per mode, as any method for a general kernel must be).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

TimeFunction = Callable[[np.ndarray], np.ndarray]

_S6 = np.sqrt(6.0)
RADAU_C = np.array([(4 - _S6) / 10, (4 + _S6) / 10, 1.0])
RADAU_A = np.array([
    [(88 - 7 * _S6) / 360, (296 - 169 * _S6) / 1800, (-2 + 3 * _S6) / 225],
    [(296 + 169 * _S6) / 1800, (88 + 7 * _S6) / 360, (-2 - 3 * _S6) / 225],
    [(16 - _S6) / 36, (16 + _S6) / 36, 1 / 9],
])
RADAU_ORDER = 5


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
                s_modes: np.ndarray, s_known: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One Radau IIA step of all channels. Returns the new mode and known-channel states.

    ``s_modes`` (modes, states), ``s_known`` (known, states).

    The states of one channel couple only through their sum ``V w``: a state obeys
    ``S_s' = -decay_s S_s + beta_s(t) z(t)`` with ``z = (r + V w)/d`` shared by all of them.
    Eliminating the states, whose stage operator ``I + h decay_s A`` is the same for every
    mode, leaves one 3x3 system in the stage values of ``z`` per mode: the step costs
    O(modes) small operations instead of a (3 states)^2 solve per mode.
    """
    ts = t0 + RADAU_C * h
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
                     max_steps: int = 20000) -> VolterraSolution:
    """Solve ``problem`` at ``times`` (increasing, >= 1) for a degenerate kernel.

    ``kernel`` has ``rates``, ``tau_part(tau)`` and ``exponential_parts(tau)`` (see
    :class:`core.creep.DegenerateKernel`). ``tol`` bounds the global error relative to the
    size of the unknowns. The main steps are chosen for accuracy alone; an output time
    inside a step is reached by a separate, shorter side step from the step's start (its
    error is below that of the accepted step, so it needs no estimate of its own).
    """
    times = np.asarray(times, dtype=float)
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
            tt = np.array([t])
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
    while k_out < len(times):
        if steps + rejected > max_steps:
            # No answer is better than a wrong one: the times not reached are NaN.
            w_out[:, k_out:] = vw_out[:, k_out:] = vu_out[:, k_out:] = np.nan
            return VolterraSolution(w_out, vw_out, vu_out, np.inf, steps, rejected, False,
                                    f"time stepping stopped after {max_steps} steps at "
                                    f"t = {t_now:.6g}")
        h_try = min(h, t_final - t_now)
        full = _radau_step(kernel, problem, t_now, h_try, s_modes, s_known)
        half = _radau_step(kernel, problem, t_now, h_try / 2, s_modes, s_known)
        fine = _radau_step(kernel, problem, t_now + h_try / 2, h_try / 2, *half)
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
        t_next = t_now + h_try
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


def _trapezoid_solve(kernel: Callable, problem: ModalProblem,
                     grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Product trapezoid rule on ``grid`` (which starts at 1). Values on the grid."""
    n = len(grid)
    kmat = np.tril(np.asarray(kernel(grid[:, None], grid[None, :]), dtype=float))
    if not np.all(np.isfinite(kmat)):
        raise ValueError("kernel: returned non-finite values K(t, tau) for 1 <= tau <= t")
    nm, nk = problem.n_modes, problem.n_known
    vu = np.zeros((nk, n))
    if nk:
        u = problem.u(grid)
        for i in range(1, n):
            vu[:, i] = u[:, : i + 1] @ (kmat[i, : i + 1] * _trapezoid_weights(grid, i))
    w = np.zeros((nm, n))
    vw = np.zeros((nm, n))
    if nm:
        d = problem.d(grid)
        r = problem.r(grid) + (problem.coupling @ vu if nk else 0.0)
        w[:, 0] = r[:, 0] / d[:, 0]
        for i in range(1, n):
            kw = kmat[i, : i + 1] * _trapezoid_weights(grid, i)
            hist = w[:, :i] @ kw[:i]
            w[:, i] = (r[:, i] + hist) / (d[:, i] - kw[i])
            vw[:, i] = hist + kw[i] * w[:, i]
    return w, vw, vu


def solve_general(kernel: Callable, problem: ModalProblem, times: np.ndarray, *, tol: float,
                  max_points: int = 4097) -> VolterraSolution:
    """Same problem as :func:`solve_degenerate` for any vectorized kernel ``K(t, tau)``.

    Trapezoid product quadrature on a grid containing every output time, refined by
    halving; Richardson extrapolation of the last two grids gives the answer and their
    difference the error estimate.
    """
    times = np.asarray(times, dtype=float)
    anchors = np.unique(np.concatenate([[1.0], times]))
    span = max(anchors[-1] - 1.0, 1e-300)
    sub = np.maximum(1, np.ceil(np.diff(anchors) / (span / 16)).astype(int))
    w_scale, u_scale = _scales(problem, float(anchors[-1]))
    previous = None
    previous_extrapolated = None
    while True:
        grid = np.concatenate([[anchors[0]]] + [
            np.linspace(a, b, s + 1)[1:] for a, b, s in zip(anchors[:-1], anchors[1:], sub,
                                                           strict=True)])
        idx = np.searchsorted(grid, times)
        w, vw, vu = _trapezoid_solve(kernel, problem, grid)
        current = (w[:, idx], vw[:, idx], vu[:, idx])
        if previous is not None:
            # Error c h^2 + d h^4: (4 fine - coarse)/3 removes the h^2 term.
            extrapolated = tuple((4 * c - p) / 3 for c, p in zip(current, previous,
                                                                 strict=True))
            if previous_extrapolated is not None:
                # Two extrapolations differ by 15x the finer one's O(h^4) error.
                err_w = (float(np.max(np.abs(extrapolated[0] - previous_extrapolated[0])
                                      / w_scale[:, None])) if problem.n_modes else 0.0)
                err_u = (float(np.max(np.abs(extrapolated[2] - previous_extrapolated[2])
                                      / u_scale[:, None])) if problem.n_known else 0.0)
                est = max(err_w, err_u) / 15
                if est <= tol or 2 * len(grid) > max_points:
                    ok = est <= tol
                    message = "ok" if ok else (
                        f"general-kernel time stepping reached {len(grid)} points with "
                        f"estimated error {est:.1e}")
                    return VolterraSolution(*extrapolated, max(est, 1e-15), len(grid) - 1,
                                            0, ok, message)
            previous_extrapolated = extrapolated
        previous = current
        sub = sub * 2
