"""The explorer page: a thin Panel view over the state, the solve controller and the plots.

``create_app()`` builds one :class:`ExplorerApp` per browser session (serve the factory,
not an instance). The page calls only the public API of ``core`` (through the
controller); every number the user sets lives in :class:`~explorer.state.ExplorerState`.
"""

from __future__ import annotations

import asyncio
import html
import io
import json
import logging
import re
from collections.abc import Callable
from typing import Any

import panel as pn
import param
from panel.io.state import set_curdoc

from core.profiles import MAX_TABLE_BYTES
from core.scene import MAX_SCENE_BYTES

from . import closed_pages, exports, gc_policy
from .controller import SolveController, format_error, worker_processes
from .creep_view import CODE_CREEP_MODELS, CodeCreepPanel
from .design import DesignLimits, check_html, design_check
from .links import decode_scene
from .panel_fixes import install as install_panel_fixes
from .plots import Figures
from .presets import DEFAULT_PRESET, preset_label, presets
from .report import report_html
from .results import ResultView
from .scales import DisplayScales
from .state import (
    CREEP_MODELS,
    MAX_DESCRIPTION_CHARS,
    MAX_NAME_CHARS,
    QUANTITIES,
    QUANTITY_UNITS,
    SCREEN_LAYERS,
    STATEMENTS,
    ExplorerState,
    check_text,
)
from .status import status_html
from .undo import UndoStack
from .view_link import read_view_query, view_query
from .widgets import (
    NAMES,
    Binding,
    BoundedUpload,
    EditableIntSlider,
    HistoryEditor,
    ProfileEditor,
    PromptIntSlider,
    fine_slider,
    slider,
)
from .workers import solve_view

log = logging.getLogger(__name__)
install_panel_fixes()

#: Time after a page connects before the sidebar tabs not yet opened are filled in the
#: background [ms]: after the first paint and a first look (see _fill_idle_tab).
FILL_TABS_AFTER_MS = 3000
#: A solve shows the busy indicator only once it has run this long [ms]. A slider step
#: is solved in 10-50 ms: its new plots are the feedback, and switching the indicator on
#: and off costs three more messages to the page per step (a sixth of the server's work
#: with 20 busy sessions, measured with py-spy).
BUSY_AFTER_MS = 250
#: The page's address follows the scene on screen at most this often [ms]: rewriting it
#: at every slider step would cost a message per step, for a link nobody copies mid-drag.
LINK_EVERY_MS = 1000
#: Geometry and material sliders apply each drag step (not only the release) while the
#: last solve took less than this [s]: then a step's answer arrives before the next step.
LIVE_SOLVE_S = 0.030

#: Which validity flags are shown next to which plot.
BADGES: dict[str, dict[str, tuple[str, str]]] = {
    # group: flag -> (text when raised, text when the check passes)
    "scene": {"thick_coating": ("coating not thin", "coating thin"),
              "stiff_coating": ("coating stiffer than base", "coating softer than base"),
              "model_error": ("coating model error above solver.model_tol",
                              "coating model within solver.model_tol")},
    "pressure": {"contact_lost": ("contact lost: q < 0 (shaded)", "full contact")},
    "history": {"large_tilt": ("large tilt", "small tilt")},
    "status": {"tol_not_met": ("tolerance not met", ""),
               "unresolved_input": ("input finer than the quadrature", "")},
}

CSS = """
.cp-badge {display: inline-block; padding: 1px 8px; margin: 2px 4px 2px 0;
           border-radius: 10px; font-size: 12px; font-weight: 600;}
.cp-bad {background: #fde2e1; color: #9b1c1c; border: 1px solid #f5a3a0;}
.cp-ok {background: #e3f5e6; color: #1d6b2c; border: 1px solid #a8dcb2;}
.cp-msg {font-size: 12px; color: #9b1c1c; margin-left: 4px; overflow-wrap: anywhere;}
.cp-status {font-size: 12px; color: #444;}
.cp-readout td, .cp-readout th {padding: 1px 8px; font-size: 13px; text-align: right;}
.cp-readout th:first-child, .cp-readout td:first-child {text-align: left;}
.cp-given {color: #777;}
"""

SPACINGS = {"linear": "linear", "log": "log"}


def _html(text: str = "", **kwargs: Any) -> pn.pane.HTML:
    """An HTML pane carrying the page's style sheet (panes render in their own shadow DOM)."""
    return pn.pane.HTML(text, stylesheets=[CSS], **kwargs)


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_").lower() or "scene"


def _fmt(value: float) -> str:
    return f"{value:.5g}" if abs(value) < 1e5 else f"{value:.4e}"


def badges_html(view: ResultView | None, group: str) -> str:
    """Validity badges of one plot group (flag names as CSS classes, messages as tooltips)."""
    if view is None:
        return ""
    parts = []
    for flag, (bad, good) in BADGES[group].items():
        if flag in view.flags:
            message = html.escape(exports.flag_message(view, flag))
            parts.append(f'<span class="cp-badge cp-bad flag-{flag}" title="{message}">'
                         f"⚠ {bad}</span><span class='cp-msg'>{message}</span>")
        elif good:
            parts.append(f'<span class="cp-badge cp-ok ok-{flag}">✓ {good}</span>')
    return "".join(parts)


def readout_html(view: ResultView | None, index: int, pinned: ResultView | None) -> str:
    """Values at the selected time: current, pinned and their difference."""
    if view is None:
        return ""
    t = float(view.times[index])
    head = "<tr><th></th><th>current</th>"
    head += "<th>pinned</th><th>change</th></tr>" if pinned is not None else "</tr>"
    rows = [head]
    j = pinned.time_index(t) if pinned is not None else 0
    for q in QUANTITIES:
        unit = QUANTITY_UNITS[q][0]
        value = float(view.display(q)[index])
        role = "given" if q in view.given else "computed"
        cls = "cp-given" if role == "given" else ""
        row = (f"<tr class='{cls}'><td>{NAMES[q]} [{unit}] ({role})</td>"
               f"<td class='readout-{q}'>{_fmt(value)}</td>")
        if pinned is not None:
            other = float(pinned.display(q)[j])
            change = f"{100 * (value - other) / abs(other):+.2f} %" if other else "n/a"
            row += f"<td class='pinned-{q}'>{_fmt(other)}</td><td>{change}</td>"
        rows.append(row + "</tr>")
    force, moment = float(view.values["force"][index]), float(view.values["moment"][index])
    ecc = f"e = M/P = {moment / force:.4g} m" if force > 0 else "e = M/P undefined (P ≤ 0)"
    return (f"<div class='readout'><b>At t = {t:.4g} days after loading</b> · {ecc}"
            f"<table class='cp-readout'>{''.join(rows)}</table></div>")


