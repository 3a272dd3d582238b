"""Several punches on one foundation: the ``punches`` form of a scene, and its answer.

A scene with ``punches`` (a list of ``{center, half_width, shape, loading}``) instead of
``punch`` and ``loading`` puts several rigid punches on one coated base; they act on each
other through the base (core/SCENES.md, "Several punches"). Each punch is checked as the
single-punch scene it would be at its own centre (same coating, base, times and solver),
so every field keeps its rules; a refusal names it as ``punches[k].<field>``.

One punch is the single-punch scene at its centre, answered by :func:`core.scene.solve`
(every base, contact model and engine). Several punches are coupled by the default engine
(:mod:`core.engines.nystrom.multi`) with the thin-layer coating model, in full contact (on
an elastic, aging or creeping base); they may lift off (``solver.contact``
``"unilateral"``, or ``"auto"`` when full contact is lost under some punch; then every
punch's contact set is an unknown): on an elastic base by
:func:`core.contact.solve_unilateral_punches`, each time on its own, on a creeping or
aging one by :func:`core.contact.solve_creep_punches`, one march in time over all
punches. Lift-off needs every punch pressed (a pulled punch is refused naming
``punches[k].loading.<field>``). The coating's profiles are functions of the global x
along the whole surface (checked over the punches' span); each punch sees them from its
centre.
"""

from __future__ import annotations

import copy
import copyreg
import json
import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np

from core import limits
from core.coating import DEFAULT_INTERFACE, THIN_LAYER
from core.contact import LoadNotCarried, solve_creep_punches, solve_unilateral_punches
from core.engines.nystrom import PunchGeometry, solve_punches
from core.problem import (
    TimeInputs,
    UnresolvedOperator,
    validate_geometry,
    validate_time_inputs,
)
from core.profiles import shifted
from core.scene import punches_output, schema
from core.scene.contact_zone import contact_width, lift_off_length
from core.scene.design import DesignCheck, DesignLimits
from core.scene.display import answered_settings
from core.scene.load_limits import check_loads_touch, not_carried
from core.scene.model import Scene
from core.scene.records import PROGRAM, csv_header
from core.scene.results import UNITS, SceneSolution
from core.scene.schema import SCHEMA_VERSION, _jsonable
from core.validation import bounded_list, finite_number
from core.version import VERSION


@dataclass(frozen=True, eq=False)
class PunchesScene:
    """A validated scene of several punches (build it with :func:`punches_from_dict`).

    ``scenes[k]`` is punch ``k`` as a single-punch :class:`core.scene.Scene` in its own
    coordinates (``x - centers[k]`` [m]); ``centers`` [m] the punch centres in the global
    x; ``data`` the canonical dict.
    """

    scenes: tuple[Scene, ...]
    centers: tuple[float, ...]
    data: dict

    def to_dict(self) -> dict[str, Any]:
        """The canonical JSON-able dict of the scene."""
        return copy.deepcopy(self.data)

    @property
    def name(self) -> str:
        """The scene's name."""
        return str(self.data["name"])

    @property
    def times(self) -> np.ndarray:
        """The output times [day after loading]."""
        return self.scenes[0].times

    @property
    def spans(self) -> list[tuple[float, float]]:
        """The zone ``(center - a, center + a)`` [m] of every punch, in order."""
        return [(c - s.half_width, c + s.half_width)
                for c, s in zip(self.centers, self.scenes, strict=True)]


def has_punches(d: Any) -> bool:
    """Whether ``d`` is a scene of the ``punches`` form (a dict or a :class:`PunchesScene`)."""
    return isinstance(d, PunchesScene) or (isinstance(d, Mapping) and "punches" in d)


def _renamed(message: str, k: int) -> str:
    """A refusal of the single-punch scene of punch ``k`` in the words of the file."""
    for prefix in ("punch.", "loading"):
        if message.startswith(prefix):
            rest = message[len("punch."):] if prefix == "punch." else message
            return f"punches[{k}].{rest}"
    return message.replace("punch.half_width", f"punches[{k}].half_width")


