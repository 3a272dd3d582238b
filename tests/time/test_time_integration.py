"""The Radau IIA step of the modal Volterra equations against the plain stage system.

:func:`core.time.integration._radau_step` eliminates the kernel's states (they couple
only through their sum) and solves one 3x3 system per mode. The reference here builds
the whole stage system of each mode, ``I - h (A (x) J_j)`` of size 3 * states, and
solves it densely: the textbook form of the method, an independent second computation.
"""

from __future__ import annotations

import numpy as np
import pytest

from core.creep.kernels import DegenerateKernel
from core.time import ModalProblem, solve_degenerate
from core.time.radau import RADAU_A, RADAU_C, _radau_step


def _reference_step(kernel, problem, t0, h, s_modes, s_known):
    ts = t0 + RADAU_C * h
    rates = np.asarray(kernel.rates, dtype=float)
    beta = np.vstack([np.asarray(kernel.tau_part(ts))[None],
                      np.asarray(kernel.exponential_parts(ts)).reshape(len(rates), 3)])
    decay = np.concatenate([[0.0], rates])
    ns = len(decay)

    def solve(jacobians, forcing, start):
        # y_i = start + h sum_j A_ij (J_j y_j + forcing_j), all stages i at once
        big = np.eye(3 * ns)
        for i in range(3):
            for j in range(3):
                big[i * ns:(i + 1) * ns, j * ns:(j + 1) * ns] -= h * RADAU_A[i, j] * jacobians[j]
        rhs = np.concatenate([start + h * sum(RADAU_A[i, j] * forcing[j] for j in range(3))
                              for i in range(3)])
        return np.linalg.solve(big, rhs).reshape(3, ns)

    known_new, known_sums = [], []
    u = problem.u(ts)
    for k in range(problem.n_known):
        y = solve([-np.diag(decay)] * 3, [beta[:, j] * u[k, j] for j in range(3)], s_known[k])
        known_new.append(y[2])
        known_sums.append(y.sum(axis=1))
    d, r = problem.d(ts), problem.r(ts)
    if problem.n_known:
        r = r + problem.coupling @ np.array(known_sums)
    modes_new = []
    for m in range(problem.n_modes):
        jac = [-np.diag(decay) + np.outer(beta[:, j], np.ones(ns)) / d[m, j] for j in range(3)]
        y = solve(jac, [beta[:, j] * r[m, j] / d[m, j] for j in range(3)], s_modes[m])
        modes_new.append(y[2])
    return np.array(modes_new).reshape(problem.n_modes, ns), \
        np.array(known_new).reshape(problem.n_known, ns)


def _problem(rng, modes, known):
    gamma = rng.uniform(0.01, 50.0, modes)
    coupling = rng.normal(size=(modes, known))
    return ModalProblem(
        d=lambda t: 1.0 + (1.0 + 0.3 * np.sin(t))[None, :] / gamma[:, None],
        r=lambda t: np.cos(np.outer(np.arange(1, modes + 1), t)),
        u=lambda t: np.exp(-0.1 * np.arange(known)[:, None] * np.asarray(t)[None, :]),
        coupling=coupling)


@pytest.mark.parametrize("terms", [
    ((2e-11, 5e-10, 0.05),),                                      # one exponential
    ((1e-11, 3e-10, 0.02), (2e-11, 1e-10, 1.0), (5e-12, 0.0, 30.0)),  # three, one stiff
])
@pytest.mark.parametrize("h", [1e-4, 0.3, 40.0])
def test_the_eliminated_step_equals_the_full_stage_system(terms, h):
    rng = np.random.default_rng(7)
    kernel = DegenerateKernel(age_at_loading=28.0, modulus_final=3e10, beta=0.4, alpha=0.05,
                              terms=terms)
    ns = 1 + len(terms)
    problem = _problem(rng, modes=9, known=2)
    s_modes = rng.normal(size=(9, ns))
    s_known = rng.normal(size=(2, ns))
    got = _radau_step(kernel, problem, 1.7, h, s_modes, s_known)
    want = _reference_step(kernel, problem, 1.7, h, s_modes, s_known)
    for a, b in zip(got, want, strict=True):
        # measured: at most 1.3e-15 of the largest state in these six cases; the margin
        # is for other BLAS builds and processors
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-13 * np.max(np.abs(b)))


