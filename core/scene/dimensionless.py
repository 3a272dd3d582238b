"""The dimensionless problem of a scene: the conversion of a :class:`core.scene.Scene`
to the arguments of :func:`core.solver.solve_dimensionless` (model notes, "Dimensionless
problem"), and the reference values that convert the answer back.

Conversion (``a`` half-width, ``H`` base thickness, ``nu`` base Poisson ratio,
``tau0`` age at loading, ``E0 = E(tau0)``, ``t`` days after loading, ``age = tau0 + t``):

    x* = x / a,    lam = a / H,    t* = age / tau0 = (tau0 + t) / tau0,
    m*(x*) = E0 / (2 (1 - nu^2) a) * sum_k (1 - nu_k^2) h_k / E_k,
    g(x) = f(x) - sum_k h_k(x) - min over [-a, a] of the same,   g* = g / a,
    c(t*) = E(age) / E0,   delta* = delta / a,   alpha* = alpha,
    P* = 2 (1 - nu^2) P / (E(age) a),   M* = 2 (1 - nu^2) M / (E(age) a^2),
    q = E(age) q* / (2 (1 - nu^2)).

The base is taken to be made at age 0 (the seed's ``tau_b = 0``), so ages are counted
from its casting and the loading starts at ``age = tau0``. ``E0`` is the modulus at
loading so that ``c(1) = 1``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from core.cache import StageCache, fingerprint
from core.profiles import Profile, profile_values
from core.validation import refuse_first

if TYPE_CHECKING:
    from core.problem import ContactSolution
    from core.scene.model import Scene


#: Values of ``m*`` and ``g*`` at the points the solver asks for, shared by scenes of the
#: same geometry: the solver validates and recognises a geometry by sampling both at the
#: same ~2300 points on every solve (three times per solve, ~1 ms of a load change).
_SAMPLED = StageCache("scene_sampled_coefficients", max_items=64, max_bytes=4 * 2**20)


def _sampled(kind: str, scene: Scene, factor: float, xs: Any,
             evaluate: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """``evaluate(xs)``, remembered by the scene's geometry, ``factor`` and the points."""
    xs = np.asarray(xs, dtype=float)
    key = fingerprint(kind, scene._geometry_key, factor, xs)
    values, _ = _SAMPLED.get_or_compute(key, lambda: _frozen(evaluate(xs)))
    return values.copy()  # callers may write into what they get


def _frozen(values: np.ndarray) -> np.ndarray:
    values = np.array(values, dtype=float)
    values.setflags(write=False)
    return values


@dataclass(frozen=True, eq=False)
class DimensionlessProblem:
    """The arguments of :func:`core.solver.solve_dimensionless` for one scene.

    ``m``, ``g`` are numbers or vectorized callables of ``x*``; ``c`` and the ``loads``
    numbers or callables of ``t*``; ``times`` are ``t*`` values; ``breakpoints`` in ``x*``.
    The reference values convert back: ``half_width`` [m], ``modulus_at_loading`` E0 [Pa],
    ``age_at_loading`` tau0 [day], ``plane_factor`` ``2 (1 - nu^2)`` [-].
    """

    lam: float
    m: float | Callable[[np.ndarray], np.ndarray]
    g: float | Callable[[np.ndarray], np.ndarray]
    c: float | Callable[[np.ndarray], np.ndarray]
    kernel: Any
    loads: Mapping[str, float | Callable[[np.ndarray], np.ndarray]]
    times: np.ndarray
    breakpoints: tuple[float, ...]
    tol: float
    half_width: float
    modulus_at_loading: float
    age_at_loading: float
    plane_factor: float
    modulus: Callable[[np.ndarray], np.ndarray]
    contact: str = "auto"
    #: ``t*`` where a given history jumps or kinks (the time stepper lands on them).
    time_breaks: tuple[float, ...] = ()

    def days_after_loading(self, t_star: Any) -> np.ndarray:
        """The days after loading [day] of the solver's times ``t*``
        (:func:`days_after_loading`)."""
        return days_after_loading(t_star, self.age_at_loading)

    def modulus_after_loading(self, t: Any) -> np.ndarray:
        """``E(tau0 + t)`` [Pa] at ``t`` days after loading."""
        return np.asarray(self.modulus(self.age_at_loading + np.asarray(t, dtype=float)),
                          dtype=float)

    def pressure_scale(self, t: Any) -> np.ndarray:
        """``q / q* = E(age) / (2 (1 - nu^2))`` [Pa] at ``t`` days after loading."""
        return self.modulus_after_loading(t) / self.plane_factor

    def solve(self) -> ContactSolution:
        """Run :func:`core.solver.solve_dimensionless` on these arguments."""
        # imported here: validating a scene should not load the numerical pipeline
        from core.solver import solve_dimensionless

        return solve_dimensionless(self.lam, self.m, self.g, self.times, c=self.c,
                                   kernel=self.kernel, breakpoints=self.breakpoints,
                                   tol=self.tol, contact=self.contact,
                                   time_breaks=self.time_breaks, find_jumps=False,
                                   **self.loads)