@contextmanager
def _in_scene_terms(scene: PunchesScene) -> Iterator[None]:
    """A load the lift-off model finds no contact for at one of its times refused in the
    words of the file (:func:`core.scene.load_limits.not_carried`), and an operator the
    coupled solve does not resolve, naming ``solver.tol``."""
    try:
        yield
    except LoadNotCarried as exc:
        k = 0 if exc.punch is None else exc.punch
        raise ValueError(not_carried(scene.scenes[k], exc, f"punches[{k}].")) from None
    except UnresolvedOperator as exc:
        # one punch falls back to another engine; the coupled modes of several have none
        # (the preset of two footings at tol 1e-11 and 1e-12; at 1e-10 it is answered,
        # flagged tol_not_met)
        raise ValueError(f"solver.tol: the coupled solve of several punches does not "
                         f"resolve this scene at tol {scene.scenes[0].tol:g} ({exc}); a "
                         "looser tol may be answered") from None


def punches_from_dict(d: Mapping[str, Any] | PunchesScene) -> PunchesScene:
    """Check a scene dict of the ``punches`` form and build a :class:`PunchesScene`.

    Raises ValueError naming the field: ``punch`` or ``loading`` given as well, a punch
    field out of range, two punches that overlap or touch (both named).
    """
    from core.scene.validate import scene_from_dict

    if isinstance(d, PunchesScene):
        return d
    for name in ("punch", "loading"):
        if isinstance(d, Mapping) and name in d:
            raise ValueError(f"{name}: give either punch and loading (one punch) or punches, "
                             "not both")
    d = schema.check_fields(d, "", tuple(n for n in schema.required_fields("scene")
                                          if n not in ("punch", "loading")) + ("punches",),
                            tuple(n for n in schema.optional_fields("scene") if n != "punches")
                            + (schema.SCHEMA_KEY,))
    punches = bounded_list(d["punches"], "punches", least=1, most=limits.MAX_PUNCHES,
                           what="punches")
    scenes, centers = [], []
    common = {k: v for k, v in d.items() if k not in ("punches", schema.SCHEMA_KEY)}
    # a coating that varies along x is read in the global x (below); each punch's own
    # checks see it at its centre meanwhile
    uniform = len(punches) == 1 or _uniform(common["coating"])
    for k, spec in enumerate(punches):
        path = f"punches[{k}]"
        schema.check_fields(spec, path, schema.required_fields("punches[k]"),
                            schema.optional_fields("punches[k]"))
        center = finite_number(spec["center"], f"{path}.center")
        single = dict(common, punch={"half_width": spec["half_width"],
                                     "shape": spec.get("shape", 0.0)},
                      loading=spec["loading"])
        if not uniform:
            single["coating"] = _at_centre(common["coating"], center)
        try:
            scenes.append(scene_from_dict(single))
        except ValueError as exc:
            raise ValueError(_renamed(str(exc), k)) from None
        centers.append(center)
    spans = [(c - s.half_width, c + s.half_width) for c, s in zip(centers, scenes, strict=True)]
    order = sorted(range(len(spans)), key=lambda k: spans[k][0])
    for left, right in zip(order, order[1:], strict=False):
        if spans[right][0] <= spans[left][1]:
            i, j = sorted((left, right))
            raise ValueError(
                f"punches: punches[{i}] and punches[{j}] overlap or touch ([{spans[i][0]:g}, "
                f"{spans[i][1]:g}] m and [{spans[j][0]:g}, {spans[j][1]:g}] m): move a centre "
                "or narrow a punch so that a gap remains between them")
    if len(scenes) > 1 and not scenes[0].coating:
        # the bare layer's answer (its corners' square-root edges) is one punch's
        raise ValueError("coating: several punches need at least one coating layer (the "
                         "bare layer, no coating, is answered for one punch only): add a "
                         "layer, or solve each punch on its own")
    if len(scenes) > 1 and not _uniform(common["coating"]):
        scenes = _along_x(common, scenes, centers, spans)
    # copies of only the parts kept (a whole scene's copy per part read was ~a tenth of a
    # load change of two punches)
    data = {k: copy.deepcopy(v) for k, v in scenes[0]._data.items()
            if k not in ("punch", "loading")}
    data["punches"] = [{"center": c, **copy.deepcopy(s._data["punch"]),
                        "loading": copy.deepcopy(s._data["loading"])}
                       for c, s in zip(centers, scenes, strict=True)]
    return PunchesScene(tuple(scenes), tuple(centers), data)


