"""The Galerkin system of the exact layered solve: its modes, nodes and matrix.

The pressure ``q*(t) = sum_n c_n T_n(t) / sqrt(1 - t^2)`` (n < modes) on the stack's kernel
``k_stack(lam (t - s)) = -L_inf ln|t - s| + K(t - s)`` (:mod:`core.engines.layered.solve`): the
logarithmic part's Galerkin matrix is diagonal, the smooth part's comes from ``K`` on
Gauss-Chebyshev nodes through two DCTs (:func:`galerkin_matrix`), ``K`` read from the
stack's table (:class:`core.kernel.RegularPartTable`). How many modes and nodes,
and the table's degree, follow from the coating's thinnest layer and the tolerance
(:func:`default_modes`, :func:`node_count`, :func:`table_degree`): tolerances of
:data:`COARSE_TOL` and above take coarser rules, measured to leave <= 2.3e-10.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import lru_cache

import numpy as np

from core.kernel import COARSE_PANEL_DEGREE, PANEL_DEGREE, RegularPartTable, UniformLayer

__all__ = ["COARSE_TOL", "MAX_MODES", "MAX_NODES", "default_modes", "galerkin_matrix",
           "gap_moments", "node_count", "table_degree"]

#: Chebyshev modes of the pressure per ``sqrt(a / h_min)``: the edge boundary layer of
#: width ``h`` is ``sqrt(h / a)`` wide in the angle of ``t = cos(theta)``. Measured (smooth,
#: E_c = 0.3 E, H = a): h = 0.04 a, 64 modes: force and moment settled to 1e-10; h = 0.002 a:
#: 128 modes 6e-5, 256 modes 1e-7 (relative change to the next doubling).
MODES_PER_ROOT = 12
#: Fewest modes.
MIN_MODES = 32
#: Most modes (up to 2048 nodes: a quarter of 2048^2 table reads); a thinner coating than
#: ``(MODES_PER_ROOT / MAX_MODES)^2 a`` (5.5e-4 a) would need more from the start.
MAX_MODES = 512
#: Gauss-Chebyshev nodes of the smooth part per mode.
NODES_PER_MODE = 4
#: The same for ``tol >= COARSE_TOL``. Measured at tol 1e-6 against tol 1e-11 with 4 per
#: mode (force and moment; 135-270 modes): 2 per mode leaves 1.1e-13 (uniform_flat),
#: 1.4e-11 (rounded_graded: its nodes are set by the thickness), 2.3e-10 (soft bonded,
#: h = 0.008 a: the coarser table's floor), 2.1e-12 (stiff smooth, H = a / 2); bases much
#: thinner than the punch (a / H = 5 to 40, h = 0.2 H to 2 H, bonded): <= 2.2e-10.
COARSE_NODES_PER_MODE = 2
#: Nodes per ``a / h_min``: the smooth part ``K`` turns from the top coating's logarithm
#: to the base's over distances ~ h, so the node spacing at the centre (``pi / nodes``)
#: must resolve h. Measured (bonded, h = 0.008 a, E_c = 0.01 E, crowned punch with a
#: kink): spacing 0.73 h errs by 3e-7 in the settlement, 0.36 h by 1e-13.
NODES_PER_THICKNESS = 3 * np.pi
#: Tolerances at or above this take the coarser quadrature and table below: their error
#: (<= 2.3e-10 measured) stays 200x below the ``tol / 2`` a solve aims at.
COARSE_TOL = 1e-7
#: Nodes per ``a / h_min`` for ``tol >= COARSE_TOL`` (spacing 0.5 h). Measured against
#: 6 pi on rounded_graded at tol 1e-6 (135 modes): 3 pi 1.6e-14, 2.4 pi 1.5e-13, 2 pi
#: 2.1e-11, 1.6 pi 2.7e-9, 1.4 pi 3.0e-8 in force and moment; a soft bonded and a stiff
#: smooth coating (240-270 modes) are set by the modes there, 3.5e-14 and 1e-16.
COARSE_NODES_PER_THICKNESS = 2 * np.pi
#: Most nodes (a 4096^2 table lookup and product, a few seconds): coatings thinner than
#: ``NODES_PER_THICKNESS a / MAX_NODES`` (2.3e-3 a) are left to the thin-layer model.
MAX_NODES = 4096
#: Gauss-Legendre points per panel of the gap's moments (panels of ~ pi / modes in angle).
GAP_POINTS = 12
_GAP_RULE = np.polynomial.legendre.leggauss(GAP_POINTS)

def node_count(half_width: float, layers: Sequence[UniformLayer], modes: int, *,
               tol: float = 0.0, base_thickness: float | None = None) -> int:
    """Gauss-Chebyshev nodes [-]: ``max(NODES_PER_MODE modes, NODES_PER_THICKNESS a /
    h_min)`` (:data:`COARSE_NODES_PER_MODE`, :data:`COARSE_NODES_PER_THICKNESS` for ``tol
    >= COARSE_TOL``), rounded up to twice a product of 2, 3 and 5: the Galerkin matrix
    transforms each half of the nodes (:func:`galerkin_matrix`), and DCTs of such lengths
    take half the time of others (1179 nodes 28 ms, 1200 nodes 13 ms).

    Without coating layers ``h_min`` is the base's thickness ``base_thickness`` H [m] when
    that is thinner than the punch: the kernel then varies over distances ~ H. Measured on
    a bare base at tol 1e-6 without it (2 nodes per mode only): a / H = 60 erred by 1.9e-7
    in the settlement with an estimate of 1.1e-8, a / H = 87 by 4.5e-5 with 5e-8; with it,
    <= 2e-10 (tests/engines/test_uncoated.py). A coating's thinnest layer sets the nodes
    as it did when they were measured.
    """
    # imported here: a scene the layered kernel declines never loads scipy.fft (and
    # scipy.special behind it), a tenth of the command line's start-up
    from scipy.fft import next_fast_len

    scales = [lay.thickness for lay in layers] if layers else (
        [] if base_thickness is None else [base_thickness])
    thinnest = min(scales + [half_width])
    coarse = tol >= COARSE_TOL
    per_thickness = COARSE_NODES_PER_THICKNESS if coarse else NODES_PER_THICKNESS
    per_mode = COARSE_NODES_PER_MODE if coarse else NODES_PER_MODE
    wanted = max(per_mode * modes, int(np.ceil(per_thickness * half_width / thinnest)))
    return 2 * next_fast_len((wanted + 1) // 2, real=True)


def table_degree(tol: float) -> int:
    """The Chebyshev degree [-] of the stack's table for a solve to ``tol`` [-]."""
    return COARSE_PANEL_DEGREE if tol >= COARSE_TOL else PANEL_DEGREE


