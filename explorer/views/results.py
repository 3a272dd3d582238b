"""The results column: messages, status, plots, time player, readout, pin and design check."""

from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import panel as pn
import param

from core.scene import creeps, days_text, number_text, percent_text

from ..files import flag_message, page_words
from ..model import (
    QUANTITIES,
    QUANTITY_UNITS,
    DesignLimits,
    Pin,
    ResultView,
    Screen,
    check_html,
    contact_text,
    design_check,
    lifted_times,
    model_evidence,
    punch_design_checks,
    punches_check_html,
    shown_flags,
)
from ..plots import PIN_COLORS, PUNCH_COLORS, Figures, LogTime
from ..solving import SolveController
from .busy import BusyIndicator, BusySpinner
from .contact import ContactPanes
from .link import AddressLink
from .loop import PageLoop
from .pins import PinsView
from .status import BADGES, following_text, held_text, preview_text, status_html
from .style import NOTE_STYLE, html_pane, set_shown
from .widgets import NAMES, LabelledCheckbox, TimePlayer


def _fmt(value: float) -> str:
    # five digits, without an exponent up to a million ("1.0000e+09" past 1e5 before)
    return number_text(value, 5)


def lift_off_badge(view: ResultView, index: int | None = None) -> str:
    """The pressure plots' badge of a unilateral answer that lifts off at some output time
    ('' if it never does): at the output time ``index`` shown, or, where the base is
    wholly in contact then, when it lifts (a crowned punch lifting at loading read "part
    of the base carries no load (shaded)" at 365 days, in full contact, nothing shaded)."""
    if "contact_lost" in view.flags:
        return ""  # a full-contact answer: its own badge says so
    lifted = lifted_times(view)
    if not lifted.any():
        return ""
    if index is None or lifted[min(index, lifted.size - 1)]:
        return ('<span class="cp-badge cp-bad lift-off">⚠ lift-off: part of the base '
                'carries no load (shaded)</span>')
    when = np.asarray(view.times, dtype=float)[lifted]
    first, last = days_text(float(when[0])), days_text(float(when[-1]))
    runs = int(lifted[0]) + int(np.count_nonzero(lifted[1:] & ~lifted[:-1]))
    if when.size == 1:
        span = f"at t = {first}"
    elif runs == 1:
        span = f"at t = {first} to {last}"
    else:  # lifted, in contact again, lifted: "0 to 1000 days" would take in the time shown
        span = f"at {when.size} of {lifted.size} output times, first {first}, last {last}"
    return (f'<span class="cp-badge cp-bad lift-off lift-off-elsewhere">⚠ lift-off '
            f'{html.escape(span)}: full contact at the time shown</span>')


def badges_html(view: ResultView | None, group: str,
                evidence: Mapping[str, Any] | None = None, index: int | None = None) -> str:
    """Validity badges of one plot group (flag names as CSS classes, messages as tooltips).

    ``evidence``: :func:`explorer.model.model_evidence` of ``view``; the ``model_error``
    badge says what it rests on (the FE check's measurement, else the estimate).
    ``index``: the output time shown, of which the pressure's lift-off badge speaks
    (:func:`lift_off_badge`)."""
    if view is None:
        return ""
    flags = shown_flags(view, evidence)
    parts = []
    lift_off = lift_off_badge(view, index) if group == "pressure" else ""
    lifted = bool(lift_off)
    if lifted:  # a unilateral solve: no q < 0, and no full contact either
        parts.append(lift_off)
    uncoated = group == "scene" and not view.scene.get("coating")
    for flag, (bad, good) in BADGES[group].items():
        if lifted and flag == "contact_lost":
            continue
        if uncoated and flag not in flags:
            continue  # no coating: nothing of a coating to vouch for
        if flag == "model_error" and evidence is None and flag not in flags:
            good = ""  # no estimate read: nothing to vouch with
        text = flag_message(view, flag)
        if flag == "model_error" and evidence is not None:
            # a badge of the model's error says whether it was measured or estimated
            of = f" of {evidence['quantity']}" if evidence.get("quantity") else ""
            bad, good = (f"{word} ({evidence['label']} "
                         f"{percent_text(evidence['error'])}{of})" for word in (bad, good))
            if not view.punches:  # (several: the flag's message names the punches)
                text = page_words(evidence["message"])
        if flag == "model_error" and "beyond_model_map" in flags:
            good = ""  # an extrapolated estimate vouches for nothing: its own badge says so
        if flag in flags:
            message = html.escape(text)
            parts.append(f'<span class="cp-badge cp-bad flag-{flag}" title="{message}">'
                         f"⚠ {bad}</span><span class='cp-msg'>{message}</span>")
        elif good:
            parts.append(f'<span class="cp-badge cp-ok ok-{flag}">✓ {good}</span>')
    return "".join(parts)


