"""The report's smallest contact width is the answer's ``contact_width`` (the length of
its contact set, :func:`core.scene.contact_width`), as every other output gives it."""

from __future__ import annotations

import numpy as np

from core.report.content import key_numbers
from core.scene import solve
from tests.conftest import scene_file


def test_the_report_gives_the_smallest_contact_width() -> None:
    result = solve(scene_file("eccentric_footing_liftoff"))
    widths = result.contact_width
    np.testing.assert_array_equal(
        widths, [sum(hi - lo for lo, hi in zones) for zones in result.contact_set])
    k = int(np.argmin(widths))
    # the lift-off preset narrows most at loading: 1.306 m of the 2 m
    assert k == 0 and f"{widths[k]:.4g}" == "1.306"
    assert dict(key_numbers(result))["smallest contact width"] == (
        f"{widths[k]:.4g} m of 2 m at t = {result.times[k]:.4g} days")
