"""The exact layered kernel: its symbol's limits, its kernel against mpmath quadrature, and
the flat-punch solve with it against the resolved FE model."""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

from core.coating import layer_compliance
from core.engines.layered.stiffness import flat_punch_stiffness
from core.kernel import RegularPartTable, UniformLayer, symbol_at_infinity
from core.kernel.layered import stack_kernel, stack_kernel_regular, stack_symbol
from core.kernel.plane import plane_kernel

BASE = dict(base_thickness=1.0, base_modulus=1.0, base_poisson=0.2)


def base_symbol(u):
    return np.expm1(-2 * u) ** 2 / (1 - np.exp(-4 * u) + 4 * u * np.exp(-2 * u))


def test_no_coating_is_the_base_symbol_and_kernel():
    u = np.array([0.01, 0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 50.0, 400.0])
    # measured 8.4e-15 at u = 0.01 (the recursion's cancellation grows like 1/u^2 there),
    # <= 1.1e-15 for u >= 0.1
    err = np.abs(stack_symbol(u, [], **BASE) / base_symbol(u) - 1)
    assert err[0] < 5e-14 and err[1:].max() < 5e-15
    s = np.array([0.01, 0.1, 0.5, 1.0, 2.0, 5.0])
    # measured <= 6.7e-16 against core.kernel.plane (itself checked against mpmath)
    assert np.abs(stack_kernel(s, [], **BASE) - plane_kernel(s)).max() < 3e-15


def test_same_material_bonded_layer_thickens_the_base():
    u = np.array([0.1, 0.5, 1.0, 3.0, 20.0])
    layer = [UniformLayer(0.1, 1.0, 0.2, "bonded")]
    # measured <= 6.7e-16
    assert np.allclose(stack_symbol(u, layer, **BASE), base_symbol(1.1 * u), rtol=3e-14,
                       atol=0)


def test_smooth_layer_on_a_rigid_base_is_a_layer_on_a_rigid_bed():
    u = np.array([0.05, 0.3, 1.0, 3.0, 10.0])
    layer = [UniformLayer(0.1, 1.0, 0.3, "smooth")]
    stiff = dict(base_thickness=1.0, base_modulus=1e12, base_poisson=0.2)
    expected = symbol_at_infinity(layer, 1e12, 0.2) * base_symbol(0.1 * u)
    # measured 1.1e-11: the base's own compliance, E_c / E_base = 1e-12, times the span
    assert np.allclose(stack_symbol(u, layer, **stiff), expected, rtol=1e-10, atol=0)


@pytest.mark.parametrize("interface", ["smooth", "bonded"])
def test_short_waves_see_the_top_coating_as_a_half_space(interface):
    layers = [UniformLayer(0.01, 0.3, 0.45, interface), UniformLayer(0.02, 3.0, 0.3)]
    l_inf = symbol_at_infinity(layers, 1.0, 0.2)
    assert l_inf == pytest.approx((1 - 0.45**2) / ((1 - 0.2**2) * 0.3), rel=1e-15)
    # measured 1.1e-16 at u h = 40 and 100
    assert np.allclose(stack_symbol([4000.0, 1e4], layers, **BASE), l_inf, rtol=1e-14)


@pytest.mark.parametrize("modulus", [0.3, 3.0])
def test_thin_smooth_coating_adds_the_winkler_compliance(modulus):
    # L_stack - L = u c E / (2 (1 - nu^2) H) (1 + O(h^2)): measured relative remainders at
    # u = 1: 8.1e-7 (h = 1e-2), 8.1e-9 (1e-3) for E_c = 0.3 E; 8.1e-5, 8.0e-7 for 3 E
    u = np.array([0.5, 1.0])
    remainders = []
    for h in (1e-2, 1e-3):
        layer = [UniformLayer(h, modulus, 0.3, "smooth")]
        winkler = u * float(layer_compliance(h, modulus, 0.3, "smooth")) / (2 * (1 - 0.04))
        remainders.append(np.abs((stack_symbol(u, layer, **BASE) - base_symbol(u))
                                 / winkler - 1).max())
    assert remainders[0] < 2e-4
    assert remainders[1] < remainders[0] / 50  # second order in h


