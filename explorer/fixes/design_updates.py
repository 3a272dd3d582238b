"""A widget's or pane's changed parameter, sent without the theme worked out again.

Panel (checked with 1.9.4) turns each parameter change of a component on the page into
the properties of its Bokeh model in ``Reactive._update_properties``. That method first
works out the design's properties for the component (``Design.params``: the theme's
modifiers, its style sheets, each path of them resolved on disk) and uses them only to
put the theme's style sheets in front of new ``stylesheets``. For any other change (a
slider's value, a pane's visibility, a button's label) the work is thrown away; a load
step makes it for every widget and pane it changes: ~3 % of the server's CPU of a step
(py-spy, the uniform_flat preset in Chromium).

Here the design is worked out only when ``stylesheets`` changed; the properties sent are
the same (a test compares both ways on a slider, a pane and a style-sheet change).
"""

from __future__ import annotations

import inspect
import logging
from typing import Any

log = logging.getLogger(__name__)

_INSTALLED = False

#: The method as Panel 1.9.4 has it, line by line (its body is checked before replacing).
_CHECKED_BODY = (
    "params, _ = self._design.params(self, doc) if self._design else ({}, None)",
    "changes = {event.name: event.new for event in events}",
    "if 'stylesheets' in changes and 'stylesheets' in params:",
    "changes['stylesheets'] = params['stylesheets'] + changes['stylesheets']",
    "return self._process_param_change(changes)",
)


def update_properties(self: Any, *events: Any, doc: Any) -> dict[str, Any]:
    """Panel's ``Reactive._update_properties`` with the design worked out only for a
    change of the style sheets (the only use it had)."""
    changes = {event.name: event.new for event in events}
    if "stylesheets" in changes and self._design:
        params, _ = self._design.params(self, doc)
        if "stylesheets" in params:
            changes["stylesheets"] = params["stylesheets"] + changes["stylesheets"]
    return self._process_param_change(changes)


def install() -> bool:
    """Replace Panel's ``Reactive._update_properties`` once per process; False if Panel's
    method differs from the one checked (nothing is replaced, and a warning says so)."""
    global _INSTALLED
    if _INSTALLED:
        return True
    from panel.reactive import Reactive

    original = Reactive.__dict__.get("_update_properties")
    try:
        lines = inspect.getsource(original).splitlines()[1:] if original else []
    except (OSError, TypeError):
        lines = []
    body = tuple(line.strip() for line in lines if line.strip())
    if body != _CHECKED_BODY:
        log.warning("Panel's property updates have changed; the theme is worked out at "
                    "each change as Panel does")
        return False
    update_properties.__wrapped__ = original  # type: ignore[attr-defined]
    Reactive._update_properties = update_properties
    _INSTALLED = True
    return True
