"""Widgets bound to the state classes, in both directions, with no feedback loops.

The state (``explorer.model.state``) is the single source of truth: a widget writes into it
(on every drag step for loads, on release for everything costly) and follows it when
it changes from Python (a preset, a file, a link). A :class:`Binding` can be re-pointed
at another object of the same class, so one set of widgets edits the selected coating
layer or whichever two loads are given.
"""

from __future__ import annotations

import contextlib
import html
import logging
import math
import numbers
from collections.abc import Callable
from typing import Any

import panel as pn
import param
from bokeh.models import CustomJSTickFormatter
from panel.io.state import set_curdoc

from core.profiles import MAX_TABLE_BYTES, VARIATIONS, profile_from_csv

from ..model import QUANTITY_RANGES, HistoryState, ProfileState
from ..solving import mark
from .upload import MAX_FILENAME_CHARS, UPLOAD_CHUNK_BYTES, BoundedUpload

log = logging.getLogger(__name__)

__all__ = ["MAX_FILENAME_CHARS", "UPLOAD_CHUNK_BYTES", "Binding", "BoundedUpload",
           "CountBox", "EditableIntSlider", "EditableSlider", "HistoryEditor",
           "LabelledCheckbox", "LazySlider", "NumberBox", "PLAYER_BUTTONS", "ProfileEditor",
           "TIGHT_NUMBER_BOX", "TimePlayer", "slider", "unusable_number", "watch_release"]


# Panel holds every change from the browser for 50 ms before handling it, to gather a
# burst into one event. The explorer gathers bursts itself (a solve runs at most once at
# a time and the newest request waits), so here the wait is only latency: measured 50 of
# the 140 ms from a load slider step to the new pressure data on the server's side.
#
# Panel also counts every browser change as a busy event of its global state
# (``pn.state.busy``: four watched parameter changes an event, two events a slider step).
# The explorer shows its own busy indicator (views/busy.py) and nothing follows Panel's,
# so the value changes of these widgets (and of the time player) are left out of that
# count: ~4 of the 50-66 ms of server CPU a load step cost (uniform_flat preset in
# Chromium, py-spy).
_NOT_BUSY = ["value", "value_throttled"]


class PromptFloatSlider(pn.widgets.FloatSlider):
    """A FloatSlider whose browser changes are handled at once (no 50 ms debounce), and
    without the tooltip over its handle: the label shows the value, and a tooltip left on
    screen after a drag (a tab switched, the slider hidden) covered the label above."""

    _debounce = 0
    _busy__ignore = _NOT_BUSY
    tooltips = param.Boolean(default=False, doc="Whether the handle shows its value.")
    #: Whether the page's release of the handle (``value_throttled``) reaches Python
    #: (:meth:`EditableSlider.apply_steps_only` turns it off for one slider).
    _releases = True

    @property
    def _linked_properties(self) -> tuple[str, ...]:
        linked = super()._linked_properties
        return linked if self._releases else tuple(p for p in linked
                                                   if p != "value_throttled")


class PromptSelect(pn.widgets.Select):
    """A Select whose choice is handled at once.

    Panel waits 50 ms for a further change of a widget's value before it takes it up
    (``_debounce``), which a choice from a list, a tick or a typed number never brings
    (the 50 ms were a tenth of a preset switch). And widgets that wait and widgets that do
    not take up their changes out of the order the page sent them: the time slider moved
    and a preset chosen at once reached the server preset first, and the slider's range
    stayed the old preset's. So every widget the user sets takes its change up at once
    (a test walks the page); a slider's superseded steps are dropped by the solving's own
    rule (one request pending per session), not by waiting."""

    _debounce = 0


class PromptRadioButtonGroup(pn.widgets.RadioButtonGroup):
    """A RadioButtonGroup whose choice is handled at once (see :class:`PromptSelect`)."""

    _debounce = 0


class PromptCheckbox(pn.widgets.Checkbox):
    """A Checkbox whose tick is handled at once (see :class:`PromptSelect`)."""

    _debounce = 0


class PromptToggle(pn.widgets.Toggle):
    """A Toggle whose press is handled at once (see :class:`PromptSelect`)."""

    _debounce = 0


class PromptCheckBoxGroup(pn.widgets.CheckBoxGroup):
    """A CheckBoxGroup whose ticks are handled at once (see :class:`PromptSelect`)."""

    _debounce = 0


class PromptTextInput(pn.widgets.TextInput):
    """A TextInput whose text is taken up at once (see :class:`PromptSelect`)."""

    _debounce = 0


class PromptTextAreaInput(pn.widgets.TextAreaInput):
    """A TextAreaInput whose text is taken up at once (see :class:`PromptSelect`)."""

    _debounce = 0


