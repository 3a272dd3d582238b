"""The eccentricity slider: where the force acts, e = M/P [m], for a footing's lesson.

Moving the force off the centre is how a design engineer meets lift-off: the slider sets
the moment M = e P of a constant force P (statement "force + moment given") and shows
the e of the scene on screen whatever set it (a preset, a file, the moment's own slider).
When solves are too slow to follow the handle, a note under the slider says so while it
is dragged, with the e the plots still show, until the release sets the new one; where the
base creeps, the page previews each e meanwhile (the base elastic at loading, see
:mod:`explorer.app`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import panel as pn

from ..model import ExplorerState, eccentricity
from ..solving import SolveController
from .style import NOTE_STYLE, html_pane
from .widgets import _set_widget, next_tick, slider, unusable_number, watch_release

#: Drag steps of the slider are applied at once while the last solve took less than this
#: [s] of CPU time; slower, the moment is set on release. The speed goal of a lift-off
#: scene under creep (100 output times in 200 ms) is what keeps this slider
#: live; the solver keeps one pending request, so a step taking longer than a frame is
#: not lost. CPU, not wall time: on the shared 2-core machine at load 4-8, moment steps
#: of the eccentric-footing lesson took 115-150 ms CPU but 150-310 ms wall, so on wall
#: time the slider went live and dead from one step to the next.
LIVE_SOLVE_S = 0.2

#: The slider spans this share of the half-width either way: at |e| = a no contact can
#: carry the load (the solver refuses it); near it the zone is a sliver. A value beyond
#: can still be typed into the box.
SLIDER_SPAN = 0.9

#: When the slider cannot set the moment, and why.
NOT_APPLICABLE = ("The eccentricity sets the moment when force and moment are given and "
                  "the force is a constant above zero.")
#: What the greyed slider's note says while the force is not above zero.
UNDEFINED = "e = M/P is undefined while the force P is not above zero."


def lag_text(dragged: float, shown: float | None, cpu_seconds: float | None,
             previewed: float | None = None) -> str:
    """What the page says while the handle is at ``dragged`` [m] and the plots still show
    the result solved at e = ``shown`` [m] (None: not known), solved in ``cpu_seconds``
    [s] of CPU time (None: not known), or a preview at e = ``previewed`` [m] (the base
    elastic at loading; None: no preview on screen)."""
    took = ("" if cpu_seconds is None
            else f" (the last one took {1e3 * cpu_seconds:.0f} ms)")
    if previewed is not None:
        return (f"Solves with creep are too slow to follow the handle{took}: the plots "
                f"preview e = {previewed:.3f} m on the base as it answers at loading "
                f"(without creep), and show the answer with creep at e = {dragged:.3f} m "
                "when you release it.")
    showing = ("the previous result" if shown is None
               else f"the result at e = {shown:.3f} m")
    return (f"Solves are too slow to follow the handle{took}: the plots show {showing} "
            f"and update to e = {dragged:.3f} m when you release it.")


class EccentricityControl:
    """A slider of e = M/P [m] bound to the loading of the session's state."""

    def __init__(self, state: ExplorerState, controller: SolveController,
                 reject: Callable[[str], None], drag: Any = None) -> None:
        """``controller``: its last solve's time decides whether drag steps apply;
        ``reject``: says why a value was refused; ``drag``: where a held step's moment
        goes (``drag.held(history, "value", M)``), the release
        (``drag.released(dragged)``) and, where it has them, the steps and the end of
        the drag's one step of undo (``drag.gesture_step()``, ``drag.gesture_ended()``),
        as for the other sliders (:class:`~.widgets.Binding`); None: nowhere."""
        self.state = state
        self.drag = drag
        self.controller = controller
        self.reject = reject
        self.slider = slider("eccentricity e = M/P [m] (sets the moment)", -1.0, 1.0, 0.01,
                             css_classes=["eccentricity-slider"])
        self.note = html_pane("", styles=NOTE_STYLE, visible=False)
        # said while a drag step waits for the release (the plots lag behind the box)
        self.lag = html_pane("", styles=NOTE_STYLE, visible=False,
                             css_classes=["eccentricity-lag"])
        self._syncing = False
        self.slider.param.watch(self._on_drag, "value")
        watch_release(self.slider, self._on_release, lambda: self._syncing)
        loading = state.loading
        for q in ("force", "moment"):
            loading.histories[q].param.watch(self.refresh, ["kind", "value"])
        loading.param.watch(self.refresh, "statement")
        state.punch.param.watch(self.refresh, "half_width")
        # a result arriving mid-drag changes what the plots show: the note follows it
        controller.param.watch(self._on_result, ["view", "preview"])
        self.panel = pn.Column(self.slider, self.lag, self.note, sizing_mode="stretch_width",
                               margin=0)
        self.refresh()

    def applicable(self) -> bool:
        """Whether the slider can set the moment (constant force P > 0 and M given)."""
        loading = self.state.loading
        force = loading.histories["force"]
        return (loading.given == ("force", "moment") and force.kind == "constant"
                and force.value > 0)

    def eccentricity(self) -> float | None:
        """e = M/P [m] of the state (the moment's main level), None when not defined."""
        if not self.applicable():
            return None
        loading = self.state.loading
        return loading.histories["moment"].value / loading.histories["force"].value

    def refresh(self, *events: Any) -> None:
        """Follow the state: the range (the half-width), the value, enabled or not."""
        a = self.state.punch.half_width
        self.slider.param.update(start=-SLIDER_SPAN * a, end=SLIDER_SPAN * a)
        e = self.eccentricity()
        loading = self.state.loading
        force = loading.histories["force"]
        # a force typed <= 0 (refused at the solve) leaves e undefined for a moment: the
        # slider stays in its place, greyed, so the boxes below do not move up under the
        # next click (the moment box took a value meant for the force)
        undefined = (e is None and loading.given == ("force", "moment")
                     and force.kind == "constant")
        # not applicable: the note says why, without a dead slider taking the room
        self.slider.disabled = e is None
        self.slider.visible = e is not None or undefined
        self.note.object = "" if e is not None else (UNDEFINED if undefined
                                                     else NOT_APPLICABLE)
        self.note.visible = e is None
        if e is None:
            self.say_lag(None)
        # the value the slider already shows is left alone: a round trip through M = e P
        # differs in the last digit, and resending it would jerk the handle mid-drag
        if e is not None and abs(e - (self.slider.value or 0.0)) > 1e-9 * max(a, 1.0):
            self._syncing = True
            try:
                _set_widget(self.slider, e)
            finally:
                self._syncing = False

    def _on_drag(self, event: Any) -> None:
        if self._syncing:
            return
        if self.drag is not None:
            self.drag.dragging()  # its results are spaced out, as every drag's
            step = getattr(self.drag, "gesture_step", None)
            if step is not None and event.new is not None:
                # the moves up to the release are one step of undo, however far apart
                # in time the page or the server spaced them (as every slider's)
                step()
        if self.controller.solved_within(LIVE_SOLVE_S) or unusable_number(event.new):
            # (an emptied box or a number not finite is refused at once, not held)
            self.say_lag(None)
            self.apply(event.new)
            return
        self.say_lag(event.new)
        moment = self.state.loading.histories["moment"]
        if (self.drag is not None and event.new is not None and self.applicable()
                and moment.kind == "constant"):
            self.drag.held(moment, "value", self._moment_for(float(event.new)))

    def _on_release(self, event: Any, dragged: bool) -> None:
        self.say_lag(None)
        self.apply(event.new)
        if self.drag is not None:
            self.drag.released(dragged)
            ended = getattr(self.drag, "gesture_ended", None)
            if ended is not None:
                ended()  # the drag's one step of undo ends with the released value

    def _on_result(self, event: Any) -> None:
        if self.lag.visible:
            self.say_lag(self.slider.value)

    def solved_eccentricity(self) -> float | None:
        """e = M/P [m] of the result on screen (the last one solved), None when it has
        no constant force above zero or before the first result."""
        view = self.controller.view
        return None if view is None else eccentricity(view.scene)

    def say_lag(self, dragged: float | None) -> None:
        """Say that the plots lag behind the handle at ``dragged`` [m] (None: they do
        not: the note goes). A handle back at the e on screen needs no release."""
        shown = self.solved_eccentricity()
        a = self.state.punch.half_width
        if (dragged is None or not self.applicable()
                or (shown is not None and abs(dragged - shown) <= 1e-9 * max(a, 1.0))):
            self.lag.object, self.lag.visible = "", False
            return
        view = self.controller.view
        spent = None if view is None else view.info.get("cpu_seconds",
                                                        view.info.get("seconds"))
        preview = self.controller.preview
        self.lag.object = lag_text(float(dragged), shown,
                                   float(spent) if isinstance(spent, (int, float)) else None,
                                   None if preview is None else eccentricity(preview.scene))
        self.lag.visible = True

    def apply(self, e: float | None) -> None:
        """Set the moment M = e P [kN·m/m] (constant) for the eccentricity ``e`` [m]."""
        if self._syncing:
            return
        reason = unusable_number(e)
        if reason is not None:
            # the box emptied, or a number not finite: said, and the box shows the
            # eccentricity kept (it stayed blank, nothing said: an audit), as every other
            # box does
            kept = self.eccentricity()
            if kept is not None:
                self.reject(f"{self.slider.name}: {reason}; it stays {kept:g}")
                next_tick(self.refresh)
            return
        if not self.applicable():
            self.reject(NOT_APPLICABLE)
            return
        moment = self.state.loading.histories["moment"]
        value = self._moment_for(float(e))
        if moment.kind != "constant" or moment.value != value:
            moment.param.update(kind="constant", value=value)

    def _moment_for(self, e: float) -> float:
        """M = e P [kN·m/m] for the eccentricity ``e`` [m]; an ``e`` within round-off of the
        state's own (the handle back where it was) gives the state's moment itself: e P
        after e = M / P can differ from M in the last digit, and that step back read as a
        new value (a preview kept on screen after a release that changed nothing)."""
        loading = self.state.loading
        moment, force = loading.histories["moment"], loading.histories["force"].value
        current = self.eccentricity()
        if (current is not None and moment.kind == "constant"
                and abs(e - current) <= 1e-9 * max(self.state.punch.half_width, 1.0)):
            return float(moment.value)
        return e * force