class ExplorerApp(pn.viewable.Viewer):
    """One session of the explorer: widgets, plots, status, files and the link."""

    notice = param.String(default="", doc="A problem with a file or a link (not a solve).")
    time_index = param.Integer(default=0, doc="Index of the output time shown.")

    def __init__(self, scene: dict[str, Any] | None = None, *,
                 query: dict[str, str] | None = None,
                 solve: Callable[[dict[str, Any]], Any] | None = None,
                 executor: Any = "shared", **params: Any) -> None:
        super().__init__(**params)
        self._doc = pn.state.curdoc
        self._location = pn.state.location if self._served else None
        self.state = ExplorerState()
        self.controller = SolveController(self.state, solve=solve, executor=executor,
                                          dispatch=self._dispatch, auto=False)
        self.pinned: ResultView | None = None
        self.presets = presets()
        self.scales = DisplayScales()
        self.limits = DesignLimits()
        self.undo_stack = UndoStack()
        self._undoing = False
        self._loaded_scene: dict[str, Any] | None = None
        self.figures = Figures(self.scales)
        self._drawn: ResultView | None = None
        self._busy_shown = False
        self._busy_due = False
        self._link_due = False
        self._linked = ""
        self._initial_scene(scene, query or {})
        self._build_widgets()
        self._layout = self._build_layout()
        self._wanted_index, tab, pin_scene, pin_message = read_view_query(
            query or {}, len(self.sidebar))
        if tab:
            self._fill(tab)
            self.sidebar.active = tab
        self._pin_controller: SolveController | None = None
        if pin_scene is not None:
            self._solve_pin(pin_scene)
        if pin_message and not self.notice:
            self.notice = pin_message
        # Changes to plain Bokeh models made after the page was generated but before its
        # websocket connects would never reach the browser: hold them until it does.
        self._initializing = True
        self._connected = not self._served
        if self._served:
            pn.state.onload(self._on_load)
        self.controller.param.watch(self._on_view, "view")
        self.controller.param.watch(self._on_status, ["error", "busy"])
        self.param.watch(self._on_time, "time_index")
        self.param.watch(self._on_notice, "notice")
        self.state.param.watch(self._on_revision, "revision")
        # A known answer (a preset solved at start-up) is shown before the page is sent;
        # anything else is solved in the background while the page loads.
        self.controller.start()
        if self.controller.view is None and self.controller.error:
            self._fallback_to_default()
        if self.controller.view is None:
            # a slow first solve (a link to a long history): say so, not a blank page
            self.status.object = status_html(None, True)
        self._initializing = False

    def page_parts(self) -> list[Any]:
        """Every viewable of the page: the layout and the sidebar tabs not filled yet."""
        return [self._layout] + [obj for _, objects in self._deferred_tabs.values()
                                 for obj in objects]

    # -- plumbing --------------------------------------------------------------------
    @property
    def _served(self) -> bool:
        return bool(self._doc is not None and self._doc.session_context)

    def _dispatch(self, callback: Callable[[], None]) -> None:
        """Run ``callback`` (from a solver thread) on this session's event loop, or at
        once where there is none (a notebook, a script)."""
        if self._served:
            self._later(callback, 0)
        else:
            callback()

    def _initial_scene(self, scene: dict[str, Any] | None, query: dict[str, str]) -> None:
        from core import scene_from_dict

        default = self.presets.get(DEFAULT_PRESET) or next(iter(self.presets.values()), None)
        chosen = scene
        if chosen is None and query.get("scene"):
            try:
                chosen = decode_scene(query["scene"])
                scene_from_dict(chosen)
            except ValueError as exc:
                self.notice = (f"The scene in the link was not used: {format_error(str(exc))}"
                               ". Showing the default scene instead.")
                chosen = None
        if chosen is None and query.get("preset"):
            chosen = self.presets.get(query["preset"])
            if chosen is None:
                self.notice = (f"Unknown preset {query['preset'][:40]!r} in the link; "
                               "showing the default scene.")
        chosen = chosen or default
        if chosen is not None:
            try:
                self.state.load_scene(chosen)
                self._loaded_scene = chosen
            except ValueError as exc:
                self.notice = f"The scene could not be shown: {exc}"
        self._remember()
        self._preset_key = next((k for k, s in self.presets.items() if s == chosen), None)

    def _fallback_to_default(self) -> None:
        default = self.presets.get(DEFAULT_PRESET)
        if default is None:
            return
        self.notice = (f"The scene could not be solved ({self.controller.error}); showing "
                       "the default scene instead.")
        self.scales.reset()
        self.state.load_scene(default)
        self.controller.solve_now()

    # -- widgets ---------------------------------------------------------------------
    def _fast_solves(self) -> bool:
        """Whether the last solve was quick enough for sliders to apply every drag step."""
        view = self.controller.view
        seconds = view.info.get("seconds") if view is not None else None
        return isinstance(seconds, (int, float)) and seconds < LIVE_SOLVE_S

    def _build_widgets(self) -> None:
        s = self.state
        reject = self._reject
        live = self._fast_solves
        # presets
        options = {"(custom scene)": ""}
        options.update({preset_label(k, v): k for k, v in self.presets.items()})
        self.preset = pn.widgets.Select(label="Preset scene", options=options,
                                        value=self._preset_key or "",
                                        sizing_mode="stretch_width",
                                        css_classes=["preset-select"])
        self.preset_description = pn.pane.Markdown(self._preset_text(), margin=(0, 10),
                                                   styles={"font-size": "13px"})
        self.preset.param.watch(self._on_preset, "value")

        # punch
        self.punch = Binding(reject, live_when=live)
        pb = self.punch
        self.half_width = pb.add("half_width", slider("half-width a [m]", 0.1, 5.0, 0.01,
                                                      css_classes=["punch-half-width"]))
        self.shape = pb.add("shape", pn.widgets.Select(label="base shape", options={
            "flat": "flat", "crowned (parabolic, radius R)": "parabolic",
            "wedge (slope of each face)": "wedge", "single step (height, position)": "stepped",
            "central land (raised middle)": "land",
            "wavy / rough (amplitude, wavelength)": "wavy",
            "custom table (CSV upload or file)": "custom"}, sizing_mode="stretch_width"))
        self.radius = pb.add("radius", fine_slider("crown radius R [km]", 1.0, 500.0, 0.5, "0[.]0"))
        self.slope = pb.add("slope", fine_slider("slope of each face [µrad]", 0.0, 200.0, 0.5,
                                            "0[.]0"))
        self.step_height = pb.add("step_height", fine_slider(
            "step height [µm] (right part raised)", -100.0, 100.0, 0.5, "0[.]0"))
        self.step_position = pb.add("step_position", fine_slider("step position x [m]", -1.0, 1.0,
                                                             0.01))
        self.land_height = pb.add("land_height", fine_slider(
            "land height [µm] (middle protrudes)", 0.0, 100.0, 0.5, "0[.]0"))
        self.land_width = pb.add("land_width", fine_slider("land width [m]", 0.05, 2.0, 0.01))
        self.wave_amplitude = pb.add("wave_amplitude", fine_slider("wave amplitude [µm]", 0.0, 50.0,
                                                              0.1, "0[.]0"))
        self.wave_length = pb.add("wave_length", fine_slider("wavelength [m]", 0.02, 5.0, 0.01))
        self.shape_file = BoundedUpload(accept=(".csv", ".txt"), max_bytes=MAX_TABLE_BYTES)
        self.shape_file.param.watch(self._on_shape_file, "value")
        self.shape_note = _html("", styles={"font-size": "12px", "color": "#666"})
        pb.bind(s.punch)
        s.punch.param.watch(lambda *e: self._refresh_punch(), ["shape", "half_width",
                                                              "custom_label"])

        # coating
        self.n_layers = PromptIntSlider(label="number of layers", start=1,
                                             end=SCREEN_LAYERS, value=min(s.n_layers,
                                                                          SCREEN_LAYERS),
                                             sizing_mode="stretch_width")
        self.n_layers.param.watch(lambda e: setattr(s, "n_layers", e.new), "value_throttled")
        self.layer = pn.widgets.RadioButtonGroup(label="edit layer", options=["1"], value="1",
                                                 color="primary", variant="outline",
                                                 sizing_mode="stretch_width")
        self.layer.param.watch(lambda *e: self._bind_layer(), "value")
        self.thickness_editor = ProfileEditor("thickness", "mm", 0.5, 50.0, 0.1, "0[.]00",
                                              amplitude=("µm", -1000.0, 1000.0, 0.5),
                                              css="coating-thickness", live_when=live)
        self.modulus_editor = ProfileEditor("Young's modulus", "MPa", 1.0, 10000.0, 1.0,
                                            "0[.]0", live_when=live)
        self.poisson_editor = ProfileEditor("Poisson ratio", "-", 0.0, 0.49, 0.01, "0[.]000",
                                            variations=False, live_when=live)
        self.layer_note = _html("", styles={"font-size": "12px", "color": "#666"})
        # model fidelity: layer interface, contact model, coating-model tolerance
        from explorer.fidelity_view import FidelityView
        self.fidelity = FidelityView(s, reject)
        s.param.watch(lambda *e: self._refresh_layers(), "n_layers")
        self._refresh_layers()

        # base
        self.base = Binding(reject, live_when=live)
        bb = self.base
        self.base_thickness = bb.add("thickness", slider("thickness H [m]", 0.1, 20.0, 0.05,
                                                         "0[.]00", css_classes=["base-thickness"]))
        self.base_poisson = bb.add("poisson", slider("Poisson ratio", 0.0, 0.49, 0.01))
        self.base_modulus = bb.add("modulus", slider("Young's modulus E [GPa]", 0.1, 60.0, 0.1,
                                                     "0[.]0"))
        self.creep_model = bb.add("creep_model", pn.widgets.Select(
            label="creep model", options={v: k for k, v in CREEP_MODELS.items()},
            sizing_mode="stretch_width", css_classes=["creep-select"]))
        self.compliance = bb.add("compliance", fine_slider("final creep compliance C∞ [1/GPa]",
                                                      0.0, 0.1, 0.0005, "0[.]0000"))
        self.rate = bb.add("rate", fine_slider("creep rate γ [1/day]", 0.001, 1.0, 0.001,
                                               "0[.]000"))
        self.beta = bb.add("beta", fine_slider("modulus aging β [-]", 0.0, 0.95, 0.01))
        self.alpha = bb.add("alpha", fine_slider("modulus aging rate α [1/day]", 0.001, 1.0,
                                                 0.001))
        self.aging = bb.add("aging", fine_slider("aging creep A [day/GPa]", 0.0, 5.0, 0.01,
                                            "0[.]00"))
        self.age = bb.add("age_at_loading", slider("age at loading τ₀ [days]", 1.0, 3650.0,
                                                   1.0, "0[.]0"))
        self.creep_note = _html("", styles={"font-size": "12px", "color": "#666"})
        bb.bind(s.base)
        s.base.param.watch(lambda *e: self._refresh_base(), ["creep_model", "custom"])
        # design-code creep (fib MC2010, Eurocode 2): inputs and phi(t, t0) plot
        self.code_creep = CodeCreepPanel(s.base, Binding(reject))

        # loading
        self.statement = pn.widgets.Select(label="statement (which two are given)",
                                           options=list(STATEMENTS), value=s.loading.statement,
                                           sizing_mode="stretch_width",
                                           css_classes=["statement-select"])
        self.statement.param.watch(lambda e: setattr(s.loading, "statement", e.new), "value")
        s.loading.param.watch(self._on_statement, "statement")
        self.history_editors = (HistoryEditor("load-0"), HistoryEditor("load-1"))
        self.unknowns_note = _html("", styles={"font-size": "13px"})

        # times and accuracy
        self.global_binding = Binding(reject, live_when=live)
        gb = self.global_binding
        self.time_end = gb.add("time_end", slider("time span [days after loading]", 1.0,
                                                  3650.0, 1.0, "0[.]0"))
        self.time_count = gb.add("time_count", EditableIntSlider(
            label="output times", start=2, end=200, step=1, sizing_mode="stretch_width"))
        self.time_spacing = gb.add("time_spacing", pn.widgets.RadioButtonGroup(
            label="spacing", options=list(SPACINGS), sizing_mode="stretch_width"))
        self.tol = gb.add("tol", pn.widgets.Select(
            label="accuracy target (relative)", options={f"{v:g}": v for v in
                                                        s.param.tol.objects},
            sizing_mode="stretch_width", css_classes=["tol-select"]))
        self.scene_name = gb.add("scene_name", pn.widgets.TextInput(
            label="scene name", sizing_mode="stretch_width", max_length=MAX_NAME_CHARS,
            css_classes=["scene-name"]),
            check=lambda v: check_text("scene name", v, MAX_NAME_CHARS))
        self.description = gb.add("description", pn.widgets.TextAreaInput(
            label="description (saved with the scene)", sizing_mode="stretch_width",
            max_length=MAX_DESCRIPTION_CHARS, height=90, css_classes=["scene-description"]),
            check=lambda v: check_text("description", v, MAX_DESCRIPTION_CHARS))
        gb.bind(s)
        s.param.watch(lambda *e: self._refresh_tol(), "tol")

        # files
        self.save_scene = pn.widgets.FileDownload(callback=self._scene_file,
                                                  filename="scene.json",
                                                  label="Save scene (JSON)",
                                                  color="primary",
                                                  sizing_mode="stretch_width")
        self.load_file = BoundedUpload(accept=(".json",), max_bytes=MAX_SCENE_BYTES)
        self.load_file.param.watch(self._on_scene_file, "value")
        self.csv_download = pn.widgets.FileDownload(callback=self._csv_file,
                                                    filename="results.csv",
                                                    label="Results: histories (CSV)",
                                                    sizing_mode="stretch_width")
        self.pressure_download = pn.widgets.FileDownload(callback=self._pressure_file,
                                                         filename="pressure.csv",
                                                         label="Results: q(x, t) (CSV)",
                                                         sizing_mode="stretch_width")
        self.report_download = pn.widgets.FileDownload(
            callback=self._report_file, filename="report.html", color="primary",
            label="Printable report (HTML)", sizing_mode="stretch_width",
            css_classes=["report-download"])

        # design check
        def limit(label: str, name: str, css: str) -> pn.widgets.FloatInput:
            box = pn.widgets.FloatInput(label=label, value=None, start=0,
                                        sizing_mode="stretch_width", css_classes=[css])
            box.param.watch(lambda e: setattr(self.limits, name, e.new), "value")
            return box

        self.allowable_pressure = limit("allowable bearing pressure [kPa]",
                                        "allowable_pressure", "limit-pressure")
        self.settlement_limit = limit("settlement limit [mm]", "settlement_limit",
                                      "limit-settlement")
        self.tilt_limit = limit("tilt limit [mrad]", "tilt_limit", "limit-tilt")
        self.eccentricity = pn.widgets.FloatInput(
            label="eccentricity e = M/P [m] (sets the moment)", value=None,
            sizing_mode="stretch_width", css_classes=["eccentricity-input"])
        self.eccentricity.param.watch(self._on_eccentricity, "value")
        self.design = _html("", sizing_mode="stretch_width", css_classes=["design-pane"])
        self.limits.param.watch(lambda *e: self._show_design(), list(
            n for n in self.limits.param if n != "name"))
        self.json_download = pn.widgets.FileDownload(callback=self._json_file,
                                                     filename="results.json",
                                                     label="Results: everything (JSON)",
                                                     sizing_mode="stretch_width")

        # display
        self.alert = pn.pane.Alert("", alert_type="danger", visible=False,
                                   sizing_mode="stretch_width", css_classes=["solve-error"])
        self.notice_alert = pn.pane.Alert(html.escape(self.notice), alert_type="warning",
                                          visible=bool(self.notice),
                                          sizing_mode="stretch_width",
                                          css_classes=["notice"])
        self.spinner = pn.indicators.LoadingSpinner(value=False, size=20, label="",
                                                    margin=(5, 5))
        self.status = _html("", sizing_mode="stretch_width", margin=(5, 5))
        badge = {"margin": (0, 5), "sizing_mode": "stretch_width"}
        self.scene_badges = _html("", **badge)
        self.pressure_badges = _html("", **badge)
        self.history_badges = _html("", **badge)
        self.status_badges = _html("", **badge)
        self.player = self._new_player(1, 0)
        self.player_box = pn.Row(self.player, sizing_mode="stretch_width", margin=0)
        self.time_label = _html("", margin=(12, 10))
        self.readout = _html("", sizing_mode="stretch_width")
        # The address bar is written by the page itself when this hidden box changes:
        # Panel's location model delayed an update until the next one (its push waits
        # for the document's first idle signal, which a replaced view never sees).
        self._address = pn.widgets.TextInput(value="", visible=False)
        self._address.jscallback(value="if (cb_obj.value) { window.history.replaceState("
                                       "null, '', cb_obj.value) }")
        self.undo_button = pn.widgets.Button(label="↶ Undo", disabled=True,
                                             css_classes=["undo-button"])
        self.undo_button.on_click(lambda e: self.undo())
        self.reset_button = pn.widgets.Button(label="Reset to the loaded scene",
                                              css_classes=["reset-button"])
        self.reset_button.on_click(lambda e: self.reset())
        self.classical = pn.widgets.Checkbox(label="classical solutions on q(x)",
                                             css_classes=["classical-toggle"])
        self.classical.param.watch(self._on_classical, "value")
        self.pin_button = pn.widgets.Button(label="Pin this result", color="default")
        self.unpin_button = pn.widgets.Button(label="Clear pin", color="light",
                                              disabled=True)
        self.pin_button.on_click(lambda e: self.pin())
        self.unpin_button.on_click(lambda e: self.unpin())
        self._refresh_punch()
        self._refresh_base()
        self._on_statement()
        self._refresh_tol()

    # -- layout ----------------------------------------------------------------------
    def _build_layout(self) -> pn.viewable.Viewable:
        column = {"sizing_mode": "stretch_width", "margin": (4, 0)}
        tabs = (
            ("Scene", pn.Column(
                self.preset, pn.Row(self.undo_button, self.reset_button),
                self.preset_description,
                _html("<b>Loading</b> (updates while you drag)", margin=(10, 10, 0, 10)),
                self.statement, self.history_editors[0].panel, self.history_editors[1].panel,
                self.unknowns_note, **column)),
            ("Punch", pn.Column(
                self.half_width, self.shape, self.radius, self.slope, self.step_height,
                self.step_position, self.land_height, self.land_width, self.wave_amplitude,
                self.wave_length, self.shape_note,
                _html("<small>Upload a shape table: CSV with two columns, x [m] and "
                      "f(x) [m], f the height of the punch base above its lowest point."
                      "</small>"),
                self.shape_file, **column)),
            ("Coating", pn.Column(
                _html("<small>Layer 1 touches the punch. Changes apply when you release "
                      "a slider.</small>"),
                self.n_layers, self.layer, self.layer_note, self.thickness_editor.panel,
                self.modulus_editor.panel, self.poisson_editor.panel,
                self.fidelity.interface_panel, **column)),
            ("Base", pn.Column(
                self.base_thickness, self.base_poisson, self.creep_model, self.base_modulus,
                self.compliance, self.rate, self.beta, self.alpha, self.aging, self.age,
                self.creep_note, self.code_creep.panel, **column)),
            ("Time", pn.Column(self.time_end, self.time_count, self.time_spacing, self.tol,
                               self.fidelity.solver_panel, **column)),
            ("Check", pn.Column(
                _html("<small>Limits of the design check (leave empty: not checked). "
                      "The check covers the whole history.</small>"),
                self.allowable_pressure, self.settlement_limit, self.tilt_limit,
                self.eccentricity, **column)),
            ("Files", pn.Column(
                self.report_download, self.scene_name, self.description, self.save_scene,
                _html("<small>Load a scene (the JSON the command line reads):</small>"),
                self.load_file, self.csv_download, self.pressure_download, self.json_download,
                _html("<small>Downloads hold the result on screen. The address bar holds "
                      "a link to it.</small>"), **column)),
        )
        # A served page arrives with the first tab only (a fifth of the widget models,
        # 0.4 s less to the first paint); another tab gets its widgets when first opened,
        # or a few seconds after the page, and keeps them (see _fill_idle_tab). Panel's
        # dynamic tabs would rebuild a tab at every switch:
        # measured 110 ms of server time each, which made 20 sessions 8x slower.
        self._deferred_tabs: dict[int, tuple[pn.Column, list[Any]]] = {}
        for k, (_title, content) in enumerate(tabs):
            if k and self._served:
                self._deferred_tabs[k] = (content, list(content.objects))
                content.objects = []
        sidebar = pn.Tabs(*tabs, dynamic=False, width=370, margin=(0, 10, 0, 0),
                          css_classes=["sidebar-tabs"])
        sidebar.param.watch(self._fill_tab, "active")
        sidebar.param.watch(lambda e: self._schedule_link(), "active")
        self.sidebar = sidebar
        f = self.figures
        bokeh = {"sizing_mode": "stretch_width", "margin": (0, 5)}
        self._bokeh_panes = [pn.pane.Bokeh(fig, **bokeh) for fig in (
            f.scene_fig, f.q_fig, f.image_fig, *(f.history_fig[q] for q in QUANTITIES))]
        scene_pane, q_pane, image_pane, *history_panes = self._bokeh_panes
        main = pn.Column(
            self._address,
            self.notice_alert,
            self.alert,
            pn.Row(self.spinner, self.status, sizing_mode="stretch_width"),
            self.status_badges,
            self.scene_badges,
            scene_pane,
            self.pressure_badges,
            pn.Row(q_pane, image_pane, sizing_mode="stretch_width"),
            pn.Row(self.player_box, self.time_label, sizing_mode="stretch_width"),
            pn.Row(self.readout, pn.Column(self.pin_button, self.unpin_button,
                                           self.classical),
                   sizing_mode="stretch_width"),
            self.design,
            self.history_badges,
            pn.GridBox(*history_panes, ncols=2, sizing_mode="stretch_width"),
            sizing_mode="stretch_width",
        )
        header = _html(
            "<h2 style='margin:4px 0'>Coated punch explorer</h2>"
            "<div style='font-size:13px;color:#555'>A rigid punch on thin elastic coatings "
            "over an aging viscoelastic layer (plane strain, per metre out of plane). "
            "Loads update while you drag; geometry and materials when you release.</div>",
            sizing_mode="stretch_width")
        self.header = header
        self.presenting = pn.widgets.Toggle(label="Presentation mode", width=170,
                                            css_classes=["presentation-toggle"])
        self.presenting.param.watch(self._on_presentation, "value")
        return pn.Column(pn.Row(header, self.presenting, sizing_mode="stretch_width"),
                         pn.Row(sidebar, main, sizing_mode="stretch_width"),
                         sizing_mode="stretch_width")

    def _on_presentation(self, event: Any) -> None:
        """Presentation mode: large fonts, the whole story on a 1024x768 projector."""
        on = bool(event.new)
        with pn.io.hold():
            self.figures.set_presentation(on)
            self.header.visible = not on
            self.sidebar.width = 300 if on else 370
            size = "17px" if on else ""
            for pane in (self.readout, self.status, self.design):
                pane.styles = {"font-size": size} if on else {}
        self._push()

    def __panel__(self) -> pn.viewable.Viewable:
        return self._layout

    # -- refreshers of widget visibility ---------------------------------------------
    def _preset_text(self) -> str:
        key = getattr(self, "preset", None) and self.preset.value
        scene = self.presets.get(key) if key else None
        if scene is None:
            return "Your own scene: start from a preset, a file or a link."
        return str(scene.get("description", ""))

    def _refresh_punch(self) -> None:
        p = self.state.punch
        a = p.half_width
        self.step_position.param.update(start=-a, end=a)
        shape = p.shape
        self.radius.visible = shape == "parabolic"
        self.slope.visible = shape == "wedge"
        self.step_height.visible = self.step_position.visible = shape == "stepped"
        self.land_height.visible = self.land_width.visible = shape == "land"
        self.wave_amplitude.visible = self.wave_length.visible = shape == "wavy"
        if shape == "custom":
            source = p.custom_label or "a file"
            self.shape_note.object = (f"Custom shape from {html.escape(source)}." if p.custom
                                      is not None else "Upload a CSV table below.")
        else:
            self.shape_note.object = ""
        self.shape_note.visible = bool(self.shape_note.object)
        self.shape_file.visible = True

    def _refresh_layers(self) -> None:
        n = self.state.n_layers
        shown = min(n, SCREEN_LAYERS)
        options = [str(k + 1) for k in range(shown)]
        if self.layer.value not in options:
            self.layer.value = options[-1]
        self.layer.options = options
        self.n_layers.value = shown
        self.layer_note.object = (f"This scene has {n} layers; the screen edits the first "
                                  f"{SCREEN_LAYERS}." if n > SCREEN_LAYERS else "")
        self.layer_note.visible = bool(self.layer_note.object)
        self._bind_layer()

    def _bind_layer(self) -> None:
        k = int(self.layer.value) - 1
        layer = self.state.layers[k]
        a = self.state.punch.half_width
        self.thickness_editor.bind(layer.thickness, a)
        self.modulus_editor.bind(layer.modulus, a)
        self.poisson_editor.bind(layer.poisson, a)
        self.fidelity.bind_layer(layer)

    def _refresh_base(self) -> None:
        model = self.state.base.creep_model
        creeps = model in ("exponential", "arutyunyan")
        self.compliance.visible = self.rate.visible = creeps
        self.beta.visible = self.alpha.visible = self.aging.visible = model == "arutyunyan"
        self.base_modulus.label = ("final Young's modulus E∞ [GPa]" if model == "arutyunyan"
                                   else "Young's modulus E [GPa]")
        self.base_modulus.visible = model not in ("custom", *CODE_CREEP_MODELS)
        # "other model (from file)" is offered only while the scene holds one: picked
        # without it, the base was silently solved as elastic
        offered = {v: k for k, v in CREEP_MODELS.items()
                   if k != "custom" or self.state.base.custom is not None}
        if offered != self.creep_model.options:
            self.creep_model.options = offered
        self.creep_note.object = ("A creep model from a file (kept as it is); choose another "
                                  "model to replace it." if model == "custom" else "")
        self.creep_note.visible = model == "custom"

    def _refresh_tol(self) -> None:
        options = {f"{v:g}": v for v in self.state.param.tol.objects}
        if options != self.tol.options:
            self.tol.options = options
        self.tol.value = self.state.tol

    def _on_statement(self, *events: Any) -> None:
        loading = self.state.loading
        if self.statement.value != loading.statement:
            self.statement.value = loading.statement
        for editor, q in zip(self.history_editors, loading.given, strict=True):
            editor.bind(loading.histories[q], self.state.time_end)
        unknowns = " and ".join(NAMES[q] for q in loading.unknowns)
        self.unknowns_note.object = f"Computed: <b>{unknowns}</b> (and the pressure)."

    # -- events ----------------------------------------------------------------------
    def _reject(self, message: str) -> None:
        self.notice = f"Value not accepted: {message}"

    def _on_revision(self, event: Any) -> None:
        self._remember()
        self.controller.request()

    def _remember(self) -> None:
        if self._undoing:
            return
        try:
            self.undo_stack.push(self.state.to_scene())
        except ValueError:
            return  # a state that is no scene (its message comes with the solve)
        if hasattr(self, "undo_button"):
            self.undo_button.disabled = not self.undo_stack.can_undo

    def undo(self) -> None:
        """Go back to the scene before the last change."""
        scene = self.undo_stack.undo()
        if scene is None:
            return
        self._undoing = True
        try:
            self.state.load_scene(scene)
        finally:
            self._undoing = False
        self.undo_button.disabled = not self.undo_stack.can_undo

    def reset(self) -> None:
        """Back to the scene as it was loaded (the preset, the file, the link)."""
        if self._loaded_scene is not None:
            self.state.load_scene(self._loaded_scene)

    def _on_preset(self, event: Any) -> None:
        key = event.new
        self.preset_description.object = self._preset_text()
        if not key or key not in self.presets:
            return
        self.load_scene(self.presets[key])

    def load_scene(self, scene: dict[str, Any]) -> bool:
        """Validate a scene dict with the core and show it; False (and a notice) if bad."""
        from core import scene_from_dict

        try:
            scene_from_dict(scene)
            self.state.load_scene(scene)
        except ValueError as exc:
            self.notice = f"The scene was not loaded: {format_error(str(exc))}"
            return False
        self.scales.reset()
        self._loaded_scene = scene
        self.notice = ""
        return True

    def _on_scene_file(self, event: Any) -> None:
        data = event.new
        if not data:
            return
        from core.scene import read_scene_json

        # the same limit as the command line: a browser may send up to the websocket's
        # message size, and parsing costs memory and time on the shared server
        if len(data) > MAX_SCENE_BYTES:
            self.notice = (f"The file {self.load_file.filename!r} is too large ({len(data)} "
                           f"bytes; a scene file has at most {MAX_SCENE_BYTES})")
            return
        name = self.load_file.filename or "the file"
        try:
            text = data.decode("utf-8-sig") if isinstance(data, bytes) else data
            # read as the command line reads it: a repeated field is refused, not dropped
            scene = read_scene_json(text, repr(name))
        except UnicodeDecodeError:
            self.notice = f"The file {name!r} is not text in UTF-8 (a scene file is JSON)."
            return
        except ValueError as exc:
            self.notice = f"The file {exc}"
            return
        if not isinstance(scene, dict):
            self.notice = "The file does not hold a scene (a JSON object)."
            return
        if self.load_scene(scene):
            self.preset.value = ""

    def _on_shape_file(self, event: Any) -> None:
        data = event.new
        if not data:
            return
        from core.profiles import profile_from_csv

        a = self.state.punch.half_width
        try:
            profile = profile_from_csv(data, field="punch.shape", variable="x",
                                       domain=(-a, a))
        except ValueError as exc:
            self.notice = f"The shape table was not used: {format_error(str(exc))}"
            return
        self.notice = ""
        self.state.punch.param.update(custom=profile.spec, shape="custom",
                                      custom_label=self.shape_file.filename or "a CSV file")

    def _on_notice(self, event: Any) -> None:
        # notices echo user text (file names, field names, formulas, links): the alert
        # renders Markdown, which passes raw HTML through, so the text is escaped
        self.notice_alert.object = html.escape(self.notice)
        self.notice_alert.visible = bool(self.notice)

    def _on_status(self, *events: Any) -> None:
        error = self.controller.error
        # the core's messages echo user text (see _on_notice)
        after = ("The plots still show the last good result." if self.controller.view
                 is not None else "There is no result to show yet: change the scene, or "
                 "choose a preset.")
        self.alert.object = f"**Not solved:** {html.escape(error)}  \n{after}" if error else ""
        self.alert.visible = bool(error)
        if not self.controller.busy:
            self._show_busy(False)
            self._schedule_link()  # a link skipped while busy, if no newer result came
        elif not self._served:  # no event loop to wait on: show it at once
            self._show_busy(True)
        elif not (self._busy_shown or self._busy_due):
            self._busy_due = True
            self._later(self._busy_timeout, BUSY_AFTER_MS)

    def _busy_timeout(self) -> None:
        self._busy_due = False
        if self.controller.busy:
            self._show_busy(True)

    def _show_busy(self, busy: bool) -> None:
        if busy == self._busy_shown:
            return
        self._busy_shown = busy
        self.spinner.value = busy
        self.status.object = status_html(self.controller.view, busy)

    def _on_load(self) -> None:
        self._connected = True
        if self.controller.view is not None and self.controller.view is not self._drawn:
            self._on_view(None)
        self._later(self._fill_idle_tab, FILL_TABS_AFTER_MS)

    def _fill_tab(self, event: Any) -> None:
        """Give a sidebar tab its widgets when it is first opened; they then stay."""
        self._fill(event.new)

    def _fill(self, index: int) -> None:
        content = self._deferred_tabs.pop(index, None)
        if content is not None:
            column, objects = content
            column.objects = objects

    def _fill_idle_tab(self) -> None:
        """Fill the next unopened tab, then the others one per turn of the event loop.

        Under load the server can miss a tab click (measured once in ~600 first openings
        with 20 sessions: the client showed the tab, the server never heard of it), and
        the tab stayed empty; filled in the background it cannot."""
        if self._deferred_tabs:
            self._fill(min(self._deferred_tabs))
        if self._deferred_tabs:
            self._later(self._fill_idle_tab, 0)
        elif self._served:
            # the page is complete; it lives as long as the session
            gc_policy.page_built(getattr(self._doc, "session_context", None))

    def _later(self, callback: Callable[[], None], delay_ms: float) -> None:
        """Run ``callback`` on this session's event loop after ``delay_ms`` [ms]."""
        doc = self._doc
        if doc is None or not doc.session_context:
            return

        def run() -> None:
            with set_curdoc(doc):
                callback()

        try:
            if delay_ms > 0:
                doc.add_timeout_callback(run, delay_ms)
            else:
                doc.add_next_tick_callback(run)
        except Exception:  # the session was closed meanwhile (a result, a timer)
            log.debug("callback dropped: session gone")

    def _on_view(self, event: Any) -> None:
        view = self.controller.view
        if view is None or not (self._connected or self._initializing):
            return
        n = len(view.times)
        old = self._drawn
        if old is None and self._wanted_index is not None:
            index = min(self._wanted_index, n - 1)  # the time the link was made at
        elif old is None or len(old.times) != n:
            index = n - 1
        else:
            index = min(self.time_index, n - 1)
        self._drawn = view
        with pn.io.hold():
            self.figures.show(view, index, self.pinned)
            if old is None or len(old.times) != n:
                self._replace_player(max(n - 1, 1), index)
            else:
                self.player.value = index
            with param.discard_events(self):
                self.time_index = index
            self._show_time_texts(view, index)
            self.status.object = status_html(view, self._busy_shown)
            self.scene_badges.object = badges_html(view, "scene")
            self.pressure_badges.object = badges_html(view, "pressure")
            self.history_badges.object = badges_html(view, "history")
            self.status_badges.object = badges_html(view, "status")
            self._show_design()
            slug = _slug(str(view.scene.get("name", "scene"))[:60])
            self.save_scene.filename = f"{slug}.json"
            self.csv_download.filename = f"{slug}_results.csv"
            self.pressure_download.filename = f"{slug}_pressure.csv"
            self.json_download.filename = f"{slug}_results.json"
            self.report_download.filename = f"{slug}_report.html"
        self._push()
        self._schedule_link()

    def _schedule_link(self) -> None:
        if self._location is not None and self._drawn is not None and not self._link_due:
            self._link_due = True
            self._later(self._update_link, LINK_EVERY_MS)

    def _update_link(self) -> None:
        """Put the scene on screen into the page's address (a link that reproduces it)."""
        self._link_due = False
        view = self._drawn
        if view is None or self._location is None or self.controller.busy:
            return  # a newer result is coming, and will ask again
        try:
            pin = self.pinned.scene if self.pinned is not None else None
            query = view_query(view.scene, self.time_index, self.sidebar.active, pin)
            # the whole query at once: the values are URL-safe already (base64url, digits)
            link = "?" + "&".join(f"{k}={v}" for k, v in query.items() if v)
            if link != self._linked:
                self._address.value = link
                self._linked = link
        except Exception:  # the link is a convenience; the page must not fail for it
            log.exception("could not update the link")

    def _on_time(self, event: Any) -> None:
        view = self._drawn
        if view is None:
            return
        index = min(max(int(event.new), 0), len(view.times) - 1)
        with pn.io.hold():
            self.figures.show_time(view, index, self.pinned)
            self._show_time_texts(view, index)
        self._push()
        self._schedule_link()

    def _show_time_texts(self, view: ResultView, index: int) -> None:
        self.time_label.object = (f"<span class='time-label'>t = "
                                  f"{float(view.times[index]):.4g} days</span>")
        self.readout.object = readout_html(view, index, self.pinned)

    def _solve_pin(self, scene: dict[str, Any]) -> None:
        """Solve the pinned scene of a link (off the page's thread), then pin it."""
        from core import scene_from_dict

        state = ExplorerState()
        try:
            scene_from_dict(scene)
            state.load_scene(scene)
        except ValueError as exc:
            self.notice = f"The pinned result in the link was not used: {format_error(str(exc))}"
            return
        executor = self.controller.executor
        self._pin_controller = SolveController(state, executor=executor,
                                               dispatch=self._dispatch, auto=False)
        self._pin_controller.param.watch(self._on_pin_view, "view")
        self._pin_controller.request()

    def _on_pin_view(self, event: Any) -> None:
        if event.new is not None:
            self.pinned = event.new
            self.unpin_button.disabled = False
            self._redraw_pin()

    def _on_classical(self, event: Any) -> None:
        with pn.io.hold():
            self.figures.set_classical(self._drawn, self.time_index, bool(event.new))
        self._push()

    def _show_design(self) -> None:
        view = self._drawn
        self.design.object = check_html(design_check(view, self.limits)) if view else ""

    def _on_eccentricity(self, event: Any) -> None:
        """Set the moment so that M = e P (force and moment given, constant force)."""
        e = event.new
        loading = self.state.loading
        if e is None:
            return
        force = loading.histories["force"]
        if loading.given != ("force", "moment") or force.kind != "constant":
            self.notice = ("Value not accepted: the eccentricity sets the moment when force "
                           "and moment are given and the force is constant.")
            return
        moment = loading.histories["moment"]
        moment.param.update(kind="constant", value=float(e) * force.value)

    def _report_file(self) -> io.StringIO:
        view = self._shown()
        if view is None:
            return io.StringIO("")
        index = min(self.time_index, len(view.times) - 1)
        return io.StringIO(report_html(view, self.limits, index,
                                       self.scales.pressure_unit(view)))

    def _new_player(self, end: int, value: int) -> pn.widgets.Player:
        player = pn.widgets.Player(label="time", start=0, end=end, value=value, interval=250,
                                   loop_policy="once", show_loop_controls=False,
                                   sizing_mode="stretch_width", show_value=False,
                                   css_classes=["time-player"])
        player.param.watch(lambda e: setattr(self, "time_index", int(e.new)), "value")
        return player

    def _replace_player(self, end: int, value: int) -> None:
        """A new player for a new number of output times: the page's player redraws its
        range only when its value changes, so a new range with the same value (or a value
        arriving before the range) left the old range on screen."""
        self.player = self._new_player(end, value)
        self.player_box.objects = [self.player]

    def pin(self) -> None:
        """Keep the result on screen for comparison with the next ones."""
        self.pinned = self._drawn
        self.unpin_button.disabled = self.pinned is None
        self._redraw_pin()
        self._schedule_link()

    def unpin(self) -> None:
        self.pinned = None
        self.unpin_button.disabled = True
        self._redraw_pin()
        self._schedule_link()

    def _redraw_pin(self) -> None:
        view = self._drawn
        if view is None:
            return
        with pn.io.hold():
            self.figures.show_pinned(view, self.pinned, self.time_index)
            self._show_time_texts(view, self.time_index)
        self._push()

    def _push(self) -> None:
        """In a notebook, plain Bokeh models changed in place must be pushed by hand."""
        if not self._served and self._bokeh_panes:
            pn.io.push_notebook(*self._bokeh_panes)

    # -- files -------------------------------------------------------------------------
    def _shown(self) -> ResultView | None:
        return self._drawn

    def _scene_file(self) -> io.StringIO:
        view = self._shown()
        scene = view.scene if view is not None else self.state.to_scene()
        return io.StringIO(json.dumps(scene, indent=2) + "\n")

    async def _download(self, kind: str, empty: str) -> io.StringIO:
        # awaited, not waited for: the worker's answer must not hold the event loop, and
        # with it every page of the server
        view = self._shown()
        if view is None:
            return io.StringIO(empty)
        try:
            return io.StringIO(await asyncio.wrap_future(
                self.controller.download_later(view, kind)))
        except Exception as exc:
            # no file is better than a wrong one; say why on the page
            self.alert.object = f"**Download failed:** {html.escape(str(exc))}"
            self.alert.visible = True
            raise

    def _csv_file(self) -> io.StringIO:
        view = self._shown()
        return io.StringIO(exports.histories_csv(view) if view is not None else "")

    def _pressure_file(self) -> io.StringIO:
        view = self._shown()
        if view is None:
            return io.StringIO("")
        return io.StringIO(exports.pressure_csv(view, self.scales.pressure_unit(view)))

    async def _json_file(self) -> io.StringIO:
        return await self._download("to_json", "{}")


