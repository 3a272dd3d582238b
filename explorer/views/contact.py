"""Where the contact figures sit on the page, and when they are sent to it.

The contact width plot and the inset of small features join the page the first time a
result needs them (a lift-off; a wear patch, a step, a crown), then stay and are only
hidden: every figure on the first page costs its models and its render before the first
paint, and most scenes need neither.
"""

from __future__ import annotations

from typing import Any

import panel as pn

from ..model import ResultView, lifts_off
from ..plots import Figures


class ContactPanes:
    """Two slots: the inset beside the drawing, the width plot under the histories."""

    def __init__(self, figures: Figures, panes: list[Any]) -> None:
        """``panes``: the page's list of Bokeh panes (pushed in a notebook); the new
        panes are added to it when they are made."""
        self.figures = figures
        self._panes = panes
        self.inset_slot = pn.Column(margin=0, visible=False)
        self.width_slot = pn.Column(sizing_mode="stretch_width", margin=0, visible=False)

    def update(self, view: ResultView) -> None:
        """Show the figures ``view`` needs (call after the figures drew it)."""
        f = self.figures
        self._show(self.inset_slot, f.inset_fig, bool(f.inset_fig.visible),
                   {"margin": (0, 5)})
        self._show(self.width_slot, f.contact_fig, lifts_off(view),
                   {"sizing_mode": "stretch_width", "margin": (0, 5)})

    def _show(self, slot: pn.Column, fig: Any, needed: bool, options: dict) -> None:
        if needed and not slot.objects:
            pane = pn.pane.Bokeh(fig, **options)
            self._panes.append(pane)
            slot.objects = [pane]
        slot.visible = needed
