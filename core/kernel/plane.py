"""The plane-strain kernel of an elastic layer on a frictionless rigid foundation.

    k_pl(s) = int_0^inf L(u)/u cos(s u) du,   L(u) = (cosh 2u - 1) / (sinh 2u + 2u),

with ``s`` the horizontal distance divided by the layer thickness (dimensionless), and
``k_pl`` dimensionless. ``L(u)/u`` is even, positive, equal to 1/2 at ``u = 0`` and
``~ 1/u`` at infinity, so ``k_pl`` is even with a logarithmic singularity at 0:

    k_pl(s) = -ln|s| + k_reg(s),   k_reg even and analytic for |Im s| < 2.

Two exact series are used, each where it converges fast.

Taylor series of the regular part (|s| < 2). Writing
``L(u)/u = (1 - exp(-u))/u + h(u)`` gives the exact split
``k_pl(s) = ln(1 + 1/s^2)/2 + int_0^inf h(u) cos(s u) du``, hence

    k_reg(s) = sum_j a_j s^(2j),
    a_0 = int_0^inf h(u) du,   h(u) = [L(u) - 1 + exp(-u)] / u,
    a_j = (-1)^j / (2j)! int_0^inf u^(2j-1) [L(u) - 1] du      (j >= 1).

The last form equals ``(-1)^j mu_2j/(2j)! + (-1)^(j+1)/(2j)`` with
``mu_k = int u^k h(u) du`` but is free of the cancellation between those two terms.
``L(u) - 1 ~ -4u exp(-2u)``, so ``a_j ~ (-1)^(j+1) (2 + 1/j) 4^-j``: radius of convergence 2
(the nearest singularities of ``k_reg`` are at ``s = +-2i``).

Residue series (s > 0). Closing the contour of ``(1/2) int_R L(u)/u exp(i s u) du`` in
the upper half plane picks up the simple poles ``u_n`` of ``L`` (``2 u_n`` are the roots
of ``sinh z + z = 0``; they come in pairs ``u_n``, ``-conj(u_n)``), with residues
``tanh^2(u_n) / (2 u_n)``:

    k_pl(s) = -2 pi sum_{n >= 1, Re u_n > 0} Im[ c_n exp(i s u_n) ],   c_n = tanh^2(u_n)/(2 u_n),

``u_1 = 1.12536430580093 + 2.10619611524533 i``, ``Im u_n ~ (n - 1/4) pi``. Hence for large
``s``: ``k_pl(s) ~ -2 pi |c_1| exp(-2.10619611524533 s) sin(1.12536430580093 s + arg c_1)``.

Evaluation. Both series are turned once, at import, into polynomial tables (built in
extended precision, about 10 ms), so that an evaluation is a few Horner steps:

* ``|s| < 2``: one polynomial of degree 24 in ``y = s^2/2 - 1`` for ``k_reg`` (Chebyshev
  interpolation of the Taylor series below 1 and of the residue series above, then monomial
  form; stable because the Chebyshev coefficients decay like (3 + 2 sqrt 2)^-k).
* ``2 <= |s| < 354.25``: on each interval of width 1/8 a polynomial of degree 9 in the
  local variable, times a per-interval scale ``exp(-Im(u_1) c)`` (``c`` the interval
  centre). The local variable is computed without rounding, so the relative accuracy does
  not degrade at large ``s`` (a formula in ``exp(-2.106 s)`` would lose ``2.1 s`` ulps to
  the rounding of its argument).
* ``|s| >= 354.25``: ``|k_pl|`` is below half the smallest subnormal double; 0 is returned.

Measured against mpmath (30 digits; references as in ``tests/kernel/test_kernel.py``) on 14,300
points of [0, 354.3]: for ``|s| < 2`` the error of ``k_pl`` is <= 2.7e-16 max(1, |k_pl|)
(near 0 that is the rounding of ``ln s``; <= 1.6e-16 absolute on [1, 2]) and that of
``k_reg`` <= 1.9e-16; for ``|s| >= 2`` the error of ``k_pl`` is <= 2.6e-16 of the envelope
``2 pi |c_1| exp(-Im(u_1) s)`` while that is a normal double (s < 336.5), <= 1.3 units of
2^-1074 beyond, and that of ``k_reg`` <= 2.1e-16 max(1, ln s).

Speed: about 11 ms per million points for ``|s| < 2`` and 20 ms per million above
(CPU time, numpy only, on a loaded 2-core machine).
"""

