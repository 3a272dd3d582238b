"""A printable report of the result on screen: one self-contained HTML file.

It holds what an engineer files with a check: the inputs (the scene, in the units on
screen, and the scene file itself), a drawing, the plots (inline SVG, so it prints sharp
and needs no network or script), the design check, the validity flags with their
explanations, the units, the solver's accuracy statement and the project's version.
Built from a :class:`~explorer.model.results.ResultView` only (no solve). No Panel import.
"""

from __future__ import annotations

import html
import json
from datetime import datetime, timezone

import numpy as np

from ..model import (
    QUANTITIES,
    QUANTITY_UNITS,
    DesignLimits,
    ResultView,
    check_html,
    contact_text,
    contact_widths,
    design_check,
    lifts_off,
)
from .exports import accuracy_statement, flag_lines, project_version

_W, _H, _PAD = 460, 200, 42

CSS = """
body {font-family: Helvetica, Arial, sans-serif; font-size: 12px; margin: 18px; color: #222;}
h1 {font-size: 18px; margin: 0 0 4px 0;} h2 {font-size: 14px; margin: 16px 0 4px 0;}
table {border-collapse: collapse;} td, th {padding: 2px 8px; border-bottom: 1px solid #ddd;
text-align: left;} .flag {color: #9b1c1c; font-weight: bold;} .ok {color: #1d6b2c;}
.plots {display: flex; flex-wrap: wrap; gap: 8px;} svg {border: 1px solid #ccc;}
pre {font-size: 10px; white-space: pre-wrap; word-break: break-all;}
.cp-bad {color: #9b1c1c; font-weight: bold;} .cp-ok {color: #1d6b2c;}
@media print {body {margin: 8mm;} .plots {page-break-inside: avoid;}}
"""


def _svg_line(x: np.ndarray, series: list[tuple[np.ndarray, str]], title: str,
              xlabel: str, ylabel: str, css: str = "") -> str:
    """A small line plot as SVG: ``series`` of (y, colour) over ``x``."""
    x = np.asarray(x, dtype=float)
    ys = [np.asarray(y, dtype=float) for y, _ in series]
    x0, x1 = float(np.min(x)), float(np.max(x))
    y0 = min(0.0, *(float(np.min(y)) for y in ys))
    y1 = max(0.0, *(float(np.max(y)) for y in ys))
    if x1 <= x0:
        x1 = x0 + 1.0
    if y1 <= y0:
        y1 = y0 + 1.0
    w, h = _W - 2 * _PAD, _H - 2 * _PAD

    def px(v: np.ndarray) -> np.ndarray:
        return _PAD + (v - x0) / (x1 - x0) * w

    def py(v: np.ndarray) -> np.ndarray:
        return _PAD + (1 - (v - y0) / (y1 - y0)) * h

    lines = []
    for (_, colour), yy in zip(series, ys, strict=True):
        points = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(px(x), py(yy), strict=True))
        lines.append(f"<polyline fill='none' stroke='{colour}' stroke-width='1.6' "
                     f"points='{points}'/>")
    zero = float(py(np.array(0.0)))
    return (f"<svg class='{css}' width='{_W}' height='{_H}' viewBox='0 0 {_W} {_H}' "
            f"xmlns='http://www.w3.org/2000/svg'>"
            f"<text x='{_W / 2}' y='16' text-anchor='middle' font-weight='bold'>"
            f"{html.escape(title)}</text>"
            f"<line x1='{_PAD}' x2='{_W - _PAD}' y1='{zero:.1f}' y2='{zero:.1f}' "
            f"stroke='#999'/>{''.join(lines)}"
            f"<text x='{_PAD}' y='{_H - 8}'>{x0:.4g}</text>"
            f"<text x='{_W - _PAD}' y='{_H - 8}' text-anchor='end'>{x1:.4g}</text>"
            f"<text x='{_W / 2}' y='{_H - 8}' text-anchor='middle'>{html.escape(xlabel)}"
            f"</text><text x='4' y='{_PAD - 6}'>{y1:.4g}</text>"
            f"<text x='4' y='{_H - _PAD + 12}'>{y0:.4g}</text>"
            f"<text x='{_PAD}' y='30'>{html.escape(ylabel)}</text></svg>")


