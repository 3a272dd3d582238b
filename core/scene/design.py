"""The design check: the largest contact pressure, settlement and tilt of an answer over
its whole history, each against a limit, with where and when the extreme occurs.

The limits (:class:`DesignLimits`, SI units) come from the ``limits`` section of a scene
file or from the caller; :func:`check_design` judges plain arrays, so the explorer (which
draws arrays, not a :class:`~core.scene.SceneSolution`), the command line and the JSON
output share one check; :func:`design_check` reads a solution. A limit holds when the
magnitude of the extreme is at most the limit; a limit left out is not checked.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.coating import THIN_LAYER
from core.validation import finite_number, show_value

#: The limit checks in order: (field of :class:`DesignLimits`, quantity, unit, label).
CHECKS: tuple[tuple[str, str, str, str], ...] = (
    ("allowable_pressure", "q_max", "Pa", "largest contact pressure q_max"),
    ("settlement_limit", "settlement", "m", "largest settlement δ (punch centre)"),
    # (the largest either way, its sign kept: "largest tilt -0.0094 mrad" puzzled a reader)
    ("tilt_limit", "tilt", "rad", "largest tilt α (either way, signed)"),
)



#: Values of a history within this share of its extreme are the extreme (round-off), at
#: least (:func:`answer_accuracy`).
SAME_SHARE = 1e-9


def _six_digits(value: float) -> str:
    return f"{value:.6g}"

@dataclass(frozen=True)
class DesignLimits:
    """What the design must not exceed (``None``: not checked).

    ``allowable_pressure`` [Pa]: the largest contact pressure q over x and time;
    ``settlement_limit`` [m]: the largest settlement delta (magnitude), the punch centre's
    (a tilted punch's edges move by alpha a more or less);
    ``tilt_limit`` [rad]: the largest tilt alpha, either way. Each finite and >= 0.
    """

    allowable_pressure: float | None = None
    settlement_limit: float | None = None
    tilt_limit: float | None = None

    def __post_init__(self) -> None:
        for name, _, unit, _ in CHECKS:
            value = getattr(self, name)
            if value is None:
                continue
            x = finite_number(value, f"limits.{name}")
            if x < 0:
                raise ValueError(f"limits.{name}: must be >= 0 {unit}, got "
                                 f"{show_value(value)} {unit}")
            object.__setattr__(self, name, x)

    @classmethod
    def from_dict(cls, spec: Mapping[str, Any]) -> DesignLimits:
        """The limits of a scene file's ``limits`` object (fields as in :data:`CHECKS`; a
        limit not checked is left out: a ``null`` is refused, as the JSON Schema refuses
        it, where it was taken silently for no limit)."""
        for name, _, unit, _ in CHECKS:
            if name in spec and spec[name] is None:
                raise ValueError(f"limits.{name}: must be a number [{unit}], got null (leave "
                                 "the field out to check no limit)")
        return cls(**{name: spec.get(name) for name, _, _, _ in CHECKS})

    def to_dict(self) -> dict[str, float]:
        """The limits that are set, as a scene file's ``limits`` object."""
        return {name: getattr(self, name) for name, _, _, _ in CHECKS
                if getattr(self, name) is not None}

    @property
    def empty(self) -> bool:
        """Whether no limit is set."""
        return not self.to_dict()


#: [m] the least distance from a corner said in words: a limit exceeded closer to the
#: corner than this is "exceeded within 0.001 mm of the corner" (it read "~0.000000072
#: mm", a precision no corner is built to)
CORNER_RESOLUTION = 1e-6


