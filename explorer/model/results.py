"""A solved scene turned into the arrays the plots show (computed off the UI thread).

:func:`prepare_view` evaluates everything a redraw needs: pressure on the plot grids, the
histories in display units, the geometry of the drawing. Moving the time slider then
only slices arrays that already exist.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from core import scene_from_dict
from core.scene import flags_with_evidence, model_error_evidence

from .state import QUANTITIES, QUANTITY_UNITS

#: Points across the punch for the q(x) line (when the core gives no grid) and the drawing.
LINE_POINTS = 401
#: Grid of the q(x, t) image: points across the punch, rows in time.
IMAGE_X = 160
IMAGE_T = 120


@dataclass
class Geometry:
    """The scene drawing, in metres and pascals, evaluated on ``x``."""

    x: np.ndarray                 # [m], on [-a, a]
    shape: np.ndarray             # punch base shape f(x) [m]
    thickness: list[np.ndarray]   # per layer h_k(x) [m]
    modulus: list[np.ndarray]     # per layer E_k(x) [Pa]
    base_thickness: float         # H [m]
    base_modulus: float           # E of the base at loading [Pa]
    half_width: float             # a [m]


@dataclass
class ResultView:
    """One solved scene, ready to draw. Pressure in Pa, times in days.

    It holds arrays and plain values only, so that it pickles (it is made in a worker
    process when the server has them); the downloads solve ``scene`` again."""

    scene: dict[str, Any]
    given: tuple[str, ...]
    times: np.ndarray
    values: dict[str, np.ndarray]          # SI histories of the four quantities
    x: np.ndarray                          # [m], grid of the q(x) line
    pressure: np.ndarray                   # [Pa], (len(x), len(times))
    image: np.ndarray                      # [Pa], (IMAGE_T, IMAGE_X), rows uniform in time
    geometry: Geometry
    flags: list[str] = field(default_factory=list)
    flag_messages: dict[str, str] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)
    # per output time, the intervals of x [m] in contact (solver's contact_set); empty
    # when the solution does not say
    contact_set: list[list[tuple[float, float]]] = field(default_factory=list)

    @property
    def unknowns(self) -> tuple[str, ...]:
        return tuple(q for q in QUANTITIES if q not in self.given)

    @cached_property
    def pressure_unit(self) -> tuple[str, float]:
        """Display unit of pressure (kPa below 1 MPa peak, else MPa) and its size [Pa]
        (a scan of the whole pressure array, asked for by every plot of a redraw)."""
        peak = float(np.nanmax(np.abs(self.pressure))) if self.pressure.size else 0.0
        return ("MPa", 1e6) if peak >= 1e6 else ("kPa", 1e3)

    def display(self, quantity: str) -> np.ndarray:
        """History of a quantity in its display unit (mm, mrad, kN/m, kN·m/m)."""
        return self.values[quantity] / QUANTITY_UNITS[quantity][1]

    def time_index(self, t: float) -> int:
        """Index of the output time nearest to ``t`` [days]."""
        return int(np.argmin(np.abs(self.times - t)))

    def lift_off_band(self) -> float:
        """Pressure [Pa] below which (q < -band) the punch is taken to lift off.

        The solver raises ``contact_lost`` only when the pressure is negative beyond its
        own error band (estimated relative error times the largest pressure): a pressure
        just below zero within that band is round-off of a full contact. The shading and
        the files follow the same rule, so they never contradict the badge. Without the
        flag nothing lies beyond the band (infinite band)."""
        if "contact_lost" not in self.flags:
            return float("inf")
        err = self.info.get("error_estimate")
        err = float(err) if isinstance(err, (int, float)) and np.isfinite(err) else 0.0
        peak = float(np.nanmax(np.abs(self.pressure))) if self.pressure.size else 0.0
        return max(err, 1e-12) * peak

    def negative_intervals(self, index: int) -> list[tuple[float, float]]:
        """Intervals of ``x`` [m] where the pressure at output ``index`` is negative
        beyond the error band (see :meth:`lift_off_band`), or, when the unilateral
        contact model lifted part of the base off, the lifted parts of the base."""
        if index < len(self.contact_set):
            lifted = lifted_intervals(self.contact_set[index], self.geometry.half_width)
            if lifted:
                return lifted
        band = self.lift_off_band()
        if not np.isfinite(band):
            return []
        return negative_intervals(self.x, self.pressure[:, index] + band)


def model_evidence(view: ResultView,
                   check: Mapping[str, Any] | None = None) -> dict[str, Any] | None:
    """The coating model's error to show for ``view`` (:func:`core.scene.model_error_evidence`):
    the FE check's measurement when ``check`` was made for its scene, else the estimate the
    result carries; None for a result that carries none."""
    estimate = view.info.get("model_error_estimate")
    if not isinstance(estimate, (int, float)):
        return None
    return model_error_evidence(view.scene, float(estimate), check)


def shown_flags(view: ResultView, evidence: Mapping[str, Any] | None) -> list[str]:
    """The result's flags with ``model_error`` as the best evidence has it."""
    return list(view.flags) if evidence is None else flags_with_evidence(view.flags, evidence)


def lifted_intervals(zones: list[tuple[float, float]],
                     half_width: float) -> list[tuple[float, float]]:
    """Parts of the base ``[-a, a]`` [m] outside the contact ``zones`` [m] (lift-off)."""
    lifted: list[tuple[float, float]] = []
    edge = -half_width
    for lo, hi in sorted(zones):
        if lo > edge:
            lifted.append((edge, min(lo, half_width)))
        edge = max(edge, hi)
    if edge < half_width:
        lifted.append((edge, half_width))
    # a gap narrower than round-off of the zone ends is not a lift-off
    return [(lo, hi) for lo, hi in lifted if hi - lo > 1e-9 * half_width]