from __future__ import annotations

from decimal import Decimal

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "KERNEL_INTEGRAL",
    "KERNEL_REGULAR_AT_ZERO",
    "SWITCH",
    "plane_kernel",
    "plane_kernel_regular",
]

#: ``k_reg(0) = lim_{s -> 0} [k_pl(s) + ln|s|] = int_0^inf h(u) du`` (dimensionless).
#: mpmath, 45 digits: -0.351675392618701497551219584097 (not -0.3522).
KERNEL_REGULAR_AT_ZERO = -0.351675392618701497551219584097

#: ``int_{-inf}^{inf} k_pl(s) ds = pi * [L(u)/u]_{u=0} = pi/2`` (dimensionless), i.e.
#: ``int_0^inf k_pl(s) ds = pi/4``. Fourier inversion of the even symbol ``L(|u|)/|u|``,
#: whose value at ``u = 0`` is 1/2.
KERNEL_INTEGRAL = np.pi / 2

# Taylor coefficients a_0..a_36 of k_reg(s) = sum_j a_j s^(2j). Computed with mpmath
# (mp.dps = 45) by mp.quad of h(u) over [0, 0.5, 1, 2, 4, ..., 128] for a_0 and of
# u^(2j-1) (L(u) - 1), L - 1 = -(1 + 2u - exp(-2u))/(sinh 2u + 2u), over the same points
# plus 200 for j >= 1; a second run with a uniform subdivision agreed to all 30 digits.
# Only |s| <= 1 uses them here, where the tail after a_36 is below 4^-37.
_TAYLOR_DIGITS = """
    -3.51675392618701497551219584097e-1 5.21037458734225660753365656643e-1
    -1.3494967687149006699171959858e-1 3.45765723736846143595471795987e-2
    -8.63515373131893149571382779084e-3 2.13657996673033625264179254046e-3
    -5.28095583536280399984134295065e-4 1.30726796592780595049156517967e-4
    -3.24205106283495087474780765564e-5 8.05294383957008968360013983714e-6
    -2.00269509758036120896924227312e-6 4.98510149632391941640519914871e-7
    -1.24176247108243191211412132845e-7 3.09485591015397746146338310156e-8
    -7.71667232994339947393459919912e-9 1.92473329219268912542815661844e-9
    -4.80213200635409857452495457552e-10 1.19839301755109431444371985443e-10
    -2.99122701833726813413757194037e-11 7.46743018243440087349094749455e-12
    -1.86446413859889280340016793709e-12 4.65574668762384358575646843268e-13
    -1.16270629487864382027323851573e-13 2.90395726788811468243149811938e-14
    -7.25345709421704516106282552351e-15 1.81188397618821363278998472199e-15
    -4.5262938696256110672092640781e-16 1.13078271026636138543467738948e-16
    -2.82512108944794184534149472407e-17 7.0585300056987315805174862962e-18
    -1.76363553390975383189778047552e-18 4.4067572171991470237748518912e-19
    -1.1011428314305904388189478585e-19 2.75157369532306049412981575834e-20
    -6.87591451300549686926865205251e-21 1.71826683585872354491477307098e-21
    -4.29398646871971699663215794682e-22
"""

# First pole of L in the upper half plane, from mpmath.findroot of sinh z + z at 40
# digits (u_1 = z/2).
_U1_RE = "1.12536430580093027142000751508"
_U1_IM = "2.10619611524533030049188528078"
_PI = "3.14159265358979323846264338327950288"

