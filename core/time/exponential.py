"""Exponential collocation of the modal Volterra equations: exact for the kernel's terms.

The modes of :mod:`core.time.integration` with a kernel
``K(t, tau) = b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))`` carry their memory in the
states ``S_s(t) = int_1^t beta_s(tau) exp(-decay_s (t - tau)) z(tau) dtau`` (``beta_0 = b``,
``decay_0 = 0``; ``beta_r = a_r``, ``decay_r = rate_r``), and over a step ``[t_n, t_n + h]``

    S_s(t_n + a h) = exp(-decay_s a h) S_s(t_n)
                     + int_0^{a h} exp(-decay_s (a h - sigma)) beta_s z (t_n + sigma) dsigma

holds exactly. Here ``beta_s z`` is replaced by its cubic interpolant at the four Lobatto
points of the step (``0, (5 -+ sqrt 5)/10, 1``) and the integral of each cubic against
the exponential is taken exactly (:mod:`core.time.exponential_weights`): the method is exact
for the exponential terms, however stiff, and its error is set by the smoothness of ``beta_s z``
(the modulus, the loads and the creep response), not by the kernel's rates. At
``decay_s = 0`` it is Lobatto IIIA collocation (order 6 at the step ends); for
``decay_s h >> 1`` the stage values tend to the quasi-static answer (no instability).

The value at a step's start is explicit (``d z = r + V w`` with ``V w`` the sum of the
states there), so a step solves one 3x3 system per mode for its three other points. The
steps are fixed before the march (graded geometrically in time from the start and from
every jump of a history, with a bound on their length), so every factor of every step
(kernel values, histories, exponential weights and the inverses of the 3x3 systems) is
computed for all steps at once and the march itself is a few array operations a step.
Output times inside a step are read from the sextic through its points and three of a
neighbouring step (dense output, :mod:`core.time.exponential_weights`), all at once.

The error is measured, not modelled: the march is repeated on grids with every step
halved (at least three, marched in one pass: :func:`march_grids`), and the estimate is
the difference of the last two answers at the output times over the convergence factor
the grids show, or the sum of the local errors of the states that decay within a step,
where larger. :func:`solve_exponential`
returns ``None`` when that takes more than its step budget (a history that oscillates
fast): the caller then steps adaptively (:mod:`core.time.radau`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from core.cache import StageCache, content_key, fingerprint
from core.time.exponential_modes import by_step, mode_march
from core.time.exponential_weights import (
    NODES,
    output_steps,
    output_weights_at,
    seven,
    sextic_weights,
    weights,
)
from core.time.radau import JUMP_SIDE
from core.work import check_work

#: Convergence order of the answers at output times used by the error estimate: the
#: stage order (4) of the collocation; at the step ends it is higher where the kernel's
#: rates times the step are small (measured in tests/time/test_time_integration.py).
ORDER = 4
#: Steps per decade of time since the start or a jump, and steps over the whole span,
#: of the first grid (each refinement doubles both).
STEPS_PER_DECADE = 3
SPAN_STEPS = 4
#: The first grid whose answer may be taken: three grids give two differences, whose
#: ratio is the measured convergence factor (see :func:`solve_exponential`).
MIN_LEVEL = 2
#: The first grids are as dense as STEPS_PER_DECADE and SPAN_STEPS say at this ``tol``
#: and ``(tol / DENSITY_TOL)**(1/6)`` times sparser at a looser one (at most 2x), so
#: that a loose tol is not met by grids far finer than it needs (three are marched).
#: Measured on the aging creep scene at tol 1e-6 (time tol 3.3e-8): at 3e-8 its finest
#: grid (46 steps) was 13x more accurate than asked (2.5e-9); at 3e-9 it takes 32 steps
#: and still meets the time tol on three grids (march 10.8 -> 9.0 ms CPU).
DENSITY_TOL = 3e-9
#: The point systems of the modes are built for blocks of steps of at most this many
#: floats (16 a step and mode: 8 MB), so a long march of many modes stays small.
MAX_BLOCK_ELEMENTS = 2**20
#: Marches of up to this many steps carry their local errors by one matrix product
#: (512^2 floats, 2 MB), longer ones step by step.
CARRY_MATRIX_STEPS = 512
#: Grid refinements tried before the caller's adaptive stepping takes over.
MAX_REFINEMENTS = 6


def grid(start: float, end: float, jumps: np.ndarray, first_step: float,
         level: int, density: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Step ends from ``start`` to ``end`` through every jump, and which start on a jump.

    In each piece ``[a, b]`` between jumps the steps are equal in the smooth, increasing
    ``sigma(t) = n_dec log10(1 + (t - a)/theta) + n_span (t - a)/span`` with
    ``n_dec = density STEPS_PER_DECADE 2**level``, ``n_span = density SPAN_STEPS
    2**level`` and ``theta = first_step``: graded geometrically from the piece's start
    (creep follows log time, and a jump starts a new transient), never longer than about
    ``span / n_span``. One level more halves every step in ``sigma`` exactly, so the
    answers of two levels converge like ``h**order`` and their difference estimates the
    error.
    """
    edges = np.concatenate([[start], jumps, [end]])
    span = end - start
    n_dec, n_span = (density * STEPS_PER_DECADE * 2**level, density * SPAN_STEPS * 2**level)
    slope = n_dec / np.log(10.0)
    points = [np.array([start])]
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        theta = min(first_step, b - a)

        def sigma(t, a=a, theta=theta):
            return slope * np.log1p((t - a) / theta) + n_span * (t - a) / span

        total = float(sigma(b))
        n = max(1, int(np.ceil(total)))
        target = total * np.arange(1, n) / n
        # invert sigma: start from the log part alone (below sigma's root), then Newton
        # (sigma is increasing and concave, so Newton from below stays below and converges)
        t = a + theta * np.expm1(np.minimum(target / slope, np.log1p((b - a) / theta)))
        t = np.minimum(t, b)
        for _ in range(50):
            step = (sigma(t) - target) / (slope / (theta + t - a) + n_span / span)
            t = t - step
            if np.all(np.abs(step) <= 1e-15 * np.maximum(1.0, np.abs(t))):
                break
        points += [np.sort(t), np.array([b])]
    ends = np.concatenate(points)
    jump_start = np.isin(ends[:-1], jumps)
    return ends, jump_start


