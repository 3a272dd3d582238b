"""The validated scene: its fields and what follows from them alone (statement,
breakpoints, sample points, coating compliance and thickness, the gap).

A :class:`Scene` is built by :func:`core.scene.scene_from_dict` (which checks every
field, :mod:`core.scene.validate`); its dimensionless problem comes from
:mod:`core.scene.dimensionless`. Lengths in metres, moduli in pascals, times in days.
"""

from __future__ import annotations

import copy
import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from core.cache import StageCache, fingerprint
from core.coating import DEFAULT_INTERFACE, layer_compliance
from core.problem import STATEMENTS
from core.profiles import Profile, profile_values, without_offset
from core.scene.design import DesignLimits
from core.scene.dimensionless import DimensionlessProblem, to_dimensionless
from core.scene.golden_section import golden_minimum_batched

#: Uniform samples of [-a, a] for the gap minimum and the coating checks (on top of each
#: profile's own sample points).
DENSE_SAMPLES = 4001
# Shared between scenes of the same geometry (a load slider makes a new scene each step):
# the samples of one geometry are ~4100 points, 33 kB.
_SAMPLE_X = StageCache("sample_x", max_items=128, max_bytes=16 * 2**20)
_GAP_MINIMUM = StageCache("gap_minimum", max_items=256, max_bytes=2**20)
# Shared likewise: the extremes on the samples (a solve reports them) and the layers'
# largest moduli (the stiff-coating flag), ~1 ms of each new scene of a known geometry.
_SAMPLE_EXTREMES = StageCache("sample_extremes", max_items=256, max_bytes=2**20)
_LAYER_MODULUS_MAX = StageCache("layer_modulus_max", max_items=256, max_bytes=2**20)




@dataclass(frozen=True, eq=False)
class Layer:
    """One coating layer: profiles of x [m] for ``thickness`` [m], ``modulus`` [Pa], ``poisson``;
    ``interface``: how it is joined to what lies under it (``"smooth"`` or ``"bonded"``)."""

    thickness: Profile
    modulus: Profile
    poisson: Profile
    interface: str = DEFAULT_INTERFACE


