"""Scalar Volterra equations of the modes, solved in time.

After the modal decomposition (:mod:`core.statements`) every mode obeys

    d(t) w(t) - (V w)(t) = r(t),      (V w)(t) = int_1^t K(t, tau) w(tau) dtau,   t >= 1,

with ``d(t) = 1 + c(t)/gamma >= 1`` (one equation per mode, many modes at once), and the
known rows need ``V u`` for a few known functions ``u(t)``. The requested times are
outputs, not the step: each solver chooses its own steps and meets ``tol`` at them.

* :func:`solve_degenerate` — for ``K(t, tau) = b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))``
  (every shipped creep model). ``V w`` is the sum of states ``S_0' = b w`` and
  ``S_r' = -rate_r S_r + a_r w``, so each mode is a small linear ODE. It is stepped by the
  3-stage Radau IIA collocation method (order 5, L-stable, so a fast, stiff exponential
  costs nothing extra), all modes at once, each step O(1) per mode. Step size from
  step-doubling error estimates, error per unit step.
* :func:`solve_general` — any vectorized ``K(t, tau)``: product trapezoid rule on grids
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
class VolterraSolution:
    """Solution at the output times.

    ``w`` and ``vw`` (= ``V w``) have shape (modes, times); ``vu`` (known functions, times).
    ``error_estimate`` bounds the error of ``vw`` relative to ``max|w|`` (and of ``vu``
    relative to ``max|u|``); ``steps`` counts accepted steps.
    """

    w: np.ndarray
    vw: np.ndarray
    vu: np.ndarray
    error_estimate: float
    steps: int
    rejected: int
    message: str


def _stage_matrices(kernel, t_stage: np.ndarray, d: np.ndarray, unknown: bool) -> tuple:
    """Per-stage ODE matrices ``A_j`` and forcing factors for every channel.

    ``d`` (channels, stages). Returns ``beta`` (states, stages) and the system matrices
    (channels, stages, states, states).
    """
    rates = np.asarray(kernel.rates, dtype=float)
    beta = np.concatenate([kernel.tau_part(t_stage)[None, :],
                           kernel.exponential_parts(t_stage).reshape(len(rates), -1)], axis=0)
    decay = np.concatenate([[0.0], rates])
    ns = len(decay)
    base = -np.diag(decay)
    if unknown:
        # A = -diag(decay) + (beta / d) 1^T
        mats = base[None, None] + (beta.T[None, :, :, None] / d[:, :, None, None]) * np.ones(ns)
    else:
        mats = np.broadcast_to(base, (d.shape[0], len(t_stage), ns, ns))
    return beta, mats


def _radau_step(kernel, t0: float, h: float, s0: np.ndarray, d_fn, r_fn, u_fn,
                n_unknown: int) -> tuple[np.ndarray, np.ndarray]:
    """One Radau IIA step for all channels. Returns the new states and stage values of w.

    ``s0`` (channels, states); the first ``n_unknown`` channels are unknown modes
    (``w = (r + sum S)/d``), the rest known functions (``w = u``).
    """
    ts = t0 + RADAU_C * h
    nch, ns = s0.shape
    blocks = []
    forcing = []
    wfac = []
    if n_unknown:
        d = d_fn(ts)  # (modes, 3)
        r = r_fn(ts)
        beta, mats = _stage_matrices(kernel, ts, d, True)
        blocks.append(mats)
        forcing.append(beta.T[None] * (r / d)[:, :, None])  # (modes, 3, states)
        wfac.append((d, r))
    if nch > n_unknown:
        u = u_fn(ts)  # (known, 3)
        beta, mats = _stage_matrices(kernel, ts, np.ones_like(u), False)
        blocks.append(mats)
        forcing.append(beta.T[None] * u[:, :, None])
    mats = np.concatenate(blocks, axis=0)  # (channels, 3, ns, ns)
    f = np.concatenate(forcing, axis=0)  # (channels, 3, ns)
    big = np.zeros((nch, 3 * ns, 3 * ns))
    eye = np.eye(ns)
    for i in range(3):
        for j in range(3):
            big[:, i * ns:(i + 1) * ns, j * ns:(j + 1) * ns] = (
                (eye if i == j else 0.0) - h * RADAU_A[i, j] * mats[:, j])
    rhs = np.repeat(s0[:, None, :], 3, axis=1) + h * np.einsum("ij,cjs->cis", RADAU_A, f)
    y = np.linalg.solve(big, rhs.reshape(nch, 3 * ns, 1)).reshape(nch, 3, ns)
    return y[:, 2, :].copy(), y


def solve_degenerate(kernel, times: np.ndarray, d_fn: TimeFunction, r_fn: TimeFunction,
                     u_fn: TimeFunction | None, n_unknown: int, n_known: int, *,
                     tol: float, max_steps: int = 20000) -> VolterraSolution:
    """Solve ``d w - V w = r`` (``n_unknown`` modes) and compute ``V u`` (``n_known``).

    ``d_fn(t)``, ``r_fn(t)`` return arrays (modes, len(t)); ``u_fn(t)`` (known, len(t)).
    ``tol`` is the target for the global error relative to the size of ``w`` and ``u``.
    """
    times = np.asarray(times, dtype=float)
    ns = 1 + len(kernel.rates)
    nch = n_unknown + n_known
    state = np.zeros((nch, ns))
    t_now = 1.0
    w_out = np.zeros((n_unknown, len(times)))
    vw_out = np.zeros((n_unknown, len(times)))
    vu_out = np.zeros((n_known, len(times)))

    # Scales for the error norm: sizes of the unknowns and of the known functions.
    probe = np.linspace(1.0, times[-1], 9)
    w_scale = 1.0
    if n_unknown:
        w_scale = float(np.max(np.abs(r_fn(probe) / d_fn(probe)))) or 1.0
    u_scale = np.ones(n_known)
    if n_known:
        u_scale = np.maximum(np.max(np.abs(u_fn(probe)), axis=1), 1e-300)
    scale = np.concatenate([np.full(n_unknown, w_scale), u_scale])[:, None]
    span = max(times[-1] - 1.0, 1e-300)
    local_tol = 0.1 * tol

    def record(k: int, t: float, s: np.ndarray) -> None:
        sums = s.sum(axis=1)
        if n_unknown:
            tt = np.array([t])
            d = d_fn(tt)[:, 0]
            r = r_fn(tt)[:, 0]
            w = (r + sums[:n_unknown]) / d
            w_out[:, k] = w
            vw_out[:, k] = sums[:n_unknown]
        if n_known:
            vu_out[:, k] = sums[n_unknown:]

    k_out = 0
    while k_out < len(times) and times[k_out] <= 1.0:
        record(k_out, 1.0, state)
        k_out += 1
    h = min(span / 50.0, 0.1) if span > 0 else 0.0
    total_error = 0.0
    steps = rejected = 0
    last_free_h = h
    while k_out < len(times):
        if steps + rejected > max_steps:
            return VolterraSolution(w_out, vw_out, vu_out, np.inf, steps, rejected,
                                    f"time stepping stopped after {max_steps} steps")
        target = times[k_out]
        h_try = min(h, target - t_now)
        forced = h_try < target - t_now or h_try < 0.5 * h
        if h_try < 0.5 * last_free_h and h_try < h:
            # An output time forces a step much shorter than an accepted one: its error is
            # below the last estimate by (h_try/h)^6, so no new estimate is needed.
            s_new, _ = _radau_step(kernel, t_now, h_try, state, d_fn, r_fn, u_fn, n_unknown)
            err = 0.0
        else:
            s_full, _ = _radau_step(kernel, t_now, h_try, state, d_fn, r_fn, u_fn, n_unknown)
            s_half, _ = _radau_step(kernel, t_now, h_try / 2, state, d_fn, r_fn, u_fn,
                                    n_unknown)
            s_new, _ = _radau_step(kernel, t_now + h_try / 2, h_try / 2, s_half, d_fn, r_fn,
                                   u_fn, n_unknown)
            diff = np.abs(s_new.sum(axis=1) - s_full.sum(axis=1))[:, None] / scale
            err = float(np.max(diff)) / (2**RADAU_ORDER - 1)
            allowed = local_tol * max(h_try / span, 1e-3)
            if err > allowed and h_try > 1e-12 * span:
                rejected += 1
                h = h_try * max(0.2, 0.9 * (allowed / err) ** (1 / RADAU_ORDER))
                continue
            factor = 4.0 if err == 0 else min(4.0, max(0.2, 0.9 * (allowed / err) ** (
                1 / RADAU_ORDER)))
            if not forced or h_try >= h:
                h = h_try * factor
                last_free_h = h_try
        state = s_new
        t_now = t_now + h_try
        total_error += err
        steps += 1
        if abs(t_now - target) <= 1e-13 * max(1.0, target):
            t_now = target
            record(k_out, t_now, state)
            k_out += 1
    est = max(total_error, 1e-15)
    return VolterraSolution(w_out, vw_out, vu_out, est, steps, rejected, "ok")


def _trapezoid_solve(kernel: Callable, grid: np.ndarray, d_fn, r_fn, u_fn, n_unknown: int,
                     n_known: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Product trapezoid rule on ``grid`` (which starts at 1). Values on the grid."""
    n = len(grid)
    h = np.diff(grid)
    kmat = np.tril(np.asarray(kernel(grid[:, None], grid[None, :]), dtype=float))
    w = np.zeros((n_unknown, n))
    vw = np.zeros((n_unknown, n))
    d = d_fn(grid) if n_unknown else None
    r = r_fn(grid) if n_unknown else None
    if n_unknown:
        w[:, 0] = r[:, 0] / d[:, 0]
    for i in range(1, n):
        # weights of int_1^{t_i}: h_1/2, (h_j + h_{j+1})/2, ..., h_i/2
        om = np.empty(i + 1)
        om[0] = h[0] / 2
        om[1:i] = (h[: i - 1] + h[1:i]) / 2
        om[i] = h[i - 1] / 2
        kw = kmat[i, : i + 1] * om
        if n_unknown:
            hist = w[:, :i] @ kw[:i]
            w[:, i] = (r[:, i] + hist) / (d[:, i] - kw[i])
            vw[:, i] = hist + kw[i] * w[:, i]
    vu = np.zeros((n_known, n))
    if n_known:
        u = u_fn(grid)
        for i in range(1, n):
            om = np.empty(i + 1)
            om[0] = h[0] / 2
            om[1:i] = (h[: i - 1] + h[1:i]) / 2
            om[i] = h[i - 1] / 2
            vu[:, i] = u[:, : i + 1] @ (kmat[i, : i + 1] * om)
    return w, vw, vu


