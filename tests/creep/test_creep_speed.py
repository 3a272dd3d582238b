"""Creep solves that reuse work: a load change of an aging scene, batched output times.

Times are never asserted; what is shown is that a load change does not step in time
again (the prepared object's build counts) and that the answers agree.
"""

from __future__ import annotations

import numpy as np

from core.cache import clear_caches
from core.scene import scene_from_dict
from tests.conftest import scene_file


def _young_concrete(force: float) -> dict:
    data = scene_file("young_concrete_50_years")
    # one year and 24 outputs keep the test short; the path is the one of 50 years
    data["times"] = {"end": 365.25, "count": 24, "spacing": "log"}
    data["loading"] = {"force": force, "moment": 0.0}
    return data


def test_a_load_change_of_an_aging_scene_does_not_step_in_time_again():
    clear_caches()
    first = scene_from_dict(_young_concrete(6.0e5)).dimensionless.solve()
    steps_built = first.info["builds"]["time_response"]
    # a force in N turned dimensionless: its shape differs from the first one's by
    # rounding only, so the cached response to that shape is scaled
    second = scene_from_dict(_young_concrete(6.0e5 * 1.37)).dimensionless.solve()
    assert second.info["builds"]["time_response"] == steps_built
    assert second.info["success"]
    # linear in the loads: measured ratio 1.37 to 2e-16 relative
    np.testing.assert_allclose(second.settlement, 1.37 * first.settlement, rtol=1e-12)


def _problem(modes: int, known: int):
    from core.time import ModalProblem

    rng = np.random.default_rng(11)
    gamma = rng.uniform(0.01, 50.0, modes)
    return ModalProblem(
        d=lambda t: 1.0 + (1.0 + 0.3 * np.sin(t))[None, :] / gamma[:, None],
        r=lambda t: np.cos(np.outer(np.arange(1, modes + 1), t)),
        u=lambda t: np.exp(-0.1 * np.arange(known)[:, None] * np.asarray(t)[None, :]),
        coupling=rng.normal(size=(modes, known)))


def test_batched_steps_equal_single_steps():
    from core.creep.kernels import DegenerateKernel
    from core.time.radau import _radau_step, _radau_steps

    kernel = DegenerateKernel(age_at_loading=28.0, modulus_final=3e10, beta=0.4, alpha=0.05,
                              terms=((1e-11, 3e-10, 0.02), (5e-12, 0.0, 30.0)))
    problem = _problem(modes=7, known=2)
    rng = np.random.default_rng(5)
    s_modes, s_known = rng.normal(size=(7, 3)), rng.normal(size=(2, 3))
    hs = np.array([0.4, 0.2, 1e-5, 3.0])
    jump = np.array([True, False, False, True])
    modes, known = _radau_steps(kernel, problem, 2.5, hs, s_modes, s_known, before_jump=jump)
    for k, h in enumerate(hs):
        one = _radau_step(kernel, problem, 2.5, h, s_modes, s_known, before_jump=jump[k])
        # the same arithmetic on other array shapes: measured identical
        np.testing.assert_allclose(modes[k], one[0], rtol=0, atol=1e-14 * np.max(np.abs(one[0])))
        np.testing.assert_allclose(known[k], one[1], rtol=0, atol=1e-14 * np.max(np.abs(one[1])))


def test_outputs_inside_steps_are_the_answer_at_their_times():
    """An output time inside a step is a side step from the step's start; asking for it
    alone (a run whose last step ends on it) gives the same answer to the time tol."""
    from core.creep.kernels import DegenerateKernel
    from core.time import solve_degenerate

    kernel = DegenerateKernel(age_at_loading=28.0, modulus_final=3e10, beta=0.4, alpha=0.05,
                              terms=((1e-11, 3e-10, 0.02), (5e-12, 0.0, 30.0)))
    problem = _problem(modes=5, known=2)
    times = 1.0 + np.geomspace(1e-3, 5.0, 40)
    tol = 1e-8
    many = solve_degenerate(kernel, problem, times, tol=tol)
    for k in (3, 17, 29):
        alone = solve_degenerate(kernel, problem, times[: k + 1], tol=tol)
        scale = np.max(np.abs(alone.w))
        # measured 3.8e-10, 8.3e-15, 3.9e-11 relative (adaptive Radau IIA, 591 steps);
        # 5.9e-15, 1.2e-13, 6.2e-12 (exponential collocation, 1155 steps): below tol = 1e-8
        assert np.max(np.abs(many.w[:, k] - alone.w[:, -1])) <= tol * scale
    assert many.success and many.error_estimate <= tol


