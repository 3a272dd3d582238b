"""Step-by-step lessons built from the presets, for a class in front of a projector.

A lesson is a preset and a sequence of steps; each step sets a few fields of the scene
(dotted paths of the scene dict, SI units, as the scene files write them) and shows a
short note. The steps add up: step k is the preset with the changes of steps 1..k. The
numbers in the notes are the solver's, checked by ``tests/explorer/test_explorer_lessons.py``
(rounded as written). No Panel import.
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass, field
from typing import Any

from .presets import presets
from .state import MODIFIED


@dataclass(frozen=True)
class Step:
    """One step of a lesson: the fields it sets and what the class should see."""

    note: str
    changes: dict[str, Any] = field(default_factory=dict)
    #: draw the histories on a log time axis (True), a linear one (False), or leave it
    log_time: bool | None = None


@dataclass(frozen=True)
class Lesson:
    """A preset and its steps; ``pin_steps``: each step's result stays pinned when the
    class moves on, so the legend reads the steps (not for several punches: pins
    compare results of one punch)."""

    key: str
    title: str
    preset: str
    steps: tuple[Step, ...]
    pin_steps: bool = True


LESSONS: tuple[Lesson, ...] = (
    Lesson(
        key="load_and_tilt",
        title="Force, eccentricity and tilt",
        preset="uniform_flat",
        steps=(
            Step("A centred force of 500 kN/m on a 2 m wide flat punch. It settles "
                 "0.024 mm at loading and 0.041 mm after a year, as the slab creeps, and "
                 "does not tilt. The pressure is lowest at the centre and highest at the "
                 "edges."),
            Step("Double the force to 1000 kN/m: the settlement doubles (0.049 mm at "
                 "loading, 0.082 mm after a year) and so does the pressure everywhere: "
                 "coating and slab are linear.",
                 {"loading.force": 1.0e6}),
            Step("Move the force 0.2 m to the right (M = 200 kN·m/m, e = M/P = 0.2 m): "
                 "the punch tilts toward it, 0.015 mrad at loading and 0.023 mrad after a "
                 "year, while the centre still settles 0.082 mm. The pressure rises under "
                 "the right edge and falls under the left.",
                 {"loading.moment": 2.0e5}),
            Step("At e = 0.3 m the tilt is 1.5 times larger (0.035 mrad after a year) and "
                 "the left edge carries less still. At about e = 0.4 m its pressure "
                 "reaches zero at loading: further out the left edge lifts off.",
                 {"loading.moment": 3.0e5}),
        ),
    ),
    Lesson(
        key="creep",
        title="Creep of young concrete",
        preset="eccentric_creep",
        steps=(
            Step("800 kN/m at e = 0.15 m on concrete loaded at 28 days. The settlement "
                 "grows from 0.059 mm at loading to 0.087 mm at 1000 days (x1.47). On the "
                 "log time axis: nearly all of it in the first 90 days (x1.44), and no "
                 "more after about 250 days.",
                 log_time=True),
            Step("Load the same slab a year later (age at loading 365 days): the older "
                 "concrete is stiffer, 0.049 mm at loading, and creeps less: the "
                 "settlement grows by 22 % instead of 47 %.",
                 {"base.age_at_loading": 365.0}),
            Step("Without creep (an elastic slab with the concrete's final modulus, "
                 "30 GPa) the settlement stays 0.049 mm: creep alone made it grow.",
                 {"base.creep": {"model": "elastic", "modulus": 3.0e10}}),
        ),
    ),
    Lesson(
        key="coating_edges",
        title="What a coating does to the edge pressure",
        preset="bare_layer",
        steps=(
            Step("A flat punch, 2 m wide, presses a bare 1 m concrete slab with 500 kN/m "
                 "(0.25 MPa on average). The pressure is lowest in the middle, 0.20 MPa, "
                 "and rises without bound toward the edges: 0.31 MPa 10 cm from an edge, "
                 "0.86 MPa 1 cm from it, infinite at the edge itself. The punch settles "
                 "0.0068 mm."),
            Step("Put a 20 mm polymer coating (800 MPa) under the punch: 1 cm from the "
                 "edge the pressure falls from 0.86 to 0.34 MPa, and the middle carries "
                 "more, 0.23 MPa. The soft coating is squeezed: the settlement nearly "
                 "doubles, 0.0127 mm.",
                 {"coating.0": {"thickness": 0.02, "modulus": 8.0e8, "poisson": 0.3}}),
            Step("A thicker, softer coating (50 mm, 200 MPa) spreads the load almost "
                 "evenly, 0.24 to 0.25 MPa from the middle to 25 mm from the edges: it "
                 "acts almost like a bed of springs. (At the rigid corner itself the "
                 "pressure on this elastic base still grows without bound, in a band "
                 "thinner than the coating; across that band the plot holds the value "
                 "25 mm from the corner, as the design check below the plots says.) The "
                 "settlement is now 0.064 mm, mostly the coating's.",
                 {"coating.0.thickness": 0.05, "coating.0.modulus": 2.0e8}),
        ),
    ),
    Lesson(
        key="neighbour_footing",
        title="A new footing beside an old one",
        preset="new_footing_beside_old",
        steps=(
            Step("Punch 1, the old footing, carries 600 kN/m from the start, on concrete 7 days "
                 "old: it settles 0.026 mm at once and 0.065 mm by one year. Then punch 2, its "
                 "centre 3 m to the right (a gap of 1 m), is loaded from its own weight (100 kN/m)"
                 " to 600 kN/m: the old footing goes down to 0.067 mm at once and to 0.085 mm at "
                 "50 years. It tilts toward the new one (its right side goes down): 0.0012 mrad "
                 "before, 0.0031 mrad just after and 0.0058 mrad at 50 years, its right edge 12 µm"
                 " below its left. Why: the new load sinks the layer most under itself. Were the "
                 "old footing to stay level, its right edge would lose support and its left carry "
                 "more, off its centre; no moment holds it level, so it turns toward the neighbour"
                 " until its pressure is centred again. The new footing, likewise, tilts toward "
                 "the old one.",
                 log_time=True),
            Step("The same, but the new footing is never loaded beyond its own weight: "
                 "the old one settles 0.080 mm at 50 years and tilts 0.0015 mrad. So the "
                 "new load added 0.0022 mm at once and 0.0050 mm (6 %) by 50 years: the "
                 "creeping concrete more than doubles what the neighbour adds.",
                 {"punches.1.loading.force": 1.0e5}),
            Step("Load the new footing again, but 3 m farther (centre x = 6 m, a gap of "
                 "4 m, the layer's thickness): the old footing settles 0.078 mm at 50 "
                 "years, as it would alone (0.079 mm), and tilts 15 times less, 0.0004 "
                 "mrad. A 4 m layer on rock spreads a load over about its own thickness: "
                 "farther apart, footings hardly feel each other.",
                 {"punches.1.center": 6.0,
                  "punches.1.loading.force": {"kind": "step", "values": [1.0e5, 6.0e5],
                                              "breaks": [365.25]}}),
        ),
        pin_steps=False,
    ),
)


#: The end of a lesson step's scene name, after the lesson's title (:func:`step_scene`).
STEP_SUFFIX = ", step {k} of {n}"
#: :data:`STEP_SUFFIX` as it ends a name.
STEP_END = re.compile(r", step \d+ of \d+$")


def lesson_title(name: str) -> str | None:
    """The lesson's title of a step's scene name (changed on screen or not: " (modified)"
    left out), None for any other name."""
    step = STEP_END.search(name.removesuffix(MODIFIED))
    return None if step is None else name[: step.start()]


def lessons() -> dict[str, Lesson]:
    """Lesson key -> lesson, in display order (those whose preset exists)."""
    available = presets()
    return {lesson.key: lesson for lesson in LESSONS if lesson.preset in available}


def _set(scene: dict[str, Any], path: str, value: Any) -> None:
    keys = path.split(".")
    node: Any = scene
    for key in keys[:-1]:
        node = node[int(key)] if isinstance(node, list) else node[key]
    last = keys[-1]
    if isinstance(node, list) and int(last) == len(node):
        node.append(copy.deepcopy(value))  # "coating.0" on a bare scene adds its layer
    elif isinstance(node, list):
        node[int(last)] = copy.deepcopy(value)
    else:
        node[last] = copy.deepcopy(value)


def step_scene(lesson: Lesson, index: int) -> dict[str, Any]:
    """The scene of step ``index`` (0 = first): the preset with steps 1..index applied."""
    if not 0 <= index < len(lesson.steps):
        raise ValueError(f"lesson {lesson.key!r}: step {index + 1} does not exist "
                         f"(it has {len(lesson.steps)})")
    scene = presets()[lesson.preset]
    for step in lesson.steps[: index + 1]:
        for path, value in step.changes.items():
            _set(scene, path, value)
    scene["name"] = f"{lesson.title}{STEP_SUFFIX.format(k=index + 1, n=len(lesson.steps))}"
    scene["description"] = lesson.steps[index].note
    return scene
