"""A flat punch on uniform coating layers, solved with the exact layered kernel.

A rigid flat punch of half-width ``a`` in full contact, settled by ``delta`` and tilted by
``alpha``, on the stack of :mod:`core.layered_kernel` (elastic base):

    2 (1 - nu^2) / (pi E) int_{-a}^{a} k_stack((x - xi) / H) q(xi) dxi = delta + alpha x.

In ``x = a t``, ``k_stack(lam d) = -L_inf ln|d| + K(d)`` with ``K(d) = R(lam d) - L_inf ln
lam`` smooth (``R`` the regular part, ``lam = a / H``). The top coating is a half-space at
the punch edges, so ``q`` has the inverse square-root singularity: ``q(t) = sum_n c_n
T_n(t) / sqrt(1 - t^2)`` (Chebyshev, first kind). Galerkin with the same functions: the
logarithmic part is diagonal (``int -ln|t - s| T_n(s) / sqrt(1 - s^2) ds = pi T_n(t) / n``,
``pi ln 2`` for ``n = 0``), the smooth part by Gauss-Chebyshev quadrature. Force and moment:
``P = pi a c_0``, ``M = pi a^2 c_1 / 2``.

This is the answer of the coating model "layered kernel" for statement 1 (settlement and
tilt given) with a flat punch and an elastic base; :func:`flat_punch_stiffness` returns the
force per unit settlement and the moment per unit tilt, the two numbers the FE comparison
(``benchmarks/layered_kernel.py``) needs.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.layered_kernel import RegularPartTable, UniformLayer, symbol_at_infinity

__all__ = ["FlatPunchStiffness", "flat_punch_stiffness"]

#: Chebyshev modes of the pressure per ``sqrt(a / h_min)``: the edge boundary layer of
#: width ``h`` is ``sqrt(h / a)`` wide in the angle of ``t = cos(theta)``. Measured (smooth,
#: E_c = 0.3 E, H = a): h = 0.04 a, 64 modes: force and moment settled to 1e-10; h = 0.002 a:
#: 128 modes 6e-5, 256 modes 1e-7 (relative change to the next doubling).
MODES_PER_ROOT = 12
#: Fewest modes.
MIN_MODES = 32
#: Gauss-Chebyshev nodes of the smooth part per mode.
NODES_PER_MODE = 4


@dataclass(frozen=True)
class FlatPunchStiffness:
    """``force_per_settlement`` [N/m per m], ``moment_per_tilt`` [N per rad] (per unit
    length out of plane), the pressure's Chebyshev coefficients [Pa] for a unit settlement
    (``settlement_modes``) and a unit tilt (``tilt_modes``), and ``modes``, ``nodes``."""

    force_per_settlement: float
    moment_per_tilt: float
    settlement_modes: np.ndarray
    tilt_modes: np.ndarray
    modes: int
    nodes: int


def flat_punch_stiffness(half_width: float, layers: Sequence[UniformLayer],
                         base_thickness: float, base_modulus: float, base_poisson: float,
                         *, modes: int | None = None,
                         nodes: int | None = None) -> FlatPunchStiffness:
    """Force per unit settlement and moment per unit tilt of a flat punch of half-width a
    [m] on ``layers`` (top first) over the base (H [m], E [Pa], nu), all SI units.

    ``modes`` defaults to ``max(MIN_MODES, MODES_PER_ROOT sqrt(a / h_min))``, ``nodes`` to
    ``NODES_PER_MODE * modes``.
    """
    if modes is None:
        thinnest = min([lay.thickness for lay in layers] + [half_width])
        modes = max(MIN_MODES, int(np.ceil(MODES_PER_ROOT * np.sqrt(half_width / thinnest))))
    if half_width <= 0 or not np.isfinite(half_width):
        raise ValueError(f"half_width: must be a finite positive number, got {half_width!r}")
    n_nodes = nodes or NODES_PER_MODE * modes
    lam = half_width / base_thickness
    l_inf = symbol_at_infinity(layers, base_modulus, base_poisson)
    table = RegularPartTable(2 * lam, layers, base_thickness, base_modulus, base_poisson)
    theta = np.pi * (np.arange(n_nodes) + 0.5) / n_nodes
    t = np.cos(theta)
    smooth = np.empty((n_nodes, n_nodes))
    for start in range(0, n_nodes, 64):  # blocks keep the table's temporaries small
        rows = slice(start, start + 64)
        smooth[rows] = table(lam * (t[rows, None] - t[None, :]))
    smooth -= l_inf * np.log(lam)
    cheb = np.cos(np.outer(np.arange(modes), theta))  # T_m(t_i)
    weight = np.pi / n_nodes
    matrix = weight * weight * (cheb @ smooth @ cheb.T)
    diagonal = np.empty(modes)
    diagonal[0] = np.pi**2 * np.log(2.0)
    diagonal[1:] = np.pi**2 / (2 * np.arange(1, modes))
    matrix[np.diag_indices(modes)] += l_inf * diagonal
    # right-hand sides: pi E / (2 (1 - nu^2) a) int (delta + alpha a t) T_m / sqrt(1-t^2)
    scale = np.pi * base_modulus / (2 * (1 - base_poisson**2))
    rhs = np.zeros((modes, 2))
    rhs[0, 0] = scale * np.pi / half_width
    rhs[1, 1] = scale * np.pi / 2
    coef = np.linalg.solve(matrix, rhs)
    force = np.pi * half_width * coef[0, 0]
    moment = 0.5 * np.pi * half_width**2 * coef[1, 1]
    return FlatPunchStiffness(float(force), float(moment), coef[:, 0], coef[:, 1], modes,
                              n_nodes)
