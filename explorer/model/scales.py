"""Units and colour ranges that stay put while a scene is being edited.

A *scene family* is what the user loaded (a preset, a file, a link) and every edit made
to it since. Within a family the pressure keeps one unit (kPa or MPa, chosen from the
first result) and the q(x, t) image keeps one colour scale, about the values of the
results (round numbers), widened when a result falls outside it: so that dragging a
slider changes the colours, not the meaning of the colours, and a peak crossing 1 MPa
does not relabel every axis. A result that spans less than :data:`SHRINK_BELOW` of the
scale (a much softer change after a stiff one, a nearly uniform pressure) gets its own
scale again: a map drawn in one colour says nothing.
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
        """Colour range of q(x, t) [display unit]: round numbers about this result's
        values (:func:`own_range`), widened to those of the family seen before while this
        result spans at least :data:`SHRINK_BELOW` of them (a drag keeps its colours),
        its own again where it spans less."""
        size = self.pressure_unit(view)[1]
        img = view.image
        finite = img[np.isfinite(img)] / size if img.size else np.zeros(0)
        lo, hi = own_range(float(finite.min()) if finite.size else 0.0,
                           float(finite.max()) if finite.size else 1.0)
        if self._range is not None:
            old_lo, old_hi = self._range
            if hi - lo >= SHRINK_BELOW * (old_hi - old_lo):
                lo, hi = min(lo, old_lo), max(hi, old_hi)
        self._range = (lo, hi)
        return self._range


#: Colour steps of the q(x, t) scale over the values of one result (:func:`own_range`).
COLOUR_STEPS = 5


def own_range(lo: float, hi: float) -> tuple[float, float]:
    """A colour range about the values ``lo`` to ``hi`` [display unit]: their ends
    rounded out to a round step (1, 2, 2.5, 5 times a power of ten) of about a
    :data:`COLOUR_STEPS`-th of their span. Zero is not forced in: a scale from 0 drew a
    coating of five layers (235 to 292 kPa, on 0 to 500) in one colour; a lift-off has
    q = 0 in it, its lowest colour."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return 0.0, 1.0
    if hi - lo <= 1e-9 * max(abs(lo), abs(hi)):
        if hi == 0.0:
            return 0.0, 1.0  # no pressure at all
        # one value (a uniform pressure): a step about it
        step = nice_ceiling(abs(hi) / COLOUR_STEPS)
        low, high = lo - step, hi + step
    else:
        step = nice_ceiling((hi - lo) / COLOUR_STEPS)
        # (a value a rounding below a step's multiple is on it: 0.3 / 0.1 = 2.9999...)
        low = math.floor(lo / step + 1e-9) * step
        high = math.ceil(hi / step - 1e-9) * step
    digits = max(0, 1 - math.floor(math.log10(step)))
    low, high = round(low, digits), round(high, digits)
    # (a pressure never below 0 keeps its scale there: no colour for "below zero")
    return (max(low, 0.0) if lo >= 0.0 else low), high
