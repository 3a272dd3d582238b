"""An idle page costs no frames; the file dropper still works after the page was idle.

The dropper's frame loop (FilePond) ran at 60 frames a second for as long as the page
was open, ~9 % of a core of the browser on an idle page; it is now held while nothing
happens (explorer/fixes/idle_painter.py). Checked in Debian's Chromium: no frames are asked for
on an idle page, and a file chosen long after the last click (no event on the page but
the file input's own) is still taken up and loaded.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]

from tests.browser_pages import patience, require_browser  # noqa: E402

require_browser()

from explorer.fixes.idle_painter import AWAKE_MS  # noqa: E402
from tests.browser_pages import Page, page_fixtures, until  # noqa: E402

server, browser_context, page = page_fixtures(1400, 900)

ROOT = Path(__file__).resolve().parents[2]

# Counting the frames of FilePond's loop: a writer of its frame function that counts
# (window.__droppersFrames), added by JS_START_COUNT and taken out by JS_STOP_COUNT,
# which returns the count.
JS_START_COUNT = """() => {
  const counter = {runs: 0};
  counter.count = () => { counter.runs += 1; };
  (window.__framePainter ? window.__framePainter.writers : []).push(counter.count);
  window.__droppersFrames = counter;
}"""
JS_STOP_COUNT = """() => {
  const counter = window.__droppersFrames;
  const writers = window.__framePainter ? window.__framePainter.writers : [];
  const at = writers.indexOf(counter.count);
  if (at >= 0) writers.splice(at, 1);
  return counter.runs;
}"""


def _painter_runs(page: Page, ms: int) -> int:
    """Frames FilePond's loop ran during ``ms`` [ms] (-1: no painter on the page)."""
    if not page.page.evaluate("() => Boolean(window.__explorerPainter)"):
        return -1
    page.page.evaluate(JS_START_COUNT)
    page.page.wait_for_timeout(ms)
    return page.page.evaluate(JS_STOP_COUNT)


def _wait_asleep(page: Page, timeout: float = 90.0) -> None:
    deadline = time.monotonic() + timeout
    while page.page.evaluate("() => window.__explorerPainter.awake()"):
        assert time.monotonic() < deadline, "the dropper's loop never went to sleep"
        time.sleep(0.25)


def test_an_idle_page_holds_the_droppers_loop_and_a_late_file_still_loads(page: Page):
    page.open_tab("Files")
    upload = page.page.locator(".scene-upload input[type=file]").first
    upload.wait_for(state="attached", timeout=30_000 * patience())
    # awake after the click on the tab: the loop runs (the dropper draws itself)
    assert _painter_runs(page, 500) > 5
    # idle: once every tab has its widgets (the Fit tab's dropper too, which wakes the
    # loop when it is made), no more frames of the dropper, for longer than the wake
    page.complete_by_hand(then="Scene")
    _wait_asleep(page)
    assert _painter_runs(page, AWAKE_MS + 500) == 0
    # a load step with the keys, away from the droppers: the answer comes and is drawn,
    # and the dropper's loop sleeps on (it woke at every key and every change from the
    # server, ~32 frames of it a step)
    page.page.evaluate(JS_START_COUNT)
    before = page.q()
    handle = page.page.locator(".load-0-value .noUi-handle").first
    handle.focus()
    handle.press("ArrowRight")
    until(lambda: page.q() != before, "the load step's pressure")
    time.sleep(0.5)  # its frames drawn (a window for the loop to run in, not a wait)
    assert page.page.evaluate(JS_STOP_COUNT) == 0
    page.open_tab("Files")  # (a tab's title clicked: the loop wakes, a dropper may show)
    _wait_asleep(page)
    # a file chosen now (as after a long look through the file dialog): only the file
    # input's own events happen on the page, and the dropper takes it up all the same
    scene = json.loads((ROOT / "core" / "presets" / "scenes" / "stepped_punch.json").read_text())
    scene["name"] = "chosen while idle"
    upload.set_input_files(files=[{"name": "scene.json", "mimeType": "application/json",
                                   "buffer": json.dumps(scene).encode()}])
    page.page.wait_for_function(
        "() => Bokeh.documents[0].get_model_by_name('scene_figure').title.text"
        ".includes('chosen while idle')", timeout=60_000 * patience())
    # and after it, idle again
    _wait_asleep(page)
    assert _painter_runs(page, 1500) == 0
    assert page.errors == []
