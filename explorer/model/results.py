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
from core.coating import model_error_quantity
from core.scene import flags_with_evidence, model_error_evidence, without_round_off

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
    half_width: float             # a [m]; several punches: the sum of theirs
    # several punches: each punch's x [m] (global) and shape f [m], in order
    punch_x: list[np.ndarray] = field(default_factory=list)
    punch_shape: list[np.ndarray] = field(default_factory=list)


@dataclass
class PunchResult:
    """One punch of several, ready to draw (arrays and plain values: it pickles).

    ``x`` is the punch's plotting grid in the global x [m]; ``values`` its SI histories
    (the moment about its own centre); ``contact_set`` per output time, global x [m]."""

    center: float                          # [m]
    half_width: float                      # a [m]
    given: tuple[str, ...]
    values: dict[str, np.ndarray]
    x: np.ndarray                          # [m], global
    pressure: np.ndarray                   # [Pa], (len(x), len(times))
    contact_set: list[list[tuple[float, float]]]
    flags: list[str]
    error_estimate: float

    def display(self, quantity: str) -> np.ndarray:
        """History of a quantity in its display unit (mm, mrad, kN/m, kN·m/m)."""
        return self.values[quantity] / QUANTITY_UNITS[quantity][1]

    @property
    def span(self) -> tuple[float, float]:
        """The punch's zone ``(center - a, center + a)`` [m]."""
        return (self.center - self.half_width, self.center + self.half_width)

    def negative_intervals(self, index: int) -> list[tuple[float, float]]:
        """The lifted parts of the punch (global x [m]) at output ``index``, or where its
        full-contact pressure is negative beyond its error band (see
        :meth:`ResultView.lift_off_band`)."""
        c = self.center
        if index < len(self.contact_set):
            local = [(lo - c, hi - c) for lo, hi in self.contact_set[index]]
            lifted = lifted_intervals(local, self.half_width)
            if lifted:
                return [(lo + c, hi + c) for lo, hi in lifted]
        if "contact_lost" not in self.flags:
            return []
        peak = float(np.nanmax(np.abs(self.pressure))) if self.pressure.size else 0.0
        band = max(self.error_estimate, 1e-12) * peak
        return negative_intervals(self.x, self.pressure[:, index] + band)


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
    # the times [day] where a given load jumps (of any punch of several): the histories
    # are drawn broken there (:func:`load_jumps`)
    jumps: tuple[float, ...] = ()
    # several punches (the ``punches`` form of a scene), in order; empty for one punch.
    # Then ``x`` and ``pressure`` run over the whole surface (NaN rows between punches
    # break the line), ``contact_set`` is the union of the punches' zones, and
    # ``values`` and ``given`` are those of the first punch (each one's are here)
    punches: list[PunchResult] = field(default_factory=list)

    @property
    def several(self) -> bool:
        """Whether the result is of a scene of several punches (``punches``)."""
        return bool(self.punches)

    @property
    def span(self) -> tuple[float, float]:
        """The loaded stretch of the surface [m]: ``(-a, a)``, or from the left edge of
        the leftmost punch to the right edge of the rightmost."""
        if not self.punches:
            a = self.geometry.half_width
            return (-a, a)
        return (min(p.span[0] for p in self.punches), max(p.span[1] for p in self.punches))

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
        contact model lifted part of the base off, the lifted parts of the base (of every
        punch, for several)."""
        if self.punches:
            return [span for p in self.punches for span in p.negative_intervals(index)]
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
    result carries; None for a result that carries none, or whose scene has no coating
    (the bare layer: no coating model, whose error of 0 % the page stated)."""
    if not view.scene.get("coating"):
        return None
    estimate = view.info.get("model_error_estimate")
    if not isinstance(estimate, (int, float)):
        return None
    # (the FE check measures one punch: a report on screen is of another scene)
    evidence = model_error_evidence(view.scene, float(estimate),
                                    None if view.punches else check)
    parts = view.info.get("model_error")
    if evidence["source"] == "measured" or not isinstance(parts, Mapping):
        return evidence
    # whose error it is (a tilt of 0.3 % of the settlement made it the moment's)
    punch = parts.get("punch")
    if view.punches and isinstance(punch, int) and 0 <= punch < len(view.punches):
        quantity = model_error_quantity(view.punches[punch].given, parts.get("part"))
        # (the punch is named whatever the part: a bound of both names no unknown)
        evidence["quantity"] = (f"{quantity} of punch {punch + 1}" if quantity
                                else f"punch {punch + 1}")
    elif isinstance(view.scene.get("loading"), Mapping):
        evidence["quantity"] = model_error_quantity(view.scene["loading"], parts.get("part"))
    return evidence


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