def _uniform(coating: Any) -> bool:
    """Whether every profile of a coating spec is a number or a constant (as given)."""
    if not isinstance(coating, list):
        return True  # refused by the single-punch checks, naming the field
    for layer in coating:
        if not isinstance(layer, Mapping):
            return True
        for name in ("thickness", "modulus", "poisson"):
            spec = layer.get(name)
            if isinstance(spec, Mapping) and spec.get("kind") != "constant":
                return False
    return True


def _at_centre(coating: list, center: float) -> list:
    """A coating spec with every varying profile replaced by a valid constant (1: the
    single-punch checks of the other fields run on it; the coating itself is read in the
    global x by :func:`_along_x`)."""
    out = []
    for layer in coating:
        layer = dict(layer)
        for name, value in (("thickness", 0.01), ("modulus", 1e9), ("poisson", 0.3)):
            if isinstance(layer.get(name), Mapping) and layer[name].get("kind") != "constant":
                layer[name] = value
        out.append(layer)
    return out


def _along_x(common: Mapping[str, Any], scenes: list[Scene], centers: list[float],
             spans: list[tuple[float, float]]) -> list[Scene]:
    """The punches' scenes under a coating that varies along x: its profiles are read in
    the global x over the punches' span (checked there, refusals naming
    ``coating[k].<field>``) and each punch sees them from its centre."""
    from dataclasses import replace

    from core.scene.validate import (
        _check_breakpoints,
        _check_load_rates,
        _check_solvable,
        check_uncoated,
    )

    domain = (min(lo for lo, _ in spans), max(hi for _, hi in spans))
    bounds = {"thickness": {"lower": 0.0}, "modulus": {"lower": 0.0},
              "poisson": {"lower": schema.POISSON_RANGE[0], "upper": schema.POISSON_RANGE[1]}}
    layers = []
    for k, spec in enumerate(common["coating"]):
        layers.append({name: schema._profile(spec[name], f"coating[{k}].{name}", "x", domain,
                                             **bounds[name])
                       for name in ("thickness", "modulus", "poisson")})
    coating_data = [{name: schema._jsonable(schema._spec_of(layer[name], spec[name]))
                     for name in ("thickness", "modulus", "poisson")}
                    | {"interface": spec.get("interface", DEFAULT_INTERFACE)}
                    for layer, spec in zip(layers, common["coating"], strict=True)]
    out = []
    for k, (scene, center) in enumerate(zip(scenes, centers, strict=True)):
        a = scene.half_width
        local = tuple(
            replace(old, **{name: shifted(layer[name], center, (-a, a))
                            for name in ("thickness", "modulus", "poisson")})
            for old, layer in zip(scene.coating, layers, strict=True))
        data = scene.to_dict()
        # the centre keys the geometry's caches: two punches alike but for their place
        # see different stretches of the coating
        data["punch"]["center"] = center
        data["coating"] = coating_data
        moved = replace(scene, coating=local, _data=data)
        try:
            _check_breakpoints(moved)
            _check_solvable(moved)
            check_uncoated(moved)
            _check_load_rates(moved)
        except ValueError as exc:
            raise ValueError(_renamed(str(exc), k)) from None
        out.append(moved)
    return out


