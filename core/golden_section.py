"""Golden-section search for the smallest value of a function of one variable."""

from __future__ import annotations

import math
from collections.abc import Callable


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