def test_a_step_without_known_channels_or_modes():
    rng = np.random.default_rng(3)
    kernel = DegenerateKernel(age_at_loading=28.0, modulus_final=3e10, beta=0.4, alpha=0.05,
                              terms=((2e-11, 5e-10, 0.05),))
    only_modes = _problem(rng, modes=4, known=0)
    s = rng.normal(size=(4, 2))
    got, _ = _radau_step(kernel, only_modes, 1.0, 0.5, s, np.zeros((0, 2)))
    want, _ = _reference_step(kernel, only_modes, 1.0, 0.5, s, np.zeros((0, 2)))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-13 * np.max(np.abs(want)))
    only_known = _problem(rng, modes=0, known=2)
    sk = rng.normal(size=(2, 2))
    _, got = _radau_step(kernel, only_known, 1.0, 0.5, np.zeros((0, 2)), sk)
    _, want = _reference_step(kernel, only_known, 1.0, 0.5, np.zeros((0, 2)), sk)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-13 * np.max(np.abs(want)))


# ------------------------------------------- the exponential collocation (the default)

def _creep_problem(modes: int = 6, known: int = 2):
    """A creep-like problem: slowly varying loads from t = 1 on, an aging modulus."""
    rng = np.random.default_rng(3)
    gamma = rng.uniform(0.05, 20.0, modes)
    return ModalProblem(
        d=lambda t: 1.0 + (1.6 - 0.6 * np.exp(1.0 - np.asarray(t)))[None, :] / gamma[:, None],
        r=lambda t: np.outer(np.linspace(0.5, 1.5, modes),
                             1.0 + 0.2 * np.sin(0.1 * np.asarray(t))),
        u=lambda t: np.vstack([np.ones_like(t), 0.5 + 0.1 * np.cos(0.1 * t)])[:known],
        coupling=rng.normal(size=(modes, known)))


_STIFF = DegenerateKernel(age_at_loading=28.0, modulus_final=3e10, beta=0.4, alpha=0.05,
                          terms=((1e-11, 3e-10, 0.02), (2e-11, 1e-10, 1.0), (5e-12, 0.0, 30.0)))


def test_exponential_collocation_converges_at_high_order():
    """True error against a tight adaptive Radau IIA reference (an independent method) on
    grids of 2x, 4x, 8x the steps: the order in the step count is the method's."""
    from core.time.exponential import first_step, grid, march

    problem = _creep_problem()
    times = 1.0 + np.geomspace(1e-3, 60.0, 30)
    ref = solve_degenerate(_STIFF, problem, times, tol=1e-13, method="radau")
    size = np.max(np.abs(ref.vw))
    theta = first_step(_STIFF, 1.0, times[-1] - 1.0)
    steps, errors = [], []
    for level in (1, 2, 3, 4):
        ends, starts = grid(1.0, float(times[-1]), np.array([]), theta, level)
        vw, vu, _ = march(_STIFF, problem, ends, starts, np.zeros(ends.size - 1, bool), times)
        steps.append(ends.size - 1)
        errors.append(max(np.max(np.abs(vw - ref.vw)), np.max(np.abs(vu - ref.vu))) / size)
    order = -np.polyfit(np.log(steps), np.log(errors), 1)[0]
    # measured: steps 43, 86, 171, 341 -> errors 7.1e-07, 3.5e-08, 2.5e-09, 1.2e-10,
    # order 4.2: the stage order 4 of the collocation (the exponentials exact, their
    # states fed by a cubic per step); 3.8 leaves room for rounding only
    assert order >= 3.8, (steps, errors)


