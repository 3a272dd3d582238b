"""A footing on a creeping layer (exponential creep, eccentric load) for the back-analysis:
its solves take ~15 ms once the geometry is prepared, so a fit of three fields takes
~0.3 s. The tests of core.back_analysis and ``python -m benchmarks.calibrate`` fit it."""

from __future__ import annotations

import copy
from typing import Any

_SCENE: dict[str, Any] = {
    "schema_version": 1, "name": "Footing on a creeping layer",
    "punch": {"half_width": 1.0, "shape": 0.0},
    "coating": [{"thickness": 0.02, "modulus": 2e8, "poisson": 0.3}],
    "base": {"thickness": 4.0, "poisson": 0.3, "age_at_loading": 28.0,
             "creep": {"model": "exponential", "modulus": 3e8, "compliance": 3e-9,
                       "rate": 0.02}},
    "loading": {"force": 2e5, "moment": 2e4},
    "times": {"end": 3650.0, "count": 50},
    "solver": {"tol": 1e-6},
}


def creeping_footing() -> dict[str, Any]:
    """A fresh copy of the scene (a dict, as a file holds it)."""
    return copy.deepcopy(_SCENE)
