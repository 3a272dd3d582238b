"""The scene suite of the work-precision benchmark (all quantities dimensionless).

Every scene is one instance of the dimensionless problem of ``docs/method.md``:

    c(t) m(x) q + (I - V) F q = delta + alpha x - g(x),   int q = P,   int x q = M,

given by ``lam = a/H``, the coating compliance ``m(x)``, the gap ``g(x)`` (with the points
where either jumps), the output times, the relative modulus ``c(t)``, the creep kernel
and two of the four loads. The parameters are chosen to stress one feature each (see
``Scene.description``); :func:`suite` returns them in the order of the report.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from core.creep.models import Arutyunyan

Function = Callable[[np.ndarray], np.ndarray]
Load = float | Function

#: Arutyunyan creep of a concrete base (the explorer's preset ``eccentric_creep``):
#: E(age) = 3e10 (1 - 0.5 exp(-0.03 age)) Pa,
#: C(t, tau) = (0.9e-11 + 4.8e-10 / tau)(1 - exp(-0.03 (t - tau))) 1/Pa, ages in days.
CONCRETE = Arutyunyan(modulus_final=3.0e10, beta=0.5, alpha=0.03, compliance_final=0.9e-11,
                      aging=4.8e-10, rate=0.03)
#: Age of the base at loading [day]; the dimensionless time is t = age / AGE_AT_LOADING.
AGE_AT_LOADING = 28.0


@dataclass(frozen=True)
class Scene:
    """One benchmark problem (dimensionless) and the resolutions swept on it.

    ``loads`` holds exactly two of settlement, tilt, force, moment. ``n_sweep`` are the
    fixed mode counts of the projection method, ``tol_sweep`` its adaptive tolerances,
    ``colloc_sweep`` the ``(panels_per_unit, edge_width)`` pairs of the collocation method
    and, on a creeping base, ``time_sweep`` the collocation ``time_points``.
    """

    key: str
    title: str
    description: str
    lam: float
    m: Load
    g: Load
    loads: dict[str, Load]
    breakpoints: tuple[float, ...] = ()
    times: np.ndarray = field(default_factory=lambda: np.array([1.0]))
    c: Load = 1.0
    kernel: Any = None
    smooth: bool = False
    n_sweep: tuple[int, ...] = (4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256)
    tol_sweep: tuple[float, ...] = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)
    colloc_sweep: tuple[tuple[float, float], ...] = (
        (1, 1e-1), (2, 1e-2), (4, 1e-3), (8, 1e-4), (16, 1e-5), (24, 1e-6))
    time_sweep: tuple[int, ...] = ()
    #: Collocation reference: (panels_per_unit, edge_width, time_points or None).
    colloc_reference: tuple[float, float, int | None] = (32, 1e-7, None)
    #: Time tolerance of the fixed-n projection runs (tol of solve_dimensionless).
    n_sweep_tol: float = 1e-12

    @property
    def creeping(self) -> bool:
        """Whether the base creeps (a kernel is given)."""
        return self.kernel is not None

    def arguments(self, scale: float = 1.0) -> dict[str, Any]:
        """Keyword arguments common to both solvers; the loads multiplied by ``scale``."""
        loads: dict[str, Load] = {}
        for name, value in self.loads.items():
            if callable(value):
                loads[name] = (lambda t, _f=value, _s=scale: _s * _f(t))
            else:
                loads[name] = scale * float(value)
        return dict(c=self.c, kernel=self.kernel, breakpoints=self.breakpoints, **loads)

    def with_times(self, times: np.ndarray) -> Scene:
        """The same scene at other output times."""
        return replace(self, times=np.asarray(times, dtype=float))


# ------------------------------------------------------------------------ coatings


def smooth_m(x: np.ndarray) -> np.ndarray:
    """A coating whose thickness varies smoothly: m = 0.1 (1 + 0.2 x + 0.3 x^2)."""
    return 0.1 * (1.0 + 0.2 * x + 0.3 * x**2)


def jump_m(x: np.ndarray) -> np.ndarray:
    """Two layers, the upper one three times stiffer on x > 0.3 (a patch): m jumps there.

    ``m = 0.04 (1 + 0.1 x) + (0.06 if x < 0.3 else 0.02)``.
    """
    x = np.asarray(x, dtype=float)
    return 0.04 * (1.0 + 0.1 * x) + np.where(x < 0.3, 0.06, 0.02)


def stepped_g(x: np.ndarray) -> np.ndarray:
    """A stepped punch base: recessed by 0.004 on x < -0.5 and by 0.008 on x > 0.25."""
    x = np.asarray(x, dtype=float)
    return np.where(x < -0.5, 0.004, 0.0) + np.where(x > 0.25, 0.008, 0.0)


def rough_g(x: np.ndarray) -> np.ndarray:
    """A rough punch: g = 0.002 (1 + sin(2 pi 10 x)), 20 wavelengths across [-1, 1]."""
    return 0.002 * (1.0 + np.sin(2.0 * np.pi * 10.0 * np.asarray(x, dtype=float)))


#: The ten coating layers, top first: (thickness h0, its linear and quadratic variation,
#: modulus E0, its cosine amplitude and wave number, Poisson ratio). Thickness
#: h_k(x) = h0 (1 + a x + b x^2), modulus E_k(x) = E0 (1 + e cos(pi w x)); units cancel
#: in the scaling below.
TEN_LAYERS: tuple[tuple[float, float, float, float, float, float, float], ...] = (
    (1.0, 0.10, 0.00, 1.0, 0.20, 1.0, 0.30),
    (0.5, -0.20, 0.10, 3.0, 0.10, 2.0, 0.25),
    (2.0, 0.00, -0.20, 10.0, 0.30, 0.5, 0.35),
    (0.8, 0.30, 0.05, 0.7, -0.20, 1.5, 0.20),
    (1.5, -0.10, 0.20, 5.0, 0.15, 3.0, 0.30),
    (0.3, 0.05, -0.10, 0.4, 0.25, 2.5, 0.40),
    (1.2, 0.20, 0.15, 20.0, -0.10, 1.0, 0.28),
    (0.6, -0.30, 0.00, 2.0, 0.20, 4.0, 0.33),
    (2.5, 0.10, -0.05, 8.0, 0.05, 0.8, 0.22),
    (0.9, 0.00, 0.25, 1.5, -0.30, 1.2, 0.31),
)


def _ten_layer_sum(x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    total = np.zeros(x.shape)
    for h0, a, b, e0, e, w, nu in TEN_LAYERS:
        h = h0 * (1.0 + a * x + b * x**2)
        modulus = e0 * (1.0 + e * np.cos(np.pi * w * x))
        total = total + (1.0 - nu**2) * h / modulus
    return total


_GX, _GW = np.polynomial.legendre.leggauss(64)
#: Scale of the ten-layer sum so that its mean over [-1, 1] is 0.08.
TEN_LAYER_SCALE = 0.08 / (0.5 * float(np.dot(_GW, _ten_layer_sum(_GX))))


def ten_layer_m(x: np.ndarray) -> np.ndarray:
    """m(x) = s sum_k (1 - nu_k^2) h_k(x) / E_k(x) over :data:`TEN_LAYERS` (mean 0.08)."""
    return TEN_LAYER_SCALE * _ten_layer_sum(x)


def tiny_m(x: np.ndarray) -> np.ndarray:
    """Nearly no coating: m = 1e-4."""
    return np.full(np.shape(x), 1e-4)


# ---------------------------------------------------------------------------- loads


def cyclic_force(t: np.ndarray) -> np.ndarray:
    """P(t) = 1 + 0.5 sin(2 pi (t - 1) / 4): a 112-day cycle for loading at 28 days."""
    return 1.0 + 0.5 * np.sin(0.5 * np.pi * (np.asarray(t, dtype=float) - 1.0))


def drifting_eccentricity(t: np.ndarray) -> np.ndarray:
    """e(t) = 0.05 + 0.15 (1 - exp(-(t - 1)/3)): the load drifts off centre."""
    return 0.05 + 0.15 * (1.0 - np.exp(-(np.asarray(t, dtype=float) - 1.0) / 3.0))


def cyclic_moment(t: np.ndarray) -> np.ndarray:
    """M(t) = P(t) e(t)."""
    return cyclic_force(t) * drifting_eccentricity(t)


def creep_times(days: float, count: int) -> np.ndarray:
    """``count`` equally spaced output times from loading to ``days`` after it (t = age/28)."""
    return 1.0 + np.linspace(0.0, days / AGE_AT_LOADING, count)


# ---------------------------------------------------------------------------- suite


def suite() -> list[Scene]:
    """The ten scenes of the report, in order."""
    kernel = CONCRETE.dimensionless_kernel(AGE_AT_LOADING)
    c = CONCRETE.relative_modulus(AGE_AT_LOADING)
    eccentric = {"force": 1.0, "moment": 0.1}
    return [
        Scene("smooth", "Smooth coating, flat punch",
              "lam = 1, m = 0.1 (1 + 0.2 x + 0.3 x^2), g = 0, P = 1, M = 0.1, elastic base",
              1.0, smooth_m, 0.0, eccentric, smooth=True),
        Scene("modulus_jump", "Modulus jump in one layer",
              "lam = 1, m = 0.04 (1 + 0.1 x) + (0.06 for x < 0.3, 0.02 for x > 0.3), "
              "breakpoint 0.3, g = 0, P = 1, M = 0.1, elastic",
              1.0, jump_m, 0.0, eccentric, breakpoints=(0.3,)),
        Scene("stepped_punch", "Stepped punch",
              "lam = 1, m = 0.1 (1 + 0.2 x + 0.3 x^2), g = 0.004 on x < -0.5, 0.008 on "
              "x > 0.25 (breakpoints -0.5, 0.25), P = 1, M = 0.1, elastic",
              1.0, smooth_m, stepped_g, eccentric, breakpoints=(-0.5, 0.25)),
        Scene("rough_punch", "Rough punch",
              "lam = 1, m = 0.1 (1 + 0.2 x + 0.3 x^2), g = 0.002 (1 + sin(20 pi x)), "
              "P = 1, M = 0.1, elastic",
              1.0, smooth_m, rough_g, eccentric),
        Scene("thin_base", "Very thin base (lam = 50)",
              "lam = 50, m = 0.1 (1 + 0.2 x + 0.3 x^2), g = 0, P = 1, M = 0.1, elastic",
              50.0, smooth_m, 0.0, eccentric, smooth=True),
        Scene("thick_base", "Very thick base (lam = 0.05)",
              "lam = 0.05, m = 0.1 (1 + 0.2 x + 0.3 x^2), g = 0, P = 1, M = 0.1, elastic",
              0.05, smooth_m, 0.0, eccentric, smooth=True),
        Scene("no_coating", "Nearly no coating (m = 1e-4)",
              "lam = 1, m = 1e-4, g = 0, P = 1, M = 0.1, elastic (square-root edge "
              "singularities smoothed over ~1e-4)",
              1.0, tiny_m, 0.0, eccentric),
        Scene("ten_layers", "Ten layers",
              "lam = 1, m = s sum_k (1 - nu_k^2) h_k(x)/E_k(x) over ten layers "
              "(tests/support/scenes.py: TEN_LAYERS; mean m = 0.08), g = 0, P = 1, M = 0.1, "
              "elastic",
              1.0, ten_layer_m, 0.0, eccentric, smooth=True),
        Scene("aging_creep", "Aging creep, 1000 days, 500 output times",
              "lam = 1, m = 0.1 (1 + 0.2 x + 0.3 x^2), g = 0, P = 1, M = 0.1; Arutyunyan "
              "base (E_inf 3e10 Pa, beta 0.5, alpha 0.03/day, C_inf 0.9e-11/Pa, A 4.8e-10 "
              "day/Pa, gamma 0.03/day) loaded at 28 days; 500 equally spaced outputs over "
              "1000 days (t = 1 ... 36.7)",
              1.0, smooth_m, 0.0, eccentric, times=creep_times(1000.0, 500), c=c,
              kernel=kernel, smooth=True, time_sweep=(499, 998, 1996),
              colloc_sweep=((2, 1e-2), (4, 1e-3), (8, 1e-4)),
              colloc_reference=(8, 1e-5, 1996), n_sweep_tol=1e-10,
              n_sweep=(4, 8, 16, 32, 64, 128, 256),
              tol_sweep=(1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)),
        Scene("eccentric_history", "Time-varying eccentric load with creep",
              "lam = 1, m = 0.1 (1 + 0.2 x + 0.3 x^2), g = 0, same base as aging_creep; "
              "P(t) = 1 + 0.5 sin(pi (t - 1)/2) (112-day cycle), M(t) = P(t) e(t), "
              "e(t) = 0.05 + 0.15 (1 - exp(-(t - 1)/3)); 200 outputs over 365 days",
              1.0, smooth_m, 0.0, {"force": cyclic_force, "moment": cyclic_moment},
              times=creep_times(365.0, 200), c=c, kernel=kernel, smooth=True,
              time_sweep=(199, 398, 796), colloc_sweep=((2, 1e-2), (4, 1e-3), (8, 1e-4)),
              colloc_reference=(8, 1e-5, 796), n_sweep_tol=1e-10,
              n_sweep=(4, 8, 16, 32, 64, 128, 256),
              tol_sweep=(1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)),
    ]
