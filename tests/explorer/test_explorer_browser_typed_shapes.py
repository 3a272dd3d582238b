"""Every slider of a shape or a profile variation takes a typed value (the crown radius,
a patch's modulus, centre and width), and a load's box shows the value as typed, in a
real browser (Debian's Chromium).

These sliders once had no text box: a crown radius of 123.5 km or a patch 0.4 m wide
could only be dragged to. The typed values are read back from the page's address link,
which holds the scene on screen. Every wait is on a condition in the page.
"""

from __future__ import annotations

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

from explorer.model import decode_scene  # noqa: E402
from tests.browser_pages import Page, module_page_fixture, until  # noqa: E402

page = module_page_fixture(1400, 900)


def _linked_scene(page: Page) -> dict | None:
    """The scene of the page's address link (None before it has one)."""
    href = page.page.evaluate("() => window.location.href")
    if "scene=" not in href:
        return None
    return decode_scene(href.split("scene=", 1)[1].split("&", 1)[0])


def _linked(page: Page, check, what: str) -> dict:
    """Wait until the linked scene passes ``check``; return it."""
    seen: dict = {}

    def ok() -> bool:
        scene = _linked_scene(page)
        if scene is None:
            return False
        seen["scene"] = scene
        return bool(check(scene))

    until(ok, what, 60, lambda: seen.get("scene"))
    return seen["scene"]


def test_the_crown_radius_is_typed(page: Page):
    page.open_tab("Punch")
    page.page.locator("select").filter(has_text="crowned").first.select_option(
        label="crowned (parabolic, radius R)")
    box = page.page.locator(".punch-crown-radius input").first
    until(lambda: box.is_visible(), "the crown radius's text box")
    page.type_into(".punch-crown-radius", "123.5")
    # f(x) = x^2 / (2 R): the quadratic coefficient 1 / (2 x 123.5 km)
    _linked(page, lambda s: isinstance(s["punch"]["shape"], dict) and
            abs(s["punch"]["shape"]["coefficients"][2] * 2 * 123.5e3 - 1) < 1e-12,
            "the typed crown radius in the link")
    assert page.errors == []


def test_a_patch_of_the_coating_modulus_is_typed(page: Page):
    page.open_tab("Coating")
    page.page.locator("select").filter(has_text="patch (a band").nth(1).select_option(
        label="patch (a band of another value)")
    until(lambda: page.page.locator(".coating-modulus-length input").first.is_visible(),
          "the patch's text boxes")
    page.type_into(".coating-modulus-amplitude", "37")
    page.type_into(".coating-modulus-position", "0.25")
    page.type_into(".coating-modulus-length", "0.4")
    # the default layer, 800 MPa, with a band 37 % stiffer over [0.05, 0.45] m
    scene = _linked(page, lambda s: isinstance(s["coating"][0]["modulus"], dict) and
                    s["coating"][0]["modulus"].get("breaks") is not None and
                    abs(s["coating"][0]["modulus"]["breaks"][1] - 0.45) < 1e-12 and
                    abs(s["coating"][0]["modulus"]["breaks"][0] - 0.05) < 1e-12,
                    "the typed patch in the link")
    assert scene["coating"][0]["modulus"]["values"][1] == pytest.approx(1.096e9, rel=1e-12)
    assert page.errors == []


def test_a_typed_moment_reads_as_typed_in_its_box(page: Page):
    # the history boxes show up to four decimals (a tilt in mrad needs them): a moment of
    # 777.48 kN m/m read "777.4800" in its box beside the readout's 777.48 (here 123.45
    # kN m/m: the default force of 500 kN/m carries it within the base)
    page.open_tab("Scene")
    page.type_into(".load-1-value", "123.45")
    box = page.page.locator(".load-1-value input").first
    until(lambda: box.input_value() == "123.45", "123.45 in the moment's box", 60,
          lambda: box.input_value())
    _linked(page, lambda s: s["loading"].get("moment") == pytest.approx(123.45e3, rel=1e-12),
            "the typed moment in the link")
    assert page.errors == []
