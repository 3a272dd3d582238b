"""The file droppers' words for a file of a type they do not take.

FilePond (Panel's ``FileDropper``) refuses such a file with "Expects {allButLastType} or
{lastType}" of the MIME types it was given: a dropper of one type read "Expects  or
application/json" where its box asks for a file ending in .json (a teacher's audit).
Each dropper is given its words as it is made (when its tab first shows): every accepted
type listed, by the ending the boxes ask for. Checked with Panel 1.9.4 and the FilePond
4.32.12 it bundles.
"""

from __future__ import annotations

import json
from typing import Any

from bokeh.models import CustomJS

#: The endings of the files the droppers take, by the MIME type Panel gives FilePond
#: for each (its ``extensionsToMimeTypes``).
TYPE_ENDINGS = {"application/json": ".json", "text/csv": ".csv", "text/plain": ".txt"}

#: Runs once per page when its document is ready (idempotent: a flag on the window).
DROPPER_LABELS_JS = """
if (!window.__explorerDropperLabels && window.FilePond && window.FilePond.create) {
  window.__explorerDropperLabels = true;
  const options = {
    fileValidateTypeLabelExpectedTypes: "Expects a file ending in {allTypes}",
    fileValidateTypeLabelExpectedTypesMap: ENDINGS,
  };
  // set on each dropper as it is made: FilePond's defaults set before Panel registers the
  // type plugin (with the first dropper) are not its plugin's
  const create = window.FilePond.create;
  window.FilePond.create = function (...args) {
    const pond = create.apply(this, args);
    try { pond.setOptions(options); } catch (e) { /* an older FilePond: its words */ }
    return pond;
  };
}
""".replace("ENDINGS", json.dumps(TYPE_ENDINGS))


def install(doc: Any) -> bool:
    """Set the droppers' words on the page of Bokeh document ``doc``; False (nothing
    done) when there is no document (a notebook, a script)."""
    if doc is None or not hasattr(doc, "js_on_event"):
        return False
    doc.js_on_event("document_ready", CustomJS(code=DROPPER_LABELS_JS))
    return True