# BokehJS draws a number box's arrows as empty buttons: no accessible name. Generated
# content, clipped out of sight, names them (see _PLAYER_LABELS_CSS).
_SPIN_LABELS_CSS = "\n".join([
    ".bk-spin-btn::after { position: absolute; width: 1px; height: 1px; overflow: hidden;"
    " clip-path: inset(50%); white-space: nowrap; }",
    '.bk-spin-btn-up::after { content: "Increase"; }',
    '.bk-spin-btn-down::after { content: "Decrease"; }'])


#: A narrow number box's arrows and padding cut to leave its digits room.
TIGHT_NUMBER_BOX = ("input.bk-input { padding-left: 4px; padding-right: 16px; }\n"
                    ".bk-spin-btn { width: 14px; }")


class _OwnStyle:
    """A widget carrying the style sheet ``_own_css`` after those it is given."""

    _own_css = ""

    def __init__(self, **params: Any) -> None:
        params["stylesheets"] = [*params.get("stylesheets", []), self._own_css]
        super().__init__(**params)


class NumberBox(_OwnStyle, pn.widgets.FloatInput):
    """A FloatInput whose arrow buttons are named, its changes taken up at once (see
    :class:`PromptSelect`)."""

    _debounce = 0
    _own_css = _SPIN_LABELS_CSS


class CountBox(_OwnStyle, pn.widgets.IntInput):
    """An IntInput whose arrow buttons are named, its changes taken up at once (see
    :class:`PromptSelect`)."""

    _debounce = 0
    _own_css = _SPIN_LABELS_CSS


class PromptFloatInput(NumberBox):
    """A FloatInput whose browser changes are handled at once (a :class:`NumberBox`) and
    left out of Panel's busy count."""

    _busy__ignore = _NOT_BUSY


class PromptIntSlider(pn.widgets.IntSlider):
    """An IntSlider whose browser changes are handled at once (no 50 ms debounce), without
    the tooltip over its handle (see :class:`PromptFloatSlider`)."""

    _debounce = 0
    _busy__ignore = _NOT_BUSY
    tooltips = param.Boolean(default=False, doc="Whether the handle shows its value.")


class PromptIntInput(CountBox):
    """An IntInput whose browser changes are handled at once (a :class:`CountBox`) and
    left out of Panel's busy count."""

    _busy__ignore = _NOT_BUSY


#: What each of the time player's buttons does, by the button's class in Panel's player.
PLAYER_BUTTONS = {"slower": "Slower", "first": "First time", "previous": "Previous time",
                  "reverse": "Play backwards", "pause": "Pause", "play": "Play",
                  "next": "Next time", "last": "Last time", "faster": "Faster"}

# Panel draws the player's buttons as bare icons: no title, no accessible name. Generated
# content names a button (browsers read it into the accessible name) and shows as a small
# tooltip on hover or keyboard focus; otherwise it is clipped out of sight.
_PLAYER_LABELS_CSS = "\n".join([
    "button { position: relative; }",
    "button::after { position: absolute; left: 50%; bottom: calc(100% + 3px);"
    " transform: translateX(-50%); white-space: nowrap; pointer-events: none; z-index: 10;"
    " font-size: 11px; line-height: 1.3; color: #fff; background: #333;"
    " border-radius: 3px; width: 1px; height: 1px; overflow: hidden;"
    " clip-path: inset(50%); }",
    "button:hover::after, button:focus-visible::after { width: auto; height: auto;"
    " overflow: visible; clip-path: none; padding: 1px 5px; }",
    *(f'button.{name}::after {{ content: "{label}"; }}'
      for name, label in PLAYER_BUTTONS.items())])


class TimePlayer(_OwnStyle, pn.widgets.Player):
    """The player of the output times, left out of Panel's busy count (see above), its
    buttons named (``PLAYER_BUTTONS``)."""

    _debounce = 0  # (see PromptSelect)
    _busy__ignore = _NOT_BUSY
    _own_css = _PLAYER_LABELS_CSS


class LabelledCheckbox(pn.viewable.Viewer):
    """A checkbox whose words toggle it too and name it: Bokeh's ``Checkbox`` draws its
    words as a plain block beside the box, so only the 13 px box took a click (hard to
    hit on a projector or a touch screen) and the box had no accessible name. Drawn as
    a group of one option, whose words are the box's label."""

    value = param.Boolean(default=False, doc="Whether the box is ticked.")
    disabled = param.Boolean(default=False, doc="Whether the box takes no change.")

    def __init__(self, label: str, **params: Any) -> None:
        value, disabled = params.pop("value", False), params.pop("disabled", False)
        super().__init__(value=value, disabled=disabled)
        self._label = label
        self._group = PromptCheckBoxGroup(options=[label], value=[label] if value
                                          else [], disabled=disabled, **params)
        self._group.param.watch(lambda e: setattr(self, "value", label in e.new), "value")
        self.param.watch(lambda e: setattr(self._group, "value", [label] if e.new else []),
                         "value")
        self.param.watch(lambda e: setattr(self._group, "disabled", e.new), "disabled")

    def __panel__(self) -> pn.widgets.CheckBoxGroup:
        return self._group


