"""Panel, Bokeh and Python's collector adjusted for a server holding many pages.

Each module is one fix, with the versions it was checked with and why it is needed; each
is used through its module (``panel_fixes.install()``), so a test can replace one part.

- ``panel_fixes``: messages Panel queues for a page and then never sends.
- ``empty_inputs``: an emptied number box shown empty, not as "NaN".
- ``bokeh_fixes``: style sheets BokehJS rewrites with the same text; the page's layout
  computed once per frame, not once per change; colours and line styles not read back
  from the computed style at each paint; a renderer's place written on its element, not
  into a style sheet; a figure's base font size read once; a canvas layer cleared to its
  edges; a figure off the page not laid out.
- ``idle_painter``: the file dropper's frame loop, paused while nothing happens.
- ``dropper_labels``: the file droppers' words for a file of a type they do not take.
- ``closed_pages``: pages closed abruptly (a debug line, not a traceback), Panel's
  link registry released when a session ends, and Panel's busy-counter task started
  holding no page.
- ``gc_policy``: the garbage collector kept off complete pages, and given them back
  (Panel's own collection after a destroyed page left to it).
- ``model_walk``: Bokeh's walk over a document's models without building the constant
  defaults it reads (each change of the page's shape walks every model).
- ``property_defaults``: Bokeh's property defaults and type names worked out once per
  class, not per new model.
- ``patch_refs``: Bokeh's patch messages written without listing every model of the page.
- ``design_updates``: a changed parameter sent without the theme worked out again.
- ``layout_batch``: many layout changes of a page (a preset's new sliders) with the
  page's models walked once, not once per change.
"""

from . import (
    bokeh_fixes,
    closed_pages,
    design_updates,
    dropper_labels,
    empty_inputs,
    gc_policy,
    idle_painter,
    layout_batch,
    model_walk,
    panel_fixes,
    patch_refs,
    property_defaults,
)

__all__ = ["bokeh_fixes", "closed_pages", "design_updates", "dropper_labels", "empty_inputs",
           "gc_policy",
           "idle_painter",
           "install_in_process", "layout_batch", "model_walk", "panel_fixes", "patch_refs",
           "property_defaults"]


def install_in_process() -> None:
    """Install the fixes that hold for the whole process (not per page): Panel's queued
    messages, its empty number boxes and property updates, Bokeh's model walk, its
    property defaults and its patch messages."""
    panel_fixes.install()
    empty_inputs.install()
    design_updates.install()
    model_walk.install()
    property_defaults.install()
    patch_refs.install()