def _lift_off(scene: PunchesScene, geometries: list[PunchGeometry],
              inputs: list[TimeInputs]) -> list[Any]:
    """Every punch's answer with lift-off (:func:`core.contact.solve_unilateral_punches`
    on an elastic base, :func:`core.contact.solve_creep_punches` on a creeping one)."""
    if inputs[0].kernel is None:
        return solve_unilateral_punches(geometries, inputs)
    return solve_creep_punches(geometries, inputs, time_breaks=_time_breaks(scene))


def _time_breaks(scene: PunchesScene) -> tuple[float, ...]:
    """Where any punch's given loads jump or kink (a punch loaded later): every time grid
    lands on each of them."""
    return tuple(sorted({b for sub in scene.scenes for b in sub.dimensionless.time_breaks}))


class PunchSolution(SceneSolution):
    """The answer of one punch of several, in SI units: a :class:`SceneSolution` of the
    punch's own scene (``pressure(x)`` and the plotting grid ``x`` in its coordinates,
    ``x - center``), plus ``center`` [m] and ``contact_set`` in the global x [m]; the
    moment is about the punch's own centre (it does work with the tilt)."""

    def __init__(self, scene: Scene, center: float, solution: Any) -> None:
        super().__init__(scene, scene.dimensionless, solution)
        self.center = float(center)
        self.contact_set = [[(self.center + lo, self.center + hi) for lo, hi in zones]
                            for zones in self.contact_set]

    def pressure_at(self, x: Any) -> np.ndarray:
        """q [Pa] at points ``x`` [m] of the global x on this punch, (len(x), len(times))."""
        return self.pressure(np.asarray(x, dtype=float) - self.center)

    @property
    def local_contact_set(self) -> list[list[tuple[float, float]]]:
        """:attr:`contact_set` in the punch's own coordinates ``x - center`` [m]."""
        return [[(lo - self.center, hi - self.center) for lo, hi in zones]
                for zones in self.contact_set]

    @property
    def contact_width(self) -> np.ndarray:
        """The contact width [m] at each output time (:func:`core.scene.contact_width`,
        the one definition, on the punch's own coordinates)."""
        return contact_width(self.local_contact_set, self.scene.half_width)

    @property
    def lift_off_length(self) -> np.ndarray:
        """The length of the base lifted off [m] at each output time
        (:func:`core.scene.lift_off_length`)."""
        return lift_off_length(self.local_contact_set, self.scene.half_width)


def _joint_message(messages: list[str]) -> str:
    """What a flag's text points to ("see info.message") for the scene: the punches' one
    message when they share it (one march answers them together), else each punch's,
    named (``punches[0]: ...; punches[1]: ...``)."""
    if len(set(messages)) == 1:
        return messages[0]
    return "; ".join(f"punches[{k}]: {m}" for k, m in enumerate(messages) if m)


