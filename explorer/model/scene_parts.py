"""The parts of the explorer's state: punch, coating layers and base (the loading:
:mod:`explorer.model.loading_state`).

Plain ``param`` classes, one per part of a scene, each holding the values a user sets in
the units shown on screen (mm, MPa, GPa, kN/m, ...) and turning them into the part of the
SI scene dictionary that ``core.scene_from_dict`` validates (and back, from any valid
scene). :class:`~explorer.model.state.ExplorerState` holds one of each. Nothing here imports
Panel; validating a value is the job of the core, whose messages name the field.
"""

from __future__ import annotations

import copy
import math
from typing import Any

import param

from core import limits
from core.coating import DEFAULT_INTERFACE, INTERFACES
from core.profiles import VARIATIONS, variation_of

from .code_creep_state import CODE_CREEP_MODELS, CodeCreepState

#: Contact models of ``solver.contact``, as the solver names them ("auto" is the default).
CONTACT_MODELS = ("auto", "full", "unilateral")
DEFAULT_CONTACT = "auto"

CREEP_MODELS: dict[str, str] = {
    "elastic": "elastic (no creep)",
    "exponential": "non-aging exponential creep",
    "arutyunyan": "aging creep (Arutyunyan)",
    "fib_mc2010": "concrete, fib Model Code 2010",
    "eurocode2": "concrete, Eurocode 2",
    # (a preset's inline model too: "from file" read wrong on the patched insert)
    "custom": "the scene's own model",
}

_GPA = 1e9
_MPA = 1e6
_MM = 1e-3
_UM = 1e-6
_URAD = 1e-6
_KM = 1e3

# Relative agreement below which a parametric family is accepted as a reading of a spec.
_RTOL = 1e-12


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _close(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=_RTOL, abs_tol=1e-300)


class ProfileState(param.Parameterized):
    """A function of position across the punch, ``x`` in m on ``[-a, a]``.

    The value is a level ``mean`` (display units; ``scale`` converts to SI) with an
    optional variation of size ``amplitude``: in absolute display units of
    ``amplitude_scale`` when that is given (coating thickness: micrometres, because a wear
    of a few micrometres already matters), else in percent of the level (moduli).
    """

    kind = param.Selector(
        default="none", objects=[*VARIATIONS, "custom"],
        doc="Variation across the punch: none, linear (left to right), a step at a "
            "position, a patch (a band of another value), sine, bump, or custom (a table "
            "or formula from a file).")
    mean = param.Number(default=1.0, doc="Level, in display units.")
    amplitude = param.Number(
        default=0.0,
        doc="Size A of the variation: linear and step go from level - A to level + A; a "
            "patch has level + A; sine and bump add A at their peak.")
    position = param.Number(
        default=0.0, doc="Step position, or centre of a patch or bump [m from the centre].")
    length = param.Number(
        default=0.5, doc="Sine wavelength, or width of a patch or bump [m].")
    custom = param.Parameter(
        default=None, doc="A profile spec (SI) kept verbatim when kind is 'custom'.")

    def __init__(self, scale: float = 1.0, amplitude_scale: float | None = None,
                 **params: Any) -> None:
        super().__init__(**params)
        self.scale = scale
        self.amplitude_scale = amplitude_scale

    @property
    def relative(self) -> bool:
        """Whether the amplitude is in percent of the level."""
        return self.amplitude_scale is None

    def _amplitude_si(self, m: float) -> float:
        if self.amplitude_scale is None:
            return m * self.amplitude / 100.0
        return self.amplitude * self.amplitude_scale

    def _amplitude_from(self, m: float, amplitude_si: float) -> float | None:
        if self.amplitude_scale is None:
            return None if m == 0 else 100.0 * amplitude_si / m
        return amplitude_si / self.amplitude_scale

    def to_spec(self) -> float | dict[str, Any]:
        """The profile spec in SI units (a number or a dict of the scene schema)."""
        m = self.mean * self.scale
        if self.kind == "custom":
            return m if self.custom is None else copy.deepcopy(self.custom)
        return VARIATIONS[self.kind].spec({"level": m, "amplitude": self._amplitude_si(m),
                                           "position": self.position, "length": self.length})

    def load_spec(self, spec: Any) -> None:
        """Set the state from an SI spec; anything else is kept as a ``custom`` profile."""
        values: dict[str, Any] = {"kind": "custom", "custom": copy.deepcopy(spec)}
        found = variation_of(spec)
        if found is not None:
            name, numbers = found
            level = numbers["level"]
            amp = self._amplitude_from(level, numbers.get("amplitude", 0.0))
            if amp is not None or "amplitude" not in numbers:  # None: % of a zero level
                values = {**numbers, "kind": name, "custom": None, "mean": level / self.scale}
                del values["level"]
                if "amplitude" in numbers:
                    values["amplitude"] = amp
        self.param.update(**values)


