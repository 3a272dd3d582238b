"""The report as a PDF: the same sections as the HTML report on A4 pages, and the same
plots (:func:`core.report.plots.report_layout`) drawn with Matplotlib.

The plots are HoloViews elements with Bokeh options (the HTML report's); they are drawn
here element by element (curves and shaded spans, in their Bokeh colours), not through
HoloViews' Matplotlib backend, which took ~8 s of CPU for the three plots of a preset
(its layout engine drew the figure to fit it, and each plot set Matplotlib's settings
again); drawn directly, the whole report takes 1.5-3 s (measured on three presets).
"""

from __future__ import annotations

import io
import os
import textwrap
from collections.abc import Mapping
from typing import Any

import numpy as np

from core.optional import import_optional
from core.report.content import scene_json, sections
from core.report.plots import report_layout
from core.scene import PunchesSolution, SceneSolution, holoviews_for_bokeh

#: A4 portrait [inch].
PAGE = (8.27, 11.69)
#: Lines of text on a page, and characters on a line, at the font size used.
LINES_PER_PAGE = 62
CHARACTERS_PER_LINE = 100
COLOURS = {"bad": "#9b1c1c", "good": "#1d6b2c", "": "#222222"}
#: Values of a plot below this in its shown unit (mm, mrad, kPa, m) are round-off: a
#: plot of nothing larger is drawn flat at zero (else Matplotlib spreads ~1e-18 over the
#: axis with an offset, as if the tilt of a centred load varied).
ROUND_OFF_SHOWN = 1e-9


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


def text_pages(lines: list[tuple[str, str, bool]]) -> list[list[tuple[str, str, bool]]]:
    """``lines`` cut into pages of :data:`LINES_PER_PAGE`, no page starting with a blank
    line (the blank after the last section made a blank page when the text ended at a
    page's end)."""
    pages: list[list[tuple[str, str, bool]]] = []
    for line in lines:
        if not pages or len(pages[-1]) == LINES_PER_PAGE:
            if not line[0]:
                continue
            pages.append([])
        pages[-1].append(line)
    return pages


def _text_pages(pdf, plt, lines: list[tuple[str, str, bool]], size: float = 8.5,
                keep_last: bool = False) -> tuple[Any, float] | None:
    """Write ``lines`` on pages of their own; with ``keep_last``, the last page is not
    written but returned with how far down it is filled (share of the page from its top,
    where what follows may go on), None without lines."""
    pages = text_pages(lines)
    for number, page in enumerate(pages):
        figure = plt.figure(figsize=PAGE)
        for k, (text, tone, bold) in enumerate(page):
            figure.text(0.07, 0.95 - k * 0.9 / LINES_PER_PAGE, text, fontsize=size,
                        color=COLOURS.get(tone, "#222222"), family="DejaVu Sans",
                        weight="bold" if bold else "normal", va="top")
        if keep_last and number == len(pages) - 1:
            return figure, 0.05 + len(page) * 0.9 / LINES_PER_PAGE
        pdf.savefig(figure)
        plt.close(figure)
    return None


def _style(element: Any) -> dict[str, Any]:
    """The Bokeh style options of a HoloViews element (its colour, alpha)."""
    return dict(element.opts.get("style", backend="bokeh").kwargs)


def _axis_labels(item: Any, curves: list[Any]) -> tuple[str, str]:
    """The x and y labels of a plot: its own (an overlay's, set because its spans would
    name the axes x and y), else its first curve's dimensions with their units."""
    given = item.opts.get("plot", backend="bokeh").kwargs
    first = curves[0] if curves else None
    x = given.get("xlabel") or (first.kdims[0].pprint_label if first is not None else "")
    y = given.get("ylabel") or (first.vdims[0].pprint_label if first is not None else "")
    return x, y


