"""Creep and aging of concrete as the design codes specify them.

Two models, with their inputs in the units of the codes (MPa, %, mm, days, deg C):
``"fib_mc2010"``, fib Model Code for Concrete Structures 2010 (subclause 5.1.9.4 for
creep, 5.1.9.3 / 5.1.7.2 for the development of the modulus), and ``"eurocode2"``,
EN 1992-1-1:2004 (Annex B.1 for creep, 3.1.2 / 3.1.3 for the modulus). Their equations,
clause by clause, are in :mod:`core.creep.code_formulas`, the validation of their inputs in
:mod:`core.creep.code_inputs`.

The creep function of the model notes is ``C(t, tau) = phi(t, tau)/E_ref`` and the
kernel ``K(t, tau) = E(tau) d/dtau [1/E(tau) + C(t, tau)]`` (<= 0 for a creeping
material; core/creep/models.py). The derivative in ``tau`` is not taken of the code formulas
directly: the compliance is fitted by a Dirichlet series whose amplitudes are smooth in
the age (:mod:`core.creep.kernel_fit`) and the kernel follows from the fit exactly. Its error
(``fit_error``) enters the solver's error estimate.

Inputs outside the ranges the codes cover are refused with a ValueError naming the field
and the range (see ``RANGES``); nothing is clipped.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from core import limits
from core.creep.code_formulas import (
    _FORMULAS,
    _REFERENCE_MODULUS,
    _modulus_log_slope,
    clamp_age,
)
from core.creep.code_inputs import (
    CodeInputs,
    _in_range,
    check_inputs,
)
from core.validation import show_python

#: Longest load duration the kernel is fitted for [day] (100 years).
MAX_DURATION = 36525.0
#: Shortest load duration the kernel's fit error covers [day] (a minute and a half).
RESOLUTION = 1e-3
#: Largest positive value of the fitted kernel, relative to its largest magnitude, that is
#: taken as rounding (measured ~1e-15 on the corners of the input ranges).
K_SIGN_SLACK = 1e9


@dataclass(frozen=True)
class RelativeCodeModulus:
    """``c(t*) = E(tau0 t*) / E(tau0)`` [-] of a code model, ``t* = age / tau0``."""

    inputs: CodeInputs
    age_at_loading: float

    def __call__(self, t: Any) -> np.ndarray:
        """The relative modulus at dimensionless times ``t*``."""
        modulus = _FORMULAS[self.inputs.model][0]
        tau0 = self.age_at_loading
        return modulus(self.inputs, tau0 * np.asarray(t, dtype=float)) / self._at_loading

    @property
    def _at_loading(self) -> float:
        value = self.__dict__.get("_e0")
        if value is None:
            value = float(_FORMULAS[self.inputs.model][0](self.inputs, self.age_at_loading))
            object.__setattr__(self, "_e0", value)
        return value

    def log_slope(self, t: Any) -> np.ndarray:
        """``c'(t*)/c(t*)`` [-]."""
        tau0 = self.age_at_loading
        return tau0 * _modulus_log_slope(self.inputs, tau0 * np.asarray(t, dtype=float))


#: The solver tolerances a scene with a design code's creep law may get by default, finest
#: first (the tolerance menu of the explorer from 1e-6 up).
DEFAULT_TOL_LADDER = (1e-6, 1e-5, 1e-4, 1e-3)
#: The default tolerance is at least this many times the error of the creep law's fit by
#: exponentials (which the time stepping's estimate carries): the stepping's own error
#: then has the other half (the fits of :data:`FIT_LEVELS`).
FIT_ERROR_SHARE = 2.0
#: The fits of a code's compliance by exponentials, coarsest first: (retardation times a
#: decade, Chebyshev nodes in ln age, the largest reported fit error measured). Measured
#: over fib MC2010 and Eurocode 2 for C20/25 (cement S, RH 40 %, h0 1000 mm, 5 C), C30/37
#: (N, 60 %, 300 mm, 20 C), C50/60 (R, 90 %, 100 mm) and C90/105 (R, 100 %, 50 mm, 30 C),
#: ages at loading 1 to 3650 days, 100 years of duration: 1.84e-6, 2.98e-8 and 2.93e-9.
#: A solve takes the coarsest whose error, times :data:`FIT_ERROR_SHARE`, is within its
#: tolerance: 35 terms from tol 1e-5 on, 46 to 1e-7, 57 below (the time stepping's cost
#: per step grows with the terms; a fit costs ~0.1 s once per law and age).
FIT_LEVELS = ((3, 40, 1.9e-6), (4, 48, 3e-8), (5, 64, 3e-9))


