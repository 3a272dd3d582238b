"""The answer for a scene in SI units (:class:`SceneSolution`) and its serialisation:
JSON (``to_dict``/``to_json``), CSV of the histories and of the pressure, the flags
that make an answer doubtful and the last check that it is finite.

:func:`core.scene.solve` builds a :class:`SceneSolution` from the dimensionless answer
(the conversion back: :mod:`core.scene.dimensionless`).
"""

from __future__ import annotations

import json
import math
import re
from functools import cached_property, lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np

from core.cache import StageCache, fingerprint
from core.coating import THIN_LAYER, model_error_estimate, model_error_map, tilt_share
from core.engines.layered import EXACT_LAYERED, NO_COATING, corner_reach, uniform_layers
from core.problem import QUANTITIES, positions
from core.scene.contact_zone import (
    LIFT_OFF_SHARE,
    contact_width,
    lift_off_length,
    narrowest_zone,
)
from core.scene.design import DesignCheck, DesignLimits, design_check
from core.scene.display import (
    HISTORIES,
    answered_settings,
    corner_note,
    days_text,
    html_summary,
    text_summary,
)
from core.scene.display import to_dataframe as _to_dataframe
from core.scene.display import to_xarray as _to_xarray
from core.scene.load_rates import oscillations, undersampled_loads
from core.scene.model import Scene
from core.scene.records import PROGRAM, csv_header
from core.scene.schema import SCHEMA_VERSION, _jsonable
from core.version import VERSION

if TYPE_CHECKING:
    from collections.abc import Sequence

    import pandas
    import xarray

    from core.problem import ContactSolution
    from core.scene.dimensionless import DimensionlessProblem

#: The thin-coating model is doubtful where sum h_k reaches this fraction of 2a (or of
#: the narrowest contact zone of a punch that lifts off).
THICK_COATING_RATIO = 0.1
#: Tilts beyond this many radians are not small.
LARGE_TILT = 0.01
#: A punch base moving down more than this share of the foundation's thickness (base
#: and coating) strains it beyond the small-strain (linear) model: an average strain of
#: 1 % is about three times the crushing strain of concrete.
LARGE_SETTLEMENT = 0.01
#: A coating compressed by more than this share of its thickness (its compliance times
#: the pressure, over its thickness) is strained beyond its small-strain (linear) model:
#: a soft pad pressed by more than its own thickness was answered with every badge green.
LARGE_COATING_STRAIN = 0.01
#: Points of the default plotting grid :attr:`SceneSolution.x`.
PLOT_POINTS = 201

#: One-line explanations of the flags a solution may carry.
FLAG_MESSAGES: dict[str, str] = {
    "contact_lost": "The computed pressure is negative somewhere: part of the punch base "
                    "lifts off, so this full-contact answer is not physical.",
    "thick_coating": f"The coating is {THICK_COATING_RATIO:g} of the punch width (or of "
                     "the narrowest contact zone, where the punch lifts off) or thicker "
                     "somewhere: the thin (Winkler) coating model is doubtful.",
    "stiff_coating": "A coating layer is stiffer than the base at loading somewhere: the "
                     "thin-coating model assumes soft coatings.",
    "no_contact": "The punch does not touch the coating at some output times: q = 0 and "
                  "P = M = 0 there (the given settlement and tilt hold it clear of the "
                  "surface; the settlement is positive downward, into the foundation).",
    "large_settlement": f"The punch base moves down more than {100 * LARGE_SETTLEMENT:g} % "
                        "of the foundation's thickness (base and coating), or the coating "
                        "is compressed by more than "
                        f"{100 * LARGE_COATING_STRAIN:g} % of its own thickness: strains "
                        "this large are beyond the small-strain (linear elastic) model.",
    "large_tilt": f"The tilt exceeds {LARGE_TILT:g} rad: the small-angle assumption is "
                  "doubtful.",
    "model_error": "The estimated error of the thin-coating model (info.model_error_estimate, "
                   "from measurements against a resolved finite-element model) exceeds "
                   "solver.model_tol: check the coating model (coated-punch check).",
    "beyond_model_map": "The coating lies outside the range its model's error was measured "
                        "on (info.model_error.beyond_map: softer or stiffer against the base, or "
                        "nearer to incompressible): the estimate is an extrapolation. "
                        "Measure it: coated-punch check, or the explorer's coating check.",
    "tol_not_met": "The solver could not reach the requested tolerance: see info.message.",
    "unresolved_input": "A profile has features finer than the quadrature resolves: "
                        "see info.message.",
    "contact_set_unverified": "The unilateral contact set failed its final check (q < 0 "
                              "on it, or the surfaces overlap off it): see info.message.",
    "undersampled_load": "A given load oscillates faster than the output times sample it "
                         "(fewer than 8 of them per period at their widest spacing; "
                         "info.undersampled_loads names it): the answer is right at each "
                         "output time, but its "
                         "histories drawn through them are aliased, and the largest values "
                         "read there (the design check's) can miss the peaks between them. "
                         "Ask for more output times (times.count) or a shorter span.",
}

