"""The answer of a back-analysis (:class:`Calibration`) and its forecast with a band
(:class:`Forecast`), each with a JSON-able ``to_dict()`` carrying units and a short text
summary."""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from core.back_analysis.readings import SERIES_UNITS, Readings
from core.scene import Scene, SceneSolution, at_output_times, provenance, scene_from_dict
from core.study import apply_point
from core.validation import show_value

if TYPE_CHECKING:
    from core.back_analysis.model import Field, Model

#: The default confidence level of a forecast's band.
BAND_LEVEL = 0.95
#: In place of the interval of a field the readings do not determine
#: (:meth:`Calibration.determined_intervals`).
NOT_DETERMINED = "not determined by the readings (see the warnings)"


def quantile(level: float, dof: int | None = None) -> float:
    """The factor ``z`` of a two-sided interval ``value -/+ z se`` of confidence ``level``.

    Parameters
    ----------
    level : float
        The confidence, in (0, 1).
    dof : int or None
        None where the readings' standard deviations were given (the covariance is
        known): the normal quantile (1.96 at 0.95). Else the fit's degrees of freedom
        ``n - p`` of the noise estimated from the residuals: Student's t quantile, which
        accounts for that estimate's own scatter (3.18 at 0.95 with 3 degrees of freedom,
        where 1.96 covers 86 %).
    """
    # (scipy.special: the quantiles without importing scipy.stats)
    from scipy.special import ndtri, stdtrit

    level = _level(level)
    if dof is not None and (isinstance(dof, bool) or not isinstance(dof, numbers.Integral)
                            or dof < 1):
        raise ValueError(f"dof: must be a whole number >= 1 (or None), got {show_value(dof)}")
    p = 0.5 + level / 2
    return float(ndtri(p) if dof is None else stdtrit(int(dof), p))


def _level(level: Any) -> float:
    """``level`` as a confidence in (0, 1), else a ValueError naming it."""
    try:
        value = float(level)
    except (TypeError, ValueError):
        raise ValueError(f"level: must be a number in (0, 1), got {show_value(level)}"
                         ) from None
    if not 0 < value < 1:
        raise ValueError(f"level: must be in (0, 1), got {show_value(level)}")
    return value


def _jsonable_array(values: np.ndarray) -> list[float | None]:
    return [None if not math.isfinite(v) else float(v) for v in np.asarray(values, float)]


