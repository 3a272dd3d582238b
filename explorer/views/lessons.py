"""The Lessons tab: a preset taken step by step, a short note at each step."""

from __future__ import annotations

import html
from collections.abc import Callable
from typing import Any

import panel as pn

from ..model import MODIFIED, Lesson, lessons, step_scene
from .pins import PinsView
from .style import TAB_COLUMN, html_pane
from .widgets import LabelledCheckbox, PromptSelect

#: What the Lessons tab says while the scene on screen is a step changed on the page.
CHANGED_NOTE = ("<div class='cp-msg' style='font-size:13px'>You changed the scene of this "
                "step: the note below speaks of the step as the lesson gives it. "
                "<i>next</i> pins what is on screen and shows the next step as the lesson "
                "gives it; <i>previous</i> or choosing the lesson again brings its steps "
                "back.</div>")


#: A disabled "next" (before a lesson is chosen, at its last step) drawn grey: in the
#: theme's primary colour, only lighter, it read as a button to press (a teacher's audit).
DISABLED_GREY = (".bk-btn.bk-btn-primary:disabled {background-color: #d5d8dc !important; "
                 "border-color: #d5d8dc !important; color: #4b5563 !important; opacity: 1;}")


class LessonsView:
    """Choose a lesson, then go through its steps with next and previous."""

    title = "Lessons"

    def __init__(self, pins: PinsView, log_time: LabelledCheckbox,
                 load_scene: Callable[[dict[str, Any], bool], bool]) -> None:
        """``pins``: a step left stays pinned; ``log_time``: the histories' log time
        axis, which a step may switch; ``load_scene(scene, first)``: shows a step's scene
        (``first``: the lesson's start, where the display's scales start again)."""
        self.pins = pins
        self.log_time = log_time
        self.load_scene = load_scene
        self.lessons = lessons()
        self.lesson: Lesson | None = None
        self.step = 0
        options = {"(choose a lesson)": ""} | {v.title: k for k, v in self.lessons.items()}
        self.lesson_select = PromptSelect(label="lesson", options=options, value="",
                                          sizing_mode="stretch_width",
                                          css_classes=["lesson-select"])
        self.lesson_select.param.watch(lambda e: self.start(e.new), "value")
        self.previous_button = pn.widgets.Button(label="◀ previous", disabled=True,
                                                 css_classes=["lesson-previous"])
        self.next_button = pn.widgets.Button(label="next ▶", disabled=True,
                                             color="primary",
                                             css_classes=["lesson-next"],
                                             stylesheets=[DISABLED_GREY])
        self.previous_button.on_click(lambda e: self.go(self.step - 1))
        self.next_button.on_click(lambda e: self.go(self.step + 1))
        self.lesson_note = html_pane("<small>A lesson loads a preset and changes a few "
                                     "values at each step; each step stays pinned for "
                                     "comparison.</small>", sizing_mode="stretch_width",
                                     css_classes=["lesson-note"])

        # said while the scene on screen is no longer the step's (a teacher's edit)
        self.changed_note = html_pane(CHANGED_NOTE, sizing_mode="stretch_width",
                                      visible=False, css_classes=["lesson-changed"])

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(self.lesson_select,
                         pn.Row(self.previous_button, self.next_button),
                         self.changed_note, self.lesson_note, **TAB_COLUMN)

    def follow(self, scene_name: str) -> None:
        """The scene on screen is now named ``scene_name``: while a lesson runs and the
        scene is its step changed on the page (``(modified)``), the tab says that the
        note speaks of the step as the lesson gives it and what next does (a teacher set
        700 kN/m at the step of 1000: the note's numbers no longer matched, next pinned
        the 700 and the next step went back to 1000, unsaid)."""
        changed = self.lesson is not None and scene_name.endswith(MODIFIED)
        if self.changed_note.visible != changed:
            self.changed_note.visible = changed

    def start(self, key: str) -> None:
        """Begin the lesson ``key`` at its first step (clears the pins)."""
        self.lesson = self.lessons.get(key)
        if self.lesson is None:
            self.previous_button.disabled = self.next_button.disabled = True
            return
        self.pins.unpin()
        self.go(0, pin=False, first=True)

    def go(self, index: int, pin: bool = True, first: bool = False) -> None:
        """Show step ``index`` (0 = first); the step left stays pinned going forward;
        ``first``: the lesson starts."""
        lesson = self.lesson
        if lesson is None or not 0 <= index < len(lesson.steps):
            return
        if pin and lesson.pin_steps and index > self.step:
            self.pins.pin()
        step = lesson.steps[index]
        self.step = index
        if step.log_time is not None:
            self.log_time.value = step.log_time
        self.load_scene(step_scene(lesson, index), first)
        self.previous_button.disabled = index == 0
        self.next_button.disabled = index == len(lesson.steps) - 1
        self.lesson_note.object = (
            f"<div class='cp-lesson'><b>Step {index + 1} of {len(lesson.steps)}</b>"
            f"<p style='font-size:15px;line-height:1.35'>{html.escape(step.note)}</p></div>")