def default_modes(half_width: float, layers: Sequence[UniformLayer]) -> int:
    """``max(MIN_MODES, MODES_PER_ROOT sqrt(a / h_min))`` [-] for half-width a [m]."""
    thinnest = min([lay.thickness for lay in layers] + [half_width])
    return max(MIN_MODES, int(np.ceil(MODES_PER_ROOT * np.sqrt(half_width / thinnest))))


def galerkin_matrix(lam: float, l_inf: float, table: RegularPartTable, modes: int,
                    n_nodes: int) -> np.ndarray:
    """``pi`` times the Galerkin matrix of ``(1/pi) int k_stack(lam (t - s)) . ds`` on
    ``T_n / sqrt(1 - t^2)``, n < modes, with ``n_nodes`` (even) Gauss-Chebyshev nodes."""
    from scipy.fft import dct  # here for start-up speed (see node_count)

    if n_nodes % 2:
        raise ValueError(f"n_nodes: must be even, got {n_nodes}")
    q = n_nodes // 2
    theta = np.pi * (np.arange(q) + 0.5) / n_nodes
    top = np.cos(theta)  # the nodes t_i > 0; the others are -t_i
    # S_ij = K(t_i - t_j) over all nodes is symmetric under (i, j) -> (n-1-i, n-1-j): its
    # even part in i (and j) gives the modes m, n both even, its odd part both odd, the
    # rest vanish. On the nodes t_i > 0 those parts are (A + B) / 2 and (A - B) / 2 with
    # A = K(t_i - t_j), B = K(t_i + t_j): a quarter of the n^2 table reads, and transforms
    # of half the length (sum_i T_m(t_i) X_i over all nodes: a DCT-II of the half for even
    # m, a DCT-IV for odd m; scipy's are twice the sums).
    near = _symmetric_block(table, lam, top, -1.0)
    far = _symmetric_block(table, lam, top, 1.0)
    even = 0.5 * (near + far) - l_inf * np.log(lam)
    odd = 0.5 * (near - far)
    weight = np.pi / n_nodes
    matrix = np.zeros((modes, modes))
    n_even, n_odd = (modes + 1) // 2, modes // 2
    matrix[0::2, 0::2] = dct(dct(even, type=2, axis=0)[:n_even], type=2, axis=1)[:, :n_even]
    matrix[1::2, 1::2] = dct(dct(odd, type=4, axis=0)[:n_odd], type=4, axis=1)[:, :n_odd]
    matrix *= weight * weight
    diagonal = np.empty(modes)
    diagonal[0] = np.pi**2 * np.log(2.0)
    diagonal[1:] = np.pi**2 / (2 * np.arange(1, modes))
    matrix[np.diag_indices(modes)] += l_inf * diagonal
    return matrix


