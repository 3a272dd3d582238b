"""The Fit tab's back-analysis: readings uploaded, scene fields fitted to them.

:func:`read_upload` reads a readings file (``core.back_analysis.readings_from_text``:
a ``ValueError`` naming the line and the column), :func:`fit_choices` lists the fields
the tab offers (the Study tab's, :func:`explorer.model.study.study_choices`, without the
derived eccentricity: a fit sets scene fields), :func:`plan_fit` checks the fields chosen
and :func:`run_fit` fits them with ``core.calibrate`` and forecasts the fitted scene over
the scene's output times. The rest turns readings, fit and forecast into the numbers the
page shows, in display units (mm, mrad, the fields' units on screen).

Nothing here imports Panel (the fit runs on a thread of the server).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from core.back_analysis import (
    MAX_CONDITION,
    NOT_DETERMINED,
    Calibration,
    Forecast,
    Readings,
    calibrate,
    readings_from_text,
)
from core.limits import MAX_READINGS_BYTES
from core.scene import days_text, number_text, scene_from_dict
from core.study import apply_point, number_at

from .loading_state import QUANTITY_UNITS
from .scene_parts import MAX_DESCRIPTION_CHARS, MAX_NAME_CHARS
from .study import ECCENTRICITY, Choice, study_choices

#: Most fields one fit of the page fits: each costs one more solve per step of the fit
#: (its finite-difference column) and three already take up to ~6 s (measured on the
#: default preset's creeping base).
MAX_FIT_FIELDS = 3
#: The series a readings file holds, as the page draws them.
SERIES = ("settlement", "tilt")


def read_upload(data: bytes, filename: str) -> Readings:
    """The readings of an uploaded file (CSV or JSON, ``core/SCENES.md``, "Readings
    files"). Raises ValueError naming the file, the line and the column."""
    name = filename or "readings"
    if len(data) > MAX_READINGS_BYTES:
        raise ValueError(f"{name}: {len(data):,} bytes, more than a readings file may hold "
                         f"({MAX_READINGS_BYTES:,})")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{name}: not a text file in UTF-8 (readings are CSV or JSON)") \
            from None
    return readings_from_text(text, name)


def fit_choices(scene: Mapping[str, Any]) -> list[Choice]:
    """The fields of ``scene`` the tab can fit (the Study tab's fields, scene paths)."""
    return [c for c in study_choices(scene) if c.key != ECCENTRICITY]


def plan_fit(scene: Mapping[str, Any], keys: Sequence[str | None]) -> list[Choice]:
    """The fields chosen (``None`` entries left out), checked: one to
    :data:`MAX_FIT_FIELDS`, each a field of ``scene`` the tab offers, none twice.
    Raises ValueError naming the tab's field (``field 2: ...``)."""
    offered = {c.key: c for c in fit_choices(scene)}
    chosen: list[Choice] = []
    for i, key in enumerate(keys):
        if key is None:
            continue
        where = f"field {i + 1}"
        if key not in offered:
            raise ValueError(f"{where}: {key!r} is not a field of this scene the tab can fit")
        if any(c.key == key for c in chosen):
            raise ValueError(f"{where}: chosen twice; choose another field or none")
        chosen.append(offered[key])
    if not chosen:
        raise ValueError("field 1: choose a field to fit")
    if len(chosen) > MAX_FIT_FIELDS:
        raise ValueError(f"field {MAX_FIT_FIELDS + 1}: at most {MAX_FIT_FIELDS} fields")
    return chosen


@dataclass(frozen=True)
class FitOutcome:
    """A fit of the page: the core's :class:`~core.back_analysis.Calibration`, the
    forecast of the fitted scene over the scene's output times (None when it could not
    be made: ``forecast_error`` says why), the fields as the tab names them, and the
    wall time of fit and forecast [s]."""

    calibration: Calibration
    forecast: Forecast | None
    choices: tuple[Choice, ...]
    seconds: float
    forecast_error: str = ""

    def rows(self) -> list[tuple[str, str, str, str]]:
        """(field, fitted value, standard error, unit) of each field, in the units on
        screen."""
        values, errors = self.calibration.values, self.calibration.standard_errors
        out = []
        for c in self.choices:
            value, se = values[c.key] / c.scale, errors[c.key] / c.scale
            out.append((c.label, number_text(value, 4), _error_text(se), c.unit))
        return out

    def noise_text(self) -> str:
        """The noise the standard errors assume, per series, in the display unit (mm,
        mrad): the readings' deviations, or the scatter about the fit."""
        return ", ".join(f"{name} {number_text(v / QUANTITY_UNITS[name][1], 3)} "
                         f"{QUANTITY_UNITS[name][0]}"
                         for name, v in self.calibration.noise.items())

    def intervals(self) -> list[str]:
        """The confidence interval (:data:`core.back_analysis.BAND_LEVEL`) of each field,
        in the units on screen: Student's t where the noise was estimated from the
        scatter (:meth:`core.back_analysis.Calibration.intervals`)."""
        intervals = self.calibration.determined_intervals()
        out = []
        for c in self.choices:
            shown = intervals[c.key]
            if shown is None:  # (a bound reached: an interval past the bound was read)
                out.append(NOT_DETERMINED)
                continue
            low, high = (v / c.scale for v in shown)
            # (with its unit: the column read "24.84 to 25.4" beside "25.12 ± 0.12 GPa")
            out.append(f"{number_text(low, 4)} to {number_text(high, 4)} {c.unit}".rstrip())
        return out

    def correlations(self) -> list[tuple[str, str, float]]:
        """(field, field, correlation of their fitted values) of each pair."""
        corr = self.calibration.correlation
        n = len(self.choices)
        return [(self.choices[j].label, self.choices[k].label, float(corr[j, k]))
                for j in range(n) for k in range(j + 1, n)]

    def fitted_scene(self) -> dict[str, Any]:
        """The scene with the fitted values (the scene's own output times), named as
        fitted and saying from what: applied, it passed for the scene fitted (a saved
        file or report kept the preset's name)."""
        scene = self.calibration.scene.to_dict()
        # a fitted scene fitted again keeps one mark ("... (fitted) (fitted)")
        name = str(scene.get("name", "")).removesuffix(" (fitted)") or "scene"
        values = "; ".join(f"{label} = {value} ± {se} {unit}".rstrip()
                           for label, value, se, unit in self.rows())
        scene["name"] = f"{name[: MAX_NAME_CHARS - 9]} (fitted)"
        scene["description"] = (f"Fitted on screen to the readings "
                                f"{self.calibration.readings.source} from the scene "
                                f"“{name}”: {values}.")[:MAX_DESCRIPTION_CHARS]
        return scene

    @property
    def determined(self) -> bool:
        """Whether the readings determine every combination of the fields fitted (the
        condition number at most :data:`core.back_analysis.MAX_CONDITION`): else the
        fitted values are arbitrary along a combination (a coating's thickness and
        modulus, whose ratio alone counts, went to 11 m and 279 GPa), not a scene to
        apply."""
        return self.calibration.condition <= MAX_CONDITION

    def made_for(self, scene: Mapping[str, Any]) -> bool:
        """Whether ``scene`` (a scene dict on screen) is the scene this fit was made from
        or its fitted scene (names and descriptions aside): after any other change its
        values and forecast are of another scene, and applying it would set that scene
        back."""
        try:
            if _canonical(scene) == self._fitted_from:
                return True
        except ValueError:
            return False
        return self.describes(scene)

    @cached_property
    def _fitted_from(self) -> str:
        return _canonical(self.calibration.base)

    def describes(self, scene: Mapping[str, Any]) -> bool:
        """Whether ``scene`` (a scene dict on screen) is this fit's fitted scene: the
        fitted values in its fields (to a relative 1e-9: a slider's unit conversion
        rounds in the last digits) and, those set back to the start, the scene fitted.
        A report of any other scene must not carry the fit."""
        calibration = self.calibration
        try:
            for path, value in calibration.values.items():
                if not math.isclose(number_at(scene, path, "fit", "fitted"), value,
                                    rel_tol=FITTED_SCENE_RTOL):
                    return False
            restored = _canonical(apply_point(dict(scene), calibration.start))
            fitted = self._fitted_from
        except ValueError:  # a field fitted is not in the scene, or the scene is refused
            return False
        return restored == fitted


#: How close a field on screen must be to its fitted value to be that value (relative).
FITTED_SCENE_RTOL = 1e-9


def _canonical(scene: Mapping[str, Any]) -> str:
    """A scene as the core reads it (defaults filled in: the page leaves some out), as
    sorted JSON, its name and description left out (they do not change an answer)."""
    data = scene_from_dict(dict(scene)).to_dict()
    return json.dumps({k: v for k, v in data.items() if k not in ("name", "description")},
                      sort_keys=True)


def _error_text(se: float) -> str:
    """A standard error with two significant digits ('unbounded' when infinite)."""
    if not math.isfinite(se):
        return "unbounded"
    return f"{se:.2g}"


def run_fit(scene: Mapping[str, Any], readings: Readings, keys: Sequence[str | None]
            ) -> FitOutcome:
    """Fit the fields ``keys`` of ``scene`` (the scene dict on screen) to ``readings``
    and forecast the fitted scene over the scene's output times with its band.

    Raises ValueError (the tab's or the core's message, naming the field) when the fit
    cannot be made."""
    choices = plan_fit(scene, keys)
    started = time.perf_counter()
    calibration = calibrate(dict(scene), readings, fit=[c.key for c in choices])
    try:
        forecast, error = calibration.forecast(scene["times"]), ""
    except ValueError as exc:  # the fitted scene is refused at the scene's times
        forecast, error = None, str(exc)
    return FitOutcome(calibration, forecast, tuple(choices),
                      time.perf_counter() - started, error)


def readings_columns(readings: Readings | None) -> dict[str, dict[str, list[float]]]:
    """Per series (settlement, tilt): the rows with a reading as ``t`` [day], ``v`` and
    the error bar ``lower``/``upper`` (one standard deviation, ``v`` without one) in the
    display unit (mm, mrad). Empty lists for a series the readings do not hold."""
    out: dict[str, dict[str, list[float]]] = {}
    for name in SERIES:
        values = None if readings is None else getattr(readings, name)
        if values is None:
            out[name] = {"t": [], "v": [], "lower": [], "upper": []}
            continue
        size = QUANTITY_UNITS[name][1]
        given = np.isfinite(values)
        std = getattr(readings, f"{name}_std")
        spread = np.zeros_like(values) if std is None else np.nan_to_num(std)
        v = values[given] / size
        s = spread[given] / size
        out[name] = {"t": readings.time[given].tolist(), "v": v.tolist(),
                     "lower": (v - s).tolist(), "upper": (v + s).tolist()}
    return out


def forecast_columns(forecast: Forecast | None) -> dict[str, dict[str, list[float]]]:
    """Per series: the forecast ``v`` and its band ``lower``/``upper`` at ``t`` [day] in
    the display unit (empty lists without a forecast)."""
    out: dict[str, dict[str, list[float]]] = {}
    for name in SERIES:
        if forecast is None:
            out[name] = {"t": [], "v": [], "lower": [], "upper": []}
            continue
        size = QUANTITY_UNITS[name][1]
        # no band where the readings do not determine the forecast (an infinite one):
        # a gap in the drawn band
        lower, upper = (np.where(np.isfinite(edge), edge / size, np.nan)
                        for edge in forecast.band(name))
        out[name] = {"t": forecast.times.tolist(),
                     "v": (getattr(forecast, name) / size).tolist(),
                     "lower": lower.tolist(), "upper": upper.tolist()}
    return out


def readings_note(readings: Readings) -> str:
    """What a readings file holds, in words."""
    parts = []
    for name in readings.series:
        n = int(np.isfinite(getattr(readings, name)).sum())
        std = " with standard deviations" if getattr(readings, f"{name}_std") is not None \
            else ""
        parts.append(f"{n} {name} reading{'s' if n != 1 else ''}{std}")
    t = readings.time
    # (the days as the page writes every time: a 50-year record ended at "18260 days")
    return (f"{' and '.join(parts)} from t = {days_text(float(t[0]), years=False)} to "
            f"{days_text(float(t[-1]), years=False)} after loading")