#: What the page does when a number is typed in a composite slider's box beyond the
#: handle's range: Panel's own script (1.9: widen the range to it) for a finite number
#: only. An emptied box (null) or a non-finite number ("1e400" reads as Infinity) leaves
#: the range alone: noUiSlider throws on a range that is not a finite number, and the
#: throw cut short the rest of that message from the server; after "1e400" in the force
#: box the page took no preset, reset or undo any more, then showed parts of two scenes
#: (a user's audit). The value itself still goes to the server, which refuses it.
FINITE_WIDEN_JS = """
const value = cb_obj.value;
if (value != null && Number.isFinite(value)) {
  if (value < slider.start)
    slider.start = value;
  else if (value > slider.end)
    slider.end = value;
}
"""


def finite_widening(box: pn.widgets.Widget) -> bool:
    """Replace Panel's script that widens the handle's range to a value typed in ``box``
    (a composite slider's text box) by :data:`FINITE_WIDEN_JS`; False (a warning, the
    script left as it is) if Panel's script is not found."""
    from panel.links import Callback

    for callback in Callback.registry.get(box, []):
        code = callback.code
        if isinstance(code, dict) and "slider.end = cb_obj.value" in str(code.get("value")):
            callback.code = {**code, "value": FINITE_WIDEN_JS}
            return True
    log.warning("Panel's editable slider has changed; a non-finite number typed in its box "
                "may break the page")
    return False


class _RangeKept:
    """A composite slider whose handle's range comes back after a value typed outside it.

    A value typed in the box beyond the slider's range widens the handle's range in the
    page (Panel's own script, there only, for a finite number: :func:`finite_widening`):
    a time span of 1e9 days, refused, left the handle's range at 1e9, and every later
    span sat at its far left. Once a value inside the range comes back (the last good
    one, or one typed), the range is sent again; a value set on the slider from Python
    widens the range on both sides as before (``_set_widget``)."""

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        finite_widening(self._value_edit)
        self._stretched = False
        self._value_edit.param.watch(self._on_typed, "value")
        self.param.watch(self._on_value, "value")

    def _on_typed(self, event: Any) -> None:
        value = event.new
        if value is not None and not (self.start <= value <= self.end):
            self._stretched = True

    def _on_value(self, event: Any) -> None:
        value = event.new
        if self._stretched and value is not None and self.start <= value <= self.end:
            self._stretched = False
            # the page's range is not the slider's in Python, which therefore sees no
            # change in the same range: a step off and back sends it
            step = self.step or 1
            inner = self._slider
            inner.param.update(start=self.start - step, end=self.end + step)
            inner.param.update(start=self.start, end=self.end)


class EditableSlider(_RangeKept, pn.widgets.EditableFloatSlider):
    """An EditableFloatSlider made of prompt parts."""

    _slider_widget = PromptFloatSlider
    _input_widget = PromptFloatInput
    _busy__ignore = _NOT_BUSY
    tooltips = param.Boolean(default=False, doc="Whether the handle shows its value (the "
                             "text box does).")

    def apply_steps_only(self) -> None:
        """Leave the page's releases of the handle out of Python (call before the slider
        is first shown: its model is linked then).

        A key press sends the slider's value and then its release (``value_throttled``),
        and Panel handles each in full (its event, the composite's values brought in
        line): for a slider that applies every step (a load) the release carries nothing
        new, yet it cost the server about as much as the step's own event.
        """
        self._slider._releases = False

    def watch_handle_release(self, callback: Callable[[Any, bool], None],
                             skip: Callable[[], bool]) -> None:
        """:func:`watch_release` of the handle: ``callback(event, dragged)`` at each
        release by the page (the end of a drag, or of a key press), after the step it
        ends reached the composite, unless ``skip()``."""
        watch_release(self._slider, callback, skip)

    def watch_drag_first(self, callback: Callable[[Any], None]) -> None:
        """Call ``callback(value)`` [the slider's value] at each move of the slider,
        before the composite's own watchers bring its value and text box in line.

        A load step reached the explorer's binding only after those (~7 ms on a loaded
        server, as long as the solve); called first, the solve starts at once and the
        text box follows while the worker solves. The composite's own watcher is taken
        off and put back after ``callback``: watchers of the same precedence run in the
        order they were added.
        """
        inner = self._slider
        inner.param.watch(lambda event: callback(event.new), "value")
        own = [w for w in inner.param.watchers.get("value", {}).get("value", [])
               if getattr(w.fn, "__func__", None) is _SYNC_VALUE]
        for watcher in own:
            inner.param.unwatch(watcher)
            inner.param.watch(watcher.fn, watcher.parameter_names, onlychanged=watcher.onlychanged,
                              queued=watcher.queued, precedence=watcher.precedence)


#: The composite slider's own watcher of its parts (re-ordered by ``watch_drag_first``).
_SYNC_VALUE = pn.widgets.EditableFloatSlider._sync_value


