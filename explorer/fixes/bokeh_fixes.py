"""Eight fixes applied in the page to BokehJS: style sheets rewritten with the same text,
the page's layout computed once per frame (and not for a closed tab), also after a view
renders itself again, colours and line
styles no longer read back from the computed style at each paint, a renderer's place
written on its element rather than into a style sheet, a figure's base font size read
once, a canvas layer cleared to its edges, and a figure off the page not laid out.

**Style sheets.** BokehJS (checked with 3.9.2) writes the text of a ``<style>`` element
each time it paints a renderer (``update_position``) or lays a figure out, even when the
text is the one it holds already. Writing it marks the page's styles as changed; the next renderer
then reads its colours from the computed style (``getComputedStyle``, so that CSS
variables can set them), and the browser must work out every style of the page again
first. A load step repainted ~30 renderers and recomputed the page's styles ~30 times:
~27 ms of the page's CPU per step, half of the time its figures took (measured with a
Chrome trace, benchmarks/explorer_latency.py). The fix leaves a style element alone when
its text would not change. Nothing else of BokehJS changes, and a BokehJS without the
patched method is left as it is (the page logs a warning).

**One layout per frame.** BokehJS computes the layout of the whole page (every figure's
axes, titles and colours read from the computed style) each time any part of it changes
in a way that may move things: a widget shown or hidden, a slider's range, a column's
children (``LayoutDOMView.invalidate_layout``), synchronously, once per change. A preset
switch brings 30-80 messages from the server, with 10-20 such changes; each layout of
this page costs ~150-300 ms of the page's CPU, so a switch took 1.7-6.6 s on a quiet
machine, 60-75 % of the page's part in repeated layouts (a Chrome CPU profile of the page
during the preset switches of ``benchmarks/explorer_latency.py``).
The fix updates the part of the page that changed at once (its styles and, for a figure
just added, its layout objects) and lays out each root of the changed views once, at the
next animation frame: what the page shows is what one layout after the last change
gives, which is what the repeated layouts ended with. A change inside a sidebar tab that
is not open (the page fills its closed tabs in the background, one per turn) lays out
nothing until that tab is opened: each fill laid the whole page out once more, ~0.3 s of
the page's CPU, 2.6 s of the 8 s a page cost the browser to load and complete (a CPU
profile of the page through the DevTools protocol). BokehJS without the
patched method is left as it is (the page logs a warning).

**A view rendered again, laid out with the page.** A view that renders itself again
(``LayoutDOMView.rerender``: a ``Div``'s new text, such as a slider's label when the
given quantity changes from a force to a settlement) then lays the whole page out at
once, past the deferral above (its ``compute_layout`` walks up to the root): in a preset
switch each such label cost 36-60 ms of the page's CPU (two labels on a switch to a
preset that gives a settlement and a tilt), each a full style and layout of a page half
changed. The fix renders it as BokehJS does and then asks for its layout as any other
change does (its own part at once, the page's at the next frame). Measured in Chromium,
the ten presets switched in turn in one page, the fix on and off in alternate rounds (two
rounds each, answers cached, so the page's part): the switches' medians summed 5009 ->
4304 ms, the page's CPU 5361 -> 4622 ms; the largest gains on presets whose statement
differs from the one before (patched_insert 718 -> 515 ms, eccentric_creep 744 -> 542 ms).

**Visual properties without CSS variables.** Before it strokes or fills anything,
BokehJS asks the computed style of the figure whether a CSS variable (``--bk-line-color``,
``--bk-fill-alpha``, ...; ``VisualProperties._get_css_value``) overrides the model's
colour, alpha, width, dash or font: one ``getComputedStyle`` per property per glyph per
paint, each a style recalculation of the page when anything changed since the last one
(a repaint after new data always has). That was ~18 ms of the page's ~130 ms of CPU per
load step (a DevTools CPU profile of key steps on the default scene). No style sheet of
this page defines such a variable: Bokeh's and Panel's own define none, nor do ours
(``test_no_style_sheet_of_the_page_defines_bokeh_css_variables`` checks the installed
packages), so every such read returned "" and the model's value was used. The fix
answers "" without asking the browser; what is drawn is the same (a screenshot of the
default scene is pixel-identical). Measured in Chromium, 30 force key steps on the default
scene, four pairs of runs alternated: the page's CPU per step 128-139 -> 103-116 ms, key
to frame 202-241 -> 177-194 ms (medians per run).

**A renderer's place on its element.** At every paint BokehJS places each renderer's
element over what it draws (``RendererView.update_position``) by writing the rectangle
into a style sheet of the element's own shadow root (``:host {position: absolute; left:
...}``). A line whose data moved has a new rectangle, so a load step rewrote 5-7 such
sheets on the default scene; each new sheet text makes the browser collect that root's
style sheets again and work out the styles they reach, and the next read of a computed
style or of a size (an axis's font, a figure's size) waits for it. The fix writes the
same rectangle as the element's own style (the sheet, emptied once, holds nothing that
could undo it): the element is where BokehJS puts it (to 0.01 px, checked in the page),
and only its own style changes. A renderer in a side panel, or one with nothing to draw
(a hidden or empty one), is left to BokehJS, which writes those rarely.
Measured in Chromium, 30-40 force key steps on the default scene under the browser's
profiler, six pairs of runs alternated: the page's CPU per step 47-72 -> 43-64 ms, its
part from the new data to the frame 34-48 -> 29-41 ms (medians per run; every pair
gained, by 1.5-8.5 ms of CPU).

**A figure's base font size, read once.** Each axis asks its figure for the font size of
the figure's element (``PlotView.base_font_size``, a ``getComputedStyle``) each time it
measures or draws its labels, to resolve text sized in ``em``. While a preset switch lays
the page out, each read made the browser work out the styles the layout had just changed:
~65 ms of the page's ~650 ms of CPU per switch, the largest single item of its profile.
The page's figures size all their text in ``px`` (a browser test checks every font size
of the page), for which that size is not used; the fix reads it once per figure and again
after the window is resized (a media query may change it).
Measured with the placing fix above, both against neither: switches between five presets
(answers cached, so the page's part), two runs of each alternated: the page's CPU per
switch 442-724 -> 376-664 ms (sum over the five 2881, 2914 -> 2400, 2795 ms), the switch
(choice to last frame) 349-706 -> 327-626 ms.

**A canvas layer cleared to its edges.** BokehJS (3.9.2, ``CanvasLayer.prepare``) shifts
a layer's drawing by half a pixel for crisp lines and then clears the layer's rectangle
in the shifted coordinates: a strip half a pixel wide at its left and top edges is never
cleared. The glyph layer paints its background over it; the overlay layer (the time
cursors and the points at the time shown, :data:`explorer.plots.bokeh_data.MOVING`) is
transparent and keeps whatever was drawn there. A figure that joins the page (the
contact width plot at the first lift-off) is painted once before its frame is laid out,
its cursor and point at x = 0; a red corner and a dotted stroke then stayed left of its
title for good. The fix clears the whole layer with the shift undone; what is drawn is
the same.

**A figure off the page not laid out.** At every paint a figure asks whether its axes,
title or legend changed size and, if so, lays itself out again
(``PlotView._invalidate_layout_if_needed``). A figure taken off the page (``display:
none``: the histories and the q(x, t) map of an answer at one output time,
``explorer/views/style.py``) has no size, so each paint found its axes "changed" and laid
the figure out: three figures at every load step of an elastic preset, ~75 ms of the
page's ~110 ms of CPU a key step (a DevTools CPU profile of force steps on the bare layer
preset). The fix lays out only a figure that is on the page; one that is off keeps its
layout due, done at its first paint once shown (the data that brings it back repaints
it, and the page's growth lays the page out).
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


#: Runs once per page when its document is ready (idempotent: a flag on the method). A
#: root removed before its frame is not laid out; a hidden page lays out when shown again
#: (browsers hold animation frames of hidden pages), as it paints.
LAYOUT_ONCE_JS = """
const layouts = (window.Bokeh && Bokeh.require) ? Bokeh.require("models/layouts/layout_dom")
                                                : null;
