"""Exact integrals of polynomials against exponentials: the weights of the exponential
collocation (:mod:`core.time.exponential`).

Over a step ``[t_n, t_n + h]`` a state decaying at rate ``decay`` gathers
``int exp(-decay (a h - sigma)) p(sigma / h) dsigma`` of a polynomial ``p`` through values
at points of the step: the cubic through the step's four Lobatto points (:data:`NODES`,
:func:`weights`) in the march, the sextic through those and three of a neighbouring step
for the output times (dense output, :func:`sextic_weights`, :func:`output_weights`). All
reduce to the moments ``mu_k(x) = int_0^1 exp(-x (1 - u)) u^k du`` (:func:`moments`),
computed without cancellation for every ``x >= 0``.
"""

from __future__ import annotations

import math

import numpy as np

_S5 = np.sqrt(5.0)
#: The Lobatto points of a step (fractions of its length).
NODES = np.array([0.0, (5 - _S5) / 10, (5 + _S5) / 10, 1.0])
# cubic Lagrange basis in monomials of the fraction u of the step: l_j(u) = sum_k L[j, k] u^k
_LAGRANGE = np.linalg.inv(np.vander(NODES, 4, increasing=True)).T
#: Below this ``x = decay h`` the moments come from their Taylor series (forward
#: recursion loses at most a factor 3.4 of accuracy above it for four powers, 11 for
#: seven); 24 terms leave 2^24 / 25! < 1e-17 of the series.
_SERIES_BELOW = 2.0
_SERIES_TERMS = 24
#: Powers of the moments: up to the sextic of the dense output (:func:`output_weights`).
_POWERS = 7
#: (largest x, terms) of the series: 0.02^8 / 9! and 0.3^14 / 15! are below 1e-19
_SERIES_GROUPS = ((0.02, 8), (0.3, 14), (_SERIES_BELOW, _SERIES_TERMS))
# k! / (n + k + 1)!: the Taylor coefficients of mu_k, (terms, powers)
_SERIES = np.array([[math.factorial(k) / math.factorial(n + k + 1) for k in range(_POWERS)]
                    for n in range(_SERIES_TERMS)])


def moments(x: np.ndarray, powers: int = 4) -> np.ndarray:
    """``mu_k(x) = int_0^1 exp(-x (1 - u)) u^k du`` for k < powers (at most 7), shape
    x.shape + (powers,).

    Taylor series ``sum_n (-x)^n k! / (n + k + 1)!`` for small x, else the recursion
    ``mu_0 = (1 - exp(-x))/x``, ``mu_k = (1 - k mu_{k-1}) / x`` (for x >= 2 it loses at
    most a factor ``6!/2^6 = 11`` of accuracy by k = 6).
    """
    x = np.asarray(x, dtype=float)
    out = np.empty(x.shape + (powers,))
    small = x < _SERIES_BELOW
    # the series in groups by size, each with the terms it needs (x^n / (n + 1)! < 1e-19)
    lower = -1.0
    for upper, terms in _SERIES_GROUPS:
        group = (x > lower) & (x <= upper) & small if lower >= 0 else (x <= upper) & small
        lower = upper
        xs = x[group]
        if not xs.size:
            continue
        # Horner in -x, all k at once
        acc = np.broadcast_to(_SERIES[terms - 1, :powers], (xs.size, powers)).copy()
        neg = -xs[:, None]
        for row in _SERIES[terms - 2::-1, :powers]:
            acc *= neg
            acc += row
        out[group] = acc
    xl = x[~small]
    if xl.size:
        mu = -np.expm1(-xl) / xl
        out[~small, 0] = mu
        for k in range(1, powers):
            mu = (1.0 - k * mu) / xl
            out[~small, k] = mu
    return out


def weights(fraction: np.ndarray, h: np.ndarray, decay: np.ndarray) -> tuple[np.ndarray,
                                                                                np.ndarray]:
    """Exponential weights of the step's cubic up to ``fraction`` of the step.

    ``fraction`` (..., A), ``h`` (...,) step lengths, ``decay`` (S,) rates. Returns
    ``carry = exp(-decay a h)`` (..., S, A) and ``weight`` (..., S, A, 4):
    ``int_0^{a h} exp(-decay (a h - sigma)) l_j(sigma/h) dsigma``.
    """
    ah = fraction * h[..., None]                                  # (..., A)
    x = decay[:, None] * ah[..., None, :]                         # (..., S, A)
    mu = moments(x)                                              # (..., S, A, 4 powers)
    powers = fraction[..., None, :, None] ** np.arange(1, 5)      # a^(k+1): (..., 1, A, 4)
    weight = h[..., None, None, None] * ((mu * powers) @ _LAGRANGE.T)  # (..., S, A, 4 nodes)
    return np.exp(-x), weight


