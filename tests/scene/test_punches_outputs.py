"""The files of an answer for several punches (core/scene/punches_output.py): the CSV of
every punch's histories, q over the whole surface (as CSV and as ``pressure(x)``) and the
design check of each punch in the global x."""

from __future__ import annotations

import csv
import io
from typing import Any

import numpy as np
import pytest

import core
from core import limits
from core.scene import PunchesSolution
from core.scene.punches_output import EDGE_ROUNDING
from tests.support.punch_pairs import ELASTIC, wide_and_narrow


def _pair(**extra: Any) -> dict[str, Any]:
    """Two punches 1.9 m apart on an elastic base: a wide one under a force and a moment,
    a narrow one held level under a force."""
    return wide_and_narrow(ELASTIC, {"end": 10.0, "count": 3}) | extra


@pytest.fixture(scope="module")
def pair() -> PunchesSolution:
    return core.solve(_pair())


def _table(text: str) -> list[dict[str, str]]:
    """The rows of a CSV text, its ``#`` lines skipped."""
    return list(csv.DictReader(line for line in io.StringIO(text) if not line.startswith("#")))


def test_the_histories_of_every_punch_in_one_table(pair: PunchesSolution) -> None:
    rows = _table(pair.to_csv())
    header = list(rows[0])
    assert header == ["time_day"] + [f"punches[{k}].{name}" for k in range(2) for name in
                                     ("settlement_m", "tilt_rad", "force_N_per_m",
                                      "moment_N")]
    assert [float(r["time_day"]) for r in rows] == pair.times.tolist()
    units = {"settlement": "m", "tilt": "rad", "force": "N_per_m", "moment": "N"}
    for k, punch in enumerate(pair.punches):
        for name, unit in units.items():
            # repr() of a float reads back to the same float: equal, not close
            assert [float(r[f"punches[{k}].{name}_{unit}"]) for r in rows] == \
                getattr(punch, name).tolist()


def test_one_punch_writes_the_single_punch_file_under_its_path() -> None:
    d = _pair()
    d["punches"] = d["punches"][:1]
    one = core.solve(d)
    single = core.solve(one.scene.scenes[0])
    head, *rows = one.to_csv(header=False).splitlines()
    single_head, *single_rows = single.to_csv(header=False).splitlines()
    assert head == "time_day," + ",".join(f"punches[0].{name}"
                                          for name in single_head.split(",")[1:])
    assert rows == single_rows


def test_the_pressure_over_the_surface_is_every_punch_on_its_zone(
        pair: PunchesSolution) -> None:
    rows = _table(pair.pressure_csv())
    assert list(rows[0]) == ["time_day", "x_m", "pressure_Pa"]
    n_x = sum(p.x.size for p in pair.punches)
    assert len(rows) == n_x * pair.times.size
    first = [r for r in rows if float(r["time_day"]) == pair.times[0]]
    x = np.array([float(r["x_m"]) for r in first])
    q = np.array([float(r["pressure_Pa"]) for r in first])
    assert np.all(np.diff(x) > 0)  # one curve along the surface, punches in order
    np.testing.assert_array_equal(x, pair.x)
    for punch in pair.punches:
        a, c = punch.scene.half_width, punch.center
        # the edge c + a less c is a rounding above a (the slack of pressure(x))
        on = np.abs(x - c) <= a * (1 + EDGE_ROUNDING)
        # every row is on a zone: the free surface between the punches is not written
        assert on.sum() == punch.x.size
        np.testing.assert_array_equal(q[on], punch.pressure_on_grid[:, 0])
    assert not np.any((x > -0.5) & (x < 0.9))  # the gap between the zones


def test_pressure_is_zero_on_the_free_surface_and_the_punch_on_its_zone(
        pair: PunchesSolution) -> None:
    x = np.array([-3.0, -2.5, -1.5, -0.5, 0.0, 0.9, 1.5, 2.1, 5.0])
    q = pair.pressure(x)
    assert q.shape == (x.size, pair.times.size)
    off = np.array([True, False, False, False, True, False, False, False, True])
    assert np.all(q[off] == 0.0)
    np.testing.assert_array_equal(q[1:4], pair.punches[0].pressure_at(x[1:4]))
    np.testing.assert_array_equal(q[5:8], pair.punches[1].pressure_at(x[5:8]))
    text = pair.pressure_csv(x)
    assert len(_table(text)) == x.size * pair.times.size


def test_pressure_refuses_what_it_cannot_answer(pair: PunchesSolution) -> None:
    with pytest.raises(ValueError, match=r"^x: positions must be finite"):
        pair.pressure([0.0, np.nan])
    too_many = limits.MAX_PRESSURE_VALUES // pair.times.size + 1
    with pytest.raises(ValueError, match=r"^x: .* more than"):
        pair.pressure(np.zeros(too_many))


