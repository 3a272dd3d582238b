"""A top layer as thick as the punch is wide, answered by the exact layered kernel."""

from __future__ import annotations

import numpy as np

import core


def _thick_top(h: float) -> dict:
    return {"schema_version": 1, "name": "thick top layer", "punch": {"half_width": 0.5},
            "coating": [{"thickness": h, "modulus": 3e8, "poisson": 0.35}],
            "base": {"thickness": 2.0, "poisson": 0.2, "age_at_loading": 90.0,
                     "creep": {"model": "elastic", "modulus": 3.4e10}},
            "loading": {"tilt": 0.0, "force": 8e5}, "times": [1.0]}


def test_a_top_layer_thicker_than_the_punch_gives_the_pressure_over_the_punch() -> None:
    """q was held within half the top layer's thickness of each corner: under a 0.5 m
    half-width a 1.8 m layer held it over the whole punch (q everywhere its value at x =
    -0.8 a, unflagged), a 2 m one made it infinite everywhere ("the computed pressure is
    not finite"). Held now over at most 5 % of the half-width. A soft layer 6 half-widths
    thick on stiff concrete nears the half-space's q = P / (pi sqrt(a^2 - x^2)): measured
    1.4 % above it at the centre, 0.9 % below at 0.9 a."""
    a, force = 0.5, 8e5
    x = np.linspace(-0.9 * a, 0.9 * a, 181)
    for h in (1.8, 2.0, 3.0):
        result = core.solve(_thick_top(h))
        q = result.pressure(x)[:, 0]
        assert np.all(np.isfinite(q)) and result.info["success"], h
        middle = q.size // 2
        # rising from the middle to the edges, even about it
        assert np.all(np.diff(q[middle:]) > 0) and np.allclose(q, q[::-1], rtol=1e-9), h
    half_space = force / (np.pi * np.sqrt(a * a - x * x))
    assert abs(q[middle] / half_space[middle] - 1) < 0.02
    assert abs(q[-1] / half_space[-1] - 1) < 0.02
