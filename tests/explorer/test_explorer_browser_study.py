"""The Study tab in a real browser (Debian's Chromium): a small study runs and draws its
chart, its CSV and PNG download, and a larger one is cancelled. Every wait is on a
condition in the page."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(600)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

from tests.browser_pages import (  # noqa: E402
    JS_SHOWN,
    Page,
    page_fixtures,
    patience,
    until,
)
from tests.support.probe import LivenessProbe, assert_responsive, own_explorer_server  # noqa: E402,E501

# The points of the line chart (the source named study_source) and of the heat map
# (study_map_source); empty, or not on the page, before a study of that kind has run.
JS_STUDY_Y = """() => {
  const src = Bokeh.documents[0].get_model_by_name('study_source');
  return src && src.data.y ? Array.from(src.data.y) : null;
}"""
JS_STUDY_VALUES = """() => {
  const src = Bokeh.documents[0].get_model_by_name('study_map_source');
  return src && src.data.value ? Array.from(src.data.value) : null;
}"""


def status(page: Page) -> str:
    """The tab's message (what the study did, or why it was not run)."""
    return page.pane_text(".study-status")


server, browser_context, page = page_fixtures(1400, 900, accept_downloads=True)
# a server of this module's own: the probe below must not time the collection of the
# sessions that other modules' pages left (explorer/fixes/gc_policy.py)
explorer_server = own_explorer_server()


def test_a_study_runs_draws_its_chart_and_a_second_is_cancelled(page: Page):
    page.open_tab("Study")
    page.page.locator(".study-run button").first.wait_for(timeout=60_000 * patience())
    # parameter 1: the force (the default), 3 points from 250 to 750 kN/m
    page.type_into(".study-p1-count", "3")
    page.page.locator(".study-run button").first.click()
    assert page.page.evaluate(JS_STUDY_Y) is None  # the chart comes with a result
    until(lambda: len(page.page.evaluate(JS_STUDY_Y) or []) == 3, "the chart of 3 points",
          240, lambda: status(page))
    y = page.page.evaluate(JS_STUDY_Y)
    assert all(v > 0 for v in y) and y[0] < y[1] < y[2]  # settlement grows with the force
    until(lambda: page.page.evaluate(JS_SHOWN, "Done: 3 points"), "the study's summary", 60,
          lambda: status(page))

    # the CSV is written on a thread when the result comes: its button is offered then
    csv_button = page.page.locator(".study-csv button").first
    until(lambda: csv_button.is_enabled(), "the study's CSV offered")
    with page.page.expect_download(timeout=60_000 * patience()) as info:
        csv_button.click()
    text = Path(info.value.path()).read_text()
    rows = [line for line in text.splitlines() if not line.startswith("#")]
    assert rows[0].startswith("loading_force_p_kN_per_m,time_day,settlement_mm")
    with page.page.expect_download(timeout=60_000 * patience()) as info:
        page.page.locator(".study-png").first.click()
    assert Path(info.value.path()).read_bytes().startswith(b"\x89PNG")

    # the largest study the tab takes, 20 x 20, cancelled while it runs. Over the coating's
    # thickness and modulus every point is a new geometry: 9.7 s of CPU on a quiet 2-core
    # machine (2026-12-02, core.sweep of the same grid). Over the force and the modulus (20
    # geometries) it took 1.7 s there and ended before the wait below saw Cancel.
    for part, label in (("p1", "coating 1: thickness [mm]"),
                        ("p2", "coating 1: Young's modulus [MPa]")):
        page.page.locator(f".study-{part}-field select").first.select_option(label=label)
        # the server answers a new field with its first range (9 points): a count typed
        # before that answer arrives would be overwritten by it
        count = page.page.locator(f".study-{part}-count input").first
        until(lambda count=count: count.input_value() == "9", f"the {part} field's first range",
              describe=count.input_value)
    page.type_into(".study-p1-count", "20")
    page.type_into(".study-p2-count", "20")
    # the page complete first (every tab opened): its background filling of tabs is not
    # what the probe below measures (and it waits for the page to be left alone, longer
    # than the study runs)
    page.complete_by_hand(then="Study")
    page.page.locator(".study-run button").first.click()
    until(lambda: page.page.evaluate(JS_SHOWN, "running:"), "the study running", 120,
          lambda: status(page))
    # the server's event loop, which every page shares, answers at once while the study
    # runs (in a process of its own) and reports its progress, and when it is cancelled
    with LivenessProbe(page.url) as probe:
        time.sleep(2.0)  # a window of the study's running, not a wait for the page
        cancel = page.page.locator(".study-cancel button").first
        until(lambda: cancel.is_enabled(), "Cancel enabled")
        cancel.click()
        until(lambda: page.page.evaluate(JS_SHOWN, "cancelled: the study was stopped"),
              "the study cancelled", 60, lambda: status(page))
    assert_responsive(probe)
    assert page.page.locator(".study-run button").first.is_enabled()
    # the chart still shows the first study (the cancelled one drew nothing)
    assert page.page.evaluate(JS_STUDY_Y) == y
    # no heat map yet: the tab shows one chart, the line (the map is not on the page)
    assert not page.page.evaluate(JS_STUDY_VALUES)

    # the second study runs to its heat map when it is small
    page.type_into(".study-p1-count", "2")
    page.type_into(".study-p2-count", "2")
    page.page.locator(".study-run button").first.click()
    until(lambda: len(page.page.evaluate(JS_STUDY_VALUES) or []) == 4,
          "the heat map of 2 x 2", 240, lambda: status(page))
    assert page.errors == []


def test_the_link_follows_the_scene_while_a_study_setting_is_bad(page: Page):
    """A Study value out of range (1000 points) is named by the tab; the page's address
    keeps following the scene on screen, with the last good study settings (it stopped
    updating: every later change was lost on a reload)."""
    from urllib.parse import parse_qsl, urlsplit

    from explorer.model import decode_scene

    def linked() -> tuple[float | None, int | None]:
        query = dict(parse_qsl(urlsplit(page.page.evaluate("() => location.href")).query))
        force = decode_scene(query["scene"])["loading"]["force"] if "scene" in query else None
        study = decode_scene(query["study"]) if query.get("study") else None
        return force, None if study is None else study["axes"][0][3]

    page.open_tab("Study")
    page.type_into(".study-p1-count", "5")
    until(lambda: linked()[1] == 5, "5 points in the link", describe=linked)
    page.type_into(".study-p1-count", "1000")
    page.open_tab("Scene")
    page.type_into(".load-0-value", "640")
    until(lambda: linked() == (640e3, 5), "the new force and the last good study in the link",
          describe=linked)
    assert page.errors == []


def test_too_few_points_typed_are_refused_in_words(page: Page):
    """Typed into the points box, 1 or 0 stayed in the box while the study ran on the
    last count taken (the box's lower bound refused it in the page, without a word)."""
    page.open_tab("Study")
    page.page.locator(".study-run button").first.wait_for(timeout=60_000 * patience())
    for typed in ("1", "0"):
        page.type_into(".study-p1-count", typed)
        page.page.locator(".study-run button").first.click()
        until(lambda typed=typed: f"points: must be a whole number from 2 to 200, got {typed}"
              in status(page), f"the refusal of {typed} point(s)", 60, lambda: status(page))
    assert page.errors == []