def days_after_loading(t_star: Any, tau0: float) -> np.ndarray:
    """The days after loading [day] of the solver's times ``t*``: ``t* = (tau0 + days) /
    tau0`` (``tau0`` the age at loading [day])."""
    return tau0 * (np.asarray(t_star, dtype=float) - 1.0)


def _is_constant(profile: Profile) -> bool:
    return getattr(profile, "kind", None) == "constant"


def landing_points(profile: Any, t_end: float) -> tuple[float, ...]:
    """The times [day after loading] in ``(0, t_end)`` a load history's time steps land
    on: where its value or slope may jump (``nonsmooth_points``), and its features a step
    could pass over unseen: every row of a table (a ``pchip`` table is smooth between its
    rows, and a three-day pulse through its rows was stepped over: the answer of the
    constant load, 2 % off at tol 1e-6, a review found), a bump's centre and one and
    two widths either side of it, and a formula's few extremes (:func:`formula_features`)."""
    points = set(profile.nonsmooth_points(0.0, t_end)) if hasattr(
        profile, "nonsmooth_points") else set()
    spec = getattr(profile, "spec", None)
    if isinstance(spec, Mapping) and spec.get("kind") == "table":
        points |= {float(row[0]) for row in spec["points"]}
    elif isinstance(spec, Mapping) and spec.get("kind") == "bump":
        centre, width = float(spec["center"]), float(spec["width"])
        points |= {centre + k * width for k in (-2, -1, 0, 1, 2)}
    elif isinstance(spec, Mapping) and spec.get("kind") == "expr":
        points |= set(formula_features(profile, t_end))
    return tuple(sorted(p for p in points if 0.0 < p < t_end))


#: Samples of a formula load over ``[0, t_end]`` (days after loading) at which its
#: extremes are looked for, evenly and as many again geometrically from
#: ``t_end / FEATURE_SPAN`` (where a log-spaced scene's steps are short): a pulse wider
#: than about two of them is seen (over a year, ~0.2 day evenly).
FEATURE_SAMPLES = 4097
#: The ratio of the last to the first of the geometric samples.
FEATURE_SPAN = 1e6
#: An extreme is narrow, and its samples become landing points, where its width at half
#: its prominence is under this share of the span: the time steps refine over a wider one
#: as over any smooth load. Every extreme of a smooth wave made landing points: a sine
#: moment of 40 days over 1000 took 2380 steps instead of 796 on the lift-off preset, for
#: the same answer to 1.1e-8 (a review).
NARROW_SHARE = 1.0 / 128.0
#: ... and under this share of the distance to the nearest other extreme (a wave's crest
#: is about half that wide).
PULSE_SHARE = 0.25
#: The samples, counted from a narrow extreme's, that become landing points (its flanks,
#: of a width the samples hardly tell, too).
FEATURE_OFFSETS = (-16, -8, -4, -2, -1, 0, 1, 2, 4, 8, 16)
#: A formula with more narrow extremes than this oscillates fast: none of them become
#: landing points (its steps refine over it as over any load, and the
#: ``undersampled_load`` flag speaks for its output times).
MAX_FEATURES = 32