#: Smallest |s| handled by the interval table; below it the even polynomial is used.
SWITCH = 2.0
_WIDTH = 0.125  # interval width of the table
# Degree on each interval: on a half-width h the Chebyshev coefficients of exp(i u_1 s)
# fall like 2 (|u_1| h / 2)^k / k!, the 10th is 3e-18 of the first for h = 1/16 (the log
# singularity at s = 0 is farther, 66 half-widths from the first interval).
_DEGREE = 9
# Degree in y = s^2/2 - 1 on |s| <= 2: the Chebyshev coefficients of k_reg fall like
# (3 + 2 sqrt 2)^-k (singularities at s = +-2i, i.e. y = -3); the 26th is 2e-19.
_EVEN_DEGREE = 24
# Beyond this |k_pl| < 2^-1075 (2 pi |c_1| exp(-Im(u_1) s), s > 354.0069): returned as 0.
_END = 354.25
_N_INTERVALS = round((_END - SWITCH) / _WIDTH)
_N_POLES = 24  # poles kept for s >= 1: there term 24 is ~1e-32 of term 1
_CHUNK = 1 << 14  # points per block: keeps the Horner temporaries in cache

# The tables are built in extended precision where the platform has it (x86: 64-bit
# significand), so that their only error is the final rounding to double. Where long
# double is plain double the same construction measured <= 2.1e-15 (in the units of the
# module docstring's error bounds) instead of <= 2.7e-16.
_X = np.longdouble


def _split(text: str, bits: int) -> tuple[float, np.longdouble]:
    """A decimal number as hi + lo, hi a double with ``bits`` significant bits."""
    x = float(text)
    e = int(np.floor(np.log2(abs(x))))
    scale = 2.0 ** (bits - 1 - e)
    hi = float(np.round(x * scale) / scale)
    return hi, _X(str(Decimal(text) - Decimal(hi)))


def _poles(n: int) -> np.ndarray:
    """The first ``n`` poles u_n (Re > 0, Im > 0) of L(u), by Newton on sinh z + z (z = 2u)."""
    k = np.arange(1, n + 1)
    z = np.log((4 * k - 1) * np.pi) + 1j * (2 * k - 0.5) * np.pi
    for _ in range(30):
        z = z - (np.sinh(z) + z) / (np.cosh(z) + 1.0)
    z = z.astype(np.clongdouble)
    for _ in range(2):
        z = z - (np.sinh(z) + z) / (np.cosh(z) + 1)
    z[0] = 2 * (_X(_U1_RE) + 1j * _X(_U1_IM))
    return z / 2


