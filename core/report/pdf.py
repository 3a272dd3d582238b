"""The report as a PDF: the same sections as the HTML report on A4 pages, and the same
plots (:func:`core.report.plots.report_layout`) rendered by HoloViews' Matplotlib
backend."""

from __future__ import annotations

import io
import os
import textwrap
import warnings
from collections.abc import Mapping
from typing import Any

from core.optional import import_optional
from core.report.content import scene_json, sections
from core.report.plots import matplotlib_layout, report_layout
from core.scene import PunchesSolution, SceneSolution

#: A4 portrait [inch].
PAGE = (8.27, 11.69)
#: Lines of text on a page, and characters on a line, at the font size used.
LINES_PER_PAGE = 62
CHARACTERS_PER_LINE = 100
COLOURS = {"bad": "#9b1c1c", "good": "#1d6b2c", "": "#222222"}


def _text_lines(result: SceneSolution | PunchesSolution, time: float | None,
                check: Mapping[str, Any] | None = None,
                calibration: Any = None) -> list[tuple[str, str, bool]]:
    """(text, tone, bold) lines of the report's sections."""
    lines: list[tuple[str, str, bool]] = [
        (f"Coated punch: {result.scene.name or 'scene'}", "", True), ("", "", False)]
    for section in sections(result, time, check, calibration):
        lines.append((section.title, "", True))
        if section.lead:
            lines.extend((t, section.tone, False)
                         for t in textwrap.wrap(section.lead, CHARACTERS_PER_LINE))
        for label, value in section.rows:
            wrapped = textwrap.wrap(f"{label}: {value}", CHARACTERS_PER_LINE,
                                    subsequent_indent="    ")
            lines.extend((t, "", False) for t in wrapped)
        for note in section.notes:
            lines.extend((t, section.tone, False)
                         for t in textwrap.wrap(note, CHARACTERS_PER_LINE))
        lines.append(("", "", False))
    return lines


def _text_pages(pdf, plt, lines: list[tuple[str, str, bool]], size: float = 8.5) -> None:
    for start in range(0, len(lines), LINES_PER_PAGE):
        figure = plt.figure(figsize=PAGE)
        for k, (text, tone, bold) in enumerate(lines[start:start + LINES_PER_PAGE]):
            figure.text(0.07, 0.95 - k * 0.9 / LINES_PER_PAGE, text, fontsize=size,
                        color=COLOURS.get(tone, "#222222"), family="DejaVu Sans",
                        weight="bold" if bold else "normal", va="top")
        pdf.savefig(figure)
        plt.close(figure)


def report_pdf(result: SceneSolution | PunchesSolution, time: float | None = None,
               check: Mapping[str, Any] | None = None, calibration: Any = None) -> bytes:
    """The report of ``result`` as PDF bytes (the sections, the plots, the scene file).

    ``time`` [day after loading], ``check`` (a :func:`core.scene.check_scene` report),
    ``calibration`` (a :class:`core.back_analysis.Calibration`): as for
    :func:`core.report.report_html`.

    Raises
    ------
    ValueError
        When ``time`` is not within the output times.
    MissingDependency
        Without Matplotlib or HoloViews (the ``report`` extra).
    """
    hv = import_optional("holoviews", "the PDF report")
    import_optional("matplotlib", "the PDF report")
    import matplotlib

    matplotlib.use("Agg", force=False)
    import holoviews.plotting.mpl  # noqa: F401  (registers the Matplotlib backend)
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages

    lines = _text_lines(result, time, check, calibration)
    layout, titles = report_layout(result, time)
    buffer = io.BytesIO()
    with PdfPages(buffer, metadata={"Title": f"Report: {result.scene.name or 'scene'}",
                                    "Creator": "coated-punch"}) as pdf:
        _text_pages(pdf, plt, lines)
        layout = matplotlib_layout(layout.opts(fig_inches=PAGE[0] - 1.5, sublabel_format="",
                                               backend="matplotlib"))
        with warnings.catch_warnings():
            # HoloViews hands Matplotlib's span a colour beside its face colour, and the
            # colour wins (the face colour alone came out blue once Bokeh had drawn the
            # same layout): both are the shade (matplotlib_layout)
            warnings.filterwarnings("ignore", message="Setting the 'color' property")
            figure = hv.render(layout, backend="matplotlib")
        # the plots' titles are Bokeh options; the same words here
        for axes, title in zip(figure.axes, titles, strict=False):
            axes.set_title(title, fontsize=10)
        pdf.savefig(figure, bbox_inches="tight")
        plt.close(figure)
        scene = [(line, "", False) for raw in scene_json(result).splitlines()
                 for line in (textwrap.wrap(raw, CHARACTERS_PER_LINE + 20,
                                            subsequent_indent="      ") or [""])]
        _text_pages(pdf, plt, [("Scene file (SI units)", "", True), *scene], size=6.5)
    return buffer.getvalue()


def write_report(result: SceneSolution | PunchesSolution, path: str | os.PathLike,
                 time: float | None = None, check: Mapping[str, Any] | None = None,
                 calibration: Any = None) -> None:
    """Write the report of ``result`` to ``path``: PDF for a ``.pdf`` name, else HTML
    (``time`` [day after loading], ``check``, ``calibration``: as for
    :func:`core.report.report_html`)."""
    from core.files import atomic_write_bytes, atomic_write_text
    from core.report.html import report_html

    if str(path).lower().endswith(".pdf"):
        atomic_write_bytes(path, report_pdf(result, time, check, calibration))
    else:
        atomic_write_text(path, report_html(result, time, check, calibration))
