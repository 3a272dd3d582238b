"""Where a test measures q: the whole of [-1, 1], as the solver promises it."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def whole_interval(count: int, near: int = 20, farthest: float = 0.05,
                   jumps: Sequence[float] = ()) -> np.ndarray:
    """``count`` even points of [-1, 1] (dimensionless x), and ``near`` more toward each
    end and each side of every jump, geometric from 1e-10 to ``farthest`` away; sorted,
    none repeated. A jump itself is not among them unless an even point falls on it."""
    d = np.geomspace(1e-10, farthest, near)
    parts = [np.linspace(-1.0, 1.0, count), -1.0 + d, 1.0 - d]
    parts += [b + s * d for b in jumps for s in (-1.0, 1.0)]
    return np.unique(np.clip(np.concatenate(parts), -1.0, 1.0))
