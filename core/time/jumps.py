"""Jumps of a given history that its caller did not declare.

A time march that steps across a jump of a load loses its order, and worse, its error
estimate can miss it: with a force doubling at t = 4.3 and no ``time_breaks``, the
default engine answered at tol 1e-8 with an estimate of 4.2e-9 and a settlement 2e-4
off (the steps of all its grids straddled the jump alike). :func:`undeclared_jumps`
finds such jumps so that the march can land on them as on declared ones.

The history is sampled densely; in each interval between samples its change is compared
with what the slope beside the interval (the gentler of the two neighbours') gives over
it, and an interval whose change departs from that by more than the smallest jump that
matters at ``tol`` is bisected, always into the half that departs more. A jump keeps its
whole departure however short the interval, a smooth change loses it as soon as the
interval is shorter than the change: a departure that stays held within a millionth of
the sampled interval is a jump (a rise that steep, a ramp of 1e-9 days, is stepped as
one), located to :data:`JUMP_WIDTH` of its time. Bisection finds one jump an interval;
a second round looks beside each jump found for another (two jumps 2e-3 days apart).

What the samples cannot see is not found: a pulse narrower than their spacing (~1/2000 of
the span) that rises and falls between two samples, and three or more jumps within one
interval. Such times still have to be declared.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from core.time.radau import JUMP_SIDE

#: Samples of a history over its span, evenly and as many geometrically (dense after
#: loading, where load histories often change first).
JUMP_SAMPLES = 2049
#: A departure smaller than this share of ``tol`` times the history's largest magnitude
#: is no jump that matters: it moves the answer by well below tol even where a step
#: straddles it.
JUMP_TOL_SHARE = 1e-2
#: An interval keeps being halved while the half it goes on with departs by at least this
#: share of the whole interval's departure (two equal jumps in one interval: a half holds
#: half of it).
KEPT_SHARE = 0.45
#: A departure held within this share of the sampled interval is a jump.
CONCENTRATED = 1e-6
#: The bisection stops where the interval is this short relative to its time: the march
#: reads each side of a jump this far from it (:data:`core.time.JUMP_SIDE`).
JUMP_WIDTH = JUMP_SIDE
#: Halvings at most (from a sample spacing of the whole span down to ``JUMP_WIDTH``).
MAX_HALVINGS = 64
#: Rounds of the search: the second looks beside each jump the first found.
ROUNDS = 2


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
    f = _values(history, t)
    # where the history is not finite (a pole of a formula between the output times) the
    # solve's own checks speak; the search looks at the rest
    finite = np.isfinite(f)
    t, f = t[finite], f[finite]
    if t.size < 3:
        return ()
    scale = float(np.max(np.abs(f)))
    if scale == 0.0:
        return ()
    floor = JUMP_TOL_SHARE * tol * scale
    slope = np.diff(f) / np.diff(t)
    # the background of each interval: the gentler slope beside it (the other may hold
    # the jump back of a pulse)
    left = np.concatenate([[np.inf], slope[:-1]])
    right = np.concatenate([slope[1:], [np.inf]])
    background = np.where(np.abs(left) <= np.abs(right), left, right)
    background = np.where(np.isfinite(background), background, 0.0)
    a, b, fa, fb = t[:-1], t[1:], f[:-1], f[1:]
    found: list[float] = []
    for _ in range(ROUNDS):
        departure = np.abs(fb - fa - background * (b - a))
        look = departure > floor
        if not look.any():
            break
        a, b, fa, fb, background = (v[look] for v in (a, b, fa, fb, background))
        jumps, where = _bisected(history, a, b, fa, fb, background)
        found.extend(float(p) for p in jumps)
        # beside each jump, the rest of its interval (another jump there, if any)
        a0, b0, fa0, fb0, s0 = (v[where] for v in (a, b, fa, fb, background))
        side = 2.0 * JUMP_WIDTH * np.abs(jumps)
        before, after = jumps - side, jumps + side
        f_before, f_after = _values(history, before), _values(history, after)
        a = np.concatenate([a0, after])
        b = np.concatenate([before, b0])
        fa = np.concatenate([fa0, f_after])
        fb = np.concatenate([f_before, fb0])
        background = np.concatenate([s0, s0])
        keep = b > a
        a, b, fa, fb, background = (v[keep] for v in (a, b, fa, fb, background))
    known = np.asarray([float(p) for p in declared], dtype=float)
    kept = [p for p in found if start < p < end
            and not np.any(np.abs(known - p) <= 2.0 * JUMP_WIDTH * abs(p))]
    return tuple(sorted(set(kept)))


def _values(history: Callable[[np.ndarray], np.ndarray], t: np.ndarray) -> np.ndarray:
    return np.asarray(history(t), dtype=float) * np.ones_like(t)


def _bisected(history: Callable[[np.ndarray], np.ndarray], a: np.ndarray, b: np.ndarray,
              fa: np.ndarray, fb: np.ndarray, background: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """The jumps in the intervals ``[a, b]`` (one each at most; all intervals halved at
    once, one evaluation of ``history`` a halving) and the index of the interval of each:
    each interval is halved into the half whose change departs more from ``background``
    (a slope) while that half keeps ``KEPT_SHARE`` of the interval's departure; a
    departure held within ``CONCENTRATED`` of the interval is a jump, located at the
    middle of the shortest interval that held it."""
    index = np.arange(a.size)
    whole = np.abs(fb - fa - background * (b - a))
    width = b - a
    held = np.full(a.size, np.inf)  # the shortest interval that held the departure
    at = 0.5 * (a + b)
    for _ in range(MAX_HALVINGS):
        short = (b - a) <= JUMP_WIDTH * np.maximum(np.abs(a), np.abs(b))
        held[index[short]] = (b - a)[short]
        at[index[short]] = 0.5 * (a + b)[short]
        live = ~short
        if not live.any():
            break
        index, a, b, fa, fb = (v[live] for v in (index, a, b, fa, fb))
        s = background[index]
        mid = 0.5 * (a + b)
        fm = _values(history, mid)
        left = np.abs(fm - fa - s * (mid - a))
        right = np.abs(fb - fm - s * (b - mid))
        to_left = left >= right
        kept = np.maximum(left, right) >= KEPT_SHARE * whole[index]
        b, fb = np.where(to_left, mid, b), np.where(to_left, fm, fb)
        a, fa = np.where(to_left, a, mid), np.where(to_left, fa, fm)
        held[index[kept]] = (b - a)[kept]
        at[index[kept]] = 0.5 * (a + b)[kept]
        index, a, b, fa, fb = (v[kept] for v in (index, a, b, fa, fb))
        if not index.size:
            break
    jump = held <= CONCENTRATED * width
    return at[jump], np.flatnonzero(jump)
