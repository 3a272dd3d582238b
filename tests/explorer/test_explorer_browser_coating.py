"""The "check the coating model" button in a real browser: a click runs the resolved
finite-element check of the scene on screen and shows its model error beside the estimate.

Debian's Chromium through Playwright; every wait is on a condition in the page.
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

from tests.browser_pages import (  # noqa: E402
    JS_SHOWN,
    Page,
    module_page_fixture,
    patience,
    until,
)
from tests.support.probe import LivenessProbe, assert_responsive, own_explorer_server  # noqa: E402,E501

page = module_page_fixture(1400, 900)
# a server of this module's own: the probe below must not time the collection of the
# sessions that other modules' pages left (explorer/fixes/gc_policy.py)
explorer_server = own_explorer_server()


def test_check_button_shows_the_measured_model_error_beside_the_estimate(page: Page):
    # the server's event loop, which every page shares, answers at once while the check
    # runs (it runs in a process of its own); the page complete first (every tab opened),
    # so that its own background filling of tabs is not what the probe measures
    page.complete_by_hand(then="Coating")
    button = page.page.locator(".coating-check-button button").first
    with LivenessProbe(page.url) as probe:
        button.click()
        # the progress bar shows while the FE model solves (or the report is already there)
        bar = page.page.locator(".coating-check-progress").first
        until(lambda: bar.is_visible() or page.page.evaluate(JS_SHOWN, "model error: measured"),
              "the check's progress bar", timeout=60)
        page.page.wait_for_function(JS_SHOWN, arg="model error: measured",
                                    timeout=180_000 * patience())
        for text in ("estimated", "settlement [mm]", "pressure", "Coating model: thin layer"):
            assert page.page.evaluate(JS_SHOWN, text), text
        assert button.is_enabled()
        # and while a result's q(x, t) is written for a download (on a thread of the server)
        page.open_tab("Files")
        with page.page.expect_download(timeout=60_000 * patience()) as info:
            page.page.get_by_text("Results: q(x, t) (CSV)").first.click()
        assert Path(info.value.path()).stat().st_size > 10_000
    assert_responsive(probe)
    assert page.errors == []