def warm_up(keys: tuple[str, ...] = (DEFAULT_PRESET,)) -> None:
    """Solve some presets now, so that the first visitors find them in the caches."""
    available = presets()
    for key in keys:
        scene = available.get(key)
        if scene is None:
            continue
        state = ExplorerState()
        state.load_scene(scene)
        SolveController(state, executor=None, auto=False).solve_now()
        processes = worker_processes()
        if processes is not None and processes.lanes > 1:
            # the first solve warmed one worker; the others get the same caches
            processes.run_everywhere(solve_view, state.to_scene())


def _query_from_session() -> dict[str, str]:
    """The page's query arguments (first value of each, as text)."""
    out: dict[str, str] = {}
    for key, values in (pn.state.session_args or {}).items():
        if values:
            raw = values[0]
            out[key] = raw.decode("utf-8", "replace") if isinstance(raw, bytes) else str(raw)
    return out


def create_app(**kwargs: Any) -> ExplorerApp:
    """A new explorer session (serve this factory so each browser gets its own state).

    Served, it solves off the page's thread (in the server's worker processes when
    ``python -m explorer`` started them, else on a shared thread pool); inline in a
    notebook (no server session) it solves in the kernel, each change when it happens.
    """
    pn.extension("filedropper", notifications=False)
    served = bool(pn.state.curdoc is not None and pn.state.curdoc.session_context)
    kwargs.setdefault("executor", "shared" if served else None)
    if served:
        pn.state.on_session_destroyed(gc_policy.session_ended)
    if "query" not in kwargs:
        kwargs["query"] = _query_from_session()
    app = ExplorerApp(**kwargs)
    if served:
        pn.state.on_session_destroyed(closed_pages.page_releaser(app.page_parts))
    return app
