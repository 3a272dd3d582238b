"""The explorer page: a thin Panel view over the state, the solve controller and the plots.

``create_app()`` builds one :class:`ExplorerApp` per browser session (serve the factory,
not an instance). The page calls only the public API of ``core`` (through the
controller); every number the user sets lives in :class:`~explorer.model.state.ExplorerState`.
The widgets live in the views of :mod:`explorer.views`, one per sidebar tab and one for
the results; ``SIDEBAR_VIEWS`` is the one place where the tabs are assembled.
"""

from __future__ import annotations

import html
import logging
from collections.abc import Callable
from typing import Any

import panel as pn
import param
from panel.io.state import set_curdoc

from core import scene_from_dict

from .fixes import bokeh_fixes, closed_pages, gc_policy, idle_painter, panel_fixes
from .model import (
    DEFAULT_PRESET,
    DesignLimits,
    DisplayScales,
    ExplorerState,
    ResultView,
    decode_scene,
    presets,
    read_study_query,
    read_view_query,
)
from .plots import Figures
from .solving import SolveController, format_error, install_websocket_marks, mark, warm_up
from .views import (
    BADGES,
    BUSY_AFTER_MS,
    CSS,
    FILL_TABS_AFTER_MS,
    LINK_EVERY_MS,
    AddressLink,
    BaseView,
    BusyIndicator,
    CheckView,
    CoatingView,
    DeferredTabs,
    FidelityView,
    FilesView,
    LessonsView,
    PinsView,
    PunchView,
    ResultsView,
    SceneHistory,
    SceneView,
    StudyView,
    TimesView,
    badges_html,
    html_pane,
    readout_html,
    status_html,
)

__all__ = ["BADGES", "BUSY_AFTER_MS", "CSS", "FILL_TABS_AFTER_MS", "LINK_EVERY_MS",
           "ExplorerApp", "SIDEBAR_VIEWS", "badges_html", "create_app", "readout_html",
           "warm_up"]

log = logging.getLogger(__name__)
panel_fixes.install()
install_websocket_marks()

#: Geometry and material sliders apply each drag step (not only the release) while the
#: last solve took less than this much CPU time [s]: then a step's answer arrives before
#: the next step. CPU time, not wall time: on a shared server the wall time of the same
#: scene swings 2-3x with what others run, and the sliders would turn live and back from
#: one step to the next; the CPU time is what the scene costs. A step that still arrives
#: late costs no backlog: the controller runs one solve at a time and keeps only the
#: newest request.
LIVE_SOLVE_S = 0.030

#: The sidebar's tabs, in their order on the page: each a view class taking the session
#: (with a ``title`` and a ``content()`` column). A new tab is one more entry here; the
#: index of a tab is part of the page's links (``view_link``), so append, do not insert.
SIDEBAR_VIEWS: tuple[type, ...] = (SceneView, PunchView, CoatingView, BaseView, TimesView,
                                   CheckView, FilesView, LessonsView, StudyView)
