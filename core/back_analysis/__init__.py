"""Back-analysis: fit scene fields to measured settlements and tilts, with the
uncertainty of the fitted values and a forecast with a band.

``calibrate(scene, measurements, fit=[PATH, ...], bounds=None)`` (``fit.py``) fits the
scene fields named by their paths (as a study's ``vary``: ``coating[0].modulus``,
``base.creep.relative_humidity``, ``base.age_at_loading``) by weighted nonlinear least
squares and returns a :class:`Calibration`: ``.values``, ``.standard_errors``,
``.correlation``, ``.scene`` (the fitted scene), ``.forecast(times)``, ``.to_dict()``
and ``.summary()``.

- ``readings.py``: the readings (CSV or JSON, format in ``core/SCENES.md``, "Readings
  files"), checked row by row;
- ``model.py``: the fitted fields (log coordinates for positive fields) and the scene's
  answer at the reading times, with its finite-difference Jacobian;
- ``fit.py``: the least-squares fit, the covariance from the Jacobian, the warnings
  (not identifiable, a bound reached, the solver's error near the noise);
- ``result.py``: :class:`Calibration` and :class:`Forecast` (the delta-method band).
"""

from __future__ import annotations

from core.back_analysis.fit import MAX_CONDITION, MAX_SOLVER_ERROR_TO_NOISE, calibrate
from core.back_analysis.model import FD_STEP, FIT_SOLVER_TOL
from core.back_analysis.readings import (
    Readings,
    read_readings,
    readings_csv,
    readings_from_csv,
    readings_from_mapping,
    readings_from_text,
)
from core.back_analysis.result import (
    BAND_LEVEL,
    NOT_DETERMINED,
    Calibration,
    Forecast,
    quantile,
)

__all__ = [
    "BAND_LEVEL",
    "NOT_DETERMINED",
    "calibrate",
    "Calibration",
    "FD_STEP",
    "FIT_SOLVER_TOL",
    "Forecast",
    "quantile",
    "MAX_CONDITION",
    "MAX_SOLVER_ERROR_TO_NOISE",
    "read_readings",
    "Readings",
    "readings_csv",
    "readings_from_csv",
    "readings_from_mapping",
    "readings_from_text",
]
