"""Fixtures shared by the contact tests."""

from __future__ import annotations

import pytest

from core.discretize import base_panels, kernel_operator


@pytest.fixture(scope="module")
def rule():
    """A rule symmetric about 0 (graded to 1e-2 at +-1, panels at most 0.05 wide), the
    operator F on it (lam = 1), an even coating compliance m and right-hand side (a
    crown's gap, negated): (op, m, x, w, rhs)."""
    panels = base_panels(1.0, (), edge_width=1e-2, max_width=0.05)
    op = kernel_operator(1.0, panels).matrix
    x, w = panels.nodes, panels.weights
    m = 0.05 * (1.0 + 0.3 * x ** 2)
    rhs = -0.01 * x ** 2
    return op, m, x, w, rhs
