"""The fit: weighted nonlinear least squares of the scene's settlements and tilts to the
readings, and the uncertainty of the fitted fields from the Jacobian.

The residual of reading ``i`` is ``(model_i - reading_i) / sigma_i``. With standard
deviations given, ``sigma_i`` is the reading's and the covariance of the fitted
coordinates is ``(J^T J)^-1``; without them every reading of the one series weighs the
same and the covariance is ``s^2 (J^T J)^-1`` with ``s^2 = chi^2 / (n - p)``, the
scatter about the fit (the noise estimated from the residuals). ``J`` is the Jacobian of
the weighted residuals by forward differences (:mod:`core.back_analysis.model`) while the
fit moves, and at its answer by central differences, whose two sides measure how well the
derivatives are resolved (:data:`MAX_DERIVATIVE_SPREAD`).

The fit stops as soon as the Gauss-Newton step from its point is below
:data:`STEP_TO_SE` of every standard error (each iteration costs 1 + p solves; steps
far inside the uncertainty buy nothing), else at the least-squares solver's own
tolerances :data:`X_TOL` and :data:`F_TOL`, both relative (its gradient test, absolute on
the weighted residuals, is off: it stopped a flat start when the deviations were large,
and their overall size moves no minimum).
"""

from __future__ import annotations

import inspect
import math
import os
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from scipy.optimize import OptimizeResult, least_squares

from core.back_analysis.model import (
    FD_STEP,
    FIT_SOLVER_TOL,
    MAX_CONDITION,
    Field,
    Model,
    central,
    fitted_fields,
    scaled_svd,
)
from core.back_analysis.readings import Readings, as_readings
from core.back_analysis.result import Calibration
from core.limits import MAX_FIT_SOLVES
from core.scene import (
    PunchesScene,
    Scene,
    at_output_times,
    has_punches,
    load_scene,
    scene_from_dict,
)

#: Pairs more correlated than this are named in a warning, even when identifiable.
STRONG_CORRELATION = 0.99
#: The solver's error must be this far below the noise (as a fraction of the smallest
#: standard deviation, or of the scatter about the fit), or the fit says so.
MAX_SOLVER_ERROR_TO_NOISE = 0.1
#: The derivative of a field is resolved when the differences on either side of its
#: step agree to this fraction of the central difference: its standard error then holds
#: to about as much. Measured on smooth answers, the two sides differ by ~h/2 of the
#: curvature, 1e-4..1e-3 (a standard error's h/2 bias, 5e-4, seen against an independent
#: central difference).
MAX_DERIVATIVE_SPREAD = 0.1
#: A coordinate this close to a bound (in the fit's coordinates) is at the bound.
BOUND_CLOSENESS = 1e-6
#: How far beyond the answer (in the fit's coordinates: relative for a log-fitted field)
#: the scene is checked for the edge of its accepted values: the trust region stops
#: within ~1e-6 of such an edge (it sees only the large residual beyond it), and an
#: interior answer 1e-4 from an edge is determined by the readings.
EDGE_PROBE = 1e-4
#: Residual vector of a point whose scene is invalid: large, so that the trust region
#: shrinks away from it, finite, so that the least-squares solver goes on.
_INVALID_RESIDUAL = 1e8
#: Stopping tolerances of the least-squares solver on the fit's coordinates (relative)
#: and on the cost: a change of 1e-8 in a log coordinate is 1e-8 of the field, far below
#: any standard error a record of readings gives.
X_TOL = 1e-8
F_TOL = 1e-10
#: The fit stops once the Gauss-Newton step from its point is below this fraction of
#: every standard error (Bates and Watts' relative-offset criterion, at their 0.001): the
#: answer is then within ~1e-3 standard errors of the least-squares minimum, far inside
#: its uncertainty, and the last iteration (1 + p solves) or two are not paid. Measured
#: on the creeping footing of tests/back_analysis (two creep fields, 12 noise draws):
#: 137 -> 102 solves, the values within 2.4e-4 of their standard errors of the fit run to
#: ``X_TOL``, the standard errors within 5e-6 (relative). Exact readings without standard
#: deviations (residuals at the solver's level) make the standard errors tiny, and the fit
#: runs on to ``X_TOL``; so does a fit whose fields the readings do not determine (its
#: standard errors do not hold: :data:`MAX_CONDITION`).
STEP_TO_SE = 1e-3
#: Whether the installed SciPy's ``least_squares`` takes the callback that stops there
#: (from SciPy 1.16; with an older one the fit runs on to ``X_TOL``, as it did before).
STOPS_SETTLED = "callback" in inspect.signature(least_squares).parameters
#: The least-squares solver's message when that criterion stopped it.
SETTLED = (f"the Gauss-Newton step is below {STEP_TO_SE:g} of every standard error "
           "(relative offset)")