class LayerState(param.Parameterized):
    """One coating layer: thickness [mm], Young's modulus [MPa], Poisson ratio, and how it
    is joined to what lies under it (``interface``)."""

    interface = param.Selector(
        default=DEFAULT_INTERFACE, objects=list(INTERFACES),
        doc="Joint with the layer (or base) below: smooth (free to slide) or bonded.")

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        self.thickness = ProfileState(scale=_MM, amplitude_scale=_UM, mean=10.0,
                                      name="thickness")
        self.modulus = ProfileState(scale=_MPA, mean=200.0, amplitude=0.0, name="modulus")
        self.poisson = ProfileState(scale=1.0, mean=0.3, amplitude=0.0, name="poisson")

    @property
    def profiles(self) -> tuple[ProfileState, ProfileState, ProfileState]:
        return (self.thickness, self.modulus, self.poisson)

    def to_dict(self) -> dict[str, Any]:
        """The layer of the scene schema (SI)."""
        layer = {"thickness": self.thickness.to_spec(), "modulus": self.modulus.to_spec(),
                 "poisson": self.poisson.to_spec()}
        if self.interface != DEFAULT_INTERFACE:  # the default is left implicit, as in files
            layer["interface"] = self.interface
        return layer

    def load(self, layer: dict[str, Any]) -> None:
        self.interface = layer.get("interface", DEFAULT_INTERFACE)
        self.thickness.load_spec(layer["thickness"])
        self.modulus.load_spec(layer["modulus"])
        self.poisson.load_spec(layer["poisson"])


#: Longest scene name and description the explorer accepts [characters], from a file, a
#: link or the page: the core's own bounds (``core.limits``; a name is echoed into the
#: drawing's title, the file names and the address bar: a 15-million-character name once
#: went into all three). The page's description bound was 4000 where a scene file's is
#: 5000: a scene the command line solved was refused by the page.
MAX_NAME_CHARS = limits.MAX_NAME_CHARS
MAX_DESCRIPTION_CHARS = limits.MAX_DESCRIPTION_CHARS


def check_text(field: str, value: Any, limit: int) -> str:
    """``value`` if it is text of at most ``limit`` characters, else a ValueError naming
    ``field`` (the text itself is not repeated: it may be huge)."""
    if not isinstance(value, str):
        raise ValueError(f"{field}: must be text, got {type(value).__name__}")
    if len(value) > limit:
        raise ValueError(f"{field}: at most {limit} characters, got {len(value)}")
    return value


#: Layers the state holds (the schema allows ten; the screen offers five).
MAX_LAYERS = 10
SCREEN_LAYERS = 5