def _draw(axes: Any, item: Any, title: str) -> None:
    """One plot of the layout on ``axes``: its shaded spans under its curves."""
    hv = holoviews_for_bokeh("the PDF report")  # loaded already: the layout's elements

    elements = list(item) if isinstance(item, hv.Overlay) else [item]
    for span in (e for e in elements if isinstance(e, hv.VSpan)):
        lo, hi = span.data
        style = _style(span)
        axes.axvspan(lo, hi, color=style.get("color", "#dddddd"), alpha=style.get("alpha", 0.5),
                     linewidth=0, zorder=0)
    curves = [e for e in elements if isinstance(e, hv.Curve)]
    drawn = []
    for curve in curves:
        colour = _style(curve).get("color")
        if not isinstance(colour, str):
            # a curve without a colour of its own takes HoloViews' next default, as in
            # the HTML report
            cycle = list(getattr(colour, "values", None) or ["#30a2da"])
            colour = cycle[len(drawn) % len(cycle)]
        y = np.asarray(curve.dimension_values(1), dtype=float)
        drawn.append(y)
        axes.plot(curve.dimension_values(0), y, color=colour, linewidth=1.4,
                  label=curve.label or None, zorder=2)
    x_label, y_label = _axis_labels(item, curves)
    axes.set_xlabel(x_label, fontsize=8)
    axes.set_ylabel(y_label, fontsize=8)
    axes.set_title(title, fontsize=9)
    axes.tick_params(labelsize=7)
    axes.grid(True, color="#e5e5e5", linewidth=0.6)
    axes.margins(x=0)
    axes.ticklabel_format(axis="y", useOffset=False)
    values = np.concatenate(drawn) if drawn else np.zeros(0)
    values = values[np.isfinite(values)]
    if values.size:
        largest = float(np.max(np.abs(values)))
        if largest < ROUND_OFF_SHOWN:
            # round-off about zero (the tilt of a centred load): drawn flat at zero, not
            # magnified to the round-off
            axes.set_ylim(-1.0, 1.0)
        elif float(np.ptp(values)) <= ROUND_OFF_SHOWN * largest:
            # a history that does not change: flat at its value
            axes.set_ylim(float(np.min(values)) - 0.05 * largest,
                          float(np.max(values)) + 0.05 * largest)
    if any(curve.label for curve in curves):
        axes.legend(fontsize=6.5, loc="best", frameon=False)


def plots_height(layout: Any) -> float:
    """The share of an A4 page the report's plots take, two a row, each row ~3 inches."""
    rows = max(1, -(-len(list(layout)) // 2))
    return min(0.88, rows * 0.29)


#: Room between the last line of text and the plots' titles below it [share of the page].
PLOTS_GAP = 0.05


def _plot_page(plt: Any, layout: Any, titles: list[str], figure: Any = None,
               top: float = 0.93) -> Any:
    """The report's plots, two a row, on one A4 page (a figure: ``figure``, whose text
    ends above ``top``, or a new page)."""
    items = list(layout)
    rows = max(1, -(-len(items) // 2))
    figure = plt.figure(figsize=PAGE) if figure is None else figure
    height = plots_height(items)
    grid = figure.add_gridspec(rows, 2, left=0.09, right=0.96, top=top, bottom=top - height,
                               hspace=0.55, wspace=0.32)
    for k, item in enumerate(items):
        axes = figure.add_subplot(grid[k // 2, k % 2])
        _draw(axes, item, titles[k] if k < len(titles) else "")
    return figure


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
    # Matplotlib first: its extra, report, brings HoloViews too (asked for first, the
    # plot extra was named, and after it the report extra)
    import_optional("matplotlib", "the PDF report")
    import_optional("holoviews", "the PDF report")
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages

    lines = _text_lines(result, time, check, calibration)
    layout, titles = report_layout(result, time)
    buffer = io.BytesIO()
    with PdfPages(buffer, metadata={"Title": f"Report: {result.scene.name or 'scene'}",
                                    "Creator": "coated-punch"}) as pdf:
        # the plots below the last lines of text where they fit (a page of five lines
        # and a page of plots after it read as a page left blank)
        last = _text_pages(pdf, plt, lines, keep_last=True)
        if last is not None and 0.95 - last[1] - PLOTS_GAP - plots_height(layout) >= 0.04:
            figure = _plot_page(plt, layout, titles, last[0], 0.95 - last[1] - PLOTS_GAP)
        else:
            if last is not None:
                pdf.savefig(last[0])
                plt.close(last[0])
            figure = _plot_page(plt, layout, titles)
        pdf.savefig(figure)
        plt.close(figure)
        _text_pages(pdf, plt, scene_lines(result), size=6.5)
    return buffer.getvalue()


def scene_lines(result: SceneSolution | PunchesSolution) -> list[tuple[str, str, bool]]:
    """The lines of the PDF's last pages: the scene file (SI units) under its heading,
    wrapped to the page."""
    scene = [(line, "", False) for raw in scene_json(result).splitlines()
             for line in (textwrap.wrap(raw, CHARACTERS_PER_LINE + 20,
                                        subsequent_indent="      ") or [""])]
    return [("Scene file (SI units)", "", True), *scene]


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
