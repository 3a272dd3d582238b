"""The page's style sheet and the HTML pane that carries it."""

from __future__ import annotations

import re
from typing import Any

import panel as pn

CSS = """
.cp-badge {display: inline-block; padding: 1px 8px; margin: 2px 4px 2px 0;
           border-radius: 10px; font-size: 12px; font-weight: 600;}
.cp-bad {background: #fde2e1; color: #9b1c1c; border: 1px solid #f5a3a0;}
.cp-ok {background: #e3f5e6; color: #1d6b2c; border: 1px solid #a8dcb2;}
.cp-msg {font-size: 12px; color: #9b1c1c; margin-left: 4px; overflow-wrap: anywhere;}
.coating-check-stale {opacity: 0.45;}
.readout-scroll {overflow-x: auto; max-width: 100%;}
.cp-change {font-size: 0.85em; color: #666;}
.readout-scroll::-webkit-scrollbar {height: 8px;}
.readout-scroll::-webkit-scrollbar-track {background: #f0f0f0;}
.readout-scroll::-webkit-scrollbar-thumb {background: #b0b0b0; border-radius: 4px;}
.readout-scroll .cp-readout td:first-child, .readout-scroll .cp-readout th:first-child
  {position: sticky; left: 0; background: var(--background-color, #fff); z-index: 1;
   min-width: 9em;}
.readout-scroll .cp-readout td:not(:first-child) {white-space: nowrap;}
.cp-status {font-size: 12px; color: #444;}
.cp-status.model-flagged {color: #9b1c1c; font-weight: 600;}
.cp-readout td, .cp-readout th {padding: 1px 8px; font-size: 13px; text-align: right;}
.cp-readout th:first-child, .cp-readout td:first-child {text-align: left;}
.cp-given {color: #777;}
.design-check .cp-readout td.check-heading {text-align: left; padding: 10px 0 2px 0;}
.design-check .cp-readout td.check-footer {text-align: left; padding: 0 0 4px 0;}
.readout {overflow-x: auto;}
.time-label {display: inline-block; min-width: 15.5em; white-space: nowrap;}
"""

#: Style of the small grey notes under a group of widgets.
NOTE_STYLE = {"font-size": "12px", "color": "#666"}
#: Keyword arguments of the column that holds one sidebar tab.
TAB_COLUMN = {"sizing_mode": "stretch_width", "margin": (4, 0)}


def set_shown(pane: Any, shown: bool) -> None:
    """Show or take off ``pane`` (a Panel object or a Bokeh figure) by its element's inline
    ``display`` style, leaving its ``visible`` alone.

    A change of ``visible`` (of any layout property) asks BokehJS to lay the page out
    again; a change of ``styles`` restyles the one element, and the browser's own layout
    places it. A preset switch between an elastic answer and one over time toggles five
    panes: by ``visible`` it took ~120 ms longer in Chromium (measured with
    ``benchmarks.explorer_latency --switches-only``, bare_layer 604 -> 480 ms).
    """
    if is_shown(pane) != shown:
        pane.styles = {**pane.styles, "display": None if shown else "none"}


def is_shown(pane: Any) -> bool:
    """Whether :func:`set_shown` left ``pane`` on the page."""
    return (pane.styles or {}).get("display") != "none"


class TextPane(pn.pane.HTML):
    """An HTML pane whose new text reaches the page as its text alone.

    Panel's pane works out every property of its model (styles, style sheets, the
    theme's modifiers) at each change of its text, and sets them all again on the model:
    about 1 ms of the server's CPU per text, and a load step changes four to eight texts
    (the readout, the status line, the badges, the design check). Here a change of the
    text (the only thing that reaches :meth:`_update`: Panel re-renders a pane there for
    a change of ``object`` or of how it is sanitised) sets the model's ``text`` only, as
    Panel would have made it; every other parameter reaches the model as before.
    """

    def _update(self, ref: str, model: Any) -> None:
        if self.enable_streaming:
            super()._update(ref, model)
            return
        model.update(text=self._transform_object(self.object)["object"])


def html_pane(text: str = "", **kwargs: Any) -> pn.pane.HTML:
    """An HTML pane carrying the page's style sheet (panes render in their own shadow DOM),
    whose text changes cost the server little (:class:`TextPane`)."""
    return TextPane(text, stylesheets=[CSS], **kwargs)


def slug(text: str) -> str:
    """A file-name-safe form of a scene name (``"scene"`` when nothing is left)."""
    return re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_").lower() or "scene"