def formula_features(profile: Any, t_end: float) -> tuple[float, ...]:
    """The times [day after loading] at a formula load's narrow extremes among its
    samples (:data:`FEATURE_SAMPLES` evenly and geometrically; :data:`NARROW_SHARE`),
    with samples either side of each (:data:`FEATURE_OFFSETS`), so that the time steps
    land on a narrow pulse: a five-hour pulse (``exp(-((t - 101.3) / 0.2)^2)``, half the
    force) between the steps of the first grids was stepped over by every grid, the
    answer of the steady force 8.6e-5 off at tol 1e-6, flagged nothing, where the same
    pulse as a ``bump`` was answered. A pulse narrower than the samples' spacing can
    still be stepped over: a ``bump`` or a ``table`` says where it is. Empty for more
    than :data:`MAX_FEATURES` narrow extremes, or a formula not finite at every sample."""
    from scipy.signal import find_peaks, peak_widths

    if not t_end > 0.0:
        return ()
    found: list[float] = []
    for t in (np.linspace(0.0, t_end, FEATURE_SAMPLES),
              np.geomspace(t_end / FEATURE_SPAN, t_end, FEATURE_SAMPLES)):
        y = np.asarray(profile(t), dtype=float) * np.ones_like(t)
        if not np.all(np.isfinite(y)):
            return ()
        index = np.arange(t.size)
        parts = []
        for signed in (y, -y):
            peaks, _ = find_peaks(signed)
            if peaks.size:
                _, _, left, right = peak_widths(signed, peaks, rel_height=0.5)
                parts.append((peaks, np.interp(right, index, t) - np.interp(left, index, t)))
        if not parts:
            continue
        peaks = np.concatenate([p for p, _ in parts])
        days = np.concatenate([d for _, d in parts])
        # a wave's crest is as wide as half the way to its neighbours (sin(t)'s first
        # crest, measured from the span's start, read 2.1 days wide); a pulse, far less
        apart = np.full(peaks.size, np.inf)
        if peaks.size > 1:
            at = t[peaks]
            gaps = np.abs(at[:, None] - at[None, :])
            np.fill_diagonal(gaps, np.inf)
            apart = gaps.min(axis=1)
        narrow = peaks[(days < NARROW_SHARE * t_end) & (days < PULSE_SHARE * apart)]
        if narrow.size > MAX_FEATURES:
            return ()
        picked = np.unique(np.concatenate([narrow + k for k in FEATURE_OFFSETS]))
        picked = picked[(picked > 0) & (picked < t.size - 1)]
        found.extend(float(v) for v in t[picked])
    return tuple(sorted(set(found)))