def sextic_weights(h: np.ndarray, jump_start: np.ndarray, decay: np.ndarray,
                    step_of: np.ndarray, a: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weights of the seven points of step ``step_of`` and a neighbour for the integral
    from the step's start to ``a`` of it (see :func:`output_weights`).

    Returns ``side`` (T,): +1 the next step, -1 the previous, 0 none (then the step's
    cubic, its four weights first); ``weight`` (T, S, 7); ``x = decay a h`` (T, S).
    """
    n_steps = h.size
    hn = h[step_of]
    has_next = (step_of + 1 < n_steps) & ~jump_start[np.minimum(step_of + 1, n_steps - 1)]
    has_prev = (step_of >= 1) & ~jump_start[step_of]
    side = np.where(has_next, 1, np.where(has_prev, -1, 0))
    rho_next = h[np.minimum(step_of + 1, n_steps - 1)] / hn
    rho_prev = h[np.maximum(step_of - 1, 0)] / hn
    nodes = np.where(
        (side == 1)[:, None],
        np.concatenate([np.broadcast_to(NODES, (a.size, 4)),
                        1.0 + rho_next[:, None] * NODES[1:]], axis=1),
        np.concatenate([rho_prev[:, None] * (NODES[:3] - 1.0),
                        np.broadcast_to(NODES, (a.size, 4))], axis=1))
    plain = side == 0
    nodes[plain] = np.linspace(-1.0, 1.0, 7)                      # unused (cubic below)
    # the nodes depend on the step and the side only: one inverse per such pair
    _, first, which = np.unique(step_of * 3 + side + 1, return_index=True,
                                return_inverse=True)
    inv_vander = np.linalg.inv(nodes[first, :, None] ** np.arange(7))[which.ravel()]
    x = decay[None, :] * (a * hn)[:, None]                        # (T, S)
    mu = moments(x, 7) * (a[:, None, None] ** np.arange(1, 8))   # (T, S, 7 powers)
    weight = hn[:, None, None] * (mu @ inv_vander)                # (T, S, 7 nodes)
    if np.any(plain):
        _, cubic = weights(a[plain, None], hn[plain], decay)
        weight[plain] = 0.0
        weight[plain, :, :4] = cubic[:, :, 0, :]
    return side, weight, x


def output_weights(ends: np.ndarray, jump_start: np.ndarray, beta: np.ndarray,
                    decay: np.ndarray, t_out: np.ndarray):
    """How ``V`` at each output time is read from the march (dense output).

    An output at ``t_n + a h`` in step n carries the states from the step's start
    (``carry`` (T, S)) and integrates the sextic through the seven points of step n and
    of a neighbouring step (the next, else the previous where a jump separates them; the
    step's own cubic where both do) against the exponentials (``total`` (T, 7)). The
    sextic's error is far below the steps' own, so the answers at output times converge
    like those at the step ends, wherever the outputs fall in the steps (with the cubic
    they converged erratically, and their difference on two grids was no estimate).
    Returns ``step_of`` (T,), ``side`` (T,): +1 next, -1 previous, 0 none, and the two.
    """
    h = np.diff(ends)
    step_of, a = output_steps(ends, t_out)
    side, carry, total = output_weights_at(h, jump_start, beta, decay, step_of, a,
                                           t_out <= ends[0])
    return step_of, side, carry, total


def output_steps(ends: np.ndarray, t_out: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The step of each output time (T,) and its fraction ``a`` of that step (T,)."""
    h = np.diff(ends)
    # np.minimum / np.maximum: np.clip of integers costs ~7x more (numpy 2)
    step_of = np.minimum(np.maximum(np.searchsorted(ends, t_out, side="left") - 1, 0),
                         h.size - 1)
    return step_of, np.clip((t_out - ends[step_of]) / h[step_of], 0.0, 1.0)


def output_weights_at(h: np.ndarray, apart: np.ndarray, beta: np.ndarray, decay: np.ndarray,
                      step_of: np.ndarray, a: np.ndarray, before_start: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`output_weights` for outputs already placed in their steps (``step_of``, ``a``).

    ``h`` (B,) may hold the steps of several grids one after the other: ``apart`` (B,)
    marks the steps that take no neighbour before them (a jump, or the first step of a
    grid); ``before_start`` (T,) the outputs at or before their grid's start (no memory).
    Returns ``side``, ``carry`` (T, S) and ``total`` (T, 7).
    """
    side, weight, x = sextic_weights(h, apart, decay, step_of, a)
    beta7 = seven(beta.transpose(0, 2, 1), step_of, side)        # (T, 7, S)
    total = np.einsum("tsj,tjs->tj", weight, beta7)
    carry = np.exp(-x)
    carry[before_start] = 0.0
    total[before_start] = 0.0
    return side, carry, total


def seven(values: np.ndarray, step_of: np.ndarray, side: np.ndarray) -> np.ndarray:
    """Values at the four points of each output's step and three of its neighbour, in the
    order of :func:`output_weights` (``values`` (B, 4, ...); zeros for no neighbour)."""
    n_steps = values.shape[0]
    before = (side == -1)[:, None]
    # step and point of each of the seven slots: own 0..3 then next 1..3, or previous
    # 0..2 then own 0..3
    slot_step = np.where(before, step_of[:, None] + _PREVIOUS_STEP, step_of[:, None]
                         + _NEXT_STEP)
    slot_point = np.where(before, _PREVIOUS_POINT, _NEXT_POINT)
    picked = values[np.minimum(np.maximum(slot_step, 0), n_steps - 1), slot_point]  # (T, 7, ...)
    missing = (side == 0)[:, None] & (np.arange(7) >= 4)[None, :]
    if np.any(missing):
        picked[missing] = 0.0
    return picked


_NEXT_STEP = np.array([0, 0, 0, 0, 1, 1, 1])
_NEXT_POINT = np.array([0, 1, 2, 3, 1, 2, 3])
_PREVIOUS_STEP = np.array([-1, -1, -1, 0, 0, 0, 0])
_PREVIOUS_POINT = np.array([0, 1, 2, 0, 1, 2, 3])
