"""Findings of a red-team pass (issue 19), each reproduced by a test before its fix.

Bounded work (limits checked before the work), files (the CLI never overwrites its own
input or a read-only file, writes through symlinks, refuses non-regular files), text
fields bounded in length, load histories that vary too fast for the time stepper, the
times where a history jumps, and refusals that name the scene field.
"""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from core import limits
from core.cli import main
from core.scene import load_scene, save_scene, scene_from_dict

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "assets" / "scenes"


def scene_dict() -> dict:
    return json.loads((SCENES / "uniform_flat.json").read_text())


def elastic_dict(**changes) -> dict:
    """The uniform preset on an elastic base, few times: a solve of ~0.1 s."""
    d = scene_dict()
    d["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    d["times"] = {"end": 10.0, "count": 3}
    d.update(changes)
    return d


def write_scene(path: Path, d: dict | None = None) -> Path:
    path.write_text(json.dumps(d or elastic_dict()))
    return path


# ------------------------------------------------------------------------ item 8: files


def test_cli_refuses_to_overwrite_its_input(tmp_path: Path, capsys):
    scene = write_scene(tmp_path / "scene.json")
    before = scene.read_text()
    assert main(["solve", str(scene), "--output", str(scene)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --output:") and "scene file" in err
    assert scene.read_text() == before
    # also through another spelling of the same path, and through a link to it
    other = tmp_path / "sub" / ".." / "scene.json"
    (tmp_path / "sub").mkdir()
    assert main(["solve", str(scene), "--pressure-csv", str(other)]) == 2
    link = tmp_path / "link.json"
    link.symlink_to(scene)
    assert main(["solve", str(link), "--output", str(scene)]) == 2
    assert scene.read_text() == before


def test_cli_refuses_two_outputs_to_one_path(tmp_path: Path, capsys):
    scene = write_scene(tmp_path / "scene.json")
    out = tmp_path / "out.csv"
    assert main(["solve", str(scene), "--output", str(out), "--pressure-csv", str(out)]) == 2
    assert "--pressure-csv" in capsys.readouterr().err
    assert not out.exists()


def test_cli_respects_a_read_only_output(tmp_path: Path, capsys):
    scene = write_scene(tmp_path / "scene.json")
    out = tmp_path / "result.csv"
    out.write_text("keep me\n")
    out.chmod(0o444)
    assert main(["solve", str(scene), "--output", str(out)]) == 2
    assert "read-only" in capsys.readouterr().err
    assert out.read_text() == "keep me\n"
    # save_scene too (the explorer's and the library's save)
    with pytest.raises(ValueError, match="read-only"):
        save_scene(load_scene(scene), out)
    assert out.read_text() == "keep me\n"


def test_cli_writes_through_a_symlink(tmp_path: Path):
    scene = write_scene(tmp_path / "scene.json")
    target = tmp_path / "data" / "result.csv"
    target.parent.mkdir()
    target.write_text("old\n")
    link = tmp_path / "result.csv"
    link.symlink_to(target)
    assert main(["solve", str(scene), "--output", str(link)]) == 0
    assert link.is_symlink()  # still a link, not replaced by a regular file
    assert target.read_text().startswith("time_day,")


def test_cli_refuses_non_regular_files(tmp_path: Path):
    """A named pipe as the scene file used to wait forever for a writer."""
    fifo = tmp_path / "scene.json"
    os.mkfifo(fifo)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    for command in (["validate", str(fifo)], ["solve", str(fifo)]):
        proc = subprocess.run([sys.executable, "-m", "core", *command], cwd=ROOT, env=env,
                              capture_output=True, text=True, timeout=60)
        assert proc.returncode == 2
        assert "not a regular file" in proc.stderr
    scene = write_scene(tmp_path / "ok.json")
    with pytest.raises(ValueError, match="not a regular file"):
        load_scene(tmp_path)  # a directory
    out_fifo = tmp_path / "out.csv"
    os.mkfifo(out_fifo)
    assert main(["solve", str(scene), "--output", str(out_fifo)]) == 2
    assert stat.S_ISFIFO(os.lstat(out_fifo).st_mode)


# ------------------------------------------------------------------- item 6: text fields


@pytest.mark.parametrize("field, limit", [("name", limits.MAX_NAME_CHARS),
                                          ("description", limits.MAX_DESCRIPTION_CHARS)])
def test_text_fields_are_bounded(field: str, limit: int, tmp_path: Path):
    scene_from_dict(elastic_dict(**{field: "x" * limit}))
    long = elastic_dict(**{field: "x" * 15_000_000})
    with pytest.raises(ValueError, match=rf"^{field}: .*at most {limit} characters"):
        scene_from_dict(long)
    # the same refusal from a file and from the JSON text of a link
    with pytest.raises(ValueError, match=rf"^{field}: "):
        load_scene(write_scene(tmp_path / "long.json", elastic_dict(**{field: "y" * (
            limit + 1)})))


# ------------------------------------------------------- item 1: a work budget per solve


class _ExponentialKernel:
    """``K(t, tau) = -amplitude exp(-rate (t - tau))`` (non-aging): degenerate, and a
    plain callable for the general path. Records the largest block it is asked for."""

    def __init__(self, amplitude: float, rate: float) -> None:
        self.amplitude, self.rate_value = amplitude, rate
        self.rates = np.array([rate])
        self.largest_call = 0

    def tau_part(self, tau):
        return np.zeros(np.shape(tau))

    def exponential_parts(self, tau):
        return np.full((1,) + np.shape(tau), -self.amplitude)

    def __call__(self, t, tau):
        t, tau = np.broadcast_arrays(np.asarray(t, float), np.asarray(tau, float))
        self.largest_call = max(self.largest_call, t.size)
        return np.where(t >= tau, -self.amplitude * np.exp(-self.rate_value * (t - tau)), 0.0)


def _one_mode(load, d: float = 2.0):
    from core.time import ModalProblem
    return ModalProblem(d=lambda t: np.full((1, np.size(t)), d),
                        r=lambda t: np.asarray(load(np.asarray(t, float)), float)[None, :],
                        u=lambda t: np.zeros((0, np.size(t))), coupling=np.zeros((1, 0)))


def _exact_step_response(times, t_break, d, amplitude, rate, before=1.0, after=3.0):
    """``d w - V w = r`` for r = ``before`` up to ``t_break``, ``after`` from it on:
    ``S = V w`` obeys ``S' = -(rate + amplitude/d) S - amplitude r / d`` (closed form on
    each piece), and ``w = (r + S)/d``."""
    lam, beta = rate + amplitude / d, amplitude / d

    def piece(t, t0, s0, r):
        s_inf = -beta * r / lam
        return s_inf + (s0 - s_inf) * np.exp(-lam * (t - t0))

    s_break = piece(t_break, 1.0, 0.0, before)
    t = np.asarray(times, float)
    s = np.where(t < t_break, piece(t, 1.0, 0.0, before), piece(t, t_break, s_break, after))
    r = np.where(t < t_break, before, after)
    return (r + s) / d


def test_general_kernel_grid_is_checked_before_it_is_built():
    """5000 output times used to ask for a 20001-point grid (a 3.2 GB matrix)."""
    from core.time import solve_general
    kernel = _ExponentialKernel(0.5, 1.0)
    times = np.linspace(1.0, 3.0, 5000)
    with pytest.raises(ValueError, match=r"^times: 5000 output times need .* more than "
                                         rf"the {limits.MAX_KERNEL_GRID_POINTS}"):
        solve_general(kernel, _one_mode(lambda t: np.ones_like(t)), times, tol=1e-8)
    assert kernel.largest_call == 0  # refused before any kernel evaluation


def test_general_kernel_grid_stays_within_its_limit():
    """2000 output times: grids of 2001 and 4001 points; the next (8001) is never built,
    and the kernel matrix is evaluated in blocks within the formula budget."""
    from core.time import solve_general
    kernel = _ExponentialKernel(0.5, 1.0)
    times = np.linspace(1.0, 3.0, 2000)
    sol = solve_general(kernel, _one_mode(lambda t: np.ones_like(t)), times, tol=1e-12)
    assert sol.steps + 1 <= limits.MAX_KERNEL_GRID_POINTS
    assert kernel.largest_call <= limits.KERNEL_BLOCK_ELEMENTS
    exact = _exact_step_response(times, 10.0, 2.0, 0.5, 1.0)
    error = float(np.max(np.abs(sol.w[0] - exact)) / np.max(np.abs(exact)))
    # measured 3.3e-16 (extrapolated, two grids) against an estimate of 3.1e-09
    assert error <= sol.error_estimate
    assert not sol.success and "3999 points" in sol.message


def test_formula_temporaries_are_bounded():
    from core.profiles import parse_expression
    expr = parse_expression("t - (tau - (t - (tau - (t - tau))))", ("t", "tau"))
    n = 3000  # 9e6 points times the formula's live arrays: over the budget
    with pytest.raises(ValueError, match="evaluate it in blocks"):
        expr(np.ones((n, 1)), np.ones((1, n)))
    assert expr(np.ones((100, 1)), np.ones((1, 100))).shape == (100, 100)


GUARD = """
import resource, sys, time, json
resource.setrlimit(resource.RLIMIT_AS, ({limit_mib} * 2**20,) * 2)
sys.path.insert(0, {root!r})
from core.scene.pipeline import scene_from_dict, solve
d = json.loads({scene!r})
t0 = time.perf_counter()
try:
    result = solve(scene_from_dict(d))
    print(json.dumps({{"solved": True, "message": result.info["message"],
                      "flags": result.flags}}))
except ValueError as exc:
    print(json.dumps({{"solved": False, "message": str(exc)}}))
"""


def _nested_kernel_scene() -> dict:
    e = "exp(-0.03*(t-tau))"
    for k in range(8):
        e = f"(0.5+0.5*{e})*(1+0*(t-tau+{k}))"
    d = scene_dict()
    d["base"]["creep"] = {"model": "kernel", "modulus": 3e10, "expr": f"-0.01*{e}"}
    d["times"] = {"end": 365.0, "count": 2000}
    return d


def test_small_scene_with_a_nested_kernel_formula_is_bounded():
    """A 1.1 kB scene (a nested kernel formula, 2000 output times) took 2.6 GB here
    (9.5 GiB in the report): it must now solve within 1.2 GiB of address space."""
    script = GUARD.format(limit_mib=1200, root=str(ROOT),
                          scene=json.dumps(_nested_kernel_scene()))
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=300, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert proc.returncode == 0, proc.stderr[-2000:]
    outcome = json.loads(proc.stdout.splitlines()[-1])
    assert outcome["solved"], outcome


# ------------------------------------------- item 3 (support): steps that stop at jumps

# the case in the time stepper's own terms: a load stepping up 3x at 3.3 days
# after loading at 28 days (t = age / 28), creep at 0.05/day, outputs over a year
_JUMP = 1.0 + 3.3 / 28
_RATE = 0.05 * 28 / 10


def _step_load(t):
    return np.where(t >= _JUMP, 3.0, 1.0)


@pytest.mark.parametrize("tol", [1e-6, 1e-8])
def test_steps_stop_at_a_jump_of_the_load(tol: float):
    from core.time import solve_degenerate
    times = np.sort(np.concatenate([np.linspace(1.0, 1.0 + 365 / 28, 40), [_JUMP]]))
    exact = _exact_step_response(times, _JUMP, 2.0, 0.5, _RATE)
    kernel = _ExponentialKernel(0.5, _RATE)
    # the finding: without the jump the estimate reads 2.8e-8 while the error is 2.9e-3
    blind = solve_degenerate(kernel, _one_mode(_step_load), times, tol=tol)
    assert np.max(np.abs(blind.w[0] - exact)) / np.max(np.abs(exact)) > 1000 * tol
    sol = solve_degenerate(kernel, _one_mode(_step_load), times, tol=tol, breaks=[_JUMP])
    error = float(np.max(np.abs(sol.w[0] - exact)) / np.max(np.abs(exact)))
    # measured 4.5e-8 (tol 1e-6) and 2.8e-10 (tol 1e-8), the value at the jump included
    assert sol.success and error <= tol


def test_general_kernel_grid_holds_the_jumps():
    from core.time import solve_general
    times = np.sort(np.concatenate([np.linspace(1.0, 1.0 + 365 / 28, 40), [_JUMP]]))
    exact = _exact_step_response(times, _JUMP, 2.0, 0.5, _RATE)
    kernel = _ExponentialKernel(0.5, _RATE)
    blind = solve_general(kernel, _one_mode(_step_load), times, tol=1e-8)
    assert not blind.success  # measured error 1.0e-4: the grid cannot refine it away
    sol = solve_general(kernel, _one_mode(_step_load), times, tol=1e-8, breaks=[_JUMP])
    error = float(np.max(np.abs(sol.w[0] - exact)) / np.max(np.abs(exact)))
    # measured 1.1e-9, the estimate 1.1e-9
    assert sol.success and error <= 1e-8


# ------------------------------------------------------ item 7: a fast-oscillating load


def _sine_force(wavelength: float) -> dict:
    d = scene_dict()  # exponential creep: the O(1)-per-step stepper
    d["loading"]["force"] = {"kind": "sine", "mean": 5e5, "amplitude": 2e5,
                             "wavelength": wavelength}
    return d


def test_a_load_faster_than_the_step_limit_is_refused_before_solving():
    """A sine force of period 0.05 day over a year (7300 periods) ran into the step limit
    after a minute and was then blamed on double precision."""
    with pytest.raises(ValueError, match=r"^loading\.force\.wavelength: the load varies "
                                         r"faster than the time stepping can follow: "
                                         r"about 7\.3e\+03 oscillations"):
        scene_from_dict(_sine_force(0.05))
    d = _sine_force(0.05)
    d["loading"]["force"] = {"expr": "5e5 + 2e5 * sin(2 * pi * t / 0.05)"}
    with pytest.raises(ValueError, match=r"^loading\.force: the load varies faster"):
        scene_from_dict(d)
    # a period of a day needs 8500 steps at tol 1e-6 (measured): accepted
    scene_from_dict(_sine_force(1.0))
    # an elastic base has no time stepping
    elastic = _sine_force(0.05)
    elastic["base"]["creep"] = {"model": "elastic", "modulus": 3e10}
    scene_from_dict(elastic)


def test_the_step_limit_is_named_when_it_is_hit(monkeypatch):
    """The stepper's own limit, when hit, is reported as such with the load's field."""
    import functools

    import core.engines.nystrom.modal
    import core.engines.projection.levels
    from core.time import solve_degenerate
    # the projection's time stage and the default engine's
    for engine in (core.engines.projection.levels, core.engines.nystrom.modal):
        monkeypatch.setattr(engine, "solve_degenerate",
                            functools.partial(solve_degenerate, max_steps=40))
    from core.scene import solve
    with pytest.raises(ValueError, match=r"^loading\.force: the time stepping could not "
                                         r"follow the loads: .*limit of 40 steps.*vary "
                                         "faster") as info:
        solve(scene_from_dict(_sine_force(10.0)))
    assert "double precision" not in str(info.value)


# ------------------------------------ item 3 (support): where a history jumps or kinks


def test_profiles_expose_their_jumps_and_kinks():
    from core.profiles import profile_from_spec

    def history(spec):
        return profile_from_spec(spec, field="loading.force", variable="t",
                                 domain=(0.0, 365.0))

    step = history({"kind": "step", "values": [1.0, 3.0], "breaks": [3.3]})
    assert step.nonsmooth_points() == (3.3,)
    assert step.nonsmooth_points(4.0, 365.0) == ()
    assert history({"kind": "ramp", "start": 0, "end": 1, "duration": 7}
                   ).nonsmooth_points() == (7.0,)
    table = history({"kind": "table", "points": [[0, 0], [2, 1], [5, 1]],
                     "interpolation": "step"})
    assert table.nonsmooth_points() == (2.0, 5.0)
    assert history({"expr": "1 + heaviside(t - 10)"}).nonsmooth_points() == \
        pytest.approx((10.0,), abs=1e-9)
    assert history({"kind": "sine", "mean": 1, "amplitude": 1, "wavelength": 9}
                   ).nonsmooth_points() == ()


# ------------------------------------------------------------ item 9: names of refusals


def test_a_formula_pole_between_check_samples_names_the_scene_field():
    """Was refused as "m: must be > 0" (the solver's internal name)."""
    from core.scene import solve
    d = elastic_dict()
    d["coating"][0]["thickness"] = {"expr": "0.02 + 1e-7/(x - 0.123456789)"}
    scene = scene_from_dict(d)  # the 4097 check samples miss the pole
    with pytest.raises(ValueError, match=r"^coating\[0\]\.thickness: must be > 0, is -\S+ "
                                         r"at x = 0\.1234\d* m, between the points"):
        solve(scene)


def test_an_uploaded_shape_table_beyond_the_solver_limit_is_refused_on_upload():
    """A 40-row shape table was accepted by the upload (10,000 rows allowed) and then
    always refused when the scene was built (16 kinks at most in a scene)."""
    from core.profiles import profile_from_csv
    rows = "x,f\n" + "".join(f"{-1 + 2 * k / 39:.6f},{1e-4 * (k % 2)}\n" for k in range(40))
    with pytest.raises(ValueError, match=rf"^punch\.shape: a table of 40 rows with 'linear' "
                                         rf".* more than the {limits.MAX_BREAKPOINTS} .*"
                                         "'pchip'"):
        profile_from_csv(rows, field="punch.shape", variable="x", domain=(-1.0, 1.0))
    smooth = profile_from_csv(rows, field="punch.shape", variable="x", domain=(-1.0, 1.0),
                              interpolation="pchip")
    d = elastic_dict()
    d["punch"]["shape"] = smooth.spec
    scene_from_dict(d)  # the solver's limit agrees: accepted
    # a load history in time has no such limit
    history = "t,f\n" + "".join(f"{k},{k % 2}\n" for k in range(40))
    profile_from_csv(history, field="loading.force", variable="t", domain=(0.0, 50.0))


def test_output_times_and_pressure_points_are_bounded(monkeypatch):
    from core.scene import solve
    from core.solver import solve_dimensionless
    times = 1.0 + np.arange(limits.MAX_SOLVER_TIMES + 1) * 1e-3
    with pytest.raises(ValueError, match=rf"^times: at most {limits.MAX_SOLVER_TIMES}"):
        solve_dimensionless(1.0, 0.05, 0.0, times, force=1.0, moment=0.0)
    result = solve(elastic_dict())
    monkeypatch.setattr(limits, "MAX_PRESSURE_VALUES", 3000)  # the check, not the work
    points = limits.MAX_PRESSURE_VALUES // result.times.size + 1
    with pytest.raises(ValueError, match=r"^x: .* more than the"):
        result.pressure(np.zeros(points))
    assert result.pressure(np.zeros(points - 1)).shape == (points - 1, result.times.size)