def default_tolerance(model: CodeCreep, age_at_loading: float,
                      field: str = "age_at_loading") -> float:
    """The solver tolerance [-] a scene with this code's creep law meets by default.

    The smallest of :data:`DEFAULT_TOL_LADDER` that is at least :data:`FIT_ERROR_SHARE`
    times the error of the law's finest fit by exponentials at this age at loading [day]
    (the coarsest when none is): 1e-6 for every law measured (:data:`FIT_LEVELS`). (The
    fits once stopped at 1.6e-5 at 7 days, and a scene by a code then defaulted to 1e-4.)
    """
    fit_error = float(model.dimensionless_kernel(age_at_loading, field=field).fit_error)
    wanted = FIT_ERROR_SHARE * fit_error
    return next((tol for tol in DEFAULT_TOL_LADDER if tol >= wanted), DEFAULT_TOL_LADDER[-1])


def fit_advice(fit_error: float) -> str:
    """What a message says of a creep law fitted to ``fit_error`` (relative) when the
    solver's tolerance is below what that fit allows."""
    return (f"the creep law is fitted by exponentials no closer than {fit_error:.1e}: "
            f"ask for solver.tol >= {FIT_ERROR_SHARE * fit_error:.1e}")


class CodeCreep:
    """Creep and aging of concrete by a design code (``"fib_mc2010"`` or ``"eurocode2"``).

    ``modulus(age)`` [Pa], ``creep_coefficient(t, t0)`` [-] and ``compliance(t, tau)``
    (the creep function ``C = phi/E_ref`` [1/Pa], ``E_ref`` the 28-day modulus) follow
    the code's equations (:mod:`core.creep.code_formulas`); ``dimensionless_kernel`` is the
    kernel of the model notes fitted by :func:`core.creep.fit_compliance` (its
    ``fit_error`` enters the solver's estimate).
    """

    def __init__(self, model: str, spec: dict, field: str = "base.creep") -> None:
        if model not in _FORMULAS:
            raise ValueError(f"{field}.model: unknown code model {model!r}; known: "
                             + ", ".join(sorted(_FORMULAS)))
        self.name = model
        self.inputs = check_inputs(model, spec, field)
        self._reference = float(_REFERENCE_MODULUS[model](self.inputs))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, CodeCreep) and other.inputs == self.inputs

    def __hash__(self) -> int:
        return hash(self.inputs)

    def __repr__(self) -> str:
        return f"CodeCreep({self.spec!r})"

    def modulus(self, age: Any) -> np.ndarray:
        """Instantaneous modulus ``E(age)`` [Pa] at ages [day]."""
        return 1e6 * _FORMULAS[self.name][0](self.inputs, np.asarray(age, dtype=float))

    def creep_coefficient(self, t: Any, t0: Any) -> np.ndarray:
        """The code's creep coefficient ``phi(t, t0)`` [-] at ages ``t >= t0`` [day]."""
        return _FORMULAS[self.name][1](self.inputs, t, t0)

    def compliance(self, t: Any, tau: Any) -> np.ndarray:
        """Creep function ``C(t, tau) = phi(t, tau)/E(28)`` [1/Pa] at ages [day]; 0 for t < tau."""
        return self.creep_coefficient(t, tau) / (1e6 * self._reference)

    def age_at_loading_in_range(self, value: Any, field: str) -> float:
        """``value`` [day] as the age at loading, checked against the code's range
        (:data:`RANGES`); a ``ValueError`` naming ``field`` and the range's source."""
        return _in_range(value, self.name, "age_at_loading", field)

    def relative_modulus(self, age_at_loading: float, *,
                         field: str = "age_at_loading") -> RelativeCodeModulus:
        """``c(t*) = E(tau0 t*) / E(tau0)`` [-]; ``age_at_loading`` tau0 [day]."""
        return RelativeCodeModulus(self.inputs, self.age_at_loading_in_range(age_at_loading, field))

    def dimensionless_kernel(self, age_at_loading: float, *,
                             field: str = "age_at_loading", tol: float | None = None):
        """``K*(t*, tau*)`` [-] fitted on ages ``tau0`` to ``tau0 + MAX_DURATION`` days.

        ``tol``: the solver tolerance the kernel serves; the coarsest fit of
        :data:`FIT_LEVELS` whose error is within ``tol / FIT_ERROR_SHARE`` (a finer one if
        its measured error is not), the finest without one. Returns a
        :class:`core.creep.kernel_fit.FittedKernel` (``fit_error``, ``rates``, ...).
        Raises ValueError if the fitted kernel is positive anywhere (it must creep).
        """
        from core.creep.kernel_fit import fit_compliance, nonpositive_violation

        tau0 = self.age_at_loading_in_range(age_at_loading, field)
        inputs = self.inputs
        c = RelativeCodeModulus(inputs, tau0)
        e0 = float(_FORMULAS[self.name][0](inputs, tau0))
        scale = e0 / self._reference

        def creep(t: np.ndarray, tau: np.ndarray) -> np.ndarray:
            return scale * _FORMULAS[inputs.model][1](inputs, tau0 * t, tau0 * tau)

        if tol is None:
            candidates = FIT_LEVELS[-1:]
        else:
            first = next((k for k, level in enumerate(FIT_LEVELS)
                          if FIT_ERROR_SHARE * level[2] <= tol), len(FIT_LEVELS) - 1)
            candidates = FIT_LEVELS[first:]
        for per_decade, age_nodes, _ in candidates:
            fitted = fit_compliance(creep, end=1.0 + MAX_DURATION / tau0,
                                    resolution=RESOLUTION / tau0, modulus=c,
                                    log_slope=c.log_slope,
                                    breaks=(clamp_age(inputs) / tau0,), key=(inputs, tau0),
                                    per_decade=per_decade, age_nodes=age_nodes)
            # a law outside the measured set may need a finer fit than predicted
            if tol is None or FIT_ERROR_SHARE * fitted.fit_error <= tol:
                break
        violation = nonpositive_violation(fitted)
        if violation > K_SIGN_SLACK:
            raise ValueError(f"{field}: the fitted creep kernel is positive somewhere "
                             f"({violation:.2g} of its largest magnitude); the base would "
                             "not creep")
        return fitted

    def kernel(self, t: Any, tau: Any) -> np.ndarray:
        """``K(t, tau)`` [1/day] at ages [day] >= 1 (the fitted kernel with tau0 = 1 day)."""
        return self.dimensionless_kernel(1.0)(t, tau)

    @property
    def spec(self) -> dict:
        """JSON-able description, inverse of ``creep_model_from_spec`` (code units)."""
        inp = self.inputs
        out: dict[str, Any] = {"model": self.name}
        if inp.strength_class is not None:
            out["strength_class"] = inp.strength_class
        else:
            out["fcm"] = inp.fcm
        out.update(cement=inp.cement, relative_humidity=inp.relative_humidity,
                   notional_size=inp.notional_size, temperature=inp.temperature)
        return out


