"""The Radau IIA step of the modal Volterra equations against the plain stage system.

:func:`core.time_integration._radau_step` eliminates the kernel's states (they couple
only through their sum) and solves one 3x3 system per mode. The reference here builds
the whole stage system of each mode, ``I - h (A (x) J_j)`` of size 3 * states, and
solves it densely: the textbook form of the method, an independent second computation.
"""

from __future__ import annotations

import numpy as np
import pytest

from core.creep import DegenerateKernel
from core.time_integration import RADAU_A, RADAU_C, ModalProblem, _radau_step


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