class EditableIntSlider(_RangeKept, pn.widgets.EditableIntSlider):
    """An EditableIntSlider made of prompt parts."""

    _slider_widget = PromptIntSlider
    _input_widget = PromptIntInput
    _busy__ignore = _NOT_BUSY
    tooltips = param.Boolean(default=False, doc="Whether the handle shows its value (the "
                             "text box does).")


#: Significant digits of a box shown by :func:`significant_format`: every value of the
#: page's units to its hundredths (six rounded a modulus of 1234567.8 MPa to 1234570).
SIGNIFICANT_DIGITS = 8


def significant_format() -> CustomJSTickFormatter:
    """A box format of :data:`SIGNIFICANT_DIGITS` significant digits, trailing zeros
    dropped: a fixed number of decimals showed a coating 0.0001 mm thick as "0" while that
    thickness was solved (a modulus of 1e-6 MPa, a creep rate of 0.0002 /day, a C∞ of
    1e-5 /GPa likewise), and a typed moment of 777.48 as "777.4800". A new model each
    time: one belongs to one page."""
    return CustomJSTickFormatter(
        code=f"return Number(Number(tick).toPrecision({SIGNIFICANT_DIGITS})).toString();")


def slider(label: str, start: float, end: float, step: float,
           fmt: str | CustomJSTickFormatter | None = None,
           **kwargs: Any) -> pn.widgets.EditableFloatSlider:
    """A float slider with an input box (any value can be typed; the core validates it),
    its value shown in ``fmt`` (default :func:`significant_format`)."""
    return EditableSlider(label=label, start=start, end=end, step=step,
                          format=significant_format() if fmt is None else fmt,
                          sizing_mode="stretch_width", **kwargs)