#: The step grids of :func:`grid` met last (a geometry slider asks for the same ones).
GRIDS = StageCache("creep_time_grids", max_items=64, max_bytes=16 * 2**20)


def _kept_grid(start: float, end: float, jumps: np.ndarray, first_step: float,
               level: int, density: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`grid`, kept in :data:`GRIDS` (its arrays read-only)."""
    key = fingerprint(float(start), float(end), np.asarray(jumps, dtype=float),
                      float(first_step), int(level), float(density))
    return GRIDS.get_or_compute(key, lambda: grid(start, end, jumps, first_step, level,
                                                  density))[0]


@dataclass(frozen=True)
class LocalErrorFactors:
    """What the local errors of one grid's steps read of the kernel alone
    (:func:`local_error_factors`): ``side`` (B,) the neighbour of each step's sextic,
    ``drive`` (B, 7) the fast states' sextic-minus-cubic weights, ``step_of`` (T,) the
    step of each output time, ``carry`` (B, B) the carrying of a step's error to the later
    steps (None for a march longer than :data:`CARRY_MATRIX_STEPS`)."""

    side: np.ndarray
    drive: np.ndarray
    step_of: np.ndarray
    carry: np.ndarray | None


def local_error_factors(ends: np.ndarray, jump_start: np.ndarray, decay: np.ndarray,
                        beta: np.ndarray, end_weight: np.ndarray,
                        t_out: np.ndarray) -> LocalErrorFactors:
    """The kernel's part of :func:`_local_errors` on the steps ``ends``.

    A state that decays fast within a step forgets all but its last steps, so its error
    at a time is the local error of the steps just before it, which depends on where the
    time falls in them: two grids may then agree by chance (measured on a stiff aging
    kernel: 2.1e-9 on the finer grid, 8.9e-10 on the coarser, their difference 1.1e-9).
    Each step's error is estimated as the difference of its cubic from the sextic through
    its points and three of a neighbour (:func:`sextic_weights`).
    """
    h = np.diff(ends)
    n_steps = h.size
    steps = np.arange(n_steps)
    side, sextic, _ = sextic_weights(h, jump_start, decay, steps, np.ones(n_steps))
    cubic = np.zeros_like(sextic)
    own_last = side == -1
    cubic[~own_last, :, :4] = end_weight[~own_last]
    cubic[own_last, :, 3:] = end_weight[own_last]
    beta7 = seven(beta.transpose(0, 2, 1), steps, side)          # (B, 7, S)
    # A state slow over a step (decay h < 1) keeps its errors: they add up smoothly over
    # the steps, and the difference of two grids measures them (measured on the 50-year
    # fib MC2010 preset: that difference over 15 is 1.2-1.4x the true error at every
    # level). Only the states that forget within a step are counted here, their errors
    # summed over the states with their signs (the error of V w, their sum) and each
    # step's carried on with a decay of exp(-1) a step, the least of those states.
    fast = (decay[None, :] * h[:, None] >= 1.0)[:, :, None]      # (B, S, 1)
    drive = np.sum((sextic - cubic) * beta7.transpose(0, 2, 1) * fast, axis=1)  # (B, 7)
    # at the output times: an output inside a step is read from the points of that step
    # and of a neighbour (dense output), whose errors are those of their steps: the larger
    step_of = np.minimum(np.maximum(np.searchsorted(ends, t_out, side="left") - 1, 0),
                         n_steps - 1)
    # carried[b] = sum_{j < b} exp(-(b - 1 - j)) per_part[j], as one product for a march
    # of up to CARRY_MATRIX_STEPS steps (the loop a step costs more below that)
    carry = None
    if n_steps <= CARRY_MATRIX_STEPS:
        lag = np.subtract.outer(np.arange(n_steps), np.arange(n_steps)) - 1.0
        carry = np.where(lag >= 0.0, np.exp(-np.maximum(lag, 0.0)), 0.0)
    return LocalErrorFactors(side, drive, step_of, carry)


def _local_errors(factors: LocalErrorFactors,
                  channels: list[tuple[np.ndarray, np.ndarray]], parts: int) -> np.ndarray:
    """Sum of the steps' local errors at the output times, largest per group (parts,).

    Each step's error (``factors``: :func:`local_error_factors`) is carried to the output
    times (its absolute value: no cancelling between steps), relative to ``rows`` (the
    size of each channel), for each ``(values, rows)`` of ``channels`` (``values``
    (B, 4, C) at the points of the steps): the larger.
    """
    side, drive, step_of, carry = factors.side, factors.drive, factors.step_of, factors.carry
    n_steps = side.size
    steps = np.arange(n_steps)
    worst = np.zeros(parts)
    for values, rows in channels:
        values7 = seven(values, steps, side)                     # (B, 7, C)
        local = np.abs((drive[:, None, :] @ values7)[:, 0, :]) / rows  # (B, C)
        per_part = local.reshape(n_steps, parts, -1).max(axis=2)  # (B, P)
        if carry is not None:
            carried = carry @ per_part
        else:
            carried = np.zeros((n_steps, parts))
            for b in range(1, n_steps):
                carried[b] = carried[b - 1] * np.exp(-1.0) + per_part[b - 1]
        at_outputs = carried[step_of] + np.maximum(
            per_part[step_of], per_part[np.minimum(step_of + 1, n_steps - 1)])
        worst = np.maximum(worst, np.max(at_outputs, axis=0, initial=0.0))
    return worst


Grid = tuple[np.ndarray, np.ndarray, np.ndarray]
March = tuple[np.ndarray, np.ndarray, Callable[..., np.ndarray] | None]


def march(kernel, problem, ends: np.ndarray, jump_start: np.ndarray, jump_end: np.ndarray,
          times: np.ndarray, rows: tuple[np.ndarray, np.ndarray] | None = None) -> March:
    """``V w`` (modes, T) and ``V u`` (known, T) at ``times`` (in ``[ends[0], ends[-1]]``)
    by exponential collocation on the steps ``ends``.

    ``jump_start`` / ``jump_end`` (steps,) bools: that step starts (ends) where a history
    jumps, so its first (last) point reads the history after (before) it. With ``rows``
    (the sizes of the modes and of the known functions) the third answer computes, when
    called, the sum of the local errors per group of ``problem.parts``
    (:func:`_local_errors`; its optional argument, sizes measured after the march,
    replaces ``rows``); else it is None.
    """
    return march_grids(kernel, problem, [(ends, jump_start, jump_end)], times, rows)[0]


@dataclass(frozen=True)
class GridFactors:
    """What a march on some grids reads of the kernel alone: the same for every problem
    marched on them (every geometry and load under one creep law and output times).

    The steps of all grids one after the other (B steps, S kernel states, T outputs a
    grid): ``flat`` (4B,) the times of the steps' points, ``restart`` (B + 1,) where the
    states start at zero, ``first`` (grids + 1,) each grid's first step, ``jump_start``
    (B,), ``beta`` (B, S, 4) and ``decay`` (S,) the kernel's factors, ``total``
    (B, 3, 4), ``end_drive`` (B, 4, S), ``end_carry`` (B, S), ``end_weight`` (B, S, 4)
    and ``reads`` (B, S, 4) the step weights; ``step_of``, ``side``, ``out_total`` (GT,)
    the outputs' steps, neighbours and weights, ``order``, ``bounds`` and the sorted
    ``out_carry_s``, ``out_total_s`` the outputs in the order of their steps.
    ``local`` keeps each grid's :class:`LocalErrorFactors` once asked for.
    """

    ends_of: tuple[np.ndarray, ...]
    flat: np.ndarray
    restart: np.ndarray
    first: np.ndarray
    jump_start: np.ndarray
    beta: np.ndarray
    decay: np.ndarray
    total: np.ndarray
    end_drive: np.ndarray
    end_carry: np.ndarray
    end_weight: np.ndarray
    reads: np.ndarray
    step_of: np.ndarray
    side: np.ndarray
    out_total: np.ndarray
    order: np.ndarray
    in_order: bool
    bounds: np.ndarray
    out_carry_s: np.ndarray
    out_total_s: np.ndarray
    t_out: np.ndarray
    local: dict[int, LocalErrorFactors] = field(default_factory=dict, compare=False)

    def local_factors(self, g: int) -> LocalErrorFactors:
        """Grid ``g``'s :class:`LocalErrorFactors` (made at the first ask: the local
        errors are read on the grid whose answer is taken only)."""
        found = self.local.get(g)
        if found is None:
            steps = slice(self.first[g], self.first[g + 1])
            found = local_error_factors(self.ends_of[g], self.jump_start[steps], self.decay,
                                        self.beta[steps], self.end_weight[steps], self.t_out)
            self.local[g] = found  # two threads may both make it: the same value
        return found


def grid_factors(kernel, grids: list[Grid], times: np.ndarray) -> GridFactors:
    """The :class:`GridFactors` of ``grids`` (``(ends, jump_start, jump_end)``) and the
    output ``times`` under ``kernel``.

    Kept in :data:`GRID_FACTORS`, the kernel known by its content or as the same object
    (:func:`core.cache.content_key`): a geometry slider changes the modes but neither the
    kernel nor the steps, and these factors were ~40 % of a new geometry's march
    (measured on the 50-year fib MC2010 preset).
    """
    content, identity = content_key(kernel)
    key = (identity, fingerprint(content, [tuple(np.asarray(part) for part in g)
                                           for g in grids], np.asarray(times, dtype=float)))
    return GRID_FACTORS.get_or_compute(key, lambda: _grid_factors(kernel, grids, times))[0]


def _grid_factors(kernel, grids: list[Grid], times: np.ndarray) -> GridFactors:
    from core.time.radau import _kernel_factors

    # copies: the cached value's arrays are made read-only, not the caller's
    ends_of = tuple(np.array(g[0], dtype=float) for g in grids)
    counts = np.array([e.size - 1 for e in ends_of])
    first = np.concatenate([[0], np.cumsum(counts)])               # first step of each grid
    h = np.concatenate([np.diff(e) for e in ends_of])
    n_steps = h.size
    restart = np.zeros(n_steps + 1, dtype=bool)                    # states start at zero
    restart[first] = True
    jump_start = np.concatenate([np.asarray(g[1], dtype=bool) for g in grids])
    jump_end = np.concatenate([np.asarray(g[2], dtype=bool) for g in grids])
    # no neighbour across a jump or into another grid (dense output, local errors)
    apart = jump_start | restart[:-1]
    at = np.concatenate([e[:-1] for e in ends_of])[:, None] + h[:, None] * NODES[None, :]
    side = JUMP_SIDE * np.maximum(1.0, np.abs(at))
    at[:, 0] += np.where(jump_start, side[:, 0], 0.0)
    at[:, 3] -= np.where(jump_end, side[:, 3], 0.0)
    flat = at.ravel()
    beta, decay = _kernel_factors(kernel, flat)                   # (S, 4B), (S,)
    n_states = decay.size
    beta = beta.reshape(n_states, n_steps, 4).transpose(1, 0, 2)  # (B, S, 4)
    carry, weight = weights(NODES[1:], h, decay)                 # (B,S,3), (B,S,3,4)
    driven = weight * beta[:, :, None, :]                         # (B, S, 3, 4)
    total = driven.sum(axis=1)                                    # (B, 3, 4)
    end_drive = driven[:, :, 2, :].transpose(0, 2, 1).copy()      # (B, 4, S)
    end_carry = carry[:, :, 2]                                    # (B, S)
    end_weight = weight[:, :, 2, :]                               # (B, S, 4)
    # state sums at the step's points: ones for its start, carries for the others
    reads = np.concatenate([np.ones((n_steps, n_states, 1)), carry], axis=2)  # (B, S, 4)

    # the outputs of every grid, one grid after the other (G T outputs)
    t_out = np.asarray(times, dtype=float)
    placed = [output_steps(e, t_out) for e in ends_of]
    step_of = np.concatenate([s + f for (s, _), f in zip(placed, first[:-1], strict=True)])
    a = np.concatenate([a for _, a in placed])
    before_start = np.concatenate([t_out <= e[0] for e in ends_of])
    side, out_carry, out_total = output_weights_at(h, apart, beta, decay, step_of, a,
                                                   before_start)
    # the outputs in the order of their steps (already so for increasing times), so that
    # each step's outputs are one slice of rows
    order = np.argsort(step_of, kind="stable")
    in_order = bool(np.array_equal(order, np.arange(order.size)))
    bounds = np.searchsorted(step_of[order], np.arange(n_steps + 1))
    return GridFactors(ends_of, flat, restart, first, jump_start, beta, decay, total,
                       end_drive, end_carry, end_weight, reads, step_of, side, out_total,
                       order, in_order, bounds, out_carry[order], out_total[order], t_out)


#: The :class:`GridFactors` of the kernels and grids met last (LRU; cleared by
#: core.cache.clear_caches). A 50-year march of three grids holds ~0.3 MiB.
GRID_FACTORS = StageCache("creep_grid_factors", max_items=16, max_bytes=64 * 2**20)


def march_grids(kernel, problem, grids: list[Grid], times: np.ndarray,
                rows: tuple[np.ndarray, np.ndarray] | None = None) -> list[March]:
    """:func:`march` on each of ``grids`` (``(ends, jump_start, jump_end)``), in one pass.

    The steps of all grids are laid one after the other and every factor (kernel values,
    histories, weights, point systems, output weights) is formed for all of them at once;
    only the march itself restarts from zero states at each grid's first step. The
    answers are those of separate marches (a few fixed costs a call, ~0.9 ms of CPU
    measured on the aging scene, are paid once). The kernel's factors come from
    :func:`grid_factors` (kept across problems).
    """
    f = grid_factors(kernel, grids, times)
    flat, restart, first, step_of, side = f.flat, f.restart, f.first, f.step_of, f.side
    total, reads, end_drive, end_carry = f.total, f.reads, f.end_drive, f.end_carry
    order, bounds, out_carry_s, out_total_s = f.order, f.bounds, f.out_carry_s, f.out_total_s
    n_steps, n_states = flat.size // 4, f.decay.size
    n_out = f.t_out.size

    def read(fn) -> np.ndarray:
        return by_step(fn(flat), 4)                              # (B, channels, 4)

    nm, nk = problem.n_modes, problem.n_known
    channels: list[tuple[np.ndarray, int]] = []                  # (values, which size)
    vu_out = np.zeros((nk, step_of.size))
    vu_nodes = None
    if nk:
        u = read(problem.u)                                       # (B, K, 4)
        # V u at the points: the carried states plus the step's own drive
        vu_nodes = np.zeros_like(u)
        vu_nodes[:, :, 1:] = u @ total.transpose(0, 2, 1)
        next_drive = u @ end_drive                                # (B, K, S)
        # the known functions' states at each step's start (no solve: a carry and a
        # drive a step; zero at each grid's start), then read at the points and the
        # outputs all at once
        s_known = np.zeros((n_steps + 1, nk, n_states))
        for b in range(n_steps):
            if not restart[b + 1]:
                np.multiply(s_known[b], end_carry[b], out=s_known[b + 1])
                s_known[b + 1] += next_drive[b]
        vu_nodes += s_known[:-1] @ reads
        vu_out[:, order] = np.einsum("tks,ts->kt", s_known[step_of[order]], out_carry_s)
        vu_out += np.einsum("tj,tjk->kt", f.out_total, seven(u.transpose(0, 2, 1), step_of,
                                                              side))
        if rows is not None:
            channels.append((u.transpose(0, 2, 1), 1))
    vw_out = np.zeros((nm, step_of.size))
    if nm:
        # V w at the outputs, a row per output in the order of their steps
        vw_rows = np.empty((step_of.size, nm))
        carried, z_all = mode_march(problem, flat.reshape(n_steps, 4), total, reads,
                                    end_drive, end_carry, vu_nodes, MAX_BLOCK_ELEMENTS,
                                    restart[1:], read_at=(bounds, out_carry_s))
        # the outputs of each step: its carried states and the drive by z at its seven
        # points (the neighbour read, ``side``, is the same for all outputs of a step)
        for b in np.flatnonzero(bounds[1:] > bounds[:-1]):
            lo, hi = bounds[b], bounds[b + 1]
            sd = side[order[lo]]
            z7 = (np.concatenate([z_all[b - 1, :3], z_all[b]]) if sd == -1 else
                  np.concatenate([z_all[b], z_all[b + 1, 1:]]) if sd == 1 else
                  np.concatenate([z_all[b], np.zeros((3, nm))]))
            vw_rows[lo:hi] = carried[lo:hi] + out_total_s[lo:hi] @ z7
        if f.in_order:  # increasing times: as marched
            vw_out = vw_rows.T
        else:
            vw_out[:, order] = vw_rows.T
        if rows is not None:
            channels.append((z_all, 0))

    def answer(g: int) -> March:
        steps = slice(first[g], first[g + 1])
        columns = slice(g * n_out, (g + 1) * n_out)

        def local(sizes: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
            # ``sizes`` replace ``rows`` (sizes measured after the march)
            sizes = rows if sizes is None else sizes
            return _local_errors(f.local_factors(g),
                                 [(values[steps], sizes[which]) for values, which in channels],
                                 problem.parts)

        return (vw_out[:, columns], vu_out[:, columns],
                local if rows is not None else None)

    return [answer(g) for g in range(len(grids))]


def _largest_change(new: np.ndarray, old: np.ndarray) -> np.ndarray:
    """``max |new - old|`` along the times of each channel (channels, T) -> (channels,),
    with one temporary (the answers at 1000 outputs are 2.4 MB each)."""
    change = new - old
    np.abs(change, out=change)
    return np.max(change, axis=1, initial=0.0)


def first_step(kernel, start: float, span: float) -> float:
    """The length of the first step after a start or a jump: a tenth of the time scale of
    the fastest transient the kernel can drive (its rate plus its size, as ``d >= 1``),
    at least ``1e-9 span``."""
    from core.time.radau import _kernel_factors

    beta, decay = _kernel_factors(kernel, np.array([start]))
    fastest = float(np.max(decay + np.abs(beta[:, 0]), initial=0.0))
    return max(0.1 / fastest, 1e-9 * span) if fastest > 0 else span


def solve_exponential(kernel, problem, times: np.ndarray, jumps: np.ndarray, *, tol: float,
                      w_scale: np.ndarray, u_scale: np.ndarray, max_steps: int,
                      unknowns: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None):
    """``V w`` and ``V u`` at ``times`` to ``tol``, or None past ``max_steps`` steps.

    ``w_scale`` (modes,), ``u_scale`` (known,): sizes of the unknowns, for the relative
    error, measured per group of ``problem.parts``. ``unknowns(vw, vu)``: ``w`` at the
    times; when given, each group's error is measured against the largest ``|w|`` of the
    group on the first grid instead (at least a thousandth of ``w_scale``): the forcing
    behind ``w_scale`` can exceed the unknowns by the creep factor (6.9 measured on the
    inverse problem of tests/creep/test_creep.py). Returns ``(vw, vu, part_errors,
    steps)``: the answer of the finest grid marched, the estimate of its error per group
    and its steps. The estimate is the larger of the difference from the grid of twice
    longer steps over ``factor - 1`` (the global error, carried through the march), with
    ``factor`` the ratio of the last two such differences (the convergence as measured,
    within 2 and 2**7: a coarse first grid, far from the asymptotic rate, made the
    assumed ``2**ORDER`` 12x pessimistic on tests/engines/test_hard_cases.py's reversing load),
    and the sum of the steps' local errors (:func:`_local_errors`: a fast state's error,
    which two grids can miss).
    """
    start, end = 1.0, float(times[-1])
    span = end - start
    theta = first_step(kernel, start, span)
    density = float(np.clip((DENSITY_TOL / tol) ** (1 / 6), 0.5, 1.0))
    parts = problem.parts
    previous = last_change = None
    used = 0
    marched: list[tuple[int, March]] = []
    for level in range(MAX_REFINEMENTS + 1):
        check_work("refining the time steps of the creep")
        if not marched:
            # the first MIN_LEVEL + 1 grids (none of which can be taken alone) in one
            # pass, their fixed costs once; the refinements after them one at a time
            levels = range(level, MIN_LEVEL + 1) if level < MIN_LEVEL else [level]
            grids = []
            for lev in levels:
                ends, jump_start = _kept_grid(start, end, jumps, theta, lev, density)
                grids.append((ends, jump_start, np.isin(ends[1:], jumps)))
            used += sum(g[0].size - 1 for g in grids)
            if used > max_steps:
                return None
            marched = [(g[0].size - 1, answer) for g, answer in zip(
                grids, march_grids(kernel, problem, grids, times, rows=(w_scale, u_scale)),
                strict=True)]
        steps, (vw, vu, local) = marched.pop(0)
        if previous is None and unknowns is not None and problem.n_modes:
            size = np.max(np.abs(unknowns(vw, vu)).reshape(parts, -1), axis=1)
            given = w_scale.reshape(parts, -1)
            w_scale = np.clip(size[:, None], 1e-3 * given, given).ravel()
        if previous is not None:
            diff = np.concatenate([
                (_largest_change(vw, previous[0]) / w_scale).reshape(parts, -1),
                (_largest_change(vu, previous[1]) / u_scale).reshape(parts, -1)], axis=1)
            change = np.max(diff, axis=1, initial=0.0)
            # the ratio of the last two changes is the convergence factor of a step halving
            # as measured (2**ORDER until there are two), kept within 2 and 2**7
            factor = (np.clip(last_change / np.maximum(change, 1e-300), 2.0, 2.0**7)
                      if last_change is not None else np.full(parts, 2.0**ORDER))
            errors = change / (factor - 1.0)
            last_change = change
            if level >= MIN_LEVEL and np.max(errors) <= tol:
                # the local errors against the sizes as measured on the first grid
                errors = np.maximum(errors, local((w_scale, u_scale)))
                if np.max(errors) <= tol:
                    return vw, vu, errors, steps
        previous = (vw, vu)
    return None
