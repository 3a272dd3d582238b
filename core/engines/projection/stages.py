"""Validation and the cached spatial stages of the projection engine.

Panels, operator, basis, Galerkin rows, gap terms and modes (see the stage table of
:mod:`core.engines.projection.solve`), each cached in :mod:`core.engines.projection.caches`
on exactly its inputs.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from core.cache import StageCache, fingerprint
from core.discretize import (
    DENSE_SAMPLES,
    Basis,
    KernelOperator,
    Panels,
    base_panels,
    build_basis,
    galerkin_correction,
    graded_cuts,
    kernel_operator,
    operator_rows,
    refine_to_resolve,
)
from core.engines.projection.caches import (
    _BASIS,
    _CORRECTION,
    _GALERKIN,
    _GAP,
    _MODES,
    _OPERATOR,
    _PANELS,
    _SAMPLE_ROWS,
)
from core.engines.projection.matrices import GapTerms, galerkin_matrix, gap_terms
from core.problem import (
    Geometry,
    ModalSystem,
    TimeInputs,
    check_values,
    modal_system,
    validate_geometry,
    validate_time_inputs,
)

# ---------------------------------------------------------------------- validation


@dataclass(frozen=True)
class _Inputs:
    lam: float
    m: Callable[[np.ndarray], np.ndarray]
    g: Callable[[np.ndarray], np.ndarray]
    g_is_zero: bool
    times: np.ndarray
    c: Callable[[np.ndarray], np.ndarray]
    c_is_constant: bool
    kernel: Any
    loads: dict[str, Callable[[np.ndarray], np.ndarray]]
    given: frozenset[str]
    breakpoints: tuple[float, ...]
    tol: float
    #: times where a given history jumps or kinks (the time steps land on them)
    time_breaks: tuple[float, ...] = ()


def validate_inputs(lam, m, g, times, c, kernel, loads, breakpoints, tol) -> _Inputs:
    """The inputs of the dimensionless problem checked (as ``solve_dimensionless`` checks
    them) and joined in the form the projection's stages take."""
    return joined_inputs(validate_geometry(lam, m, g, breakpoints, tol),
                         validate_time_inputs(times, c, kernel, loads))


def joined_inputs(geometry: Geometry, timing: TimeInputs,
                  time_breaks: Sequence[float] = ()) -> _Inputs:
    """A validated geometry and time side in the form the projection's stages take;
    ``time_breaks``: the times of (1, last output time) where a given history jumps or
    kinks."""
    end = float(timing.times[-1])
    breaks = tuple(sorted({float(b) for b in np.asarray(time_breaks, dtype=float).ravel()
                           if np.isfinite(b) and 1.0 < b < end}))
    return _Inputs(geometry.lam, geometry.m, geometry.g, geometry.g_is_zero, timing.times,
                   timing.c, timing.c_is_constant, timing.kernel, timing.loads, timing.given,
                   geometry.breakpoints, geometry.tol, breaks)


# -------------------------------------------------------------------------- stages


@dataclass(frozen=True)
class _Discretization:
    """Panels, operator, basis and the Galerkin data, with their cache keys."""

    panels: Panels
    operator: KernelOperator
    basis: Basis
    m_nodes: np.ndarray
    r_matrix: np.ndarray
    gap: GapTerms
    sample_x: np.ndarray
    sample_phi: np.ndarray
    sample_m: np.ndarray
    sample_g: np.ndarray
    galerkin_key: str
    resolved: bool
    cuts: tuple[float, ...]
    check_x: np.ndarray
    check_phi: np.ndarray
    sample_rows: np.ndarray  # F at the sample points (for the residual check)


def _max_width(lam: float, cap: int) -> float:
    # 16 Gauss nodes per panel resolve the degree-``cap`` polynomials when a panel spans at
    # most ~16/cap of [-1, 1]; 3/lam resolves the kernel's smooth part (module quadrature).
    return min(0.25, 3.0 / lam, 16.0 / cap)