def test_force_and_moment_parts_in_one_march_equal_separate_marches():
    import core
    from core.creep.models import Arutyunyan

    material = Arutyunyan(3e10, 0.5, 0.03, 0.9e-11, 4.8e-10, 0.03)
    kernel, c = material.dimensionless_kernel(28.0), material.relative_modulus(28.0)
    prepared = core.prepare(1.0, lambda x: 0.1 * (1.0 + 0.2 * x + 0.3 * x**2), 0.0, tol=1e-6)
    form = prepared.modal(frozenset({"force", "moment"}))
    times = 1.0 + np.linspace(0.0, 10.0, 12)

    def zero(t):
        return np.zeros_like(t)

    parts = [({"force": np.ones_like, "moment": zero}, 0.0),
             ({"force": zero, "moment": lambda t: 0.1 * np.ones_like(t)}, 0.0)]
    tol = 1e-8
    together = form.solve_parts(times, c, kernel, parts, tol)
    for (loads, gap), both in zip(parts, together, strict=True):
        alone = form.solve(times, c, kernel, loads, tol, gap)
        for name in ("settlement", "tilt"):
            scale = np.max(np.abs(alone.scalars["settlement"])) + np.max(
                np.abs(alone.scalars["tilt"]))
            difference = np.max(np.abs(both.scalars[name] - alone.scalars[name])) / scale
            # measured <= 6.4e-16 (here both take the same 39 steps); the bound is what
            # each march claims, whatever steps it takes
            assert difference <= tol
        # each part's error is measured against its own size, as in its march alone:
        # measured equal to 8e-8 (force) and 1.5e-7 (moment) relative, the same 39 steps
        assert abs(both.time_error / alone.time_error - 1.0) < 1e-5


def test_creep_validity_samples_keep_the_checked_times_close():
    """Under creep the samples between outputs are taken only in gaps wider than their
    spacing: every output is checked, no two checked times are further apart than the
    spacing (as with all samples), and dense equally spaced outputs need no sample."""
    from core.engines.nystrom.prepared import HISTORY_SAMPLES, PreparedContact

    history = PreparedContact._history_times
    for times in (1.0 + np.linspace(0.0, 35.7, 100), 1.0 + np.geomspace(1e-3, 35.7, 100),
                  np.array([1.0, 2.0, 50.0]), 1.0 + np.linspace(0.0, 35.7, 30)):
        checked = history(None, times, "creep")
        spacing = (times[-1] - times[0]) / (HISTORY_SAMPLES["creep"] - 1)
        assert np.all(np.isin(times, checked))
        assert np.max(np.diff(checked)) <= spacing * (1 + 1e-12)
    dense = 1.0 + np.linspace(0.0, 35.7, 100)
    np.testing.assert_array_equal(history(None, dense, "creep"), dense)


def test_a_geometry_change_of_an_aging_scene_reuses_the_kernels_step_factors():
    """A new half-width changes the modes, not the kernel nor the time steps: the march
    takes the kernel's factors of its grids from the cache (core.time.exponential
    .GRID_FACTORS) and answers bit for bit as with nothing shared."""
    from core.scene import solve
    from core.time.exponential import GRID_FACTORS

    clear_caches()
    solve(_young_concrete(6.0e5))
    built = GRID_FACTORS.evaluations
    assert built >= 1
    wider = _young_concrete(6.0e5)
    wider["punch"]["half_width"] *= 1.01
    shared = solve(wider)
    assert GRID_FACTORS.evaluations == built  # every grid's factors were kept
    assert shared.info["builds"]["time_response"] >= 1  # the modes were stepped anew
    clear_caches()
    fresh = solve(wider)
    assert GRID_FACTORS.evaluations > built
    for name in ("settlement", "tilt", "force", "moment"):
        assert np.array_equal(getattr(shared, name), getattr(fresh, name))
    assert np.array_equal(shared.pressure_on_grid, fresh.pressure_on_grid)
