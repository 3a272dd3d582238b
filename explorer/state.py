"""Widget state of the explorer: plain ``param`` classes that turn values into a scene dict.

Nothing here imports Panel. Each class holds the values a user sets, in the units shown on
screen (mm, MPa, GPa, kN/m, ...), and converts them to the SI scene dictionary that
``core.scene_from_dict`` validates (schema version 1). The reverse direction,
:meth:`ExplorerState.load_scene`, fills the state from any valid scene (a preset, a file
or a link); a profile that none of the on-screen families can express is kept verbatim
as a ``custom`` profile, so loading and saving a scene never changes it.

Parameters carry soft bounds only (they size the sliders): validating a value is the
job of the core, whose messages name the offending field.
"""

from __future__ import annotations

import copy
import math
from typing import Any

import param

from core.coating_model import DEFAULT_INTERFACE, DEFAULT_MODEL_TOL, INTERFACES, MODEL_TOL_RANGE
from core.profiles import HISTORY_FORMS, VARIATIONS, history_form_of, variation_of
from core.scene import QUANTITIES

from .code_creep_state import CODE_CREEP_MODELS, CodeCreepState

#: Contact models of ``solver.contact``, as the solver names them ("auto" is the default).
CONTACT_MODELS = ("auto", "full", "unilateral")
DEFAULT_CONTACT = "auto"

#: The four statements (which two quantities are given), as shown on screen.
STATEMENTS: dict[str, tuple[str, str]] = {
    "settlement + tilt given": ("settlement", "tilt"),
    "settlement + moment given": ("settlement", "moment"),
    "tilt + force given": ("tilt", "force"),
    "force + moment given": ("force", "moment"),
}


#: Display unit and its size in SI for each loading quantity.
QUANTITY_UNITS: dict[str, tuple[str, float]] = {
    "settlement": ("mm", 1e-3),
    "tilt": ("mrad", 1e-3),
    "force": ("kN/m", 1e3),
    "moment": ("kN·m/m", 1e3),
}

#: Default soft range of each loading quantity's main value, in display units.
QUANTITY_RANGES: dict[str, tuple[float, float]] = {
    "settlement": (0.0, 0.2),
    "tilt": (-0.1, 0.1),
    "force": (0.0, 2000.0),
    "moment": (-500.0, 500.0),
}