#: Names the views share; never looked up on the session (see ExplorerApp.__getattr__).
_VIEW_COMMON = frozenset({"app", "title", "content", "refresh"})


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
        self._location = pn.state.location if self.served else None
        self.state = ExplorerState()
        self.controller = SolveController(self.state, solve=solve, executor=executor,
                                          dispatch=self._dispatch, auto=False)
        self.presets = presets()
        self.scales = DisplayScales()
        self.limits = DesignLimits()
        self.history = SceneHistory(self)
        self.figures = Figures(self.scales)
        self._drawn: ResultView | None = None
        self.busy = BusyIndicator(self)
        self._views: list[Any] = []
        self._initial_scene(scene, query or {})
        self.link = AddressLink(self)
        self.pins = PinsView(self)
        self.results = ResultsView(self)
        # model fidelity (layer interface, contact model, coating-model tolerance): one
        # view whose widgets sit in the Coating and Time tabs
        self.fidelity = FidelityView(self.state, self.reject)
        self.views = [view(self) for view in SIDEBAR_VIEWS]
        self._views = [self.results, self.pins, *self.views]
        self._layout = self._build_layout()
        self._wanted_index, tab, pin_scenes, pin_message = read_view_query(
            query or {}, len(self.sidebar))
        if tab:
            self.tabs.fill(tab)
            self.sidebar.active = tab
        if pin_scenes:
            self.pins.solve_from_link(pin_scenes)
        if pin_message and not self.notice:
            self.notice = pin_message
        study_settings, study_message = read_study_query(query or {})
        if study_settings is not None:
            self.apply_study_settings(study_settings)
        if study_message and not self.notice:
            self.notice = study_message
        # Changes to plain Bokeh models made after the page was generated but before its
        # websocket connects would never reach the browser: hold them until it does.
        self._initializing = True
        self._connected = not self.served
        if self.served:
            pn.state.onload(self._on_load)
        self.controller.param.watch(self._on_view, "view")
        self.controller.param.watch(self.busy.on_status, ["error", "busy"])
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
            self.results.status.object = status_html(None, True)
        self._initializing = False

    def __getattr__(self, name: str) -> Any:
        """The widgets and file callbacks of the views, by the names they had on the
        session before the page was split into views (``app.load_file``, ``app.alert``)."""
        views = self.__dict__.get("_views") or ()
        if not name.startswith("__") and name not in _VIEW_COMMON:
            for view in views:
                if name in vars(view) or name in type(view).__dict__:
                    return getattr(view, name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def page_parts(self) -> list[Any]:
        """Every viewable of the page: the layout and the sidebar tabs not filled yet."""
        return [self._layout, *self.tabs.parts()]

    @property
    def busy_shown(self) -> bool:
        """Whether the page shows the busy indicator now."""
        return self.busy.shown

    # -- plumbing --------------------------------------------------------------------
    @property
    def _served(self) -> bool:
        return bool(self._doc is not None and self._doc.session_context)

    @property
    def served(self) -> bool:
        """Whether this session is a served page (not a notebook or a script)."""
        return self._served

    def shown(self) -> ResultView | None:
        """The result on screen (the downloads, the check and the report hold it)."""
        return self._drawn

    def _dispatch(self, callback: Callable[[], None]) -> None:
        """Run ``callback`` (from a solver thread) on this session's event loop, or at
        once where there is none (a notebook, a script)."""
        if self.served:
            self._later(callback, 0)
        else:
            callback()

    def _initial_scene(self, scene: dict[str, Any] | None, query: dict[str, str]) -> None:
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
                self.history.loaded = chosen
            except ValueError as exc:
                self.notice = f"The scene could not be shown: {exc}"
        self.history.remember()
        self.preset_key = next((k for k, s in self.presets.items() if s == chosen), None)

    def _fallback_to_default(self) -> None:
        default = self.presets.get(DEFAULT_PRESET)
        if default is None:
            return
        self.notice = (f"The scene could not be solved ({self.controller.error}); showing "
                       "the default scene instead.")
        self.scales.reset()
        self.state.load_scene(default)
        self.controller.solve_now()

    def fast_solves(self) -> bool:
        """Whether the last solve was quick enough for sliders to apply every drag step."""
        view = self.controller.view
        if view is None:
            return False
        # CPU time of the whole solve (see LIVE_SOLVE_S); a result kept from before it
        # was recorded has its wall time only
        seconds = view.info.get("cpu_seconds", view.info.get("seconds"))
        return isinstance(seconds, (int, float)) and seconds < LIVE_SOLVE_S

    # -- layout ----------------------------------------------------------------------
    def _build_layout(self) -> pn.viewable.Viewable:
        self.tabs = DeferredTabs(self, [(view.title, view.content()) for view in self.views])
        sidebar = self.tabs.sidebar
        sidebar.param.watch(lambda e: self.link.schedule(), "active")
        self.sidebar = sidebar
        header = html_pane(
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
                         pn.Row(sidebar, self.results.content(), sizing_mode="stretch_width"),
                         sizing_mode="stretch_width")

    def _on_presentation(self, event: Any) -> None:
        """Presentation mode: large fonts, the whole story on a 1024x768 projector."""
        on = bool(event.new)
        with pn.io.hold():
            self.figures.set_presentation(on)
            self.header.visible = not on
            self.sidebar.width = 300 if on else 370
            self.results.set_presentation(on)
        self.results.push()

    def __panel__(self) -> pn.viewable.Viewable:
        return self._layout

    # -- events ----------------------------------------------------------------------
    def reject(self, message: str) -> None:
        """Say on the page that a value typed or dragged was refused, and why."""
        self.notice = f"Value not accepted: {message}"

    def undo(self) -> None:
        """Go back to the scene before the last change."""
        self.history.undo()

    def reset(self) -> None:
        """Back to the scene as it was loaded (the preset, the file, the link)."""
        self.history.reset()

    def _on_revision(self, event: Any) -> None:
        mark("revision")
        self.history.remember()
        self.controller.request()

    def load_scene(self, scene: dict[str, Any]) -> bool:
        """Validate a scene dict with the core and show it; False (and a notice) if bad."""
        try:
            scene_from_dict(scene)
            self.state.load_scene(scene)
        except ValueError as exc:
            self.notice = f"The scene was not loaded: {format_error(str(exc))}"
            return False
        self.scales.reset()
        self.history.loaded = scene
        self.notice = ""
        return True

    def _on_notice(self, event: Any) -> None:
        # notices echo user text (file names, field names, formulas, links): the alert
        # renders Markdown, which passes raw HTML through, so the text is escaped
        self.notice_alert.object = html.escape(self.notice)
        self.notice_alert.visible = bool(self.notice)

    def _on_load(self) -> None:
        self._connected = True
        if self.controller.view is not None and self.controller.view is not self._drawn:
            self._on_view(None)
        self._later(self.tabs.fill_idle, FILL_TABS_AFTER_MS)

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
        self.pins.on_result(view)
        with pn.io.hold():
            self.results.draw(view, index, new_range=old is None or len(old.times) != n)
            self.files_view.name_files(view)
            mark("drawn")  # the patch goes out as the hold ends
        self.results.push()
        self.link.schedule()

    @property
    def files_view(self) -> FilesView:
        """The Files tab (it names the downloads after the scene on screen)."""
        return next(v for v in self.views if isinstance(v, FilesView))

    def _on_time(self, event: Any) -> None:
        view = self._drawn
        if view is None:
            return
        index = min(max(int(event.new), 0), len(view.times) - 1)
        with pn.io.hold():
            self.figures.show_time(view, index, self.pins.board.pins)
            self.results.show_time_texts(view, index)
        self.results.push()
        self.link.schedule()


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
        bokeh_fixes.install(pn.state.curdoc)
        idle_painter.install(pn.state.curdoc)
    if "query" not in kwargs:
        kwargs["query"] = _query_from_session()
    app = ExplorerApp(**kwargs)
    if served:
        pn.state.on_session_destroyed(closed_pages.page_releaser(app.page_parts))
    return app
