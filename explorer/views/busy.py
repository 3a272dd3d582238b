"""The busy indicator: shown only for a solve that takes long enough to be noticed."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import param

from ..solving import SolveController
from .loop import PageLoop
from .status import status_html
from .style import html_pane

#: A solve shows the busy indicator only once it has run this long [ms]. A slider step
#: is solved in 10-50 ms: its new plots are the feedback, and switching the indicator on
#: and off costs three more messages to the page per step (a sixth of the server's work
#: with 20 busy sessions, measured with py-spy).
BUSY_AFTER_MS = 250


#: A spinning ring drawn by CSS alone (inside the pane's own shadow root).
_RING = ("<style>@keyframes cp-spin {to {transform: rotate(360deg)}}</style>"
         "<div class='cp-spinner' style='width:14px;height:14px;margin:3px;"
         "border:3px solid #ddd;border-top-color:#1f77b4;border-radius:50%;"
         "animation:cp-spin 0.8s linear infinite'></div>")


class BusySpinner(param.Parameterized):
    """A spinner that turns by changing its text only.

    Panel's LoadingSpinner turns by changing its CSS classes, and a change of classes
    makes the page lay out every figure again: measured in Chromium, two whole-page
    layouts per slow solve (on and off), most of the page's work for a geometry step."""

    value = param.Boolean(default=False, doc="Whether the spinner turns.")

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        # a fixed size: a new text never changes the layout around it
        self.pane = html_pane("", width=26, height=26, margin=(5, 5),
                              css_classes=["busy-spinner"])
        self.param.watch(lambda e: setattr(self.pane, "object", _RING if e.new else ""),
                         "value")

    def __panel__(self) -> Any:
        return self.pane


class BusyIndicator:
    """Follows the controller's ``busy`` for the page's spinner and status line."""

    def __init__(self, controller: SolveController, loop: PageLoop, spinner: BusySpinner,
                 status: Any, evidence: Callable[[Any], Any] | None = None,
                 on_screen: Callable[[], tuple[Any, bool]] | None = None) -> None:
        """``status``: the pane of the status line (it says when a solve is running);
        ``evidence``: the coating model's error to state for a result
        (:meth:`explorer.views.ResultsView.evidence`), none by default; ``on_screen``:
        the result the plots show and whether it is a preview of a dragged value (default:
        the controller's result), which the status line describes."""
        self.controller = controller
        self.evidence = evidence if evidence is not None else (lambda view: None)
        self.on_screen = on_screen if on_screen is not None else (
            lambda: (controller.view, False))
        self.loop = loop
        self.spinner = spinner
        self.status = status
        self.shown = False
        self._due = False

    def follow(self, busy: bool) -> None:
        """The controller started (``busy``) or finished a solve."""
        if not busy:
            self.show(False)
        elif not self.loop.served:  # no event loop to wait on: show it at once
            self.show(True)
        elif not (self.shown or self._due):
            self._due = True
            self.loop.later(self._timeout, BUSY_AFTER_MS)

    def _timeout(self) -> None:
        self._due = False
        if self.controller.busy:
            self.show(True)

    def show(self, busy: bool) -> None:
        """Show or hide the spinner and say so in the status line."""
        if busy == self.shown:
            return
        self.shown = busy
        self.spinner.value = busy
        # (a preview stays on screen while the release's answer solves: the line speaks
        # of the preview, not of the answer kept behind it)
        view, preview = self.on_screen()
        self.status.object = status_html(view, busy, self.evidence(view), preview)
