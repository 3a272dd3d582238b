"""The modes of a nearly symmetric operator: its symmetric part's modes, refined by Newton.

The Nystrom operator of the layer, in the inner product weighted by the quadrature and
``1/m`` (:mod:`core.nystrom_time`), is the discrete form of a symmetric positive
operator; only its product-integration rows are not symmetric (their antisymmetric part
is 7e-4 of the whole on the aging creep scene of :mod:`benchmarks.scenes`, 144 nodes).
So the symmetric part's eigenvectors (``eigh``: real, orthogonal, 1.3 ms at 144 nodes)
nearly diagonalize it, and a few Newton steps of the whole eigen-decomposition at once
(each a handful of matrix products) finish the job: with ``M = Y A X`` (``Y ~ X^-1``),
``D = diag M`` and ``E = M - D``, the first-order corrections of all eigenvectors are
``X <- X (I + F)``, ``F_ij = E_ij / (D_j - D_i)``, and the error squares every step
(measured on that scene: largest correction 1.6e-2, 1.2e-2, 4.2e-4, 7.2e-7, 1.9e-12).
Where eigenvalues lie too close for that (a first correction beyond
:data:`LARGEST_FIRST_CORRECTION`) or the result does not hold to :data:`RESIDUAL_TOL`,
it answers None and the caller takes the general non-symmetric solver (``eig``, 5.6 ms
at 144 nodes, plus the inverse of its eigenvectors).
"""

from __future__ import annotations

import numpy as np

#: Newton steps tried; the error squares each step from below this first correction.
MAX_STEPS = 8
#: The largest first correction ``|F_ij|`` still inside the region where the steps
#: converge quadratically (0.016 measured on the aging scene; beyond a quarter, two
#: eigenvalues are about as close as the coupling between them).
LARGEST_FIRST_CORRECTION = 0.25
#: Accepted residual ``max|A X - X diag(gamma)| / max|A|`` and ``max|Y X - I|``: a few
#: thousand ulp (eig leaves 2.5e-15 and 7.8e-16 on the aging scene, the refinement
#: 1.4e-15 and 8.9e-16).
RESIDUAL_TOL = 1e-12


def near_symmetric_modes(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """``(gamma, psi, psi_inv)`` with ``a = psi diag(gamma) psi_inv`` for a nearly symmetric
    real square ``a`` (dimensionless), or None when the refinement does not apply.

    ``gamma`` real, in increasing order of the symmetric part's eigenvalues; ``psi`` has
    columns of about unit length; ``psi_inv`` its inverse to :data:`RESIDUAL_TOL`.
    """
    n = a.shape[0]
    if n == 0:
        return np.zeros(0), np.zeros((0, 0)), np.zeros((0, 0))
    _, x = np.linalg.eigh(0.5 * (a + a.T))
    y = x.T.copy()
    scale = max(float(np.max(np.abs(a))), 1e-300)
    twice = 2.0 * np.eye(n)
    for step in range(MAX_STEPS):
        ax = a @ x
        m = y @ ax
        d = np.diag(m).copy()
        # done when the columns of x are eigenvectors to round-off (checked on each
        # step's products, so the last correction is not taken without need)
        if float(np.max(np.abs(ax - x * d[None, :]))) <= RESIDUAL_TOL * scale:
            if float(np.max(np.abs(y @ x - np.eye(n)))) <= RESIDUAL_TOL:
                return d, x, y
            return None
        gap = d[None, :] - d[:, None]
        np.fill_diagonal(gap, 1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            f = m / gap
        np.fill_diagonal(f, 0.0)
        largest = float(np.max(np.abs(f)))
        if not np.isfinite(largest) or (step == 0 and largest > LARGEST_FIRST_CORRECTION):
            return None
        x = x + x @ f
        # (I + F)^-1 = I - F to first order, then a Newton-Schulz step: y stays the
        # inverse of x to O(F^4), so the next m is a similarity of a (an inverse left
        # behind by O(F^2) drives m's off-diagonal to zero for the wrong vectors)
        y = y - f @ y
        y = y @ (twice - x @ y)
    return None
