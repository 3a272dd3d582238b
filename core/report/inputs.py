"""The inputs of a scene as the report lists them: punch, coating layers, base, creep,
loading, output times and solver settings, each in the units an engineer reads (mm, MPa,
GPa, kN/m) with its unit; a profile that varies over x or t is given by its kind and its
range (its exact form is in the scene file the report ends with)."""

from __future__ import annotations

from typing import Any

import numpy as np

from core.scene import Scene, days_text, number_text, solver_settings

#: Shown units of the histories and the pressure, by their SI unit: (unit, its size in SI).
SHOWN_UNITS: dict[str, tuple[str, float]] = {
    "m": ("mm", 1e-3), "rad": ("mrad", 1e-3), "N/m": ("kN/m", 1e3), "N": ("kN·m/m", 1e3),
    "Pa": ("kPa", 1e3),
}
#: The loads: (the paper's symbol, SI unit).
LOADS: dict[str, tuple[str, str]] = {"settlement": ("δ", "m"), "tilt": ("α", "rad"),
                                     "force": ("P", "N/m"), "moment": ("M", "N")}
#: Fields of a coating layer: (symbol, shown unit, its size in SI).
LAYER_FIELDS: dict[str, tuple[str, str, float]] = {
    "thickness": ("h", "mm", 1e-3), "modulus": ("E", "MPa", 1e6), "poisson": ("ν", "", 1.0)}
#: The punch base's height above its lowest point: (symbol, shown unit, its size in SI).
SHAPE_UNIT = ("f(x)", "mm", 1e-3)
#: Fields of the creep models (core/SCENES.md, "Creep models"): (symbol, shown unit, its
#: size in the unit of the scene file). The design codes' fields are in the codes' units.
CREEP_FIELDS: dict[str, tuple[str, str, float]] = {
    "modulus": ("E", "GPa", 1e9), "modulus_final": ("E∞", "GPa", 1e9),
    "beta": ("β", "", 1.0), "alpha": ("α", "1/day", 1.0),
    "compliance": ("C", "1/GPa", 1e-9), "compliance_final": ("C∞", "1/GPa", 1e-9),
    "aging": ("A", "day/GPa", 1e-9), "rate": ("γ", "1/day", 1.0),
    "expr": ("K(t, τ) [1/day] =", "", 1.0),
    "fcm": ("f_cm", "MPa", 1.0), "strength_class": ("strength class", "", 1.0),
    "cement": ("cement", "", 1.0), "relative_humidity": ("RH", "%", 1.0),
    "notional_size": ("h0", "mm", 1.0), "temperature": ("T", "°C", 1.0),
}
#: The creep models in words.
CREEP_MODELS: dict[str, str] = {
    "elastic": "elastic", "exponential": "exponential creep",
    "arutyunyan": "aging creep (Arutyunyan)", "prony": "Prony series",
    "kernel": "creep kernel formula", "fib_mc2010": "fib Model Code 2010",
    "eurocode2": "EN 1992-1-1 Annex B",
}
#: Points of a load history sampled for its range, besides the output times.
LOAD_SAMPLES = 2001


def _with_unit(value: float, unit: str) -> str:
    return f"{number_text(value)} {unit}".rstrip()


def profile_text(spec: Any, values: np.ndarray, unit: str, size: float) -> str:
    """A profile of a scene file (``spec``) sampled as ``values`` [SI], in ``unit`` (of
    ``size`` in SI): a constant as its value, a varying one as its range and kind."""
    if isinstance(spec, (int, float)):
        return _with_unit(spec / size, unit)
    kind = (f"formula {spec['expr']}" if "expr" in spec
            else f"{spec.get('kind', 'constant')} profile")
    lo, hi = float(np.min(values)) / size, float(np.max(values)) / size
    low, high = number_text(lo), number_text(hi)
    span = low if low == high else f"{low} to {high}"
    return f"{span} {unit} ({kind})".replace("  ", " ")


#: The most times a load history's steps and kinks are listed at (more: their span).
LISTED_CHANGES = 6


