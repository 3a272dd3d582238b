"""The Study tab: a design chart over one or two fields of the scene on screen.

The user picks the fields (loads, coating, base, punch: :func:`explorer.model.study.
study_choices`), their ranges and the output; Run builds the study from the scene on
screen (:func:`explorer.model.study.plan_study`, refused with a message naming the field) and
runs it off the page's event loop (:class:`explorer.solving.study_runner.StudyRun`, a process of
its own, cancellable). The chart (:class:`explorer.plots.study.DesignChart`) shows the
output at a chosen time; it downloads as CSV (every output at every time) and PNG.
"""

from __future__ import annotations

import asyncio
import html
import io
import threading
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

import numpy as np
import panel as pn

from core.scene import days_text

from ..files import MAX_PAGE_DOWNLOAD_BYTES, study_csv
from ..model import (
    MAX_POINTS,
    OUTPUTS,
    SPACINGS,
    Axis,
    ExplorerState,
    default_range,
    plan_study,
    study_choices,
    study_outputs,
)
from ..plots import DesignChart, design_chart_png, flag_note
from ..solving import SolveController, StudyRun, format_error
from .loop import PageLoop
from .style import NOTE_STYLE, TAB_COLUMN, html_pane, slug
from .widgets import CountBox, NumberBox, PromptSelect

#: The second parameter's choice for "no second parameter".
NONE = "(none: a line over parameter 1)"


#: A select box of a few short words beside three number boxes in the sidebar's width.
NARROW_SELECT = "select.bk-input { padding-left: 6px; }"


class _AxisInputs:
    """The widgets of one parameter: the field, from, to, points, spacing."""

    def __init__(self, n: int, optional: bool) -> None:
        css = f"study-p{n}"
        self.optional = optional
        self.field = PromptSelect(label=f"parameter {n}", sizing_mode="stretch_width",
                                  css_classes=[f"{css}-field"])
        # four boxes and their margins in the sidebar's width (the spacing once ran ~70 px
        # past it, into the scene's axis label)
        self.start = NumberBox(label="from", width=64, css_classes=[f"{css}-from"])
        self.stop = NumberBox(label="to", width=64, css_classes=[f"{css}-to"])
        # no bounds on the box: a count the study refuses ("points: must be a whole
        # number from 2 to ...") is said when it runs; with start=2 the box kept a typed 1
        # or 0 while the study ran on the last count taken, without a word
        self.count = CountBox(label="points", value=9, width=66,
                              css_classes=[f"{css}-count"])
        # (its text once touched the arrow: a narrower left padding than the theme's 12 px)
        self.spacing = PromptSelect(label="spacing", options=list(SPACINGS), width=68,
                                    css_classes=[f"{css}-spacing"],
                                    stylesheets=[NARROW_SELECT])
        self.row = pn.Row(self.start, self.stop, self.count, self.spacing,
                          sizing_mode="stretch_width", margin=0)

    def panel(self) -> pn.Column:
        return pn.Column(self.field, self.row, sizing_mode="stretch_width", margin=0)

    def fill(self, axis: Axis) -> None:
        """Show ``axis``'s range."""
        self.start.value, self.stop.value = float(axis.start), float(axis.stop)
        self.count.value, self.spacing.value = int(axis.count), axis.spacing

    def axis(self) -> Axis | None:
        """The parameter typed, or None (the second left out)."""
        if self.field.value in (None, NONE):
            return None
        return Axis(self.field.value, _number(self.start.value), _number(self.stop.value),
                    self.count.value if self.count.value is not None else 0,
                    self.spacing.value)


def _why_failed(result: Any) -> str:
    """Why the study's points failed, for its summary: the first failed point's message
    (the page said "1 failed (no value)" and nothing more), and how many other reasons
    the CSV's ``error`` column holds."""
    reasons = list(dict.fromkeys(str(e) for e in np.asarray(result.errors)[result.failed]
                                 if str(e)))
    if not reasons:
        return ""
    first = format_error(reasons[0])  # the field in words, loads in the page's units
    first = first if len(first) <= 240 else first[:239] + "…"
    more = len(reasons) - 1
    return (f" Failed: {first}" + (f" (and {more} other reason{'s' if more > 1 else ''}: "
                                   "the CSV's error column)" if more else ""))


def _number(value: Any) -> float:
    return float("nan") if value is None else float(value)