def _symmetric_block(table: RegularPartTable, lam: float, x: np.ndarray,
                     sign: float) -> np.ndarray:
    """``K(x_i + sign x_j) = table(lam |x_i + sign x_j|)``, symmetric: read for j >= i only,
    in blocks of rows that keep the temporaries small."""
    out = np.empty((x.size, x.size))
    for start in range(0, x.size, 64):
        rows = slice(start, min(start + 64, x.size))
        block = table(lam * np.abs(x[rows, None] + sign * x[None, start:]))
        out[rows, start:] = block
        out[start:, rows] = block.T
    return out


def gap_moments(gap: Callable[[np.ndarray], np.ndarray], breakpoints: Sequence[float],
                modes: int) -> np.ndarray:
    """``G_m = int_0^pi g*(cos th) cos(m th) dth`` [-], m < modes, for a callable ``gap``
    of ``t`` in [-1, 1] (Gauss-Legendre panels in ``th`` broken at the breakpoints)."""
    cuts = tuple(sorted({0.0, np.pi} | {float(np.arccos(b)) for b in breakpoints
                                         if -1 < b < 1}))
    theta, rows = _gap_rule(cuts, modes)
    values = np.broadcast_to(np.asarray(gap(np.cos(theta)), dtype=float), theta.shape)
    return rows @ values


@lru_cache(maxsize=8)
def _gap_rule(cuts: tuple[float, ...], modes: int) -> tuple[np.ndarray, np.ndarray]:
    """The points ``theta`` of :func:`gap_moments`' rule and its rows ``w cos(m theta)``
    (the same for every gap of a zone: a march under a gap that changes at each step
    builds them once)."""
    count = max(4, modes // 2)
    edges = np.unique(np.concatenate([np.linspace(lo, hi, max(2, int(np.ceil(
        count * (hi - lo) / np.pi)) + 1)) for lo, hi in zip(cuts[:-1], cuts[1:], strict=True)]))
    x, w = _GAP_RULE
    half = 0.5 * np.diff(edges)
    theta = (0.5 * (edges[1:] + edges[:-1])[:, None] + half[:, None] * x).ravel()
    weights = (half[:, None] * w).ravel()
    rows = np.cos(np.outer(np.arange(modes), theta)) * weights[None, :]
    theta.setflags(write=False)
    rows.setflags(write=False)
    return theta, rows