CREEP_MODELS: dict[str, str] = {
    "elastic": "elastic (no creep)",
    "exponential": "non-aging exponential creep",
    "arutyunyan": "aging creep (Arutyunyan)",
    "fib_mc2010": "concrete, fib Model Code 2010",
    "eurocode2": "concrete, Eurocode 2",
    "custom": "other model (from file)",
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
#: link or the page: a name is echoed into the drawing's title, the file names and the
#: address bar (a 15-million-character name once went into all three).
MAX_NAME_CHARS = 200
MAX_DESCRIPTION_CHARS = 4000


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
            radius = self.radius * _KM
            # a zero radius must reach the core, which names the field, not crash here
            curvature = 1.0 / (2.0 * radius) if radius != 0 else math.inf
            return {"kind": "polynomial", "coefficients": [0.0, 0.0, curvature]}
        if self.shape == "wedge":
            rise = self.slope * _URAD * a
            return {"kind": "table", "points": [[-a, rise], [0.0, 0.0], [a, rise]],
                    "interpolation": "linear"}
        if self.shape == "stepped":
            return {"kind": "step", "values": [0.0, self.step_height * _UM],
                    "breaks": [self.step_position]}
        if self.shape == "land":
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
            values.update(shape="custom", custom=copy.deepcopy(spec), custom_label="a file")
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
                raise ValueError("base.creep: 'other model (from file)' needs a creep model "
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


class HistoryState(param.Parameterized):
    """The history of one loading quantity, ``t`` in days after loading (display units)."""

    kind = param.Selector(default="constant", objects=[*HISTORY_FORMS, "custom"],
                          doc="Shape of the history.")
    value = param.Number(default=0.0, doc="Main level: the constant, the ramp's final "
                                          "value, the value before a step, the sine's mean.")
    second = param.Number(default=0.0, doc="Ramp start value, value after a step, or sine "
                                           "amplitude (display units).")
    time = param.Number(default=10.0, softbounds=(0.1, 1000.0),
                        doc="Ramp duration, step time or sine period [days].")
    custom = param.Parameter(default=None, doc="A history spec (SI) kept verbatim.")

    def __init__(self, quantity: str, **params: Any) -> None:
        super().__init__(**params)
        self.quantity = quantity
        self.unit, self.scale = QUANTITY_UNITS[quantity]

    def to_spec(self) -> float | dict[str, Any]:
        if self.kind == "custom" and self.custom is not None:
            return copy.deepcopy(self.custom)
        form = HISTORY_FORMS.get(self.kind, HISTORY_FORMS["constant"])
        return form.spec({"value": self.value * self.scale, "second": self.second * self.scale,
                          "time": self.time})

    def load_spec(self, spec: Any) -> None:
        values: dict[str, Any] = {"kind": "custom", "custom": copy.deepcopy(spec)}
        found = history_form_of(spec)
        if found is not None:
            name, numbers = found
            values = {**numbers, "kind": name, "custom": None}
            for key in ("value", "second"):  # SI to display units; times are days
                if key in values:
                    values[key] = values[key] / self.scale
        self.param.update(**values)


class LoadingState(param.Parameterized):
    """Which two quantities are given, and the history of each of the four."""

    statement = param.Selector(default="force + moment given", objects=list(STATEMENTS),
                               doc="Which two of settlement, tilt, force, moment are given.")

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        defaults = {"settlement": 0.05, "tilt": 0.0, "force": 500.0, "moment": 0.0}
        self.histories = {q: HistoryState(q, value=defaults[q], name=q) for q in QUANTITIES}

    @property
    def given(self) -> tuple[str, str]:
        return STATEMENTS[self.statement]

    @property
    def unknowns(self) -> tuple[str, str]:
        given = self.given
        first, second = (q for q in QUANTITIES if q not in given)
        return first, second

    def to_dict(self) -> dict[str, Any]:
        return {q: self.histories[q].to_spec() for q in self.given}

    def load(self, loading: dict[str, Any]) -> None:
        keys = set(loading)
        for label, pair in STATEMENTS.items():
            if set(pair) == keys:
                statement = label
                break
        else:
            raise ValueError("loading: exactly two of settlement, tilt, force, moment, as "
                             "one of the pairs settlement+tilt, settlement+moment, "
                             "tilt+force, force+moment, got " + ", ".join(sorted(keys)))
        for q, spec in loading.items():
            self.histories[q].load_spec(spec)
        self.statement = statement


class ExplorerState(param.Parameterized):
    """Everything a user sets, turned into a scene dict by :meth:`to_scene`.

    ``revision`` increases by one after every change that alters the scene (a batch of
    changes such as loading a preset counts once): watch it to trigger solves.
    """

    scene_name = param.String(default="custom scene", doc="Name of the scene.")
    description = param.String(default="", doc="Description of the scene.")
    n_layers = param.Integer(default=1, bounds=(1, MAX_LAYERS), softbounds=(1, SCREEN_LAYERS),
                             doc="Number of coating layers.")
    time_end = param.Number(default=365.0, softbounds=(1.0, 3650.0),
                            doc="End of the time span [days after loading].")
    time_count = param.Integer(default=40, softbounds=(2, 200),
                               doc="Number of output times.")
    time_spacing = param.Selector(default="linear", objects=["linear", "log"],
                                  doc="Spacing of the output times.")
    time_list = param.List(default=None, allow_None=True, item_type=(int, float),
                           doc="Explicit output times [days] from a file; cleared by any "
                               "change of the time span, count or spacing.")
    tol = param.Selector(default=1e-6, objects=[1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8],
                         doc="Accuracy target of the solver (relative).")
    contact = param.Selector(default=DEFAULT_CONTACT, objects=list(CONTACT_MODELS),
                             doc="Contact model (solver.contact): auto (full contact unless "
                                 "it is lost), full, or unilateral (the base may lift off).")
    model_tol_percent = param.Number(
        default=100.0 * DEFAULT_MODEL_TOL,
        bounds=(100.0 * MODEL_TOL_RANGE[0], 100.0 * MODEL_TOL_RANGE[1]),
        doc="Coating-model error a result may carry unflagged (solver.model_tol) [%].")
    revision = param.Integer(default=0, doc="Counts changes of the scene.")

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        self.punch = PunchState(name="punch")
        self.layers = [LayerState(name=f"layer{k}") for k in range(MAX_LAYERS)]
        self.base = BaseState(name="base")
        self.loading = LoadingState(name="loading")
        self._extra: dict[str, Any] = {}
        # name of the scene as loaded, while it is shown unchanged (see _rename_modified)
        self._loaded_name: str | None = None
        self._batch = 0
        self._dirty = False
        watched = [self.punch, self.base, self.base.code, self.loading,
                   *self.loading.histories.values(),
                   *(p for layer in self.layers for p in layer.profiles)]
        watched += self.layers
        for obj in watched:
            names = [n for n in obj.param if n != "name"]
            obj.param.watch(self._on_change, names)
        self.param.watch(self._on_change, ["scene_name", "description", "n_layers",
                                           "time_end", "time_count", "time_spacing", "tol",
                                           "time_list", "contact", "model_tol_percent"])
        self.param.watch(self._on_times, ["time_end", "time_count", "time_spacing"])

    # -- change tracking -------------------------------------------------------------
    def _on_change(self, *events: param.parameterized.Event) -> None:
        if self._batch:
            self._dirty = True
            return
        self._rename_modified(events)
        self.revision += 1

    def _rename_modified(self, events: tuple[param.parameterized.Event, ...]) -> None:
        """The first change of a loaded scene renames it "... (modified)" and says where
        it came from, so that a saved file does not pass for the preset; a name or
        description the user typed is kept."""
        loaded = self._loaded_name
        if loaded is None:
            return
        if any(e.obj is self and e.name in ("scene_name", "description") for e in events):
            self._loaded_name = None  # the user names the scene now
            return
        self._loaded_name = None
        if self.scene_name != loaded or loaded.endswith(" (modified)"):
            return
        self._batch += 1
        try:
            self.param.update(
                scene_name=f"{loaded[: MAX_NAME_CHARS - 11]} (modified)",
                description=f"Changed on screen from the scene “{loaded}”.")
        finally:
            self._batch -= 1

    def _on_times(self, *events: param.parameterized.Event) -> None:
        if not self._batch and self.time_list is not None:
            self.time_list = None

    def to_scene(self) -> dict[str, Any]:
        """The scene dict (schema version 1, SI units, days) of the current values."""
        scene: dict[str, Any] = {
            "schema_version": 1,
            "name": self.scene_name,
            "description": self.description,
            "punch": self.punch.to_dict(),
            "coating": [layer.to_dict() for layer in self.layers[: self.n_layers]],
            "base": self.base.to_dict(),
            "loading": self.loading.to_dict(),
            "times": (list(self.time_list) if self.time_list is not None else
                      {"end": self.time_end, "count": self.time_count,
                       "spacing": self.time_spacing}),
            "solver": self._solver_dict(),
        }
        for key, value in self._extra.items():
            scene.setdefault(key, copy.deepcopy(value))
        return scene

    def _solver_dict(self) -> dict[str, Any]:
        """``solver`` of the scene; fields at their defaults are left implicit."""
        solver: dict[str, Any] = {"tol": self.tol}
        if self.contact != DEFAULT_CONTACT:
            solver["contact"] = self.contact
        # to 12 digits, so that a loaded 0.05 (shown as 5 %) is saved as 0.05 again
        model_tol = float(f"{self.model_tol_percent / 100.0:.12g}")
        if not math.isclose(model_tol, DEFAULT_MODEL_TOL, rel_tol=_RTOL):
            solver["model_tol"] = model_tol
        return solver

    def load_scene(self, scene: dict[str, Any]) -> None:
        """Fill every value from a scene dict (assumed valid) as one change.

        Raises ``ValueError`` (naming the field) when the scene cannot be represented; the
        state is then left unchanged.
        """
        check_text("name", scene.get("name", ""), MAX_NAME_CHARS)
        check_text("description", scene.get("description", ""), MAX_DESCRIPTION_CHARS)
        layers = scene["coating"]
        if not 1 <= len(layers) <= MAX_LAYERS:
            raise ValueError(f"coating: between 1 and {MAX_LAYERS} layers are supported, "
                             f"got {len(layers)}")
        snapshot = self.to_scene()
        self._batch += 1
        try:
            self._load(scene)
        except (KeyError, TypeError, ValueError) as exc:
            self._load(snapshot)
            detail = exc.args[0] if exc.args else ""
            if isinstance(exc, KeyError):
                detail = f"missing {detail!r}"
            raise ValueError(f"scene: cannot be shown ({detail})") from exc
        finally:
            self._batch -= 1
        if not self._batch:
            self._dirty = False
            self._loaded_name = self.scene_name
            self.revision += 1

    def _load(self, scene: dict[str, Any]) -> None:
        known = {"schema_version", "name", "description", "punch", "coating", "base",
                 "loading", "times", "solver"}
        # Keys outside the on-screen schema (later schema additions) travel unchanged.
        self._extra = {k: copy.deepcopy(v) for k, v in scene.items() if k not in known}
        self.punch.load(scene["punch"])
        for layer, spec in zip(self.layers, scene["coating"], strict=False):
            layer.load(spec)
        self.base.load(scene["base"])
        self.loading.load(scene["loading"])
        times = scene.get("times", {})
        time_list = None
        if isinstance(times, list):
            time_list = list(times)
            times = {"end": max(times, default=self.time_end), "count": len(times)}
        solver = scene.get("solver", {})
        tol = float(solver.get("tol", 1e-6))
        if tol not in self.param.tol.objects:
            self.param.tol.objects = sorted({*self.param.tol.objects, tol}, reverse=True)
        self.param.update(
            scene_name=scene.get("name", "custom scene"),
            description=scene.get("description", ""),
            n_layers=len(scene["coating"]),
            time_end=times.get("end", self.time_end),
            time_count=times.get("count", self.time_count),
            time_spacing=times.get("spacing", self.time_spacing),
            tol=tol,
            contact=solver.get("contact", DEFAULT_CONTACT),
            model_tol_percent=100.0 * float(solver.get("model_tol", DEFAULT_MODEL_TOL)),
            time_list=time_list,
        )

    def is_load_event(self, obj: param.Parameterized) -> bool:
        """Whether ``obj`` belongs to the loading histories (cheap re-solve expected)."""
        return obj in self.loading.histories.values()
