"""The pins of a session: pin, remove one, clear, pin every step, and pins from a link."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import panel as pn

from ..controller import SolveController, format_error
from ..pins import PinBoard
from ..state import ExplorerState

if TYPE_CHECKING:
    from ..app import ExplorerApp
    from ..results import ResultView


class PinsView:
    """Results kept on the plots for comparison, each named after what differs."""

    def __init__(self, app: ExplorerApp) -> None:
        self.app = app
        self.board = PinBoard()
        self.pin_button = pn.widgets.Button(label="Pin this result", color="default",
                                            css_classes=["pin-button"])
        self.unpin_button = pn.widgets.Button(label="Clear pins", color="light",
                                              disabled=True, css_classes=["unpin-button"])
        # each new result is pinned as it arrives (the oldest pin goes when there are
        # six): a class moves a slider step by step, and the steps stay on the plots
        self.every_step = pn.widgets.Checkbox(label="pin every step",
                                              css_classes=["pin-every-step"])
        self.pin_button.on_click(lambda e: self.pin())
        self.unpin_button.on_click(lambda e: self.unpin())
        self.pin_list = pn.Column(margin=0, css_classes=["pin-list"])
        # pins of a link, solved off the page's thread: slot -> result (None: refused)
        self._pending: dict[int, ResultView | None] = {}
        self._expected = 0
        self._controllers: list[SolveController] = []

    def content(self) -> pn.Column:
        """The pin buttons and the list of pins (next to the readout)."""
        return pn.Column(self.pin_button, self.every_step, self.unpin_button, self.pin_list,
                         margin=0)

    # -- actions ---------------------------------------------------------------------
    def pin(self) -> None:
        """Keep the result on screen for comparison with the next ones."""
        view = self.app.shown()
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
        if self.every_step.value:
            self.board.add(view)
            self._show_list()

    # -- pins of a link ----------------------------------------------------------------
    def solve_from_link(self, scenes: list[dict[str, Any]]) -> None:
        """Solve the pinned scenes of a link (off the page's thread), then pin them in
        the link's order."""
        from core import scene_from_dict

        self._expected = len(scenes)
        for slot, scene in enumerate(scenes):
            state = ExplorerState()
            try:
                scene_from_dict(scene)
                state.load_scene(scene)
            except ValueError as exc:
                self.app.notice = (f"A pinned result in the link was not used: "
                                   f"{format_error(str(exc))}")
                self._arrived(slot, None)
                continue
            controller = SolveController(state, executor=self.app.controller.executor,
                                         dispatch=self.app._dispatch, auto=False)
            controller.param.watch(lambda e, slot=slot: self._arrived(slot, e.new), "view")
            controller.param.watch(lambda e, slot=slot: e.new and self._arrived(slot, None),
                                   "error")
            self._controllers.append(controller)
            controller.request()

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
        """Draw the pins on the figures, the readout and the list; update the link."""
        app = self.app
        self._show_list()
        view = app.shown()
        if view is not None:
            with pn.io.hold():
                app.figures.show_pinned(view, self.board.pins, app.time_index)
                if app.results.time_axis.on:
                    app.results.time_axis.fit()
                app.results.show_time_texts(view, app.time_index)
            app.results.push()
        app.link.schedule()

    def _show_list(self) -> None:
        """One remove button per pin, coloured and named as in the legend."""
        from ..pin_plots import PIN_COLORS

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