const View = layouts && layouts.LayoutDOMView;
if (!View || typeof View.prototype.invalidate_layout !== "function") {
  console.warn("explorer: BokehJS layouts have changed; the layout fix is not applied");
} else if (!View.prototype.invalidate_layout.__once_per_frame) {
  const invalidate = View.prototype.invalidate_layout;
  // layouts asked for and laid out (for the page's tests and benchmarks)
  const count = window.__explorerLayouts = {asked: 0, done: 0, held: 0};
  let roots = null;
  const layOut = () => {
    const due = roots;
    roots = null;
    let failed = null;
    for (const root of due) {
      if (root.is_destroyed) continue;
      count.done += 1;
      // one root that throws must not leave the others unlaid; its error is the page's
      try { invalidate.call(root); } catch (error) { failed = failed || error; }
    }
    if (failed !== null) throw failed;
  };
  // the closed tabs changed since the page was last laid out, by their tabs view
  const changed = new WeakMap();
  // the tabs view and tab (a child view of it) of a view inside a closed tab, or null
  const closedTab = (view) => {
    let child = view;
    for (let parent = view.parent; parent instanceof View; parent = parent.parent) {
      if (parent.model.type.endsWith("Tabs") &&
          parent.child_views.indexOf(child) !== parent.model.active) return [parent, child];
      child = parent;
    }
    return null;
  };
  const deferred = function () {
    // its own part now (a figure just added gets its layout objects, which a layout of
    // the page asked for before the frame, on a resize, would read), the page's once
    this.update_layout();
    count.asked += 1;
    const closed = closedTab(this);
    if (closed !== null) {
      // laid out when its tab is opened (a closed tab takes no space: views/tabs.py)
      const [tabs, tab] = closed;
      count.held += 1;
      if (!changed.has(tabs)) {
        changed.set(tabs, new WeakSet());
        tabs.connect(tabs.model.properties.active.change, () => {
          const open = tabs.child_views[tabs.model.active];
          // (inside another closed tab, that one's opening lays it out)
          if (open !== undefined && changed.get(tabs).delete(open)) deferred.call(open);
        });
      }
      changed.get(tabs).add(tab);
      return;
    }
    let root = this;
    while (root.parent instanceof View) root = root.parent;
    if (roots === null) {
      roots = new Set();
      requestAnimationFrame(layOut);
    }
    roots.add(root);
  };
  deferred.__once_per_frame = true;
  View.prototype.invalidate_layout = deferred;
}
"""


#: Runs once per page when its document is ready (idempotent: a flag on the method). Only
#: BokehJS's read of CSS variables changes: the model's values are drawn as before.
NO_CSS_VARIABLES_JS = """
const visual = (window.Bokeh && Bokeh.require) ? Bokeh.require("core/visuals/visual") : null;
const Props = visual && visual.VisualProperties;
if (!Props || typeof Props.prototype._get_css_value !== "function") {
  console.warn("explorer: BokehJS visual properties have changed; the style read fix is "
               + "not applied");
} else if (!Props.prototype._get_css_value.__no_css_variables) {
  // no style sheet of this page defines a --bk- variable (see the module's docstring)
  const none = function (name) { return ""; };
  none.__no_css_variables = true;
  Props.prototype._get_css_value = none;
}
"""

#: Runs once per page when its document is ready (idempotent: a flag on the method). The
#: rectangle is BokehJS's (3.9.2, ``RendererView.update_position``); only where it is
#: written changes.
INLINE_POSITION_JS = """
const renderers = (window.Bokeh && Bokeh.require) ? Bokeh.require("models/renderers/renderer")
                                                  : null;
