"""The exact layered kernel with no coating layers: a rigid punch on the bare base layer."""

from __future__ import annotations

import numpy as np
import pytest

from core.engines.layered.solve import solve_layered
from core.engines.layered.stiffness import flat_punch_stiffness
from core.kernel import FULL_ACCURACY, UniformLayer, kernel_regular

#: The settlement coefficient ``pi theta delta / P`` of a flat punch on a layer of
#: thickness H = a (theta = E / (2 (1 - nu^2))), as the benchmark states it (8 digits).
BENCHMARK = 0.66679549
#: Its last stated digit: the benchmark is rounded to 1e-8.
BENCHMARK_ROUNDING = 0.5e-8


def coefficient(lam: float, tol: float) -> tuple[float, object]:
    """``pi delta* / P*`` (= pi theta delta / P) of a flat punch at a / H = ``lam``."""
    answer = solve_layered(lam, [], 1.0, 1.0, 0.3, {"force": 1.0, "moment": 0.0}, tol=tol)
    return float(np.pi * answer.settlement[0] / answer.force[0]), answer


def independent_coefficient(lam: float, modes: int = 24, nodes: int = 256) -> float:
    """The same by a Galerkin solve of its own on the layer kernel of
    :mod:`core.kernel.plane` (residue series and table, not the stack's Fourier integral):
    ``q* = sum_n c_n T_n / sqrt(1 - t^2)``, even modes (a centred load), the logarithm's
    part exact, the smooth part ``k_pl(lam d) + ln|lam d|`` by Gauss-Chebyshev."""
    theta = np.pi * (np.arange(nodes) + 0.5) / nodes
    t = np.cos(theta)
    smooth = kernel_regular(lam * np.abs(t[:, None] - t[None, :]), FULL_ACCURACY) - np.log(lam)
    even = np.arange(0, modes, 2)
    rows = np.cos(np.outer(even, theta))  # T_n(t_i)
    matrix = (np.pi / nodes) ** 2 * rows @ smooth @ rows.T
    log_part = np.where(even == 0, np.pi**2 * np.log(2.0), np.pi**2 / (2 * np.maximum(even, 1)))
    matrix[np.diag_indices(even.size)] += log_part
    rhs = np.zeros(even.size)
    rhs[0] = np.pi**2  # delta* = 1 against T_0 / sqrt(1 - t^2)
    c = np.linalg.solve(matrix, rhs)
    return float(np.pi / (np.pi * c[0]))  # P* = pi c_0


def test_the_settlement_coefficient_at_h_equal_a_is_the_benchmark():
    value, answer = coefficient(1.0, 1e-12)
    # measured 0.66679548521976 (32 modes, 256 nodes; estimate 1e-12): 4.8e-9 below the
    # stated 0.66679549, within its rounding
    assert abs(value - BENCHMARK) <= BENCHMARK_ROUNDING
    assert answer.error_estimate <= 1e-12


def test_the_coefficient_agrees_with_a_solve_on_the_plane_kernel():
    # measured differences 0 at a / H = 1, 2.2e-16 at 0.1, 1.9e-14 at 5 (24 modes, 256
    # nodes on the smooth part): both rules are at rounding
    for lam in (0.1, 1.0, 5.0):
        assert coefficient(lam, 1e-12)[0] == pytest.approx(independent_coefficient(lam),
                                                           rel=1e-13, abs=0)


def test_the_coefficient_is_the_same_at_every_tol():
    # measured: tol 1e-2 and 1e-6 give the tol-1e-12 value to 0 at a / H = 1 (32 modes
    # already reach the error floor, estimate 5e-10); at a / H = 30, 3.2e-9 at tol 1e-2
    # (estimate 5.0e-4) and 1.4e-14 at tol 1e-6 (estimate 5e-10)
    for lam in (1.0, 30.0):
        reference = coefficient(lam, 1e-12)[0]
        for tol in (1e-2, 1e-6):
            value, answer = coefficient(lam, tol)
            assert abs(value / reference - 1) <= answer.error_estimate <= 0.5 * tol


@pytest.mark.parametrize("lam", [60.0, 87.0])
def test_a_base_thinner_than_the_punch_is_resolved_at_coarse_tol(lam):
    # before the nodes resolved H on a bare base, tol 1e-6 erred by 1.9e-7 (a / H = 60)
    # and 4.5e-5 (a / H = 87) with estimates of 1.1e-8 and 5e-8; now measured 3.0e-11 and
    # 1.2e-11 in the settlement, under estimates of 1.1e-8 and 5e-8
    given = {"force": 1.0, "moment": 0.3}
    reference = solve_layered(lam, [], 1.0, 1.0, 0.3, given, tol=1e-12)
    answer = solve_layered(lam, [], 1.0, 1.0, 0.3, given, tol=1e-6)
    error = max(abs(answer.settlement[0] / reference.settlement[0] - 1),
                abs(answer.tilt[0] / reference.tilt[0] - 1))
    assert error <= answer.error_estimate <= 0.5e-6


def test_a_coating_of_the_base_material_bonded_is_a_thicker_bare_base():
    # a bonded layer of the base's own material is part of the base: the stack's kernel
    # with one layer and the bare kernel answer the same punch. Measured: 2.2e-16 in the
    # force per settlement, 4.4e-16 in the moment per tilt (64 modes)
    modulus, poisson = 3.0e10, 0.2
    bare = flat_punch_stiffness(1.0, [], 1.0, modulus, poisson, modes=64)
    layer = UniformLayer(0.25, modulus, poisson, "bonded")
    split = flat_punch_stiffness(1.0, [layer], 0.75, modulus, poisson, modes=64)
    assert split.force_per_settlement == pytest.approx(bare.force_per_settlement, rel=1e-11)
    assert split.moment_per_tilt == pytest.approx(bare.moment_per_tilt, rel=1e-11)
    theta = modulus / (2 * (1 - poisson**2))
    assert np.pi * theta / bare.force_per_settlement == pytest.approx(BENCHMARK, abs=1e-8)
