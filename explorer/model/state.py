"""Widget state of the explorer: plain ``param`` classes that turn values into a scene dict.

Nothing here imports Panel. Each class holds the values a user sets, in the units shown on
screen (mm, MPa, GPa, kN/m, ...), and converts them to the SI scene dictionary that
``core.scene_from_dict`` validates (schema version 1). The reverse direction,
:meth:`ExplorerState.load_scene`, fills the state from any valid scene (a preset, a file
or a link); a profile that none of the on-screen families can express is kept verbatim
as a ``custom`` profile, so loading and saving a scene never changes it.

The parts of a scene (punch, coating layers, base, loading) are classes of their own
(:mod:`explorer.model.scene_parts`, :mod:`explorer.model.loading_state`); their names
are also found here.

Parameters carry soft bounds only (they size the sliders): validating a value is the
job of the core, whose messages name the offending field.
"""

from __future__ import annotations

import copy
import math
from typing import Any

import param

from core.coating import DEFAULT_MODEL_TOL, INTERFACES, MODEL_TOL_RANGE
from core.problem import QUANTITIES
from core.scene import default_tol

from .code_creep_state import CODE_CREEP_MODELS
from .loading_state import QUANTITY_RANGES, QUANTITY_UNITS, STATEMENTS, HistoryState, LoadingState
from .punches_state import SCREEN_PUNCHES, PunchEntryState, next_center
from .scene_parts import (
    _RTOL,
    CONTACT_MODELS,
    CREEP_MODELS,
    DEFAULT_CONTACT,
    MAX_DESCRIPTION_CHARS,
    MAX_LAYERS,
    MAX_NAME_CHARS,
    SCREEN_LAYERS,
    BaseState,
    LayerState,
    ProfileState,
    PunchState,
    check_text,
)

__all__ = ["CONTACT_MODELS", "CREEP_MODELS", "DEFAULT_CONTACT", "INTERFACES",
           "MAX_DESCRIPTION_CHARS", "MAX_LAYERS", "MAX_NAME_CHARS", "MODEL_TOL_RANGE",
           "QUANTITIES", "QUANTITY_RANGES", "QUANTITY_UNITS", "SCREEN_LAYERS", "STATEMENTS",
           "BaseState", "ExplorerState", "HistoryState", "LayerState", "LoadingState",
           "ProfileState", "PunchState", "check_text"]


#: What the first change of a loaded scene appends to its name.
MODIFIED = " (modified)"