class PunchState(param.Parameterized):
    """The rigid punch: half-width and base shape ``f(x)`` (height above its lowest point).

    Shape features are given in micrometres (and microradians, kilometres of radius):
    what matters is their size against the elastic deflections, which are of that order.
    """

    half_width = param.Number(default=1.0, softbounds=(0.1, 5.0),
                              doc="Punch half-width a [m].")
    shape = param.Selector(
        default="flat",
        objects=["flat", "parabolic", "wedge", "stepped", "land", "wavy", "custom"],
        doc="Base shape of the punch.")
    radius = param.Number(default=20.0, softbounds=(1.0, 500.0),
                          doc="Radius of a crowned (parabolic) punch [km] (f = x^2 / 2R).")
    slope = param.Number(default=20.0, softbounds=(0.0, 200.0),
                         doc="Slope of each face of a symmetric wedge [µrad] (f = s|x|).")
    step_height = param.Number(
        default=10.0, softbounds=(-100.0, 100.0),
        doc="Height of a single step [µm]: the part right of the step is raised by it.")
    step_position = param.Number(default=0.0, doc="Position of the step [m].")
    land_height = param.Number(default=15.0, softbounds=(0.0, 100.0),
                               doc="How far the central land protrudes below the outer "
                                   "parts [µm].")
    land_width = param.Number(default=0.8, softbounds=(0.05, 2.0),
                              doc="Width of the central land [m].")
    wave_amplitude = param.Number(default=5.0, softbounds=(0.0, 50.0),
                                  doc="Amplitude of a wavy (rough) base [µm].")
    wave_length = param.Number(default=0.5, softbounds=(0.02, 5.0),
                               doc="Wavelength of a wavy base [m].")
    custom = param.Parameter(default=None,
                             doc="A shape spec (SI) from a file or an uploaded CSV table.")
    custom_label = param.String(default="", doc="Where the custom shape came from.")

    def shape_spec(self) -> float | dict[str, Any]:
        """The shape ``f(x)`` as a profile spec in metres."""
        a = self.half_width
        if self.shape == "parabolic":
            # said in the box's words: 0 km read "punch.shape.coefficients[2]: must be a
            # finite number, is inf", and -5 km drew a dished base under "crowned"
            if not (math.isfinite(self.radius) and self.radius > 0.0):
                raise ValueError(f"punch.shape: the crown radius R must be > 0 km, is "
                                 f"{self.radius:g} km (a dished base is a custom shape, a "
                                 "table of heights or a polynomial in a scene file)")
            curvature = 1.0 / (2.0 * self.radius * _KM)
            return {"kind": "polynomial", "coefficients": [0.0, 0.0, curvature]}
        if self.shape == "wedge":
            rise = self.slope * _URAD * a
            return {"kind": "table", "points": [[-a, rise], [0.0, 0.0], [a, rise]],
                    "interpolation": "linear"}
        # the step's and the land's edges must lie on the punch: said in the slider's words
        # (the core's "punch.shape.breaks[0]: must lie strictly inside ..." named no box)
        if self.shape == "stepped":
            if not -a < self.step_position < a:
                raise ValueError(f"punch.shape: the step position must lie strictly inside "
                                 f"the punch ({-a:g}, {a:g}) m, is {self.step_position:g} m")
            return {"kind": "step", "values": [0.0, self.step_height * _UM],
                    "breaks": [self.step_position]}
        if self.shape == "land":
            if not 0.0 < self.land_width < 2.0 * a:
                raise ValueError(f"punch.shape: the land width must be above 0 and below the "
                                 f"punch's width 2a = {2.0 * a:g} m, is {self.land_width:g} m")
            h, half = self.land_height * _UM, 0.5 * self.land_width
            return {"kind": "step", "values": [h, 0.0, h], "breaks": [-half, half]}
        if self.shape == "wavy":
            return {"kind": "sine", "mean": 0.0, "amplitude": self.wave_amplitude * _UM,
                    "wavelength": self.wave_length, "phase": 0.0}
        if self.shape == "custom" and self.custom is not None:
            return copy.deepcopy(self.custom)
        return 0.0

    def to_dict(self) -> dict[str, Any]:
        return {"half_width": self.half_width, "shape": self.shape_spec()}

    def load(self, punch: dict[str, Any]) -> None:
        a = punch["half_width"]
        spec = punch.get("shape", 0.0)
        values: dict[str, Any] = {"half_width": a, "custom": None, "custom_label": ""}
        kind = spec.get("kind") if isinstance(spec, dict) else None
        points = spec.get("points") if kind == "table" else None
        coefficients = spec.get("coefficients", []) if kind == "polynomial" else []
        steps = spec.get("values", []) if kind == "step" else []
        breaks = spec.get("breaks", []) if kind == "step" else []
        if _is_number(spec) and spec == 0:
            values["shape"] = "flat"
        elif (len(coefficients) == 3 and coefficients[0] == 0 and coefficients[1] == 0
              and _is_number(coefficients[2]) and coefficients[2] > 0):
            values.update(shape="parabolic", radius=1.0 / (2.0 * coefficients[2]) / _KM)
        elif (points is not None and len(points) == 3 and spec.get("interpolation") == "linear"
              and points[1] == [0.0, 0.0] and points[0][0] == -a and points[2][0] == a
              and points[0][1] == points[2][1]):
            values.update(shape="wedge", slope=points[2][1] / a / _URAD)
        elif len(steps) == 2 and steps[0] == 0 and len(breaks) == 1:
            values.update(shape="stepped", step_height=steps[1] / _UM,
                          step_position=breaks[0])
        elif (len(steps) == 3 and steps[1] == 0 and steps[0] == steps[2]
              and len(breaks) == 2 and breaks[0] == -breaks[1]):
            values.update(shape="land", land_height=steps[0] / _UM,
                          land_width=breaks[1] - breaks[0])
        elif (kind == "sine" and spec.get("mean") == 0 and spec.get("phase", 0) == 0
              and _is_number(spec.get("amplitude"))):
            values.update(shape="wavy", wave_amplitude=spec["amplitude"] / _UM,
                          wave_length=spec["wavelength"])
        else:
            values.update(shape="custom", custom=copy.deepcopy(spec), custom_label="the scene")
        self.param.update(**values)


