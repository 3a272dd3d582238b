"""``python -m core calibrate``: a fit written as JSON with its forecast, one-line errors
naming the row and column of a bad reading, and ``--strict`` on a warning."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np

import core
from core.back_analysis import readings_csv
from core.cli import EXIT_BAD_INPUT, EXIT_FLAGGED, EXIT_OK
from tests.back_analysis.test_fit import SCENE, SETTLEMENT_STD, TIMES
from tests.cli_runs import run_cli


def _files(tmp_path: Path, noise: float = SETTLEMENT_STD) -> tuple[Path, Path]:
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(SCENE))
    exact = core.solve(dict(SCENE, times=TIMES.tolist()))
    rng = np.random.default_rng(3)
    readings = tmp_path / "readings.csv"
    readings.write_text(readings_csv({
        "time": TIMES.tolist(),
        "settlement": (exact.settlement + noise * rng.standard_normal(TIMES.size)).tolist(),
        "settlement_std": [noise] * TIMES.size}))
    return scene, readings


def test_calibrate_writes_the_fit_and_its_forecast(tmp_path: Path) -> None:
    scene, readings = _files(tmp_path)
    out = tmp_path / "fit.json"
    proc = run_cli("calibrate", scene, readings, "--fit", "base.creep.compliance",
                   "--fit", "base.creep.rate", "--bound", "base.creep.rate=1e-3,",
                   "--forecast", "3650", "--forecast-count", "20", "--output", out,
                   cwd=tmp_path)
    assert proc.returncode == EXIT_OK, proc.stderr
    assert "base.creep.rate" in proc.stdout and "chi^2/dof" in proc.stdout
    d = json.loads(out.read_text())
    assert [f["path"] for f in d["fields"]] == ["base.creep.compliance", "base.creep.rate"]
    assert d["fields"][1]["bounds"] == [1e-3, None]
    assert len(d["forecast"]["times"]) == 20 and d["forecast"]["units"]["settlement"] == "m"
    assert d["fitted_scene"]["base"]["creep"]["rate"] == d["fields"][1]["value"]


def test_a_bad_reading_is_one_line_naming_row_and_column(tmp_path: Path) -> None:
    scene, readings = _files(tmp_path)
    lines = readings.read_text().splitlines()
    lines[3], lines[4] = lines[4], lines[3]
    readings.write_text("\n".join(lines) + "\n")
    proc = run_cli("calibrate", scene, readings, "--fit", "loading.force", cwd=tmp_path)
    assert proc.returncode == EXIT_BAD_INPUT
    assert proc.stderr.startswith(f"error: {readings}: line 5, column time:"), proc.stderr
    assert len(proc.stderr.splitlines()) == 1


def test_bad_fit_and_bound_arguments(tmp_path: Path) -> None:
    scene, readings = _files(tmp_path)
    proc = run_cli("calibrate", scene, readings, "--fit", "coating[2].modulus", cwd=tmp_path)
    assert proc.returncode == EXIT_BAD_INPUT
    assert proc.stderr.startswith("error: fit[0]: coating[2].modulus: no such field")
    proc = run_cli("calibrate", scene, readings, "--fit", "loading.force", "--bound",
                   "loading.moment=0,1", cwd=tmp_path)
    assert proc.returncode == EXIT_BAD_INPUT
    assert proc.stderr.startswith("error: --bound: 'loading.moment' is not one of the")


def test_strict_fails_on_a_warning(tmp_path: Path) -> None:
    scene, readings = _files(tmp_path)
    proc = run_cli("calibrate", scene, readings, "--fit", "coating[0].thickness", "--fit",
                   "coating[0].modulus", "--strict", "--output", tmp_path / "f.json", cwd=tmp_path)
    assert proc.returncode == EXIT_FLAGGED, proc.stderr
    assert "warning: calibrate: not identifiable" in proc.stderr


def test_the_forecasts_options_are_named_as_typed(tmp_path: Path) -> None:
    """``--forecast 0`` was left out without a word (exit 0, no forecast); ``-5`` and
    ``--forecast-count 0`` were refused as ``times.end`` and ``times.count``, and ``1e9``
    as ``times.end`` still."""
    from core.cli import main

    scene, readings = _files(tmp_path)
    cases = [(["--forecast", "0"], "error: --forecast: must be a number of days > 0, got 0"),
             (["--forecast", "-5"], "error: --forecast: must be a number of days > 0, got -5"),
             # a forecast past the latest time a scene takes read "times.end: ..."
             (["--forecast", "1e9"], "error: --forecast: must be <= 100000 days after "
                                     "loading (about 274 years), got 1e+09"),
             (["--forecast", "100", "--forecast-count", "0"],
              "error: --forecast-count: must be a whole number from 1 to 2000, got 0")]
    for extra, said in cases:
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            code = main(["calibrate", str(scene), str(readings), "--fit", "loading.force",
                         *extra])
        assert code == EXIT_BAD_INPUT and err.getvalue().startswith(said), err.getvalue()


def test_a_forecast_past_a_design_codes_span_is_refused_before_the_fit(tmp_path: Path
                                                                         ) -> None:
    """A design code's law is fitted for 100 years: --forecast 50000 on such a scene ran
    the whole fit, then read "times.end: must be <= 36525 days" (a review)."""
    from core.cli import main
    from core.presets import read_preset

    scene = tmp_path / "young.json"
    scene.write_text(json.dumps(read_preset("young_concrete_50_years")))
    readings = tmp_path / "r.csv"
    readings.write_text("time [day], settlement [mm]\n30, 0.05\n100, 0.06\n")
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["calibrate", str(scene), str(readings), "--fit",
                     "base.creep.relative_humidity", "--forecast", "50000"])
    assert code == EXIT_BAD_INPUT
    assert err.getvalue().startswith("error: --forecast: must be <= 36525 days after "
                                     "loading (100 years"), err.getvalue()


def test_a_history_this_program_wrote_says_how_to_fit_it(tmp_path: Path) -> None:
    """SCENES.md said such a history "reads as it is"; it holds settlement and tilt, and
    the refusal ("settlement_std: required when both ... are fitted") said no way on."""
    scene, _ = _files(tmp_path)
    history = tmp_path / "history.csv"
    proc = run_cli("solve", scene, "-o", history, cwd=tmp_path)
    assert proc.returncode == EXIT_OK, proc.stderr
    proc = run_cli("calibrate", scene, history, "--fit", "base.creep.compliance",
                   cwd=tmp_path)
    assert proc.returncode == EXIT_BAD_INPUT
    assert proc.stderr.startswith("error: settlement_std: required when both settlements "
                                  "and tilts are fitted")
    assert "add the settlement_std and tilt_std columns, or leave out the series not to " \
           "fit" in proc.stderr
    # its tilt column left out, it fits as it is
    lines = history.read_text().splitlines()
    head = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    names = lines[head].split(",")
    keep = [i for i, name in enumerate(names) if not name.startswith("tilt")]
    history.write_text("\n".join([*lines[:head], *(",".join(row.split(",")[i] for i in keep)
                                                 for row in lines[head:])]) + "\n")
    proc = run_cli("calibrate", scene, history, "--fit", "base.creep.compliance",
                   cwd=tmp_path)
    assert proc.returncode == EXIT_OK, proc.stderr


def test_a_scene_of_several_punches_is_refused_in_one_line(tmp_path: Path) -> None:
    """It was refused with the whole repr of the scene (11 kB on one line)."""
    _, readings = _files(tmp_path)
    proc = run_cli("calibrate", "preset:new_footing_beside_old", readings, "--fit",
                   "base.poisson", cwd=tmp_path)
    assert proc.returncode == EXIT_BAD_INPUT
    assert proc.stderr == ("error: scene: holds 2 punches (punches); a fit takes a scene of "
                           "one punch, whose readings are its settlement and tilt\n")


def test_a_forecast_band_is_given_where_it_is_determined_and_none_where_not(
        tmp_path: Path, monkeypatch) -> None:
    """The readings fix a coating's h / E alone, and the settlement depends on that ratio
    alone: its band is the ratio's (finite). A forecast the readings do not determine has
    none, said so (the summary would have printed "[-inf, inf] m")."""
    from core.back_analysis.result import Calibration

    scene, readings = _files(tmp_path)
    args = ("calibrate", scene, readings, "--fit", "coating[0].thickness", "--fit",
            "coating[0].modulus", "--forecast", "3650")
    proc = run_cli(*args, cwd=tmp_path)
    assert proc.returncode == EXIT_OK, proc.stderr
    line = next(t for t in proc.stdout.splitlines() if t.startswith("forecast at"))
    assert "inf" not in line and "% band [" in line, line
    monkeypatch.setattr(Calibration, "_forecast_variance",
                        lambda self, gradient: np.full(gradient.shape[0], np.inf))
    proc = run_cli(*args, cwd=tmp_path)
    line = next(t for t in proc.stdout.splitlines() if t.startswith("forecast at"))
    assert line.endswith("% band none: the readings do not determine it (see the warnings)")