def test_thin_bonded_soft_coating_adds_the_constrained_compliance():
    # as E_c / E -> 0 the base holds the layer laterally: measured 2.1e-5 at E_c = 1e-4 E
    u = np.array([0.5, 1.0])
    layer = [UniformLayer(1e-3, 1e-4, 0.3, "bonded")]
    winkler = u * float(layer_compliance(1e-3, 1e-4, 0.3, "bonded")) / (2 * (1 - 0.04))
    extra = stack_symbol(u, layer, **BASE) - base_symbol(u)
    assert np.allclose(extra, winkler, rtol=1e-4)


def _mp_symbol_one_layer(u, layer, nu_b=0.2):
    """L_stack(u) of one smooth or bonded layer on the base (H = E = 1) in mpmath: the
    displacement / stress formulas of core/kernel/layered.py written out again with
    unscaled exponentials (the working precision absorbs the conditioning)."""
    def face(z, h, nu, mu):
        # columns: f = exp(-kz), g = exp(-kz), f = exp(kz), g = exp(kz); rows U, W, S, T
        # (U, W times 2 mu_b k; f / k^2, g / k as in the module)
        em, ep = mp.exp(-u * z), mp.exp(u * z)
        zz = u * z
        r = 1 / (2 * (1 + nu_b)) / mu
        return [[-r * em, -r * zz * em, -r * ep, -r * zz * ep],
                [-r * em, -r * (zz + 3 - 4 * nu) * em, r * ep, r * (zz - 3 + 4 * nu) * ep],
                [em, (zz + 1 - 2 * nu) * em, -ep, -(zz - 1 + 2 * nu) * ep],
                [em, (zz + 2 * (1 - nu)) * em, ep, (zz - 2 * (1 - nu)) * ep]]
    h = mp.mpf(layer.thickness)
    mu_c = mp.mpf(layer.modulus) / (2 * (1 + mp.mpf(layer.poisson)))
    top, c_bot = face(0, h, layer.poisson, mu_c), face(h, h, layer.poisson, mu_c)
    b_top, b_bot = face(0, 1, nu_b, 1 / (2 * (1 + mp.mpf(nu_b)))), face(1, 1, nu_b,
                                                                      1 / (2 * (1 + mp.mpf(nu_b))))
    a = mp.zeros(8, 8)
    rhs = mp.zeros(8, 1)
    rows = [(top[2], None), (top[3], None)]
    rhs[1] = -1
    if layer.interface == "bonded":
        rows += [(c_bot[q], b_top[q]) for q in range(4)]
    else:
        rows += [(c_bot[1], b_top[1]), (c_bot[3], b_top[3]), (c_bot[2], None),
                 (None, b_top[2])]
    rows += [(None, b_bot[1]), (None, b_bot[2])]
    for i, (upper, lower) in enumerate(rows):
        for j in range(4):
            if upper is not None:
                a[i, j] = upper[j]
            if lower is not None:
                a[i, 4 + j] = -lower[j] if upper is not None else lower[j]
    coef = mp.lu_solve(a, rhs)
    w = sum(top[1][j] * coef[j] for j in range(4))
    return w / (2 * (1 - mp.mpf(nu_b)))


def test_symbol_against_mpmath():
    mp.mp.dps = 40
    for interface in ("smooth", "bonded"):
        layer = UniformLayer(0.2, 0.3, 0.45, interface)
        u = np.array([0.02, 0.3, 1.0, 4.0, 30.0])
        ref = np.array([float(_mp_symbol_one_layer(mp.mpf(x), layer)) for x in u])
        err = np.abs(stack_symbol(u, [layer], **BASE) / ref - 1)
        # measured: 6.7e-15 / 1.2e-14 at u = 0.02 (cancellation ~1e-16 / u^2 below u = 1),
        # <= 2.2e-15 above
        assert err[0] < 1e-12 and err[1:].max() < 1e-14


