"""Tests of the layer kernel k_pl(s) and its regular part k_pl(s) + ln|s|.

The reference values are 30-digit mpmath computations by two formulas independent of the
tables in core.kernel.plane: the exact split

    k_pl(s) = ln(1 + 1/s^2)/2 + int_0^inf [L(u) - 1 + exp(-u)]/u cos(s u) du

by quadrature for s < 1, and the residue series over the poles of L (roots of
sinh z + z = 0 found by mpmath.findroot) for s >= 1. They agree to 1e-40 at s = 0.6, 1
and 1.5 (40-digit working precision).
Regenerate the stored table with ``python tests/kernel/test_kernel.py`` (package installed, as
``tests/run.sh`` does, or ``PYTHONPATH=.``).
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
from scipy import integrate

from core.kernel.plane import (
    KERNEL_INTEGRAL,
    KERNEL_REGULAR_AT_ZERO,
    SWITCH,
    plane_kernel,
    plane_kernel_regular,
)

# First pole of L(u) = (cosh 2u - 1)/(sinh 2u + 2u) in the upper half plane (mpmath).
A1 = 1.1253643058009302714  # oscillation wavenumber of the tail
B1 = 2.1061961152453303005  # decay rate of the tail
ENVELOPE = 1.6075402535330034647  # 2 pi |c_1|, c_1 = tanh^2(u_1) / (2 u_1)
FIRST_ZERO = 1.2855947277324637105  # mp.findroot of the residue series near 1.28


# ---------------------------------------------------------------- mpmath reference ----

_ROOTS: list[tuple[mp.mpc, mp.mpc]] = []


def _poles(n: int) -> list[tuple[mp.mpc, mp.mpc]]:
    """The first n poles u_k of L in Re u > 0, Im u > 0 with c_k = tanh^2(u_k)/(2 u_k)."""
    while len(_ROOTS) < n:
        k = len(_ROOTS) + 1
        guess = mp.log((4 * k - 1) * mp.pi) + 1j * (2 * k - mp.mpf(1) / 2) * mp.pi
        u = mp.findroot(lambda z: mp.sinh(z) + z, guess) / 2
        _ROOTS.append((u, mp.tanh(u) ** 2 / (2 * u)))
    return _ROOTS[:n]


def mp_kernel_residues(s: float) -> mp.mpf:
    """k_pl(s), s >= ~0.5, by the residue series (terms kept until 1e-35 relative)."""
    s = mp.mpf(s)
    n = int(82 / (mp.pi * s)) + 3
    return -2 * mp.pi * mp.fsum(mp.im(c * mp.exp(1j * s * u)) for u, c in _poles(n))


def mp_kernel_split(s: float) -> mp.mpf:
    """k_pl(s), s > 0, by the split formula and quadrature (slow: about a second)."""
    s = mp.mpf(s)

    def h(u):
        big_l = 2 * mp.sinh(u) ** 2 / (mp.sinh(2 * u) + 2 * u)
        return (big_l - 1 + mp.exp(-u)) / u * mp.cos(s * u)

    # The integrand decays like exp(-u)/u; nodes at the oscillation scale 1/s.
    top = 110
    step = min(mp.mpf(1), mp.pi / s)
    nodes = [0] + [step * k for k in range(1, int(top / step) + 1)]
    return mp.log(1 + 1 / s**2) / 2 + mp.quad(h, nodes)


def mp_kernel(s: float, dps: int = 30) -> mp.mpf:
    """k_pl(s) for s > 0 at ``dps`` digits."""
    with mp.workdps(dps + 10):
        return +(mp_kernel_split(s) if s < 1 else mp_kernel_residues(s))


# Reference values: (s, k_pl(s)) with s exact as a double and k_pl to 25 digits, from
# mp_kernel(s, 30) (run ``python tests/kernel/test_kernel.py``, about 20 s). Points: near 0, the
# switch point SWITCH = 2 and its neighbours, a centre and an end of a table interval
# (2.0625, 2.125), the first zero, the check values of the model notes, and the tail up to
# the last normal doubles.
REFERENCE = [
    (1e-300, "690.4238525055950036827871"),
    (1e-12, "27.27934572330984673077803"),
    (1e-06, "13.46383516534609368926735"),
    (0.001, "6.556080407400759318269461"),
    (0.01, "4.253546895765801079230305"),
    (0.1, "1.956106614485433206708486"),
    (0.3, "0.8981223427212353875383435"),
    (0.6, "0.3307142688863642860070319"),
    (0.9, "0.1024639734466704863436986"),
    (1.0, "0.06206704791051218054364989"),
    (1.2855947277324637, "-4.631579344008662578136173e-18"),
    (1.5, "-0.01626211836094056417057068"),
    (1.9, "-0.01869726184911546863806916"),
    (1.9999999999999998, "-0.01711021423713402124564293"),
    (2.0, "-0.01711021423713401737440962"),
    (2.0000000000000004, "-0.01711021423713400963194302"),
    (2.0625, "-0.01598139491147843992867185"),
    (2.125, "-0.01480181226830367525117925"),
    (2.2, "-0.01336764100565341267118051"),
    (2.5, "-0.008129111648696819753961939"),
    (3.0, "-0.002716267502369278392136729"),
    (4.0, "-0.00003162800298832336867424785"),
    (5.0, "0.00003691359232331442848650482"),
    (7.3, "-0.0000001567216647926994297705517"),
    (10.0, "4.240973383174879338921978e-10"),
    (12.5, "-3.018085957981386679040555e-13"),
    (16.0, "2.792042716232960785871021e-15"),
    (20.0, "-6.562743784987238442405046e-19"),
    (30.0, "-4.541567380156889465402759e-28"),
    (45.0, "9.732648227394153992588647e-42"),
    (60.0, "2.076681103788424595192232e-56"),
    (100.0, "4.918130475365069074740873e-92"),
    (150.0, "7.512323142421028164674739e-138"),
    (200.0, "9.918848568701306534336388e-184"),
    (250.0, "9.651906031461819229424302e-230"),
    (300.0, "5.717248552842329434555124e-277"),
    (336.0, "2.287783383140799079106358e-308"),
]


def envelope(s: np.ndarray) -> np.ndarray:
    """2 pi |c_1| exp(-Im(u_1) s): the amplitude of the k_pl tail (dimensionless)."""
    return ENVELOPE * np.exp(-B1 * np.asarray(s))


# ---------------------------------------------------------------------------- tests ----


def test_check_values_of_the_model_notes():
    # The notes print 15 significant digits; the tolerance is half a unit of the last one
    # plus 1e-16 (our error, measured <= 1.7e-16 below 2).
    checks = [(0.1, 1.95610661448543, 5e-15), (1.0, 0.0620670479105122, 5e-17),
              (2.0, -0.017110214237134, 5e-16)]
    for s, value, tol in checks:
        assert abs(float(plane_kernel(s)) - value) <= tol + 1e-16
    # The notes' k_pl(5) = 3.69135923233141e-5 is off by 3 units in its last digit: mpmath
    # (residues and quadrature alike) gives 3.691359232331442849e-5. Tolerance: 6e-16 of the
    # envelope (4.3e-5 here), as in the table test below.
    assert abs(float(plane_kernel(5.0)) - 3.691359232331442849e-5) <= 6e-16 * envelope(5.0)


def test_against_stored_mpmath_table():
    s = np.array([p for p, _ in REFERENCE])
    ref = [mp.mpf(v) for _, v in REFERENCE]
    k = plane_kernel(s)
    reg = plane_kernel_regular(s)
    for si, ki, ri, kr in zip(s, k, reg, ref, strict=True):
        err = abs(mp.mpf(float(ki)) - kr)
        if si < SWITCH:
            # Measured max over the table: 1.6e-16 * max(1, |k|) (near 0 the answer is
            # dominated by the rounding of -ln s, hence the relative form).
            assert err <= 4e-16 * max(1.0, abs(float(kr)))
            # k_reg itself: measured <= 1.1e-16 here, 1.9e-16 on 6,000 points of [0, 2).
            err_reg = abs(mp.mpf(float(ri)) - (kr + mp.log(si)))
            assert err_reg <= 4e-16 * max(1.0, abs(math.log(si)))
        else:
            # Relative to the envelope of the tail: measured 1.5e-16 here, <= 2.7e-16 on
            # 4,000 points of [2, 336].
            assert err <= 6e-16 * envelope(si)
            err_reg = abs(mp.mpf(float(ri)) - (kr + mp.log(si)))
            # ln s rounded: measured 0 here (correctly rounded), <= 4.5e-16 on [2, 60].
            assert err_reg <= 4e-16 * max(1.0, math.log(si))


def test_against_live_mpmath_residue_series():
    # A fresh, random set of points (the stored table could share a blind spot).
    rng = np.random.default_rng(20240611)
    s = np.concatenate([rng.uniform(1.0, 2.0, 4), rng.uniform(2.0, 12.0, 8),
                        rng.uniform(12.0, 330.0, 6)])
    k = plane_kernel(s)
    with mp.workdps(40):
        for si, ki in zip(s, k, strict=True):
            ref = mp_kernel_residues(si)
            # Measured here 9.8e-17; on 7,000 points <= 1.7e-16 absolute on [1, 2] and
            # <= 2.7e-16 of the envelope above 2.
            scale = 1.0 if si < SWITCH else envelope(si)
            assert float(abs(mp.mpf(float(ki)) - ref)) <= 6e-16 * scale


def test_value_at_zero_and_constant():
    # a_0 = int_0^inf [L(u) - 1 + exp(-u)]/u du = -0.351675392618701497551219584097 (mpmath
    # mp.quad at 45 digits); the 0.3522 of the model notes is wrong in the third digit.
    assert KERNEL_REGULAR_AT_ZERO == -0.3516753926187015
    assert plane_kernel_regular(0.0) == KERNEL_REGULAR_AT_ZERO
    # k_reg(s) = a_0 + a_1 s^2 + ..., a_1 = 0.52103745873422566: at s = 1e-4 the s^2 term is
    # 5e-9, so the value is a_0 + 5.2103745873e-9 to within a_2 s^4 ~ 1e-17.
    assert abs(float(plane_kernel_regular(1e-4)) - (KERNEL_REGULAR_AT_ZERO
                                                    + 0.52103745873422566e-8)) <= 2e-16
    assert plane_kernel(0.0) == np.inf


def test_evenness_and_shapes():
    rng = np.random.default_rng(1)
    s = rng.uniform(0.0, 400.0, (37, 53))
    s[0, :5] = [0.0, 1.0, SWITCH, 354.25, 1e300]
    for f in (plane_kernel, plane_kernel_regular):
        out = f(s)
        assert out.shape == s.shape
        # Evaluated on |s|: exactly even, bit for bit.
        assert np.array_equal(f(-s), out)
        assert f(2.5).shape == ()
    assert plane_kernel([]).shape == (0,)


def test_special_values():
    k = plane_kernel([np.inf, -np.inf, np.nan, 354.25, 1e300])
    assert np.array_equal(k[[0, 1, 3, 4]], np.zeros(4))
    assert np.isnan(k[2])
    reg = plane_kernel_regular([np.inf, np.nan, 1e300])
    assert reg[0] == np.inf and np.isnan(reg[1])
    assert reg[2] == math.log(1e300)


def test_first_sign_change():
    # The only zero below 2; k_pl > 0 before it, < 0 after it up to the next zero at ~4.
    s = np.linspace(1e-6, FIRST_ZERO, 2001)[:-1]
    assert np.all(plane_kernel(s) > 0)
    s = np.linspace(FIRST_ZERO, 3.5, 2001)[1:]
    assert np.all(plane_kernel(s) < 0)
    # k_pl(FIRST_ZERO) = -4.6e-18 (mpmath; FIRST_ZERO is rounded, k_pl' = -0.12 there); the
    # result, a difference of two numbers near 0.25, is measured to be exactly 0.
    assert abs(float(plane_kernel(FIRST_ZERO))) <= 1e-16
    assert plane_kernel(FIRST_ZERO - 1e-12) > 0 > plane_kernel(FIRST_ZERO + 1e-12)


def _one_sided_derivative(f, x: float, h: float, side: int) -> float:
    """Fourth-order one-sided difference; side = -1 uses points left of x, +1 right."""
    w = np.array([-25.0, 48.0, -36.0, 16.0, -3.0]) / 12.0
    pts = x + side * h * np.arange(5)
    return side * float(np.dot(w, f(pts))) / h


def test_continuity_at_the_switch_point():
    left = float(plane_kernel(np.nextafter(SWITCH, 0.0)))
    right = float(plane_kernel(SWITCH))
    # True difference: k_pl'(2) * 2.2e-16 = 3.9e-18; measured jump 2.8e-17 (1 ulp of 0.017).
    assert abs(left - right) <= 1e-16
    # Derivatives from each side (no point crosses SWITCH) against mpmath:
    # k_pl'(2) = 0.017434484862184673 (mp.diff of the residue series, 40 digits).
    # With h = 1e-3: truncation ~3e-13 (the error falls 81-fold per 3-fold smaller h:
    # 3.8e-9, 3.0e-11 at h = 1e-2, 3e-3), rounding ~2e-16 * 6 / h ~ 1e-12;
    # measured errors 1.1e-12 (left) and 3.8e-13 (right).
    exact = 0.017434484862184673
    d_left = _one_sided_derivative(plane_kernel, float(np.nextafter(SWITCH, 0.0)), 1e-3, -1)
    d_right = _one_sided_derivative(plane_kernel, SWITCH, 1e-3, +1)
    assert abs(d_left - exact) <= 3e-12
    assert abs(d_right - exact) <= 3e-12


def test_continuity_across_table_intervals():
    # Interval ends 2 + k/8: the value just below and at each end agree to rounding.
    ends = SWITCH + np.arange(1, 2816) / 8.0
    below = plane_kernel(np.nextafter(ends, 0.0))
    at = plane_kernel(ends)
    env = envelope(ends)
    # The true change over that ulp of s is at most |k_pl'| ds <= (B1 + A1) ds * envelope
    # (up to 1.8e-13 * envelope at s = 336); measured: every jump is below that bound minus
    # 2.6e-16 * envelope, so the jumps are the slope, not a mismatch of the pieces.
    ds = ends - np.nextafter(ends, 0.0)
    normal = env > 1e-300
    bound = ((B1 + A1) * ds + 4e-16) * env
    assert np.all(np.abs(at - below)[normal] <= bound[normal])


def test_integral_over_half_line():
    # int_0^inf k_pl = pi/4: int_{-inf}^{inf} k_pl = pi * [L(u)/u at u = 0] = pi/2.
    assert KERNEL_INTEGRAL == np.pi / 2
    # The log singularity is integrated exactly: int_0^2 -ln s ds = 2 - 2 ln 2; then quad
    # on the regular part and on the smooth tail (k_pl(40) ~ 1e-37, negligible).
    smooth, _ = integrate.quad(lambda s: float(plane_kernel_regular(s)), 0.0, 2.0,
                               epsabs=1e-14, epsrel=0.0, limit=200)
    tail, _ = integrate.quad(lambda s: float(plane_kernel(s)), 2.0, 40.0, epsabs=1e-15,
                             epsrel=0.0, limit=400)
    total = smooth - (2 * math.log(2) - 2) + tail
    # Measured |total - pi/4| = 1.1e-16 (quad's own estimates: 6.5e-15 and 1.4e-16).
    assert abs(total - np.pi / 4) <= 1e-15
    # And quad of k_pl itself, log singularity included: measured error 2.2e-16 (estimate
    # 1.3e-15).
    direct, _ = integrate.quad(lambda s: float(plane_kernel(s)), 0.0, 2.0, epsabs=1e-14,
                               epsrel=0.0, limit=200)
    assert abs(direct + tail - np.pi / 4) <= 1e-15


def test_large_s_decay_rate():
    # One period of the oscillation later the tail is smaller by exp(-B1 * period): at
    # s >= 20 the second pole contributes exp(-3.25 s) < 1e-28 relative. The rate from the
    # ratio is B1 up to the rounding of s + period (which shifts the phase by up to
    # A1 ulp(s)/2, 3e-14 at s = 300); measured max |rate - B1| = 4.0e-15 on [20, 300].
    period = 2 * np.pi / A1
    s0 = np.linspace(20.0, 300.0, 97)
    s1 = s0 + period
    k0, k1 = plane_kernel(s0), plane_kernel(s1)
    ok = np.abs(k0) > 0.5 * envelope(s0)  # away from zeros of the oscillation
    assert ok.sum() > 50
    rate = -np.log(k1[ok] / k0[ok]) / (s1 - s0)[ok]
    assert np.max(np.abs(rate - B1)) <= 1e-14
    # The 2.106 of the model notes.
    assert round(B1, 3) == 2.106


if __name__ == "__main__":
    # Prints REFERENCE (takes about a minute: quadrature below s = 1).
    for s in [p for p, _ in REFERENCE]:
        print(f"    ({s!r}, \"{mp.nstr(mp_kernel(s), 25)}\"),")
