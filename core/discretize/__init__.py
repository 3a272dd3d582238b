"""Space discretization: panels, product-integration quadrature and bases on [-1, 1].

- ``panels.py``: composite Gauss-Legendre panels graded toward ``x = +-1`` and jumps, the
  panel rule (``GAUSS_NODES``, ``GAUSS_WEIGHTS``) and the panel-wise interpolant;
- ``quadrature.py``: product-integration weights exact for the log singularity and the
  discrete operator ``F`` on panels (``kernel_operator``, ``operator_rows``);
- ``pair_tables.py``: reference tables of near panel pairs (near entries with no log per
  entry);
- ``basis.py``, ``basis_pieces.py``, ``graded_basis.py``: orthonormal bases for the
  weight ``1/m`` (the seed's global polynomials, piecewise, and the default graded one);
- ``galerkin.py``: the Galerkin correction that makes the projection exact for panel-wise
  polynomials.
"""

from __future__ import annotations

from core.discretize.basis import build_basis
from core.discretize.basis_pieces import Basis
from core.discretize.galerkin import galerkin_correction
from core.discretize.graded_basis import graded_cuts
from core.discretize.panels import (
    BARYCENTRIC_WEIGHTS,
    DENSE_SAMPLES,
    GAUSS_NODES,
    GAUSS_WEIGHTS,
    MIRROR_TOL,
    NODES_PER_PANEL,
    SHORT_SHARE,
    VALUES_TO_LEGENDRE,
    Panels,
    base_panels,
    even_overall,
    even_per_node,
    interpolation_weights,
    mirrored_rule,
    panel_index,
    panel_legendre_coefficients,
    refine_to_resolve,
)
from core.discretize.quadrature import (
    FRESH_SHARE,
    NEAR_FIELD,
    KernelOperator,
    kernel_operator,
    node_rows,
    operator_rows,
    operator_rows_from_pairs,
    panel_nodes,
    shared_panels,
)

__all__ = [
    "DENSE_SAMPLES",
    "BARYCENTRIC_WEIGHTS",
    "SHORT_SHARE",
    "base_panels",
    "even_overall",
    "even_per_node",
    "Basis",
    "build_basis",
    "FRESH_SHARE",
    "galerkin_correction",
    "GAUSS_NODES",
    "GAUSS_WEIGHTS",
    "graded_cuts",
    "interpolation_weights",
    "kernel_operator",
    "KernelOperator",
    "MIRROR_TOL",
    "mirrored_rule",
    "NEAR_FIELD",
    "node_rows",
    "NODES_PER_PANEL",
    "operator_rows",
    "operator_rows_from_pairs",
    "panel_index",
    "panel_legendre_coefficients",
    "panel_nodes",
    "Panels",
    "refine_to_resolve",
    "shared_panels",
    "VALUES_TO_LEGENDRE",
]