#: The message when it stopped a fit of fields the readings do not all determine: each
#: combination of them that the readings determine (a singular direction of the scaled
#: Jacobian within :data:`MAX_CONDITION` of the strongest) has settled, and along the
#: others the readings give no direction to go. Run on to X_TOL, such a fit took 55 solves
#: for a coating's thickness and modulus (whose ratio alone counts), now 11
#: (tests/back_analysis).
SETTLED_DETERMINED = (f"the Gauss-Newton step along each combination of the fields that "
                      f"the readings determine is below {STEP_TO_SE:g} of its standard "
                      "error (relative offset); the readings do not determine the others")

#: The fit's status when no fitted field moves any reading at its start.
NOTHING_MOVES = "no fitted field moves any reading at the start: nothing to fit"


def reading_times(readings: Readings) -> list[float]:
    """The readings' times [day after loading], the output times of the fit's solves."""
    return [float(t) for t in readings.time]


def _working_scene(scene: Scene | Mapping[str, Any] | str | os.PathLike,
                   readings: Readings) -> tuple[dict, dict]:
    """The canonical scene dict and the dict the fit's values are set on: the solver
    tolerance at most :data:`FIT_SOLVER_TOL`, the scene's own output times (the fit
    solves it at the readings' times, each load the same function of time:
    :class:`~core.back_analysis.model.Model`)."""
    if isinstance(scene, (str, os.PathLike)):
        scene = load_scene(scene)  # its messages start with the file's path
    if isinstance(scene, PunchesScene) or (isinstance(scene, Mapping) and has_punches(scene)):
        punches = scene.scenes if isinstance(scene, PunchesScene) else scene["punches"]
        count = len(punches) if isinstance(punches, (list, tuple)) else 0
        if count > 1:
            raise ValueError(f"scene: holds {count} punches (punches); a fit takes a scene "
                             "of one punch, whose readings are its settlement and tilt")
        raise ValueError("scene: is written in the form of several punches (punches); a fit "
                         "takes a scene of one punch written with punch and loading")
    try:
        base = scene_from_dict(scene).to_dict()
    except ValueError as exc:
        # (a message of the scene's own starts "scene: " already)
        raise ValueError(str(exc) if str(exc).startswith("scene") else f"scene: {exc}") from None
    work = dict(base)
    solver = dict(work.get("solver", {}))
    solver["tol"] = min(float(solver.get("tol", FIT_SOLVER_TOL)), FIT_SOLVER_TOL)
    work["solver"] = solver
    try:
        scene_from_dict(at_output_times(work, reading_times(readings)))
    except ValueError as exc:
        text = str(exc)
        if text.startswith("times["):  # the scene's output times are the readings'
            raise ValueError(f"measurements: time{text.removeprefix('times')}: the scene "
                             "cannot be solved at this reading's time") from None
        raise ValueError(f"measurements: the scene cannot be solved at the reading times "
                         f"({text})") from None
    return base, work


def _weights(readings: Readings) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """The readings stacked as the model's values are (``mask`` picks those given), their
    ``sigma`` and whether those are the readings' standard deviations."""
    series = readings.series
    given = readings.has_std
    if len(series) > 1 and not given:
        missing = next(f"{name}_std" for name in series
                       if getattr(readings, f"{name}_std") is None)
        raise ValueError(f"{missing}: required when both settlements and tilts are fitted "
                         "(without standard deviations the weight of metres against "
                         "radians is unknown): add the settlement_std and tilt_std "
                         "columns, or leave out the series not to fit (a history this "
                         "program wrote holds both)")
    y = np.concatenate([getattr(readings, name) for name in series])
    mask = np.isfinite(y)
    if given:
        sigma = np.concatenate([getattr(readings, f"{name}_std") for name in series])
    else:
        # one series, equal weights: the scale cancels in s^2 (J^T J)^-1; the largest
        # reading keeps the residuals of order one for the solver's tolerances
        scale = float(np.max(np.abs(y[mask]))) or 1.0
        sigma = np.full(y.shape, scale)
    return y, mask, sigma, given


