"""The loading part of the explorer's state: which two quantities are given, and the
history of each.

Plain ``param`` classes holding the values in the units shown on screen (mm, mrad, kN/m,
kN·m/m) and turning them into the ``loading`` part of the SI scene dictionary (and back).
Nothing here imports Panel.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

import param

from core.problem import QUANTITIES
from core.profiles import HISTORY_FORMS, history_form_of

#: The four statements (which two quantities are given), as shown on screen.
STATEMENTS: dict[str, tuple[str, str]] = {
    "settlement + tilt given": ("settlement", "tilt"),
    "settlement + moment given": ("settlement", "moment"),
    "tilt + force given": ("tilt", "force"),
    "force + moment given": ("force", "moment"),
}


#: Display unit and its size in SI for each loading quantity.
QUANTITY_UNITS: dict[str, tuple[str, float]] = {
    "settlement": ("mm", 1e-3),
    "tilt": ("mrad", 1e-3),
    "force": ("kN/m", 1e3),
    "moment": ("kN·m/m", 1e3),
}

#: Default soft range of each loading quantity's main value, in display units.
QUANTITY_RANGES: dict[str, tuple[float, float]] = {
    "settlement": (0.0, 0.2),
    "tilt": (-0.1, 0.1),
    "force": (0.0, 2000.0),
    "moment": (-500.0, 500.0),
}


#: The amplitude a sine chosen on the page starts at, as a share of its mean, where the
#: history had no "second" value (a constant).
SINE_SHARE = 0.2
#: The value after a step chosen on the page, as a multiple of the value before it, where
#: the history had no "second" value: 0 took a force away at 10 days, which no contact
#: carries with a moment left ("M = 120 kN·m/m with no force", an engineer's audit).
STEP_FACTOR = 2.0
#: At most this many periods of a sine chosen on the page over the time span (its period
#: is lengthened to span / SINE_PERIODS where it had more): the page's 10 days over the
#: 50-year preset, 1826 periods, ran 28 s into the time stepping's limit and was refused;
#: 40 periods of 457 days there solve in 0.8 s (tol 1e-4).
SINE_PERIODS = 40


class HistoryState(param.Parameterized):
    """The history of one loading quantity, ``t`` in days after loading (display units)."""

    kind = param.Selector(default="constant", objects=[*HISTORY_FORMS, "custom"],
                          doc="Shape of the history.")
    value = param.Number(default=0.0, doc="Main level: the constant, the ramp's final "
                                          "value, the value before a step, the sine's mean.")
    second = param.Number(default=0.0, doc="Ramp start value, value after a step, or sine "
                                           "amplitude (display units).")
    time = param.Number(default=10.0, softbounds=(0.1, 1000.0),
                        doc="Ramp duration, step time or sine period [days].")
    custom = param.Parameter(default=None, doc="A history spec (SI) kept verbatim.")

    def __init__(self, quantity: str, **params: Any) -> None:
        super().__init__(**params)
        self.quantity = quantity
        self.unit, self.scale = QUANTITY_UNITS[quantity]
        self._loading = False  # load_spec sets the history as a file gives it
        #: the time span of the scene [days] (set by the state that holds the history)
        self.span: Callable[[], float] = lambda: 365.0
        self.param.watch(self._on_kind, "kind")

    def _on_kind(self, event: Any) -> None:
        """A kind chosen on the page starts from values that solve: ``second`` is a load
        for a ramp (its start: 0) and a step (the value after it: STEP_FACTOR times the
        one before), a departure for a sine (its amplitude: SINE_SHARE of its mean), so it
        is set afresh at every choice. A sine once took the "after the step" value of
        1000 kN/m as its amplitude about 500 ("the punch is pulled away"), and from a
        constant an amplitude of 0 (a teacher saw nothing change). A sine's period is at
        most span / SINE_PERIODS. A file's history keeps its own values."""
        new = event.new
        if self._loading or new not in ("ramp", "step", "sine"):
            return
        # (every choice afresh: a sine chosen again after a constant kept an amplitude of
        # 100 about a mean typed down to 50, and a period of 10 days over a span widened
        # to 50 years since: a review)
        values: dict[str, float] = {"second": {"sine": SINE_SHARE, "step": STEP_FACTOR,
                                               "ramp": 0.0}[new] * self.value}
        if new == "sine" and self.time > 0 and self.span() / self.time > SINE_PERIODS:
            values["time"] = float(f"{self.span() / SINE_PERIODS:.3g}")
        self.param.update(**values)

    def to_spec(self) -> float | dict[str, Any]:
        if self.kind == "custom" and self.custom is not None:
            return copy.deepcopy(self.custom)
        form = HISTORY_FORMS.get(self.kind, HISTORY_FORMS["constant"])
        return form.spec({"value": self.value * self.scale, "second": self.second * self.scale,
                          "time": self.time})

    def load_spec(self, spec: Any) -> None:
        values: dict[str, Any] = {"kind": "custom", "custom": copy.deepcopy(spec)}
        found = history_form_of(spec)
        if found is not None:
            name, numbers = found
            values = {**numbers, "kind": name, "custom": None}
            for key in ("value", "second"):  # SI to display units; times are days
                if key in values:
                    values[key] = values[key] / self.scale
        self._loading = True
        try:
            self.param.update(**values)
        finally:
            self._loading = False


class LoadingState(param.Parameterized):
    """Which two quantities are given, and the history of each of the four."""

    statement = param.Selector(default="force + moment given", objects=list(STATEMENTS),
                               doc="Which two of settlement, tilt, force, moment are given.")

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        defaults = {"settlement": 0.05, "tilt": 0.0, "force": 500.0, "moment": 0.0}
        self.histories = {q: HistoryState(q, value=defaults[q], name=q) for q in QUANTITIES}

    @property
    def given(self) -> tuple[str, str]:
        return STATEMENTS[self.statement]

    @property
    def unknowns(self) -> tuple[str, str]:
        given = self.given
        first, second = (q for q in QUANTITIES if q not in given)
        return first, second

    def to_dict(self) -> dict[str, Any]:
        return {q: self.histories[q].to_spec() for q in self.given}

    def load(self, loading: dict[str, Any]) -> None:
        keys = set(loading)
        for label, pair in STATEMENTS.items():
            if set(pair) == keys:
                statement = label
                break
        else:
            raise ValueError("loading: exactly two of settlement, tilt, force, moment, as "
                             "one of the pairs settlement+tilt, settlement+moment, "
                             "tilt+force, force+moment, got " + ", ".join(sorted(keys)))
        for q, spec in loading.items():
            self.histories[q].load_spec(spec)
        self.statement = statement
