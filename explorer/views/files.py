"""The Files tab: scene name and description, saving and loading scenes, downloads."""

from __future__ import annotations

import asyncio
import html
import io
import json
from collections.abc import Callable
from typing import Any

import panel as pn

from core.scene import MAX_SCENE_BYTES, read_scene_json

from ..files import histories_csv, pressure_csv
from ..model import (
    MAX_DESCRIPTION_CHARS,
    MAX_NAME_CHARS,
    DesignLimits,
    DisplayScales,
    ExplorerState,
    ResultView,
    Screen,
    check_text,
    scene_with_limits,
)
from ..solving import SolveController
from .style import TAB_COLUMN, html_pane, slug
from .widgets import Binding, BoundedUpload, PromptTextAreaInput, PromptTextInput


class FilesView:
    """The scene file (save, load) and the result files of the result on screen."""

    title = "Files"

    def __init__(self, state: ExplorerState, screen: Screen, controller: SolveController,
                 scales: DisplayScales, limits: DesignLimits,
                 load_scene: Callable[[dict[str, Any]], bool],
                 show_error: Callable[[str], None]) -> None:
        """``screen``: the result the downloads hold, and where a refused file is said;
        ``controller``: solves the JSON download and the reports again (in the worker
        that solves this session's scenes); ``scales`` and ``limits``: the units of the
        CSV files and the design check of the saved scene and the reports; ``load_scene``:
        shows a scene read from a file (False if refused); ``show_error``: says on the
        page why a download failed."""
        self.state = s = state
        self.screen = screen
        self.controller = controller
        self.scales = scales
        self.limits = limits
        self.load_scene = load_scene
        self.show_error = show_error
        self.naming = Binding(screen.reject)
        self.scene_name = self.naming.add("scene_name", PromptTextInput(
            label="scene name", sizing_mode="stretch_width", max_length=MAX_NAME_CHARS,
            css_classes=["scene-name"]),
            check=lambda v: check_text("scene name", v, MAX_NAME_CHARS))
        self.description = self.naming.add("description", PromptTextAreaInput(
            label="description (saved with the scene)", sizing_mode="stretch_width",
            max_length=MAX_DESCRIPTION_CHARS, height=90, css_classes=["scene-description"]),
            check=lambda v: check_text("description", v, MAX_DESCRIPTION_CHARS))
        self.naming.bind(s)
        stretch = {"sizing_mode": "stretch_width"}
        self.save_scene = pn.widgets.FileDownload(callback=self._scene_file,
                                                  filename="scene.json",
                                                  label="Save scene (JSON)", color="primary",
                                                  **stretch)
        self.load_file = BoundedUpload(accept=(".json",), max_bytes=MAX_SCENE_BYTES,
                                       css="scene-upload")
        self.load_file.param.watch(self._on_scene_file, "value")
        self.csv_download = pn.widgets.FileDownload(callback=self._csv_file,
                                                    filename="results.csv",
                                                    label="Results: histories (CSV)", **stretch)
        self.pressure_download = pn.widgets.FileDownload(callback=self._pressure_file,
                                                         filename="pressure.csv",
                                                         label="Results: q(x, t) (CSV)",
                                                         **stretch)
        # the command line's report (core.report), built in the worker: the plots are
        # Bokeh's and Matplotlib's, and the file records version, scene and settings
        self.report_download = pn.widgets.FileDownload(
            callback=self._report_file, filename="report.html", color="primary",
            label="Printable report (HTML)", css_classes=["report-download"], **stretch)
        self.pdf_report_download = pn.widgets.FileDownload(
            callback=self._pdf_report_file, filename="report.pdf",
            label="Printable report (PDF)", css_classes=["report-pdf-download"], **stretch)
        self.json_download = pn.widgets.FileDownload(callback=self._json_file,
                                                     filename="results.json",
                                                     label="Results: everything (JSON)",
                                                     **stretch)

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(
            self.report_download, self.pdf_report_download,
            self.scene_name, self.description, self.save_scene,
            html_pane("<small>Load a scene (the JSON the command line reads):</small>"),
            self.load_file,
            self.csv_download, self.pressure_download,
            self.json_download,
            html_pane("<small>Downloads hold the result on screen. The address bar holds "
                      "a link to it.</small>"), **TAB_COLUMN)

    def name_files(self, view: ResultView) -> None:
        """Name the downloads after the scene on screen."""
        stem = slug(str(view.scene.get("name", "scene"))[:60])
        self.save_scene.filename = f"{stem}.json"
        self.csv_download.filename = f"{stem}_results.csv"
        self.pressure_download.filename = f"{stem}_pressure.csv"
        self.json_download.filename = f"{stem}_results.json"
        self.report_download.filename = f"{stem}_report.html"
        self.pdf_report_download.filename = f"{stem}_report.pdf"

    # -- loading ---------------------------------------------------------------------
    def _on_scene_file(self, event: Any) -> None:
        data = event.new
        if data is None:  # (cleared before each file: the same file again is new)
            return
        try:
            self._read_scene_file(data)
        finally:
            # accepted or refused, the box is ready for the next file: a refused file
            # left a green "Upload complete" beside the refusal, and a second file could
            # be dropped only after removing the first
            self.load_file.clear()

    def _read_scene_file(self, data: bytes) -> None:
        screen = self.screen
        # the same limit as the command line: a browser may send up to the websocket's
        # message size, and parsing costs memory and time on the shared server
        if len(data) > MAX_SCENE_BYTES:
            screen.notice = (f"The file {self.load_file.filename!r} is too large ({len(data)} "
                             f"bytes; a scene file has at most {MAX_SCENE_BYTES})")
            return
        name = self.load_file.filename or "the file"
        try:
            text = data.decode("utf-8-sig") if isinstance(data, bytes) else data
            # read as the command line reads it: a repeated field is refused, not dropped
            scene = read_scene_json(text, repr(name))
        except UnicodeDecodeError:
            screen.notice = f"The file {name!r} is not text in UTF-8 (a scene file is JSON)."
            return
        except ValueError as exc:
            screen.notice = f"The file {exc}"
            return
        if not isinstance(scene, dict):
            screen.notice = "The file does not hold a scene (a JSON object)."
            return
        self.load_scene(scene)

    # -- downloads -------------------------------------------------------------------
    def _scene_file(self) -> io.StringIO:
        view = self.screen.shown()
        scene = view.scene if view is not None else self.state.to_scene()
        # the limits typed in the Check tab, as the command line checks them (Pa, m, rad)
        return io.StringIO(json.dumps(scene_with_limits(scene, self.limits), indent=2) + "\n")

    async def _fetch(self, kind: str, report: bool = False) -> str | bytes | None:
        """The file ``kind`` of the result on screen from the worker (None without one);
        a report is checked against the Check tab's limits, describes the time on screen
        and gives the coating model's error the FE check measured, if it was run on it."""
        view = self.screen.shown()
        if view is None:
            return None
        # the Check tab's limits in every file's scene, with the check they give
        options: dict[str, Any] = {"limits": self.limits}
        if report:
            index = min(self.screen.time_index, len(view.times) - 1)
            # the FE check's measurement, where it was made for this scene (the report
            # itself decides: core.scene.model_error_evidence)
            fit = self.screen.fit
            options = {"limits": self.limits, "shown_time": float(view.times[index]),
                       "check": self.screen.model_check,
                       # the fit, while the scene on screen is its fitted scene
                       "calibration": fit.calibration
                       if fit is not None and fit.describes(view.scene) else None}
        # awaited, not waited for: the worker's answer must not hold the event loop, and
        # with it every page of the server
        try:
            return await asyncio.wrap_future(
                self.controller.download_later(view, kind, **options))
        except Exception as exc:
            # no file is better than a wrong one; say why on the page
            self.show_error(f"**Download failed:** {html.escape(str(exc))}")
            raise

    # The CSV files are written on a thread: q on 201 points at 2000 output times is ~8 MB
    # of text, time the event loop (every page's) would spend on one download.
    async def _csv_file(self) -> io.StringIO:
        view = self.screen.shown()
        if view is None:
            return io.StringIO("")
        if view.several:  # every punch's columns, in SI units (the core's file)
            return io.StringIO(str(await self._fetch("to_csv") or ""))
        return io.StringIO(await asyncio.to_thread(histories_csv, view, self.limits,
                                                   self.screen.model_check))

    async def _pressure_file(self) -> io.StringIO:
        view = self.screen.shown()
        if view is None:
            return io.StringIO("")
        if view.several:  # q on every punch's zone, global x, in Pa (the core's file)
            return io.StringIO(str(await self._fetch("pressure_csv") or ""))
        unit = self.scales.pressure_unit(view)
        return io.StringIO(await asyncio.to_thread(pressure_csv, view, unit, self.limits,
                                                   self.screen.model_check))

    async def _json_file(self) -> io.StringIO:
        text = await self._fetch("to_json")
        return io.StringIO("{}" if text is None else str(text))

    async def _report_file(self) -> io.StringIO:
        text = await self._fetch("report_html", report=True)
        return io.StringIO("" if text is None else str(text))

    async def _pdf_report_file(self) -> io.BytesIO:
        data = await self._fetch("report_pdf", report=True)
        return io.BytesIO(data if isinstance(data, bytes) else b"")