class StudyView:
    """Widgets, progress and chart of the session's design study."""

    title = "Study"

    def __init__(self, state: ExplorerState, controller: SolveController, loop: PageLoop,
                 on_settings: Callable[[], None]) -> None:
        """``state``: the scene a study is built around; ``controller``: the fields offered
        follow its results; ``loop``: where the study's progress is shown;
        ``on_settings``: called when the fields or the output change (the link keeps
        them)."""
        self.state = state
        self.loop = loop
        self.study_run = StudyRun(dispatch=loop.dispatch)
        # the CSV of the last result, built off the event loop when the result comes
        # (a 400-point study over 2000 output times is ~75 MB: 12 s of the loop's time)
        self._csv_data: bytes | None = None
        self._choices: dict[str, Any] = {}
        self._scene: dict[str, Any] | None = None
        self.study_first = _AxisInputs(1, optional=False)
        self.study_second = _AxisInputs(2, optional=True)
        stretch = {"sizing_mode": "stretch_width"}
        self.study_output = PromptSelect(
            label="output", options={f"{n} [{u}]": k for k, (n, u, _) in OUTPUTS.items()},
            css_classes=["study-output"], **stretch)
        self.study_time = PromptSelect(label="at time after loading", options={},
                                       css_classes=["study-time"], **stretch)
        self.study_run_button = pn.widgets.Button(label="Run study", color="primary",
                                                  css_classes=["study-run"], **stretch)
        self.study_cancel_button = pn.widgets.Button(label="Cancel", disabled=True,
                                                     css_classes=["study-cancel"], **stretch)
        self.study_progress = pn.indicators.Progress(value=0, max=1, visible=False,
                                                     css_classes=["study-progress"],
                                                     **stretch)
        self.study_status = html_pane("", css_classes=["study-status"], **stretch)
        # the figures are built for the first study, not with the page: three Bokeh
        # figures cost ~70 ms of the server's CPU (measured), a seventh of a new session,
        # for a tab few open; on a thread while that study runs (built with its result,
        # they held the event loop, which every page shares, ~0.3 s)
        self.study_charts: DesignChart | None = None
        self._charts_built: Future[DesignChart] | None = None
        self._chart_pane: pn.pane.Bokeh | None = None
        self._chart_box = pn.Column(
            html_pane("<small><i>Run a study to see its design chart here.</i></small>"),
            **stretch)
        self.study_csv = pn.widgets.FileDownload(callback=self._csv, filename="study.csv",
                                                 label="Study data (CSV)", disabled=True,
                                                 css_classes=["study-csv"], **stretch)
        self.study_png = pn.widgets.FileDownload(callback=self._png, filename="study.png",
                                                 label="Design chart (PNG)", disabled=True,
                                                 css_classes=["study-png"], **stretch)
        self.study_first.field.param.watch(lambda e: self._on_field(self.study_first),
                                           "value")
        self.study_second.field.param.watch(lambda e: self._on_field(self.study_second),
                                            "value")
        self.study_output.param.watch(lambda e: self._redraw(), "value")
        self.study_time.param.watch(lambda e: self._redraw(), "value")
        self.study_run_button.on_click(lambda e: self.start())
        self.study_cancel_button.on_click(lambda e: self.study_run.cancel())
        self.study_run.param.watch(self._on_run, ["status", "done", "total", "message"])
        self.study_run.param.watch(self._on_result, "result")
        # the fields offered follow each result on screen (a solve, not every slider step)
        controller.param.watch(lambda e: self.refresh(getattr(e.new, "scene", None)),
                               "view")
        # the settings are part of the page's link (explorer.model.view_link)
        self._wanted: dict[str, Any] | None = None
        for inputs in (self.study_first, self.study_second):
            for widget in (inputs.field, inputs.start, inputs.stop, inputs.count,
                           inputs.spacing):
                widget.param.watch(lambda e: on_settings(), "value")
        self.study_output.param.watch(lambda e: on_settings(), "value")
        if loop.served:
            # a closed page stops its study
            pn.state.on_session_destroyed(lambda ctx: self.study_run.cancel())
        # (made when its tab is filled: the scene of the result on screen, as its watcher
        # gives the later ones)
        self.refresh(getattr(controller.view, "scene", None))

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(
            html_pane("<small>A design chart around the scene on screen: one field over a "
                      f"range (a line) or two (a heat map), at most {MAX_POINTS} points. "
                      "Every point is a full solve. Of several punches, each output is "
                      "one punch's (a punch's centre is the spacing).</small>"),
            self.study_first.panel(), self.study_second.panel(), self.study_output,
            pn.Row(self.study_run_button, self.study_cancel_button, **stretch_row()),
            self.study_progress, self.study_status, self._chart_box, self.study_time,
            html_pane("<small>Red x: the solver flagged the point (outside the model's "
                      "validity, e.g. contact lost); grey or a gap: the point failed. The "
                      "CSV holds every output at every time.</small>", styles=NOTE_STYLE),
            self.study_csv, self.study_png, **TAB_COLUMN)

    # -- choices -------------------------------------------------------------------------
    def refresh(self, scene: dict[str, Any] | None = None) -> None:
        """Offer the fields of ``scene`` (default: the scene of the state), keeping the
        fields chosen when they are still there."""
        if scene is None:
            try:
                scene = self.state.to_scene()
            except ValueError:
                return  # not a scene now; its message comes with the solve
        self._scene = scene
        self._offer_outputs(study_outputs(scene))
        choices = {c.key: c for c in study_choices(scene)}
        if list(choices) == list(self._choices):
            self._choices = choices
            return
        self._choices = choices
        options = {c.title: c.key for c in choices.values()}
        for inputs, extra in ((self.study_first, {}), (self.study_second, {NONE: NONE})):
            keep = inputs.field.value
            inputs.field.options = extra | options
            if keep in inputs.field.options.values():
                inputs.field.value = keep
            else:
                inputs.field.value = NONE if inputs.optional else next(iter(choices), None)
                self._on_field(inputs)
        if self._wanted is not None:
            self.apply_study_settings(self._wanted)

    def _offer_outputs(self, outputs: dict[str, tuple[str, str, float]]) -> None:
        """Offer ``outputs`` (those of one punch, or of each of several), keeping the one
        chosen when it is still there (else the same quantity of the first punch, or of
        the single punch)."""
        options = {f"{n} [{u}]": k for k, (n, u, _) in outputs.items()}
        if options == self.study_output.options:
            return
        keep = self.study_output.value
        self.study_output.options = options
        if keep in outputs:
            self.study_output.value = keep
            return
        quantity = str(keep).rsplit(".", 1)[-1]
        self.study_output.value = next((k for k in outputs
                                        if k.rsplit(".", 1)[-1] == quantity),
                                       next(iter(outputs)))

    def _on_field(self, inputs: _AxisInputs) -> None:
        """A new field: its first range around the value on screen."""
        choice = self._choices.get(inputs.field.value)
        inputs.row.visible = choice is not None
        if choice is not None:
            inputs.fill(default_range(choice, self._scene))

    # -- the link ------------------------------------------------------------------------
    def study_settings(self) -> dict[str, Any] | None:
        """The parameters and output typed, as a link keeps them
        (:func:`explorer.model.view_link.study_settings`), or None when one is incomplete."""
        axes = [a for a in (self.study_first.axis(), self.study_second.axis())
                if a is not None]
        rows = [[a.key, a.start, a.stop, a.count, a.spacing] for a in axes]
        if not rows or any(r[1] != r[1] or r[2] != r[2] for r in rows):
            return None
        return {"axes": rows, "output": self.study_output.value}

    def apply_study_settings(self, settings: dict[str, Any]) -> None:
        """Show the settings of a link (checked by :func:`explorer.model.view_link.
        study_settings`); a field the scene does not offer yet is set when it does."""
        self._wanted = settings
        axes = settings["axes"]
        if any(axis[0] not in self._choices for axis in axes):
            return  # the scene on screen has not offered these fields yet
        self._wanted = None
        for inputs, axis in zip((self.study_first, self.study_second), axes + [None],
                                strict=False):
            if axis is None:
                inputs.field.value = NONE
                continue
            key, start, stop, count, spacing = axis
            inputs.field.value = key  # fills its default range first
            inputs.fill(Axis(key, start, stop, count, spacing))
        if settings["output"] in self.study_output.options.values():
            self.study_output.value = settings["output"]

    # -- running ---------------------------------------------------------------------------
    def start(self) -> bool:
        """Build the study from the scene on screen and run it; False (and the reason on
        the page) if it is refused."""
        if self.study_run.running:
            return False
        axes = [a for a in (self.study_first.axis(), self.study_second.axis())
                if a is not None]
        try:
            planned = plan_study(self.state.to_scene(), axes)
        except ValueError as exc:
            # (the core's loads and stresses in the page's units: "P = -100000 N/m")
            self._say(f"Not run: {format_error(str(exc))}", bad=True)
            return False
        self.study_run.start(planned)
        if self.study_charts is None and self._charts_built is None:
            self._charts_built = Future()
            self._off_the_loop(self._build_charts, "study-charts")
        return True

    def _off_the_loop(self, work: Callable[[], None], name: str) -> None:
        """Run ``work`` on a thread of its own on a served page (the event loop is every
        page's), at once elsewhere."""
        if self.loop.served:
            threading.Thread(target=work, name=name, daemon=True).start()
        else:
            work()

    def _build_charts(self) -> None:
        # Bokeh models outside any document: no page sees them until one is shown
        built = self._charts_built
        try:
            built.set_result(DesignChart())
        except Exception as exc:  # shown where the result is drawn
            built.set_exception(exc)

    def _say(self, text: str, bad: bool = False) -> None:
        color = "#9b1c1c" if bad else "#333"
        self.study_status.object = (f"<div class='study-message' style='font-size:13px;"
                                    f"color:{color}'>{html.escape(text)}</div>")

    def _on_run(self, *events: Any) -> None:
        run = self.study_run
        busy = run.status in ("waiting", "running")
        self.study_run_button.disabled = busy
        self.study_cancel_button.disabled = not busy
        self.study_progress.visible = busy
        self.study_progress.max = max(run.total, 1)
        self.study_progress.value = min(run.done, max(run.total, 1))
        if run.status == "done" and run.result is not None:
            # the same words whichever of the run's and the result's events comes last
            self._say(self._done_text(run.result))
        else:
            self._say(run.message, bad=run.status == "failed")

    def _done_text(self, result: Any) -> str:
        return f"Done: {self.study_run.message}. Marks: {flag_note(result)}.{_why_failed(result)}"

    def _on_result(self, event: Any) -> None:
        result = event.new
        if result is None:
            return
        # four digits ("0.4378 days", not "0.437764 days"), more where they would merge
        for digits in (4, 6, 10):
            labels = [days_text(float(t), digits) for t in result.times]
            if len(set(labels)) == len(labels):
                break
        self.study_time.options = {label: k for k, label in enumerate(labels)}
        self.study_time.value = len(result.times) - 1
        if self.study_charts is None:
            # built on a thread since the study started (a result loaded otherwise, or
            # the thread not done: then built or awaited here)
            built, self._charts_built = self._charts_built, None
            self.study_charts = DesignChart() if built is None else built.result()
        shown = self.study_charts.draw(result, self.study_output.value,
                                       self.study_time.value)
        # one figure of the three on the page, in one pane (three panes toggled by their
        # "visible" showed all three, the heat map empty, in Chromium)
        if self._chart_pane is None:
            self._chart_pane = pn.pane.Bokeh(shown, sizing_mode="stretch_width")
            self._chart_box.objects = [self._chart_pane]
        elif self._chart_pane.object is not shown:
            self._chart_pane.object = shown
        stem = slug(str(result.planned.study.base.get("name", "scene"))[:60])
        self.study_csv.filename = f"{stem}_study.csv"
        self.study_png.filename = f"{stem}_study.png"
        self.study_png.disabled = False
        self._prepare_csv(result)
        self._say(self._done_text(result))

    def _redraw(self) -> None:
        if self.study_charts is not None and self.study_time.value is not None:
            self.study_charts.show(self.study_output.value, int(self.study_time.value))

    # -- files -----------------------------------------------------------------------------
    def _prepare_csv(self, result: Any) -> None:
        """Build the result's CSV on a thread of its own (at once without a served page)
        and offer it when it is no larger than :data:`MAX_PAGE_DOWNLOAD_BYTES`."""
        self._csv_data = None
        self.study_csv.disabled = True
        self.study_csv.label = "Study data (CSV): preparing"

        def build() -> None:
            data = study_csv(result).encode("utf-8")
            self.loop.dispatch(lambda: self._offer_csv(result, data))

        self._off_the_loop(build, "study-csv")

    def _offer_csv(self, result: Any, data: bytes) -> None:
        if self.study_run.result is not result:
            return  # a newer result came meanwhile
        if len(data) > MAX_PAGE_DOWNLOAD_BYTES:
            self._csv_data = None
            self.study_csv.disabled = True
            self.study_csv.label = (f"Study data (CSV): {len(data) / 2**20:.0f} MiB, more "
                                    "than the page sends")
            self._say(f"{self._done_text(result)} The study's CSV is "
                      f"{len(data) / 2**20:.0f} MiB, more than the page sends "
                      f"({MAX_PAGE_DOWNLOAD_BYTES / 2**20:.0f} MiB): choose fewer output "
                      "times (Time tab) or points, or run the study with `coated-punch "
                      "sweep`, which writes files of any size.")
            return
        self._csv_data = data
        self.study_csv.label = "Study data (CSV)"
        self.study_csv.disabled = False

    def _csv(self) -> io.BytesIO:
        return io.BytesIO(self._csv_data or b"")

    async def _png(self) -> io.BytesIO:
        result = self.study_run.result
        if result is None:
            return io.BytesIO(b"")
        output, index = self.study_output.value, int(self.study_time.value or 0)
        # drawn off the event loop (Matplotlib: ~0.3 s), which other pages share
        return io.BytesIO(await asyncio.to_thread(design_chart_png, result, output, index))


def stretch_row() -> dict[str, Any]:
    """Keyword arguments of a full-width row without margins."""
    return {"sizing_mode": "stretch_width", "margin": 0}
