"""Time grids for stepping on fixed grids: every requested time a grid point, halvings
exact (for Richardson extrapolation), load jumps held on both sides."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from core.time.radau import JUMP_SIDE

__all__ = ["history_key_times", "time_grid"]

#: Points of a march's span ``[1, t_end]`` (as many spaced evenly and as many
#: geometrically) where :func:`history_key_times` samples a history.
KEY_SAMPLES = 129
#: A kink (``time_grid(..., kinks=)``) within this many nominal steps of another interval
#: end is taken to be on it: a sliver of a step would cost a factorization of its own,
#: and the kink's error, of the order of its distance times the step, is as small.
KINK_SNAP = 1e-4


def time_grid(times: np.ndarray, steps: int, refine: int = 0,
              jumps: Sequence[float] = (), graded: int = 0,
              windows: Sequence[tuple[float, float, float]] = (),
              kinks: Sequence[float] = ()
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A grid on ``[1, times[-1]]`` containing every requested time (dimensionless t).

    The nominal step is ``(times[-1] - 1) / steps``; each interval between consecutive
    requested times (and from 1 to the first) is split into equal steps no longer than
    that, and then every step is halved ``refine`` times. Halving the steps of a fixed
    grid (rather than recounting for ``2 steps``, which need not halve every interval's
    step) keeps the trapezoid error expansion in even powers of one step, which is what
    Richardson extrapolation needs. Returns the grid (G,), the step lengths (G-1,),
    exactly equal within an interval, and the grid index of each requested time.

    ``jumps``: times where a given load jumps. No step straddles one: the grid holds both
    of its sides, ``JUMP_SIDE`` (relative) before and after it, so the loads are read on
    each side of the jump and the trapezoid's error keeps its expansion on either side (a
    step across a jump erred to first order: the halved grids' difference was no
    estimate). A requested time on a jump is its side after it.

    ``graded``: the first interval after the start and after each jump is split at
    ``length / 2**k`` (k = 1 .. graded) from its start before its steps are counted, so
    the steps grow geometrically out of the start (a creep law's transient just after a
    load is applied, such as the ``(t - t0)^0.3`` of the design codes); beyond that
    interval, points at ``length * 2**k`` (k = 1, 2, ...) from the start, up to the next
    jump, keep the steps growing at most twofold per interval (a design code's decays
    spread over decades of time, so each one meets steps of the same size relative to its
    decay time on every grid; with equal steps between output times a decade apart the
    halved grids' differences shrank irregularly, ratios 3.5 then 2.2, and their Richardson
    value of the fib MC2010 preset with 6 log-spaced outputs read 2.1e-4 off against an
    estimate of 2.7e-5; now ratios 3.7 to 4.0). None falls within an eighth of its
    distance from the start of a requested time. These points do not depend on
    ``refine``, so halving stays exact.

    ``windows``: (from, to, longest step): the intervals between ``from`` and ``to`` (each
    ``to`` an interval end) get steps no longer than that (a creep law's decay, stepped
    finely while it lasts); also independent of ``refine``.

    ``kinks``: times where the answer has a kink the grid must land on (a corner of the
    punch touching down or lifting off, located by the march itself): each an interval
    end, as a requested time is, but not an output (none within ``KINK_SNAP`` nominal
    steps of another end, or inside a jump's sides); also independent of ``refine``.
    """
    times = np.asarray(times, dtype=float)
    h = (times[-1] - 1.0) / steps
    # the ends of the intervals: (time, index of the requested time or -1)
    ends: list[tuple[float, int]] = []
    inside = sorted({float(j) for j in jumps if 1.0 < float(j) < float(times[-1])})
    sides = {j: JUMP_SIDE * max(1.0, abs(j)) for j in inside}
    if graded:
        marks = np.unique(np.concatenate([times, inside]))
        starts = [1.0] + [j + sides[j] for j in inside]
        stops = [j - sides[j] for j in inside] + [float(times[-1])]
        for start, stop in zip(starts, stops, strict=True):
            after = marks[marks > start * (1.0 + 1e-9)]
            if after.size:
                length = float(after[0]) - start
                ends += [(start + length * 2.0**-k, -1) for k in range(graded, 0, -1)]
                # and on out of it, doubling, up to the next jump: the decays of a law
                # whose rates spread over decades then each meet steps of one size
                # relative to their decay time, at every halving alike
                grown = start + length * 2.0 ** np.arange(1, 64)
                # (not beside a requested time: a sliver of an interval buys nothing)
                ends += [(float(t), -1) for t in grown[grown < stop * (1.0 - 1e-9)]
                         if not np.any(np.abs(marks - t) <= (t - start) / 8.0)]
    # a window shorter than the nominal step ends on an interval end, so that each
    # interval is inside it or outside it
    windows = [(float(a), float(b), float(step)) for a, b, step in windows if step < h]
    ends += [(b, -1) for _, b, _ in windows if 1.0 < b < float(times[-1])
             and all(abs(b - j) > sides[j] for j in inside)]
    for t in sorted(float(k) for k in kinks):
        # (not beside another end or a jump's sides: a sliver of a step buys nothing)
        if (1.0 < t < float(times[-1]) and not np.any(np.abs(times - t) <= KINK_SNAP * h)
                and all(abs(t - j) > sides[j] for j in inside)
                and all(abs(t - e) > KINK_SNAP * h for e, _ in ends)):
            ends.append((t, -1))
    on_jump: dict[int, int] = {}
    for j, side in sides.items():
        ends += [(j - side, -1), (j + side, -1)]
        hit = np.flatnonzero(np.abs(times - j) <= side)
        if hit.size:
            on_jump[int(hit[0])] = len(ends) - 1
    ends += [(float(t), k) for k, t in enumerate(times) if k not in on_jump]
    order = sorted(range(len(ends)), key=lambda i: ends[i][0])
    points = [1.0]
    widths: list[float] = []
    index = np.zeros(times.size, dtype=int)
    start = 1.0
    for i in order:
        t, k = ends[i]
        length = t - start
        if length > 0.0:
            step = min([h] + [w for a, b, w in windows if a < t and b > start])
            count = max(1, math.ceil(length / step - 1e-9)) * 2**refine
            points.extend(start + length * np.arange(1, count + 1) / count)
            points[-1] = t
            # One width per interval, not np.diff of the points: equal widths keep the
            # step matrix bit-identical, so its factorization is reused.
            widths.extend([length / count] * count)
            start = t
        if k >= 0:
            index[k] = len(points) - 1
        for out, end in on_jump.items():
            if end == i:
                index[out] = len(points) - 1
    return np.array(points), np.array(widths), index


def history_key_times(times: np.ndarray, breaks: Sequence[float] = ()) -> np.ndarray:
    """Where a given history (a load, ``c``) is sampled for the key of a cached time-stepped
    response: the march's whole span ``[1, times[-1]]`` (dimensionless t), not the output
    times alone, at :data:`KEY_SAMPLES` points evenly and as many geometrically (dense after
    loading, where creep moves fastest), and on both sides of every jump or kink in
    ``breaks``. Two histories that agree at all of them are stepped alike by a march that
    lands on those breaks (a difference between samples, away from any break, is a
    feature the march is not told of either: the scene passes its loads' features as
    breaks)."""
    start, end = 1.0, float(np.asarray(times, dtype=float)[-1])
    parts = [np.asarray(times, dtype=float).ravel()]
    if end > start:
        parts += [np.linspace(start, end, KEY_SAMPLES), np.geomspace(start, end, KEY_SAMPLES)]
    cuts = np.asarray([b for b in breaks if start < b < end], dtype=float)
    if cuts.size:
        parts += [cuts * (1 - JUMP_SIDE), cuts * (1 + JUMP_SIDE)]
    return np.unique(np.concatenate(parts))
