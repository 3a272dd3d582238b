"""A fix applied in the page to BokehJS: style sheets rewritten with the same text.

BokehJS (checked with 3.9.2) writes the text of a ``<style>`` element each time it
paints a renderer (``update_position``) or lays a figure out, even when the text is the
one it holds already. Writing it marks the page's styles as changed; the next renderer
then reads its colours from the computed style (``getComputedStyle``, so that CSS
variables can set them), and the browser must work out every style of the page again
first. A load step repainted ~30 renderers and recomputed the page's styles ~30 times:
~27 ms of the page's CPU per step, half of the time its figures took (measured with a
Chrome trace, benchmarks/explorer_latency.py). The fix leaves a style element alone when
its text would not change. Nothing else of BokehJS changes, and a BokehJS without the
patched method is left as it is (the page logs a warning).
"""

from __future__ import annotations

from typing import Any

from bokeh.models import CustomJS

#: Runs once per page when its document is ready (idempotent: a flag on the class).
SAME_STYLE_JS = """
const dom = (window.Bokeh && Bokeh.require) ? Bokeh.require("core/dom") : null;
const sheet = dom && dom.InlineStyleSheet;
if (!sheet || typeof sheet.prototype._update !== "function") {
  console.warn("explorer: BokehJS style sheets have changed; the repaint fix is not applied");
} else if (!sheet.prototype._update.__same_text_skipped) {
  const write = sheet.prototype._update;
  const update = function (css) {
    if (this.el.textContent !== css) write.call(this, css);
  };
  update.__same_text_skipped = true;
  sheet.prototype._update = update;
}
"""


def install(doc: Any) -> bool:
    """Apply the fix in the page of Bokeh document ``doc`` once it is ready; False
    (nothing done) when there is no document (a notebook, a script)."""
    if doc is None or not hasattr(doc, "js_on_event"):
        return False
    doc.js_on_event("document_ready", CustomJS(code=SAME_STYLE_JS))
    return True