#: Spec fields of the code models: (required, optional).
SPEC_FIELDS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    name: (("relative_humidity", "notional_size"),
           ("fcm", "strength_class", "cement", "temperature")) for name in _FORMULAS}


def creep_coefficient_curve(spec: dict, age_at_loading: float, durations: Any, *,
                            field: str = "creep") -> np.ndarray:
    """``phi(t0 + d, t0)`` [-] of a code model at load durations ``d`` [day] (for plots).

    ``spec`` is a ``{"model": "fib_mc2010" | "eurocode2", ...}`` creep spec (SCENES.md),
    ``age_at_loading`` t0 [day]. Durations must be >= 0 and at most ``MAX_DURATION``.
    """
    # a list or object as the model name is unhashable: test its type before the lookup
    if not isinstance(spec, dict) or not isinstance(spec.get("model"), str) \
            or spec["model"] not in _FORMULAS:
        raise ValueError(f"{field}.model: must be one of " + ", ".join(sorted(_FORMULAS)))
    model = CodeCreep(spec["model"], spec, field)
    t0 = model.age_at_loading_in_range(age_at_loading, "age_at_loading")
    try:
        d = np.asarray(durations, dtype=float)
    except (TypeError, ValueError):
        raise ValueError("durations: must be a number or an array of numbers [day], got "
                         f"{show_python(durations)[:60]}") from None
    if d.size > limits.MAX_CURVE_POINTS:
        raise ValueError(f"durations: at most {limits.MAX_CURVE_POINTS:,} values, got "
                         f"{d.size:,}")
    if not np.all(np.isfinite(d)) or np.any(d < 0) or np.any(d > MAX_DURATION):
        raise ValueError(f"durations: must be finite, in [0, {MAX_DURATION:g}] days")
    return model.creep_coefficient(t0 + d, t0)
