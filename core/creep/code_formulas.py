"""The equations of the design codes' creep and aging of concrete (code units).

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

The inputs are validated by :mod:`core.creep.code_inputs`; :mod:`core.creep.design_codes` builds the
creep model and its fitted kernel on these functions.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from core.creep.code_inputs import CEMENT_CLASSES, CodeInputs


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


def mc2010_reference_modulus(inp: CodeInputs) -> float:
    """``E_ci`` [MPa], the modulus at 28 days that divides ``phi`` in ``J`` (MC2010 5.1-21,
    5.1-61): not adjusted for temperature. (``mc2010_modulus(inp, 28)`` is: 0.99988
    ``E_ci`` at 20 C, 0.946 at 5 C and 1.025 at 30 C; dividing by it made the creep part
    of ``J`` up to 5.7 % larger than the code's text.)"""
    return 21500.0 * (inp.fcm / 10.0) ** (1.0 / 3.0)


def ec2_reference_modulus(inp: CodeInputs) -> float:
    """``E_c`` [MPa], the tangent modulus at 28 days that divides ``phi`` in ``J``
    (EN 1992-1-1 3.1.4(2), 3.1.3): ``1.05 E_cm``."""
    return float(ec2_modulus(inp, 28.0))


#: The modulus dividing the creep coefficient in each code's compliance [MPa].
_REFERENCE_MODULUS = {"fib_mc2010": mc2010_reference_modulus,
                      "eurocode2": ec2_reference_modulus}
