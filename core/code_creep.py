"""Creep and aging of concrete as the design codes specify them.

Two models, with their inputs in the units of the codes (MPa, %, mm, days, deg C):

* ``"fib_mc2010"``: fib Model Code for Concrete Structures 2010 (Ernst & Sohn, 2013),
  subclause 5.1.9.4 (creep) and 5.1.9.3 / 5.1.7.2 (development of the modulus):

      J(t, t0)    = 1/E_ci(t0) + phi(t, t0)/E_ci                          (5.1-61)
      phi         = phi_bc + phi_dc                                        (5.1-63)
      phi_bc      = beta_bc(fcm) beta_bc(t, t0)                            (5.1-64)
      beta_bc(fcm) = 1.8 / fcm^0.7                                         (5.1-65)
      beta_bc(t, t0) = ln[(30/t0_adj + 0.035)^2 (t - t0) + 1]             (5.1-66)
      phi_dc      = beta_dc(fcm) beta(RH) beta_dc(t0) beta_dc(t, t0)       (5.1-67)
      beta_dc(fcm) = 412 / fcm^1.4                                         (5.1-68)
      beta(RH)    = (1 - RH/100) / (0.1 h/100)^(1/3)                       (5.1-69)
      beta_dc(t0) = 1 / (0.1 + t0_adj^0.2)                                 (5.1-70)
      beta_dc(t, t0) = [(t - t0)/(beta_h + t - t0)]^gamma(t0)              (5.1-71a)
      gamma(t0)   = 1 / (2.3 + 3.5/sqrt(t0_adj))                           (5.1-71b)
      beta_h      = 1.5 h + 250 alpha_fcm <= 1500 alpha_fcm                (5.1-71c)
      alpha_fcm   = (35/fcm)^0.5                                           (5.1-71d)
      t0_adj      = t0_T [9/(2 + t0_T^1.2) + 1]^alpha >= 0.5 day           (5.1-73)
      t_T         = t exp[13.65 - 4000/(273 + T)]    (constant T)          (5.1-85)
      E_ci(t)     = beta_E(t) E_ci,  beta_E = beta_cc^0.5                  (5.1-56, 5.1-57)
      beta_cc(t)  = exp{s [1 - (28/t_T)^0.5]}                              (5.1-51)
      E_ci        = E_c0 alpha_E (fcm/10)^(1/3), E_c0 = 21500 MPa          (5.1-21)

  quartzite aggregate (alpha_E = 1); ``s`` from Table 5.1-9 (0.20 for fcm > 60 MPa).

* ``"eurocode2"``: EN 1992-1-1:2004, Annex B.1 (creep) and 3.1.2 / 3.1.3 (modulus):

      phi(t, t0) = phi_0 beta_c(t, t0),  phi_0 = phi_RH beta(fcm) beta(t0)   (B.1, B.2)
      phi_RH = 1 + (1 - RH/100)/(0.1 h0^(1/3))              fcm <= 35       (B.3a)
             = [1 + (1 - RH/100)/(0.1 h0^(1/3)) alpha_1] alpha_2  fcm > 35  (B.3b)
      beta(fcm) = 16.8 / sqrt(fcm),  beta(t0) = 1/(0.1 + t0^0.20)          (B.4, B.5)
      beta_c(t, t0) = [(t - t0)/(beta_H + t - t0)]^0.3                      (B.7)
      beta_H = 1.5 [1 + (0.012 RH)^18] h0 + 250 alpha_3 <= 1500 alpha_3     (B.8a, B.8b)
      alpha_1,2,3 = (35/fcm)^0.7, (35/fcm)^0.2, (35/fcm)^0.5 (1 for fcm <= 35)  (B.8c)
      t0 = t0_T [9/(2 + t0_T^1.2) + 1]^alpha >= 0.5 day                      (B.9)
      t0_T = t0 exp[13.65 - 4000/(273 + T)]  (constant T)                    (B.10)
      E_cm(t) = [f_cm(t)/f_cm]^0.3 E_cm,  f_cm(t) = beta_cc(t) f_cm          (3.5, 3.1)
      beta_cc(t) = exp{s [1 - (28/t)^0.5]}                                   (3.2)
      E_cm = 22 (f_cm/10)^0.3 GPa                                             (Table 3.1)

  The creep coefficient is taken relative to the tangent modulus E_c = 1.05 E_cm
  (3.1.4(2)), so ``E(t) = 1.05 E_cm(t)`` and ``J(t, t0) = 1/E(t0) + phi(t, t0)/E(28)``.

The cement class is ``"S"``, ``"N"`` or ``"R"``: alpha = -1, 0, 1 (5.1-73, B.9) and
s = 0.38, 0.25, 0.20 (Table 5.1-9, 3.1.2(6)). The strength is the mean cylinder
strength ``fcm`` [MPa] or a class ``"C30/37"`` (fcm = fck + 8 MPa, 5.1-1 and Table 3.1).

The creep function of the model notes is ``C(t, tau) = phi(t, tau)/E_ref`` and the
kernel ``K(t, tau) = E(tau) d/dtau [1/E(tau) + C(t, tau)]`` (<= 0 for a creeping
material; core/creep.py). The derivative in ``tau`` is not taken of the code formulas
directly: the compliance is fitted by a Dirichlet series whose amplitudes are smooth in
the age (:mod:`core.kernel_fit`) and the kernel follows from the fit exactly. Its error
(``fit_error``) enters the solver's error estimate.

Inputs outside the ranges the codes cover are refused with a ValueError naming the field
and the range (see ``RANGES``); nothing is clipped.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from core import limits
from core.validation import PYTHON_STYLE, finite_number, show_python

#: alpha of 5.1-73 / B.9 and s of Table 5.1-9 / 3.1.2(6), by cement class.
CEMENT_CLASSES: dict[str, tuple[float, float]] = {"S": (-1.0, 0.38), "N": (0.0, 0.25),
                                                  "R": (1.0, 0.20)}
#: fcm = fck + DELTA_F [MPa] (MC2010 5.1-1, EN 1992-1-1 Table 3.1).
DELTA_F = 8.0
#: Accepted ranges of the inputs: (low, high, where the bound comes from).
RANGES: dict[str, dict[str, tuple[float, float, str]]] = {
    "fib_mc2010": {
        "fcm": (20.0, 130.0, "fib MC2010 5.1.9.4.2"),
        "relative_humidity": (40.0, 100.0, "fib MC2010 5.1.9.4.2"),
        "notional_size": (50.0, 1500.0, "this project: the range of the codes' tables; "
                          "the formulas state no bound"),
        "temperature": (5.0, 30.0, "fib MC2010 5.1.9.4.2; other temperatures need 5.1.10"),
        "age_at_loading": (1.0, 3650.0, "fib MC2010 5.1.9.4.2 (>= 1 day); at most 10 years "
                           "(this project)"),
    },
    "eurocode2": {
        "fcm": (20.0, 98.0, "EN 1992-1-1 Table 3.1: C12/15 to C90/105"),
        "relative_humidity": (40.0, 100.0, "EN 1992-1-1 3.1.4(2)"),
        "notional_size": (50.0, 1500.0, "this project: Figure 3.1 covers 100 to 1500 mm; "
                          "the formulas of Annex B state no bound"),
        "temperature": (-40.0, 40.0, "EN 1992-1-1 3.1.4(2)"),
        "age_at_loading": (1.0, 3650.0, "EN 1992-1-1 Figure 3.1 starts at 1 day; at most "
                           "10 years (this project)"),
    },
}
#: Longest load duration the kernel is fitted for [day] (100 years).
MAX_DURATION = 36525.0

_STRENGTH_CLASS = re.compile(r"^\s*C\s*(\d{2,3})\s*/\s*(\d{2,3})\s*$")


def _in_range(value: Any, model: str, name: str, field: str) -> float:
    x = finite_number(value, field, style=PYTHON_STYLE)
    low, high, source = RANGES[model][name]
    if not low <= x <= high:
        raise ValueError(f"{field}: must be in [{low:g}, {high:g}] ({source}), got "
                         f"{show_python(value)}")
    return x


def mean_strength(fcm: Any, strength_class: Any, model: str, field: str) -> float:
    """``fcm`` [MPa] from exactly one of ``fcm`` [MPa] and ``strength_class`` ("C30/37")."""
    if (fcm is None) == (strength_class is None):
        raise ValueError(f"{field}: give exactly one of fcm (mean cylinder strength, MPa) "
                         "and strength_class (e.g. 'C30/37')")
    if fcm is not None:
        return _in_range(fcm, model, "fcm", f"{field}.fcm")
    match = _STRENGTH_CLASS.match(strength_class) if isinstance(strength_class, str) else None
    if match is None:
        raise ValueError(f"{field}.strength_class: must look like 'C30/37' (cylinder/cube "
                         f"strength in MPa), got {show_python(strength_class)}")
    fck = float(match.group(1))
    low, high, source = RANGES[model]["fcm"]
    if not low <= fck + DELTA_F <= high:
        raise ValueError(f"{field}.strength_class: fcm = fck + {DELTA_F:g} MPa must be in "
                         f"[{low:g}, {high:g}] ({source}), got {fck + DELTA_F:g} MPa for "
                         f"{show_python(strength_class)}")
    return fck + DELTA_F


def _cement(value: Any, field: str) -> str:
    if not isinstance(value, str) or value not in CEMENT_CLASSES:
        raise ValueError(f"{field}: must be one of 'S' (slow), 'N' (normal), 'R' (rapid "
                         f"hardening), got {show_python(value)}")
    return value


def _maturity_factor(temperature: float) -> float:
    """``t_T / t`` at a constant temperature [deg C] (MC2010 5.1-85, EN 1992-1-1 B.10)."""
    return float(np.exp(13.65 - 4000.0 / (273.0 + temperature)))


def _adjusted_age(age_t: np.ndarray | float, alpha: float) -> np.ndarray:
    """``t0_adj`` of MC2010 5.1-73 (EN 1992-1-1 B.9) from a temperature-adjusted age."""
    age_t = np.asarray(age_t, dtype=float)
    return np.maximum(age_t * (9.0 / (2.0 + age_t**1.2) + 1.0) ** alpha, 0.5)


def clamp_age(inp: CodeInputs) -> float:
    """The age [day] below which ``t0_adj`` is held at 0.5 day (5.1-73, B.9): the
    compliance has a kink in the age at loading there, and the kernel a jump."""
    alpha = CEMENT_CLASSES[inp.cement][0]
    lo, hi = 1e-9, 1e3  # the adjusted age increases with the age for every cement class
    for _ in range(100):
        mid = np.sqrt(lo * hi)
        if mid * (9.0 / (2.0 + mid**1.2) + 1.0) ** alpha < 0.5:
            lo = mid
        else:
            hi = mid
    return float(np.sqrt(lo * hi)) / _maturity_factor(inp.temperature)


@dataclass(frozen=True)
class CodeInputs:
    """Validated inputs shared by the code models (code units)."""

    model: str
    fcm: float                 # MPa
    cement: str                # S, N or R
    relative_humidity: float   # %
    notional_size: float       # mm
    temperature: float         # deg C
    strength_class: str | None = None


def check_inputs(model: str, spec: dict, field: str) -> CodeInputs:
    """Validate the fields of a code model (see ``RANGES``); ValueErrors name the field."""
    fcm = mean_strength(spec.get("fcm"), spec.get("strength_class"), model, field)
    return CodeInputs(
        model=model, fcm=fcm,
        cement=_cement(spec.get("cement", "N"), f"{field}.cement"),
        relative_humidity=_in_range(spec["relative_humidity"], model, "relative_humidity",
                                    f"{field}.relative_humidity"),
        notional_size=_in_range(spec["notional_size"], model, "notional_size",
                                f"{field}.notional_size"),
        temperature=_in_range(spec.get("temperature", 20.0), model, "temperature",
                              f"{field}.temperature"),
        strength_class=spec.get("strength_class"))


# ------------------------------------------------------------------------- the formulas


def mc2010_modulus(inp: CodeInputs, age: Any) -> np.ndarray:
    """``E_ci(t)`` [MPa] at ages [day] (MC2010 5.1-21, 5.1-51, 5.1-56, 5.1-57, 5.1-85)."""
    s = 0.20 if inp.fcm > 60.0 else CEMENT_CLASSES[inp.cement][1]
    age_t = np.asarray(age, dtype=float) * _maturity_factor(inp.temperature)
    beta_cc = np.exp(s * (1.0 - np.sqrt(28.0 / age_t)))
    return 21500.0 * (inp.fcm / 10.0) ** (1.0 / 3.0) * np.sqrt(beta_cc)


def mc2010_creep_coefficient(inp: CodeInputs, t: Any, t0: Any) -> np.ndarray:
    """``phi(t, t0)`` [-] at ages ``t >= t0`` [day] (MC2010 5.1-63 to 5.1-73, 5.1-85)."""
    t, t0 = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(t0, dtype=float))
    lag = np.maximum(t - t0, 0.0)
    alpha = CEMENT_CLASSES[inp.cement][0]
    t0_adj = _adjusted_age(t0 * _maturity_factor(inp.temperature), alpha)
    basic = 1.8 / inp.fcm**0.7 * np.log1p((30.0 / t0_adj + 0.035) ** 2 * lag)
    alpha_fcm = np.sqrt(35.0 / inp.fcm)
    beta_h = min(1.5 * inp.notional_size + 250.0 * alpha_fcm, 1500.0 * alpha_fcm)
    gamma = 1.0 / (2.3 + 3.5 / np.sqrt(t0_adj))
    drying = (412.0 / inp.fcm**1.4
              * (1.0 - inp.relative_humidity / 100.0)
              / (0.1 * inp.notional_size / 100.0) ** (1.0 / 3.0)
              / (0.1 + t0_adj**0.2)
              * (lag / (beta_h + lag)) ** gamma)
    return basic + drying


def ec2_modulus(inp: CodeInputs, age: Any) -> np.ndarray:
    """Tangent modulus ``E_c(t) = 1.05 E_cm(t)`` [MPa] at ages [day] (3.1, 3.2, 3.5, 3.1.4(2))."""
    s = CEMENT_CLASSES[inp.cement][1]
    beta_cc = np.exp(s * (1.0 - np.sqrt(28.0 / np.asarray(age, dtype=float))))
    return 1.05 * 22000.0 * (inp.fcm / 10.0) ** 0.3 * beta_cc**0.3


def ec2_creep_coefficient(inp: CodeInputs, t: Any, t0: Any) -> np.ndarray:
    """``phi(t, t0)`` [-] at ages ``t >= t0`` [day] (EN 1992-1-1 B.1 to B.10)."""
    t, t0 = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(t0, dtype=float))
    lag = np.maximum(t - t0, 0.0)
    fcm, rh, h0 = inp.fcm, inp.relative_humidity, inp.notional_size
    a1, a2, a3 = ((35.0 / fcm) ** 0.7, (35.0 / fcm) ** 0.2, (35.0 / fcm) ** 0.5) \
        if fcm > 35.0 else (1.0, 1.0, 1.0)
    phi_rh = (1.0 + (1.0 - rh / 100.0) / (0.1 * h0 ** (1.0 / 3.0)) * a1) * a2
    alpha = CEMENT_CLASSES[inp.cement][0]
    t0_mod = _adjusted_age(t0 * _maturity_factor(inp.temperature), alpha)
    phi_0 = phi_rh * 16.8 / np.sqrt(fcm) / (0.1 + t0_mod**0.20)
    beta_h = min(1.5 * (1.0 + (0.012 * rh) ** 18) * h0 + 250.0 * a3, 1500.0 * a3)
    return phi_0 * (lag / (beta_h + lag)) ** 0.3


def _modulus_log_slope(inp: CodeInputs, age: np.ndarray) -> np.ndarray:
    """``E'(age)/E(age)`` [1/day], by hand from 5.1-51/5.1-57 (MC2010) or 3.2/3.5 (EC2)."""
    age = np.asarray(age, dtype=float)
    if inp.model == "fib_mc2010":
        s = 0.20 if inp.fcm > 60.0 else CEMENT_CLASSES[inp.cement][1]
        # ln E = const + s/2 (1 - sqrt(28/(f age))), f the maturity factor
        return 0.25 * s * np.sqrt(28.0 / _maturity_factor(inp.temperature)) * age**-1.5
    s = CEMENT_CLASSES[inp.cement][1]
    # ln E = const + 0.3 s (1 - sqrt(28/age))
    return 0.15 * s * np.sqrt(28.0) * age**-1.5