def negative_intervals(x: np.ndarray, q: np.ndarray) -> list[tuple[float, float]]:
    """Where ``q < 0`` on the grid ``x``, as ``(left, right)`` pairs, the ends placed at
    the zero crossings found by linear interpolation."""
    q = np.asarray(q, dtype=float)
    neg = q < 0
    if not neg.any():
        return []
    # the runs of negative nodes: where the mask switches on and off
    switch = np.diff(neg.astype(np.int8))
    first = np.flatnonzero(switch == 1) + 1
    last = np.flatnonzero(switch == -1)
    if neg[0]:
        first = np.concatenate([[0], first])
    if neg[-1]:
        last = np.concatenate([last, [len(q) - 1]])

    def crossing(k: int) -> float:  # zero of the chord between k and k + 1
        return float(x[k] - q[k] * (x[k + 1] - x[k]) / (q[k + 1] - q[k]))

    return [(float(x[0]) if i == 0 else crossing(i - 1),
             float(x[-1]) if j == len(q) - 1 else crossing(j))
            for i, j in zip(first.tolist(), last.tolist(), strict=True)]


def _values(profile: Any, x: np.ndarray) -> np.ndarray:
    return np.broadcast_to(np.asarray(profile(x), dtype=float), x.shape).copy()


def scene_geometry(scene: Any, points: int = LINE_POINTS) -> Geometry:
    """Evaluate the punch shape and the coating layers of a validated ``core.Scene``."""
    a = float(scene.half_width)
    x = np.linspace(-a, a, points)
    return Geometry(
        x=x,
        shape=_values(scene.shape, x),
        thickness=[_values(layer.thickness, x) for layer in scene.coating],
        modulus=[_values(layer.modulus, x) for layer in scene.coating],
        base_thickness=float(scene.base_thickness),
        base_modulus=float(scene.modulus_at_loading()),
        half_width=a,
    )


def _drop_round_off(values: dict[str, np.ndarray], a: float) -> None:
    """Show an exact zero where a quantity is round-off next to its partner's size.

    A centred load gives a tilt of 1e-18 rad, which an autoscaled plot would blow up into
    a curve. The partner sets the scale: settlement / a for the tilt, force * a for the
    moment, and conversely. Downloads keep the solver's numbers untouched.
    """
    peak = {q: float(np.max(np.abs(v))) if v.size else 0.0 for q, v in values.items()}
    scale = {"tilt": peak["settlement"] / a, "settlement": peak["tilt"] * a,
             "moment": peak["force"] * a, "force": peak["moment"] / a}
    for q, v in values.items():
        if 0 < peak[q] <= 1e-10 * scale[q]:
            values[q] = np.zeros_like(v)


def _resample_time(times: np.ndarray, q: np.ndarray, rows: int) -> np.ndarray:
    """``q`` (nx, nt) on ``rows`` times uniform over ``[times[0], times[-1]]`` -> (rows, nx)."""
    if len(times) == 1:
        return np.repeat(q.T, rows, axis=0)
    grid = np.linspace(times[0], times[-1], rows)
    j = np.clip(np.searchsorted(times, grid, side="right") - 1, 0, len(times) - 2)
    w = (grid - times[j]) / (times[j + 1] - times[j])
    return (q[:, j] * (1 - w) + q[:, j + 1] * w).T


def prepare_view(solution: Any, scene: dict[str, Any]) -> ResultView:
    """Everything the explorer draws for one solution of ``scene`` (a valid scene dict)."""
    scene_obj = getattr(solution, "scene", None)
    if scene_obj is None or not hasattr(scene_obj, "coating"):
        scene_obj = scene_from_dict(scene)
    a = float(scene_obj.half_width)
    times = np.asarray(solution.times, dtype=float)
    values = {q: np.asarray(getattr(solution, q), dtype=float) for q in QUANTITIES}
    for q, profile in getattr(scene_obj, "loading", {}).items():
        # a given history is drawn as given: after the round trip through the
        # dimensionless problem it carries round-off that autoscaled axes would magnify
        values[q] = _values(profile, times)
    grid = getattr(solution, "x", None)
    if grid is not None and len(grid) >= 101 and hasattr(solution, "pressure_on_grid"):
        # the core already evaluated q on its plotting grid (clustered toward the edges,
        # where the pressure varies fastest): reuse it instead of evaluating again
        x = np.asarray(grid, dtype=float)
        pressure = np.asarray(solution.pressure_on_grid, dtype=float)
    else:
        x = np.linspace(-a, a, LINE_POINTS)
        pressure = np.asarray(solution.pressure(x), dtype=float)
    pressure = pressure.reshape(len(x), len(times))
    _drop_round_off(values, a)
    xi = np.linspace(-a, a, IMAGE_X)
    qi = np.stack([np.interp(xi, x, pressure[:, j]) for j in range(len(times))], axis=1)
    image = _resample_time(times, qi, IMAGE_T)
    info = dict(getattr(solution, "info", {}) or {})
    flags = list(getattr(solution, "flags", info.get("flags", [])) or [])
    messages = dict(getattr(solution, "flag_messages", {}) or {})
    given = tuple(q for q in QUANTITIES if q in scene["loading"])
    return ResultView(scene=scene, given=given, times=times, values=values,
                      x=x, pressure=pressure, image=image, geometry=scene_geometry(scene_obj),
                      flags=flags, flag_messages=messages, info=info,
                      contact_set=[[(float(lo), float(hi)) for lo, hi in zones]
                                   for zones in getattr(solution, "contact_set", None) or []])