def _changes_text(profile: Any, t_end: float) -> str:
    """When a load history steps or kinks within the output times [day] ("" where it does
    not): the report gave a force stepping from 800 to 1600 kN/m as "800 to 1600 kN/m
    (step profile)", its time in the appended JSON alone (an engineer's audit)."""
    points = getattr(profile, "nonsmooth_points", None)
    at = [] if points is None else [float(p) for p in points(0.0, t_end)]
    if not at:
        return ""
    if len(at) <= LISTED_CHANGES:
        times = ", ".join(number_text(p) for p in at)
        return f"; it steps or kinks at t = {times} days"
    return (f"; it steps or kinks {len(at)} times, from t = {number_text(at[0])} to "
            f"{number_text(at[-1])} days")


def _values(profile: Any, points: np.ndarray) -> np.ndarray:
    return np.broadcast_to(np.asarray(profile(points), dtype=float), points.shape)


def _creep_text(spec: dict[str, Any]) -> str:
    """A creep model's fields in the units an engineer reads."""
    def field(name: str, value: Any) -> str:
        symbol, unit, size = CREEP_FIELDS.get(name, (name, "", 1.0))
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return f"{symbol} = {_with_unit(value / size, unit)}"
        return f"{symbol} {value}"

    parts = [field(k, v) for k, v in spec.items() if k not in ("model", "terms")]
    for r, term in enumerate(spec.get("terms", ()), start=1):
        parts.append(f"term {r}: " + ", ".join(field(k, v) for k, v in term.items()))
    model = str(spec.get("model"))
    return f"{CREEP_MODELS.get(model, model)}: " + "; ".join(parts)


def _times_text(scene: Scene, spec: Any) -> str:
    times = scene.times
    if len(times) == 1:
        return f"1 output time, {days_text(times[0])} after loading"
    text = (f"{len(times)} output times, {number_text(times[0])} to "
            f"{days_text(times[-1])} after loading")
    if isinstance(spec, dict):
        start = f" from {days_text(spec['start'])}" if spec.get("start") else ""
        return text + f" ({spec.get('spacing', 'linear')} spacing{start})"
    return text + (" (listed)" if isinstance(spec, list) else "")


def input_rows(scene: Scene) -> list[tuple[str, str]]:
    """The scene's inputs as (label, value with unit) rows."""
    data = scene.to_dict()
    x = scene.sample_x
    a = scene.half_width
    symbol, unit, size = SHAPE_UNIT
    shape = data["punch"].get("shape", 0.0)
    rows = [("punch", f"half-width a = {number_text(a)} m (width 2a = "
                      f"{number_text(2 * a)} m); base "
                      + ("flat" if shape == 0 else
                         f"{symbol} = {profile_text(shape, _values(scene.shape, x), unit, size)}"
                         " above its lowest point"))]
    if scene.description:
        rows.insert(0, ("description", scene.description))
    for k, (layer, spec) in enumerate(zip(scene.coating, data["coating"], strict=True),
                                      start=1):
        parts = [f"{symbol} = " + profile_text(spec[name], _values(getattr(layer, name), x),
                                               unit, size)
                 for name, (symbol, unit, size) in LAYER_FIELDS.items()]
        where = " (under the punch)" if k == 1 and len(scene.coating) > 1 else ""
        rows.append((f"coating layer {k}{where}",
                     ", ".join(parts) + f", {layer.interface} interface"))
    if not scene.coating:
        rows.append(("coating", "none: the punch on the bare base"))
    rows.append(("base", f"H = {number_text(scene.base_thickness)} m, ν = "
                         f"{number_text(scene.base_poisson)}, age at loading τ0 = "
                         f"{days_text(scene.age_at_loading)}, modulus at loading E(τ0) = "
                         f"{number_text(scene.modulus_at_loading() / 1e9)} GPa"))
    rows.append(("base creep", _creep_text(data["base"]["creep"])))
    t = np.union1d(np.linspace(0.0, float(scene.times[-1]), LOAD_SAMPLES), scene.times)
    for name in LOADS:
        if name in scene.loading:
            symbol, si = LOADS[name]
            unit, size = SHOWN_UNITS[si]
            rows.append((f"{name} {symbol} (given)", profile_text(
                data["loading"][name], _values(scene.loading[name], t), unit, size)
                + _changes_text(scene.loading[name], float(scene.times[-1]))))
    rows.append(("output times", _times_text(scene, data["times"])))
    settings = solver_settings(scene)
    rows.append(("solver settings", ", ".join(f"{k} {v:g}" if isinstance(v, float)
                                              else f"{k} {v}" for k, v in settings.items())))
    return rows
