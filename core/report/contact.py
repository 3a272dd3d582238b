"""The contact zone of a solved scene in the report's words: where the punch base touches
at a time the reader chose, and when it lifts off.

The unilateral contact model reports its contact set per output time
(:attr:`SceneSolution.contact_set`); the full-contact model keeps the whole base in
contact and, where its pressure comes out negative (flag ``contact_lost``), that answer is
not physical there. Both are said here in one sentence form.
"""

from __future__ import annotations

import numpy as np

from core.scene import LIFT_OFF_SHARE, SceneSolution, known_contact_width, lifts_off_at


def output_index(result: SceneSolution, time: float | None) -> int:
    """The output time nearest to ``time`` [day after loading] (default: the last).

    Raises
    ------
    ValueError
        When ``time`` is not a number within the output times, naming ``time``.
    """
    times = result.times
    if time is None:
        return len(times) - 1
    if isinstance(time, bool) or not isinstance(time, (int, float, np.floating, np.integer)) \
            or not np.isfinite(time):
        raise ValueError(f"time: {time!r} is not a finite number of days after loading")
    # half a day of slack: a time typed to the day still finds the first or last output
    if not times[0] - 0.5 <= float(time) <= times[-1] + 0.5:
        raise ValueError(f"time: {float(time):g} days is outside the output times, "
                         f"{times[0]:g} to {times[-1]:g} days after loading")
    return int(np.argmin(np.abs(times - float(time))))


def _metres(value: float) -> str:
    """A length [m] to the millimetre (shorter lengths to 2 significant digits)."""
    return f"{value:.3f}".rstrip("0").rstrip(".") if abs(value) >= 1e-3 else f"{value:.2g}"


def lifted_parts(result: SceneSolution, k: int) -> list[tuple[float, float]]:
    """The parts of the base ``[-a, a]`` [m] out of contact at ``times[k]``: outside the
    unilateral contact set, or where the full-contact pressure is negative beyond the
    solver's error band (the rule by which the engines raise ``contact_lost``)."""
    a = result.scene.half_width
    if result.contact_lost:
        return _negative_parts(result, k)
    if not lifts_off_at(result, k):
        return []
    parts, edge = [], -a
    for lo, hi in sorted(result.contact_set[k]):
        if lo > edge:
            parts.append((edge, min(lo, a)))
        edge = max(edge, hi)
    if edge < a:
        parts.append((edge, a))
    # a gap as narrow as the rounding of the zone ends is no lift-off
    return [(lo, hi) for lo, hi in parts if hi - lo > LIFT_OFF_SHARE * 2 * a]


def _negative_parts(result: SceneSolution, k: int) -> list[tuple[float, float]]:
    q = result.pressure_on_grid
    error = result.info.get("error_estimate")
    error = float(error) if isinstance(error, (int, float)) and np.isfinite(error) else 0.0
    # the engines' rule (core/engines/nystrom/result.py): q < -max(error, 1e-12) max|q|
    band = max(error, 1e-12) * float(np.max(np.abs(q)))
    return _runs_below_zero(result.x, q[:, k] + band)


def _runs_below_zero(x: np.ndarray, q: np.ndarray) -> list[tuple[float, float]]:
    """Where ``q < 0`` on the grid ``x`` as ``(left, right)`` pairs [m], the ends at the
    zero crossings of the chords (the grid's ends where a run reaches them)."""
    below = np.concatenate([[False], q < 0, [False]]).astype(np.int8)
    starts = np.flatnonzero(np.diff(below) == 1)    # first node of each run
    ends = np.flatnonzero(np.diff(below) == -1) - 1  # last node of each run

    def crossing(i: int) -> float:  # the zero of the chord from node i to node i + 1
        return float(x[i] - q[i] * (x[i + 1] - x[i]) / (q[i + 1] - q[i]))

    return [(float(x[0]) if i == 0 else crossing(i - 1),
             float(x[-1]) if j == len(x) - 1 else crossing(j))
            for i, j in zip(starts.tolist(), ends.tolist(), strict=True)]


def contact_text(result: SceneSolution, k: int, origin: float = 0.0) -> str:
    """The contact at ``times[k]`` in plain words, lengths in m, e.g. "contact 1.306 m of
    2 m (65 %), lifted 0.694 m: x = -1 to -0.306 m (unilateral contact)"; positions are
    ``origin + x`` [m] (a punch of several: its centre, so that they read in the global x)."""
    full = 2 * result.scene.half_width
    parts = lifted_parts(result, k)
    if not parts:
        return f"full contact: the whole width 2a = {_metres(full)} m touches"
    width = full - sum(hi - lo for lo, hi in parts)
    where = ", ".join(f"x = {_metres(origin + lo)} to {_metres(origin + hi)} m"
                      for lo, hi in parts)
    if result.contact_lost:
        return (f"contact {_metres(width)} m of {_metres(full)} m "
                f"({100 * width / full:.0f} %), q < 0 (contact lost, not physical) "
                f"{_metres(full - width)} m: {where} (full-contact model)")
    return (f"contact {_metres(width)} m of {_metres(full)} m ({100 * width / full:.0f} %), "
            f"lifted {_metres(full - width)} m: {where} (unilateral contact)")


def lift_off_times(result: SceneSolution) -> np.ndarray:
    """Indices of the output times at which the unilateral contact model lifts part of the
    base off (empty for the full-contact model and in full contact)."""
    if known_contact_width(result) is None or result.info.get("contact") != "unilateral":
        return np.zeros(0, dtype=int)
    return np.array([k for k in range(len(result.times)) if lifts_off_at(result, k)], dtype=int)