class PunchesSolution:
    """The answer for a scene of several punches (see :func:`solve_punches_scene`).

    ``punches[k]`` (:class:`PunchSolution`) holds punch ``k``'s ``settlement`` [m],
    ``tilt`` [rad], ``force`` [N/m], ``moment`` [N] over ``times`` [day after loading]
    and its ``contact_set`` in the global x; ``flags`` are the punches' flags, each
    named ``punches[k].<flag>``; ``info["error_estimate"]`` is the largest of theirs.
    """

    def __init__(self, scene: PunchesScene, punches: list[PunchSolution]) -> None:
        self.scene = scene
        self.punches = punches
        self.times = np.array(scene.times, dtype=float)
        self.flags = [f"punches[{k}].{flag}" for k, p in enumerate(punches) for flag in p.flags]
        self.info: dict[str, Any] = {
            "punches": len(punches),
            "error_estimate": max(float(p.info["error_estimate"]) for p in punches),
            "success": all(bool(p.info["success"]) for p in punches),
            "flags": list(self.flags),
            "coating_model": punches[0].info.get("coating_model", THIN_LAYER),
            "message": _joint_message([str(p.info.get("message", "")) for p in punches]),
        }

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able dict, headed as one punch's (:meth:`SceneSolution.to_dict`): what
        produced it (``format``, ``program``, ``version``, ``solver``), the scene, the
        times, the flags, ``info`` and each punch's answer (its ``to_dict``, with its
        ``center`` and its design check in the global x [m], as its ``contact_set``; its
        ``x`` and ``pressure`` on its own coordinates, ``x - center``)."""
        punches = []
        for punch, check in zip(self.punches, self.design_checks(), strict=True):
            # the punch's own dict checks its design on its own x: the global one instead
            record = dict(punch.to_dict(), center=punch.center,
                          design_check=None if check is None else _jsonable(check.to_dict()))
            record["units"] = {**record["units"], "center": "m (global x)",
                               "contact_set": "m (global x)"}
            punches.append(record)
        return _jsonable({
            "format": punches_output.SOLUTION_OF_PUNCHES, "program": PROGRAM, "version": VERSION,
            "solver": answered_settings(self.punches[0]), "schema_version": SCHEMA_VERSION,
            "scene": self.scene.to_dict(),
            "units": {"times": UNITS["times"], "center": "m (global x)"},
            "times": self.times, "flags": self.flags, "info": dict(self.info),
            "punches": punches})

    def to_json(self) -> str:
        """:meth:`to_dict` as compact JSON text."""
        return json.dumps(self.to_dict(), separators=(",", ":"), allow_nan=False)

    def to_csv(self, header: bool = True) -> str:
        """The histories of every punch as CSV: ``time_day``, then ``punches[k].settlement_m``,
        ``punches[k].tilt_rad``, ``punches[k].force_N_per_m``, ``punches[k].moment_N`` for
        each punch in order (:func:`core.scene.punches_output.histories_csv`); ``header``:
        start with the ``#`` lines of :func:`core.scene.csv_header`."""
        table = punches_output.histories_csv(self)
        return csv_header(self, "histories of every punch") + table if header else table

    def pressure(self, x: Any) -> np.ndarray:
        """Contact pressure q [Pa] at points ``x`` [m] of the global x, shape (len(x),
        len(times)): each punch's q on its zone, 0 on the free surface between them."""
        return punches_output.surface_pressure(self, x)

    @property
    def x(self) -> np.ndarray:
        """The plotting points of the whole surface [m, global x]: every punch's grid about
        its centre, punches in order along x (the free surface between them left out)."""
        return punches_output.surface_x(self)

    @property
    def pressure_on_grid(self) -> np.ndarray:
        """q [Pa] at :attr:`x`, shape (len(x), len(times))."""
        return punches_output.surface_pressure_on_grid(self)

    def pressure_csv(self, x: Any = None, header: bool = True) -> str:
        """q(x, t) over the whole surface as CSV in long form: ``time_day``, ``x_m`` (the
        global x), ``pressure_Pa``; by default on :attr:`x` (rows on the contact zones
        only: q = 0 between the punches), else at the points ``x`` [m]; ``header`` as
        :meth:`to_csv`."""
        table = punches_output.pressure_csv(self, x)
        if not header:
            return table
        return csv_header(self, "contact pressure q(x, t) over the surface, x global") + table

    def plot(self, count: int | None = None, times: Sequence[float] | None = None) -> Any:
        """A ``holoviews.Layout``: q(x) over the surface at ``count`` output times (or
        those nearest to ``times`` [day]) coloured by time, settlement [mm] and tilt [mrad]
        over time with a line per punch (:func:`core.scene.plotting.plot_punches`)."""
        from core.scene.plotting import PLOT_CURVES, plot_punches

        return plot_punches(self, PLOT_CURVES if count is None else count, times)

    def to_xarray(self) -> Any:
        """The answer as an ``xarray.Dataset`` over ``punch``, ``time`` [day] and ``x`` [m,
        global] (:func:`core.scene.punches_output.to_xarray`)."""
        return punches_output.to_xarray(self)

    def design_checks(self, limits: DesignLimits | None = None) -> list[DesignCheck | None]:
        """The design check of every punch, in order, over the whole history against
        ``limits`` [Pa, m, rad] (default: the scene's ``limits``), positions in the global
        x [m]; None for each when neither gives a limit."""
        return punches_output.design_checks(self, limits)

    def __repr__(self) -> str:
        return (f"PunchesSolution({len(self.punches)} punches, {self.times.size} times, "
                f"flags={self.flags})")