def test_the_design_check_of_each_punch_is_in_the_global_x() -> None:
    result = core.solve(_pair(limits={"allowable_pressure": 4.0e5}))
    checks = result.design_checks()
    assert len(checks) == 2
    for punch, check in zip(result.punches, checks, strict=True):
        single = punch.design_check()  # the same check, x from the punch's centre
        assert check.check("q_max").value == single.check("q_max").value
        assert check.check("q_max").x == punch.center + single.check("q_max").x
        assert abs(check.check("q_max").x - punch.center) <= \
            punch.scene.half_width * (1 + EDGE_ROUNDING)
    assert core.solve(_pair()).design_checks() == [None, None]


def test_the_answer_as_an_xarray_dataset(pair: PunchesSolution, tmp_path) -> None:
    """The README's route to a dataset (``result.to_xarray()``) was missing for several
    punches: every punch's histories over (punch, time), q over the surface."""
    import json

    ds = pair.to_xarray()
    assert dict(ds.sizes) == {"punch": 2, "time": pair.times.size, "x": pair.x.size}
    for k, punch in enumerate(pair.punches):
        for name in ("settlement", "tilt", "force", "moment", "contact_width"):
            assert ds[name].sel(punch=k).values.tolist() == \
                np.asarray(getattr(punch, name), dtype=float).tolist()
        assert float(ds["center"][k]) == punch.center
    assert np.array_equal(ds["pressure"].values, pair.pressure_on_grid)
    assert ds["moment"].attrs["units"] == "N" and ds["x"].attrs["units"] == "m"
    assert json.loads(ds.attrs["scene"]) == pair.scene.to_dict()
    ds.to_netcdf(tmp_path / "pair.nc")    # every attribute a string or a number


def test_the_answer_plots_the_surface_and_every_punchs_histories(pair: PunchesSolution
                                                                ) -> None:
    """``result.plot()``, the README's route to a picture, was missing for several
    punches: q over the surface coloured by time, a line per punch on the histories."""
    import holoviews as hv
    from bokeh.models import Axis

    from core.scene import PUNCH_COLOURS

    layout = pair.plot(count=3)
    assert isinstance(layout, hv.Layout) and len(layout) == 3
    pressure, settlement, tilt = layout
    curves = list(pressure)
    assert len(curves) == 3 and curves[0].kdims[0].unit == "m"
    np.testing.assert_allclose(curves[-1].dimension_values(0), pair.x, rtol=0)
    for overlay, name in ((settlement, "settlement"), (tilt, "tilt")):
        lines = list(overlay)
        assert [c.label for c in lines] == ["punches[0]", "punches[1]"]
        for k, line in enumerate(lines):
            np.testing.assert_allclose(line.dimension_values(1),
                                       np.asarray(getattr(pair.punches[k], name)) * 1e3,
                                       rtol=1e-15)
            assert line.opts.get("style", backend="bokeh").kwargs["color"] == \
                PUNCH_COLOURS[k]
    labels = {a.axis_label for a in hv.render(layout, backend="bokeh").select(
        {"type": Axis})}
    assert {"x (m)", "t (day)", "settlement (mm)", "tilt (mrad)"} <= labels


def test_the_json_is_headed_as_one_punchs_and_checks_each_punch_in_the_global_x() -> None:
    """The JSON of several punches had no format, program, version nor solver (a script
    checking them failed on every such file), and each punch's design check read x on
    the punch's own coordinates (q_max "at x = 1.0 m" where the report and
    design_checks() say 4 m), beside a contact set in the global x."""
    import json

    result = core.solve(_pair(limits={"allowable_pressure": 5e5, "settlement_limit": 0.01}))
    d = json.loads(result.to_json())
    assert d["format"] == "coated-punch solution of several punches"
    assert d["program"] == "coated-punch" and d["version"] == core.__version__
    assert d["solver"]["tol"] == result.scene.to_dict()["solver"]["tol"]
    assert d["flags"] == result.flags and d["units"]["center"] == "m (global x)"
    for k, (record, check) in enumerate(zip(d["punches"], result.design_checks(),
                                            strict=True)):
        assert record["center"] == result.punches[k].center
        assert record["design_check"] == json.loads(json.dumps(check.to_dict()))
        assert record["units"]["contact_set"] == "m (global x)"
    # punch 1 sits right of the origin: its x are the global ones, not its own
    q_max = next(c for c in d["punches"][1]["design_check"]["checks"]
                 if c["quantity"] == "q_max")
    assert q_max["x_m"] > result.punches[0].scene.half_width