def _set_widget(widget: pn.widgets.Widget, value: Any) -> None:
    """Show ``value`` in ``widget`` as if the user had set it, throttled value included."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
        start, end = getattr(widget, "start", None), getattr(widget, "end", None)
        if start is not None and value < start:
            widget.start = value
        if end is not None and value > end:
            widget.end = value
    widget.value = value
    # Setting ``value`` from Python leaves ``value_throttled`` stale (holoviz/panel#2675):
    # the next release at that old value would then send no event at all. The inner
    # widgets of a composite slider carry their own copy.
    for part in (widget, getattr(widget, "_slider", None), getattr(widget, "_value_edit", None)):
        if part is not None and "value_throttled" in part.param:
            with param.edit_constant(part):
                part.param.update(value_throttled=value)


def watch_release(widget: pn.widgets.Widget, released: Callable[[Any, bool], None],
                  skip: Callable[[], bool]) -> None:
    """Call ``released(event, dragged)`` at each release of the slider ``widget`` (its
    ``value_throttled`` event), unless ``skip()`` (a value set from the state). ``dragged``: the
    handle was dragged, its value changed twice or more since the last release (a key
    press changes it once and releases at once: a key held down is a run of releases,
    each of which must not cut short the solve of the one before)."""
    steps = 0

    def moved(event: Any) -> None:
        nonlocal steps
        if not skip():
            steps += 1

    def let_go(event: Any) -> None:
        nonlocal steps
        dragged, steps = steps > 1, 0
        if not skip():
            released(event, dragged)

    widget.param.watch(moved, "value")
    widget.param.watch(let_go, "value_throttled")


def unusable_number(value: Any) -> str | None:
    """Why ``value``, typed in a number box, cannot be taken (None: it can): an emptied box
    (None), or a number that is not finite ("1e400" reads as Infinity in the page). Every
    number of a scene is finite; such a value, taken, left the page's parts out of step
    (:data:`FINITE_WIDEN_JS`)."""
    if value is None:
        return "a number is needed (the box was empty)"
    if isinstance(value, numbers.Real) and not isinstance(value, bool) \
            and not math.isfinite(value):
        return f"must be a finite number, got {value}"
    return None


def next_tick(callback: Callable[[], None]) -> None:
    """Run ``callback`` on the served page's next tick (at once outside a server): a
    widget's value set while the page's own change of it is handled is not sent back to
    the page, so a refused value is put back from here."""
    doc = pn.state.curdoc
    if doc is None or not doc.session_context:
        callback()
        return

    def run() -> None:
        with set_curdoc(doc):
            callback()

    doc.add_next_tick_callback(run)


class Binding:
    """Widgets editing parameters of one Parameterized at a time (re-bindable)."""

    def __init__(self, on_reject: Callable[[str], None] | None = None,
                 live_when: Callable[[], bool] | None = None) -> None:
        """``live_when``: asked at each drag step of a slider that updates on release;
        when it answers True the step is applied at once (a fast solver makes every
        slider live). Where it also has ``held(target, name, value)`` and
        ``released(dragged)`` (the explorer's :class:`~explorer.app.DragSteps`), a step
        not applied is passed to ``held`` (the page may preview it) and every release to
        ``released`` (:func:`watch_release`)."""
        self._pairs: list[tuple[str, pn.widgets.Widget]] = []
        self._checks: dict[str, Callable[[Any], Any]] = {}
        self._live_when = live_when
        self._target: param.Parameterized | None = None
        self._watcher: Any = None
        self._syncing = False
        self._leading: str | None = None  # a slider the state follows ahead of its widget
        self._on_reject = on_reject

    @property
    def target(self) -> param.Parameterized | None:
        return self._target

    def add(self, name: str, widget: pn.widgets.Widget, live: bool = False,
            check: Callable[[Any], Any] | None = None) -> Any:
        """Edit parameter ``name`` with ``widget``; ``live`` updates while dragging,
        otherwise on release (``value_throttled``) where the widget has it, and while
        dragging too when ``live_when`` says so. ``check`` refuses a value (ValueError)
        before it reaches the state; the widget then shows the state's value again."""
        event = "value" if live or "value_throttled" not in widget.param else "value_throttled"
        # a policy that makes one step of undo of a drag hears where the page released it,
        # and one that previews held steps or lets a drag's solves run hears of the
        # release too (after the state has taken the value; not a value set from the
        # state: a tab made mid-drag ended its preview)
        ended = getattr(self._live_when, "gesture_ended", None)
        released = getattr(self._live_when, "released", None)

        def let_go(event: Any, dragged: bool) -> None:
            if released is not None:
                released(dragged)
            if ended is not None:
                ended()  # the drag's one step of undo ends here

        widget.param.watch(lambda e, name=name: self._to_target(name, e.new), event)
        if live and isinstance(widget, EditableSlider):
            # a drag step reaches the state before the text box follows (the watcher
            # above then finds the state at the value already: no second change)
            widget.watch_drag_first(lambda value, name=name: self._lead(name, value))
            if ended is None:
                widget.apply_steps_only()
            else:
                # at the page's release of the handle (a busy page or server spaced one
                # drag's steps more than a second apart; a drag's solve still running
                # gives way to the released value's)
                widget.watch_handle_release(let_go, lambda: self._syncing)
        if event == "value_throttled" and self._live_when is not None:
            widget.param.watch(lambda e, name=name: self._drag_step(name, e.new), "value")
            if released is not None:
                # (its drag steps note the drag themselves: ExplorerApp._drag_step_applies)
                watch_release(widget, let_go, lambda: self._syncing)
        box = getattr(widget, "_value_edit", None)
        if box is None and isinstance(widget, pn.widgets.FloatInput | pn.widgets.IntInput):
            box = widget  # a number box of its own (the notional size stayed empty, unsaid)
        if box is not None:
            # the text box of a slider emptied: said, and the value shown again (the box
            # stayed empty, the value unchanged, and nothing said why)
            box.param.watch(lambda e, name=name, widget=widget: self._emptied(name, widget,
                                                                               e.new), "value")
        if check is not None:
            self._checks[name] = check
        self._pairs.append((name, widget))
        return widget

    def _emptied(self, name: str, widget: pn.widgets.Widget, value: Any) -> None:
        reason = unusable_number(value)
        if reason is None or self._syncing or self._target is None:
            return
        # the composite took the value, the state did not (:meth:`_to_target`)
        kept = getattr(self._target, name)
        if self._on_reject is not None:
            self._on_reject(f"{widget.name}: {reason}; it stays {kept:g}")

        def show() -> None:
            self._syncing = True
            try:
                _set_widget(widget, kept)
            finally:
                self._syncing = False

        # on the next tick: a value set while the page's own change is handled is not
        # sent back to it
        next_tick(show)

    def _lead(self, name: str, value: Any) -> None:
        # the slider moved ahead of its composite: the state follows it now, and the
        # composite brings itself in line afterwards (not from here, as an echo)
        step = getattr(self._live_when, "gesture_step", None)
        if (step is not None and not self._syncing and self._target is not None
                and value is not None and value != getattr(self._target, name)):
            step()  # a step of the handle (not an echo of the state's value)
        self._leading = name
        # a policy may treat the solve this step asks as a frame of a drag
        # (:meth:`~explorer.app.DragSteps.applying`)
        applying = getattr(self._live_when, "applying", None)
        if applying is None or self._syncing or self._target is None:
            applying = contextlib.nullcontext  # (a value shown from the state)
        try:
            with applying():
                self._to_target(name, value)
        finally:
            self._leading = None

    def _drag_step(self, name: str, value: Any) -> None:
        # a value shown from the state (``bind``, a preset) is no drag: nothing to ask
        if self._syncing or self._live_when is None:
            return
        step = getattr(self._live_when, "gesture_step", None)
        if step is not None:
            step()  # the changes up to the release are one step of undo
        if self._live_when():
            self._to_target(name, value)
            return
        # held until the release: a policy with ``held`` may preview the value meanwhile
        held = getattr(self._live_when, "held", None)
        if held is None or self._target is None or value is None:
            return
        try:
            if name in self._checks:
                self._checks[name](value)
        except ValueError:
            return  # refused: the release says why
        held(self._target, name, value)

    def bind(self, target: param.Parameterized) -> None:
        """Point every widget at ``target`` and show its values."""
        if self._target is not None and self._watcher is not None:
            self._target.param.unwatch(self._watcher)
        self._target = target
        self._syncing = True
        try:
            for name, widget in self._pairs:
                _set_widget(widget, getattr(target, name))
        finally:
            self._syncing = False
        self._watcher = target.param.watch(self._from_target,
                                           sorted({name for name, _ in self._pairs}))

    def add_late(self, name: str, widget: pn.widgets.Widget) -> pn.widgets.Widget:
        """:meth:`add` once the binding is pointed at its target: the widget shows the
        target's value and follows it from now on."""
        self.add(name, widget)
        if self._target is not None:
            self.bind(self._target)
        return widget

    def _to_target(self, name: str, value: Any) -> None:
        mark("widget_value")
        if self._syncing or self._target is None or unusable_number(value) is not None:
            return  # (an emptied box or a non-finite number: said by _emptied)
        try:
            if name in self._checks:
                self._checks[name](value)
            setattr(self._target, name, value)
        except ValueError as exc:  # a type the parameter refuses outright
            if self._on_reject is not None:
                self._on_reject(str(exc))
            self._syncing = True
            try:
                for other, widget in self._pairs:
                    if other == name:
                        _set_widget(widget, getattr(self._target, name))
            finally:
                self._syncing = False

    def _from_target(self, *events: param.parameterized.Event) -> None:
        self._syncing = True
        try:
            for event in events:
                for name, widget in self._pairs:
                    if (name == event.name and name != self._leading
                            and widget.value != event.new):
                        _set_widget(widget, event.new)
        finally:
            self._syncing = False


class LazySlider:
    """A slider with a text box (:func:`slider`) made the first time it is shown.

    Such a slider costs ~9 ms of a page's build (its text box, its slider and their
    links), and most pages never show most of the sliders of shapes and variations (a
    flat punch shows none of its eight). Until then a hidden, empty column stands in its
    place (:attr:`holder`); ``visible`` and :meth:`update` act on the slider once made,
    and its range set before is kept for it.
    """

    def __init__(self, binding: Binding, name: str, label: str, start: float, end: float,
                 step: float, fmt: str | None = None, **kwargs: Any) -> None:
        self.binding, self.name = binding, name
        self._spec: dict[str, Any] = dict(label=label, start=start, end=end, step=step,
                                          fmt=fmt, **kwargs)
        self.widget: pn.widgets.Widget | None = None
        self.holder = pn.Column(margin=0, sizing_mode="stretch_width", visible=False)

    @property
    def visible(self) -> bool:
        """Whether the slider shows (it is made when first shown)."""
        return bool(self.holder.visible)

    @visible.setter
    def visible(self, value: bool) -> None:
        if value and self.widget is None:
            spec = dict(self._spec)
            self.widget = self.binding.add_late(self.name, slider(
                spec.pop("label"), spec.pop("start"), spec.pop("end"), spec.pop("step"),
                spec.pop("fmt"), **spec))
            self.holder.objects = [self.widget]
        self.holder.visible = bool(value)

    @property
    def end(self) -> float:
        """The slider's upper end."""
        return float(self.widget.end if self.widget is not None else self._spec["end"])

    def update(self, **values: Any) -> None:
        """Set the slider's ``start`` and ``end`` (now, or when it is made)."""
        self._spec.update(values)
        if self.widget is not None:
            self.widget.param.update(**values)


#: The variations of a function of x offered on screen (label -> name), from core's list.
PROFILE_KINDS = {**{v.label: v.name for v in VARIATIONS.values()},
                 "custom (from file)": "custom"}


class ProfileEditor:
    """Level, variation kind and its parameters for one :class:`ProfileState`."""

    def __init__(self, label: str, unit: str, start: float, end: float, step: float,
                 fmt: str | CustomJSTickFormatter | None = None, variations: bool = True,
                 amplitude: tuple[str, float, float, float] = ("%", -90.0, 500.0, 1.0),
                 css: str = "", live_when: Callable[[], bool] | None = None,
                 on_reject: Callable[[str], None] | None = None) -> None:
        """``amplitude``: unit of the variation ('%' of the level, or an absolute unit),
        its slider range and step. Without ``variations`` only the level is offered.
        ``live_when`` and ``on_reject`` (where a refused or emptied value is said): see
        :class:`Binding`."""
        self.binding = Binding(on_reject, live_when=live_when)
        self.variations = variations
        self.mean = self.binding.add("mean", slider(f"{label} [{unit}]", start, end, step, fmt,
                                                    css_classes=[css] if css else []))
        self.note = pn.pane.HTML("", margin=(0, 10), visible=False,
                                 styles={"font-size": "12px", "color": "#666"})
        widgets: list[Any] = [self.mean]
        if variations:
            self.kind = self.binding.add("kind", PromptSelect(
                label=f"{label}: variation across the punch", options=PROFILE_KINDS,
                sizing_mode="stretch_width"))
            a_unit, a_lo, a_hi, a_step = amplitude
            a_label = f"{a_unit} of the level" if a_unit == "%" else a_unit
            self.amplitude = LazySlider(
                self.binding, "amplitude", f"variation A [{a_label}]", a_lo, a_hi, a_step,
                css_classes=[f"{css}-amplitude"] if css else [])
            self.position = LazySlider(
                self.binding, "position", "step position / patch or bump centre [m]",
                -1.0, 1.0, 0.01, css_classes=[f"{css}-position"] if css else [])
            self.length = LazySlider(
                self.binding, "length", "wavelength / patch or bump width [m]", 0.02, 2.0,
                0.01, css_classes=[f"{css}-length"] if css else [])
            widgets += [self.kind, self.amplitude.holder, self.position.holder,
                        self.length.holder]
        self.panel = pn.Column(*widgets, self.note, sizing_mode="stretch_width", margin=0)
        self._watched: ProfileState | None = None
        self._watcher: Any = None

    def bind(self, profile: ProfileState, half_width: float) -> None:
        if self.variations:
            self.position.update(start=-half_width, end=half_width)
            self.length.update(end=max(self.length.end, 2 * half_width))
        self.binding.bind(profile)
        if self._watched is not None and self._watcher is not None:
            self._watched.param.unwatch(self._watcher)
        self._watched = profile
        self._watcher = profile.param.watch(lambda *e: self.refresh(), ["kind", "custom"])
        self.refresh()

    def refresh(self) -> None:
        profile = self.binding.target
        if profile is None:
            return
        kind = profile.kind
        custom = kind == "custom" and profile.custom is not None
        if self.variations:
            uses = VARIATIONS[kind].uses if kind in VARIATIONS else ()
            self.amplitude.visible = "amplitude" in uses
            self.position.visible = "position" in uses
            self.length.visible = "length" in uses
            self.mean.visible = not custom
            note = ("A custom profile, as the scene gives it (kept as it is). Choose "
                    "another variation to replace it." if custom else "")
        elif custom:
            note = "Varies across the punch (as the scene gives it); the level above is not used."
        elif kind != "none":
            note = "Varies across the punch (as the scene gives it) about the level above."
        else:
            note = ""
        self.note.object = note
        self.note.visible = bool(note)


HISTORY_KINDS = {"constant": "constant", "ramp": "ramp", "step": "step", "sine": "sine",
                 "custom (from file)": "custom"}

_VALUE_LABELS = {"constant": "{q}", "ramp": "{q} at the end of the ramp",
                 "step": "{q} before the step", "sine": "mean {q}", "custom": "{q}"}
_SECOND_LABELS = {"ramp": "{q} at loading (ramp start)", "step": "{q} after the step",
                  "sine": "amplitude of {q}"}
_TIME_LABELS = {"ramp": "ramp duration [days]", "step": "time of the step [days]",
                "sine": "period [days]"}
NAMES = {"settlement": "settlement δ", "tilt": "tilt α", "force": "force P",
         "moment": "moment M"}
#: The units of a history table (SI, as in a scene file).
SI_UNITS = {"settlement": "m", "tilt": "rad", "force": "N/m", "moment": "N m/m"}


def _fit(widget: pn.widgets.Widget, value: float, default: tuple[float, float]) -> None:
    """Slider range: the default one, widened to keep ``value`` well inside."""
    lo, hi = default
    if value > hi or value < lo:
        span = 2 * abs(value) if value else 1.0
        lo, hi = min(lo, -span if lo < 0 else 0.0, value), max(hi, span, value)
    widget.param.update(start=lo, end=hi)


def _refit(widget: pn.widgets.Widget, value: Any, default: tuple[float, float]) -> None:
    """After a change of ``value``: the default range again once the value is back in
    it (one typed 1e6 kN/m left the force slider at 0 to 2e6 for good, a pixel ~3,000
    kN/m), widened only where the value left the range shown."""
    if (not isinstance(value, numbers.Real) or isinstance(value, bool)
            or not math.isfinite(value)):
        return
    lo, hi = default
    if lo <= value <= hi:
        if (widget.start, widget.end) != (lo, hi):
            widget.param.update(start=lo, end=hi)
    elif not widget.start <= value <= widget.end:
        _fit(widget, value, default)


class HistoryEditor:
    """Shape and parameters of the history of one given quantity (live while dragging)."""

    def __init__(self, css: str = "", on_reject: Callable[[str], None] | None = None,
                 drag: Any = None) -> None:
        """``css``: the class prefix of its widgets; ``on_reject``: says a refused value
        (an emptied box); ``drag``: hears where a drag of its sliders starts and ends
        (``gesture_step()``, ``gesture_ended()``: one step of undo; the explorer's
        :class:`~explorer.app.DragSteps`), or None."""
        self.binding = Binding(on_reject, live_when=drag)
        self.title = pn.pane.HTML("", margin=(8, 10, 0, 10))
        self.kind = self.binding.add("kind", PromptSelect(
            label="history", options=HISTORY_KINDS, sizing_mode="stretch_width"))
        self.value = self.binding.add("value", slider("value", 0.0, 1.0, 0.001,
                                                      css_classes=[f"{css}-value"] if css
                                                      else []), live=True)
        self.second = self.binding.add("second", slider("second", 0.0, 1.0, 0.001),
                                       live=True)
        self.time = self.binding.add("time", slider("time [days]", 0.1, 365.0, 0.1),
                                     live=True)
        self.note = pn.pane.HTML("", margin=(0, 10), styles={"font-size": "12px",
                                                              "color": "#666"})
        self.panel = pn.Column(self.title, self.kind, self.value, self.second, self.time,
                               self.note, sizing_mode="stretch_width", margin=0)
        self._watched: HistoryState | None = None
        self._watchers: list[Any] = []
        self._time_end = 365.0
        # the table upload of "custom (from file)", made when that kind is first chosen
        # (a file box costs the first page; most scenes never use one)
        self.upload: BoundedUpload | None = None
        self.upload_help = pn.pane.HTML("", margin=(0, 10), visible=False,
                                        styles={"font-size": "12px", "color": "#666"})

    def bind(self, history: HistoryState, time_end: float) -> None:
        q = history.quantity
        lo, hi = QUANTITY_RANGES[q]
        step = (hi - lo) / 1000
        self.value.step = self.second.step = step
        ranges = {"value": (lo, hi),
                  "second": (min(lo, -hi) if q in ("tilt", "moment") else lo, hi)}
        _fit(self.value, history.value, ranges["value"])
        _fit(self.second, history.second, ranges["second"])
        self.time.end = max(time_end, history.time)
        self._time_end = time_end
        self.binding.bind(history)
        if self._watched is not None:
            for watcher in self._watchers:
                self._watched.param.unwatch(watcher)
        self._watched = history
        self._watchers = [
            history.param.watch(lambda *e: self.refresh(), ["kind", "custom"]),
            history.param.watch(lambda *events: [
                _refit(getattr(self, e.name), e.new, ranges[e.name]) for e in events],
                ["value", "second"])]
        self.refresh()

    def refresh(self) -> None:
        history = self._watched
        if history is None:
            return
        q = history.quantity
        name = NAMES[q]
        unit = history.unit
        kind = history.kind
        self.title.object = f"<b>Given {name} [{unit}]</b>"
        self.value.label = _VALUE_LABELS[kind].format(q=name) + f" [{unit}]"
        self.second.visible = kind in _SECOND_LABELS
        self.time.visible = kind in _TIME_LABELS
        if kind in _SECOND_LABELS:
            self.second.label = _SECOND_LABELS[kind].format(q=name) + f" [{unit}]"
            self.time.label = _TIME_LABELS[kind]
        custom = kind == "custom" and history.custom is not None
        self.value.visible = not custom
        self._say("A custom history, as the scene or its table gives it (kept as it is). "
                  "Upload another table below, or choose another shape to replace it."
                  if custom else "")
        if kind == "custom" and self.upload is None:
            self.upload = BoundedUpload(accept=(".csv", ".txt"), max_bytes=MAX_TABLE_BYTES)
            self.upload.param.watch(self._on_table, "value")
            self.panel.extend([self.upload_help, self.upload])
        self.upload_help.object = (
            f"Upload a history table: CSV with two columns, t [days after loading] and "
            f"{name} [{SI_UNITS[q]}] (SI units), linear between its rows."
            if kind == "custom" else "")
        self.upload_help.visible = kind == "custom"
        if self.upload is not None:
            self.upload.visible = kind == "custom"

    def _say(self, text: str, bad: bool = False) -> None:
        color = "#9b1c1c" if bad else "#666"
        self.note.styles = {"font-size": "12px", "color": color}
        self.note.object = html.escape(text)
        self.note.visible = bool(text)

    def _on_table(self, event: Any) -> None:
        data, history = event.new, self._watched
        if data is None or history is None or self.upload is None:
            return
        q = history.quantity
        try:
            profile = profile_from_csv(data, field=f"loading.{q}", variable="t",
                                       domain=(0.0, self._time_end))
        except ValueError as exc:
            self._say(f"The table was not used: {exc}", bad=True)
            return
        finally:
            self.upload.clear()
        history.param.update(custom=profile.spec, kind="custom")
        self._say(f"Custom history from {self.upload.filename or 'a CSV file'}. Upload "
                  "another table, or choose another shape to replace it.")