@pytest.mark.slow
@pytest.mark.parametrize("tol", [1e-5, 1e-7, 1e-9])
def test_exponential_collocation_meets_tol_and_its_estimate_is_honest(tol):
    problem = _creep_problem()
    times = 1.0 + np.geomspace(1e-3, 60.0, 30)
    ref = solve_degenerate(_STIFF, problem, times, tol=1e-13, method="radau")
    sol = solve_degenerate(_STIFF, problem, times, tol=tol)
    radau = solve_degenerate(_STIFF, problem, times, tol=tol, method="radau")
    assert sol.success and radau.success
    # the error of w relative to the largest |w| (the meaning of error_estimate)
    error = np.max(np.abs(sol.w - ref.w)) / np.max(np.abs(ref.w))
    # measured: errors 8.6e-07, 5.7e-09, 6.5e-12 against estimates 2.4e-06, 3.4e-08,
    # 9.3e-11 (2.8-14x above) for 43, 140, 681 steps (adaptive Radau IIA: 57, 152, 531)
    assert error <= tol
    assert sol.error_estimate >= error


def test_modes_marched_by_affine_maps_or_step_by_step_agree(monkeypatch):
    """The two ways of marching the modes (:mod:`core.time.exponential_modes`: an affine map of
    the states a step for few states, z formed on the way for many) give the same answer
    (4 states here; both forced in turn, five grids marched). Measured: 2.5e-16 of
    max|V w| and 3.6e-16 of max|w| apart (the order of the sums alone differs), so 1e-13
    holds it with room for other BLAS builds."""
    import core.time.exponential_modes as modes

    problem = _creep_problem()
    times = 1.0 + np.geomspace(1e-3, 60.0, 30)
    monkeypatch.setattr(modes, "AFFINE_STATES", 100)
    affine = solve_degenerate(_STIFF, problem, times, tol=1e-7)
    monkeypatch.setattr(modes, "AFFINE_STATES", 0)
    stepwise = solve_degenerate(_STIFF, problem, times, tol=1e-7)
    assert affine.steps == stepwise.steps
    size = np.max(np.abs(stepwise.vw))
    assert np.max(np.abs(affine.vw - stepwise.vw)) <= 1e-13 * size
    assert np.max(np.abs(affine.w - stepwise.w)) <= 1e-13 * np.max(np.abs(stepwise.w))


def test_exponential_collocation_in_blocks_of_steps_is_the_same(monkeypatch):
    """The point systems are built a block of steps at a time (bounded memory): blocks of
    five steps give the answer of one block (measured identical)."""
    import core.time.exponential as steps

    problem = _creep_problem()
    times = 1.0 + np.geomspace(1e-3, 60.0, 30)
    whole = solve_degenerate(_STIFF, problem, times, tol=1e-7)
    monkeypatch.setattr(steps, "MAX_BLOCK_ELEMENTS", 16 * problem.n_modes * 5)
    blocks = solve_degenerate(_STIFF, problem, times, tol=1e-7)
    assert blocks.steps == whole.steps
    np.testing.assert_array_equal(blocks.w, whole.w)


@pytest.mark.parametrize("affine_states", [100, 0])
def test_grids_marched_in_one_pass_are_marched_apart(monkeypatch, affine_states):
    """Several grids marched in one pass (:func:`core.time.march_grids`: the
    states restart at each grid's first step, no neighbour read across grids) give each
    grid's own march, with a jump inside, both ways of marching the modes, and the local
    errors of each grid. Measured identical (the same operations on the same numbers)."""
    import core.time.exponential_modes as modes
    from core.time.exponential import first_step, grid, march, march_grids

    monkeypatch.setattr(modes, "AFFINE_STATES", affine_states)
    problem = _creep_problem()
    times = 1.0 + np.geomspace(1e-3, 60.0, 30)
    jumps = np.array([20.0])
    theta = first_step(_STIFF, 1.0, times[-1] - 1.0)
    grids = []
    for level in (0, 1, 2):
        ends, starts = grid(1.0, float(times[-1]), jumps, theta, level)
        grids.append((ends, starts, np.isin(ends[1:], jumps)))
    rows = (np.ones(problem.n_modes), np.ones(problem.n_known))
    together = march_grids(_STIFF, problem, grids, times, rows)
    for g, (vw, vu, local) in zip(grids, together, strict=True):
        alone_vw, alone_vu, alone_local = march(_STIFF, problem, *g, times, rows)
        np.testing.assert_array_equal(vw, alone_vw)
        np.testing.assert_array_equal(vu, alone_vu)
        np.testing.assert_array_equal(local(), alone_local())
