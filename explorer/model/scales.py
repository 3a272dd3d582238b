"""Units and colour ranges that stay put while a scene is being edited.

A *scene family* is what the user loaded (a preset, a file, a link) and every edit made
to it since. Within a family the pressure keeps one unit (kPa or MPa, chosen from the
first result) and the q(x, t) image keeps one colour scale, widened (to a round number)
when a result falls outside it: so that dragging a slider changes the colours, not the
meaning of the colours, and a peak crossing 1 MPa does not relabel every axis. A result
that fills less than :data:`SHRINK_BELOW` of the scale (a much softer change after a
stiff one) gets its own scale again: a map drawn in one colour says nothing.
Nothing here imports Panel or Bokeh.
"""

from __future__ import annotations

import math

import numpy as np

from .results import ResultView


def nice_ceiling(value: float) -> float:
    """The smallest of 1, 2, 2.5, 5 times a power of ten at or above ``value`` (> 0)."""
    if not math.isfinite(value) or value <= 0:
        return 1.0
    power = 10.0 ** math.floor(math.log10(value))
    for step in (1.0, 2.0, 2.5, 5.0, 10.0):
        if step * power >= value * (1 - 1e-12):
            return step * power
    return 10.0 * power


#: The q(x, t) colour scale is narrowed to the result's own when the result spans less
#: than this share of it (its largest |q| against the scale's): a round-number step of
#: the scale (1, 2, 2.5, 5) is at most 2x, so a drag that wanders within a factor of 2.5
#: keeps its colours.
SHRINK_BELOW = 0.4
#: The family's pressure unit holds while the largest |q| reads within these numbers of
#: it: 1 MPa crossing reads 1000 kPa and 20 MPa 20000 kPa, not a new unit, but a load
#: 1000 times larger read "5.000e+5 kPa" on the axes.
UNIT_READS = (1e-3, 1e5)


class DisplayScales:
    """The pressure unit and the q(x, t) colour range of the current scene family."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """A new family starts (a scene was loaded): the next result chooses again."""
        self._unit: tuple[str, float] | None = None
        self._range: tuple[float, float] | None = None

    def pressure_unit(self, view: ResultView) -> tuple[str, float]:
        """Display unit of pressure and its size [Pa], fixed for the family while its
        pressures read within :data:`UNIT_READS` of it (chosen again, with the colour
        range, for a result beyond)."""
        if self._unit is not None:
            peak = float(np.nanmax(np.abs(view.pressure))) if view.pressure.size else 0.0
            reads = peak / self._unit[1]
            if reads >= UNIT_READS[1] or 0 < reads < UNIT_READS[0]:
                self._unit, self._range = None, None
        if self._unit is None:
            self._unit = view.pressure_unit
        return self._unit

    def image_range(self, view: ResultView) -> tuple[float, float]:
        """Colour range of q(x, t) [display unit]: round numbers that cover every result
        of the family seen so far (zero included, so that lift-off reads at a glance),
        narrowed to this result's own when it spans less than :data:`SHRINK_BELOW` of
        them."""
        size = self.pressure_unit(view)[1]
        img = view.image
        lo = float(np.nanmin(img)) / size if img.size else 0.0
        hi = float(np.nanmax(img)) / size if img.size else 1.0
        lo = -nice_ceiling(-lo) if lo < 0 else 0.0
        hi = nice_ceiling(hi) if hi > 0 else 1.0
        if self._range is not None:
            old_lo, old_hi = self._range
            extent = max(abs(lo), hi)
            if extent >= SHRINK_BELOW * max(abs(old_lo), old_hi):
                lo, hi = min(lo, old_lo), max(hi, old_hi)
        self._range = (lo, hi)
        return self._range