def solve_punches_scene(scene: Mapping[str, Any] | PunchesScene) -> PunchesSolution:
    """Solve a scene of the ``punches`` form (validated first); see the module notes."""
    from core.scene.pipeline import solve

    started = time.thread_time()
    scene = punches_from_dict(scene)
    # a load no contact can carry is refused in every contact mode, as for one punch
    check_loads_touch(scene)
    if len(scene.scenes) == 1:
        try:
            single = solve(scene.scenes[0])
        except ValueError as exc:
            raise ValueError(_renamed(str(exc), 0)) from None
        solution = single.dimensionless
        punches = [PunchSolution(scene.scenes[0], scene.centers[0], solution)]
    else:
        geometries, inputs = [], []
        # the engine sees each punch in its own coordinates and the others by their
        # distances: centres taken from the first punch's, so that the distances are not
        # differences of large numbers (centres at 1e9 m moved the tilts by 8e-9, over
        # an estimate of 2.5e-9)
        origin = scene.centers[0]
        for sub, center in zip(scene.scenes, scene.centers, strict=True):
            problem = sub.dimensionless
            geometries.append(PunchGeometry(
                validate_geometry(problem.lam, problem.m, problem.g, problem.breakpoints,
                                  problem.tol),
                (center - origin) / sub.base_thickness))
            inputs.append(validate_time_inputs(problem.times, problem.c, problem.kernel,
                                               {q: problem.loads.get(q) for q in
                                                ("settlement", "tilt", "force", "moment")}))
        first = scene.scenes[0]
        with np.errstate(all="ignore"), _in_scene_terms(scene):
            if first.contact == "unilateral":
                answers = _lift_off(scene, geometries, inputs)
            else:
                answers = solve_punches(geometries, inputs, _time_breaks(scene))
                for answer in answers:
                    answer.info["contact"] = "full"
                lost = [k for k, a in enumerate(answers) if "contact_lost" in a.info["flags"]]
                if lost and first.contact == "auto":
                    full = answers
                    answers = _lift_off(scene, geometries, inputs)
                    for answer, before in zip(answers, full, strict=True):
                        # what the full-contact model said, as for one punch
                        answer.info["full_contact"] = {
                            "flags": list(before.info["flags"]),
                            "min_pressure": before.info.get("min_pressure"),
                            "seconds": before.info.get("seconds")}
        punches = [PunchSolution(sub, center, answer) for sub, center, answer
                   in zip(scene.scenes, scene.centers, answers, strict=True)]
        for p in punches:
            p.info["coating_model"] = THIN_LAYER
    result = PunchesSolution(scene, punches)
    result.info["cpu_seconds"] = time.thread_time() - started
    return result


def _rebuilt(scene: PunchesScene) -> tuple[Any, tuple[dict[str, Any]]]:
    """How a :class:`PunchesScene` is copied and pickled: rebuilt from its canonical dict
    (as a single punch's scene, ``core.scene.validate``)."""
    return punches_from_dict, (scene.to_dict(),)


copyreg.pickle(PunchesScene, _rebuilt)
