"""A scene of two punches the tests of its outputs share: a wide punch under a force and
a moment at -1.5 m and a narrow one held level under a force at 1.5 m, on the uniform
preset's coating (tests/scene/test_punches_outputs.py, tests/report/test_report_punches.py,
tests/study/test_study_punches.py)."""

from __future__ import annotations

from typing import Any

from tests.conftest import scene_file

#: An elastic base of the uniform preset's concrete.
ELASTIC = {"model": "elastic", "modulus": 3.0e10}


def wide_and_narrow(creep: dict[str, Any], times: dict[str, Any]) -> dict[str, Any]:
    """The two punches on a base of ``creep`` (a scene's ``base.creep``), at ``times``."""
    d = scene_file("uniform_flat")
    d["base"]["creep"] = dict(creep)
    d["times"] = dict(times)
    del d["punch"], d["loading"]
    d["punches"] = [
        {"center": -1.5, "half_width": 1.0, "loading": {"force": 5e5, "moment": 2e4}},
        {"center": 1.5, "half_width": 0.6, "loading": {"tilt": 0, "force": 3e5}}]
    return d
