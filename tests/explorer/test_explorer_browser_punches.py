"""Several punches in a real browser (Debian's Chromium through Playwright): the preset of
a new footing beside an old one shows both punches and a history per punch; dragging a
punch's centre moves it on every plot; its lesson goes step by step.

Every wait is on a condition in the page.
"""

from __future__ import annotations

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(400)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

from tests.browser_pages import (  # noqa: E402
    JS_READY,
    JS_SHOWN,
    Page,
    page_fixtures,
    patience,
    until,
)

server, browser_context, page = page_fixtures(1400, 900)

KEY = "new_footing_beside_old"

# The history of a quantity of punch ``k`` as the page holds it.
JS_HISTORY = """([q, k]) => {
  const s = Bokeh.documents[0].get_model_by_name(`${q}_punches_source`);
  return s && s.data.ys.length > k ? Array.from(s.data.ys[k]) : null;
}"""
# The left end of each punch drawn in the scene [m].
JS_PUNCH_LEFT = """() => {
  const s = Bokeh.documents[0].get_model_by_name('punches_source');
  return Array.from(s.data.xs).map(xs => xs[0]);
}"""
# The right end of the q(x) line [m] (NaN rows between punches left out).
JS_Q_RIGHT = """() => {
  const x = Array.from(Bokeh.documents[0].get_model_by_name('q_source').data.x);
  return Math.max(...x.filter(v => Number.isFinite(v)));
}"""


def _open_preset(server: str, page: Page) -> None:
    page.page.goto(f"{server}/app?preset={KEY}", timeout=30_000 * patience())
    page.page.wait_for_function(JS_READY, timeout=120_000 * patience())
    until(lambda: page.page.evaluate(JS_PUNCH_LEFT) == [-1.0, 2.0], "the two punches",
          timeout=120)


def test_two_punches_their_histories_and_a_drag_of_a_centre(server: str, page: Page):
    _open_preset(server, page)
    # a settlement history per punch, 200 output times each and a break where the new
    # footing's load steps (test_explorer_load_jumps), the old one settling more
    until(lambda: all(len(page.page.evaluate(JS_HISTORY, ["settlement", k]) or []) == 201
                      for k in (0, 1)), "a history per punch")
    old, new = (page.page.evaluate(JS_HISTORY, ["settlement", k]) for k in (0, 1))
    assert old[-1] > new[-1] > 0
    tilt = page.page.evaluate(JS_HISTORY, ["tilt", 0])
    assert tilt[-1] > 0  # the old footing tilts toward the new one
    until(lambda: page.page.evaluate(JS_SHOWN, "punch 2 (punches[1], x = 3 m)"),
          "the readout per punch")
    assert page.page.evaluate(JS_Q_RIGHT) == pytest.approx(4.0)
    # the Punch tab: choose punch 2 and drag its centre to the right
    page.open_tab("Punch")
    choice = page.page.locator(".punch-select button", has_text="2").first
    choice.wait_for(state="visible", timeout=30_000 * patience())
    choice.click()
    handle = page.page.locator(".punch-center .noUi-handle").first
    handle.wait_for(state="visible", timeout=30_000 * patience())
    # the handle at punch 2's centre before it is taken (it showed punch 1's)
    until(lambda: float(handle.get_attribute("aria-valuenow") or "nan") == 3.0,
          "the slider at punch 2's centre")
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.page.mouse.move(x, y)
    page.page.mouse.down()
    page.page.mouse.move(x + 30, y, steps=6)
    page.page.mouse.up()
    # released: the new footing at the slider's last value on the drawing and on q(x); the
    # old one tilts less toward it. (An answer of a step of the drag may arrive before the
    # release's: wait for the release's own centre, not for any move. A drag slower than
    # its solves is previewed, and the preview stays on screen until the answer of the
    # release comes: the status line then no longer says "Preview".)
    # (the slider's value as its box writes it: aria-valuenow is rounded to 0.1)
    until(lambda: float(handle.get_attribute("aria-valuetext") or "nan") > 3.5,
          "the slider moved")
    centre = float(handle.get_attribute("aria-valuetext"))
    until(lambda: page.page.evaluate(JS_PUNCH_LEFT)[1] == pytest.approx(centre - 1.0, abs=1e-9)
          and not page.page.evaluate(JS_SHOWN, "Preview (the base elastic at loading"),
          "punch 2 moved to the slider's value", timeout=120,
          describe=lambda: page.page.evaluate(JS_PUNCH_LEFT))
    until(lambda: page.page.evaluate(JS_Q_RIGHT) == pytest.approx(centre + 1.0, abs=1e-4),
          "q(x) over the moved punch")
    until(lambda: 0 < page.page.evaluate(JS_HISTORY, ["tilt", 0])[-1] < tilt[-1],
          "the old footing tilts less")
    until(lambda: page.page.evaluate(JS_SHOWN, f"punch 2 (punches[1], x = {centre:.3g} m)"),
          "the readout of the moved punch",
          describe=lambda: page.text(".readout-punch-1"))
    assert page.errors == []


def test_the_lesson_of_the_new_footing(page: Page):
    page.open_tab("Lessons")
    select = page.page.locator(".lesson-select select").first
    select.wait_for(state="visible", timeout=30_000 * patience())
    select.select_option(label="A new footing beside an old one")
    until(lambda: "Step 1 of 3" in page.pane_text(".lesson-note"), "step 1")
    until(lambda: page.page.evaluate(JS_PUNCH_LEFT) == [-1.0, 2.0], "the preset's punches",
          timeout=120)
    assert "tilts toward the new one" in page.pane_text(".lesson-note")
    page.page.locator(".lesson-next button").first.click()
    until(lambda: "Step 2 of 3" in page.pane_text(".lesson-note"), "step 2")
    until(lambda: page.page.evaluate(JS_HISTORY, ["force", 1])[-1] == 100.0,
          "step 2: the new footing never loaded", timeout=120)
    page.page.locator(".lesson-next button").first.click()
    until(lambda: page.page.evaluate(JS_PUNCH_LEFT) == [-1.0, 5.0], "step 3: 3 m farther",
          timeout=120)
    assert "Step 3 of 3" in page.pane_text(".lesson-note")
    assert page.errors == []


# The points of the study's line chart, empty before a study has run.
JS_STUDY_Y = """() => {
  const src = Bokeh.documents[0].get_model_by_name('study_source');
  return src && src.data.y ? Array.from(src.data.y) : null;
}"""


def test_a_study_of_the_spacing(server: str, page: Page):
    _open_preset(server, page)
    page.open_tab("Study")
    field = page.page.locator(".study-p1-field select").first
    field.wait_for(state="visible", timeout=30_000 * patience())
    field.select_option(label="punch 2: centre x [m]")
    # the server answers a new field with its first range: away from the old footing,
    # from half the 1 m gap to four times it (typing before would be overwritten)
    start = page.page.locator(".study-p1-from input").first
    until(lambda: start.input_value() == "2.5", "the centre's first range",
          describe=start.input_value)
    page.type_into(".study-p1-count", "3")
    page.page.locator(".study-output select").first.select_option(
        label="punch 1: tilt [mrad]")
    page.page.locator(".study-run button").first.click()
    until(lambda: len(page.page.evaluate(JS_STUDY_Y) or []) == 3, "the chart of 3 points",
          240, lambda: page.pane_text(".study-status"))
    # at 50 years the old footing tilts toward the new one, less the further it is
    y = page.page.evaluate(JS_STUDY_Y)
    assert y[0] > y[1] > y[2] > 0
    assert page.errors == []
