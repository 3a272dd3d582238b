"""Classical answers drawn next to the computed pressure, for comparison.

- A rigid flat punch on an elastic half-space (plane strain, full contact, no coating):
  ``q(x) = (P + 2 M x / a^2) / (pi sqrt(a^2 - x^2))``, infinite at the edges.
- The Winkler limit, which for a rigid flat punch is the engineer's bearing-pressure rule
  for an eccentric footing: a trapezoid ``q = P/B + 12 M x / B^3`` (``B = 2a``) while
  ``|e| = |M/P| <= B/6``, else a triangle over ``3 (a - |e|)`` from the loaded edge with
  peak ``2 P / (3 (a - |e|))`` (no tension).

Both take the force P [N/m] and moment M [N] of the result at the chosen time and return
pressure [Pa]. A thin soft coating pulls the answer from the first toward the second.
"""

from __future__ import annotations

import numpy as np

#: The half-space pressure is infinite at the punch edges; it is drawn up to this many
#: times the mean pressure P / 2a, so that the plot keeps its scale.
EDGE_CAP = 4.0


def half_space_pressure(x: np.ndarray, force: float, moment: float, a: float) -> np.ndarray:
    """Rigid flat punch on an elastic half-space [Pa] at ``x`` [m] in (-a, a)."""
    x = np.asarray(x, dtype=float)
    root = np.sqrt(np.clip(a * a - x * x, 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        q = (force + 2.0 * moment * x / (a * a)) / (np.pi * root)
    cap = EDGE_CAP * abs(force) / (2 * a)
    return np.clip(np.nan_to_num(q, nan=cap, posinf=cap, neginf=-cap), -cap, cap)


def bearing_rule_pressure(x: np.ndarray, force: float, moment: float,
                          a: float) -> np.ndarray:
    """Trapezoidal / triangular bearing pressure of a rigid footing (Winkler) [Pa]."""
    x = np.asarray(x, dtype=float)
    width = 2 * a
    if force <= 0:
        return np.zeros_like(x)
    e = moment / force
    if abs(e) <= width / 6:
        return force / width + 12.0 * moment * x / width**3
    if abs(e) >= a:
        return np.full_like(x, np.nan)  # the resultant lies outside the footing
    length = 3.0 * (a - abs(e))
    peak = 2.0 * force / length
    edge = np.sign(e) * a                     # the loaded edge
    distance = np.abs(edge - x)
    return np.where(distance <= length, peak * (1 - distance / length), 0.0)