@dataclass(frozen=True, eq=False)
class Forecast:
    """The fitted scene's settlement [m] and tilt [rad] at ``times`` [day after loading]
    with their standard deviations from the fitted fields' covariance (linearised: the
    delta method, the gradient by central differences, as the covariance) and the band
    ``value -/+ z std`` of confidence ``level`` (``z``: :func:`quantile` of the fit's
    degrees of freedom ``dof``, None where the readings' standard deviations were given).
    The band is the uncertainty of the fitted fields alone: not the model's error nor the
    scatter of future readings."""

    times: np.ndarray
    settlement: np.ndarray
    tilt: np.ndarray
    settlement_std: np.ndarray
    tilt_std: np.ndarray
    level: float
    solution: SceneSolution = field(repr=False)
    dof: int | None = None

    @property
    def z(self) -> float:
        """The quantile of the band's two-sided ``level`` (:func:`quantile`)."""
        return quantile(self.level, self.dof)

    def band(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """The lower and upper edge of the band of ``settlement`` or ``tilt``."""
        value, std = getattr(self, name), getattr(self, f"{name}_std")
        return value - self.z * std, value + self.z * std

    def to_dict(self) -> dict[str, Any]:
        """The forecast as JSON-able lists with units."""
        # the band's factor and what it is (Student's t of dof, or normal: null)
        out: dict[str, Any] = {"times": self.times.tolist(), "level": self.level,
                               "dof": self.dof, "z": self.z}
        for name in SERIES_UNITS:
            lower, upper = self.band(name)
            out |= {name: _jsonable_array(getattr(self, name)),
                    f"{name}_std": _jsonable_array(getattr(self, f"{name}_std")),
                    f"{name}_lower": _jsonable_array(lower),
                    f"{name}_upper": _jsonable_array(upper)}
        out["units"] = {"times": "day (after loading)",
                        **{f"{name}{suffix}": unit for name, unit in SERIES_UNITS.items()
                           for suffix in ("", "_std", "_lower", "_upper")}}
        return out


@dataclass(frozen=True, eq=False)
class Calibration:
    """The answer of :func:`core.back_analysis.calibrate`.

    ``values``, ``standard_errors`` (dicts by path, in each field's unit, the standard
    error of a log-fitted field by the delta method ``value * se(log value)``),
    ``correlation`` (rows and columns in the order of ``paths``), ``residuals`` (model
    minus reading per series, NaN where a row has none), ``chi2`` (the weighted
    residuals' sum of squares: without deviations the weights are the largest reading's,
    an arbitrary scale, and the JSON leaves it out), ``dof`` and
    ``chi2_per_dof``, ``warnings`` (not identifiable, a bound reached, the solver's error
    near the noise, ...), ``scene`` (the fitted scene, with the original output times)
    and :meth:`forecast`. ``std_given`` says which covariance: ``(J^T J)^-1`` with the
    readings' standard deviations, else ``s^2 (J^T J)^-1`` with ``s^2 = chi^2 / dof``.
    """

    fields: tuple[Field, ...]
    x: np.ndarray
    cov_x: np.ndarray
    readings: Readings
    base: dict
    work: dict
    predicted: dict[str, np.ndarray]
    residuals: dict[str, np.ndarray]
    start_residuals: dict[str, np.ndarray]
    chi2: float
    dof: int
    std_given: bool
    noise_scale: float
    condition: float
    solver_error_to_noise: float
    warnings: tuple[str, ...]
    unidentified: tuple[str, ...]
    #: What stands for the interval of a field the readings do not determine.
    not_determined: ClassVar[str] = NOT_DETERMINED
    solves: int
    seconds: float
    iterations: int
    status: str
    model: Model = field(repr=False)
    sigma: np.ndarray = field(repr=False)
    #: The weighted residuals' Jacobian at the answer (readings x fields, the fit's
    #: coordinates; central differences where both sides are accepted).
    jacobian: np.ndarray | None = field(default=None, repr=False)

    def __getstate__(self) -> dict[str, Any]:
        # the cached fitted Scene holds read-only mappings, which do not pickle; it is
        # made again from ``base`` and the values on first use
        state = self.__dict__.copy()
        state.pop("scene", None)
        return state

    @property
    def paths(self) -> tuple[str, ...]:
        """The fitted fields' paths, in the order given."""
        return tuple(f.path for f in self.fields)

    @property
    def values(self) -> dict[str, float]:
        """The fitted values by path, in each field's unit."""
        return self.model.values_at(self.x)

    @property
    def start(self) -> dict[str, float]:
        """The scene's values of the fitted fields (the start of the fit)."""
        return {f.path: f.start for f in self.fields}

    @property
    def units(self) -> dict[str, str]:
        """The unit of each fitted field ("" when the field has none recorded)."""
        return {f.path: f.unit for f in self.fields}

    @cached_property
    def _derivative(self) -> np.ndarray:
        """d value / d coordinate of each field at the answer."""
        return np.array([f.to_value(v) if f.log else f.scale
                         for f, v in zip(self.fields, self.x, strict=True)])

    @cached_property
    def covariance(self) -> np.ndarray:
        """The covariance of the fitted values (linearised) [unit_i * unit_j]."""
        d = self._derivative
        return self.cov_x * np.outer(d, d)

    @property
    def standard_errors(self) -> dict[str, float]:
        """The standard error of each fitted value by path, in the field's unit."""
        se = np.sqrt(np.abs(np.diag(self.covariance)))
        return {f.path: float(s) for f, s in zip(self.fields, se, strict=True)}

    def intervals(self, level: float = BAND_LEVEL) -> dict[str, tuple[float, float]]:
        """The confidence interval of each fitted value by path, in the field's unit.

        ``x -/+ z se(x)`` in the fit's coordinate ``x`` (the logarithm of a log-fitted
        field: its interval is ``value * exp(-/+ z se(log value))``, positive and
        lopsided as the field's uncertainty is), with ``z`` the :func:`quantile` of
        ``level``: Student's t of the fit's degrees of freedom where the noise was
        estimated from the residuals (``std_given`` False), else the normal one.
        """
        z = quantile(level, None if self.std_given else self.dof)
        se = np.sqrt(np.abs(np.diag(self.cov_x)))

        def value(f: Field, x: float) -> float:
            try:
                return f.to_value(x)
            except OverflowError:  # exp of a log-fitted field's undetermined end
                return math.inf
        return {f.path: (value(f, x - z * e), value(f, x + z * e))
                for f, x, e in zip(self.fields, self.x, se, strict=True)}

    def determined_intervals(self, level: float = BAND_LEVEL
                             ) -> dict[str, tuple[float, float] | None]:
        """:meth:`intervals` as they may be shown: None for a field the readings do not
        determine (in :attr:`unidentified`: a bound reached, a combination not
        identifiable, a derivative not resolved; its standard error does not hold, nor
        an interval made from it: a fit ended at its lower bound of 28 GPa read "95 %
        interval 27.2 to 28.8 GPa") or whose interval has an infinite end."""
        out: dict[str, tuple[float, float] | None] = {}
        for path, (low, high) in self.intervals(level).items():
            out[path] = (None if path in self.unidentified
                         or not (math.isfinite(low) and math.isfinite(high)) else (low, high))
        return out

    @property
    def correlation(self) -> np.ndarray:
        """The correlation of the fitted values (the order of :attr:`paths`)."""
        se = np.sqrt(np.abs(np.diag(self.cov_x)))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = self.cov_x / np.outer(se, se)
        np.fill_diagonal(corr, 1.0)
        return corr

    @property
    def chi2_per_dof(self) -> float:
        """chi^2 over the degrees of freedom (readings minus fitted fields): near 1 when
        the stated standard deviations match the scatter. NaN when no deviations are
        given: the noise is then estimated from the scatter (:attr:`noise`), which makes
        chi^2/dof 1 by construction, and the weights' scale is arbitrary (it read
        0.0006, as if the model fitted far too well); and with as many readings as
        fields (no degree of freedom left: the fit passes through them)."""
        return self.chi2 / self.dof if self.std_given and self.dof > 0 else math.nan

    @property
    def chi2_text(self) -> str:
        """chi^2/dof as the summary, the report and the page give it (with deviations
        given): its value and degrees of freedom, or why there is none."""
        if self.dof == 0:
            return "none (as many readings as fitted fields: the deviations are not checked)"
        return f"{self.chi2_per_dof:.3g} ({self.dof} dof)"

    @property
    def identifiable(self) -> bool:
        """Whether the readings determine every field: none is in :attr:`unidentified`
        (a combination of fields not identifiable, a bound reached, a standard error
        beyond a factor e, no resolved influence on the readings)."""
        return not self.unidentified

    @property
    def noise(self) -> dict[str, float]:
        """The noise the standard errors assume: per series, the standard deviation of
        a reading [its unit] (the median of those given, or the scatter about the fit)."""
        out = {}
        m = self.readings.time.size
        for k, name in enumerate(self.readings.series):
            sigma = self.sigma[k * m:(k + 1) * m]
            given = np.isfinite(getattr(self.readings, name))
            out[name] = float(np.median(sigma[given])) * self.noise_scale
        return out

    @cached_property
    def scene(self) -> Scene:
        """The fitted scene: the scene given, the fitted values set (its own times and
        solver settings)."""
        return scene_from_dict(apply_point(self.base, self.values))

    @property
    def solution(self) -> SceneSolution:
        """The fitted scene's answer at the reading times (the fit's solver tolerance)."""
        return self.model.solve(self.x)

    def forecast(self, times: Sequence[float] | np.ndarray | Mapping[str, Any],
                 level: float = BAND_LEVEL) -> Forecast:
        """The fitted scene's settlement and tilt at ``times`` with a band.

        Parameters
        ----------
        times : list of float or dict
            Days after loading (strictly increasing, >= 0), or a scene's ``times``
            object (``{"end": 18262.5, "count": 100, "spacing": "log"}``).
        level : float
            Confidence of the band, in (0, 1).

        Returns
        -------
        Forecast
            Values, standard deviations (delta method, central differences) and the
            band; one solve plus two per fitted field.
        """
        from core.back_analysis.model import Model, central

        level = _level(level)
        if not isinstance(times, Mapping):
            times = [float(t) for t in np.asarray(times, dtype=float).ravel()]
        try:
            scene_from_dict(at_output_times(self.work, times))
        except ValueError as exc:
            msg = str(exc)
            raise ValueError(msg if msg.startswith("times") else f"times: {msg}") from None
        model = Model(self.work, self.fields, tuple(SERIES_UNITS), times)
        centre = model.values(self.x)
        # central differences where both sides are points the scene accepts, as the
        # covariance was taken (core.back_analysis.fit)
        gradient = central(*model.two_sided(self.x, centre))
        std = np.sqrt(np.maximum(self._forecast_variance(gradient), 0.0))
        solution = model.solve(self.x)
        m = solution.times.size
        return Forecast(np.asarray(solution.times, dtype=float), centre[:m], centre[m:],
                        std[:m], std[m:], float(level), solution,
                        None if self.std_given else self.dof)

    def _forecast_variance(self, gradient: np.ndarray) -> np.ndarray:
        """``g^T cov g`` of each row ``g`` of ``gradient`` (outputs x fields, by the fit's
        coordinates). Along a combination of the fields the finite differences do not
        resolve (:data:`~core.back_analysis.model.RESOLVED_SINGULAR_SHARE`), the
        covariance is their round-off (~1e24 for a coating's thickness and modulus): a
        forecast is then given a band from the resolved combinations alone when its
        gradient's share along the others is at most
        :data:`~core.back_analysis.model.UNDETERMINED_SHARE` (it depends on what the
        readings fix: the ratio of thickness and modulus), and none (infinite) otherwise.
        Through the covariance a forecast band read -0.04 to 0.04 m for a settlement of
        4.1e-5 m."""
        from core.back_analysis.model import (
            RESOLVED_SINGULAR_SHARE,
            UNDETERMINED_SHARE,
            scaled_svd,
        )

        whole = np.einsum("ij,jk,ik->i", gradient, self.cov_x, gradient)
        if self.jacobian is None:
            return whole
        _, safe, _, sv, vt = scaled_svd(self.jacobian)
        keep = sv >= sv[0] * RESOLVED_SINGULAR_SHARE if sv[0] > 0 else np.zeros(sv.size, bool)
        if keep.all():
            return whole
        along = (gradient / safe) @ vt.T                      # (outputs, directions)
        size = np.linalg.norm(along, axis=1)
        var = self.noise_scale ** 2 * np.sum(
            along[:, keep] ** 2 / np.where(keep, sv, 1.0)[keep] ** 2, axis=1)
        undetermined = np.linalg.norm(along[:, ~keep], axis=1) > UNDETERMINED_SHARE * size
        return np.where(undetermined, np.inf, var)

    def to_dict(self) -> dict[str, Any]:
        """The fit as JSON-able data with units: the fields (start, value, standard
        error, bounds, unit), the correlation, the readings with the fitted values and
        residuals, the goodness of fit, the warnings, the fitted scene and the
        provenance (program version, scene, solver settings)."""
        se = self.standard_errors
        intervals = self.intervals()
        fields = [{"path": f.path, "unit": f.unit, "start": f.start,
                   "value": self.values[f.path], "standard_error": se[f.path],
                   f"interval_{round(100 * BAND_LEVEL)}": _jsonable_array(
                       np.array(intervals[f.path])),
                   "bounds": [f.bounds[0] if math.isfinite(f.bounds[0]) else None,
                              f.bounds[1] if math.isfinite(f.bounds[1]) else None],
                   "fitted_as": "log" if f.log else "linear"} for f in self.fields]
        readings = self.readings.to_dict()
        for name in self.readings.series:
            readings[f"{name}_fitted"] = _jsonable_array(self.predicted[name])
            readings[f"{name}_residual"] = _jsonable_array(self.residuals[name])
            readings["units"] |= {f"{name}_fitted": SERIES_UNITS[name],
                                  f"{name}_residual": SERIES_UNITS[name]}
        corr = self.correlation
        return {
            **provenance(self.scene),
            "fields": fields,
            "correlation": [[None if not math.isfinite(v) else float(v) for v in row]
                            for row in corr],
            "goodness_of_fit": {
                # no chi^2 without deviations (chi2_per_dof)
                "chi2": self.chi2 if self.std_given else None, "dof": self.dof,
                "chi2_per_dof": (self.chi2_per_dof if math.isfinite(self.chi2_per_dof)
                                 else None),
                "covariance": "(J^T J)^-1, the readings' standard deviations"
                if self.std_given else "s^2 (J^T J)^-1, s^2 = the residuals' sum of "
                                       "squares / dof (noise estimated from them)",
                "noise": self.noise,
                "condition_number": self.condition if math.isfinite(self.condition)
                else None,
                "solver_error_to_noise": self.solver_error_to_noise
                if math.isfinite(self.solver_error_to_noise) else None,
                "identifiable": self.identifiable,
                "unidentified": list(self.unidentified),
            },
            "readings": readings,
            "warnings": list(self.warnings),
            "work": {"solves": self.solves, "seconds": self.seconds,
                     "evaluations": self.iterations, "status": self.status,
                     "solver_tol": self.work["solver"]["tol"]},
            "fitted_scene": self.scene.to_dict(),
        }

    def summary(self) -> str:
        """A short text summary: each field's value and standard error, the goodness of
        fit and the warnings."""
        se = self.standard_errors
        intervals = self.determined_intervals()
        width = max(len(p) for p in self.paths)
        n = self.readings.count
        lines = [f"fitted {len(self.fields)} field(s) to {n} reading(s) "
                 f"({', '.join(self.readings.series)}) in {self.solves} solves, "
                 f"{self.seconds:.2f} s"]
        for f in self.fields:
            value = self.values[f.path]
            rel = se[f.path] / abs(value) if value else math.inf
            shown = intervals[f.path]
            interval = (NOT_DETERMINED if shown is None
                        else f"{shown[0]:.4g} to {shown[1]:.4g}")
            lines.append(f"  {f.path:<{width}} = {value:.6g} +/- {se[f.path]:.2g} "
                         f"{f.unit}".rstrip() + f"  ({100 * rel:.2g} %; "
                         f"{100 * BAND_LEVEL:g} % interval {interval}; start "
                         f"{f.start:.6g})")
        if len(self.fields) > 1:
            corr = self.correlation
            pairs = [f"{self.paths[j]} ~ {self.paths[k]}: {corr[j, k]:+.3f}"
                     for j in range(len(self.fields)) for k in range(j + 1, len(self.fields))]
            lines.append("correlations: " + "; ".join(pairs))
        noise = ", ".join(f"{name} {v:.3g} {SERIES_UNITS[name]}"
                          for name, v in self.noise.items())
        lines.append((f"chi^2/dof = {self.chi2_text}; noise given: "
                      if self.std_given else
                      f"noise estimated from the scatter about the fit ({self.dof} dof): ")
                     + f"{noise}; solver error / noise = {self.solver_error_to_noise:.2g}")
        for name in self.readings.series:
            rms = float(np.sqrt(np.nanmean(self.residuals[name] ** 2)))
            lines.append(f"rms residual of {name}: {rms:.3g} {SERIES_UNITS[name]}")
        lines.extend(f"warning: {w}" for w in self.warnings)
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.summary()