class ExplorerState(param.Parameterized):
    """Everything a user sets, turned into a scene dict by :meth:`to_scene`.

    ``revision`` increases by one after every change that alters the scene (a batch of
    changes such as loading a preset counts once): watch it to trigger solves.
    """

    scene_name = param.String(default="custom scene", doc="Name of the scene.")
    description = param.String(default="", doc="Description of the scene.")
    n_layers = param.Integer(default=1, bounds=(0, MAX_LAYERS), softbounds=(0, SCREEN_LAYERS),
                             doc="Number of coating layers (0: the punch on the bare base).")
    time_end = param.Number(default=365.0, softbounds=(1.0, 3650.0),
                            doc="End of the time span [days after loading].")
    time_count = param.Integer(default=40, softbounds=(2, 200),
                               doc="Number of output times.")
    time_spacing = param.Selector(default="linear", objects=["linear", "log"],
                                  doc="Spacing of the output times.")
    time_start = param.Number(default=None, allow_None=True, bounds=(0.0, None),
                              inclusive_bounds=(False, True),
                              doc="First output time after 0 with log spacing [days after "
                                  "loading] (None: a thousandth of the time span).")
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
    n_punches = param.Integer(
        default=0, bounds=(0, SCREEN_PUNCHES),
        doc="Punches of a scene of several (``punches``, the first ``n_punches`` of "
            "``punch_entries``); 0: the scene's one ``punch`` and ``loading``.")
    revision = param.Integer(default=0, doc="Counts changes of the scene.")
    tol_note = param.String(
        default="", doc="Why the accuracy target was raised (a design code's creep law "
                        "allows no finer one); empty otherwise.")

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        self.punch = PunchState(name="punch")
        self.layers = [LayerState(name=f"layer{k}") for k in range(MAX_LAYERS)]
        self.base = BaseState(name="base")
        self.loading = LoadingState(name="loading")
        self.punch_entries = [PunchEntryState(name=f"punches{k}") for k in range(SCREEN_PUNCHES)]
        for loading in (self.loading, *(entry.loading for entry in self.punch_entries)):
            for history in loading.histories.values():
                history.span = self._span
        self._extra: dict[str, Any] = {}
        # name of the scene as loaded, while it is shown unchanged (see _rename_modified)
        self._loaded_name: str | None = None
        self._batch = 0
        self._dirty = False
        # before the change tracking: the scene of a switch to a code carries its target
        self.base.param.watch(self._on_creep_law, ["creep_model", "age_at_loading"])
        self._raising_tol = False
        self.param.watch(self._on_tol, ["tol"])
        watched = [self.punch, self.base, self.base.code, self.loading,
                   *self.loading.histories.values(),
                   *(p for layer in self.layers for p in layer.profiles)]
        watched += self.layers
        watched += [part for entry in self.punch_entries for part in entry.watched]
        for obj in watched:
            names = [n for n in obj.param if n != "name"]
            obj.param.watch(self._on_change, names)
        self.param.watch(self._on_change, ["scene_name", "description", "n_layers",
                                           "time_end", "time_count", "time_spacing",
                                           "time_start", "tol",
                                           "time_list", "contact", "model_tol_percent",
                                           "n_punches"])
        self.param.watch(self._on_times, ["time_end", "time_count", "time_spacing",
                                          "time_start"])

    # -- the accuracy a creep law allows ----------------------------------------------
    def _on_creep_law(self, *events: param.parameterized.Event) -> None:
        """Raise the accuracy target to one a design code's creep law can meet (the
        default a scene file without ``solver.tol`` gets, :func:`core.scene.default_tol`),
        and say so; a loaded scene keeps its own target."""
        if self._batch:
            return
        base = self.base
        if base.creep_model not in CODE_CREEP_MODELS:
            self.tol_note = ""
            return
        try:
            allowed = default_tol(base.creep_dict(), base.age_at_loading)
        except ValueError:
            return  # an input out of range: the solve names it
        if self.tol >= allowed:
            return
        if allowed not in self.param.tol.objects:
            self.param.tol.objects = sorted({*self.param.tol.objects, allowed}, reverse=True)
        self.tol_note = (f"Accuracy target raised from {self.tol:g} to {allowed:g}: "
                         f"the {CODE_CREEP_MODELS[base.creep_model]} creep law is fitted "
                         "by exponentials no closer at this age at loading, so a finer target "
                         "would be flagged as not met.")
        self._raising_tol = True
        try:
            self.tol = allowed
        finally:
            self._raising_tol = False

    def _on_tol(self, *events: param.parameterized.Event) -> None:
        if not self._raising_tol:
            self.tol_note = ""  # the user's own choice (or a loaded scene's) stands

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
        if self.scene_name != loaded or loaded.endswith(MODIFIED):
            return
        self._batch += 1
        try:
            self.param.update(
                scene_name=f"{loaded[: MAX_NAME_CHARS - len(MODIFIED)]}{MODIFIED}",
                description=f"Changed on screen from the scene “{loaded}”.")
        finally:
            self._batch -= 1

    def _span(self) -> float:
        """The time span of the scene [days after loading]: its last output time."""
        if self.time_list:
            return float(max(self.time_list))
        return float(self.time_end)

    def _on_times(self, *events: param.parameterized.Event) -> None:
        if not self._batch and self.time_list is not None:
            self.time_list = None

    @property
    def punches(self) -> list[PunchEntryState]:
        """The punches of a scene of several (empty for the single-punch form)."""
        return self.punch_entries[: self.n_punches]

    def add_punch(self) -> int:
        """Add a punch to a scene of several (a copy of the rightmost, beside it), as one
        change; returns its index. ValueError when the screen holds no more."""
        n = self.n_punches
        if not 0 < n < SCREEN_PUNCHES:
            raise ValueError(f"punches: the page edits 1 to {SCREEN_PUNCHES} punches "
                             f"(a scene of several punches), it has {n}")
        entries = self.punches
        right = max(entries, key=lambda e: e.center + e.punch.half_width)
        with self.batch():
            self.punch_entries[n].copy_from(right, next_center(entries))
            self.n_punches = n + 1
        return n

    def remove_punch(self, index: int) -> None:
        """Remove punch ``index`` (the others keep their order), as one change; the last
        punch stays (ValueError)."""
        n = self.n_punches
        if n <= 1 or not 0 <= index < n:
            raise ValueError(f"punches: punch {index + 1} cannot be removed (the scene has "
                             f"{n}; one at least stays)")
        specs = [e.to_dict() for k, e in enumerate(self.punches) if k != index]
        with self.batch():
            for entry, spec in zip(self.punch_entries, specs, strict=False):
                entry.load(spec)
            self.n_punches = n - 1

    def batch(self) -> _Batch:
        """A context in which changes count as one (``revision`` goes up once at its end,
        if anything changed)."""
        return _Batch(self)

    def to_scene(self) -> dict[str, Any]:
        """The scene dict (schema version 1, SI units, days) of the current values."""
        several = self.n_punches > 0
        scene: dict[str, Any] = {
            "schema_version": 1,
            "name": self.scene_name,
            "description": self.description,
            **({"punches": [entry.to_dict() for entry in self.punches]} if several
               else {"punch": self.punch.to_dict()}),
            "coating": [layer.to_dict() for layer in self.layers[: self.n_layers]],
            "base": self.base.to_dict(),
            **({} if several else {"loading": self.loading.to_dict()}),
            "times": (list(self.time_list) if self.time_list is not None else
                      {"end": self.time_end, "count": self.time_count,
                       "spacing": self.time_spacing,
                       **({"start": self.time_start} if self.time_spacing == "log"
                          and self.time_start is not None else {})}),
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
        if not 0 <= len(layers) <= MAX_LAYERS:
            raise ValueError(f"coating: between 0 and {MAX_LAYERS} layers are supported, "
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
                 "loading", "times", "solver", "punches"}
        # Keys outside the on-screen schema (later schema additions) travel unchanged.
        self._extra = {k: copy.deepcopy(v) for k, v in scene.items() if k not in known}
        punches = scene.get("punches")
        if punches is not None:
            if not 1 <= len(punches) <= SCREEN_PUNCHES:
                raise ValueError(f"punches: the page edits 1 to {SCREEN_PUNCHES} punches, "
                                 f"the scene has {len(punches)}")
            for entry, spec in zip(self.punch_entries, punches, strict=False):
                entry.load(spec)
            self.n_punches = len(punches)
        else:
            self.n_punches = 0
            self.punch.load(scene["punch"])
        for layer, spec in zip(self.layers, scene["coating"], strict=False):
            layer.load(spec)
        self.base.load(scene["base"])
        if punches is None:
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
            time_start=times.get("start"),
            tol=tol,
            contact=solver.get("contact", DEFAULT_CONTACT),
            model_tol_percent=100.0 * float(solver.get("model_tol", DEFAULT_MODEL_TOL)),
            time_list=time_list,
        )

    def is_load_event(self, obj: param.Parameterized) -> bool:
        """Whether ``obj`` belongs to the loading histories (cheap re-solve expected)."""
        return obj in self.loading.histories.values() or any(
            obj in entry.loading.histories.values() for entry in self.punch_entries)


class _Batch:
    """Changes of an :class:`ExplorerState` made inside count as one change."""

    def __init__(self, state: ExplorerState) -> None:
        self.state = state

    def __enter__(self) -> ExplorerState:
        self.state._batch += 1
        return self.state

    def __exit__(self, *exc: object) -> None:
        state = self.state
        state._batch -= 1
        if not state._batch and state._dirty:
            state._dirty = False
            state._on_change()
