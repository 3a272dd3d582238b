"""Step-by-step lessons built from the presets, for a class in front of a projector.

A lesson is a preset and a sequence of steps; each step sets a few fields of the scene
(dotted paths of the scene dict, SI units, as the scene files write them) and shows a
short note. The steps add up: step k is the preset with the changes of steps 1..k. The
numbers in the notes are the solver's, checked by ``tests/explorer/test_explorer_lessons.py``
(rounded as written). No Panel import.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any

from .presets import presets


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
    class moves on, so the legend reads the steps."""

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
)


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
    if isinstance(node, list):
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
    scene["name"] = f"{lesson.title}, step {index + 1} of {len(lesson.steps)}"
    scene["description"] = lesson.steps[index].note
    return scene
