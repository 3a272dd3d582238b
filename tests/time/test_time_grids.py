"""The time grids of the creep solves: a general kernel's grid is checked against its limit
before it is built and evaluated in bounded blocks, and steps stop where a load jumps (a
closed-form step response on one mode is the reference)."""

from __future__ import annotations

import numpy as np
import pytest

from core import limits


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


# a load stepping up 3x at 3.3 days after loading at 28 days (t = age / 28), in the
# time stepper's own terms; creep at 0.05/day, outputs over a year
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


def test_a_graded_grid_grows_geometrically_out_of_each_start_and_halves_exactly():
    from core.time import time_grid
    times = np.array([1.0, 3.6, 15.7, 83.5, 465.0, 2610.0])
    grid, widths, index = time_grid(times, 16, 0, jumps=(), graded=10)
    assert np.array_equal(grid[index], times)
    # beyond the first output: marks at 1 + 2.6 * 2^k, but none within 1/8 of its spacing of
    # an output time (83.5 beside 1 + 2.6 * 32 = 84.2)
    for k in (1, 2, 3, 4, 6, 7, 8, 9):
        assert np.any(np.isclose(grid, 1.0 + 2.6 * 2.0**k)), k
    assert not np.any(np.isclose(grid, 1.0 + 2.6 * 32.0))
    # no step longer than the time since the start (until the nominal step takes over)
    since = grid[1:-1] - 1.0
    early = grid[2:] < 2610.0 / 16
    assert np.all(widths[1:][early] <= since[early] * (1.0 + 1e-12))
    # each halving halves every step of the grid before it
    fine, fine_widths, fine_index = time_grid(times, 16, 1, jumps=(), graded=10)
    assert np.array_equal(fine[::2], grid) and np.array_equal(fine[fine_index], times)
    assert np.allclose(fine_widths[::2], widths / 2.0, rtol=1e-12, atol=0.0)


def test_a_graded_grid_grows_again_out_of_a_load_jump_and_never_inside_it():
    from core.time import time_grid

    times = np.array([1.0, 2.0, 50.0, 400.0, 3000.0])
    jump = 100.0
    grid, _, index = time_grid(times, 16, 0, jumps=(jump,), graded=6)
    assert np.array_equal(grid[index], times)
    side = 1e-12 * jump
    assert not np.any((grid > jump - side * 0.5) & (grid < jump + side * 0.5))
    # after the jump: the first interval (to 400) graded, then doubling (300 * 2, 4, ...)
    after = jump + side
    for k in (1, 2, 3):
        assert np.any(np.isclose(after + 300.0 * 2.0**k, grid)) == (after + 300.0 * 2.0**k
                                                                    < 3000.0), k


def test_every_grid_lands_on_a_kink_and_halves_exactly():
    """A corner touching down inside a step (core/contact/creep.py:
    ``corner_contact_changes``) is an interval end of every grid, not an output."""
    from core.time import time_grid

    times = np.linspace(1.0, 12.0, 12)
    kink = 1.0718
    coarse, widths, index = time_grid(times, 16, 0, kinks=(kink,))
    assert np.any(coarse == kink) and np.array_equal(coarse[index], times)
    assert np.all(widths > 0.0)
    fine, fine_widths, fine_index = time_grid(times, 16, 1, kinks=(kink,))
    assert np.array_equal(fine[::2], coarse) and np.array_equal(fine[fine_index], times)
    assert np.allclose(fine_widths[::2], widths / 2.0, rtol=1e-12, atol=0.0)
    # one on an output time or within KINK_SNAP steps of one (or of another kink),
    # outside the span or on a jump's sides adds nothing
    plain = time_grid(times, 16, 0, jumps=(5.5,))[0]
    ignored = time_grid(times, 16, 0, jumps=(5.5,),
                        kinks=(3.0, 3.0 + 1e-7, 0.5, 13.0, 5.5))[0]
    assert np.array_equal(plain, ignored)
    twins = time_grid(times, 16, 0, kinks=(kink, kink + 2e-16))[0]
    assert np.array_equal(twins, coarse) and np.all(np.diff(twins) > 0.0)