const View = renderers && renderers.RendererView;
if (!View || typeof View.prototype.update_position !== "function") {
  console.warn("explorer: BokehJS renderers have changed; the placing fix is not applied");
} else if (!View.prototype.update_position.__inline_position) {
  const update = View.prototype.update_position;
  const sides = ["position", "left", "top", "width", "height"];
  const place = function () {
    const {bbox, position} = this;
    const style = this.el && this.el.style;
    if (this.panel != null || bbox == null || !bbox.is_valid || !position || !style) {
      // BokehJS's way (a sheet written rarely); nothing of ours may outrank it
      if (this.__placed_inline) {
        for (const side of sides) style.removeProperty(side);
        this.__placed_inline = false;
      }
      update.call(this);
      return;
    }
    if (position.el.textContent !== "") position.replace("");
    style.position = "absolute";
    style.left = `${bbox.left}px`;
    style.top = `${bbox.top}px`;
    style.width = `${bbox.width}px`;
    style.height = `${bbox.height}px`;
    this.__placed_inline = true;
  };
  place.__inline_position = true;
  View.prototype.update_position = place;
}
"""

#: Runs once per page when its document is ready (idempotent: a flag on the getter).
BASE_FONT_ONCE_JS = """
const plots = (window.Bokeh && Bokeh.require) ? Bokeh.require("models/plots/plot_canvas")
                                              : null;
