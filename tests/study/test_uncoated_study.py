"""A study over a scene with no coating layers: the load batch answers it like single solves."""

from __future__ import annotations

import numpy as np
import pytest

from core import solve
from core.presets import read_preset
from core.study import study_from_dict, sweep


def test_a_load_study_of_the_bare_layer_matches_single_solves_lifted_off_or_not():
    scene = read_preset("bare_layer")
    moments = np.linspace(0.0, 4.0e5, 5)
    study = study_from_dict({
        "study_version": 1, "name": "bare eccentricity", "scene": scene,
        "vary": [{"field": "loading.moment", "linspace": {"start": 0.0, "stop": 4.0e5,
                                                          "count": 5}}],
        "outputs": ["settlement", "tilt", "q_max", "contact_width"], "times": [1.0]})
    ds = sweep(study, client="serial")
    tilt = ds["tilt"].values.reshape(5)
    width = ds["contact_width"].values.reshape(5)
    errors = ds["error"].values.reshape(5)
    for k, moment in enumerate(moments):
        single = solve(dict(scene, loading={"force": 5.0e5, "moment": float(moment)}))
        # the batch reads the very unit responses the single solve reads (full contact), or
        # solves the point alone (e = 0.6 a and 0.8 a lift the heel off): measured equal
        assert tilt[k] == pytest.approx(single.tilt[0], rel=1e-12, abs=1e-30)
        assert width[k] == pytest.approx(float(single.contact_width[0]), rel=1e-12)
        assert errors[k] == ""
    assert np.all(width[:3] == 2.0) and np.all(width[3:] < 2.0)
