"""Jumps of a given history that its caller did not declare.

A time march that steps across a jump of a load loses its order, and worse, its error
estimate can miss it: with a force doubling at t = 4.3 and no ``time_breaks``, the
default engine answered at tol 1e-8 with an estimate of 4.2e-9 and a settlement 2e-4
off (the steps of all its grids straddled the jump alike). :func:`undeclared_jumps`
finds such jumps by sampling the history densely and bisecting every interval where it
changes abruptly, so that the march can land on them as on declared ones.

A jump is told from a steep smooth change by the bisection itself: across a jump the
change stays whole however short the interval, across a smooth rise it halves with the
interval once the interval is shorter than the rise. A pulse narrower than the samples'
spacing can fall between two samples: such times still have to be declared.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from core.time.radau import JUMP_SIDE

#: Samples of a history over its span, evenly and as many geometrically (dense after
#: loading, where load histories often change first).
JUMP_SAMPLES = 2049
#: An interval is bisected when its change exceeds this many times the smaller change of
#: its two neighbours (a smooth history changes alike from one sample to the next; a kink
#: passes this test only where its slope changes this much, and its bisection drops it).
ABRUPT_RATIO = 4.0
#: ... and this share of ``tol`` times the history's largest magnitude: a smaller jump
#: moves the answer by well below tol even where a step straddles it.
JUMP_TOL_SHARE = 1e-2
#: A bisected interval is kept while its change is at least this share of the change it
#: started with (a jump keeps all of it; a smooth change loses half at each halving once
#: the interval is shorter than the change).
KEPT_SHARE = 0.75
#: The bisection stops where the interval is this short relative to its time: the march
#: reads each side of a jump this far from it (:data:`core.time.JUMP_SIDE`).
JUMP_WIDTH = JUMP_SIDE
#: Halvings at most (from a sample spacing of the whole span down to ``JUMP_WIDTH``).
MAX_HALVINGS = 64


def undeclared_jumps(history: Callable[[np.ndarray], np.ndarray], start: float, end: float,
                     tol: float, declared: Sequence[float] = ()) -> tuple[float, ...]:
    """The times of ``(start, end)`` where ``history`` jumps, other than ``declared``.

    Parameters
    ----------
    history : callable
        A vectorized history of the time (a given load, dimensionless).
    start, end : float
        The span of the march (dimensionless times, ``start < end``).
    tol : float
        The answer's relative accuracy: jumps smaller than ``JUMP_TOL_SHARE * tol`` times
        the history's largest magnitude are not looked for.
    declared : sequence of float
        Jumps already known (the caller's ``time_breaks``): not returned again.

    Returns
    -------
    tuple of float
        The jumps found, sorted, each located to ``JUMP_WIDTH`` of its time.
    """
    if not end > start:
        return ()
    t = np.unique(np.concatenate([np.linspace(start, end, JUMP_SAMPLES),
                                  np.geomspace(start, end, JUMP_SAMPLES)]))
    f = np.asarray(history(t), dtype=float) * np.ones_like(t)
    if not np.all(np.isfinite(f)):
        return ()  # the solve's own checks say what is wrong with the history
    scale = float(np.max(np.abs(f)))
    if scale == 0.0:
        return ()
    change = np.abs(np.diff(f))
    beside = np.minimum(np.concatenate([[np.inf], change[:-1]]),
                        np.concatenate([change[1:], [np.inf]]))
    abrupt = np.flatnonzero((change > ABRUPT_RATIO * beside)
                            & (change > JUMP_TOL_SHARE * tol * scale))
    if not abrupt.size:
        return ()
    found = _bisected(history, t[abrupt], t[abrupt + 1], f[abrupt], f[abrupt + 1])
    known = np.asarray([float(b) for b in declared], dtype=float)
    kept = [float(b) for b in found if start < b < end
            and not np.any(np.abs(known - b) <= 2.0 * JUMP_WIDTH * abs(b))]
    return tuple(sorted(set(kept)))


def _bisected(history: Callable[[np.ndarray], np.ndarray], a: np.ndarray, b: np.ndarray,
              fa: np.ndarray, fb: np.ndarray) -> np.ndarray:
    """The midpoints of the intervals ``[a, b]`` whose change stays whole while they are
    halved (all of them at once: one evaluation of ``history`` a halving) down to
    ``JUMP_WIDTH``; the others are dropped."""
    whole = np.abs(fb - fa)
    for _ in range(MAX_HALVINGS):
        short = (b - a) <= JUMP_WIDTH * np.maximum(np.abs(a), np.abs(b))
        if short.all():
            break
        mid = 0.5 * (a + b)
        fm = np.asarray(history(mid), dtype=float) * np.ones_like(mid)
        # the half that holds the larger part of the change (the jump, if there is one)
        left = np.abs(fm - fa) >= np.abs(fb - fm)
        to_left, to_right = ~short & left, ~short & ~left
        b, fb = np.where(to_left, mid, b), np.where(to_left, fm, fb)
        a, fa = np.where(to_right, mid, a), np.where(to_right, fm, fa)
        kept = np.abs(fb - fa) >= KEPT_SHARE * whole
        if not kept.all():
            a, b, fa, fb, whole = a[kept], b[kept], fa[kept], fb[kept], whole[kept]
            if not a.size:
                return a
    return 0.5 * (a + b)
