"""Product integration of the log kernel on panels."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from core.kernel import legendre_log_moments


@pytest.mark.parametrize("z", [-1.0, 1.0])
def test_log_moments_at_panel_ends_are_exact(z):
    """M_0(1) = 2 ln 2 - 2, M_n(1) = -2/(n (n + 1)), M_n(-1) = (-1)^n M_n(1)."""
    n = np.arange(1, 16)
    exact = np.concatenate([[2 * np.log(2) - 2], -2.0 / (n * (n + 1.0))])
    if z < 0:
        exact *= (-1.0) ** np.arange(16)
    got = legendre_log_moments(np.array([z]), 15)[0]
    # measured: 0 (the end values are assigned); it was 3e-12 off before
    assert np.max(np.abs(got - exact)) < 1e-15


@pytest.mark.parametrize("z", [-3.0, -1.2, -0.7, 0.0, 0.31, 0.999, 1.04, 2.5])
def test_log_moments_match_mpmath(z):
    """Against mpmath quadrature (25 digits), split at the log point."""
    got = legendre_log_moments(np.array([z]), 15)[0]
    for k in (0, 1, 2, 7, 15):
        pts = [-1, z, 1] if -1 < z < 1 else [-1, 1]
        with mpmath.workdps(25):  # restored on leaving: no precision leaks to other tests
            ref = float(mpmath.quad(lambda t, k=k: mpmath.log(abs(mpmath.mpf(z) - t))
                                    * mpmath.legendre(k, t), pts))
        # measured: <= 2.2e-16 (0.31, 0.999, 1.04)
        assert got[k] == pytest.approx(ref, abs=1e-14)


def _graded(lam: float, breakpoints: tuple[float, ...], edge: float):
    from core.discretize import base_panels

    return base_panels(lam, breakpoints, edge_width=edge, max_width=min(0.5, 3.0 / lam),
                       ratio=4.0)


@pytest.mark.parametrize(("lam", "breakpoints"), [(1.0, (0.3,)), (50.0, ()), (0.05, (-0.5,))])
def test_operator_reused_on_a_refined_grid_equals_a_new_one(lam, breakpoints):
    """Blocks of shared panels are copied, the rest computed: the same matrix exactly."""
    from core.discretize import Panels, kernel_operator
    from core.engines.nystrom.adapt import grade

    coarse = _graded(lam, breakpoints, 1e-3)
    fine = Panels.from_edges(grade(coarse.edges, np.array([-1.0, 1.0, *breakpoints]), 2))
    new = kernel_operator(lam, fine).matrix
    reused = kernel_operator(lam, fine, kernel_operator(lam, coarse)).matrix
    # measured: 0 (lam 1), 1.7e-18 and 3.5e-18 (lam 50, 0.05; entries up to 0.08)
    assert np.max(np.abs(reused - new)) <= 1e-16


def test_node_rows_from_reference_tables_match_operator_rows():
    """The tables of reference panel pairs give the batched moments' numbers."""
    from core.discretize import Panels, node_rows, operator_rows
    from core.engines.nystrom.adapt import grade

    coarse = _graded(1.0, (0.3,), 1e-3)
    fine = Panels.from_edges(grade(coarse.edges, np.array([-1.0, 1.0, 0.3]), 3))
    tables = node_rows(1.0, coarse, fine, np.arange(fine.n_panels))
    batched = operator_rows(1.0, coarse, fine.nodes)
    # measured: 3.0e-15 (entries up to 0.08): the keys are rounded to 1e-12
    assert np.max(np.abs(tables - batched)) <= 3e-14


def test_operator_does_not_depend_on_what_the_tables_held_before():
    """The same grid's operator, bit for bit, whether the reference tables of panel pairs
    start empty or hold the pairs of other grids (computed in other batches). Before,
    a table's last bits depended on the keys computed with it (Miller's recurrence started
    where the batch's nearest point needed, the product rounded by batch size): the
    operator differed by 1.7e-16, enough for the modal form to meet a complex pair."""
    from core.discretize import Panels, kernel_operator, pair_tables
    from core.engines.nystrom.adapt import grade

    coarse = _graded(1.0, (), 2e-4)
    fine = Panels.from_edges(grade(coarse.edges, np.array([-1.0, 1.0]), 2))
    other = _graded(1.0, (0.3,), 1e-3)
    pair_tables.clear()
    alone = kernel_operator(1.0, fine).matrix
    pair_tables.clear()
    kernel_operator(1.0, other)  # a few of its pairs recur on ``fine``, in other batches
    kernel_operator(1.0, coarse)
    after_others = kernel_operator(1.0, fine).matrix
    assert np.array_equal(alone, after_others)


@pytest.mark.parametrize("accuracy", [1e-6, 1e-9, 1e-12])
def test_kernel_values_meet_the_asked_accuracy(accuracy):
    """The truncated series and the zeros beyond the envelope stay within ``accuracy``."""
    from core.kernel import kernel_block
    from core.kernel.plane import plane_kernel

    s = np.linspace(1e-6, 40.0, 400_001)
    error = np.max(np.abs(kernel_block(s.copy(), accuracy) - plane_kernel(s)))
    # measured: 4.4e-7, 4.4e-10, 3.4e-13 (the tail is cut at half the accuracy)
    assert error <= accuracy