#: Said in place of the q(x, t) map and the histories of an answer at one output time,
#: on a base that does not creep (:data:`ONCE_CREEP_NOTE` on one that does).
ONCE_NOTE = ("<div class='once-note' style='font-size:13px;color:#444'>One output time "
             "({t}): the base answers at once (elastic) and holds that answer at every "
             "later time, so there is no history to draw. A creeping base, or more output "
             "times, draw the settlement, tilt and pressure over time.</div>")
#: The same on a creeping base: its answer is that of the one time, creep included (the
#: elastic words read beside a settlement 1.5 times the one at loading: an audit).
ONCE_CREEP_NOTE = ("<div class='once-note' style='font-size:13px;color:#444'>One output "
                   "time ({t}): the values are those at that time, creep since loading "
                   "included; with one time there is no history to draw. More output "
                   "times draw the settlement, tilt and pressure over time.</div>")
#: The design check while a preview is on screen: no verdict on a history without creep
#: (its largest settlement is the one at loading; the answer with creep comes on release).
PREVIEW_DESIGN = ("<span class='cp-badge check-none design-preview'>design check on "
                  "release: the preview leaves out creep</span>")
#: What the page does not show for a scene of several punches yet, said under its
#: readout (the features of one punch that are off for several).
SEVERAL_PUNCHES_NOTE = ("Several punches: pins, the classical solutions, the coating "
                        "model's FE check and the back-analysis are for one punch and are "
                        "off here; the design check and studies take each punch; the Files "
                        "tab's CSV files (SI units, a column per punch), reports and JSON "
                        "hold every punch.")


def punches_readout_html(view: ResultView, index: int, preview: bool = False) -> str:
    """Values of every punch of several at the selected time, a column per punch
    (``preview``: as :func:`readout_html`)."""
    t = float(view.times[index])
    head = "<tr><th></th>" + "".join(
        f"<th class='readout-punch-{k}' style='border-bottom:3px solid {PUNCH_COLORS[k]}'>"
        # (named as the files and the report name it too: "punches[1]" read as punch 1)
        f"punch {k + 1} (punches[{k}], x = {p.center:.3g} m)</th>"
        for k, p in enumerate(view.punches))
    rows = [head + "</tr>"]
    for q in QUANTITIES:
        unit = QUANTITY_UNITS[q][0]
        cells = "".join(
            f"<td class='readout-punch-{k}-{q}{' cp-given' if q in p.given else ''}'>"
            f"{_fmt(float(p.display(q)[index]))}{' (given)' if q in p.given else ''}</td>"
            for k, p in enumerate(view.punches))
        rows.append(f"<tr><td>{NAMES[q]} [{unit}]</td>{cells}</tr>")
    eccs = "".join(
        f"<td>{float(p.values['moment'][index]) / float(p.values['force'][index]):.4g} m</td>"
        if float(p.values["force"][index]) > 0 else "<td>undefined (P ≤ 0)</td>"
        for p in view.punches)
    rows.append(f"<tr><td>e = M/P</td>{eccs}</tr>")
    contact = html.escape(contact_text(view, index))
    said = " (preview, without creep)" if preview else ""
    return (f"<div class='readout punches-readout'><b>At t = {days_text(t)} after loading"
            f"{said}</b> · each punch's moment and tilt about its own centre"
            f"<div class='readout-scroll'><table class='cp-readout'>{''.join(rows)}</table>"
            "</div>"
            f"<div class='contact-readout'>{contact}</div>"
            f"<div class='cp-status several-punches-note'>{html.escape(SEVERAL_PUNCHES_NOTE)}"
            f"</div></div>")