@dataclass(frozen=True)
class LimitCheck:
    """One line of the check: the extreme ``value`` of ``quantity`` [``unit``] at ``time``
    [day after loading] (and ``x`` [m] for the pressure), against ``limit`` (None: not
    set, or ``limit_name`` None for a value reported without a limit)."""

    limit_name: str | None
    quantity: str
    label: str
    value: float
    unit: str
    time: float
    x: float | None = None
    limit: float | None = None
    #: [m] for a pressure unbounded at the punch corner ``x`` (a rigid corner in contact
    #: on an elastic body: q ~ 1 / sqrt(distance)): the distance from the corner where
    #: ``value`` is read (None: the value is the largest)
    corner_distance: float | None = None
    #: whether q ~ K / sqrt(distance) holds from ``corner_distance`` to the corner (so
    #: that :attr:`exceeded_within` can be read from it)
    asymptotic: bool = False
    #: [m] for an unbounded pressure with a limit: how far from the corner the pressure
    #: on the answer's grid stays over the limit, at its worst time (linear between the
    #: grid points either side of the limit); None: not past ``corner_distance``
    exceeded_on_grid: float | None = None
    #: whether the pressure is over the limit on the whole base at some time
    exceeded_everywhere: bool = False
    #: whether the value stays at the extreme (to the answer's accuracy) from ``time`` to
    #: the last output time, which comes later: a history that levels off ("largest
    #: settlement ... at t = 489.4 days" read as an event to a class told it stops
    #: growing after ~250 days, a teacher's audit); said "and after"
    held: bool = False

    @property
    def sign_note(self) -> str:
        """What the sign of the value says where it is not the expected one: a negative
        settlement, the punch centre rising (a heel lifting far), read as a "largest
        settlement" with no word of it (a teacher's audit); else empty."""
        if self.quantity == "settlement" and self.value < 0:
            return "negative: the punch centre rises"
        return ""

    @property
    def unbounded(self) -> bool:
        """Whether the quantity has no largest value: the pressure at a rigid corner."""
        return self.corner_distance is not None

    @property
    def exceeded_within(self) -> float | None:
        """For an unbounded pressure with a limit: the distance [m] from the corner within
        which q exceeds it. Read on the answer's grid where it reaches past
        ``corner_distance``; closer in, from q ~ K / sqrt(distance) through ``value`` at
        ``corner_distance`` (the corner's asymptote, which holds only there), or None
        where the asymptote is not known to hold (under a coating) or the limit is
        exceeded on the whole base."""
        if not self.unbounded or self.limit is None or self.exceeded_everywhere:
            return None
        if self.exceeded_on_grid is not None:
            return float(self.exceeded_on_grid)
        if not self.asymptotic:
            return None
        if self.limit <= 0:
            return math.inf
        return min(float(self.corner_distance) * (abs(self.value) / self.limit) ** 2,
                   float(self.corner_distance))

    def exceeded_text(self) -> str:
        """Where an unbounded pressure exceeds its limit, in words: "on the whole base",
        "within ~D mm of the corner" or "at the corner" (empty without a limit)."""
        if not self.unbounded or self.limit is None:
            return ""
        if self.exceeded_everywhere:
            return "on the whole base"
        within = self.exceeded_within
        if within is None or not math.isfinite(within):
            return "at the corner"
        if within < CORNER_RESOLUTION:
            # closer than anything a footing's corner is made to: at the corner
            return f"within {1e3 * CORNER_RESOLUTION:g} mm of the corner"
        return f"within ~{_millimetres(within)} mm of the corner"

    @property
    def utilisation(self) -> float | None:
        """``|value| / limit`` [-] (above 1: the limit is exceeded); None without a limit,
        infinite for an unbounded pressure."""
        if self.limit is None:
            return None
        if self.unbounded:
            return math.inf
        if self.limit == 0:
            return 0.0 if self.value == 0 else math.inf
        return abs(self.value) / self.limit

    @property
    def passed(self) -> bool | None:
        """Whether ``|value| <= limit``; None without a limit. An unbounded pressure
        exceeds every limit near its corner: never passed."""
        if self.limit is None:
            return None
        if self.unbounded:
            return False
        return bool(abs(self.value) <= self.limit)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able dict of the line (non-finite numbers as None)."""
        def plain(v: float | None) -> float | None:
            return None if v is None or not math.isfinite(v) else float(v)

        out = {"quantity": self.quantity, "limit_name": self.limit_name,
               "label": self.label, "unit": self.unit, "value": plain(self.value),
               "limit": plain(self.limit), "utilisation": plain(self.utilisation),
               "passed": self.passed, "time_day": plain(self.time), "x_m": plain(self.x),
               "held_after": self.held}
        if self.unbounded:
            out.update(unbounded=True, corner_distance_m=plain(self.corner_distance),
                       exceeded_within_m=plain(self.exceeded_within),
                       exceeded_everywhere=self.exceeded_everywhere)
        return out

    def describe(self) -> str:
        """One line for a terminal: the label, then :meth:`verdict_text`."""
        return f"{self.label} {self.verdict_text()}"

    def value_text(self, number: Callable[[float], str] = _six_digits,
                   shown: Callable[[float, str], str] | None = None,
                   place_first: bool = False,
                   time: Callable[[float], str] | None = None) -> str:
        """Value and where (or, for an unbounded pressure, the corner and the value where
        it is read), without the limit: :meth:`verdict_text`'s arguments; ``place_first``
        writes ``x`` before ``t``."""
        if shown is None:
            def shown(value: float, unit: str) -> str:
                return f"{number(value)} {unit}"
        if time is None:
            def time(t: float) -> str:
                text = number(t)
                return f"{text} {'day' if text == '1' else 'days'}"
        when = f"t = {time(self.time)}" + (" and after" if self.held else "")
        if self.unbounded:
            return (f"unbounded at the corner x = {number(self.x)} m (a rigid corner: q ~ "
                    f"1/sqrt(distance)); {shown(self.value, self.unit)} at "
                    f"{number(1e3 * float(self.corner_distance))} mm from it, {when}")
        if self.x is None:
            where = when
        else:
            place = f"x = {number(self.x)} m"
            where = f"{place}, {when}" if place_first else f"{when}, {place}"
        note = f" ({self.sign_note})" if self.sign_note else ""
        return f"{shown(self.value, self.unit)}{note} at {where}"

    def verdict_text(self, number: Callable[[float], str] = _six_digits,
                     shown: Callable[[float, str], str] | None = None,
                     time: Callable[[float], str] | None = None) -> str:
        """Value, where, limit, utilisation and verdict (the report's table cell).

        ``number`` writes a time [day] or a position [m], ``shown`` a value and its unit
        (default: in the check's SI unit, by ``number``), ``time`` a time [day] with its
        unit (default: by ``number``, in days)."""
        if shown is None:
            def shown(value: float, unit: str) -> str:
                return f"{number(value)} {unit}"
        text = self.value_text(number, shown, time=time)
        if self.limit is None:
            return text + "; no limit set"
        if self.unbounded:
            return (f"{text}; limit {shown(self.limit, self.unit)}, exceeded "
                    f"{self.exceeded_text()}: FAIL")
        verdict = "pass" if self.passed else "FAIL"
        if not math.isfinite(self.utilisation):  # a limit of 0 and a value beside it
            return f"{text}; limit {shown(self.limit, self.unit)}, exceeded: {verdict}"
        slip = (f" (over {UNIT_SLIP:g} times the limit: a scene file gives it in "
                f"{self.unit})"
                if self.utilisation > UNIT_SLIP else "")
        return (f"{text}; limit {shown(self.limit, self.unit)}, utilisation "
                f"{self.utilisation:.3g}: {verdict}{slip}")


#: A utilisation over this asks whether the limit was written in another unit: 2000 for
#: an allowable pressure of 2000 kPa read 2000 Pa, utilisation 986, with no word (an
#: engineer's audit; a file's limits are in Pa, m and rad).
UNIT_SLIP = 100.0


@dataclass(frozen=True)
class DesignCheck:
    """The design check of one answer: ``checks`` (largest pressure, settlement and tilt,
    in the order of :data:`CHECKS`) and ``q_min``, the smallest pressure (no limit)."""

    checks: tuple[LimitCheck, ...]
    q_min: LimitCheck

    @property
    def passed(self) -> bool | None:
        """True: every set limit holds; False: one is exceeded; None: no limit is set."""
        verdicts = [c.passed for c in self.checks if c.passed is not None]
        if not verdicts:
            return None
        return all(verdicts)

    @property
    def failures(self) -> tuple[LimitCheck, ...]:
        """The checks whose limit is exceeded."""
        return tuple(c for c in self.checks if c.passed is False)

    def check(self, quantity: str) -> LimitCheck:
        """The line of ``quantity`` (``"q_max"``, ``"settlement"``, ``"tilt"``, ``"q_min"``)."""
        for c in (*self.checks, self.q_min):
            if c.quantity == quantity:
                return c
        raise KeyError(quantity)

    def summary(self, flags: Sequence[str] = ()) -> str:
        """The verdict (:func:`verdict_words` with the answer's ``flags``) and every limit's
        line, on one line: what the files' ``# design_check:`` header holds."""
        return (f"{verdict_words(self.passed, flags)}; "
                + "; ".join(line.describe() for line in self.checks))

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able dict: ``passed`` and one entry per line (``checks``, ``q_min``)."""
        return {"passed": self.passed, "checks": [c.to_dict() for c in self.checks],
                "q_min": self.q_min.to_dict()}


def flagged_caution(flags: Sequence[str]) -> str:
    """What a design check's verdict is worth on an answer carrying the validity ``flags``
    (its ``flags``; ``solve --strict`` exits 4 on them): "" without any, else the caution
    to put beside "pass" or "FAIL" (the numbers checked are those the flags doubt: a pad
    whose model error is 70 % "passed" its pressure limit unqualified)."""
    if not flags:
        return ""
    return (f"on an answer flagged {', '.join(flags)}: the check is only as good as that "
            "answer, not to be relied on")


def verdict_words(passed: bool | None, flags: Sequence[str] = ()) -> str:
    """A check's verdict in words: "pass", "FAIL" or "no limit set", followed by
    :func:`flagged_caution` of ``flags`` when there is a verdict and a flag."""
    if passed is None:
        return "no limit set"
    caution = flagged_caution(flags)
    return ("pass" if passed else "FAIL") + (f" ({caution})" if caution else "")


def check_design(times: Any, x: Any, pressure: Any, settlement: Any, tilt: Any,
                 limits: DesignLimits | None = None,
                 corners: Mapping[str, Any] | None = None,
                 accuracy: float = SAME_SHARE) -> DesignCheck:
    """The design check of an answer given as arrays.

    Parameters
    ----------
    times : array, shape (n,)
        Output times [day after loading].
    x : array, shape (m,)
        Points of [-a, a] [m] where ``pressure`` is given.
    pressure : array, shape (m, n)
        Contact pressure q [Pa] (compression positive) at ``x`` and ``times``.
    settlement, tilt : arrays, shape (n,)
        Settlement delta [m] and tilt alpha [rad] at ``times``.
    limits : DesignLimits, optional
        The limits (default: none set; the extremes are still found).
    corners : mapping, optional
        Where the pressure is unbounded (``info["corner_pressure"]`` of an answer that
        carries the rigid corner's singularity: ``"corners_m"``, the corners [m] in
        contact, ``"held_within_m"``, the distance [m] from a corner within which
        ``pressure`` holds its value there, and ``"asymptotic"``, whether q ~ 1/sqrt
        (distance) holds from there on). The largest pressure is then the corner's:
        reported at that distance, never passed against a limit.
    accuracy : float, optional
        The answer's relative accuracy (:func:`answer_accuracy`): values within it of an
        extreme are that extreme, and its time is the first output time that reaches it.

    Returns
    -------
    DesignCheck
        The largest pressure, settlement and tilt (by magnitude for the last two, with
        their sign), where and when they are first reached, against the limits; the
        smallest pressure.
    """
    limits = limits or DesignLimits()
    times = np.asarray(times, dtype=float)
    x = np.asarray(x, dtype=float)
    q = np.asarray(pressure, dtype=float)
    # the extremes' values are the largest and smallest (what a limit is held to); their
    # time and place, where they are first reached to the answer's accuracy
    q_largest, q_smallest = float(np.nanmax(q)), float(np.nanmin(q))
    i_max, held_max = _first_extreme(q, max, accuracy)
    i_min, held_min = _first_extreme(q, min, accuracy)
    histories = {"settlement": np.asarray(settlement, dtype=float),
                 "tilt": np.asarray(tilt, dtype=float)}
    lines = []
    for name, quantity, unit, label in CHECKS:
        limit = getattr(limits, name)
        if quantity == "q_max":
            lines.append(_corner_line(name, label, unit, times, x, q, limit, corners)
                         or LimitCheck(name, quantity, label, q_largest, unit,
                                       float(times[i_max[1]]), float(x[i_max[0]]), limit,
                                       held=held_max))
            continue
        values = histories[quantity]
        reached = _at_largest(values, accuracy)
        k = time_of_largest(values, accuracy)
        largest = int(np.nanargmax(np.abs(values)))
        # (of its sign: a tilt of 2e-3, then -2e-3, then 2e-3 again is not held; a zero
        # history has no extreme to hold)
        held = bool(k < values.size - 1 and values[largest] != 0 and reached[k:].all())
        lines.append(LimitCheck(name, quantity, label, float(values[largest]), unit,
                                float(times[k]), None, limit, held=held))
    q_min = LimitCheck(None, "q_min", "smallest contact pressure q_min", q_smallest,
                       "Pa", float(times[i_min[1]]), float(x[i_min[0]]), held=held_min)
    return DesignCheck(tuple(lines), q_min)


def answer_accuracy(info: Mapping[str, Any]) -> float:
    """The relative accuracy of an answer whose ``info`` this is, for telling its values
    apart: its error estimate, at least :data:`SAME_SHARE` (none, or not finite: that)."""
    estimate = info.get("error_estimate")
    if isinstance(estimate, (int, float)) and math.isfinite(estimate):
        return max(float(estimate), SAME_SHARE)
    return SAME_SHARE


def _same_share(accuracy: float) -> float:
    """The share within which values are the same: ``accuracy``, at least
    :data:`SAME_SHARE`, at most :data:`LEAST_SHARE` (a failed answer's large estimate
    would date a peak anywhere)."""
    return min(max(accuracy, SAME_SHARE), LEAST_SHARE)


#: The widest share :func:`_same_share` takes.
LEAST_SHARE = 1e-3
#: Half a unit of the fourth significant digit at its smallest (the design check's
#: values are shown to four): where an extreme is dated, q is within this share of it.
SHOWN_SHARE = 5e-5


def time_of_largest(values: np.ndarray, accuracy: float = SAME_SHARE) -> int:
    """The index of the time the largest ``|values|`` is reached: the first of those of
    its sign within ``accuracy`` (relative, :func:`_same_share`) of it (a history that
    levels off read "largest at t = 887.7 days" for 1e-11 mm more there than elsewhere;
    a zero history: its first time). The largest value itself is ``values`` at
    ``argmax |values|``: a limit is held to it, not to the value at this time."""
    near = np.flatnonzero(_at_largest(values, accuracy))
    return int(near[0]) if near.size else int(np.nanargmax(np.abs(values)))


def _at_largest(values: np.ndarray, accuracy: float) -> np.ndarray:
    """Where ``values`` are their largest ``|values|``: of its sign and within
    ``accuracy`` (relative, :func:`_same_share`) of it."""
    size = np.abs(values)
    k = int(np.nanargmax(size))
    return (size >= size[k] * (1.0 - _same_share(accuracy))) & (
        np.sign(values) == np.sign(values[k]))


def _first_extreme(q: np.ndarray, pick: Callable, accuracy: float
                   ) -> tuple[tuple[int, int], bool]:
    """``(i, j)`` of the largest (``pick`` max) or smallest (min) pressure of ``q`` (x,
    time): at the first time whose extreme over x is within ``accuracy`` (relative to the
    largest |q|) of the whole one; and whether every later time's is too (the extreme is
    held from there on). The time of eccentric_creep's largest pressure, level from ~435
    days to seven digits, read 887.7 days (2.4 years) where the last digits of the
    round-off peaked (a teacher's audit)."""
    over_x = np.nanmax(q, axis=0) if pick is max else np.nanmin(q, axis=0)
    extreme = float(np.nanmax(over_x) if pick is max else np.nanmin(over_x))
    # within the accuracy of the largest |q|, but no further from the extreme than its
    # digits shown: q_min "44.39 kPa at t = 287.4 days, x = 3.6 m" read 44.45 kPa there
    slack = _same_share(accuracy) * float(np.nanmax(np.abs(q)))
    if extreme:
        slack = min(slack, SHOWN_SHARE * abs(extreme))
    reached = (over_x >= extreme - slack) if pick is max else (over_x <= extreme + slack)
    if not (np.isfinite(slack) and reached.any()):  # (an infinite pressure: where it is)
        flat = np.nanargmax(q) if pick is max else np.nanargmin(q)
        i, j = np.unravel_index(int(flat), q.shape)
        return (int(i), int(j)), False
    j = int(np.flatnonzero(reached)[0])
    held = bool(j < reached.size - 1 and reached[j:].all())
    # the place: of those within the accuracy of the time's extreme, the last (a centred
    # load's largest pressure is at both corners: the right one, to round-off either)
    at = q[:, j]
    near = np.flatnonzero(at >= over_x[j] - slack) if pick is max else \
        np.flatnonzero(at <= over_x[j] + slack)
    i = int(near[-1])
    # held at its place too: q_min = 0 "at x = -0.309 m, t = 0 days and after" read as
    # if that point stayed lifted, where the zone grew over it (a browser check)
    later = q[i, j:]
    held = held and bool(np.all(later >= extreme - slack) if pick is max
                         else np.all(later <= extreme + slack))
    return (i, j), held


def _corner_line(name: str, label: str, unit: str, times: np.ndarray, x: np.ndarray,
                 q: np.ndarray, limit: float | None,
                 corners: Mapping[str, Any] | None) -> LimitCheck | None:
    """The largest-pressure line of an answer unbounded at a corner in contact (None
    without one): the largest held value next to such a corner, and where it is read."""
    if not corners or not corners.get("corners_m"):
        return None
    held = float(corners["held_within_m"])
    best = None
    for corner in corners["corners_m"]:
        near = np.abs(x - float(corner)) <= held * (1 + 1e-9) + 1e-12 * abs(float(corner))
        if not near.any():
            continue
        rows = q[near]
        j = np.unravel_index(int(np.nanargmax(rows)), rows.shape)
        if best is None or rows[j] > best[0]:
            best = (float(rows[j]), float(times[j[1]]), float(corner))
    if best is None:
        return None
    on_grid, everywhere = None, False
    if limit is not None:
        on_grid, everywhere = _over_from(x, q, best[2], limit, held)
        if on_grid is not None and on_grid <= held * (1 + 1e-9):
            on_grid = None  # within the held values: the asymptote says more
    return LimitCheck(name, "q_max", label, best[0], unit, best[1], best[2], limit,
                      corner_distance=held, asymptotic=bool(corners.get("asymptotic")),
                      exceeded_on_grid=on_grid, exceeded_everywhere=everywhere)


def _over_from(x: np.ndarray, q: np.ndarray, corner: float, limit: float,
               held: float = 0.0) -> tuple[float | None, bool]:
    """How far from ``corner`` [m] the pressure ``q`` [Pa] on the grid ``x`` stays over
    ``limit`` without a break, at its worst time (None: not even the nearest point is
    over), and whether it is over on the whole grid at some time. Between the last grid
    point over it and the next, ``1 / q^2`` is taken linear in the distance, which the
    corner's ``q ~ K / sqrt(distance)`` makes exact (linear in q overstated the distance
    by up to 6.3 % 1.3 to 2.3 mm from the bare layer's corner, an audit); the points
    within ``held`` [m] of the corner, where q holds its value there, count at ``held``
    (read at their own distance the reach came out 1.000 mm for a true 1.084)."""
    distance = np.maximum(np.abs(x - corner), held)
    order = np.argsort(distance, kind="stable")
    d = distance[order]
    rows = np.nan_to_num(q[order], nan=-np.inf)
    over = rows > limit
    everywhere = bool(over.all(axis=0).any())
    if everywhere:
        return float(d[-1]), True
    # per time, the number of grid points over the limit counted from the corner
    runs = np.argmin(over, axis=0)
    reach = None
    for j, run in enumerate(runs):
        if run == 0:
            continue
        d0, d1, q0, q1 = d[run - 1], d[run], rows[run - 1, j], rows[run, j]
        if not q0 > q1:
            at = d0
        elif q1 > 0.0:
            at = d0 + (d1 - d0) * (q0 ** -2 - limit ** -2) / (q0 ** -2 - q1 ** -2)
        else:
            at = d0 + (d1 - d0) * (q0 - limit) / (q0 - q1)
        reach = at if reach is None else max(reach, at)
    return (None if reach is None else float(reach)), False


def _millimetres(distance: float) -> str:
    """A distance [m] in mm to two significant digits, never in exponent form."""
    return np.format_float_positional(1e3 * distance, precision=2, unique=False,
                                      fractional=False, trim="-")


#: What the thin coating model's largest pressure at a punch's edge is, said beside it.
THIN_EDGE_NOTE = (
    "at the punch's edge: the thin coating model's value, bounded by its springs, where a "
    "sharp rigid corner on the resolved coating carries a pressure without bound; the FE "
    "check compares q away from the edges only")


#: :data:`THIN_EDGE_NOTE` where room is short (a report's row).
THIN_EDGE_SHORT = "at the edge: the thin coating model's springs bound it there"
#: The same beside a step of the punch's base (or of a coating's thickness) inside it.
THIN_STEP_NOTE = (
    "beside a step of the punch: the thin coating model's value, bounded by its springs, "
    "where the step's rigid corner on the resolved coating carries a pressure without "
    "bound (within a few coating thicknesses of it); the FE check compares q there too")
THIN_STEP_SHORT = "beside a step: the thin coating model's springs bound it there"
#: A largest pressure within this many coating thicknesses of a step is beside it: the
#: resolved coating's pressure departs from the thin model's there (on the stepped
#: preset, 20 mm of coating: the thin model's 791 kPa 3 mm from the step, the resolved
#: 893 kPa at 5 mm and 1.87 MPa at 1 mm, an engineer's audit).
STEP_REACH = 2.0


def thin_edge_note(line: LimitCheck, half_width: float, coating_model: str | None,
                   short: bool = False, dimensional: Mapping[str, Any] | None = None) -> str:
    """:data:`THIN_EDGE_NOTE` (``short``: :data:`THIN_EDGE_SHORT`) when the largest
    pressure ``line`` (``q_max``, its ``x`` [m] from the punch's centre) lies at the edge
    of a punch of ``half_width`` [m] answered by the thin coating model;
    :data:`THIN_STEP_NOTE` (:data:`THIN_STEP_SHORT`) when it lies within
    :data:`STEP_REACH` coating thicknesses of a step of the gap (``dimensional``: the
    answer's ``info["dimensional"]``, its ``gap_steps_m`` and
    ``coating_thickness_max_m``; a check passed at 0.988 of the allowable pressure 3 mm
    from the stepped preset's step, where the FE check's coating exceeds it within ~5 mm,
    and nothing was said); else "".

    The model's springs make q finite at a rigid corner where the resolved coating's is
    not (q ~ 1 / sqrt(distance) under a flat punch): an engineer's check of
    ``allowable_pressure`` read a finite utilisation there, and nothing said it was the
    model's (a 0.01 % change of the coating modulus turned an answer of the exact kernel,
    "unbounded at the corner", into one of the thin layer with a utilisation of 2.7).
    """
    if coating_model != THIN_LAYER or line.x is None or line.unbounded:
        return ""
    x = float(line.x)
    if abs(abs(x) - half_width) <= 1e-9 * half_width:
        return THIN_EDGE_SHORT if short else THIN_EDGE_NOTE
    info = dimensional or {}
    reach = STEP_REACH * float(info.get("coating_thickness_max_m", 0.0))
    if any(abs(x - float(step)) <= reach for step in info.get("gap_steps_m", ())):
        return THIN_STEP_SHORT if short else THIN_STEP_NOTE
    return ""


def largest_pressure(result: Any) -> LimitCheck:
    """The largest contact pressure of a :class:`~core.scene.SceneSolution` over its whole
    history (the design check's ``q_max`` line without a limit): unbounded at a rigid
    corner in contact."""
    return check_design(result.times, result.x, result.pressure_on_grid, result.settlement,
                        result.tilt, None, result.info.get("corner_pressure"),
                        answer_accuracy(result.info)).check("q_max")


def design_check(result: Any, limits: DesignLimits | None = None) -> DesignCheck:
    """The design check of a :class:`~core.scene.SceneSolution` over its whole history:
    the pressure on its plotting grid ``x`` [m] at every output time, its settlement and
    tilt histories (round-off shown as zero, :func:`without_round_off`), against
    ``limits`` (default: the scene's ``limits``, else none)."""
    if limits is None:
        limits = getattr(result.scene, "limits", None)
    histories = without_round_off({q: getattr(result, q) for q in ROUND_OFF_PARTNERS},
                                  result.scene.half_width)
    return check_design(result.times, result.x, result.pressure_on_grid,
                        histories["settlement"], histories["tilt"], limits,
                        result.info.get("corner_pressure"), answer_accuracy(result.info))


#: Each history and the partner that sets its scale, with the factor of the half-width
#: ``a`` [m] that brings the partner to its unit: settlement [m] and tilt [rad] (a tilt
#: moves the punch's edge by a alpha), force [N/m] and moment [N·m/m].
ROUND_OFF_PARTNERS: Mapping[str, tuple[str, int]] = {
    "settlement": ("tilt", 1), "tilt": ("settlement", -1),
    "force": ("moment", -1), "moment": ("force", 1)}
#: A history whose largest magnitude is at most this share of its partner's (in its unit)
#: is round-off of zero: a centred load's tilt came out -3e-21 rad beside a settlement of
#: 5e-5 m, and the design check read "largest tilt -3.008e-18 mrad, utilisation 3e-18".
ROUND_OFF = 1e-10


def without_round_off(histories: Mapping[str, Any], half_width: float
                      ) -> dict[str, np.ndarray]:
    """``histories`` (any of settlement [m], tilt [rad], force [N/m], moment [N·m/m]
    over time) with each that is round-off next to its partner (:data:`ROUND_OFF`,
    :data:`ROUND_OFF_PARTNERS`) set to exact zeros; the others as given (new arrays).
    What is shown and checked; the answer's own arrays and the files keep the solver's
    numbers."""
    values = {q: np.array(v, dtype=float) for q, v in histories.items()}
    peak = {q: float(np.max(np.abs(v))) if v.size else 0.0 for q, v in values.items()}
    for q, v in values.items():
        partner, power = ROUND_OFF_PARTNERS[q]
        if partner not in peak:
            continue
        scale = peak[partner] * float(half_width) ** power
        if 0 < peak[q] <= ROUND_OFF * scale:
            values[q] = np.zeros_like(v)
    return values
