"""The report as one self-contained HTML file: the sections, the plots
(:func:`core.report.plots.report_layout`) rendered by Bokeh with its library inline (the
file opens and prints with no network), and the scene file itself."""

from __future__ import annotations

import html
import re
from collections.abc import Mapping
from typing import Any

from core.optional import import_optional
from core.report.content import Section, scene_json, sections
from core.report.plots import readings_overlay, report_layout
from core.scene import PunchesSolution, SceneSolution

CSS = """
body {font-family: Helvetica, Arial, sans-serif; font-size: 12px; margin: 18px; color: #222;
      max-width: 1100px;}
h1 {font-size: 18px; margin: 0 0 4px 0;} h2 {font-size: 14px; margin: 16px 0 4px 0;}
table {border-collapse: collapse;} td {padding: 2px 8px; border-bottom: 1px solid #ddd;
text-align: left; vertical-align: top;} td:first-child {white-space: nowrap;}
.bad {color: #9b1c1c; font-weight: bold;} .good {color: #1d6b2c;}
pre {font-size: 10px; white-space: pre-wrap; word-break: break-all;}
@media print {body {margin: 8mm;} .report-plots {page-break-inside: avoid;}}
"""


def _section(section: Section) -> str:
    tone = f" class='{section.tone}'" if section.tone else ""
    slug = "report-" + section.title.lower().replace(" ", "-")
    parts = [f"<section class='{slug}'><h2>{html.escape(section.title)}</h2>"]
    if section.lead:
        parts.append(f"<p{tone}>{html.escape(section.lead)}</p>")
    if section.rows:
        parts.append("<table>" + "".join(
            f"<tr><td>{html.escape(label)}</td><td>{html.escape(value)}</td></tr>"
            for label, value in section.rows) + "</table>")
    parts.extend(f"<p>{html.escape(note)}</p>" for note in section.notes)
    return "".join(parts) + "</section>"


def _plots(result: SceneSolution | PunchesSolution, time: float | None,
           calibration: Any = None) -> tuple[str, str, str]:
    """The plots as (scripts for the page head, the body's markup, the markup of the
    readings over the settlement history: empty without ``calibration``)."""
    hv = import_optional("holoviews", "the report's plots")
    embed = import_optional("bokeh.embed", "the report's plots")
    resources = import_optional("bokeh.resources", "the report's plots")
    layout, _ = report_layout(result, time)
    models = [hv.render(layout, backend="bokeh")]
    if calibration is not None and calibration.readings.settlement is not None:
        models.append(hv.render(readings_overlay(result, calibration), backend="bokeh"))
    script, divs = embed.components(models)
    return _standalone(resources.INLINE.render()) + script, divs[0], "".join(divs[1:])


#: An empty script element loading its source: ``src`` quoted either way or not.
_LOADED_SCRIPT = re.compile(
    r"""<script\b[^>]*?\ssrc\s*=\s*(?:"([^"]*)"|'([^']*)'|([^"'\s>]+))[^>]*>\s*</script>\s*""",
    re.IGNORECASE)
#: An address with a scheme (``https:``, ``data:``) or from another host (``//``).
_ABSOLUTE = re.compile(r"[a-z][a-z0-9+.-]*:|//", re.IGNORECASE)


def _standalone(head: str) -> str:
    """``head`` (Bokeh's resources, inline) without scripts loaded from an address with
    no scheme (relative, or from the root of a server): nothing answers those beside a
    report file. Where Panel is imported (the command line's report loads HoloViews,
    which loads it) Bokeh's resources carry Panel's module shim as
    ``static/extensions/panel/...``; the report's plots need only the inline Bokeh
    library."""
    def kept(found: re.Match[str]) -> str:
        source = next(group for group in found.groups() if group is not None)
        return found.group(0) if _ABSOLUTE.match(source) else ""

    return _LOADED_SCRIPT.sub(kept, head)


def report_html(result: SceneSolution | PunchesSolution, time: float | None = None,
                check: Mapping[str, Any] | None = None, calibration: Any = None) -> str:
    """The report of ``result`` as a complete HTML document (text).

    Parameters
    ----------
    result : SceneSolution or PunchesSolution
        A solved scene; its limits (if the scene sets any) are checked in the report (of
        several punches: under each punch, :mod:`core.report.punches`).
    time : float, optional
        A time t [day after loading] the reader chose: the contact at the output time
        nearest to it is described, and its q(x) drawn (default: the last output time).
    check : mapping, optional
        A report of :func:`core.scene.check_scene`: made for this scene, its measured
        coating-model error is reported next to the estimate and overrides it (the
        ``model_error`` flag); a check of another scene is ignored.
    calibration : Calibration, optional
        A back-analysis (:func:`core.calibrate`) whose fitted scene ``result`` solves: a
        section "Back-analysis" (the readings, the fitted values with their standard
        errors, correlations, chi^2/dof, warnings) and the settlement readings drawn over
        the settlement history.

    Returns
    -------
    str
        The document: validity, design check, key results with units, accuracy, the
        inputs, the plots of q(x, t), settlement and tilt (and of the contact width when
        the punch lifts off, of the punch base and the coating where they vary), and the
        scene file.

    Raises
    ------
    ValueError
        When ``time`` is not within the output times.
    MissingDependency
        Without HoloViews or Bokeh (the ``report`` extra).
    """
    text = sections(result, time, check, calibration)
    head, plots, fit_plot = _plots(result, time, calibration)
    title = html.escape(str(result.scene.name or "scene"))
    body = "".join(_section(s) + (f"<div class='report-readings'>{fit_plot}</div>"
                                  if s.title == "Back-analysis" else "") for s in text)
    return (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<title>Report: {title}</title><style>{CSS}</style>{head}</head><body>"
            f"<h1>Coated punch: {title}</h1>{body}"
            f"<section class='report-plots'><h2>Plots</h2>{plots}</section>"
            f"<section class='report-scene'><h2>Scene file (SI units)</h2>"
            f"<pre>{html.escape(scene_json(result))}</pre></section></body></html>")
