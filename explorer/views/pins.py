"""The pins of a session: pin, remove one, clear, pin every step, pin the steps of a load
over a range, and pins from a link."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import panel as pn

from core import scene_from_dict

from ..model import MAX_PINS, QUANTITY_UNITS, ExplorerState, PinBoard, ResultView, Screen
from ..plots import PIN_COLORS
from ..solving import SolveController, format_error
from .loop import PageLoop
from .style import html_pane
from .widgets import NAMES, TIGHT_NUMBER_BOX, CountBox, NumberBox, PromptCheckbox

#: How the notices of "Pin the steps" begin: steps refused as asked, a step refused by
#: the solver (both cleared once steps are pinned as asked).
STEPS_REFUSED = "Steps not pinned"
STEP_REFUSED = "A step was not pinned"


class PinsView:
    """Results kept on the plots for comparison, each named after what differs."""

    def __init__(self, state: ExplorerState, screen: Screen, controller: SolveController,
                 loop: PageLoop, on_change: Callable[[], None]) -> None:
        """``screen``: the result a pin keeps, and where a refused pin is said;
        ``controller`` and ``loop``: where the pins of a link are solved; ``on_change``:
        called when the pins changed (the page draws them)."""
        self.state = state
        self.screen = screen
        self.controller = controller
        self.loop = loop
        self.on_change = on_change
        self.board = PinBoard()
        self.pin_button = pn.widgets.Button(label="Pin this result", color="default",
                                            css_classes=["pin-button"])
        self.unpin_button = pn.widgets.Button(label="Clear pins", color="light",
                                              disabled=True, css_classes=["unpin-button"])
        # each new result is pinned as it arrives (the oldest pin goes when there are
        # six): a class moves a slider step by step, and the steps stay on the plots
        self.every_step = PromptCheckbox(label="pin every step",
                                         css_classes=["pin-every-step"])
        # the result on screen is the first step: pinned when the box is ticked
        self.every_step.param.watch(lambda e: e.new and self.pin(), "value")
        self.pin_button.on_click(lambda e: self.pin())
        self.unpin_button.on_click(lambda e: self.unpin())
        self.pin_list = pn.Column(margin=0, css_classes=["pin-list"])
        # "pin 5 steps of the force from A to B": a class sees a load's effect at once
        self.steps_label = html_pane("", margin=(8, 5, 0, 5), css_classes=["pin-steps-label"])
        # three boxes in the sidebar's width: narrower arrows and padding leave their
        # digits room (0.025 and 0.075 read "0.02" and "0.07", 1500 "150")
        number = {"width": 62, "margin": (0, 3), "stylesheets": [TIGHT_NUMBER_BOX]}
        self.step_count = CountBox(label="steps", value=5, start=2, end=MAX_PINS,
                                   css_classes=["pin-steps-count"], **number)
        # empty until the first result fills them around its load (a box that starts at
        # 0 would step from 0 to 0)
        self.step_from = NumberBox(label="from", value=None, css_classes=["pin-steps-from"],
                                   **number)
        self.step_to = NumberBox(label="to", value=None, css_classes=["pin-steps-to"],
                                 **number)
        self._stepped: str | None = None  # the load the boxes were filled for
        self.steps_button = pn.widgets.Button(label="Pin the steps", color="default",
                                              css_classes=["pin-steps-button"])
        self.steps_button.on_click(lambda e: self._on_steps())
        # pins of a link, solved off the page's thread: slot -> result (None: refused)
        self._pending: dict[int, ResultView | None] = {}
        self._expected = 0
        self._controllers: list[SolveController] = []
        # pins compare results of one punch: off while the scene has several
        state.param.watch(lambda e: self._follow_punches(), "n_punches")
        self._follow_punches()

    def _follow_punches(self) -> None:
        several = self.state.n_punches > 0
        for widget in (self.pin_button, self.every_step, self.steps_button):
            widget.disabled = several
        if several and self.every_step.value:
            self.every_step.value = False

    def content(self) -> pn.Column:
        """The pin buttons and the list of pins (next to the readout)."""
        return pn.Column(self.pin_button, self.every_step, self.unpin_button, self.pin_list,
                         self.steps_label,
                         pn.Row(self.step_count, self.step_from, self.step_to, margin=0),
                         self.steps_button, margin=0)

    # -- actions ---------------------------------------------------------------------
    def pin(self) -> None:
        """Keep the result on screen for comparison with the next ones."""
        view = self.screen.shown()
        if view is not None and self.board.add(view):
            self.redraw()

    def unpin(self) -> None:
        """Drop every pinned result."""
        self.board.clear()
        self.redraw()

    def remove(self, index: int) -> None:
        """Drop the pin at ``index`` (0 = oldest)."""
        self.board.remove(index)
        self.redraw()

    def on_result(self, view: ResultView) -> None:
        """A new result arrived (before it is drawn): pin it when pinning every step."""
        before = [(id(pin.view), pin.label) for pin in self.board]
        if self.every_step.value:
            self.board.add(view)
        # (pins compare results of one punch: none is named against several)
        self.board.name_against(None if view.several else view.scene)
        # (the buttons are built again only when a pin came or was renamed: not at every
        # step of a load slider)
        if [(id(pin.view), pin.label) for pin in self.board] != before:
            self._show_list()
        self._name_steps()

    def forget_steps(self) -> None:
        """A scene was loaded: the step boxes are filled again around its load with its
        next result (they kept the last scene's range, 250 to 750 kN/m under 800)."""
        self._stepped = None

    def stepped_quantity(self) -> str:
        """The load the steps change: the first given quantity (the first load slider)."""
        return self.state.loading.given[0]

    def _name_steps(self) -> None:
        quantity = self.stepped_quantity()
        # the steps take the place of the pins kept: said before the click, not after
        text = (f"<span class='pin-steps-name'>Pin steps of {NAMES[quantity]} "
                f"[{QUANTITY_UNITS[quantity][0]}] (replaces the pins):</span>")
        if self.steps_label.object != text:
            self.steps_label.object = text
        if self._stepped != quantity or (self.step_from.value is None
                                         and self.step_to.value is None):
            # around the value on screen, to start from (again when another load is
            # stepped: the boxes held the last one's values, in its units)
            self._stepped = quantity
            value = float(self.state.loading.histories[quantity].value)
            # to 6 significant digits: 1.5 x 0.05 read "0.07500000000000001" in its box
            self.step_from.value, self.step_to.value = (
                float(f"{0.5 * value:.6g}"), float(f"{1.5 * value:.6g}")) if value \
                else (0.0, 1.0)

    def _on_steps(self) -> None:
        if self.screen.notice.startswith((STEPS_REFUSED, STEP_REFUSED)):
            self.screen.notice = ""  # the last steps' message goes with the new steps
        try:
            self.pin_steps(self.step_count.value, self.step_from.value, self.step_to.value)
        except ValueError as exc:
            self.screen.notice = f"{STEPS_REFUSED}: {exc}"

    def pin_steps(self, count: int | None, start: float | None, end: float | None) -> None:
        """Replace the pins by ``count`` results whose stepped load (see
        :meth:`stepped_quantity`, display units) goes from ``start`` to ``end`` in equal
        steps, the rest of the scene as on screen. Solved off the page's thread; the pins
        appear together. Bad input raises ValueError naming the field."""
        if count is None or not 2 <= int(count) <= MAX_PINS:
            raise ValueError(f"steps: between 2 and {MAX_PINS} (one colour each), got "
                             f"{count}")
        for field, value in (("from", start), ("to", end)):
            if value is None or not math.isfinite(float(value)):
                raise ValueError(f"{field}: a number is needed, got {value}")
        if float(start) == float(end):
            raise ValueError(f"from and to: the same value ({start}) gives one result, "
                             "not steps")
        quantity = self.stepped_quantity()
        scene = self.state.to_scene()
        scenes = []
        for value in np.linspace(float(start), float(end), int(count)):
            state = ExplorerState()
            state.load_scene(scene)
            history = state.loading.histories[quantity]
            if history.kind == "custom":
                raise ValueError(f"{NAMES[quantity]}: its history came from a file; "
                                 "choose a history form to step its level")
            history.value = float(value)
            scenes.append(state.to_scene())
        self.board.clear()
        self.solve_from_link(scenes, what=STEP_REFUSED)

    # -- pins of a link ----------------------------------------------------------------
    def solve_from_link(self, scenes: list[dict[str, Any]],
                        what: str = "A pinned result in the link was not used") -> None:
        """Solve the pinned scenes of a link (off the page's thread), then pin them in
        the link's order; a scene refused is named in a notice starting with ``what``."""
        self._expected = len(scenes)
        for slot, scene in enumerate(scenes):
            state = ExplorerState()
            try:
                scene_from_dict(scene)
                state.load_scene(scene)
            except ValueError as exc:
                self.screen.notice = f"{what}: {format_error(str(exc))}"
                self._arrived(slot, None)
                continue
            controller = SolveController(state, executor=self.controller.executor,
                                         dispatch=self.loop.dispatch, auto=False)
            controller.param.watch(lambda e, slot=slot: self._arrived(slot, e.new), "view")
            controller.param.watch(
                lambda e, slot=slot: e.new and self._refused(slot, what, e.new), "error")
            self._controllers.append(controller)
            controller.request()

    def _refused(self, slot: int, what: str, error: str) -> None:
        """A pinned scene the solver refused (a step that pulls the punch off): named in a
        notice, the others pinned."""
        self.screen.notice = f"{what} (step {slot + 1}): {format_error(str(error))}"
        self._arrived(slot, None)

    def _arrived(self, slot: int, view: ResultView | None) -> None:
        if slot in self._pending:
            return
        self._pending[slot] = view
        if len(self._pending) < self._expected:
            return
        for k in sorted(self._pending):
            if self._pending[k] is not None:
                self.board.add(self._pending[k])
        self._pending, self._controllers = {}, []
        self.redraw()

    # -- drawing -----------------------------------------------------------------------
    def redraw(self) -> None:
        """Show the list of pins, then let the page draw them."""
        self._show_list()
        self.on_change()

    def _show_list(self) -> None:
        """One remove button per pin, coloured and named as in the legend."""
        self.unpin_button.disabled = not self.board.pins
        buttons = []
        for k, pin in enumerate(self.board.pins):
            button = pn.widgets.Button(label=f"✕ {pin.label}", color="light", width=200,
                                       css_classes=["unpin-one", f"unpin-{k}"],
                                       styles={"border-left": f"6px solid {PIN_COLORS[k]}"},
                                       description="Remove this pin")
            button.on_click(lambda e, k=k: self.remove(k))
            buttons.append(button)
        self.pin_list.objects = buttons