def mp_kernel_regular(s: float, layer: UniformLayer) -> float:
    """k_stack(s) + L_inf ln s by mpmath's adaptive quadrature of the mpmath symbol
    (about 35 s per s; its values are stored in :data:`MP_KERNEL_REGULAR`)."""
    l_inf = symbol_at_infinity([layer], 1.0, 0.2)
    mp.mp.dps = 25

    def integrand(u):
        # the unscaled system loses ~4 digits per decade of u below 1 and spans exp(+-u)
        # above: more digits at both ends; below u = 1e-8 the value at 1e-8 (r is smooth:
        # changes the integral by ~1e-16)
        u = max(u, mp.mpf("1e-8"))
        with mp.workdps(35 + int(4 * max(0, -mp.log10(u))) + int(0.9 * u)):
            symbol = _mp_symbol_one_layer(u, layer)
        return (symbol + l_inf * mp.expm1(-u)) / u * mp.cos(s * u)

    # r(u) decays like exp(-2 u h), h = 0.2: below 1e-20 beyond u = 160
    ref = mp.quad(integrand, [0, 0.5, 1, 2, 4, 8, 16, 32, 64, 100, 160])
    return float(ref) + 0.5 * l_inf * float(mp.log1p(s * s))


#: ``mp_kernel_regular(s, MP_LAYER)`` at s = 0.05, 0.7, 2.
MP_LAYER = UniformLayer(0.2, 0.3, 0.45, "bonded")
MP_KERNEL_REGULAR = {0.05: -4.636722059964961, 0.7: -0.6434900837980332,
                     2.0: 1.9203368914822456}


def test_kernel_against_mpmath_quadrature():
    s = np.array(list(MP_KERNEL_REGULAR))
    ours = stack_kernel_regular(s, [MP_LAYER], **BASE)
    ref = np.array(list(MP_KERNEL_REGULAR.values()))
    # measured 8.9e-16, 1.3e-15, 0 (the rounding of a sum over ~1,000 Gauss panels;
    # 1.1e-14 at s = 0.05 with the symbol from one linear system per wavenumber)
    assert np.abs(ours - ref).max() < 3e-14


def test_regular_part_table_matches_direct_evaluation():
    layers = [UniformLayer(0.04, 3.0, 0.45, "smooth"), UniformLayer(0.01, 0.1, 0.3, "bonded")]
    table = RegularPartTable(2.0, layers, **BASE)
    s = np.linspace(0, 2, 37) + 0.013
    # measured 1.8e-15 here; 5.0e-14 for a soft (L_inf = 19) bonded layer
    assert np.abs(table(s) - stack_kernel_regular(s, layers, **BASE)).max() < 1e-14


@pytest.mark.slow
def test_flat_punch_converges_and_agrees_with_the_fe_model():
    from core.coating import CoatingStrip, Stack, solve_stack

    layer = UniformLayer(0.04, 0.05, 0.45, "bonded")
    a = flat_punch_stiffness(1.0, [layer], **BASE, modes=32)
    b = flat_punch_stiffness(1.0, [layer], **BASE, modes=64)
    # measured change 32 -> 64 modes: 1.6e-8 / 8.2e-9
    assert a.force_per_settlement == pytest.approx(b.force_per_settlement, rel=1e-7)
    assert a.moment_per_tilt == pytest.approx(b.moment_per_tilt, rel=1e-7)
    strip = CoatingStrip(lambda x: np.full(np.shape(x), 0.04),
                         lambda x: np.full(np.shape(x), 0.05),
                         lambda x: np.full(np.shape(x), 0.45), "bonded")
    fe = solve_stack(Stack(1.0, (strip,), 1.0, 1.0, 0.2), level=0)
    # measured -5.9e-5 / -1.4e-4: FE level 0's own error (1.0e-4 / 2.3e-4 uncoated,
    # core/coating/fem_check.py); the thin-layer model errs by -29 % / -36 % here
    assert b.force_per_settlement / fe.force_parts[1] - 1 == pytest.approx(0, abs=3e-4)
    assert b.moment_per_tilt / fe.moment_parts[2] - 1 == pytest.approx(0, abs=5e-4)


def test_bad_layers_are_refused():
    with pytest.raises(ValueError, match="thickness"):
        UniformLayer(-1.0, 1.0, 0.3)
    with pytest.raises(ValueError, match="poisson"):
        UniformLayer(1.0, 1.0, 0.5)
    with pytest.raises(ValueError, match="interface"):
        UniformLayer(1.0, 1.0, 0.3, "glued")
    with pytest.raises(ValueError, match="modulus"):
        UniformLayer(1.0, float("nan"), 0.3)