def load_jumps(loading: Mapping[str, Any], times: np.ndarray) -> tuple[float, ...]:
    """The times [day] in ``(times[0], times[-1]]`` where a given load of ``loading``
    (name -> load history of the time [day] after loading) jumps: every history jumps
    with it, between the output times either side, and is not to be drawn straight
    across (a step of the new footing's force at one year read as a slope of two weeks,
    a teacher's audit)."""
    times = np.asarray(times, dtype=float)
    if times.size < 2:
        return ()
    lo, hi = float(times[0]), float(times[-1])
    found = {b for profile in loading.values()
             for b in profile.jump_points(lo, hi)}
    return tuple(sorted(found))


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
    """Show an exact zero where a quantity is round-off next to its partner's size
    (:func:`core.scene.without_round_off`, as the core's design check reads them).

    A centred load gives a tilt of 1e-18 rad, which an autoscaled plot would blow up into
    a curve. Downloads keep the solver's numbers untouched.
    """
    values.update(without_round_off(values, a))


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
    if getattr(solution, "punches", None) is not None:
        return _prepare_punches(solution, scene)
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
                                   for zones in getattr(solution, "contact_set", None) or []],
                      jumps=load_jumps(getattr(scene_obj, "loading", {}), times))


def _punch_result(p: Any, spec: dict[str, Any]) -> PunchResult:
    """One punch of a :class:`core.scene.PunchesSolution` ready to draw."""
    c = float(p.center)
    a = float(p.scene.half_width)
    times = np.asarray(p.times, dtype=float)
    values = {q: np.asarray(getattr(p, q), dtype=float) for q in QUANTITIES}
    for q, profile in p.scene.loading.items():
        values[q] = _values(profile, times)  # as given (see prepare_view)
    _drop_round_off(values, a)
    grid = getattr(p, "x", None)
    if grid is not None and len(grid) >= 101:
        x = np.asarray(grid, dtype=float)
        pressure = np.asarray(p.pressure_on_grid, dtype=float)
    else:
        x = np.linspace(-a, a, LINE_POINTS)
        pressure = np.asarray(p.pressure(x), dtype=float)
    err = p.info.get("error_estimate")
    return PunchResult(
        center=c, half_width=a, given=tuple(q for q in QUANTITIES if q in spec["loading"]),
        values=values, x=x + c, pressure=pressure.reshape(len(x), len(times)),
        contact_set=[[(float(lo), float(hi)) for lo, hi in zones] for zones in p.contact_set],
        flags=list(p.flags),
        error_estimate=float(err) if isinstance(err, (int, float)) else 0.0)


