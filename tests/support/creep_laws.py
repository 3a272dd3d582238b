"""What a bare creeping base must follow: a standard linear solid's creep law as a scene
field with its creep and relaxation functions in closed form, and an aging base's creep
function (tests/scene/test_uncoated_scene.py, tests/engines/test_bare_lift_off.py)."""

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
