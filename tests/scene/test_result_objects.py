"""A scene's answer for people and data tools: its repr and HTML table, its xarray Dataset
and pandas DataFrame with units and metadata, its HoloViews plot, a lift-off preset and a
flagged answer; the short repr of the dimensionless answers."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

import core
from core.scene import FLAG_MESSAGES, SceneSolution, days_text, scene_from_dict, solve
from core.scene.files import scene_to_json
from tests.conftest import base_scene, scene_file

HISTORY_UNITS = {"settlement": "m", "tilt": "rad", "force": "N/m", "moment": "N",
                 "contact_width": "m"}
#: Characters HTML must escape, in a scene's name (where a user may type them).
ODD_NAME = '<script>alert("x")</script> & \'quotes\''


@pytest.fixture(scope="module")
def full() -> SceneSolution:
    """The uniform preset over a few times (full contact, no flag)."""
    return solve(base_scene())


@pytest.fixture(scope="module")
def lift_off() -> SceneSolution:
    """The lift-off preset as shipped (unilateral contact: the heel lifts off)."""
    return solve(scene_file("eccentric_footing_liftoff"))


@pytest.fixture(scope="module")
def flagged() -> SceneSolution:
    """The lift-off preset forced into full contact, named with HTML's special characters:
    flagged ``contact_lost``."""
    scene = scene_file("eccentric_footing_liftoff")
    scene["name"] = ODD_NAME
    scene["times"] = {"end": 100.0, "count": 4, "spacing": "log"}
    scene["solver"]["contact"] = "full"
    return solve(scene)


# ---------------------------------------------------------------------------------- repr


def test_repr_holds_the_key_figures_with_units(full: SceneSolution) -> None:
    text = repr(full)
    lines = text.splitlines()
    assert lines[0].startswith("SceneSolution 'Uniform coating, flat punch': statement 4 "
                               "(force, moment given), 3 output times")
    assert 4 <= len(lines) <= 6
    settlement_mm = full.settlement[-1] * 1e3
    assert f"settlement {settlement_mm:.4g} mm" in text
    assert f"force {full.force[-1] / 1e3:.4g} kN/m" in text
    for unit in (" mrad", " kN m/m", " MPa"):
        assert unit in text
    assert f"{full.info['error_estimate']:.2g} numerical" in text
    assert f"{full.model_error['estimate']:.2g} coating model" in text
    assert "flags: none" in text
    assert "engine: nystrom engine, full contact, thin layer coating model" in text
    assert "contact width" not in text  # full contact: nothing lifts off


def test_repr_of_a_lift_off_gives_the_contact_width(lift_off: SceneSolution) -> None:
    text = repr(lift_off)
    width = sum(hi - lo for lo, hi in lift_off.contact_set[-1])
    assert f"contact width {width:.4g} m of 2a = 2 m (lift-off" in text
    assert "unilateral contact solver" in text


def test_repr_names_the_flags(flagged: SceneSolution) -> None:
    assert flagged.flags == ["contact_lost"]
    assert "flags: contact_lost" in repr(flagged)


def test_html_escapes_everything_and_shows_flags_in_red(flagged: SceneSolution) -> None:
    page = flagged._repr_html_()
    assert "<script>" not in page and "&lt;script&gt;" in page
    assert "&amp;" in page and "&#x27;quotes&#x27;" in page
    import html

    message = html.escape(FLAG_MESSAGES["contact_lost"])
    assert f'<span style="color:#c00000"><b>contact_lost</b>: {message}</span>' in page
    # the time, five figures (no contact width: full contact), the errors, flags, engine
    assert page.count("<tr>") == 9


def test_html_of_an_unflagged_answer(full: SceneSolution) -> None:
    page = full._repr_html_()
    assert page.startswith('<div class="coated-punch-solution"><table>')
    assert "color:" not in page and ">none<" in page
    assert f"{full.settlement[-1] * 1e3:.4g} mm" in page


def test_dimensionless_answers_have_a_short_repr(full: SceneSolution,
                                                 lift_off: SceneSolution) -> None:
    for result, name in ((full, "ContactSolution nystrom"),
                         (lift_off, "UnilateralSolution unilateral contact")):
        text = repr(result.dimensionless)
        assert text.startswith(f"<{name}, dimensionless: {len(result.times)} times")
        # one line, not the arrays: the default dataclass repr was 3-4 thousand characters
        assert "\n" not in text and len(text) < 300
        assert "flags: none" in text


# ------------------------------------------------------------------------------ xarray


def test_to_xarray_dims_units_and_metadata(lift_off: SceneSolution) -> None:
    import xarray  # noqa: F401  (installed by the test set-up)
    ds = lift_off.to_xarray()
    assert dict(ds.sizes) == {"x": len(lift_off.x), "time": len(lift_off.times)}
    assert ds.pressure.dims == ("x", "time")
    assert ds.time.attrs["units"] == "day" and ds.x.attrs["units"] == "m"
    assert ds.pressure.attrs["units"] == "Pa"
    for name, unit in HISTORY_UNITS.items():
        assert ds[name].dims == ("time",) and ds[name].attrs["units"] == unit
        assert ds[name].attrs["long_name"]
    np.testing.assert_array_equal(ds.pressure.values, lift_off.pressure_on_grid)
    np.testing.assert_array_equal(ds.settlement.values, lift_off.settlement)
    np.testing.assert_array_equal(ds.time.values, lift_off.times)
    attrs = ds.attrs
    assert attrs["version"] == core.__version__
    assert attrs["scene"] == scene_to_json(lift_off.scene)
    assert scene_from_dict(json.loads(attrs["scene"])) == lift_off.scene
    settings = json.loads(attrs["solver_settings"])
    assert settings["tol"] == 1e-4 and settings["model_tol"] == 0.02
    assert settings["contact"] == "auto" and settings["contact_model"] == "unilateral"
    assert attrs["flags"] == "" and attrs["error_estimate"] == lift_off.info["error_estimate"]
    assert attrs["model_error_estimate"] == lift_off.model_error["estimate"]


def test_to_xarray_round_trips_through_netcdf(flagged: SceneSolution, tmp_path: Path) -> None:
    import xarray as xr

    # scipy's netCDF-3 engine: the one the study files are written with (scipy is always
    # installed)
    engine = "scipy"
    ds = flagged.to_xarray()
    path = tmp_path / "result.nc"
    ds.to_netcdf(path, engine=engine)
    with xr.open_dataset(path, engine=engine) as back:
        xr.testing.assert_identical(back.load(), ds)
        assert back.attrs["flags"] == "contact_lost"
        assert json.loads(back.attrs["flag_messages"]) == flagged.flag_messages
        assert back.attrs["scene_name"] == ODD_NAME


def test_to_dataframe_holds_the_histories(lift_off: SceneSolution) -> None:
    import pandas  # noqa: F401  (installed by the test set-up)
    frame = lift_off.to_dataframe()
    assert frame.index.name == "time"
    np.testing.assert_array_equal(frame.index.to_numpy(), lift_off.times)
    assert list(frame.columns) == list(HISTORY_UNITS)
    np.testing.assert_array_equal(frame["tilt"].to_numpy(), lift_off.tilt)
    assert frame.attrs["units"] == {"time": "day", **HISTORY_UNITS}
    assert frame.attrs["version"] == core.__version__
    assert frame.attrs["scene"] == lift_off.to_xarray().attrs["scene"]


def test_a_missing_data_library_names_the_extra(full: SceneSolution,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "xarray", None)
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match=r"xarray is needed for SceneSolution.to_xarray.*"
                                          r"pip install 'coated-punch\[data\]'"):
        full.to_xarray()
    with pytest.raises(ImportError, match=r"pandas is needed for SceneSolution.to_dataframe"):
        full.to_dataframe()


def test_the_json_records_the_version(full: SceneSolution) -> None:
    data = json.loads(full.to_json())
    assert data["version"] == core.__version__
    assert data["scene"]["solver"] == {"tol": 1e-3, "model_tol": 0.02}


# -------------------------------------------------------------------------------- plot


def _curves(overlay):
    import holoviews as hv

    return [e for e in overlay if isinstance(e, hv.Curve)]


def test_plot_is_a_layout_of_pressures_settlement_and_tilt(full: SceneSolution) -> None:
    import holoviews as hv
    layout = full.plot()
    assert isinstance(layout, hv.Layout) and len(layout) == 3
    overlay, settlement, tilt = layout
    assert isinstance(overlay, hv.Overlay)
    curves = _curves(overlay)
    assert [c.label for c in curves] == [f"t = {days_text(t)}" for t in full.times]
    assert curves[0].kdims[0].unit == "m" and curves[0].vdims[0].unit == "kPa"
    # q below 1 MPa is drawn in kPa
    np.testing.assert_allclose(curves[-1].dimension_values("q"),
                               full.pressure_on_grid[:, -1] / 1e3, rtol=1e-15)
    assert settlement.vdims[0].unit == "mm" and tilt.vdims[0].unit == "mrad"
    np.testing.assert_allclose(settlement.dimension_values("settlement"),
                               full.settlement * 1e3, rtol=1e-15)
    assert settlement.kdims[0].unit == "day"
    colours = {c.opts.get("style", backend="bokeh").kwargs["color"] for c in curves}
    assert len(colours) == len(curves)


def test_plot_of_a_lift_off_shades_it_and_says_so(lift_off: SceneSolution) -> None:
    import holoviews as hv
    layout = lift_off.plot(count=4)
    overlay = layout[0]
    assert len(_curves(overlay)) == 4
    assert [c.label for c in _curves(overlay)][-1] == "t = 1000 days (2.7 years)"
    assert "MPa" == _curves(overlay)[0].vdims[0].unit
    spans = [e for e in overlay if isinstance(e, hv.VSpan)]
    lo = lift_off.contact_set[-1][0][0]
    assert [tuple(s.data) for s in spans] == [(-1.0, lo)]
    options = overlay.opts.get("plot", backend="bokeh").kwargs
    # on a line of its own: beside the title, the zone was cut at the plot's width
    assert options["title"].split("\n")[1].startswith("lift-off at t = 1000 days (2.7 years)")
    # the overlay names its axes: the span's dimensions (x, y) must not
    assert (options["xlabel"], options["ylabel"]) == ("x (m)", "q (MPa)")


def test_plot_titles_carry_the_flags_and_render_with_bokeh(flagged: SceneSolution) -> None:
    import holoviews as hv
    from bokeh.models import Axis, Title

    layout = flagged.plot(times=[0.0, 100.0])
    assert [c.label for c in _curves(layout[0])] == ["t = 0 days", "t = 100 days"]
    assert layout.opts.get("plot", backend="bokeh").kwargs["title"] == \
        f"{ODD_NAME}: flags contact_lost"
    figure = hv.render(layout, backend="bokeh")
    titles = [t.text for t in figure.select({"type": Title})]
    assert any("contact lost" in t for t in titles)
    labels = {a.axis_label for a in figure.select({"type": Axis})}
    assert {"x (m)", "q (MPa)", "t (day)", "settlement (mm)", "tilt (mrad)"} <= labels


def test_percentages_for_people_never_in_exponent_notation():
    from core.scene import percent_text

    # a numerical estimate of 5e-10 read "5e-08 %"
    assert [percent_text(x) for x in (5e-10, 0.0181, 0.02, 0.000123, 0.0, 15.5)] == [
        "< 0.001 %", "1.81 %", "2 %", "0.0123 %", "0 %", "1550 %"]
    assert percent_text(0.0464, 2) == "4.6 %"
    # a 1000 km coating's estimate read "16556648 %"
    assert percent_text(165566.48) == "> 10000 %" and percent_text(100.0) == "10000 %"


@pytest.mark.parametrize(("x", "message"), [
    (np.zeros((2, 3)), "x: a number or a list of positions [m] (one dimension)"),
    ("abc", "x: positions must be numbers [m], got 'abc'"),
    ([float("nan")], "x: positions must be finite numbers [m]"),
    ([2.0], "x: the pressure is defined on [-a, a]"),
])
def test_bad_positions_of_the_pressure_are_named(x, message):
    # a 2-D array gave NumPy's "operands could not be broadcast together"
    result = solve(scene_file("uniform_flat"))
    with pytest.raises(ValueError) as info:
        result.pressure(x)
    assert str(info.value).startswith(message), str(info.value)


@pytest.mark.parametrize("contact", ["full", "unilateral"])
def test_the_dimensionless_pressure_is_bounded_as_the_scene_one(contact):
    """``ContactSolution.pressure`` took any number of points: 5e6 ran 94 s (the scene's
    solution refuses more than MAX_PRESSURE_VALUES values at once)."""
    from core import limits
    from core.solver import solve_dimensionless

    answer = solve_dimensionless(1.0, 0.05, 0.0, [1.0, 2.0], force=1.0, moment=0.5,
                                 tol=1e-4, contact=contact)
    too_many = np.zeros(limits.MAX_PRESSURE_VALUES // 2 + 1)
    with pytest.raises(ValueError, match=r"^x: 2000001 points at 2 times are more than the "
                                         r"4000000 pressure values one call may compute"):
        answer.pressure(too_many)
    with pytest.raises(ValueError, match=r"^x: a number or a list of positions"):
        answer.pressure(np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"^x: pressure is defined on \[-1, 1\] only"):
        answer.pressure([1.5])
    assert answer.pressure(0.25).shape == (1, 2)


def test_a_notebook_reads_long_times_in_days_and_years() -> None:
    """A 50-year answer's repr and HTML table read "0 to 1.826e+04 days" and "at t =
    1.826e+04 days", where the page and the report read "18262.5 days (50.0 years)"."""
    result = solve(core.load_scene("preset:young_concrete_50_years"))
    text, table = repr(result), result._repr_html_()
    assert "0 to 18262.5 days (50.0 years) after loading" in text
    assert "at t = 18262.5 days (50.0 years):" in text
    assert "at t = 18262.5 days (50.0 years) after loading" in table
    assert "e+04" not in text + table