class BaseState(param.Parameterized):
    """The viscoelastic base layer on a rigid foundation."""

    thickness = param.Number(default=2.0, softbounds=(0.1, 20.0),
                             doc="Base thickness H [m].")
    poisson = param.Number(default=0.2, softbounds=(0.0, 0.49), doc="Base Poisson ratio.")
    modulus = param.Number(
        default=30.0, softbounds=(0.1, 60.0),
        doc="Base Young's modulus [GPa] (the final modulus for aging creep).")
    age_at_loading = param.Number(default=28.0, softbounds=(1.0, 3650.0),
                                  doc="Age of the base when the load is applied [days].")
    creep_model = param.Selector(default="elastic", objects=list(CREEP_MODELS),
                                 doc="Creep law of the base.")
    compliance = param.Number(
        default=0.03, softbounds=(0.0, 0.2),
        doc="Final creep compliance [1/GPa] (creep strain per unit stress).")
    rate = param.Number(default=0.03, softbounds=(0.001, 1.0),
                        doc="Rate of creep [1/day].")
    beta = param.Number(default=0.5, softbounds=(0.0, 0.95),
                        doc="Aging of the modulus: E(age) = E_final (1 - beta exp(-alpha age)).")
    alpha = param.Number(default=0.03, softbounds=(0.001, 1.0),
                         doc="Rate of aging of the modulus [1/day].")
    aging = param.Number(default=1.0, softbounds=(0.0, 10.0),
                         doc="Aging part of the creep compliance [day/GPa] (A / age).")
    custom = param.Parameter(default=None,
                             doc="A creep spec (SI) of a model not offered on screen, kept "
                                 "verbatim (Prony series, user kernel).")

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        #: inputs of the design-code models, in the codes' units
        self.code = CodeCreepState(name="base_code")

    def creep_dict(self) -> dict[str, Any]:
        if self.creep_model in CODE_CREEP_MODELS:
            return self.code.spec(model=self.creep_model)
        if self.creep_model == "exponential":
            return {"model": "exponential", "modulus": self.modulus * _GPA,
                    "compliance": self.compliance / _GPA, "rate": self.rate}
        if self.creep_model == "arutyunyan":
            return {"model": "arutyunyan", "modulus_final": self.modulus * _GPA,
                    "beta": self.beta, "alpha": self.alpha,
                    "compliance_final": self.compliance / _GPA,
                    "aging": self.aging / _GPA, "rate": self.rate}
        if self.creep_model == "custom":
            if self.custom is None:
                # never solve another model than the one named on screen
                raise ValueError("base.creep: 'the scene's own model' needs a creep model "
                                 "from a scene file; choose one of the models offered")
            return copy.deepcopy(self.custom)
        return {"model": "elastic", "modulus": self.modulus * _GPA}

    def to_dict(self) -> dict[str, Any]:
        return {"thickness": self.thickness, "poisson": self.poisson,
                "age_at_loading": self.age_at_loading, "creep": self.creep_dict()}

    def load(self, base: dict[str, Any]) -> None:
        creep = base["creep"]
        model = creep["model"]
        values: dict[str, Any] = {"thickness": base["thickness"], "poisson": base["poisson"],
                                  "age_at_loading": base["age_at_loading"],
                                  "creep_model": model, "custom": None}
        if model == "arutyunyan":
            values.update(modulus=creep["modulus_final"] / _GPA, beta=creep["beta"],
                          alpha=creep["alpha"], compliance=creep["compliance_final"] * _GPA,
                          aging=creep["aging"] * _GPA, rate=creep["rate"])
        elif model == "exponential":
            values.update(modulus=creep["modulus"] / _GPA, compliance=creep["compliance"] * _GPA,
                          rate=creep["rate"])
        elif model == "elastic":
            values.update(modulus=creep["modulus"] / _GPA)
        elif model in CODE_CREEP_MODELS:
            self.code.load(creep)
        else:
            values.update(creep_model="custom", custom=copy.deepcopy(creep))
            if isinstance(creep.get("modulus"), (int, float)):
                values.update(modulus=creep["modulus"] / _GPA)
        self.param.update(**values)
