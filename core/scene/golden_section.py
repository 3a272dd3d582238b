"""Golden-section search for the smallest value of a function of one variable."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np


def golden_minimum(fn: Callable[[float], float], lo: float, hi: float,
                    iterations: int = 60) -> float:
    """Smallest value of ``fn`` met by a golden-section search on ``[lo, hi]``.

    ``fn`` is called ``iterations + 2`` times; for a unimodal ``fn`` the bracket shrinks
    by the golden ratio each time, otherwise the result is the least value met.
    """
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    c = hi - ratio * (hi - lo)
    d = lo + ratio * (hi - lo)
    fc, fd = fn(c), fn(d)
    best = min(fc, fd)
    for _ in range(iterations):
        if fc < fd:
            hi, d, fd = d, c, fc
            c = hi - ratio * (hi - lo)
            fc = fn(c)
        else:
            lo, c, fc = c, d, fd
            d = lo + ratio * (hi - lo)
            fd = fn(d)
        best = min(best, fc, fd)
    return best


def golden_minimum_batched(fn: Callable[[np.ndarray], np.ndarray], lo: float, hi: float,
                           iterations: int = 60, depth: int = 5) -> float:
    """:func:`golden_minimum` with a vectorized ``fn``: the same points, fewer calls.

    Where a golden-section step goes next depends only on which of its two comparisons
    came out true, not on the values, so the points of the next ``depth`` steps along
    every possible path (``2**depth - 1`` of them) are known in advance: one call of
    ``fn`` on all of them, then the steps are walked with those values. The points met
    and the result are those of the one-at-a-time search (``fn`` elementwise); ``fn`` is
    called ``2 + ceil(iterations / depth)`` times instead of ``iterations + 2``.
    """
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    c = hi - ratio * (hi - lo)
    d = lo + ratio * (hi - lo)
    fc = float(fn(np.array([c]))[0])
    fd = float(fn(np.array([d]))[0])
    best = min(fc, fd)
    left = iterations
    while left > 0:
        steps = min(depth, left)
        # the tree of states: node k's children are 2k + 1 (fc < fd) and 2k + 2
        states = [(lo, hi, c, d)]
        points = []
        for k in range(2 ** steps - 1):
            s_lo, s_hi, s_c, s_d = states[k]
            # as golden_minimum: moving left, then right
            new_hi = s_d
            new_c = new_hi - ratio * (new_hi - s_lo)
            new_lo = s_c
            new_d = new_lo + ratio * (s_hi - new_lo)
            states.append((s_lo, new_hi, new_c, s_c))
            states.append((new_lo, s_hi, s_d, new_d))
            points += [new_c, new_d]
        values = np.asarray(fn(np.array(points)), dtype=float)
        k = 0
        for _ in range(steps):
            if fc < fd:
                fd, fc = fc, float(values[2 * k])
                k = 2 * k + 1
            else:
                fc, fd = fd, float(values[2 * k + 1])
                k = 2 * k + 2
            best = min(best, fc, fd)
        lo, hi, c, d = states[k]
        left -= steps
    return best