def _discretize(inp: _Inputs, cap: int, kind: str, stages: dict[str, dict]) -> _Discretization:
    def timed(name: str, cache: StageCache, key, compute):
        t0 = _time.perf_counter()
        value, hit = cache.get_or_compute(key, compute)
        entry = stages.setdefault(name, {"seconds": 0.0, "cached": True})
        entry["seconds"] += _time.perf_counter() - t0
        entry["cached"] = entry["cached"] and hit
        return value

    if kind == "graded":
        # Element ends of the hp-graded basis; its degree <= 15 per element is integrated
        # exactly on any panels, so they only break at the elements (and 3/lam).
        cuts = graded_cuts(inp.breakpoints, inp.lam, inp.m)
        width = min(0.5, 3.0 / inp.lam)
        start = base_panels(inp.lam, inp.breakpoints, max_width=width, edge_width=None,
                            soft_cuts=cuts)
    else:
        cuts = ()
        width = _max_width(inp.lam, cap)
        start = base_panels(inp.lam, inp.breakpoints, max_width=width)
    # (the panels resolve m and g on the even sample too: keyed on it, two m that differ
    # between the start's nodes alone would share panels)
    probe = np.concatenate([start.nodes, np.linspace(-1.0, 1.0, DENSE_SAMPLES)])
    m_probe = inp.m(probe)
    g_probe = inp.g(probe)
    panel_key = fingerprint("panels", inp.lam, inp.breakpoints, width, cuts, m_probe, g_probe)

    def make_panels():
        functions = [inp.m] if inp.g_is_zero else [inp.m, inp.g]
        return refine_to_resolve(start, functions)

    panels, resolved = timed("panels", _PANELS, panel_key, make_panels)
    op_key = fingerprint("operator", inp.lam, panels.edges)
    operator = timed("operator", _OPERATOR, op_key, lambda: kernel_operator(inp.lam, panels))
    m_nodes = inp.m(panels.nodes)
    check_values(m_nodes, "m", panels.nodes, "x", positive=True)
    count = cap if kind == "graded" else min(cap, panels.size // 2)
    if kind == "graded":
        # Panels added to resolve m or g (a rough punch, a wavy coating) become elements
        # too: the remainder of m q oscillates with g/m, and elements of degree <= 15 as
        # wide as the graded mesh's middle cannot follow twenty wavelengths.
        # Only panels of some size: refinement that chases an end-point singularity of an
        # undeclared kind (bisecting toward +-1 or a jump) must not litter the mesh.
        widths = np.diff(panels.edges)
        wide = np.minimum(widths[:-1], widths[1:]) >= 1e-2
        added = np.setdiff1d(panels.edges[1:-1][wide], start.edges)
        cuts = tuple(sorted(set(cuts) | set(added.tolist())))
    # The basis is orthonormal for the weight 1/m: for m = s m1 it is sqrt(s) times the
    # basis for m1. Built for m / max(m), it serves every uniform coating (and every
    # coating scaled as a whole), so a thickness or modulus slider of such a coating
    # reuses it.
    m_scale = float(np.max(m_nodes))
    m_unit = m_nodes / m_scale
    unit_key = fingerprint("basis", panels.edges, m_unit, inp.breakpoints, kind, cuts, count)

    def make_basis():
        basis = build_basis(panels, m_unit, count, breakpoints=inp.breakpoints, kind=kind,
                            cuts=cuts)
        xs = _sample_points(inp.breakpoints, cuts)
        xc = _check_points(inp.breakpoints)
        return basis, xs, basis.evaluate(xs), xc, basis.evaluate(xc)

    unit, sample_x, unit_sample_phi, check_x, unit_check_phi = timed("basis", _BASIS,
                                                                     unit_key, make_basis)
    root = np.sqrt(m_scale)
    basis = replace(unit, values=unit.values * root, transform=unit.transform * root,
                    moments=tuple(j / m_scale for j in unit.moments))
    sample_phi, check_phi = unit_sample_phi * root, unit_check_phi * root
    basis_key = fingerprint(unit_key, m_scale)
    correction = None
    if kind == "graded":
        correction = timed("correction", _CORRECTION, fingerprint("correction", panels.edges),
                           lambda: galerkin_correction(panels))
    sample_rows = timed("sample_rows", _SAMPLE_ROWS, fingerprint("rows", op_key, sample_x),
                        lambda: operator_rows(inp.lam, panels, sample_x))
    gal_key = fingerprint("galerkin", op_key, basis_key)
    r_matrix = timed("galerkin", _GALERKIN, gal_key,
                     lambda: galerkin_matrix(operator, basis, m_nodes, correction))
    g_nodes = inp.g(panels.nodes)
    check_values(g_nodes, "g", panels.nodes, "x")
    if inp.g_is_zero:
        gap = GapTerms(np.zeros(basis.size), 0.0, 0.0)
    else:
        gap_key = fingerprint("gap", op_key, basis_key, g_nodes)
        gap = timed("gap", _GAP, gap_key,
                    lambda: gap_terms(operator, basis, m_nodes, g_nodes, correction))
    return _Discretization(panels, operator, basis, m_nodes, r_matrix, gap, sample_x,
                           sample_phi, inp.m(sample_x), inp.g(sample_x), gal_key, resolved,
                           tuple(cuts), check_x, check_phi, sample_rows)


def _check_points(breakpoints: Sequence[float]) -> np.ndarray:
    """Points where q >= 0 is checked: Chebyshev points of [-1, 1] and both sides of jumps."""
    bps = np.asarray(breakpoints, dtype=float)
    return np.concatenate([np.cos(np.linspace(0, np.pi, 401)), bps - 1e-9, bps + 1e-9])


def _sample_points(breakpoints: Sequence[float], cuts: Sequence[float] = ()) -> np.ndarray:
    """Points where the pressure error is measured: the whole of [-1, 1].

    Chebyshev points of the interior, the basis' element ends (``cuts``: where its pieces
    meet, the pointwise error peaks; a rough punch's q was 3.2e-5 off at x = 0.125 while
    the Chebyshev points saw 6e-6) and, toward each edge and each side of every jump,
    points at distances 1e-8 to 0.05 (geometric) and the edges themselves: there ``m q``
    is least smooth (``(x - x_e) ln|x - x_e|`` and a layer of width ~``m``), so there the
    basis converges last.
    """
    xs = np.cos(np.pi * (np.arange(96) + 0.5) / 96) * 0.95
    bps = np.asarray(breakpoints, dtype=float)
    for b in bps:
        xs = xs[np.abs(xs - b) > 0.02]
    near = np.geomspace(1e-8, 0.05, 12)
    ends = [-1.0 + near, 1.0 - near, np.array([-1.0, 1.0]), np.asarray(cuts, dtype=float)]
    ends += [b + s * near for b in bps for s in (-1.0, 1.0)]
    xs = np.unique(np.clip(np.concatenate([xs, *ends]), -1.0, 1.0))
    # On a jump itself q has no value (each side has its own): never sample there.
    return xs[np.all(np.abs(xs[:, None] - bps[None, :]) > 1e-12, axis=1)] if bps.size else xs


def _modes(disc: _Discretization, given: frozenset[str], n: int,
           stages: dict[str, dict]) -> ModalSystem:
    key = (disc.galerkin_key, tuple(sorted(given)), n)
    t0 = _time.perf_counter()
    value, hit = _MODES.get_or_compute(
        key, lambda: modal_system(disc.r_matrix, disc.basis.moments, given, n))
    entry = stages.setdefault("modes", {"seconds": 0.0, "cached": True})
    entry["seconds"] += _time.perf_counter() - t0
    entry["cached"] = entry["cached"] and hit
    return value
