"""Force per unit settlement and moment per unit tilt of a flat punch on uniform coating
layers, in SI units, from the exact layered solve (:mod:`core.engines.layered.solve`): what the FE
comparison (``benchmarks/layered_kernel.py``) reads."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.engines.layered.galerkin import default_modes
from core.engines.layered.solve import layered_response
from core.kernel import UniformLayer

__all__ = ["FlatPunchStiffness", "flat_punch_stiffness"]


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
                         *, modes: int | None = None) -> FlatPunchStiffness:
    """Force per unit settlement and moment per unit tilt of a flat punch of half-width a
    [m] on ``layers`` (top first) over the base (H [m], E [Pa], nu), all SI units.

    ``modes`` defaults to :func:`default_modes` (nodes: :func:`node_count`).
    """
    if half_width <= 0 or not np.isfinite(half_width):
        raise ValueError(f"half_width: must be a finite positive number, got {half_width!r}")
    modes = modes or default_modes(half_width, layers)
    response = layered_response(half_width, layers, base_thickness, base_modulus,
                                base_poisson, modes=modes)
    # q = E / (2 (1 - nu^2)) q*, delta* = delta / a: per metre of settlement, q* / a
    scale = base_modulus / (2 * (1 - base_poisson**2))
    settlement_modes = scale * response.coefficients[:, 1] / half_width
    tilt_modes = scale * response.coefficients[:, 2]
    force = np.pi * half_width * settlement_modes[0]
    moment = 0.5 * np.pi * half_width**2 * tilt_modes[1]
    return FlatPunchStiffness(float(force), float(moment), settlement_modes, tilt_modes,
                              modes, response.nodes)