const View = plots && plots.PlotView;
const own = View && Object.getOwnPropertyDescriptor(View.prototype, "base_font_size");
if (!own || typeof own.get !== "function") {
  console.warn("explorer: BokehJS figures have changed; the font size fix is not applied");
} else if (!own.get.__read_once) {
  const read = own.get;
  let sizes = new WeakMap();
  window.addEventListener("resize", () => { sizes = new WeakMap(); }, {passive: true});
  const once = function () {
    if (!sizes.has(this)) sizes.set(this, read.call(this));
    return sizes.get(this);
  };
  once.__read_once = true;
  Object.defineProperty(View.prototype, "base_font_size", {get: once, configurable: true});
}
"""

#: Runs once per page when its document is ready (idempotent: a flag on the method). An
#: SVG layer (export) is cleared as BokehJS does.
WHOLE_CLEAR_JS = """
const canvas = (window.Bokeh && Bokeh.require) ? Bokeh.require("core/util/canvas") : null;
const Layer = canvas && canvas.CanvasLayer;
if (!Layer || typeof Layer.prototype.clear !== "function") {
  console.warn("explorer: BokehJS canvas layers have changed; the clearing fix is not applied");
} else if (!Layer.prototype.clear.__whole) {
  const clear = Layer.prototype.clear;
  const whole = function () {
    const {ctx, canvas} = this;
    if (this.backend === "svg" || !(canvas instanceof HTMLCanvasElement)
        || typeof ctx.setTransform !== "function") {
      clear.call(this);
      return;
    }
    ctx.save();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    ctx.restore();
  };
  whole.__whole = true;
  Layer.prototype.clear = whole;
}
"""

#: Runs once per page when its document is ready (idempotent: a flag on the method).
SHOWN_ONLY_LAYOUT_JS = """
const plots = (window.Bokeh && Bokeh.require) ? Bokeh.require("models/plots/plot_canvas")
                                              : null;
const PlotView = plots && plots.PlotView;
if (!PlotView || typeof PlotView.prototype._invalidate_layout_if_needed !== "function") {
  console.warn("explorer: BokehJS plots have changed; the fix for figures off the page is "
               + "not applied");
} else if (!PlotView.prototype._invalidate_layout_if_needed.__shown_only) {
  const check = PlotView.prototype._invalidate_layout_if_needed;
  // figures off the page whose layout was left due (for the page's tests)
  const count = window.__explorerOffPageLayouts = {left: 0};
  const shownOnly = function () {
    // display: none (its own or an ancestor's, across shadow roots): no box at all
    if (this.el.getClientRects().length === 0) {
      count.left += 1;
      this._needs_layout = true;
      return;
    }
    check.call(this);
  };
  shownOnly.__shown_only = true;
  PlotView.prototype._invalidate_layout_if_needed = shownOnly;
}
"""

#: Runs once per page when its document is ready, after ``LAYOUT_ONCE_JS`` (idempotent: a
#: flag on the method). Without that fix's deferred layout it leaves BokehJS as it is.
RERENDER_ONCE_JS = """
const layouts = (window.Bokeh && Bokeh.require) ? Bokeh.require("models/layouts/layout_dom")
                                                : null;
const View = layouts && layouts.LayoutDOMView;
const base = View && Object.getPrototypeOf(View.prototype).rerender;
if (!View || typeof View.prototype.rerender !== "function" || typeof base !== "function"
    || !View.prototype.invalidate_layout.__once_per_frame) {
  console.warn("explorer: BokehJS layouts have changed; the re-render fix is not applied");
} else if (!View.prototype.rerender.__layout_once) {
  const rerender = function () {
    base.call(this);           // render and after_render, as BokehJS
    this.invalidate_layout();  // its own part now, the page's at the next frame
  };
  rerender.__layout_once = true;
  View.prototype.rerender = rerender;
}
"""

#: The prefix of the CSS variables BokehJS reads for visual properties (core/visuals).
BOKEH_CSS_VARIABLE_PREFIX = "--bk-"


def install(doc: Any) -> bool:
    """Apply the eight fixes in the page of Bokeh document ``doc`` once it is ready; False
    (nothing done) when there is no document (a notebook, a script)."""
    if doc is None or not hasattr(doc, "js_on_event"):
        return False
    for code in (SAME_STYLE_JS, LAYOUT_ONCE_JS, RERENDER_ONCE_JS, NO_CSS_VARIABLES_JS,
                 INLINE_POSITION_JS, BASE_FONT_ONCE_JS, WHOLE_CLEAR_JS, SHOWN_ONLY_LAYOUT_JS):
        doc.js_on_event("document_ready", CustomJS(code=code))
    return True