def test_results_say_which_coating_model_answered(small_preset):
    from core import solve

    result = solve(small_preset(count=2))
    assert result.info["coating_model"] == "thin layer"


def _system_symbol(u, layers, nu_b=0.2):
    """L_stack(u) (H = E = 1) from one linear system of all the layers' coefficients per
    wavenumber: the boundary and interface conditions written out row by row, with the
    bounded basis of :func:`core.kernel.layered._face` (a second, independent assembly)."""
    from core.kernel.layered import _face

    k = np.asarray(u, dtype=float)
    mu_b = 1 / (2 * (1 + nu_b))
    mats = [(lay.thickness, lay.modulus / (2 * (1 + lay.poisson)), lay.poisson,
             lay.interface) for lay in layers] + [(1.0, mu_b, nu_b, "bed")]
    n = 4 * len(mats)
    system = np.zeros((k.size, n, n))
    rhs = np.zeros((k.size, n))
    one, zero = np.ones_like(k), np.zeros_like(k)
    faces = []
    for h, mu, nu, _ in mats:
        e = np.exp(-k * h)
        faces.append([np.array(f).transpose(2, 0, 1) for f in (
            _face(one, zero, e, -k * h, nu, mu_b / mu), _face(e, k * h, one, zero, nu, mu_b / mu))])
    system[:, 0, 0:4] = faces[0][0][:, 2]
    system[:, 1, 0:4] = faces[0][0][:, 3]
    rhs[:, 1] = -1.0
    row = 2
    for j in range(len(mats) - 1):
        above, below = faces[j][1], faces[j + 1][0]
        ca, cb = slice(4 * j, 4 * j + 4), slice(4 * j + 4, 4 * j + 8)
        continuous = (0, 1, 2, 3) if mats[j][3] == "bonded" else (1, 3)
        for q in continuous:
            system[:, row, ca], system[:, row, cb] = above[:, q], -below[:, q]
            row += 1
        if mats[j][3] != "bonded":  # no shear on either side
            system[:, row, ca], system[:, row + 1, cb] = above[:, 2], below[:, 2]
            row += 2
    system[:, row, n - 4:] = faces[-1][1][:, 1]
    system[:, row + 1, n - 4:] = faces[-1][1][:, 2]
    coef = np.linalg.solve(system, rhs[..., None])[..., 0]
    return np.einsum("ij,ij->i", faces[0][0][:, 1], coef[:, 0:4]) / (2 * (1 - nu_b))


@pytest.mark.parametrize("interfaces", [("smooth", "bonded", "smooth"),
                                        ("bonded", "smooth", "bonded"),
                                        ("bonded", "bonded", "smooth")])
def test_mixed_stack_recursion_against_one_linear_system(interfaces):
    layers = [UniformLayer(0.01, 0.03, 0.45, interfaces[0]),
              UniformLayer(0.02, 3.0, 0.25, interfaces[1]),
              UniformLayer(0.005, 0.5, 0.35, interfaces[2])]
    u = np.geomspace(0.05, 5e3, 40)
    err = np.abs(stack_symbol(u, layers, **BASE) / _system_symbol(u, layers) - 1)
    # measured <= 1.3e-13 below u = 1 (both lose ~1e-16 / u^2 there: the soft top layer
    # makes the system's rows span 1e2), <= 6.2e-15 above
    assert err[u < 1].max() < 4e-13 and err[u >= 1].max() < 2e-14


def test_coarse_table_for_coarser_tolerances():
    from core.kernel import COARSE_PANEL_DEGREE

    layers = [UniformLayer(0.01, 0.005, 0.45, "bonded")]
    table = RegularPartTable(2.0, layers, **BASE, degree=COARSE_PANEL_DEGREE)
    s = np.concatenate([np.geomspace(1e-6, 2.0, 200), np.linspace(0, 2, 201)])
    # measured 1.1e-10 (the soft bonded layer: L_inf = 166, values down to -894)
    assert np.abs(table(s) - stack_kernel_regular(s, layers, **BASE)).max() < 3e-10
