"""Markup in a link and in an uploaded table does not run in a real browser (Debian's
Chromium through Playwright): the page shows it as text, and no script or image of it
runs."""

from __future__ import annotations

import shutil
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from explorer.model.links import encode_scene
from tests.browser_pages import patience, require_browser, served_explorer
from tests.conftest import base_scene
from tests.support.serving import CHROMIUM, CHROMIUM_ARGS


@pytest.fixture(scope="module")
def served(request: pytest.FixtureRequest) -> Iterator[str]:
    require_browser()
    yield from served_explorer(request.getfixturevalue("explorer_server"))


@pytest.mark.browser
@pytest.mark.timeout(300)
def test_markup_in_a_link_and_an_upload_does_not_run_in_the_browser(served: str,
                                                                    tmp_path: Path) -> None:
    from playwright.sync_api import sync_playwright

    scene = base_scene()
    scene["punch"]['<img src=x onerror="window.__xss=1">'] = 1.0
    profile = tempfile.mkdtemp(prefix="security-chromium-")
    try:
        with sync_playwright() as p:
            context = p.chromium.launch_persistent_context(
                profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
            page = context.new_page()
            dialogs: list[str] = []
            page.on("dialog", lambda d: (dialogs.append(d.message), d.dismiss()))
            page.goto(f"{served}/app?scene={encode_scene(scene)}")
            notice = page.locator(".notice").first
            notice.wait_for(state="visible", timeout=60_000 * patience())
            text = notice.evaluate("e => (e.shadowRoot || e).textContent")
            assert '<img src=x onerror="window.__xss=1">' in text
            assert notice.evaluate("e => (e.shadowRoot || e).querySelectorAll('img, script')"
                                   ".length") == 0
            # an uploaded table with markup in a cell
            page.locator(".bk-tab", has_text="Punch").first.click()
            table = tmp_path / "shape.csv"
            table.write_text("x,f\n-0.5,0\n0,<img src=x onerror=alert(1)>\n")
            page.locator("input[type=file]").first.set_input_files(str(table))
            deadline = time.monotonic() + 60
            text = ""
            while "line 3" not in text and time.monotonic() < deadline:
                page.wait_for_timeout(200)
                text = notice.evaluate("e => (e.shadowRoot || e).textContent")
            assert "<img src=x onerror=alert(1)>" in text and "punch.shape" in text
            page.wait_for_timeout(500)  # an injected image would fail to load and fire
            assert page.evaluate("() => window.__xss") is None
            assert dialogs == []
            context.close()
    finally:
        shutil.rmtree(profile, ignore_errors=True)
