"""Values of the layer kernel to a chosen absolute accuracy, for the operator's assembly.

:mod:`core.kernel.plane` evaluates ``k_pl`` and ``k_reg`` to rounding; an operator whose target
is ``tol`` needs them to ~1e-4 tol only, and most of their cost is the Horner steps of a
degree-24 polynomial. Here the same series is truncated to the accuracy asked for, and
far pairs where the kernel has decayed below it are exact zeros.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.polynomial import chebyshev as npcheb

from core.kernel.plane import plane_kernel_regular

#: Default absolute accuracy of the kernel values in the operator: beyond rounding.
FULL_ACCURACY = 1e-17
#: |k_pl(s)| <= KERNEL_ENVELOPE exp(-KERNEL_DECAY s) for s >= 2 (core.kernel.plane: 2 pi |c_1|
#: exp(-Im(u_1) s)); far pairs where that is below the accuracy are exactly 0.
KERNEL_ENVELOPE = 1.6075
KERNEL_DECAY = 2.10619611524533
@lru_cache(maxsize=1)
def _even_chebyshev() -> np.ndarray:
    """Chebyshev coefficients in y = s^2/2 - 1 of ``k_reg`` on |s| <= 2 (degree 24)."""
    y = np.cos(np.pi * (np.arange(25) + 0.5) / 25)
    coef = npcheb.chebfit(y, plane_kernel_regular(np.sqrt(2.0 * (y + 1.0))), 24)
    coef.setflags(write=False)  # cached: every caller gets this very array
    return coef


@lru_cache(maxsize=64)
def _even_coefficients(accuracy: float) -> np.ndarray:
    """Monomial coefficients in y = s^2/2 - 1 of ``k_reg`` on |s| <= 2 to ``accuracy``.

    The Chebyshev series of ``k_reg`` in y falls like (3 + 2 sqrt 2)^-k (its nearest
    singularity is at y = -3): truncated where the tail is below the accuracy, a tol of
    1e-6 needs degree ~13 instead of 24, and the Horner steps are most of the kernel's cost.
    """
    cheb = _even_chebyshev()
    tail = np.cumsum(np.abs(cheb[::-1]))[::-1]  # tail[k] = sum_{j >= k} |c_j|
    degree = int(np.argmax(np.append(tail, 0.0) <= 0.5 * accuracy)) - 1
    coef = npcheb.cheb2poly(cheb[:max(degree, 1) + 1])
    coef.setflags(write=False)  # cached: every caller gets this very array
    return coef


def kernel_regular(s: np.ndarray, accuracy: float) -> np.ndarray:
    """``k_reg(s)`` (s >= 0, any shape) to within ``accuracy`` (absolute)."""
    if accuracy <= FULL_ACCURACY or not s.size or s.max() >= 2.0:
        return plane_kernel_regular(s)
    coef = _even_coefficients(accuracy)
    y = 0.5 * s * s
    y -= 1.0
    # Horner, its first step (c_n y + c_(n-1)) without filling an array with c_n
    out = y * coef[-1]
    out += coef[-2]
    for c in coef[-3::-1]:
        out *= y
        out += c
    return out


def kernel_block(s: np.ndarray, accuracy: float) -> np.ndarray:
    """``k_pl(s) = k_reg(s) - ln s`` (s > 0, any shape) to within ``accuracy`` (absolute);
    exactly 0 where its envelope is below the accuracy."""
    cut = np.log(KERNEL_ENVELOPE / max(accuracy, 1e-300)) / KERNEL_DECAY
    if s.size and s.max() >= cut:
        out = np.zeros_like(s)
        inside = s < cut
        out[inside] = kernel_block(s[inside], accuracy)
        return out
    out = kernel_regular(s, accuracy)
    with np.errstate(divide="ignore"):  # a target on a node: a near pair, replaced
        out -= np.log(s)
    return out