def _drawing(view: ResultView) -> str:
    """The punch base and the coating thickness across the punch (exaggerated)."""
    g = view.geometry
    total = np.sum(g.thickness, axis=0) * 1e3 if g.thickness else np.zeros_like(g.x)
    return (_svg_line(g.x, [(g.shape * 1e6, "#333")], "Punch base f(x) above its lowest "
                      "point [µm]", "x [m]", "µm", "report-drawing")
            + _svg_line(g.x, [(total, "#2b7bb9")], "Coating thickness, all layers [mm]",
                        "x [m]", "mm"))


def _inputs(view: ResultView) -> str:
    scene = view.scene
    rows = [("name", scene.get("name", "")), ("description", scene.get("description", "")),
            ("punch half-width a", f"{scene['punch']['half_width']:g} m"),
            ("coating layers", str(len(scene.get("coating", [])))),
            ("base thickness H", f"{scene['base']['thickness']:g} m"),
            ("base creep model", str(scene["base"]["creep"].get("model"))),
            ("base age at loading", f"{scene['base']['age_at_loading']:g} days"),
            ("given", ", ".join(view.given)),
            ("accuracy target", f"{scene.get('solver', {}).get('tol', 1e-6):g}")]
    for q in view.given:
        unit, size = QUANTITY_UNITS[q]
        spec = scene["loading"][q]
        text = f"{spec / size:.6g} {unit}" if isinstance(spec, (int, float)) else \
            json.dumps(spec)
        rows.append((f"{q} history", text))
    return "<table>" + "".join(f"<tr><td>{html.escape(k)}</td><td>{html.escape(str(v))}</td>"
                               f"</tr>" for k, v in rows) + "</table>"


def report_html(view: ResultView, limits: DesignLimits | None = None,
                index: int | None = None, unit: tuple[str, float] = ("kPa", 1e3)) -> str:
    """The report of ``view`` (``index``: the output time of the q(x) plot, default the
    last; ``unit``: the pressure unit on screen) as a complete HTML document."""
    index = len(view.times) - 1 if index is None else index
    name, size = unit
    t = float(view.times[index])
    flags = flag_lines(view)
    flag_block = ("<p class='ok'>No validity flag: the model stands behind this result.</p>"
                  if not flags else "<p class='flag'>This result is flagged; the model "
                  "cannot fully stand behind it:</p><ul>" + "".join(
                      f"<li class='flag report-flag'>{html.escape(f)}</li>" for f in flags)
                  + "</ul>")
    plots = [_drawing(view), _svg_line(view.x, [(view.pressure[:, index] / size, "#1f77b4")],
                                       f"Contact pressure q(x) at t = {t:.4g} days",
                                       "x [m]", f"q [{name}]", "report-pressure")]
    for q in QUANTITIES:
        u = QUANTITY_UNITS[q][0]
        role = "given" if q in view.given else "computed"
        plots.append(_svg_line(view.times, [(view.display(q), "#1f77b4")],
                               f"{q} [{u}] ({role})", "t [days after loading]", u))
    if lifts_off(view):
        widths = contact_widths(view)
        lifted = 2 * view.geometry.half_width - widths
        plots.append(_svg_line(view.times, [(widths, "#08306b"), (lifted, "#d62728")],
                               "contact width (navy) and lift-off length (red) [m]",
                               "t [days after loading]", "m", "report-contact"))
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    title = html.escape(str(view.scene.get("name", "scene")))
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>Report: {title}"
            f"</title><style>{CSS}</style></head><body>"
            f"<h1>Coated punch: {title}</h1>"
            f"<div>coated-punch {html.escape(project_version())} · {stamp} · plane strain, "
            f"per metre out of plane</div>"
            f"<h2>Validity</h2>{flag_block}"
            f"<h2>Accuracy</h2><p class='report-accuracy'>"
            f"{html.escape(accuracy_statement(view))}</p>"
            f"<h2>Design check</h2>{check_html(design_check(view, limits))}"
            f"<p class='report-contact-text'>At t = {t:.4g} days: "
            f"{html.escape(contact_text(view, index))}</p>"
            f"<h2>Inputs</h2>{_inputs(view)}"
            f"<h2>Drawing and plots</h2><div class='plots'>{''.join(plots)}</div>"
            f"<h2>Units</h2><p>x in m from the punch centre; t in days after loading; "
            f"pressure in {name} (compression positive); settlement mm, tilt mrad, force "
            f"kN/m, moment kN·m/m.</p>"
            f"<h2>Scene file (SI units)</h2><pre>{html.escape(json.dumps(view.scene))}</pre>"
            f"</body></html>")