def _chebyshev_nodes(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Angles pi (j + 1/2) / n and points cos of them, j = 0..n-1 (extended precision)."""
    theta = _X(_PI) * (np.arange(n, dtype=_X) + _X(0.5)) / n
    return theta, np.cos(theta)


def _interpolate(values: np.ndarray) -> np.ndarray:
    """Monomial coefficients (axis 0) of the polynomial interpolating ``values`` (axis 0) at
    the n points of :func:`_chebyshev_nodes` on [-1, 1], rounded to double."""
    n = values.shape[0]
    theta, _ = _chebyshev_nodes(n)
    to_cheb = np.cos(np.outer(np.arange(n, dtype=_X), theta)) * (_X(2) / n)
    to_cheb[0] /= 2
    # Column k: monomial coefficients of T_k, by T_k = 2 x T_(k-1) - T_(k-2).
    cheb_to_mono = np.zeros((n, n), dtype=_X)
    cheb_to_mono[0, 0] = 1
    cheb_to_mono[1, 1] = 1
    for k in range(2, n):
        cheb_to_mono[1:, k] = 2 * cheb_to_mono[:-1, k - 1]
        cheb_to_mono[:, k] -= cheb_to_mono[:, k - 2]
    # Two products, not their (large-entried) product matrix: the Chebyshev coefficients
    # decay fast, so the monomial ones carry only the rounding of the values.
    return (cheb_to_mono @ (to_cheb @ values)).astype(float)


def _residue_series(s: np.ndarray, u: np.ndarray) -> np.ndarray:
    """k_pl(s) from the poles ``u`` (extended precision; s >= 1, where 24 poles give 1e-30)."""
    coef = np.tanh(u) ** 2 / (2 * u)
    return -2 * _X(_PI) * (coef[:, None] * np.exp(1j * np.outer(u, s))).imag.sum(axis=0)


def _build_even_polynomial(u: np.ndarray) -> np.ndarray:
    """Monomial coefficients, in y = s^2/2 - 1, of k_reg on |s| <= 2 (dimensionless)."""
    _, y = _chebyshev_nodes(_EVEN_DEGREE + 1)
    s = np.sqrt(2 * (y + 1))
    values = np.empty_like(s)
    # The Taylor series (radius 2) for s < 1, where 37 terms leave < 4^-37; poles above.
    small = s < 1
    taylor = np.array(_TAYLOR_DIGITS.split(), dtype=_X)
    values[small] = np.polynomial.polynomial.polyval(s[small] ** 2, taylor)
    values[~small] = _residue_series(s[~small], u) + np.log(s[~small])
    return _interpolate(values)


def _build_table(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-interval monomial coefficients (degree, interval) and scales for SWITCH <= s < _END.

    On interval i with centre c and half-width h, k_pl(c + h x) = scale_i * sum_m C[m, i] x^m
    for x in [-1, 1], with scale_i = exp(-Im(u_1) c).
    """
    coef = np.tanh(u) ** 2 / (2 * u)
    half = _X(_WIDTH / 2)
    centres = SWITCH + half + _WIDTH * np.arange(_N_INTERVALS, dtype=_X)
    # exp(i u_n c) exp(Im(u_1) c): the scale is divided out before anything can underflow.
    # For n = 1 the phase a_1 c and the exponent b_1 c are formed as hi*c + lo*c, hi*c exact
    # (c is a multiple of 1/16 below 2^9), so they stay exact even without extended precision.
    a1_hi, a1_lo = _split(_U1_RE, 36)
    b1_hi, b1_lo = _split(_U1_IM, 36)
    phase1 = np.exp(1j * (a1_hi * centres)) * np.exp(1j * (a1_lo * centres))
    _, x = _chebyshev_nodes(_DEGREE + 1)
    local = np.exp(1j * np.outer(u, half * x))  # (poles, nodes)
    values = np.outer(phase1, coef[0] * local[0]).imag  # (intervals, nodes)
    # Poles n >= 2 only where they matter: relative size exp(-(Im u_2 - Im u_1) c) < 1e-22
    # for c > 16.
    low = centres < 16
    shift = np.exp(1j * np.outer(u[1:].real, centres[low])
                   - np.outer(u[1:].imag - u[0].imag, centres[low]))  # (poles - 1, low)
    terms = (coef[1:, None, None] * shift[:, :, None]) * local[1:, None, :]
    values[low] += terms.imag.sum(axis=0)
    values *= -2 * _X(_PI)
    mono = _interpolate(values.T)  # (degree + 1, intervals)
    scales = (np.exp(-(b1_hi * centres)) * np.exp(-(b1_lo * centres))).astype(float)
    return np.ascontiguousarray(mono), scales


_POLES = _poles(_N_POLES)
_EVEN = _build_even_polynomial(_POLES)
_TABLE, _SCALES = _build_table(_POLES)
for _shared in (_POLES, _EVEN, _TABLE, _SCALES):  # read by every evaluation: never written
    _shared.setflags(write=False)


def _even_part(s: np.ndarray) -> np.ndarray:
    """k_reg(s) for |s| < 2 by Horner in y = s^2/2 - 1 (dimensionless)."""
    y = 0.5 * s * s
    y -= 1.0
    out = _EVEN[-1] * y
    out += _EVEN[-2]
    for c in _EVEN[-3::-1]:
        out *= y
        out += c
    return out


def _table_part(s: np.ndarray) -> np.ndarray:
    """k_pl(s) for SWITCH <= s < _END from the interval table (dimensionless)."""
    # (s - 2) * 8 is exact, and so is its fractional part: x carries no rounding of s.
    u = s - SWITCH
    u *= 1.0 / _WIDTH
    idx = u.astype(np.intp)
    x = u - idx
    x *= 2.0
    x -= 1.0
    # mode="clip" skips the bounds check (idx is in range by construction) and halves the
    # cost of the gathers, which dominate here.
    out = _TABLE[-1].take(idx, mode="clip")
    tmp = np.empty_like(out)
    for row in _TABLE[-2::-1]:
        out *= x
        row.take(idx, out=tmp, mode="clip")
        out += tmp
    _SCALES.take(idx, out=tmp, mode="clip")
    out *= tmp
    return out


def _evaluate_block(a: np.ndarray, regular: bool) -> np.ndarray:
    """k_pl(a), or k_pl(a) + ln a if ``regular``, for a flat block of a = |s| (or NaN)."""
    with np.errstate(divide="ignore"):
        near = a < SWITCH
        if near.all():
            out = _even_part(a)
            if not regular:
                out -= np.log(a)
            return out
        table = (a >= SWITCH) & (a < _END)
        if table.all():
            out = _table_part(a)
            if regular:
                out += np.log(a)
            return out
        out = np.empty_like(a)
        if near.any():
            sub = a[near]
            val = _even_part(sub)
            if not regular:
                val -= np.log(sub)
            out[near] = val
        if table.any():
            sub = a[table]
            val = _table_part(sub)
            if regular:
                val += np.log(sub)
            out[table] = val
        rest = ~(near | table)  # a >= _END or NaN
        if rest.any():
            sub = a[rest]
            out[rest] = np.log(sub) if regular else np.where(np.isnan(sub), np.nan, 0.0)
    return out


def _evaluate(s: ArrayLike, regular: bool) -> np.ndarray:
    """Blockwise driver of :func:`_evaluate_block` for any shape (dimensionless)."""
    flat = np.asarray(s, dtype=float)
    shape = flat.shape
    flat = flat.ravel()
    out = np.empty_like(flat)
    # Blocks: small temporaries stay in cache and are recycled by the allocator, where
    # whole-array temporaries would each cost fresh pages.
    for start in range(0, flat.size, _CHUNK):
        block = slice(start, start + _CHUNK)
        out[block] = _evaluate_block(np.abs(flat[block]), regular)
    return out.reshape(shape)


def plane_kernel(s: ArrayLike) -> np.ndarray:
    """The layer kernel ``k_pl(s) = int_0^inf L(u)/u cos(s u) du`` (dimensionless).

    ``s`` is the horizontal distance over the layer thickness (dimensionless, any real,
    any shape). Even in ``s``; ``+inf`` at ``s = 0``; changes sign at
    ``|s| = 1.2855947277324637``; 0 for ``|s| >= 354.25`` (true value below half the
    smallest subnormal double); NaN for NaN. Error against 30-digit mpmath: <= 2.7e-16
    max(1, |k_pl|) for ``|s| < 2``; for ``|s| >= 2``, <= 2.6e-16 of the envelope
    ``1.6075 exp(-2.10619611524533 |s|)`` while that is a normal double.
    """
    return _evaluate(s, regular=False)


def plane_kernel_regular(s: ArrayLike) -> np.ndarray:
    """The regular part ``k_pl(s) + ln|s|`` (dimensionless), even and analytic in ``s``.

    ``s`` is dimensionless (any real, any shape). Finite at 0, where it equals
    :data:`KERNEL_REGULAR_AT_ZERO` ``= -0.3516753926187015``; grows like ``ln|s|`` for
    large ``|s|``; ``+inf`` at infinity. Error against 30-digit mpmath <= 1.9e-16 for
    ``|s| < 2`` and <= 2.1e-16 ln|s| above (the rounding of ``ln|s|``).
    """
    return _evaluate(s, regular=True)
