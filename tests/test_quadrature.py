"""Product integration of the log kernel on panels."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from core.quadrature import legendre_log_moments


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