def change_text(value: float, other: float) -> str:
    """The change from ``other`` to ``value`` in percent, three significant digits
    ("+40 %", "+33.3 %", "-0.0123 %"; "0 %" for none, "n/a" from zero): "+100.00 %" and
    "+0.00 %" read as more precise than the values beside them."""
    if not other:
        return "n/a"
    change = 100 * (value - other) / abs(other)
    return "0 %" if change == 0 else f"{change:+.3g} %"


def readout_html(view: ResultView | None, index: int, pins: Sequence[Pin] = (),
                 preview: bool = False) -> str:
    """Values at the selected time: current, and each pin with its change against the
    current one (for
    several punches, each punch's; pins compare results of one punch); ``preview``: the
    values are a dragged value's preview (the base without creep), which the heading
    says (it read "At t = 1000 days" over the values without creep)."""
    if view is None:
        return ""
    if view.several:
        return punches_readout_html(view, index, preview)
    t = float(view.times[index])
    head = "<tr><th></th><th>current</th>"
    for k, pin in enumerate(pins):
        color = PIN_COLORS[k]
        head += (f"<th style='border-bottom:3px dashed {color}'>{html.escape(pin.label)}"
                 "</th>")
    rows = [head + "</tr>"]
    others = [pin.view for pin in pins]
    times = [other.time_index(t) for other in others]
    for q in QUANTITIES:
        unit = QUANTITY_UNITS[q][0]
        value = float(view.display(q)[index])
        role = "given" if q in view.given else "computed"
        cls = "cp-given" if role == "given" else ""
        row = (f"<tr class='{cls}'><td>{NAMES[q]} [{unit}] ({role})</td>"
               f"<td class='readout-{q}'>{_fmt(value)}</td>")
        for k, (pinned, j) in enumerate(zip(others, times, strict=True)):
            other = float(pinned.display(q)[j])
            # the pin's value against the current one, under the pin's value: the
            # current's against the pin's read as the pin's own change (a pin of 250
            # kN/m beside 500 showed "+100 %", one of 750 "-33.3 %": a teacher's audit)
            change = change_text(other, value)
            # the change under the value, not in a column of its own: five pins took
            # 875 px of a 653 px box at 1280 and their last columns were out of sight
            # (a teacher's audit); now 6 columns, not 11
            row += (f"<td><span class='pinned-{q} pin-{k}-{q}'>{_fmt(other)}</span><br>"
                    f"<span class='cp-change'>{change}</span></td>")
        rows.append(row + "</tr>")
    force, moment = float(view.values["force"][index]), float(view.values["moment"][index])
    ecc = f"e = M/P = {moment / force:.4g} m" if force > 0 else "e = M/P undefined (P ≤ 0)"
    contact = html.escape(contact_text(view, index))
    said = " (preview, without creep)" if preview else ""
    return (f"<div class='readout'><b>At t = {days_text(t)} after loading{said}</b> · {ecc}"
            # pins add two columns each: at 1024 px three pins' table is twice the box
            # wide, and its last columns were cut off with no way to reach them; its
            # scroll bar is always drawn (an overlay bar hid that it scrolls) and the
            # names stay in view while it scrolls
            f"<div class='readout-scroll'><table class='cp-readout'>{''.join(rows)}</table>"
            "</div>"
            + (f"<div class='cp-status pins-note'>{PINS_NOTE}</div>" if pins else "")
            + f"<div class='contact-readout'>{contact}</div></div>")


#: What the percentages under the pins' values are.
PINS_NOTE = "Under each pin: its value, and its change against the current one."


#: Delay before a held drag is said on a served page [ms]: longer than from a key press's
#: step to its release (the same event), shorter than a drag's first steps.
HELD_AFTER_MS = 200