def _prepare_punches(solution: Any, scene: dict[str, Any]) -> ResultView:
    """The :class:`ResultView` of a scene of several punches (a ``PunchesSolution``)."""
    times = np.asarray(solution.times, dtype=float)
    punches = [_punch_result(p, spec) for p, spec in zip(solution.punches, scene["punches"],
                                                           strict=True)]
    # the pressure over the whole surface: each punch's grid, a NaN row between two
    # (the line breaks over the free surface, where q = 0)
    order = sorted(range(len(punches)), key=lambda k: punches[k].center)
    gap_x, gap_q = np.array([np.nan]), np.full((1, len(times)), np.nan)
    xs, qs = [], []
    for k in order:
        xs += [punches[k].x, gap_x]
        qs += [punches[k].pressure, gap_q]
    x, pressure = np.concatenate(xs[:-1]), np.concatenate(qs[:-1])
    # q(x, t) over the loaded stretch, 0 on the free surface between the punches
    lo = min(p.span[0] for p in punches)
    hi = max(p.span[1] for p in punches)
    xi = np.linspace(lo, hi, IMAGE_X)
    qi = np.zeros((IMAGE_X, len(times)))
    for p in punches:
        inside = (xi >= p.x[0]) & (xi <= p.x[-1])
        for j in range(len(times)):
            qi[inside, j] = np.interp(xi[inside], p.x, p.pressure[:, j])
    image = _resample_time(times, qi, IMAGE_T)
    geometry = _punches_geometry(solution)
    # a flag of any punch is the scene's (the badges read the names); the message says
    # which punch raised it
    flags: list[str] = []
    messages: dict[str, str] = {}
    for k, p in enumerate(solution.punches):
        for flag in p.flags:
            if flag not in flags:
                flags.append(flag)
            text = dict(getattr(p, "flag_messages", {}) or {}).get(flag, flag)
            messages[flag] = "; ".join(m for m in (messages.get(flag), f"punch {k + 1}: {text}")
                                       if m)
    info = {k: v for k, v in dict(solution.info).items() if k != "flags"}
    info["flags"] = list(solution.flags)
    # the coating model's error of the scene: its worst punch's (the page showed none
    # while every punch was within solver.model_tol)
    errors = [dict(getattr(p, "model_error", None) or {}) for p in solution.punches]
    if errors and all(isinstance(e.get("estimate"), (int, float)) for e in errors):
        worst = max(range(len(errors)), key=lambda k: errors[k]["estimate"])
        info["model_error_estimate"] = float(errors[worst]["estimate"])
        info["model_error"] = {**errors[worst], "punch": worst}
    first = solution.punches[0].info
    info.setdefault("contact", first.get("contact", "full") if len(punches) == 1 else "full")
    union = [sorted(zone for p in punches for zone in p.contact_set[j])
             for j in range(len(times))]
    return ResultView(scene=scene, given=punches[0].given, times=times,
                      values=dict(punches[0].values), x=x, pressure=pressure, image=image,
                      geometry=geometry, flags=flags, flag_messages=messages, info=info,
                      contact_set=union, punches=punches,
                      jumps=tuple(sorted({t for p in solution.punches
                                          for t in load_jumps(p.scene.loading, times)})))


def _punches_geometry(solution: Any) -> Geometry:
    """The drawing of several punches: the coating along the loaded stretch (each punch's
    profiles under it, straight between two), each punch's base shape (in the scene's
    order), in global x."""
    geos = [(scene_geometry(s), c) for s, c in zip(solution.scene.scenes,
                                                   solution.scene.centers, strict=True)]
    left_first = sorted(geos, key=lambda gc: gc[1])
    n_layers = len(geos[0][0].thickness)
    first = geos[0][0]
    return Geometry(
        x=np.concatenate([g.x + c for g, c in left_first]),
        shape=np.concatenate([g.shape for g, _ in left_first]),
        thickness=[np.concatenate([g.thickness[k] for g, _ in left_first])
                   for k in range(n_layers)],
        modulus=[np.concatenate([g.modulus[k] for g, _ in left_first])
                 for k in range(n_layers)],
        base_thickness=first.base_thickness, base_modulus=first.base_modulus,
        half_width=float(sum(g.half_width for g, _ in geos)),
        punch_x=[g.x + c for g, c in geos], punch_shape=[g.shape for g, _ in geos])
