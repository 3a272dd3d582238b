"""The two-punch entry of the work-precision report (:mod:`benchmarks.work_precision`,
which runs it: ``two_punch_result``): its scene and how its errors are measured.

Two footings 0.5 m apart on the uniform preset's coating over an elastic base: a crowned
one (a = 1 m, 500 kN/m, 10 kN m/m) and a flat, narrower one (a = 0.6 m, 300 kN/m,
-10 kN m/m), both free to settle and tilt (statement 4), one output time. ``core.solve``
(the default engine coupling the punches' grids through the base) swept over
``solver.tol``, each answer against the same scene at the tightest ``tol`` the scene file
allows (1e-12); the cross-check is the run at 1e-11 against it (self-convergence: no
second method solves several punches).

Errors at the final time, the largest over the two punches of each part, as the report
measures them on one punch in its own dimensionless units (settlement over the half-width
and tilt relative to the larger of them, force and moment over the half-width relative
to the larger of them, q on 381 points of ``|x| <= 0.95 a`` relative to its largest
there). Cold: ``clear_caches()`` before each run; warm: the scene cached, only the two
forces changed (by 1 + 1e-3 k in run k).

    python benchmarks/work_precision.py --scenes two_punches     # this entry alone
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from core.presets import read_preset

#: The key of the entry among the report's scenes.
KEY = "two_punches"
#: The tightest tol a scene file allows (core.scene.schema.TOL_RANGE): the reference.
REFERENCE_TOL = 1e-12
#: The run checked against the reference (the finest below it).
CHECK_TOL = 1e-11
#: The tolerances swept.
TOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)
QUICK_TOLS = (1e-4, 1e-7)
#: The report's curve of this entry (a "projection" curve: the default engine's).
CURVE = "projection tol (two punches, core.solve)"


@dataclass(frozen=True)
class PunchesEntry:
    """What the report reads of a scene of its suite (key, title, description, kind)."""

    key: str = KEY
    title: str = "Two punches"
    description: str = (
        "Two footings 0.5 m apart on one coated elastic base (the uniform preset's "
        "20 mm coating, H = 4 m): a crowned one, a = 1 m, P = 500 kN/m, M = 10 kN m/m, "
        "and a flat one, a = 0.6 m, P = 300 kN/m, M = -10 kN m/m; the coupled default "
        "engine (core.solve) over solver.tol; errors the largest over both punches.")
    smooth: bool = False
    creeping: bool = False


def scene(tol: float, scale: float = 1.0) -> dict[str, Any]:
    """The scene at ``solver.tol = tol``, both forces times ``scale``."""
    d = read_preset("uniform_flat")
    d["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    d["times"] = [1.0]
    d["solver"] = {"tol": tol}
    del d["punch"], d["loading"]
    d["punches"] = [
        {"center": 0.0, "half_width": 1.0,
         "shape": {"kind": "polynomial", "coefficients": [0.0, 0.0, 5e-6]},
         "loading": {"force": 5e5 * scale, "moment": 1e4}},
        {"center": 2.1, "half_width": 0.6,
         "loading": {"force": 3e5 * scale, "moment": -1e4}}]
    return d


def errors(result: Any, reference: Any) -> dict[str, float]:
    """Relative errors at the final time by part, the largest over the punches (see the
    module's notes)."""
    out = dict.fromkeys(("settlement", "tilt", "force", "moment", "pressure"), 0.0)
    for mine, best in zip(result.punches, reference.punches, strict=True):
        a = best.scene.half_width
        kin = max(abs(best.settlement[-1] / a), abs(best.tilt[-1]))
        dyn = max(abs(best.force[-1]), abs(best.moment[-1] / a))
        x = np.linspace(-0.95, 0.95, 381) * a
        q, q_ref = mine.pressure(x)[:, -1], best.pressure(x)[:, -1]
        parts = {"settlement": abs(mine.settlement[-1] - best.settlement[-1]) / a / kin,
                 "tilt": abs(mine.tilt[-1] - best.tilt[-1]) / kin,
                 "force": abs(mine.force[-1] - best.force[-1]) / dyn,
                 "moment": abs(mine.moment[-1] - best.moment[-1]) / a / dyn,
                 "pressure": float(np.max(np.abs(q - q_ref)) / np.max(np.abs(q_ref)))}
        out = {name: max(out[name], float(value)) for name, value in parts.items()}
    return out