def calibrate(scene: Scene | Mapping[str, Any] | str | os.PathLike,
              measurements: Readings | Mapping[str, Any] | str | os.PathLike,
              fit: Sequence[str], bounds: Mapping[str, Sequence[float | None]] | None = None,
              ) -> Calibration:
    """Fit scene fields to measured settlements and tilts (back-analysis).

    Parameters
    ----------
    scene : Scene, dict, str or path
        The scene of one punch (a scene file's path or ``"preset:NAME"`` is read by
        :func:`core.scene.load_scene`); its values of the fitted fields are the start of
        the fit. Its loads are the same functions of time at the reading times as at its
        own output times (a ``linear`` history keeps its own span).
    measurements : str, path, mapping or Readings
        A readings file (CSV or JSON, format in ``core/SCENES.md``) or a mapping with
        ``time`` [day after loading] and ``settlement`` [m] and/or ``tilt`` [rad] (lists),
        optionally ``settlement_std`` [m] / ``tilt_std`` [rad] (lists or one number).
    fit : list of str
        The scene paths of the fitted fields (``coating[0].modulus``,
        ``base.creep.relative_humidity``, ``base.age_at_loading``, ``loading.force``...).
    bounds : dict, optional
        ``path -> (low, high)`` in the field's unit, either end None for none. A field
        positive at the start and not allowed below zero is fitted by its logarithm.

    Returns
    -------
    Calibration
        ``.values`` and ``.standard_errors`` (dicts by path), ``.correlation``, the
        residuals, ``chi2_per_dof``, ``.warnings``, ``.scene`` (the fitted scene) and
        ``.forecast(times)``.

    Raises
    ------
    ValueError
        For bad input, naming the field (``fit[0]: ...``, ``readings.csv: line 4, column
        tilt: ...``), or when the scene cannot be solved at the start.
    OSError
        When a scene or readings file cannot be read (``FileNotFoundError``...).
    """
    started = time.perf_counter()
    readings = as_readings(measurements)
    base, work = _working_scene(scene, readings)
    fields = fitted_fields(base, fit, bounds)
    y, mask, sigma, std_given = _weights(readings)
    n, p = int(mask.sum()), len(fields)
    # With their deviations given as many readings as fields determine the fields and
    # their errors (the covariance is known); without, the noise is estimated from what
    # is left over, which needs more readings than fields.
    if n < p or (n == p and not std_given):
        raise ValueError(f"measurements: {n} reading(s) cannot determine {p} field(s)"
                         + ("" if n < p else " and the readings' noise") + "; give more "
                         "readings than fitted fields" + ("" if n < p else ", or the "
                         "readings' standard deviations"))
    model = Model(work, fields, readings.series, reading_times(readings))
    x0 = np.array([f.to_x(f.start) for f in fields])
    lo = np.array([f.x_bounds[0] for f in fields])
    hi = np.array([f.x_bounds[1] for f in fields])
    try:
        f_start = model.values(x0)
    except ValueError as exc:
        raise ValueError(f"scene: cannot be solved at the start of the fit ({exc})") from None

    def residuals(x: np.ndarray) -> np.ndarray:
        try:
            values = model.values(x)
        except ValueError:
            return np.full(n, _INVALID_RESIDUAL)
        return ((values - y) / sigma)[mask]

    def jacobian(x: np.ndarray) -> np.ndarray:
        centre = model.values(x)
        return model.jacobian(x, centre)[mask] / sigma[mask, None]

    # each evaluation of the residuals is a solve and each Jacobian p more
    max_nfev = max(1, MAX_FIT_SOLVES // (p + 1))
    dof = n - p

    stopped_determined = False

    def settled(x: np.ndarray, fun: np.ndarray) -> None:
        """Stop where the Gauss-Newton step from the point is below :data:`STEP_TO_SE`
        of every standard error (its Jacobian is the one the solver has just asked for,
        so this costs no solve); for fields the readings do not determine, of the
        standard error of every combination they do determine."""
        nonlocal stopped_determined
        r = np.asarray(fun, dtype=float)
        J = jacobian(x)
        if not (np.all(np.isfinite(J)) and np.all(np.isfinite(r))):
            return
        s2 = 1.0 if std_given else float(r @ r) / dof
        cov, condition = _covariance(J, s2)
        if not condition <= MAX_CONDITION:
            step, small = _determined_step(J, r, s2)
            if small and np.all((x + step >= lo) & (x + step <= hi)):
                stopped_determined = True
                raise StopIteration
            return
        step = np.linalg.lstsq(J, -r, rcond=None)[0]
        if not np.all((x + step >= lo) & (x + step <= hi)):
            return  # the minimum is at a bound: the solver's own tolerances decide there
        se = np.sqrt(np.abs(np.diag(cov)))
        if np.all(np.isfinite(se)) and np.all(np.abs(step) <= STEP_TO_SE * se):
            raise StopIteration

    # The least-squares solver starts with a trust radius of the norm of its start. It
    # is given the coordinates from the start (x - x0), so that radius is 1 (a factor e
    # of a field fitted by its logarithm, the start's size of another) instead of the
    # size of the logarithm of an SI value (~20-40): a first step along a direction the
    # readings hardly see took a 20 mm coating to 20 km.
    if not np.any(jacobian(x0)):
        # no field moves any reading (the tilt of a centred punch): nothing to fit, and
        # the trust region would divide 0 by 0 (the warnings below say why)
        answer = OptimizeResult(x=np.zeros_like(x0), success=True, status=0, nfev=1,
                                message=NOTHING_MOVES)
    else:
        # (numpy's warnings inside the solver on a partly degenerate Jacobian: the
        # warnings below speak of it in the fit's words)
        with np.errstate(invalid="ignore", divide="ignore"):
            answer = least_squares(
                lambda z: residuals(x0 + z), np.zeros_like(x0),
                jac=lambda z: jacobian(x0 + z), bounds=(lo - x0, hi - x0), method="trf",
                x_scale=1.0, xtol=X_TOL, ftol=F_TOL, gtol=None, max_nfev=max_nfev,
                **({"callback": lambda intermediate_result: settled(
                    x0 + intermediate_result.x, intermediate_result.fun)}
                   if STOPS_SETTLED else {}))
    if answer.status == -2:  # SciPy's status of a stop by the callback: settled
        answer.success = True
        answer.message = SETTLED_DETERMINED if stopped_determined else SETTLED
    x = x0 + answer.x
    solution = model.solve(x)
    values_fit = model.values(x)
    # the covariance from central differences where both sides of a step are points the
    # scene accepts (p more solves, once): their disagreement measures the derivatives'
    # error, which a one-sided difference cannot show
    first, other = (d[mask] / sigma[mask, None] for d in model.two_sided(x, values_fit))
    J = central(first, other)
    r = ((values_fit - y) / sigma)[mask]
    chi2 = float(r @ r)
    s2 = 1.0 if std_given else chi2 / dof
    warnings: list[str] = []
    if not answer.success:
        warnings.append(f"the least-squares solver stopped without converging "
                        f"({answer.message})")
    cov_x, condition = _covariance(J, s2)
    warnings += _identifiability(fields, cov_x, condition, x, lo, hi)
    warnings += _edge_check(model, x, lo, hi)
    ratio = _solver_error_to_noise(solution, readings, sigma, mask, math.sqrt(s2))
    if s2 == 0.0:
        # (no deviations, and the fit meets every reading: "the solver's error estimate
        # is inf of the noise" was read where the noise estimate is 0)
        warnings.append("the fit meets every reading exactly, so the scatter gives no "
                        "noise to estimate the standard errors from: give "
                        "the readings' standard deviations")
    elif ratio > MAX_SOLVER_ERROR_TO_NOISE:
        warnings.append(f"the solver's error estimate is {ratio:.2g} of the noise (more "
                        f"than {MAX_SOLVER_ERROR_TO_NOISE:g}): the standard errors reflect "
                        "the solver as much as the readings (tighten solver.tol, or the "
                        "readings fit the model to within its numerical error)")
    if std_given and dof > 0:
        warnings += _chi2_check(chi2, dof)
    unresolved = _derivative_check(fields, first, other, sigma[mask, None] * model.steps(x),
                                   solution, readings, mask, float(work["solver"]["tol"]))
    warnings += unresolved
    warnings += _flag_check(solution)
    unidentified = tuple(f.path for f in fields
                         if any(w.startswith(f.path + ":") or
                                (w.startswith("not identifiable") and f.path in w)
                                for w in warnings))
    residual = values_fit - y
    return Calibration(
        fields=fields, x=x, cov_x=cov_x, readings=readings, base=base, work=work,
        predicted=_split(values_fit, readings), residuals=_split(
            np.where(mask, residual, np.nan), readings),
        start_residuals=_split(np.where(mask, f_start - y, np.nan), readings),
        chi2=chi2, dof=dof, std_given=std_given, noise_scale=math.sqrt(s2),
        condition=condition, solver_error_to_noise=ratio, warnings=tuple(warnings),
        jacobian=J,
        unidentified=unidentified,
        solves=model.solves, seconds=time.perf_counter() - started,
        iterations=int(answer.nfev), status=str(answer.message), model=model,
        sigma=sigma,
    )


def _edge_check(model: Model, x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> list[str]:
    """A warning for each field whose answer sits at the edge of the values the scene
    accepts (its rules, not the fit's bounds: a relative humidity of fib MC2010 below
    40 %, say): the readings push it beyond, so it is not determined there."""
    out = []
    for j, f in enumerate(model.fields):
        for sign in (-1.0, 1.0):
            probe = x.copy()
            probe[j] += sign * EDGE_PROBE
            if not lo[j] <= probe[j] <= hi[j]:
                continue
            try:
                scene_from_dict(model.scene_dict(probe))
            except ValueError as exc:
                out.append(f"{f.path}: ended at the edge of the values the scene accepts "
                           f"({exc}): the readings push it beyond, so it is not "
                           "identified and its standard error does not hold")
                break
    return out


def _split(vector: np.ndarray, readings: Readings) -> dict[str, np.ndarray]:
    """A stacked vector as one array per series."""
    m = readings.time.size
    return {name: vector[k * m:(k + 1) * m] for k, name in enumerate(readings.series)}


def _flag_check(solution: Any) -> list[str]:
    """A warning when the fitted scene's answer is flagged (its model does not hold, or
    its numbers are doubtful there): settlements read in m where they were in mm fitted
    a concrete of 17 MPa, flagged large_settlement and large_tilt, with no warning."""
    flags = list(getattr(solution, "flags", ()))
    if not flags:
        return []
    size = ({"large_settlement", "large_tilt"} & set(flags))
    hint = (": readings in a wrong unit (mm read as m) fit such a scene; check them"
            if size else "")
    return [f"the fitted scene's answer is flagged {', '.join(flags)} (see the fitted "
            f"scene's flags){hint}"]


def _covariance(J: np.ndarray, s2: float) -> tuple[np.ndarray, float]:
    """``s^2 (J^T J)^-1`` by the singular values of J (a pseudo-inverse where J is
    singular: the covariance is then as large as the finite differences allow), and the
    condition number of J with its columns scaled to unit length."""
    norms, safe, _, sv, vt = scaled_svd(J)
    condition = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    tiny = sv[0] * np.finfo(float).eps * max(J.shape)
    inv = np.where(sv > tiny, 1.0 / np.where(sv > tiny, sv, 1.0) ** 2, np.inf)
    # (readings that no field moves, a tilt of a centred punch: J = 0, tiny = 0 and the
    # covariance infinite, as the warnings say; no numpy warning on the way)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        cov_n = (vt.T * np.where(np.isfinite(inv), inv, 1.0 / tiny ** 2)) @ vt
        cov = s2 * cov_n / np.outer(safe, safe)
    # readings met exactly (s2 = 0) by a field they do not see: 0 * inf, not determined
    cov[np.isnan(cov)] = np.inf
    cov[:, norms == 0] = np.inf
    cov[norms == 0, :] = np.inf
    return cov, condition


def _determined_step(J: np.ndarray, r: np.ndarray, s2: float) -> tuple[np.ndarray, bool]:
    """The Gauss-Newton step restricted to the combinations of fields the readings
    determine (the singular directions of the column-scaled ``J`` whose singular value is
    within :data:`MAX_CONDITION` of the largest), and whether it is below
    :data:`STEP_TO_SE` of each such combination's standard error ``sqrt(s2) / s_k``."""
    _, safe, u, sv, vt = scaled_svd(J)
    keep = sv >= sv[0] / MAX_CONDITION
    if sv[0] == 0 or not np.any(keep):
        return np.zeros(J.shape[1]), False
    projected = u[:, keep].T @ r  # the residual along each determined combination
    step = (vt[keep].T @ (-projected / sv[keep])) / safe
    return step, bool(np.all(np.abs(projected) <= STEP_TO_SE * math.sqrt(s2)))


def _identifiability(fields: Sequence[Field], cov: np.ndarray, condition: float,
                     x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> list[str]:
    """Warnings of fields the readings do not determine."""
    out = []
    if not condition <= MAX_CONDITION:
        se = np.sqrt(np.abs(np.diag(cov)))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = cov / np.outer(se, se)
        names = [f.path for f in fields]
        worst = [names[j] for j in range(len(fields))
                 if not np.isfinite(se[j])
                 or any(abs(corr[j, k]) > STRONG_CORRELATION for k in range(len(fields))
                        if k != j)]
        which = worst or names
        reason = (f"(condition number {condition:.3g} of the scaled Jacobian, above "
                  f"{MAX_CONDITION:g})")
        if len(which) == 1:
            # ("only a combination of" one field, "fix all but one of them", was read)
            out.append(f"not identifiable: the readings do not determine {which[0]} "
                       f"{reason}; add readings that depend on it")
        else:
            out.append(f"not identifiable: the readings determine only a combination of "
                       f"{', '.join(which)} {reason}; fix all but one of them, or add "
                       "readings that separate them")
    else:
        se = np.sqrt(np.diag(cov))
        # readings the scene meets exactly leave no scatter (se = 0): no correlation to
        # speak of, and no warning
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = cov / np.outer(se, se)
        for j in range(len(fields)):
            for k in range(j + 1, len(fields)):
                if abs(corr[j, k]) > STRONG_CORRELATION:
                    out.append(f"{fields[j].path} and {fields[k].path} are strongly "
                               f"correlated ({corr[j, k]:+.4f}): their standard errors "
                               "hold only jointly")
    for j, f in enumerate(fields):
        for end, name in ((lo[j], "lower"), (hi[j], "upper")):
            if math.isfinite(end) and abs(x[j] - end) <= BOUND_CLOSENESS * (1 + abs(end)):
                out.append(f"{f.path}: ended at its {name} bound "
                           f"({f.bounds[0 if name == 'lower' else 1]:.6g} {f.unit}): the "
                           "readings push it beyond, so it is not identified within the "
                           "bounds and its standard error does not hold")
        if math.sqrt(abs(cov[j, j])) > 1.0:
            # a coordinate's unit is a factor e (a log-fitted field) or the field's scale
            out.append(f"{f.path}: poorly determined (its standard error exceeds a factor "
                       "e = 2.7 either way)" if f.log else
                       f"{f.path}: poorly determined (its standard error exceeds its scale, "
                       f"{f.scale:.3g} {f.unit}".rstrip() + ": the start's size, or half the "
                       "range of its bounds)")
    return out


def _solver_error_to_noise(solution: Any, readings: Readings, sigma: np.ndarray,
                           mask: np.ndarray, noise_scale: float) -> float:
    """The solver's estimated error of each series [its unit] over the smallest noise
    of that series (the standard deviations times the scatter factor), the larger."""
    estimate = float(solution.info.get("error_estimate") or 0.0)
    m = readings.time.size
    ratio = 0.0
    for k, name in enumerate(readings.series):
        part = slice(k * m, (k + 1) * m)
        size = float(np.max(np.abs(getattr(solution, name))))
        noise = float(np.min(sigma[part][mask[part]])) * noise_scale
        if noise == 0:
            return math.inf
        ratio = max(ratio, estimate * size / noise)
    return ratio


def _chi2_check(chi2: float, dof: int) -> list[str]:
    """A warning when the scatter about the fit does not match the stated deviations
    (chi^2 outside its two-sided 99.9 % range for ``dof`` degrees of freedom)."""
    # the chi^2 quantiles from scipy.special (scipy.stats, ~0.5 s to import, is not needed
    # for them): chdtri(k, p) is the quantile of 1 - p
    from scipy.special import chdtri

    low, high = chdtri(dof, [0.9995, 0.0005])
    if low <= chi2 <= high:
        return []
    side = "larger" if chi2 > high else "smaller"
    return [f"chi^2/dof = {chi2 / dof:.3g}: the scatter about the fit is {side} than the "
            f"stated standard deviations allow (99.9 % range {low / dof:.3g} to "
            f"{high / dof:.3g}); the model misses the readings, or the deviations are "
            "wrong"]


def _derivative_check(fields: Sequence[Field], first: np.ndarray, other: np.ndarray,
                      to_change: np.ndarray, solution: Any, readings: Readings,
                      mask: np.ndarray, tol: float) -> list[str]:
    """Warnings of fields whose derivative the finite differences do not resolve.

    ``first`` and ``other`` are the weighted residuals' differences on either side of the
    steps (:meth:`~core.back_analysis.model.Model.two_sided`, NaN columns where one side
    is not a point the scene accepts); ``to_change`` turns ``first`` into each reading's
    change by the step [SI]. Where both sides are given, half their difference is
    measured: a field is warned of when it exceeds :data:`MAX_DERIVATIVE_SPREAD` of the
    central difference (the solver's error, or a kink of the answer within the step), or
    when neither side moves any reading. Where one side alone is given (the field at the
    edge of its bounds or of the values the scene accepts), the step must change some
    reading by more than 100 times the solver's tolerance ``tol`` (relative), a bound on
    the solver's error. That bound alone flagged a Poisson ratio the readings fix to 14 %
    (tests/back_analysis): the solves' error is far below their tolerance.
    """
    m = readings.time.size
    parts, offset = [], 0
    for k, name in enumerate(readings.series):
        count = int(mask[k * m:(k + 1) * m].sum())
        size = float(np.max(np.abs(getattr(solution, name))))
        parts.append((offset, offset + count, size))
        offset += count
    changes = first * to_change
    out = []
    for j, f in enumerate(fields):
        if np.all(np.isfinite(other[:, j])):
            size = float(np.linalg.norm(0.5 * (first[:, j] + other[:, j])))
            spread = 0.5 * float(np.linalg.norm(first[:, j] - other[:, j]))
            if size == 0.0 and spread == 0.0:
                out.append(f"{f.path}: a step of {FD_STEP:g} either way in its "
                           f"{'logarithm' if f.log else 'value over its scale'} changes no "
                           "reading: the readings do not depend on it")
            elif size == 0.0:
                out.append(f"{f.path}: a step of {FD_STEP:g} either way in its "
                           f"{'logarithm' if f.log else 'value over its scale'} moves the "
                           "readings alike: the answer is at a turning point of them, "
                           "where they do not determine it to first order")
            elif spread > MAX_DERIVATIVE_SPREAD * size:
                out.append(f"{f.path}: its derivative is not resolved: the differences on "
                           f"either side of a step of {FD_STEP:g} disagree by "
                           f"{100 * spread / size:.2g} % of it (more than "
                           f"{100 * MAX_DERIVATIVE_SPREAD:g} %): the readings hardly depend "
                           "on it, or the solver's error or a kink of the answer within "
                           "the step dominates it, so its standard error does not hold")
            continue
        if not any(np.max(np.abs(changes[a:b, j]), initial=0.0) > 100 * tol * size
                   for a, b, size in parts):
            out.append(f"{f.path}: a step of {FD_STEP:g} in its "
                       f"{'logarithm' if f.log else 'value over its scale'} changes no "
                       "reading by more than 100 times the solver's tolerance: the "
                       "readings hardly depend on it, or its derivative is the solver's "
                       "error")
    return out
