"""What a bare creeping base must follow: a standard linear solid's creep law as a scene
field with its creep and relaxation functions in closed form, an aging base's creep
function, and Lee and Radok's pressure of a Hertz contact growing on that solid
(tests/scene/test_uncoated_scene.py, tests/engines/test_bare_lift_off.py,
benchmarks/bare_lift_off.py)."""

from __future__ import annotations

import numpy as np

#: Non-aging exponential creep: J(t) = 1 / E + c (1 - exp(-r t)) (a standard linear solid),
#: its relaxation in closed form R(t) = E (1 + E c exp(-r (1 + E c) t)) / (1 + E c).
CREEP = {"model": "exponential", "modulus": 3.0e10, "compliance": 3.0e-11, "rate": 0.05}


def laws(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``E J(t)`` and ``R(t) / E`` of :data:`CREEP` at ``times`` [days after loading]: how a
    bare base's kinematics grow under given forces and its forces relax under given
    kinematics (the correspondence principle)."""
    e_c = CREEP["modulus"] * CREEP["compliance"]
    growth = 1 + e_c * (1 - np.exp(-CREEP["rate"] * times))
    relaxation = (1 + e_c * np.exp(-CREEP["rate"] * (1 + e_c) * times)) / (1 + e_c)
    return growth, relaxation


def aging_growth(result) -> np.ndarray:
    """``E(tau0) J(t, tau0)`` at the output times of ``result`` (a ``SceneSolution``): how
    the kinematics of a bare aging base grow under constant given forces."""
    scene = result.scene
    tau0 = scene.age_at_loading
    e0 = float(np.asarray(scene.creep.modulus(tau0)))
    return 1 + e0 * np.asarray(scene.creep.compliance(tau0 + result.times, tau0))


def lee_radok_pressure(x: np.ndarray, days: np.ndarray, b0: float, peak: float) -> np.ndarray:
    """The pressure [Pa] of a Hertz contact (elastic half-width ``b0`` [m], pressure ``peak
    sqrt(1 - x^2 / b0^2)`` [Pa] at loading) growing under a constant force on the standard
    linear solid of :data:`CREEP` (Lee and Radok's hereditary integral, by quadrature):
    ``q(x, t) = C int R(t - tau) / E d sqrt(b(tau)^2 - x^2)`` with ``b(tau)^2 = b0^2 E
    J(tau)``, ``C = peak / b0``, integrated in ``s = sqrt(b^2 - x^2)`` (smooth there)."""
    from scipy.integrate import quad

    e_c = CREEP["modulus"] * CREEP["compliance"]
    rate = CREEP["rate"]

    def relaxation(lag: float) -> float:  # R(lag) / E
        return (1 + e_c * np.exp(-rate * (1 + e_c) * lag)) / (1 + e_c)

    def grown(days_: float) -> float:  # b(t)^2
        return b0 * b0 * (1 + e_c * (1 - np.exp(-rate * days_)))

    def reached(square: float) -> float:  # the time b^2 reaches ``square``
        return -np.log(1 - (square / (b0 * b0) - 1) / e_c) / rate

    out = np.zeros((x.size, days.size))
    for i, xi in enumerate(x):
        for k, t in enumerate(days):
            top = grown(t) - xi * xi
            if top <= 0:
                continue
            start = max(b0 * b0 - xi * xi, 0.0)
            value = relaxation(t) * np.sqrt(start)  # the jump at loading
            value += quad(lambda s, t=t, xi=xi: relaxation(t - reached(xi * xi + s * s)),
                          np.sqrt(start), np.sqrt(top), epsabs=0.0, epsrel=1e-11, limit=200)[0]
            out[i, k] = peak / b0 * value
    return out