@dataclass(frozen=True, eq=False)
class Scene:
    """A validated scene (build it with :func:`core.scene.scene_from_dict` or
    :func:`core.scene.load_scene`).

    Lengths in metres, moduli in pascals, times in days. ``shape`` and the layer
    profiles are functions of ``x`` [m] on ``[-a, a]``; the loads are functions of the time
    after loading [day]; ``times`` are the output times [day after loading]. Two scenes are
    equal when their canonical dicts (:meth:`to_dict`) are equal.
    """

    name: str
    description: str
    half_width: float
    shape: Profile
    coating: tuple[Layer, ...]
    base_thickness: float
    base_poisson: float
    age_at_loading: float
    creep: Any
    loading: Mapping[str, Profile]
    times: np.ndarray
    tol: float
    _data: dict = field(repr=False)
    #: Contact model: "auto" (full contact unless it is lost), "full" or "unilateral".
    contact: str = "auto"
    #: Limits of the design check (the file's ``limits``; None: none given).
    limits: DesignLimits | None = None

    def to_dict(self) -> dict[str, Any]:
        """The canonical JSON-able dict of the scene (schema version 1, defaults filled in)."""
        return copy.deepcopy(self._data)

    @cached_property
    def key(self) -> str:
        """A content hash of the canonical dict (hex), equal for equal scenes."""
        text = json.dumps(self._data, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Scene) and other.key == self.key

    def __hash__(self) -> int:
        return hash(self.key)

    @property
    def given(self) -> frozenset[str]:
        """The two given quantities (of settlement, tilt, force, moment)."""
        return frozenset(self.loading)

    @property
    def statement(self) -> int:
        """The statement number (1-4) of the seed, section 3."""
        return STATEMENTS[self.given]

    @cached_property
    def breakpoints(self) -> tuple[float, ...]:
        """Points of (-a, a) [m] where the punch shape or a coating profile may jump."""
        points: list[float] = []
        profiles = [self.shape] + [p for layer in self.coating
                                   for p in (layer.thickness, layer.modulus, layer.poisson)]
        a = self.half_width
        for profile in profiles:
            points.extend(float(b) for b in getattr(profile, "breakpoints", ()))
        inside = sorted(b for b in points if -a < b < a)
        merged: list[float] = []
        for b in inside:
            # two profiles breaking at the same place would give a zero-width panel
            if not merged or b - merged[-1] > 1e-12 * a:
                merged.append(b)
        return tuple(merged)

    @cached_property
    def gap_steps(self) -> tuple[float, ...]:
        """Points of (-a, a) [m] where the gap jumps: a step of the punch's base or of a
        coating's thickness, where a rigid corner presses into the coating (the thin
        coating model's springs bound q there; the resolved coating's is unbounded)."""
        a = self.half_width
        parts = [self.shape] + [layer.thickness for layer in self.coating]
        return tuple(sorted({b for part in parts for b in part.jump_points(-a, a)}))

    @cached_property
    def _geometry_key(self) -> str:
        """Content hash of the punch and the coating (what the x-profiles depend on)."""
        return fingerprint("geometry", json.dumps(
            [self._data["punch"], self._data["coating"]], sort_keys=True,
            separators=(",", ":")))

    @cached_property
    def sample_x(self) -> np.ndarray:
        """Dense points of [-a, a] [m] where the x-profiles show their extremes: a uniform
        grid, both sides of every breakpoint and each family's known extremes (shared,
        read-only, by scenes of the same geometry)."""
        return _SAMPLE_X.get_or_compute(self._geometry_key, self._sample_points)[0]

    def _sample_points(self) -> np.ndarray:
        a = self.half_width
        profiles = [self.shape] + [p for layer in self.coating
                                   for p in (layer.thickness, layer.modulus, layer.poisson)]
        parts = [np.linspace(-a, a, DENSE_SAMPLES)]
        constant_seen = False
        for profile in profiles:
            if getattr(profile, "kind", None) == "constant":
                # every constant profile samples the same uniform grid: one is enough
                # (a three-layer coating has nine; the sort of their union took ~0.6 ms)
                if constant_seen:
                    continue
                constant_seen = True
            parts.append(profile.sample_points((-a, a)))
        points = np.unique(np.concatenate(parts))
        points.setflags(write=False)
        return points

    def modulus_at_loading(self) -> float:
        """``E0 = E(age_at_loading)`` [Pa], the base modulus when the load is applied."""
        return float(np.asarray(self.creep.modulus(self.age_at_loading), dtype=float))

    @property
    def model_tol(self) -> float:
        """``solver.model_tol``: the coating-model error a result may carry unflagged [-]."""
        return float(self._data["solver"]["model_tol"])

    def coating_compliance(self, x: Any) -> np.ndarray:
        """``sum_k c_k`` [m/Pa] at points ``x`` [m] (vectorized): ``c_k = (1 - nu_k^2) h_k /
        E_k`` for a smooth interface, the laterally constrained ``(1 + nu_k)(1 - 2 nu_k) h_k
        / ((1 - nu_k) E_k)`` for a bonded one (:mod:`core.coating.model`)."""
        x = np.asarray(x, dtype=float)
        total = np.zeros(x.shape)
        for layer in self.coating:
            total = total + layer_compliance(profile_values(layer.thickness, x),
                                             profile_values(layer.modulus, x),
                                             profile_values(layer.poisson, x), layer.interface)
        return total

    def coating_thickness(self, x: Any) -> np.ndarray:
        """``sum_k h_k`` [m] at points ``x`` [m] (vectorized)."""
        x = np.asarray(x, dtype=float)
        total = np.zeros(x.shape)
        for layer in self.coating:
            total = total + profile_values(layer.thickness, x)
        return total

    @cached_property
    def _gap_parts(self) -> tuple[Profile, ...]:
        """``f`` and the ``h_k`` less their constant parts
        (:func:`core.profiles.without_offset`)."""
        return (without_offset(self.shape),) + tuple(
            without_offset(layer.thickness) for layer in self.coating)

    def gap_variation(self, x: Any) -> np.ndarray:
        """``f(x) - sum_k h_k(x)`` [m] at points ``x`` [m], up to a constant.

        The gap of a crowned punch on a 12 mm coating is micrometres: computed as
        ``f - 0.012 + 0.012`` it would carry rounding noise of ~1e-13 of itself, which the
        solver's resolution test on ``g`` takes for unresolved features. Dropping the
        constant parts first keeps the gap accurate to rounding of its own size.
        """
        x = np.asarray(x, dtype=float)
        shape, *layers = self._gap_parts
        total = profile_values(shape, x)
        for part in layers:
            total = total - profile_values(part, x)
        return total

    @cached_property
    def gap_minimum(self) -> float:
        """``min over [-a, a]`` of :meth:`gap_variation` [m]: dense samples, refined locally.

        Shared by scenes of the same geometry (a load slider makes a new scene each
        step; the search costs ~4 ms of the ~15 ms such a step takes)."""
        # the samples depend on every x-profile (their breakpoints and extremes)
        return _GAP_MINIMUM.get_or_compute(self._geometry_key, self._search_gap_minimum)[0]

    def _search_gap_minimum(self) -> float:
        x = self.sample_x
        values = self.gap_variation(x)
        i = int(np.argmin(values))
        best = float(values[i])
        lo, hi = x[max(i - 1, 0)], x[min(i + 1, x.size - 1)]
        if hi > lo:
            # a smooth minimum can fall between samples: golden-section search on the
            # bracket; any value it finds is a true value of the function, so taking the
            # smaller one is always safe (also next to a jump). Batched: the same points
            # in 14 calls instead of 62 (1.5-3 ms of a new geometry before).
            best = min(best, golden_minimum_batched(self.gap_variation, float(lo), float(hi)))
        return best

    def gap(self, x: Any) -> np.ndarray:
        """The gap ``g(x) = f(x) - sum_k h_k(x) - min(...)`` [m] at points ``x`` [m]."""
        return self.gap_variation(x) - self.gap_minimum

    @cached_property
    def sample_extremes(self) -> dict[str, float]:
        """On :attr:`sample_x`: the range of ``m*`` (-), the largest gap [m], the largest
        coating thickness [m] and the coating's largest strain per unit pressure, its
        compliance over its thickness [1/Pa] (0 without coating); none depends on the
        loads, so a scene with other loads
        (:func:`core.scene.replace_loads`) keeps them, and scenes of the same
        geometry and base modulus share them."""
        # m* = E0 / (2 (1 - nu^2) a) * compliance: the geometry, E0 and nu fix all four
        key = fingerprint("sample_extremes", self._geometry_key, self.modulus_at_loading(),
                          self.base_poisson)
        return dict(_SAMPLE_EXTREMES.get_or_compute(key, self._sample_extremes)[0])

    def _sample_extremes(self) -> dict[str, float]:
        x = self.sample_x
        problem = self.dimensionless
        with np.errstate(all="ignore"):  # as in the solve that reports them
            m_star = problem.m(x / self.half_width) if callable(problem.m) \
                else np.full(x.shape, problem.m)
            thickness = self.coating_thickness(x)
            strain = (self.coating_compliance(x) / thickness if self.coating
                      else np.zeros(x.shape))
            return {"m_star_min": float(np.min(m_star)), "m_star_max": float(np.max(m_star)),
                    "gap_max_m": float(np.max(self.gap(x))),
                    "coating_thickness_max_m": float(np.max(thickness)),
                    "coating_strain_per_pa": float(np.max(strain[np.isfinite(strain)],
                                                          initial=0.0))}

    @cached_property
    def layer_modulus_max(self) -> tuple[float, ...]:
        """The largest modulus [Pa] of each coating layer on :attr:`sample_x` (shared by
        scenes of the same geometry)."""
        return _LAYER_MODULUS_MAX.get_or_compute(self._geometry_key, lambda: tuple(
            float(np.max(profile_values(layer.modulus, self.sample_x)))
            for layer in self.coating))[0]

    @cached_property
    def dimensionless(self) -> DimensionlessProblem:
        """The dimensionless problem of this scene (built once; the formulas:
        :mod:`core.scene.dimensionless`)."""
        return to_dimensionless(self)