def to_dimensionless(scene: Scene) -> DimensionlessProblem:
    """The dimensionless problem of a scene (the formulas: the module docstring)."""
    a = scene.half_width
    nu = scene.base_poisson
    tau0 = scene.age_at_loading
    plane = 2.0 * (1.0 - nu * nu)
    e0 = scene.modulus_at_loading()
    creep = scene.creep
    t_end = float(scene.times[-1])

    def modulus(age: Any) -> np.ndarray:
        return np.asarray(creep.modulus(age), dtype=float)

    # Every callable below is a pure function of the scene, so the solver's caches, which
    # key on sampled values, see equal inputs for equal scenes.
    m_factor = e0 / (plane * a)
    coating_constant = all(_is_constant(p) for layer in scene.coating
                           for p in (layer.thickness, layer.modulus, layer.poisson))
    if coating_constant:
        m_value: Any = float(m_factor * scene.coating_compliance(np.zeros(1))[0])
    else:
        def m_direct(xs: np.ndarray) -> np.ndarray:
            x = a * xs
            values = m_factor * scene.coating_compliance(x)
            if not np.all(np.isfinite(values) & (values > 0)):
                _check_x_profiles_at(scene, x)
            return values

        def m_value(xs: np.ndarray) -> np.ndarray:
            return _sampled("m", scene, m_factor, xs, m_direct)

    if coating_constant and _is_constant(scene.shape):
        g_value: Any = 0.0
    else:
        g_min = scene.gap_minimum

        def g_direct(xs: np.ndarray) -> np.ndarray:
            x = a * xs
            values = (scene.gap_variation(x) - g_min) / a
            if not np.all(np.isfinite(values)):
                _check_x_profiles_at(scene, x)
            return values

        def g_value(xs: np.ndarray) -> np.ndarray:
            return _sampled("g", scene, g_min, xs, g_direct)

    c_value = creep.relative_modulus(tau0, field="base.age_at_loading")
    aging = callable(c_value)

    def days(ts: np.ndarray) -> np.ndarray:
        # the solver may probe a hair outside [1, t*_end]; profiles are defined on [0, end]
        return np.clip(days_after_loading(ts, tau0), 0.0, t_end)

    loads: dict[str, Any] = {}
    for name, profile in scene.loading.items():
        if name in ("settlement", "tilt"):
            scale = 1.0 / a if name == "settlement" else 1.0
            if _is_constant(profile):
                loads[name] = float(scale * profile_values(profile, np.zeros(1))[0])
            else:
                loads[name] = _kinematic_load(profile, scale, days)
        else:
            # a * a, not a**2: Python's float power raises OverflowError for a huge a,
            # products give inf, which the checks of scene_from_dict report
            a_power = a if name == "force" else a * a
            if _is_constant(profile) and not aging:
                loads[name] = float(plane * profile_values(profile, np.zeros(1))[0]
                                    / (e0 * a_power))
            else:
                loads[name] = _static_load(profile, plane / a_power, days, modulus, tau0)

    times_star = (tau0 + np.asarray(scene.times, dtype=float)) / tau0
    times_star[0] = max(times_star[0], 1.0)
    jumps = sorted({(tau0 + d) / tau0 for profile in scene.loading.values()
                    for d in landing_points(profile, t_end)})
    return DimensionlessProblem(
        lam=a / scene.base_thickness,
        m=m_value,
        g=g_value,
        c=c_value,
        kernel=creep.dimensionless_kernel(tau0, field="base.age_at_loading", tol=scene.tol),
        loads=loads,
        times=times_star,
        breakpoints=tuple(b / a for b in scene.breakpoints),
        tol=scene.tol,
        contact=scene.contact,
        time_breaks=tuple(jumps),
        half_width=a,
        modulus_at_loading=e0,
        age_at_loading=tau0,
        plane_factor=plane,
        modulus=modulus,
    )


#: Open bounds of the values of each x-profile of a layer, as the loader checks them,
#: and the unit its values are written in
_LAYER_BOUNDS = {"thickness": (0.0, None, " m"), "modulus": (0.0, None, " Pa"),
                 "poisson": (-1.0, 0.5, "")}


def _check_x_profiles_at(scene: Scene, x: np.ndarray) -> None:
    """Refuse, naming the field, an x-profile that is not finite or out of its range at
    points ``x`` [m] the solver asked for: the loader checks profiles on samples, and a
    formula's pole or spike between them would otherwise surface under the solver's
    internal names (``m``, ``g``)."""
    candidates = [("punch.shape", scene.shape, (None, None, " m"))] + [
        (f"coating[{k}].{name}", getattr(layer, name), bounds)
        for k, layer in enumerate(scene.coating) for name, bounds in _LAYER_BOUNDS.items()]
    for path, profile, (lower, upper, unit) in candidates:
        values = profile_values(profile, x)
        checks = [(~np.isfinite(values), "must be finite")]
        if lower is not None:
            checks.append((values <= lower, f"must be > {lower:g}"))
        if upper is not None:
            checks.append((values >= upper, f"must be < {upper:g}"))
        for bad, rule in checks:
            refuse_first(bad, lambda i, path=path, rule=rule, values=values, unit=unit: (
                f"{path}: {rule}, is {values.flat[i]:.6g}{unit} at x = {x.flat[i]:.10g} m, "
                "between the points where the scene was checked (a pole or a spike of a "
                "formula narrower than the checks): keep it finite and in range on the "
                "whole punch"))


def _kinematic_load(profile: Profile, scale: float,
                    days: Callable[[np.ndarray], np.ndarray]) -> Callable:
    def load(ts: np.ndarray) -> np.ndarray:
        t = days(ts)
        return scale * profile_values(profile, t)
    return load


def _static_load(profile: Profile, scale: float, days: Callable[[np.ndarray], np.ndarray],
                 modulus: Callable[[Any], np.ndarray], tau0: float) -> Callable:
    def load(ts: np.ndarray) -> np.ndarray:
        t = days(ts)
        return scale * profile_values(profile, t) / modulus(tau0 + t)
    return load