class ResultsView:
    """The page's main column: what the result on screen is, and how far to trust it."""

    def __init__(self, screen: Screen, controller: SolveController, loop: PageLoop,
                 figures: Figures, limits: DesignLimits, pins: PinsView,
                 link: AddressLink) -> None:
        """``screen``: the result and time shown, and the notice; ``controller``: its
        refusals and busy spells are shown here; ``figures``: the plots of the column;
        ``limits``: the design check's; ``pins``: their buttons sit by the readout, their
        results on the plots; ``link``: its hidden address box is part of the column."""
        self.screen = screen
        self.controller = controller
        self.loop = loop
        self.figures = figures
        self.limits = limits
        self.pins = pins
        self.link = link
        self.alert = pn.pane.Alert("", alert_type="danger", visible=False,
                                   sizing_mode="stretch_width", css_classes=["solve-error"])
        self.notice_alert = pn.pane.Alert(html.escape(screen.notice), alert_type="warning",
                                          visible=bool(screen.notice),
                                          sizing_mode="stretch_width",
                                          css_classes=["notice"])
        self.spinner = BusySpinner()
        self.status = html_pane("", sizing_mode="stretch_width", margin=(5, 5))
        self._evidence: tuple[tuple[int, int], dict[str, Any] | None] = ((0, 0), None)
        self._refused = False  # a refusal on screen (the design check says so too)
        self._preview: ResultView | None = None  # the preview drawn, while it is
        self.busy = BusyIndicator(controller, loop, self.spinner, self.status,
                                  evidence=self.evidence, on_screen=self.on_screen)
        screen.param.watch(lambda *e: self.show_model_check(), "model_check")
        # said while a slider is dragged that only its release applies (slow solves)
        self._held_wanted = False
        self.held = html_pane("", visible=False, css_classes=["drag-held"],
                              styles=NOTE_STYLE, margin=(0, 10))
        badge = {"margin": (0, 5), "sizing_mode": "stretch_width"}
        self.scene_badges = html_pane("", **badge)
        self.pressure_badges = html_pane("", **badge)
        self.history_badges = html_pane("", **badge)
        self.status_badges = html_pane("", **badge)
        self._nudging = False  # the player moves without moving the plots
        self._range_token = 0  # counts the ranges set (a later one overrides a move)
        self.player = self._new_player(1, 0)
        self.player_box = pn.Row(self.player, sizing_mode="stretch_width", margin=0)
        self.time_label = html_pane("", margin=(12, 10))
        self.readout = html_pane("", sizing_mode="stretch_width")
        self.once_note = html_pane("", sizing_mode="stretch_width", css_classes=["once-note-pane"],
                                   styles={"display": "none"})
        self.design = html_pane("", sizing_mode="stretch_width", css_classes=["design-pane"])
        self.classical = LabelledCheckbox("classical solutions on q(x)",
                                          css_classes=["classical-toggle"])
        self.classical.param.watch(self._on_classical, "value")
        # long creep histories change most in their first days: a log axis shows both
        self.log_time = LabelledCheckbox("log time axis", css_classes=["log-time"],
                                         margin=(5, 10))
        self.log_time.param.watch(self._on_log_time, "value")
        # the contact width's history too (it stayed linear beside log histories)
        self.time_axis = LogTime([*(figures.history_fig[q] for q in QUANTITIES),
                                  figures.contact_fig])
        limits.param.watch(lambda *e: self.show_design(), list(
            n for n in limits.param if n != "name"))
        f = figures
        bokeh = {"sizing_mode": "stretch_width", "margin": (0, 5)}
        self._bokeh_panes = [pn.pane.Bokeh(fig, **bokeh) for fig in (
            f.scene_fig, f.q_fig, f.image_fig, *(f.history_fig[q] for q in QUANTITIES))]
        self.contact_panes = ContactPanes(f, self._bokeh_panes)

    def content(self) -> pn.Column:
        """The main column of the page."""
        scene_pane, q_pane, image_pane, *history_panes = self._bokeh_panes
        self.history_grid = pn.GridBox(*history_panes, ncols=2, sizing_mode="stretch_width")
        # the pins' controls beside the readout; below it in presentation mode, where the
        # readout's larger text with two pins ran under them at 1024 px
        self.pin_controls = pn.Column(self.pins.content(), self.classical)
        self.readout_row = pn.Row(self.readout, self.pin_controls, sizing_mode="stretch_width")
        self.below_readout = pn.Row(sizing_mode="stretch_width", margin=0)
        return pn.Column(
            self.link.address,
            self.notice_alert,
            self.alert,
            pn.Row(self.spinner.pane, self.status, sizing_mode="stretch_width"),
            self.held,
            self.status_badges,
            self.scene_badges,
            pn.Row(scene_pane, self.contact_panes.inset_slot, sizing_mode="stretch_width"),
            self.pressure_badges,
            pn.Row(q_pane, image_pane, sizing_mode="stretch_width"),
            self.once_note,
            pn.Row(self.player_box, self.time_label, sizing_mode="stretch_width"),
            self.readout_row,
            self.below_readout,
            self.design,
            pn.Row(self.history_badges, self.log_time, sizing_mode="stretch_width"),
            self.history_grid,
            self.contact_panes.width_slot,
            sizing_mode="stretch_width",
        )

    def draw(self, view: ResultView, index: int, new_range: bool,
             preview: bool = False) -> None:
        """Show a new result at output time ``index`` (call inside ``pn.io.hold()``);
        ``preview``: a preview of a dragged value, which the status line says."""
        self.classical.disabled = view.several
        self.figures.set_preview(preview)
        self.figures.show(view, index, self.pins.board.pins)
        self.contact_panes.update(view)
        if new_range:
            self._set_range(max(len(view.times) - 1, 1), index)
        else:
            self.player.value = index
        # one output time (an elastic scene): the player's range is 0 to 1 all the same
        # (a range of one point is no slider), so it takes no move; off the page, where a
        # greyed slider and play button read as broken (a teacher's audit): the time
        # label beside it and the once-note say the one time
        self.player.disabled = len(view.times) < 2
        set_shown(self.player_box, len(view.times) > 1)
        self.follow_time_span(view)
        with param.discard_events(self.screen):
            self.screen.time_index = index
        self._preview = view if preview else None
        self.show_time_texts(view, index)
        self.status.object = status_html(view, self.busy.shown, self.evidence(view), preview)
        self.scene_badges.object = badges_html(view, "scene", self.evidence(view))
        # (the pressure's badges with the time texts above: they follow the time shown)
        self.history_badges.object = badges_html(view, "history")
        self.status_badges.object = badges_html(view, "status")
        if self.time_axis.on:
            self.time_axis.fit()
        self.show_design(view)

    def follow_time_span(self, view: ResultView) -> None:
        """An answer at one output time (an elastic base answers at once, and holds at
        every later time) has no history to draw: the q(x, t) map and the histories are
        taken off (a map of one row and four plots of one dot each, on axes of 0.96 to
        1.04 days), and a line says why; pinned results or readings over time keep
        them."""
        grid = getattr(self, "history_grid", None)
        if grid is None:  # (the page's column is not built yet)
            return
        readings = self.figures.readings_src
        over_time = (len(view.times) > 1
                     or any(len(pin.view.times) > 1 for pin in self.pins.board.pins)
                     or any(len(readings[q].data.get("t", ())) for q in readings))
        # (the map's figure itself: its Bokeh pane puts the figure on the page as it is)
        for pane in (self.figures.image_fig, grid, self.log_time.__panel__()):
            set_shown(pane, over_time)
        note = "" if over_time else (ONCE_CREEP_NOTE if creeps(view.scene) else ONCE_NOTE
                                     ).format(t=days_text(float(view.times[0])))
        if self.once_note.object != note:
            self.once_note.object = note
        set_shown(self.once_note, not over_time)

    def evidence(self, view: ResultView | None) -> dict[str, Any] | None:
        """The coating model's error to show for ``view``: measured by the Coating tab's
        FE check when it was run on this scene, else estimated (remembered per result
        and check: the key of a scene is a validation away)."""
        if view is None:
            return None
        check = self.screen.model_check
        key = (id(view), id(check))
        if self._evidence[0] != key:
            self._evidence = (key, model_evidence(view, check))
        return self._evidence[1]

    def show_model_check(self) -> None:
        """A new FE check: the status and the badges of the result on screen say what it
        measured (or the estimate still, when it was run on another scene)."""
        view, preview = self.on_screen()
        if view is None:
            return
        self.status.object = status_html(view, self.busy.shown, self.evidence(view), preview)
        self.scene_badges.object = badges_html(view, "scene", self.evidence(view))

    def on_screen(self) -> tuple[ResultView | None, bool]:
        """The result the plots show and whether it is a preview of a dragged value (the
        answer kept behind a preview is ``screen.shown()``)."""
        if self._preview is not None:
            return self._preview, True
        return self.screen.shown(), False

    def show_time_texts(self, view: ResultView, index: int) -> None:
        """The time label and the readout at output time ``index``."""
        self.time_label.object = (f"<span class='time-label'>t = "
                                  f"{days_text(float(view.times[index]))}</span>")
        self.readout.object = readout_html(view, index, self.pins.board.pins,
                                           preview=self._preview is view)
        badges = badges_html(view, "pressure", index=index)
        if self.pressure_badges.object != badges:  # (a lift-off badge follows the time)
            self.pressure_badges.object = badges

    def show_design(self, view: ResultView | None = None) -> None:
        """The design check of ``view`` (default: the result on screen) against the
        session's limits. A preview (no creep) gets no verdict: the largest settlement
        and pressure of the whole history come with creep, on release."""
        if view is None:
            view, preview = self.on_screen()
        else:
            preview = view is self._preview
        if view is not None and view.several:
            # each punch's, as its report and the command line check them (the page
            # showed none, while its report read "A limit is exceeded under punches[0]")
            self.design.object = punches_check_html(
                view, punch_design_checks(view, self.limits)) if not preview else \
                PREVIEW_DESIGN
            return
        if preview:
            self.design.object = PREVIEW_DESIGN
            return
        # its verdict qualified by the flags the badges show (the FE check's measurement
        # lowers beyond_model_map, which the check still named); while the newest change
        # is refused, of the last good result, said ("✓ all set limits hold" stood beside
        # "Not solved" as if of the change)
        about = ("of the last good result: the newest change was not solved"
                 if self.controller.error else "")
        self.design.object = check_html(design_check(
            view, self.limits, shown_flags(view, self.evidence(view))), about=about) \
            if view else ""

    def show_pins(self) -> None:
        """Draw the pins on the figures and in the readout (they changed)."""
        view = self.on_screen()[0]
        if view is None:
            return
        index = self.screen.time_index
        with pn.io.hold():
            self.figures.show_pinned(view, self.pins.board.pins, index)
            self.follow_time_span(view)
            if self.time_axis.on:
                self.time_axis.fit()
            self.show_time_texts(view, index)
        self.push()

    def on_status(self, *events: object) -> None:
        """The controller started or finished a solve, or refused a scene."""
        controller = self.controller
        self.show_error(controller.error, controller.view is not None)
        self.busy.follow(controller.busy)
        if not controller.busy:
            self.link.schedule()  # a link skipped while busy, if no newer result came

    def say_held(self, held: bool, cpu_seconds: float | None = None,
                 preview: bool = False, following: bool = False) -> None:
        """Say (``held``) or stop saying that a dragged slider waits for its release, the
        last solve having taken ``cpu_seconds`` [s] of CPU time (None: not known);
        ``preview``: the plots show a preview of the dragged value meanwhile (said at once);
        ``following``: the slider applies every step and the plots follow it as fast as
        the solves go (a load), each frame the last value solved.

        On a served page the note comes :data:`HELD_AFTER_MS` after the step, if no
        release came meanwhile: a key press on such a slider is a step and its release at
        once, and the note shown and hidden at each press cost the page 400-600 ms of
        relayout a press (benchmarks/results/explorer_latency_presets.md)."""
        self._held_wanted = held
        if not held:
            if self.held.visible:
                self.held.object, self.held.visible = "", False
            return
        text = (preview_text(cpu_seconds) if preview
                else following_text(cpu_seconds) if following else held_text(cpu_seconds))

        def show() -> None:
            # (a preview drawn since this note was scheduled says its own note)
            if self._held_wanted and (preview or self._preview is None):
                self.held.object = text
                self.held.visible = True

        if self.loop.served and not preview:
            self.loop.later(show, HELD_AFTER_MS)
        else:
            show()

    def show_download_error(self, text: str) -> None:
        """Say why a download failed (Markdown, user text escaped)."""
        self.alert.object = text
        self.alert.visible = True

    def show_error(self, error: str, has_view: bool) -> None:
        """The solver's refusal (empty: none), and what the plots show meanwhile."""
        # the core's messages echo user text (see ExplorerApp._on_notice)
        after = ("The plots still show the last good result." if has_view
                 else "There is no result to show yet: change the scene, or choose a preset.")
        self.alert.object = f"**Not solved:** {html.escape(error)}  \n{after}" if error else ""
        self.alert.visible = bool(error)
        if bool(error) != self._refused:
            self._refused = bool(error)
            self.show_design()  # its heading says whose verdict it is

    def set_presentation(self, on: bool) -> None:
        """Projector fonts for the texts of the column (the figures set their own), and
        the pins' controls below the readout (beside it otherwise)."""
        # back to the theme's size by name: emptied styles left 17 px on the page
        size = "17px" if on else "var(--font-size)"
        for pane in (self.readout, self.status, self.design):
            pane.styles = {"font-size": size}
        if not hasattr(self, "readout_row"):  # (the page's column not made yet)
            return
        if on:
            self.readout_row.objects = [self.readout]
            self.below_readout.objects = [self.pin_controls]
        else:
            self.below_readout.objects = []
            self.readout_row.objects = [self.readout, self.pin_controls]

    def _on_classical(self, event: Any) -> None:
        with pn.io.hold():
            self.figures.set_classical(self.on_screen()[0], self.screen.time_index,
                                       bool(event.new))
        self.push()

    def _on_log_time(self, event: Any) -> None:
        with pn.io.hold():
            self.time_axis.set(bool(event.new))
        self.push()

    def _new_player(self, end: int, value: int) -> pn.widgets.Player:
        player = TimePlayer(label="time", start=0, end=end, value=value, interval=250,
                            loop_policy="once", show_loop_controls=False,
                            sizing_mode="stretch_width", show_value=False,
                            css_classes=["time-player"])
        player.param.watch(self._on_player, "value")
        return player

    def _on_player(self, event: Any) -> None:
        if self._nudging:
            return
        # never past the last output time: a one-time scene's player reaches 1, and that
        # index failed the pins and the lessons (IndexError on the server)
        view = self.on_screen()[0]
        last = None if view is None else len(view.times) - 1
        self.screen.time_index = int(event.new) if last is None else min(int(event.new), last)

    def _set_range(self, end: int, value: int) -> None:
        """The player's range for a new number of output times, at ``value``.

        The page's player sets its range input's maximum only when its value changes, so
        a new range with the same value (or a value arriving before the range) left the
        old range on screen, and a value above the input's old maximum was clamped to it
        (a 200-time scene from a file: the label said the last time, the handle sat at
        100 of 199). So the range goes out first and the value a moment later, in a
        message of its own; when the value is the one the player holds, the player is
        moved to a neighbour and back (the plots are not). A new player for each range
        did the same, but adding it to the page made Bokeh walk the whole document:
        ~330 ms of the server's CPU per preset switch on a page with its tabs filled.
        Outside a server (a notebook: no later turn of a loop to send the value in) a new
        player still replaces the old one."""
        if not self.loop.served:
            self.player = self._new_player(end, value)
            self.player_box.objects = [self.player]
            return
        player = self.player
        self._range_token += 1
        token = self._range_token
        player.end = end

        def move(step: int) -> None:
            if token != self._range_token or self.screen.time_index != value:
                return  # a newer range came, or the user chose another time meanwhile
            if step == 0 and player.value == value:
                self._nudging = True
                try:
                    player.value = value + 1 if value < end else value - 1
                finally:
                    self._nudging = False
                self.loop.later(lambda: move(1), 0)
                return
            player.value = value

        self.loop.later(lambda: move(0), 0)

    def page_loaded(self) -> None:
        """The browser has drawn the page: a player whose range and value were in the first
        document (an answer the server had before the page was sent) took the value before
        its maximum, HTML's default 100 (a link to a 200-time scene read the last time in
        its label with the handle mid-track), so both are sent again (:meth:`_set_range`)."""
        if self.loop.served and self.player.end > 1:
            self._set_range(self.player.end, self.player.value)

    def push(self) -> None:
        """In a notebook, plain Bokeh models changed in place must be pushed by hand."""
        if not self.loop.served and self._bokeh_panes:
            pn.io.push_notebook(*self._bokeh_panes)
