"""Galerkin matrices of the projection method (the seed's (16), and G computed directly).

With ``phi_j = p_j / m`` and the discrete operator ``F`` of :mod:`core.discretize.quadrature`,

    R_ij = int int k(x - xi) p_i(x) p_j(xi) / (m(x) m(xi)) dx dxi  ~  Phi^T diag(w) F Phi,
    G_i  = int int k(x - xi) p_i(x) g(xi)   / (m(x) m(xi)) dx dxi  ~  Phi^T diag(w) F psi,

with ``psi = g/m``. The seed expands ``g`` in the basis to get ``G``, which discards the
exact treatment of a rough gap; here ``G`` is a direct quadrature of ``g`` itself.
``R`` is symmetric positive definite (the symbol ``L(u)/u`` is positive); its discrete
version is symmetrized to remove the O(quadrature error) asymmetry.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.discretize import Basis, KernelOperator


@dataclass(frozen=True)
class GapTerms:
    """``G_i`` (n), and the gap moments ``int g/m`` and ``int x g/m`` (dimensionless)."""

    vector: np.ndarray
    integral: float
    first_moment: float


def galerkin_matrix(operator: KernelOperator, basis: Basis, m_values: np.ndarray,
                    correction: np.ndarray | None = None) -> np.ndarray:
    """``R`` (n x n) for all functions of ``basis`` (dimensionless).

    ``correction``: :func:`core.discretize.galerkin_correction` of the operator's panels,
    needed by a basis with kinks or jumps at panel ends (the ``"graded"`` basis).
    """
    phi = basis.values / m_values[:, None]
    weighted = operator.panels.weights[:, None] * phi
    r = weighted.T @ (operator.matrix @ phi)
    if correction is not None:
        r = r + phi.T @ (correction @ phi)
    return 0.5 * (r + r.T)


def gap_terms(operator: KernelOperator, basis: Basis, m_values: np.ndarray,
              g_values: np.ndarray, correction: np.ndarray | None = None) -> GapTerms:
    """``G_i`` and the gap moments for gap values ``g_values`` at the nodes."""
    psi = g_values / m_values
    phi = basis.values / m_values[:, None]
    w = operator.panels.weights
    vector = (w[:, None] * phi).T @ (operator.matrix @ psi)
    if correction is not None:
        vector = vector + phi.T @ (correction @ psi)
    x = operator.panels.nodes
    return GapTerms(vector, float(np.sum(w * psi)), float(np.sum(w * x * psi)))
