"""The model-fidelity widgets in a real browser: a layer's interface, the contact model and
the coating-model tolerance set on the page reach the saved scene file.

Debian's Chromium through Playwright; every wait is on a condition in the page or file.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from explorer.views import CONTACT_LABELS

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

from tests.browser_pages import (  # noqa: E402
    Page,
    module_page_fixture,
    patience,
)

page = module_page_fixture(1400, 900, accept_downloads=True)


def _saved_scene(page: Page) -> dict:
    with page.page.expect_download(timeout=60_000 * patience()) as info:
        page.page.get_by_text("Save scene (JSON)").first.click()
    return json.loads(Path(info.value.path()).read_text())


def test_fidelity_fields_set_on_the_page_reach_the_saved_scene(page: Page):
    page.open_tab("Coating")
    page.page.locator(".layer-interface button", has_text="bonded").first.click()
    page.open_tab("Time")
    page.page.locator(".contact-select select").first.select_option(
        label=CONTACT_LABELS["unilateral"])
    box = page.page.locator(".model-tol-input input").first
    box.fill("5")
    box.press("Enter")
    page.open_tab("Files")
    saved: dict = {}
    for _ in range(100):  # each widget reaches the server on its own message: read until all
        saved = _saved_scene(page)
        if (saved["coating"][0].get("interface") == "bonded"
                and saved["solver"].get("contact") == "unilateral"
                and saved["solver"].get("model_tol") == 0.05):
            break
        page.page.wait_for_timeout(100)
    assert saved["coating"][0].get("interface") == "bonded", saved["coating"][0]
    assert saved["solver"] == {**saved["solver"], "contact": "unilateral", "model_tol": 0.05}
    assert page.errors == []


def test_liftoff_preset_shades_the_lifted_heel_on_the_page(page: Page):
    from explorer.model import preset_label, presets

    key = "eccentric_footing_liftoff"
    page.open_tab("Scene")
    page.page.locator(".preset-select select").first.select_option(
        label=preset_label(key, presets()[key]))
    # the lifted part arrives as one shaded strip from the left edge of the base
    page.page.wait_for_function(
        """() => {
          const s = Bokeh.documents[0].get_model_by_name('negative_source');
          return s.data.left.length === 1 && s.data.right[0] > s.data.left[0];
        }""", timeout=120_000 * patience())
    left = page.page.evaluate(
        "() => Bokeh.documents[0].get_model_by_name('negative_source').data.left[0]")
    assert left == pytest.approx(-1.0)   # the base's edge x = -a (a = 1 m in the preset)
    assert page.errors == []
