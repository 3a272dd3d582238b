"""Pinned results to compare with the one on screen, and their names in the legend.

A pin is a solved scene kept while the user changes the scene. Each pin is named after
what differs between the pins ("e = 0.3 m", "h1 = 20 mm"), found by comparing the scene
dicts field by field, so a class that pins a result at each step of a slider reads the
step values in the legend. No Panel import: the pins view draws and links them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .results import ResultView

#: Most pins shown at once: each has its own colour, and a legend longer than this
#: did not fit one line above the pressure plot at 1024 px. Pinning more drops the oldest.
MAX_PINS = 6
#: Longest pin name [characters] (the legend and the readout's column headers).
LABEL_CHARS = 32
#: Most differing fields named in a pin's name.
LABEL_FIELDS = 2

#: Field of the scene -> (symbol, unit, size of the unit in SI) for the names.
_UNITS: dict[str, tuple[str, str, float]] = {
    "loading.force": ("P", "kN/m", 1e3),
    "loading.moment": ("M", "kN·m/m", 1e3),
    "loading.settlement": ("δ", "mm", 1e-3),
    "loading.tilt": ("α", "mrad", 1e-3),
    "punch.half_width": ("a", "m", 1.0),
    "punch.shape": ("shape", "mm", 1e-3),
    "base.thickness": ("H", "m", 1.0),
    "base.poisson": ("ν", "", 1.0),
    "base.age_at_loading": ("τ₀", "days", 1.0),  # as the slider names it
    "base.creep.modulus": ("E", "GPa", 1e9),
    "base.creep.modulus_final": ("E∞", "GPa", 1e9),
    "times.end": ("t_end", "days", 1.0),
}
#: Names of the coating fields (the layer number is appended to the symbol).
_LAYER_UNITS: dict[str, tuple[str, str, float]] = {
    "thickness": ("h", "mm", 1e-3),
    "modulus": ("E", "MPa", 1e6),
    "poisson": ("ν", "", 1.0),
}
#: Scene fields that say nothing about the mechanics (never a reason for a name).
NOT_MECHANICS = ("schema_version", "name", "description")


@dataclass
class Pin:
    """One pinned result and its name in the legend."""

    view: ResultView
    label: str = ""


def flatten(value: Any, prefix: str = "") -> dict[str, Any]:
    """A nested scene dict as ``{"a.b.0.c": leaf}`` (lists indexed by position)."""
    if isinstance(value, dict):
        items = value.items()
    elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        items = ((str(k), v) for k, v in enumerate(value))
    else:
        return {prefix: value}
    out: dict[str, Any] = {}
    for key, item in items:
        out.update(flatten(item, f"{prefix}.{key}" if prefix else str(key)))
    return out


def _number(value: Any) -> float | None:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    return None


def eccentricity(scene: dict[str, Any]) -> float | None:
    """e = M/P [m] of a scene with a constant force and moment, else None."""
    loading = scene.get("loading", {})
    force, moment = _number(loading.get("force")), _number(loading.get("moment"))
    if force is None or moment is None or force <= 0:
        return None
    return moment / force


def field_text(path: str, value: Any) -> str:
    """One field and its value as a name reads it: ``"h1 = 20 mm"``."""
    symbol, unit, size = _UNITS.get(path, (path, "", 1.0))
    parts = path.split(".")
    if parts[0] == "coating" and len(parts) >= 3 and parts[2] in _LAYER_UNITS:
        symbol, unit, size = _LAYER_UNITS[parts[2]]
        symbol = f"{symbol}{int(parts[1]) + 1}" + "".join(f".{p}" for p in parts[3:])
    number = _number(value)
    if number is None:
        return f"{symbol} = {str(value)[:12]}"
    return f"{symbol} = {_short(number / size)}" + (f" {unit}" if unit else "")


def coating_text(scene: dict[str, Any]) -> str:
    """The coating of a scene in a few words: "no coating", "h1 = 20 mm, E1 = 800 MPa"
    for one layer of constant values, else its number of layers."""
    layers = scene.get("coating") or []
    if not layers:
        return "no coating"
    if len(layers) == 1:
        parts = [field_text(f"coating.0.{name}", layers[0].get(name))
                 for name in ("thickness", "modulus")
                 if _number(layers[0].get(name)) is not None]
        if parts:
            return ", ".join(parts)
    return f"{len(layers)} coating layer{'s' if len(layers) > 1 else ''}"


def _short(number: float) -> str:
    """Three significant digits, without an exponent for the thousands (1000 kN/m)."""
    return f"{number:.0f}" if 1e3 <= abs(number) < 1e6 else f"{number:.3g}"


def _differing(flats: list[dict[str, Any]]) -> list[str]:
    keys: list[str] = []
    for flat in flats:
        keys.extend(k for k in flat if k not in keys)
    return [k for k in keys if not k.startswith(NOT_MECHANICS)
            and len({repr(flat.get(k)) for flat in flats}) > 1]


def pin_labels(scenes: list[dict[str, Any]]) -> list[str]:
    """Names of pinned scenes after what differs between them.

    A constant force and moment whose ratio differs are named by e = M/P (with P when
    that differs too). Pins that differ in nothing shown (or a single pin) are named
    after their scene, numbered."""
    flats = [flatten(scene) for scene in scenes]
    keys = _differing(flats) if len(scenes) > 1 else []
    ecc = [eccentricity(scene) for scene in scenes]
    use_e = (bool(keys) and "loading.moment" in keys and None not in ecc
             and len({round(e, 12) for e in ecc if e is not None}) > 1)
    if len({len(scene.get("coating") or []) for scene in scenes}) > 1:
        # layers added or taken off: the coating named as a whole ("coating = []" and
        # "h1 = None" read before)
        keys = ["coating", *(key for key in keys if not key.startswith("coating"))]
    labels = []
    for k, (scene, flat) in enumerate(zip(scenes, flats, strict=True)):
        parts = [f"e = {_short(ecc[k] or 0.0)} m" if use_e and key == "loading.moment"
                 else coating_text(scene) if key == "coating"
                 else field_text(key, flat.get(key)) for key in keys]
        parts = parts[:LABEL_FIELDS]
        if not parts:
            parts = [f"{k + 1}: {scene.get('name', 'pinned')}"]
        label = ", ".join(parts)
        labels.append(label if len(label) <= LABEL_CHARS
                      else label[: LABEL_CHARS - 1].rstrip() + "…")
    return labels


class PinBoard:
    """The pinned results of a session, oldest first, at most :data:`MAX_PINS`."""

    def __init__(self) -> None:
        self.pins: list[Pin] = []
        # the scene on screen: what a single pin is named against (None: not known)
        self._on_screen: dict[str, Any] | None = None

    def __len__(self) -> int:
        return len(self.pins)

    def __iter__(self):
        return iter(self.pins)

    def views(self) -> list[ResultView]:
        """The pinned results, oldest first."""
        return [pin.view for pin in self.pins]

    def scenes(self) -> list[dict[str, Any]]:
        """The pinned scenes, oldest first (what a link keeps)."""
        return [pin.view.scene for pin in self.pins]

    def add(self, view: ResultView) -> bool:
        """Pin ``view`` (a result already pinned is not pinned twice); False if it was, or
        if it is of several punches (pins compare results of one punch)."""
        if view.several:
            return False
        if any(pin.view.scene == view.scene for pin in self.pins):
            return False
        self.pins.append(Pin(view))
        del self.pins[:-MAX_PINS]
        self._name()
        return True

    def remove(self, index: int) -> None:
        """Drop the pin at ``index`` (0 = oldest); an index out of range does nothing."""
        if 0 <= index < len(self.pins):
            del self.pins[index]
            self._name()

    def clear(self) -> None:
        """Drop every pin."""
        self.pins.clear()

    def name_against(self, scene: dict[str, Any] | None) -> None:
        """The scene on screen changed: a single pin is named by what differs from it
        (alone, it differs from no other pin, and its scene's name was cut to
        "1: Force, eccentricity and tilt…" in a lesson's first pin, where "P = 500 kN/m"
        says what the class compares). None: no scene to name against (one of several
        punches)."""
        self._on_screen = scene
        if len(self.pins) == 1:  # (the names of several pins are their own differences)
            self._name()

    def _name(self) -> None:
        scenes = self.scenes()
        if len(scenes) == 1 and self._on_screen is not None:
            labels = pin_labels([*scenes, self._on_screen])[:1]
        else:
            labels = pin_labels(scenes)
        for pin, label in zip(self.pins, labels, strict=True):
            pin.label = label