UNITS: dict[str, str] = {
    "times": "day (after loading)",
    **{name: unit for name, (unit, _, _) in HISTORIES.items()},
    # (a data file's "N" read as a force to an engineer filing it)
    "moment": "N·m/m (a moment per metre of strip: N)",
    "x": "m (from the punch centre)",
    "pressure": "Pa (rows: x, columns: times)",
}


def plotting_grid(half_width: float, count: int = PLOT_POINTS) -> np.ndarray:
    """``count`` points of ``[-a, a]`` [m], clustered toward the edges (Chebyshev-Lobatto)."""
    x = -half_width * np.cos(np.pi * np.arange(count) / (count - 1))
    x[0], x[-1] = -half_width, half_width
    if count % 2:
        x[count // 2] = 0.0
    return x


#: The model-error map read on a scene's stack, shared by scenes of the same geometry
#: and base: reading it costs ~0.7 ms, more than a load change's solve.
_MODEL_ERROR_MAPS = StageCache("scene_model_error_map", max_items=128, max_bytes=2**20)


def scene_model_error(scene: Scene, share_of_tilt: float,
                      zone: float | None = None) -> dict[str, Any]:
    """:func:`core.coating.model_error_estimate` of ``scene``, its map remembered.

    The map is read on the geometry, the base modulus at loading, the base thickness and
    the narrowest contact zone ``zone`` [m] of an answer that lifts off (None in full
    contact; :func:`core.coating.model_error_map`); the answer enters through the share
    of tilt, which weighs the moment part, and that zone. The returned dict also holds
    ``"zone_m"``, the zone the map was read at (None: the punch width).
    """
    if zone is None:
        key = fingerprint("model_error_map", scene._geometry_key, scene.modulus_at_loading(),
                          scene.base_thickness)
        mapped, _ = _MODEL_ERROR_MAPS.get_or_compute(
            key, lambda: _read_only(model_error_map(scene)))
    else:
        # read for this answer's zone (~0.3 ms a layer): a load change moves the zone, and
        # the geometry's stages stay as they were
        mapped = model_error_map(scene, zone)
    return {**model_error_estimate(scene, share_of_tilt, mapped), "zone_m": zone}


def pressure_points(x: Any, times: int) -> np.ndarray:
    """``x`` as positions [m] where a pressure is asked at ``times`` output times
    (:func:`core.problem.positions`)."""
    return positions(x, times, "m")


def corner_pressure(scene: Scene, coating_model: str,
                    contact_set: list[list[tuple[float, float]]]) -> dict[str, Any] | None:
    """Where the answer's pressure is unbounded: the punch corners [m] in contact at some
    time, for a model that carries the rigid corner's square-root singularity (the exact
    layered kernel, coated or bare; the thin layer's coating springs bound q), and the
    distance [m] from a corner within which ``pressure(x)`` holds its value there
    (:func:`core.engines.layered.corner_reach`). None when no
    corner is in contact or the model bounds q."""
    if coating_model not in (EXACT_LAYERED, NO_COATING):
        return None
    a = scene.half_width
    # no contact set: a full-contact answer; an empty zone list: no contact at that time
    zones = [zone for zones in contact_set for zone in zones] if contact_set else [(-a, a)]
    reach = a * (1.0 - 2.0 * LIFT_OFF_SHARE)  # a zone end within rounding of the corner
    corners = sorted({c for lo, hi in zones
                      for c, touches in ((-a, lo <= -reach), (a, hi >= reach)) if touches})
    if not corners:
        return None
    held = a * (1.0 - corner_reach(uniform_layers(scene) if scene.coating else [], a))
    # without coating q ~ K / sqrt(distance) holds from the held distance on (measured on
    # the bare layer preset: q sqrt(d) constant within 0.14 % from 1 to 2 mm, 1.2 % to
    # 10 mm); under a coating the answer is resolved to half the top layer's thickness
    # from the corner (at most 5 % of the half-width), where q sqrt(d) is not yet
    # constant (20 mm coating: it changes 36 % from 10 to 20 mm), so the distance where a
    # limit is passed is not estimated
    return {"corners_m": [float(c) for c in corners], "held_within_m": held,
            "asymptotic": not scene.coating}


#: Gauss-Legendre points (in theta, x = a cos theta) per piece of the pressure's integral
#: between the held bands (:func:`held_shares`), split at the free zone ends of the answer
#: (q sin(theta) is smooth inside a piece; a free end's square root at a piece's end: the
#: bare layer's heel lifted at e = 0.6 a, 5.6e-8 of P off an adaptive quadrature split
#: there, 3.5e-6 with 32 points, 6e-4 unsplit with 96). Where the pieces' points at every
#: output time would pass ``HELD_VALUES`` (zones that move as the loads or the base
#: change: every time's integral is split at every time's ends) one piece of
#: ``HELD_UNSPLIT`` points, fewer if the times ask it (6.6e-6 of P off on that heel).
HELD_QUADRATURE = 128
HELD_UNSPLIT = 1024
HELD_VALUES = 1_000_000


@lru_cache(maxsize=8)
def _gauss_legendre(count: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1], made once per count (128 of them took
    1.8 ms, as long as the bare layer's whole load change)."""
    nodes, weights = np.polynomial.legendre.leggauss(count)
    nodes.flags.writeable = weights.flags.writeable = False
    return nodes, weights


def held_shares(pressure: Any, force: np.ndarray, moment: np.ndarray, half_width: float,
                held: float, contact_set: list[list[tuple[float, float]]] | None = None
                ) -> dict[str, float | None]:
    """What the rows held near the corners leave out (:func:`corner_pressure`): the largest
    share over the output times of the force ``force`` [N/m] and of the moment ``moment``
    [N·m/m] that the unbounded pressure carries within ``held`` [m] of the corners beyond
    what its held value there carries, as ``held_force_share`` and ``held_moment_share``
    [-] (None where the moment is 0 throughout). ``pressure(x)`` [Pa] is the answer's
    (held within ``held``); the force and moment are its exact resultants, so what the
    held rows miss is the resultant less their integral. ``contact_set`` [m]: the zones
    per output time; the integral at every time is split at the free ends of them all.

    Measured: a uniform 100 mm coating under P = 600 kN/m, M = 120 kN m/m, 2.2 % of P and
    6.6 % of M (a 2 m one 9.0 % and 20 %); the bare layer preset 1.1 % of P."""
    a = float(half_width)
    edge = 1.0 - held / a
    force = np.asarray(force, dtype=float)
    moment = np.asarray(moment, dtype=float)
    times = max(force.size, 1)
    ends = sorted({float(v) / a for zones in (contact_set or []) for zone in zones
                   for v in zone if -edge < float(v) / a < edge})
    cuts = [-edge, *ends, edge]
    count = HELD_QUADRATURE
    if (len(cuts) - 1) * count * times > HELD_VALUES:
        cuts = [-edge, edge]
        count = max(HELD_QUADRATURE, min(HELD_UNSPLIT, HELD_VALUES // times))
    nodes, weights = _gauss_legendre(count)
    inner_force = np.zeros(force.shape)
    inner_moment = np.zeros(force.shape)
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        # a piece at a time: all the points at once could pass pressure(x)'s own bound
        low, high = math.acos(hi), math.acos(lo)
        theta = 0.5 * (low + high) + 0.5 * (high - low) * nodes
        x = a * np.cos(theta)
        dx = 0.5 * (high - low) * weights * a * np.sin(theta)
        q = pressure(x)
        inner_force = inner_force + dx @ q
        inner_moment = inner_moment + (dx * x) @ q
    sides = pressure(np.array([-a * edge, a * edge]))
    arm = a * edge + 0.5 * held           # the held rows' centroids, from the centre
    force_left = force - inner_force - (sides[0] + sides[1]) * held
    moment_left = moment - inner_moment - (sides[1] - sides[0]) * held * arm
    # the largest share at any one time (a share at a small load counts as much); times
    # that carry next to nothing (a ramp from 0) say nothing of it
    largest = float(np.max(np.abs(force), initial=0.0))
    pressed = np.abs(force) > 1e-6 * largest
    force_share = (float(np.max(np.abs(force_left[pressed]) / np.abs(force[pressed])))
                   if pressed.any() else 0.0)
    turning = np.abs(moment)
    turned = turning > max(1e-6 * float(np.max(turning, initial=0.0)), 1e-9 * largest * a)
    moment_share = (float(np.max(np.abs(moment_left[turned]) / turning[turned]))
                    if turned.any() else None)
    return {"held_force_share": force_share, "held_moment_share": moment_share}


def strain_share(scene: Scene, settlement: Any, tilt: Any, pressure_max: float) -> float:
    """How far the answer is from small strains: the larger of the punch base's downward
    reach ``max |delta| + a max |alpha|`` [m] over the histories ``settlement`` [m] and
    ``tilt`` [rad] as a share of ``LARGE_SETTLEMENT`` times the foundation's thickness
    (base and thickest coating stack), and of the coating's compression, its compliance
    over its thickness times the largest pressure ``pressure_max`` [Pa], as a share of
    ``LARGE_COATING_STRAIN`` (:func:`coating_strain_per_pressure`: the largest ratio
    with the largest pressure, a bound where the coating varies along x). Above 1 raises
    ``large_settlement``. It scales with the loads."""
    settlement = np.asarray(settlement, dtype=float)
    tilt = np.asarray(tilt, dtype=float)
    reach = (float(np.max(np.abs(settlement), initial=0.0))
             + scene.half_width * float(np.max(np.abs(tilt), initial=0.0)))
    thickness = scene.base_thickness + scene.sample_extremes["coating_thickness_max_m"]
    strain = coating_strain_per_pressure(scene) * max(float(pressure_max), 0.0)
    return max(reach / (LARGE_SETTLEMENT * thickness), strain / LARGE_COATING_STRAIN)


def coating_strain_per_pressure(scene: Scene) -> float:
    """The largest compressive strain of the coating per unit pressure [1/Pa]: its
    compliance ``sum c_k`` over its thickness ``sum h_k`` (the thin-layer model's
    ``(1 - nu^2) / E`` smooth, the constrained ``(1 + nu)(1 - 2 nu) / ((1 - nu) E)``
    bonded), the largest on the scene's samples (:attr:`Scene.sample_extremes`: once
    per geometry, not per load step); 0 without coating."""
    return scene.sample_extremes["coating_strain_per_pa"]


def thick_coating(scene: Scene, zone: float | None = None) -> bool:
    """Whether the coating reaches :data:`THICK_COATING_RATIO` of the punch width, or of
    the narrowest contact zone ``zone`` [m] of an answer that lifts off."""
    width = 2 * scene.half_width if zone is None else zone
    return scene.sample_extremes["coating_thickness_max_m"] >= THICK_COATING_RATIO * width


def _read_only(mapped: tuple[np.ndarray, dict[str, np.ndarray]]
               ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The map's arrays, locked against writes (scenes share them)."""
    x, parts = mapped
    for values in (x, *parts.values()):
        values.setflags(write=False)
    return x, parts


class SceneSolution:
    """The answer for a scene in SI units (see :func:`solve`).

    ``times`` [day after loading], ``settlement`` [m], ``tilt`` [rad], ``force`` [N/m],
    ``moment`` [N] are arrays over ``times``; ``pressure(x)`` gives q [Pa] at points
    ``x`` [m] of ``[-a, a]``; ``x`` is a default plotting grid [m]; ``flags`` names what
    makes the answer doubtful or unphysical (``flag_messages`` explains each).
    ``contact_set[k]`` lists the ``(start, end)`` intervals [m] where q > 0 at ``times[k]``
    (``[(-a, a)]`` in full contact); ``info["contact"]`` names the contact model that
    answered (``"full"`` or ``"unilateral"``); :attr:`contact_width` and
    :attr:`lift_off_length` [m] are its lengths (:mod:`core.scene.contact_zone`).
    """

    def __init__(self, scene: Scene, problem: DimensionlessProblem,
                 solution: ContactSolution) -> None:
        self.scene = scene
        self.problem = problem
        self.dimensionless = solution
        a = scene.half_width
        self.times = np.array(scene.times, dtype=float)
        modulus = problem.modulus_after_loading(self.times)
        self._pressure_scale = modulus / problem.plane_factor
        self.settlement = a * np.asarray(solution.settlement, dtype=float)
        self.tilt = np.asarray(solution.tilt, dtype=float).copy()
        self.force = np.asarray(solution.force, dtype=float) * self._pressure_scale * a
        self.moment = np.asarray(solution.moment, dtype=float) * self._pressure_scale * a * a
        self.x = plotting_grid(a)
        self.contact_set = [[(a * lo, a * hi) for lo, hi in zones]
                            for zones in getattr(solution, "contact_set", [])]
        # the exact layered kernel (core.engines.layered.answer) carries its own estimate
        layered = solution.info.get("layered_model_error")
        self.model_error = dict(layered) if layered else scene_model_error(
            scene, tilt_share(a, self.settlement, self.tilt),
            narrowest_zone(self.contact_set, a))
        self._undersampled = undersampled_loads(
            {f"loading.{q}": profile for q, profile in scene.loading.items()}, self.times)
        self.flags = self._flags(solution)
        self.flag_messages = {
            name: FLAG_MESSAGES.get(name, f"{name}: {solution.info.get('message', '')}")
            for name in self.flags}
        self.info = dict(solution.info)
        self.info["flags"] = list(self.flags)
        self.info["model_error_estimate"] = self.model_error["estimate"]
        self.info["coating_model"] = solution.info.get("coating_model", THIN_LAYER)
        corners = corner_pressure(scene, self.info["coating_model"], self.contact_set)
        if corners is not None:
            corners.update(held_shares(self.pressure, self.force, self.moment,
                                       scene.half_width, corners["held_within_m"],
                                       self.contact_set))
            self.info["corner_pressure"] = corners
        self.info["model_error"] = dict(self.model_error)
        if self._undersampled:
            self.info["undersampled_loads"] = list(self._undersampled)
        self.info["dimensional"] = self._extras()

    def _flags(self, solution: ContactSolution) -> list[str]:
        scene = self.scene
        flags = [str(f) for f in solution.info.get("flags", [])]
        thin = solution.info.get("coating_model") != EXACT_LAYERED
        # the extremes on the scene's samples, shared by scenes of the same geometry
        # against the narrowest contact zone where the punch lifts off
        if any(not zones for zones in self.contact_set):
            flags.append("no_contact")  # often a settlement's sign: said, not left to q = 0
        if thin and thick_coating(scene, self.model_error.get("zone_m")):
            flags.append("thick_coating")
        if self.model_error["estimate"] > scene.model_tol:
            flags.append("model_error")
        if thin and self.model_error.get("beyond_map"):
            flags.append("beyond_model_map")
        e0 = self.problem.modulus_at_loading
        if thin and any(largest > e0 for largest in scene.layer_modulus_max):
            flags.append("stiff_coating")
        # between the output times too (the default engine samples the load histories)
        largest_tilt = max(float(np.max(np.abs(self.tilt))) if self.tilt.size else 0.0,
                           float(solution.info.get("max_abs_tilt", 0.0)))
        if strain_share(scene, self.settlement, largest_tilt,
                        float(np.nanmax(self.pressure_on_grid, initial=0.0))) > 1.0:
            flags.append("large_settlement")
        if largest_tilt > LARGE_TILT:
            flags.append("large_tilt")
        if self._undersampled:
            flags.append("undersampled_load")
        return list(dict.fromkeys(flags))

    def _extras(self) -> dict[str, Any]:
        scene, problem = self.scene, self.problem
        extremes = scene.sample_extremes
        return {
            "scene_key": scene.key,
            "statement": scene.statement,
            "lam": problem.lam,
            "modulus_at_loading_Pa": problem.modulus_at_loading,
            "age_at_loading_days": problem.age_at_loading,
            "m_star_min": extremes["m_star_min"],
            "m_star_max": extremes["m_star_max"],
            "gap_max_m": extremes["gap_max_m"],
            "coating_thickness_max_m": extremes["coating_thickness_max_m"],
            "breakpoints_m": list(scene.breakpoints),
            "gap_steps_m": list(scene.gap_steps),
            "min_pressure_Pa": float(np.min(self.pressure_on_grid)),
            "max_pressure_Pa": float(np.max(self.pressure_on_grid)),
        }

    @property
    def contact_lost(self) -> bool:
        """Whether the pressure is negative somewhere (the answer is then not physical)."""
        return "contact_lost" in self.flags

    @property
    def contact_width(self) -> np.ndarray:
        """The contact width [m] at each output time: the length of :attr:`contact_set`
        (``2a`` for a full-contact answer, ``contact_lost`` or not; see
        :func:`core.scene.contact_width`)."""
        return contact_width(self.contact_set, self.scene.half_width)

    @property
    def lift_off_length(self) -> np.ndarray:
        """The length of the base lifted off [m] at each output time: ``2a`` less
        :attr:`contact_width` (:func:`core.scene.lift_off_length`)."""
        return lift_off_length(self.contact_set, self.scene.half_width)

    def pressure(self, x: Any) -> np.ndarray:
        """Contact pressure q [Pa] at points ``x`` [m] of ``[-a, a]``, shape (len(x), len(times)).

        Points outside ``[-a, a]`` are refused (ValueError), and so are more points than
        :data:`core.limits.MAX_PRESSURE_VALUES` values allow (checked before any work).
        """
        a = self.scene.half_width
        xs = pressure_points(x, self.times.size)
        if np.any(np.abs(xs) > a * (1 + 1e-12)):
            raise ValueError(f"x: the pressure is defined on [-a, a] = [{-a:g}, {a:g}] m only")
        # x = +-a can land a rounding error outside [-1, 1] after the division
        q_star = self.dimensionless.pressure(np.clip(xs / a, -1.0, 1.0))
        return q_star * self._pressure_scale[None, :]

    @cached_property
    def pressure_on_grid(self) -> np.ndarray:
        """``pressure(x)`` on the plotting grid, shape (201, len(times)) [Pa]."""
        return self.pressure(self.x)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able dict: the scene, the histories, q on ``x`` at every time, info, flags.

        Units are listed under ``units``; non-finite numbers become ``null``.
        """
        return _jsonable({
            "format": "coated-punch solution",
            "program": PROGRAM,
            "version": VERSION,
            "solver": answered_settings(self),
            "schema_version": SCHEMA_VERSION,
            "scene": self.scene.to_dict(),
            "units": UNITS,
            "times": self.times,
            "settlement": self.settlement,
            "tilt": self.tilt,
            "force": self.force,
            "moment": self.moment,
            "x": self.x,
            "pressure": self.pressure_on_grid,
            "flags": self.flags,
            "flag_messages": self.flag_messages,
            "contact_set": [[list(zone) for zone in zones] for zones in self.contact_set],
            "info": self.info,
            "design_check": None if (check := self.design_check()) is None else check.to_dict(),
        })

    def __repr__(self) -> str:
        """A few lines: the scene, the figures at the last time with units, the error
        estimates, the flags and the engine."""
        return text_summary(self)

    def _repr_html_(self) -> str:
        """The summary of ``repr`` as an HTML table, flags in red with their messages."""
        return html_summary(self)

    def to_xarray(self) -> xarray.Dataset:
        """An ``xarray.Dataset`` over ``time`` [day] and ``x`` [m]: ``pressure`` q(x, t)
        [Pa] on :attr:`x`, ``settlement`` [m], ``tilt`` [rad], ``force`` [N/m], ``moment``
        [N], ``contact_width`` [m]; units and long names in the variables' attributes; the
        package version, the scene (canonical JSON), the solver settings (JSON), the flags
        and the error estimates in the dataset's. Needs xarray (``ImportError`` naming
        the extra to install otherwise)."""
        return _to_xarray(self)

    def to_dataframe(self) -> pandas.DataFrame:
        """The histories as a ``pandas.DataFrame`` indexed by ``time`` [day]: columns
        ``settlement`` [m], ``tilt`` [rad], ``force`` [N/m], ``moment`` [N],
        ``contact_width`` [m]; ``attrs`` hold the dataset attributes of :meth:`to_xarray`
        and ``units``. Needs pandas."""
        return _to_dataframe(self)

    def plot(self, count: int | None = None,
             times: Sequence[float] | None = None) -> Any:
        """A ``holoviews.Layout``: q(x) [kPa or MPa] at ``count`` output times (default
        :data:`core.scene.plotting.PLOT_CURVES`) or at those nearest to ``times`` [day],
        coloured by time; settlement delta [mm] and tilt alpha [mrad] over time; the flags
        in the title, lift-off in the pressure plot's title and shaded. Options are set
        for the Bokeh backend (:mod:`core.scene.plotting`)."""
        from core.scene.plotting import PLOT_CURVES, plot_solution

        return plot_solution(self, PLOT_CURVES if count is None else count, times)

    def to_json(self) -> str:
        """:meth:`to_dict` as compact JSON text."""
        return json.dumps(self.to_dict(), separators=(",", ":"), allow_nan=False)

    def to_csv(self, header: bool = True) -> str:
        """The histories as CSV: time [day], settlement [m], tilt [rad], force [N/m], moment [N].

        When the unilateral contact model answered, the contact set follows: the contact
        length [m] and the ends of each zone [m] (``zone1_start_m, zone1_end_m, ...``,
        ``nan`` where a time has fewer zones). ``header``: start with the ``#`` lines the
        command line writes (:func:`core.scene.csv_header`: version, scene, solver
        settings, error estimate, flags, design check); ``pandas.read_csv(text,
        comment="#")`` reads the table.
        """
        names, columns = history_columns(self)
        lines = [csv_header(self, "histories").rstrip("\n")] if header else []
        lines.append("time_day," + ",".join(names))
        lines.extend(",".join(repr(float(v)) for v in (t, *row))
                     for t, row in zip(self.times, zip(*columns, strict=True), strict=True))
        return "\n".join(lines) + "\n"

    def pressure_csv(self, x: Any = None, header: bool = True) -> str:
        """q(x, t) as CSV in long form: time [day], x [m], pressure [Pa] (default x: ``.x``);
        ``header`` as :meth:`to_csv`."""
        xs = self.x if x is None else np.atleast_1d(np.asarray(x, dtype=float))
        q = self.pressure_on_grid if x is None else self.pressure(xs)
        lines = [csv_header(self, "contact pressure q(x, t)").rstrip("\n")] if header else []
        corner = corner_note(self.info.get("corner_pressure")) if header else None
        if corner is not None:
            lines.append(corner)
        lines.append("time_day,x_m,pressure_Pa")
        for j, t in enumerate(self.times):
            tt = repr(float(t))
            lines.extend(f"{tt},{float(xi)!r},{float(qi)!r}" for xi, qi in zip(xs, q[:, j],
                                                                               strict=True))
        return "\n".join(lines) + "\n"

    def design_check(self, limits: DesignLimits | None = None) -> DesignCheck | None:
        """The design check over the whole history (:func:`core.scene.design.design_check`)
        against ``limits`` [Pa, m, rad] (default: the scene's ``limits``); None when
        neither gives a limit."""
        limits = limits if limits is not None else self.scene.limits
        if limits is None or limits.empty:
            return None
        return design_check(self, limits)


def history_columns(result: SceneSolution, prefix: str = ""
                    ) -> tuple[list[str], list[list[float]]]:
    """The columns of :meth:`SceneSolution.to_csv` after the time: their names (each
    starting with ``prefix``) and their values over ``result.times``.

    Settlement [m], tilt [rad], force [N/m], moment [N]; when the unilateral contact model
    answered, the contact length [m] and the ends of each zone [m] (``zone1_start_m``,
    ``zone1_end_m``, ...; ``nan`` where a time has fewer zones), in the coordinates of
    ``result.contact_set``.
    """
    names = [f"{prefix}{name}" for name in
             ("settlement_m", "tilt_rad", "force_N_per_m", "moment_N")]
    columns = [[float(v) for v in getattr(result, q)] for q in QUANTITIES]
    if result.info.get("contact") == "unilateral":
        zones = max((len(z) for z in result.contact_set), default=0)
        names.append(f"{prefix}contact_length_m")
        columns.append([float(w) for w in result.contact_width])
        for j in range(zones):
            names += [f"{prefix}zone{j + 1}_start_m", f"{prefix}zone{j + 1}_end_m"]
            for end in range(2):
                columns.append([float(zones_k[j][end]) if j < len(zones_k) else math.nan
                                for zones_k in result.contact_set])
    return names, columns


def _check_finite(result: SceneSolution) -> None:
    """Refuse an answer with a non-finite value: the last guard of the promise that a
    result never holds NaN or infinity (the checks of :func:`scene_from_dict` catch the
    known causes first, with the field to change)."""
    parts = [(q, getattr(result, q)) for q in QUANTITIES]
    parts.append(("pressure", result.pressure_on_grid))
    for name, values in parts:
        bad = ~np.isfinite(np.asarray(values, dtype=float))
        if bad.any():
            j = int(np.argwhere(bad)[0][-1])  # the time index (last axis)
            message = str(result.info.get("message", ""))
            if "stopped at its limit" in message:
                # the stepper gave up, which says nothing of double precision
                said = _in_days(message.split("time stepping: ", 1)[-1],
                                float(result.problem.age_at_loading))
                raise ValueError(f"{_fastest_load(result.scene)}: the time stepping could "
                                 "not follow the loads: " + said)
            raise ValueError(
                f"scene: the computed {name} is not finite at t = {result.times[j]:.6g} days "
                "after loading: the sizes in this scene (moduli, loads, lengths) are too far "
                "apart for double precision")


#: The stepper's "at t = 539.146 of 2609.93": its times are dimensionless.
_STEPPED_TO = re.compile(r"at t = (\S+) of (\S+?):")


def _in_days(message: str, age_at_loading: float) -> str:
    """The stepper's ``message`` with its dimensionless times ``t = 1 + (age - tau0) /
    tau0`` said in days after loading (it read "at t = 539.146 of 2609.93" over a span of
    18262.5 days), without an estimate of the error of an answer not reached."""
    def days(match: re.Match) -> str:
        reached, end = ((float(match.group(k)) - 1.0) * age_at_loading for k in (1, 2))
        return f"at {days_text(reached)} of {days_text(end)} after loading:"

    # (no estimate of an answer not reached: "estimated error nan" said nothing)
    message = re.sub(r" \(estimated error (?:nan|inf)\)", "", message)
    try:
        return _STEPPED_TO.sub(days, message)
    except ValueError:
        return message


def _fastest_load(scene: Scene) -> str:
    """The field of the load that oscillates most over the solved times (``loading``
    when none oscillates)."""
    end = float(scene.times[-1])
    counts = {q: oscillations(p, 0.0, end) + len(p.breakpoints)
              for q, p in scene.loading.items()}
    name = max(counts, key=lambda q: counts[q])
    return f"loading.{name}" if counts[name] > 0 else "loading"
