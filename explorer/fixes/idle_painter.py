"""The file dropper's frame loop, paused while nothing happens on the page.

The dropper of the Files tab (FilePond, loaded with Panel's ``filedropper`` extension)
starts an animation-frame loop when its script loads and keeps it running for as long as
the page is open, whether or not a dropper is on screen: every frame it measures and
redraws its views. An idle page kept ~9 % of a core of the browser busy with it
(measured with ``benchmarks/explorer_idle.py``). FilePond does all its drawing, and
handles its own actions (a file added, removed, uploaded), in that loop, so the loop is
not stopped for good: it is held while the page is idle and runs again for
:data:`AWAKE_MS` after anything that may concern a dropper: a click on a dropper or on a
tab's title (a tab opened may show one), a key or the focus on a dropper, a file dragged
over the page or dropped or pasted or chosen in the file dialog, the window resized, a
dropper created, a file being uploaded, a change of a dropper's model from the server, or
a call of ``window.__explorerPainter.wake()`` (the server's "empty the dropper" does that).

Only those: the loop once woke at every key and every change from the server, so a
slider moved with the keys or dragged kept it running: ~32 frames of the dropper a load
step, ~13 % of the page's CPU for the step (~200 -> ~173 ms, measured through the
browser's profiler on the default scene; the rest is BokehJS painting the figures).

How: the page's ``requestAnimationFrame`` passes every callback on, except FilePond's
frame function (recognised by its text: it calls its ``readers`` and ``writers``), which
is scheduled only while awake and otherwise kept until the next wake. Nothing else on
the page changes; a FilePond whose frame function reads differently is left running as
before.
"""

from __future__ import annotations

from typing import Any

from bokeh.models import CustomJS

#: How long the dropper's loop runs after the last event that may concern it [ms]: its
#: springs settle within ~1 s; an upload keeps it running for as long as it lasts.
AWAKE_MS = 3000

#: Runs once per page when its document is ready (idempotent: a flag on the window).
IDLE_PAINTER_JS = """
if (!window.__explorerPainter) {
  const AWAKE_MS = AWAKE_MS_VALUE;
  const raf = window.requestAnimationFrame.bind(window);
  const caf = window.cancelAnimationFrame.bind(window);
  const ponds = [];
  let tick = null, pending = 0, awakeUntil = performance.now() + AWAKE_MS;
  const isPainter = (cb) => {
    try {
      const text = Function.prototype.toString.call(cb);
      return text.includes(".readers.forEach") && text.includes(".writers.forEach");
    } catch (e) { return false; }
  };
  const known = new WeakMap();
  const busy = () => ponds.some((pond) => {
    try { return pond.status === 3; } catch (e) { return false; }  // FilePond BUSY
  });
  const run = (ts) => {
    pending = 0;
    if (busy()) awakeUntil = Math.max(awakeUntil, performance.now() + AWAKE_MS);
    tick(ts);
  };
  const schedule = () => {
    if (!pending && tick !== null) pending = raf(run);
    return pending;
  };
  window.requestAnimationFrame = function (cb) {
    let painter = known.get(cb);
    if (painter === undefined) {
      painter = isPainter(cb);
      if (typeof cb === "function") known.set(cb, painter);
    }
    if (!painter) return raf(cb);
    tick = cb;
    return performance.now() < awakeUntil ? schedule() : 0;  // asleep: kept for later
  };
  window.cancelAnimationFrame = function (id) {
    if (id && id === pending) pending = 0;
    return caf(id);
  };
  const wake = () => {
    awakeUntil = Math.max(awakeUntil, performance.now() + AWAKE_MS);
    schedule();
  };
  // whether an event happened on a dropper (or, for a click, on a tab's title); the
  // page's parts live in shadow roots, so the event's whole path is looked at
  const onDropper = (event, tabs) => {
    const path = typeof event.composedPath === "function" ? event.composedPath() : [];
    return path.some((el) => {
      const names = el && el.classList;
      if (!names) return false;
      for (const name of names) {
        if (name.startsWith("filepond") || (tabs && name === "bk-tab")) return true;
      }
      return false;
    });
  };
  for (const type of ["dragenter", "dragover", "drop", "paste", "resize"]) {
    window.addEventListener(type, wake, {capture: true, passive: true});
  }
  window.addEventListener("pointerdown", (e) => { if (onDropper(e, true)) wake(); },
                          {capture: true, passive: true});
  for (const type of ["keydown", "focusin"]) {
    window.addEventListener(type, (e) => { if (onDropper(e, false)) wake(); },
                            {capture: true, passive: true});
  }
  const create = window.FilePond && window.FilePond.create;
  if (typeof create === "function") {
    window.FilePond.create = function (...args) {
      const pond = create.apply(this, args);
      ponds.push(pond);
      // a file chosen in the file dialog: a "change" of the dropper's own input, which
      // does not leave the page part it is in (the dialog may take longer than the
      // wake after the click)
      const root = pond && pond.element;
      if (root && root.addEventListener) {
        for (const type of ["change", "input"]) root.addEventListener(type, wake, true);
      }
      wake();
      return pond;
    };
  }
  // a change of a dropper from the server (emptied, options set, an upload answered);
  // a change without a model (a root added or removed) may bring one too
  const ofDropper = (event) => {
    const model = event && event.model;
    if (!model) return true;
    const type = String(model.type || "");
    return type.includes("FileDropper");
  };
  for (const doc of (window.Bokeh && Bokeh.documents) || []) {
    try {
      doc.on_change((event) => { if (ofDropper(event)) wake(); });
    } catch (e) { /* an older BokehJS: clicks only */ }
  }
  // awake: a frame of the dropper's loop is still to come (also one asked for just
  // before the loop fell asleep)
  window.__explorerPainter = {wake: wake, ponds: ponds,
                              awake: () => performance.now() < awakeUntil || pending !== 0};
}
""".replace("AWAKE_MS_VALUE", str(AWAKE_MS))

#: For a jscallback that changes a dropper from the server: run its loop now.
WAKE_JS = "if (window.__explorerPainter) { window.__explorerPainter.wake(); }"


def install(doc: Any) -> bool:
    """Hold the dropper's frame loop while the page of Bokeh document ``doc`` is idle;
    False (nothing done) when there is no document (a notebook, a script)."""
    if doc is None or not hasattr(doc, "js_on_event"):
        return False
    doc.js_on_event("document_ready", CustomJS(code=IDLE_PAINTER_JS))
    return True