def solve_general(kernel: Callable, times: np.ndarray, d_fn: TimeFunction, r_fn: TimeFunction,
                  u_fn: TimeFunction | None, n_unknown: int, n_known: int, *, tol: float,
                  max_points: int = 4097) -> VolterraSolution:
    """Same problem as :func:`solve_degenerate` for any vectorized kernel ``K(t, tau)``.

    Trapezoid product quadrature on a grid containing every output time, refined by
    halving; Richardson extrapolation of the last two grids gives the answer and the
    difference of the two the error estimate.
    """
    times = np.asarray(times, dtype=float)
    anchors = np.unique(np.concatenate([[1.0], times]))
    span = max(anchors[-1] - 1.0, 1e-300)
    sub = np.maximum(1, np.ceil(np.diff(anchors) / (span / 16)).astype(int))
    previous = None
    w_scale = 1.0
    probe = np.linspace(1.0, anchors[-1], 9)
    if n_unknown:
        w_scale = float(np.max(np.abs(r_fn(probe) / d_fn(probe)))) or 1.0
    u_scale = (np.maximum(np.max(np.abs(u_fn(probe)), axis=1), 1e-300)[:, None]
               if n_known else None)
    message = "ok"
    est = np.inf
    steps = 0
    while True:
        grid = np.concatenate([[anchors[0]]] + [
            np.linspace(a, b, s + 1)[1:] for a, b, s in zip(anchors[:-1], anchors[1:], sub,
                                                           strict=True)])
        idx = np.searchsorted(grid, times)
        w, vw, vu = _trapezoid_solve(kernel, grid, d_fn, r_fn, u_fn, n_unknown, n_known)
        current = (w[:, idx], vw[:, idx], vu[:, idx])
        steps = len(grid) - 1
        if previous is not None:
            # The trapezoid error is c h^2 + O(h^4): halving h leaves a quarter of it, so the
            # difference of the last two grids is three times the error of the finer one.
            err_w = np.max(np.abs(current[1] - previous[1])) / 3 / w_scale if n_unknown else 0
            err_u = (np.max(np.abs(current[2] - previous[2]) / u_scale) / 3) if n_known else 0
            est = float(max(err_w, err_u))
            if est <= 0.1 * tol or 2 * len(grid) > max_points:
                if est > 0.1 * tol:
                    message = (f"general-kernel time stepping reached {len(grid)} points "
                               f"with estimated error {est:.1e}")
                return VolterraSolution(current[0], current[1], current[2], max(est, 1e-15),
                                        steps, 0, message)
        previous = current
        sub = sub * 2