_FORMULAS = {"fib_mc2010": (mc2010_modulus, mc2010_creep_coefficient),
             "eurocode2": (ec2_modulus, ec2_creep_coefficient)}
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


class CodeCreep:
    """Creep and aging of concrete by a design code (``"fib_mc2010"`` or ``"eurocode2"``).

    ``modulus(age)`` [Pa], ``creep_coefficient(t, t0)`` [-] and ``compliance(t, tau)``
    (the creep function ``C = phi/E_ref`` [1/Pa], ``E_ref`` the 28-day modulus) follow
    the code's equations (module docstring); ``dimensionless_kernel`` is the kernel of
    the model notes fitted by :func:`core.kernel_fit.fit_compliance` (its ``fit_error``
    enters the solver's estimate).
    """

    def __init__(self, model: str, spec: dict, field: str = "base.creep") -> None:
        if model not in _FORMULAS:
            raise ValueError(f"{field}.model: unknown code model {model!r}; known: "
                             + ", ".join(sorted(_FORMULAS)))
        self.name = model
        self.inputs = check_inputs(model, spec, field)
        self._reference = float(_FORMULAS[model][0](self.inputs, 28.0))

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

    def _age_at_loading(self, value: Any, field: str) -> float:
        return _in_range(value, self.name, "age_at_loading", field)

    def relative_modulus(self, age_at_loading: float, *,
                         field: str = "age_at_loading") -> RelativeCodeModulus:
        """``c(t*) = E(tau0 t*) / E(tau0)`` [-]; ``age_at_loading`` tau0 [day]."""
        return RelativeCodeModulus(self.inputs, self._age_at_loading(age_at_loading, field))

    def dimensionless_kernel(self, age_at_loading: float, *,
                             field: str = "age_at_loading"):
        """``K*(t*, tau*)`` [-] fitted on ages ``tau0`` to ``tau0 + MAX_DURATION`` days.

        Returns a :class:`core.kernel_fit.FittedKernel` (``fit_error``, ``rates``, ...).
        Raises ValueError if the fitted kernel is positive anywhere (it must creep).
        """
        from core.kernel_fit import fit_compliance, nonpositive_violation

        tau0 = self._age_at_loading(age_at_loading, field)
        inputs = self.inputs
        c = RelativeCodeModulus(inputs, tau0)
        e0 = float(_FORMULAS[self.name][0](inputs, tau0))
        scale = e0 / self._reference

        def creep(t: np.ndarray, tau: np.ndarray) -> np.ndarray:
            return scale * _FORMULAS[inputs.model][1](inputs, tau0 * t, tau0 * tau)

        fitted = fit_compliance(creep, end=1.0 + MAX_DURATION / tau0,
                                resolution=RESOLUTION / tau0, modulus=c,
                                log_slope=c.log_slope, breaks=(clamp_age(inputs) / tau0,),
                                key=(inputs, tau0))
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
    t0 = model._age_at_loading(age_at_loading, "age_at_loading")
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
