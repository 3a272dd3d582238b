"""The teacher's lists, read from the files the explorer reads: no copy to go stale.

- ``.. preset-list::``: the explorer's preset scenes (``core/presets/scenes/``) in its order,
  each with its key (for ``/app?preset=KEY``), name and description;
- ``.. lesson-list::``: the explorer's lessons, step by step, with the notes the class
  sees (their numbers are the solver's, checked by the tests).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "core" / "presets" / "scenes"


class PresetList(SphinxDirective):
    has_content = False

    def run(self) -> list[nodes.Node]:
        from explorer.model import presets

        for path in SCENES.glob("*.json"):
            self.env.note_dependency(str(path))
        items = nodes.definition_list()
        for key, scene in presets().items():
            term = nodes.term()
            term += nodes.strong(text=scene.get("name", key))
            term += nodes.Text(" (")
            term += nodes.literal(text=key)
            term += nodes.Text(")")
            definition = nodes.definition()
            definition += nodes.paragraph(text=scene.get("description", ""))
            items += nodes.definition_list_item("", term, definition)
        return [items]


class LessonList(SphinxDirective):
    has_content = False

    def run(self) -> list[nodes.Node]:
        from explorer.model import lessons

        self.env.note_dependency(str(ROOT / "explorer" / "model" / "lessons.py"))
        out: list[nodes.Node] = []
        for lesson in lessons().values():
            head = nodes.paragraph()
            head += nodes.strong(text=lesson.title)
            head += nodes.Text(" (preset ")
            head += nodes.literal(text=lesson.preset)
            head += nodes.Text(f", {len(lesson.steps)} steps)")
            steps = nodes.enumerated_list(enumtype="arabic")
            for step in lesson.steps:
                steps += nodes.list_item("", nodes.paragraph(text=step.note))
            out += [head, steps]
        return out


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("preset-list", PresetList)
    app.add_directive("lesson-list", LessonList)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
