"""The eccentric-footing lesson in a real browser (Debian's Chromium through Playwright):
the contact zone under the punch moves as time passes and as the eccentricity slider
moves; the contact width plot and the readout follow; small features get their inset.

Every wait is on a condition in the page.
"""

from __future__ import annotations

import copy

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(400)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

from tests.browser_pages import (  # noqa: E402
    JS_SHOWN,
    JS_VIEW_WIDTH,
    Page,
    page_fixtures,
    until,
)

KEY = "eccentric_footing_liftoff"

JS_ZONES = """(name) => {
  const s = Bokeh.documents[0].get_model_by_name(name);
  return Array.from(s.data.xs).map(xs => [xs[0], xs[xs.length - 1]]);
}"""
# Whether the inset of small features is on the page and shown (it is sent when needed).
JS_INSET_SHOWN = """() => {
  const fig = Bokeh.documents[0].get_model_by_name('features_figure');
  return !!fig && fig.visible;
}"""
JS_TITLE = "(name) => Bokeh.documents[0].get_model_by_name(name).title.text"


server, browser_context, page = page_fixtures(1400, 900)


def _choose(page: Page, key: str) -> None:
    from explorer.model import preset_label, presets

    page.page.locator(".preset-select select").first.select_option(
        label=preset_label(key, presets()[key]))


def _zones(page: Page, name: str = "contact_zone_source") -> list[list[float]]:
    return page.page.evaluate(JS_ZONES, name)


def _solved(e: float):
    """The preset solved here with the force at ``e`` [m] (the server's solver is the same
    deterministic code)."""
    from core import solve
    from explorer.model import presets

    scene = copy.deepcopy(presets()[KEY])
    scene["loading"]["moment"] = e * scene["loading"]["force"]
    return solve(scene)


def _starts_at(page: Page, start: float) -> bool:
    zones = _zones(page)
    # the page holds the zone end as a float64 list: only the last digits may differ
    return len(zones) == 1 and abs(zones[0][0] - start) < 1e-9 and zones[0][1] == 1.0


def test_the_zone_moves_with_time_and_with_the_eccentricity_slider(page: Page):
    preset = _solved(0.6)
    _choose(page, KEY)
    # at the last output time (where a new result is shown): the zone and the lifted heel
    start = preset.contact_set[-1][0][0]
    until(lambda: _starts_at(page, start), "the zone at 1000 days", timeout=120)
    assert [z[0] for z in _zones(page, "lifted_zone_source")] == [-1.0]
    assert "lift-off" in page.page.evaluate(JS_TITLE, "contact_width_figure")
    assert page.page.evaluate(JS_VIEW_WIDTH, "contact_width_figure") > 200
    until(lambda: page.page.evaluate(JS_SHOWN, "contact 1.349 m of 2 m"), "the readout")
    # time passes under creep: at loading the zone is shorter
    page.page.locator(".time-player input[type=range]").first.fill("0")
    until(lambda: _starts_at(page, preset.contact_set[0][0][0]), "the zone at t = 0")
    until(lambda: page.page.evaluate(JS_SHOWN, "contact 1.306 m of 2 m"), "the readout at 0")
    # the eccentricity slider: the force further out, the zone shrinks toward the toe
    page.type_into(".eccentricity-slider", "0.8")
    further = _solved(0.8)
    until(lambda: _starts_at(page, further.contact_set[0][0][0]), "the zone at e = 0.8 m",
          timeout=120)
    assert page.errors == []


def test_small_features_get_an_inset_and_a_flat_scene_none(page: Page):
    assert not page.page.evaluate(JS_INSET_SHOWN)   # not even sent with the first page
    _choose(page, "worn_coating")
    until(lambda: page.page.evaluate(JS_INSET_SHOWN), "the inset", timeout=120)
    until(lambda: (page.page.evaluate(JS_VIEW_WIDTH, "features_figure") or 0) > 200,
          "the inset drawn on the page")
    surface = page.page.evaluate(
        "() => Array.from(Bokeh.documents[0].get_model_by_name('features_source')"
        ".data.surface)")
    # the 20 µm wear bump of the preset, in micrometres (401-point grid: within 0.1 %)
    assert min(surface) == pytest.approx(-20.0, rel=1e-3)
    _choose(page, "uniform_flat")
    until(lambda: not page.page.evaluate(JS_INSET_SHOWN), "the inset hidden", timeout=120)
    assert not page.page.evaluate(JS_VIEW_WIDTH, "features_figure")
    assert page.errors == []
