"""Elastic answers at many output times (core/engines/nystrom/elastic.py).

The answer at every output time is a combination of cached unit responses; the extremes of
q that decide ``contact_lost`` are sought over the check points block by block. Both must
equal what single solves at each time give.
"""

from __future__ import annotations

import numpy as np
import pytest

import core
from core.engines.nystrom.elastic import CHECK_BLOCK
from core.engines.nystrom.prepared import HISTORY_SAMPLES
from tests.support.scenes import jump_m


def force(t: np.ndarray) -> np.ndarray:
    return 1.0 + 0.5 * np.sin(t)


def test_extremes_over_many_times_equal_those_of_single_solves():
    prepared = core.prepare(1.0, jump_m, lambda x: 0.004 * x**2, breakpoints=(0.3,), tol=1e-6)
    times = np.linspace(1.0, 40.0, 2000)
    many = prepared.solve(times, force=force, moment=lambda t: 0.6 * np.cos(t))
    probe = np.union1d(times, np.linspace(1.0, 40.0, HISTORY_SAMPLES["elastic"]))
    assert probe.size > 4 * CHECK_BLOCK  # the extremes are sought over several blocks
    single = [prepared.solve([t], force=force(t), moment=0.6 * np.cos(t)) for t in probe]
    lowest = min(s.info["min_pressure"] for s in single)
    highest = max(s.info["max_pressure"] for s in single)
    # The same products in another grouping: measured 1.1e-16 (min) and 0 (max) apart.
    assert many.info["min_pressure"] == pytest.approx(lowest, rel=1e-13, abs=1e-15)
    assert many.info["max_pressure"] == pytest.approx(highest, rel=1e-13)
    # this moment lifts the punch off one edge at times (min q -0.93): the flag says so
    assert lowest < 0 and "contact_lost" in many.info["flags"]
    k = 1234
    assert many.settlement[k] == pytest.approx(single[np.searchsorted(probe, times[k])]
                                               .settlement[0], rel=1e-13)
    x = np.linspace(-1.0, 1.0, 41)
    q = many.pressure(x)
    assert q.shape == (41, times.size)
    one = single[np.searchsorted(probe, times[k])].pressure(x)[:, 0]
    assert np.max(np.abs(q[:, k] - one)) <= 1e-13 * np.max(np.abs(one))
