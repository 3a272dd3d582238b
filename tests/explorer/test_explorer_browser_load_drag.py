"""A load slider dragged in a real browser (Debian's Chromium) on the lift-off preset
under creep, whose solves (~0.3 s of CPU) are slower than the explorer's live bound: the
plots follow the handle with the answers solved meanwhile (before, each drag step
cancelled the solve running and nothing was drawn until the release), the page says so,
and the release ends the note. Every wait is on a condition in the page."""

from __future__ import annotations

import time

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(400)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

from tests.browser_pages import (  # noqa: E402
    JS_SHOWN,
    JS_WATCH_PRESSURE,
    Page,
    page_fixtures,
    patience,
    until,
)

server, browser_context, page = page_fixtures(1400, 900)

FOLLOWING = "the plots show the last value solved"
DURING = "() => window.__changes.filter(t => t > window.__down).length"


def test_a_force_drag_on_the_liftoff_preset_draws_while_the_handle_moves(server: str,
                                                                       browser_context):
    page = Page(browser_context, server, "/app?preset=eccentric_footing_liftoff")
    try:
        handle = page.page.locator(".load-0-value .noUi-handle").first
        handle.wait_for(timeout=60_000 * patience())
        until(lambda: page.page.evaluate(JS_SHOWN, "Solved in"), "the preset solved",
              timeout=120)
        time.sleep(1.0)
        page.page.evaluate(JS_WATCH_PRESSURE)
        box = handle.bounding_box()
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.page.mouse.move(x, y)
        page.page.mouse.down()
        # a pixel every 50 ms for ~6 s, each a force not solved before (one back over a
        # force solved is drawn from the results kept), toward the side with room:
        # before, no answer came while the handle moved (each step cancelled the one
        # running, ~0.3-0.5 s a solve)
        track = page.page.locator(".load-0-value .noUi-base").first.bounding_box()
        room = track["x"] + track["width"] - x > x - track["x"]
        way = 1 if room else -1
        for k in range(1, int(120 * min(patience(), 2.0))):
            page.page.mouse.move(x + way * k / 2, y)
            time.sleep(0.05)
            if page.page.evaluate(DURING) >= 2:
                break
        assert page.page.evaluate(DURING) >= 2, "two answers drawn while the handle moved"
        until(lambda: page.page.evaluate(JS_SHOWN, FOLLOWING), "the note that the plots "
              "follow behind the handle", timeout=30)
        assert page.page.evaluate("() => window.__up") is None
        page.page.mouse.up()
        until(lambda: not page.page.evaluate(JS_SHOWN, FOLLOWING), "the note ended",
              timeout=30)
        assert page.errors == []
    finally:
        page.close()
