"""``solve_dimensionless``: the projection method as a pipeline of cached, pure stages.

The dimensionless problem (model notes; the seed's (9)-(12)):

    c(t) m(x) q(x,t) + (I - V) F q = delta(t) + alpha(t) x - g(x),   -1 <= x <= 1,  t >= 1,
    int q dx = P(t),   int x q dx = M(t).

With ``m q = -g/c + sum_j a_j(t) p_j(x)`` (the rough part ``g/(c m)`` carried exactly, the
``p_j`` orthonormal for the weight ``1/m``) the Galerkin rows decouple into one scalar
Volterra equation per mode (:mod:`core.statements`, :mod:`core.time_integration`).

Stages and what each depends on (each cached on exactly these inputs, :mod:`core.cache`):

============  ===============================================  ==============================
stage         inputs                                           result
============  ===============================================  ==============================
panels        lam, breakpoints, samples of m and g, basis cap  quadrature panels
operator      lam, panels                                      discrete operator F (N x N)
basis         panels, m at the nodes, breakpoints, kind, cap   orthonormal functions p_j
galerkin      operator, basis                                  R_ij
gap           operator, basis, g at the nodes                  G_i, int g/m, int x g/m
modes         galerkin, statement, n                           eigenpairs of the free block
time          modes, c, K, the loads, times                    a_j(t) and the four scalars
============  ===============================================  ==============================

A change of the loads only re-runs the last stage; an elastic base skips time stepping.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from core.basis import Basis, build_basis, graded_cuts
from core.cache import StageCache, fingerprint
from core.inputs import (
    check_values,
    validate_geometry,
    validate_time_inputs,
)
from core.projection import GapTerms, galerkin_matrix, gap_terms
from core.quadrature import (
    KernelOperator,
    Panels,
    base_panels,
    galerkin_correction,
    kernel_operator,
    operator_rows,
    refine_to_resolve,
)
from core.statements import QUANTITIES, ModalSystem, modal_system, statement_number
from core.time_integration import ModalProblem, solve_degenerate, solve_general

Scalar = float | Callable[[np.ndarray], np.ndarray]

#: Mode counts tried in turn; the error estimate compares consecutive levels.
MODE_LEVELS = (4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256)
#: Basis sizes built (a larger one only when a smaller one could not meet tol).
BASIS_CAPS = (128, 256)
#: Below this tol the first basis built is the largest (measured: the graded basis needs
#: 128-256 functions for 1e-8 on q, so a first try at 128 would be wasted work).
DIRECT_LARGEST_BELOW = 1e-7
#: Quadrature and round-off floor of the relative error (measured: ~1e-13 on the scenes
#: of the test suite; see tests/test_solver.py).
ERROR_FLOOR = 2e-13
#: Success is claimed only when the error estimate is this many times below tol: the
#: estimate itself can read ~3x low (see _extrapolated_error).
SUCCESS_MARGIN = 3.0
# Bytes per stage sum to STAGE_CACHE_BYTES (512 MiB), sized from the largest items
# measured on the hard cases of benchmarks/scenes.py: operator and correction ~9 MiB,
# basis ~8 MiB, all modes of a scene ~3 MiB, responses ~5 MiB.
_MiB = 2**20
_PANELS = StageCache("panels", max_items=32, max_bytes=8 * _MiB)
_OPERATOR = StageCache("operator", max_items=8, max_bytes=128 * _MiB)
_BASIS = StageCache("basis", max_items=16, max_bytes=64 * _MiB)
_GALERKIN = StageCache("galerkin", max_items=32, max_bytes=32 * _MiB)
_CORRECTION = StageCache("correction", max_items=8, max_bytes=128 * _MiB)
_GAP = StageCache("gap", max_items=32, max_bytes=8 * _MiB)
_MODES = StageCache("modes", max_items=256, max_bytes=64 * _MiB)
_RESPONSE = StageCache("response", max_items=256, max_bytes=64 * _MiB)
_SAMPLE_ROWS = StageCache("sample_rows", max_items=16, max_bytes=16 * _MiB)
_STAGES = (_PANELS, _OPERATOR, _BASIS, _GALERKIN, _CORRECTION, _GAP, _MODES, _RESPONSE,
           _SAMPLE_ROWS)
_DEFAULT_STAGE_BYTES = {cache.name: cache.max_bytes for cache in _STAGES}
#: Upper bound of the memory all stage caches of the solver may hold together [bytes].
STAGE_CACHE_BYTES = 512 * _MiB


def set_stage_cache_budget(total_bytes: int) -> None:
    """Bound the solver's stage caches together by ``total_bytes`` [bytes].

    The budget is shared among the stages in their default proportions (the default
    total is :data:`STAGE_CACHE_BYTES`). A process among several that solve (the
    explorer's worker processes) takes its share of the machine's budget this way. Items
    beyond a smaller bound are dropped at the next store.
    """
    if isinstance(total_bytes, bool) or not (isinstance(total_bytes, int) and total_bytes > 0):
        raise ValueError(f"total_bytes: must be a positive integer, got {total_bytes!r}")
    default_total = sum(_DEFAULT_STAGE_BYTES.values())
    from core.prepared import PREPARED, PREPARED_BYTES

    # The default engine's prepared geometries take their share in the same proportion.
    PREPARED.max_bytes = max(1, PREPARED_BYTES * total_bytes // default_total)
    for cache in _STAGES:
        cache.max_bytes = max(1, _DEFAULT_STAGE_BYTES[cache.name] * total_bytes
                              // default_total)


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class ContactSolution:
    """The answer of :func:`solve_dimensionless` (all quantities dimensionless).

    ``times`` (T,), ``settlement`` (delta), ``tilt`` (alpha), ``force`` (P), ``moment`` (M)
    as arrays over ``times``; ``pressure(x)`` gives q at points of [-1, 1] (shape
    ``(len(x), T)``); ``info`` holds ``error_estimate`` (relative, see the module notes),
    ``seconds``, ``flags``, ``message``, ``success``, ``n_modes``, ``n_steps``, ``stages``,
    ``contact`` (``"full"``). ``contact_set`` holds, per time, the intervals of x where
    q > 0: ``[(-1.0, 1.0)]`` (full contact is assumed).
    """

    times: np.ndarray
    settlement: np.ndarray
    tilt: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    info: dict[str, Any]
    _basis: Basis = field(repr=False)
    _coefficients: np.ndarray = field(repr=False)  # a_j(t), shape (n, T)
    _c: np.ndarray = field(repr=False)  # c(t) at the times
    _m: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    _g: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    #: q(x) at points x, shape (len(x), T), for engines without a basis (Nystrom).
    _evaluate: Callable[[np.ndarray], np.ndarray] | None = field(default=None, repr=False)
    contact_set: list[list[tuple[float, float]]] = field(default_factory=list)

    @property
    def success(self) -> bool:
        """Whether the error estimate meets the requested tolerance."""
        return bool(self.info["success"])

    @property
    def message(self) -> str:
        """A one-line account of how the solve went."""
        return str(self.info["message"])

    @property
    def flags(self) -> list[str]:
        """Validity flags (``contact_lost``, ``tol_not_met``, ``unresolved_input``)."""
        return list(self.info["flags"])

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """Contact pressure q(x, t) at points ``x`` of [-1, 1], shape ``(len(x), len(times))``.

        ``q = (-g(x)/c(t) + sum_j a_j(t) p_j(x)) / m(x)`` (dimensionless, the seed's (18)).
        """
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if np.any(~np.isfinite(x)) or np.any(np.abs(x) > 1.0):
            raise ValueError("x: pressure is defined on [-1, 1] only")
        if self._evaluate is not None:
            return self._evaluate(x)
        phi = self._basis.evaluate(x, self._coefficients.shape[0])
        mq = phi @ self._coefficients - np.outer(self._g(x), 1.0 / self._c)
        return mq / self._m(x)[:, None]


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


def _validate(lam, m, g, times, c, kernel, loads, breakpoints, tol) -> _Inputs:
    geometry = validate_geometry(lam, m, g, breakpoints, tol)
    timing = validate_time_inputs(times, c, kernel, loads)
    return _Inputs(geometry.lam, geometry.m, geometry.g, geometry.g_is_zero, timing.times,
                   timing.c, timing.c_is_constant, timing.kernel, timing.loads, timing.given,
                   geometry.breakpoints, geometry.tol)


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
    m_probe = inp.m(start.nodes)
    g_probe = inp.g(start.nodes)
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
        xs = _sample_points(inp.breakpoints)
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


def _sample_points(breakpoints: Sequence[float]) -> np.ndarray:
    """Interior points where the pressure error is measured (|x| <= 0.95, off the jumps)."""
    xs = np.cos(np.pi * (np.arange(96) + 0.5) / 96) * 0.95
    for b in breakpoints:
        xs = xs[np.abs(xs - b) > 0.02]
    return np.sort(xs)


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


# ---------------------------------------------------------------------- time stage


@dataclass(frozen=True)
class _LevelResult:
    n: int
    coefficients: np.ndarray  # (n, T)
    settlement: np.ndarray
    tilt: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    time_error: float
    steps: int
    time_message: str
    time_success: bool


class _LevelSetup:
    """The time-dependent pieces of one mode count's modal system.

    Free rows, per mode: ``(c + gamma) z - gamma V z = s(t) - (I - V) u(t)`` with
    ``s = Psi^T (delta e0_F + alpha e1_F)`` (the given ones) and
    ``u = Psi^T (R_FK b_K - G_F / c) = coupling @ [b_K; 1/c]`` (the known channels).
    """

    def __init__(self, inp: _Inputs, disc: _Discretization, ms: ModalSystem) -> None:
        self.inp, self.disc, self.ms = inp, disc, ms
        n = ms.n
        self.gap_vec = ms.rotate(disc.gap.vector[:n])
        self.k = len(ms.known)
        self.constraint_inv = np.linalg.inv(ms.constraint) if self.k else np.zeros((0, 0))
        r_fk = ms.r_rot[np.ix_(ms.free, ms.known)]
        self.coupling = np.concatenate(
            [ms.psi.T @ r_fk, -(ms.psi.T @ self.gap_vec[ms.free])[:, None]], axis=1)

    def known_channels(self, tt: np.ndarray, inv_c: np.ndarray,
                       loads: dict[str, np.ndarray]) -> np.ndarray:
        """``[b_K(t); 1/c(t)]``: b_K from the given force and moment, shape (k + 1, T)."""
        shift = {"force": self.disc.gap.integral, "moment": self.disc.gap.first_moment}
        rows = [self.constraint_inv @ np.array([loads[name] + shift[name] * inv_c
                                                for name in self.ms.constraint_names])
                ] if self.k else []
        return np.concatenate(rows + [inv_c[None, :]], axis=0)

    def given_drive(self, rows: np.ndarray, loads: dict[str, np.ndarray],
                    size: int) -> np.ndarray:
        """``delta e0 + alpha e1`` (the given ones) restricted to ``rows``."""
        out = np.zeros((len(rows), size))
        if "settlement" in loads:
            out += np.outer(self.ms.e0_rot[rows], loads["settlement"])
        if "tilt" in loads:
            out += np.outer(self.ms.e1_rot[rows], loads["tilt"])
        return out

    def drive(self, loads: dict[str, np.ndarray], size: int) -> np.ndarray:
        return self.ms.psi.T @ self.given_drive(self.ms.free, loads, size)

    def finish(self, times: np.ndarray, c_t: np.ndarray, loads: dict[str, np.ndarray],
               u_known: np.ndarray, z: np.ndarray, vz: np.ndarray, vu: np.ndarray,
               time_error: float, steps: int, message: str, ok: bool) -> _LevelResult:
        """Coefficients and the four scalars from the modal coordinates."""
        ms, k = self.ms, self.k
        n = ms.n
        b = np.zeros((n, times.size))
        b[ms.free] = ms.psi @ z
        b_known = u_known[:k]
        b[ms.known] = b_known
        a = ms.to_coefficients(b)
        out: dict[str, np.ndarray | None] = {name: loads.get(name) for name in QUANTITIES}
        inv_c = 1.0 / c_t
        if k:
            # Known rows: c b_K + (I - V)[R_KF b_F + R_KK b_K - G_K/c] = delta e0_K + alpha e1_K
            r_kf = ms.r_rot[np.ix_(ms.known, ms.free)]
            r_kk = ms.r_rot[np.ix_(ms.known, ms.known)]
            lhs = (c_t[None, :] * b_known
                   + r_kf @ (ms.psi @ (z - vz))
                   + r_kk @ (b_known - vu[:k])
                   - np.outer(self.gap_vec[ms.known], inv_c) + np.outer(
                       self.gap_vec[ms.known], vu[k])
                   - self.given_drive(ms.known, loads, times.size))
            unknowns = np.linalg.solve(ms.unknown_rhs, lhs)
            for i, name in enumerate(ms.unknown_names):
                out[name] = unknowns[i]
        j0, j1, j2 = self.disc.basis.moments
        e0 = np.zeros(n)
        e1 = np.zeros(n)
        e0[0] = np.sqrt(j0)
        e1[0] = j1 / np.sqrt(j0)
        if n > 1:
            e1[1] = np.sqrt((j0 * j2 - j1 * j1) / j0)
        if out["force"] is None:
            out["force"] = e0 @ a - self.disc.gap.integral * inv_c
        if out["moment"] is None:
            out["moment"] = e1 @ a - self.disc.gap.first_moment * inv_c
        return _LevelResult(n, a, *(np.asarray(out[q], dtype=float) for q in QUANTITIES),
                            time_error, steps, message, ok)


def _solve_levels(inp: _Inputs, disc: _Discretization, systems: Sequence[ModalSystem],
                  times: np.ndarray, *, time_tol: float) -> list[_LevelResult]:
    """Solve the modal systems of several mode counts at ``times`` in one time integration.

    The modes of all levels are independent scalar equations driven by the same known
    channels, so they are stacked and stepped together.
    """
    setups = [_LevelSetup(inp, disc, ms) for ms in systems]
    c_t = inp.c(times)
    loads = {name: fn(times) for name, fn in inp.loads.items()}
    u_known = setups[0].known_channels(times, 1.0 / c_t, loads)
    if inp.kernel is None:
        results = []
        for st in setups:
            z = (st.drive(loads, times.size) - st.coupling @ u_known) / (
                c_t[None, :] + st.ms.gamma[:, None])
            results.append(st.finish(times, c_t, loads, u_known, z, np.zeros_like(z),
                                     np.zeros_like(u_known), 0.0, 0,
                                     "elastic base: no time stepping", True))
        return results
    gamma = np.concatenate([st.ms.gamma for st in setups])
    coupling = np.concatenate([st.coupling for st in setups], axis=0)
    memo: dict[bytes, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def evaluate(tt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        # d, r and u are asked for at the same stage times: evaluate the loads once.
        key = tt.tobytes()
        if key not in memo:
            memo.clear()
            c_s = inp.c(tt)
            ld = {name: fn(tt) for name, fn in inp.loads.items()}
            u = setups[0].known_channels(tt, 1.0 / c_s, ld)
            drive = np.concatenate([st.drive(ld, tt.size) for st in setups], axis=0)
            d = 1.0 + c_s[None, :] / gamma[:, None]
            memo[key] = (d, (drive - coupling @ u) / gamma[:, None], u)
        return memo[key]

    problem = ModalProblem(d=lambda tt: evaluate(tt)[0], r=lambda tt: evaluate(tt)[1],
                           u=lambda tt: evaluate(tt)[2], coupling=coupling / gamma[:, None])
    if hasattr(inp.kernel, "rates") and hasattr(inp.kernel, "exponential_parts"):
        sol = solve_degenerate(inp.kernel, problem, times, tol=time_tol)
    else:
        sol = solve_general(inp.kernel, problem, times, tol=time_tol)
    results = []
    start = 0
    for st in setups:
        stop = start + st.ms.gamma.size
        results.append(st.finish(times, c_t, loads, u_known, sol.w[start:stop],
                                 sol.vw[start:stop], sol.vu, sol.error_estimate, sol.steps,
                                 sol.message, sol.success))
        start = stop
    return results


def _zero(tt: np.ndarray) -> np.ndarray:
    return np.zeros(np.shape(tt))


def _combine(parts: Sequence[tuple[float, _LevelResult]]) -> _LevelResult:
    """``sum_i w_i R_i`` of level results of one mode count (the problem is linear)."""
    first = parts[0][1]

    def total(attr: str) -> np.ndarray:
        return sum(w * getattr(r, attr) for w, r in parts)

    # Each part's time error is relative to its own size; weigh it back to absolute.
    absolute = sum(abs(w) * r.time_error * max(np.max(np.abs(r.settlement)),
                                               np.max(np.abs(r.force)), 1e-300)
                   for w, r in parts)
    combined = _LevelResult(first.n, total("coefficients"), total("settlement"),
                            total("tilt"), total("force"), total("moment"), 0.0,
                            max(r.steps for _, r in parts),
                            "; ".join(sorted({r.time_message for _, r in parts
                                              if not r.time_success})) or first.time_message,
                            all(r.time_success for _, r in parts))
    size = max(np.max(np.abs(combined.settlement)), np.max(np.abs(combined.force)), 1e-300)
    return replace(combined, time_error=float(absolute / size))


class _Superposition:
    """The time stage by superposition: one cached response per given load and the gap.

    The answer is linear in the loads and the gap, so it is the sum of the responses to
    each given load alone (normalized to unit peak) and to the gap alone. Each response
    is cached on the modes, the times, c, K and the load's *shape*, so moving a load
    slider (a change of amplitude) costs a few array operations. Everything that does not
    depend on the mode count is prepared once per solve.
    """

    def __init__(self, inp: _Inputs, disc: _Discretization, times: np.ndarray,
                 time_tol: float) -> None:
        self.disc, self.times, self.time_tol = disc, times, time_tol
        kernel_key = None if inp.kernel is None else getattr(inp.kernel, "key", None)
        self.cacheable = inp.kernel is None or kernel_key is not None
        probe = np.unique(np.concatenate([np.linspace(1.0, times[-1], 129), times]))
        self.base_key = (disc.galerkin_key, tuple(sorted(inp.given)),
                         fingerprint(times, inp.c(probe), repr(kernel_key), time_tol))
        self.no_gap = replace(disc, gap=GapTerms(np.zeros_like(disc.gap.vector), 0.0, 0.0))
        # (weight, key, inputs, discretization) of each part
        self.parts: list[tuple[float, tuple, _Inputs, _Discretization]] = []
        for name, fn in sorted(inp.loads.items()):
            values = fn(probe)
            amplitude = float(values[np.argmax(np.abs(values))])
            if amplitude == 0.0:
                continue
            unit = replace(inp, loads={k: ((lambda tt, f=fn, a=amplitude: f(tt) / a)
                                           if k == name else _zero) for k in inp.loads})
            self.parts.append((amplitude, (name, fingerprint(values / amplitude)), unit,
                               self.no_gap))
        gap = disc.gap
        if not inp.g_is_zero and (np.any(gap.vector != 0) or gap.integral != 0
                                  or gap.first_moment != 0):
            gap_only = replace(inp, loads={k: _zero for k in inp.loads})
            key = ("gap", fingerprint(gap.vector, gap.integral, gap.first_moment))
            self.parts.append((1.0, key, gap_only, disc))
        self.zero_inputs = replace(inp, loads={k: _zero for k in inp.loads})

    def solve(self, systems: Sequence[ModalSystem]) -> tuple[list[_LevelResult], bool]:
        """Results for each modal system, and whether every response came from the cache."""
        if not self.parts:  # every load is zero and there is no gap: the answer is zero
            return _solve_levels(self.zero_inputs, self.no_gap, systems, self.times,
                                 time_tol=self.time_tol), False
        sizes = tuple(ms.n for ms in systems)
        responses = []
        all_hit = True
        for weight, part_key, inputs, disc in self.parts:
            def compute(inputs=inputs, disc=disc):
                return _solve_levels(inputs, disc, systems, self.times, time_tol=self.time_tol)

            if self.cacheable:
                response, hit = _RESPONSE.get_or_compute((self.base_key, sizes, part_key),
                                                         compute)
            else:
                response, hit = compute(), False
            all_hit = all_hit and hit
            responses.append((weight, response))
        if len(responses) == 1 and responses[0][0] == 1.0:
            return list(responses[0][1]), all_hit
        return [_combine([(w, r[i]) for w, r in responses]) for i in range(len(systems))], \
            all_hit


def _scales(res: _LevelResult, disc: _Discretization, c_t: np.ndarray):
    q = (disc.sample_phi[:, : res.n] @ res.coefficients
         - np.outer(disc.sample_g, 1.0 / c_t)) / disc.sample_m[:, None]
    kin = max(np.max(np.abs(res.settlement)), np.max(np.abs(res.tilt)), 1e-300)
    dyn = max(np.max(np.abs(res.force)), np.max(np.abs(res.moment)), 1e-300)
    return kin, dyn, max(np.max(np.abs(q)), 1e-300)


def _difference(a: _LevelResult, b: _LevelResult, disc: _Discretization,
                c_t: np.ndarray) -> float:
    """Largest normalized difference between two levels (quantities over all times)."""
    kin, dyn, qs = _scales(b, disc, c_t)
    qa = (disc.sample_phi[:, : a.n] @ a.coefficients
          - np.outer(disc.sample_g, 1.0 / c_t)) / disc.sample_m[:, None]
    qb = (disc.sample_phi[:, : b.n] @ b.coefficients
          - np.outer(disc.sample_g, 1.0 / c_t)) / disc.sample_m[:, None]
    parts = [np.max(np.abs(a.settlement - b.settlement)) / kin,
             np.max(np.abs(a.tilt - b.tilt)) / kin,
             np.max(np.abs(a.force - b.force)) / dyn,
             np.max(np.abs(a.moment - b.moment)) / dyn,
             np.max(np.abs(qa - qb)) / qs]
    return float(max(parts))


def _relative_residual(res: _LevelResult, disc: _Discretization, inp: _Inputs,
                       times: np.ndarray) -> float:
    """Residual of the integral equation at the sample points, relative to its terms.

    ``c m q + F q - (delta + alpha x - g)`` for the elastic equation at ``times``. It does
    not depend on comparing mode counts, so it catches what the level differences cannot
    see: a feature no level of the basis resolves (all levels then agree on a wrong q).
    """
    c_t = inp.c(times)
    q_nodes = ((disc.basis.values[:, : res.n] @ res.coefficients
                - np.outer(inp.g(disc.panels.nodes), 1.0 / c_t))
               / disc.m_nodes[:, None])
    q_s = ((disc.sample_phi[:, : res.n] @ res.coefficients
            - np.outer(disc.sample_g, 1.0 / c_t)) / disc.sample_m[:, None])
    local = c_t[None, :] * disc.sample_m[:, None] * q_s
    nonlocal_ = disc.sample_rows @ q_nodes
    rhs = (res.settlement[None, :] + np.outer(disc.sample_x, res.tilt)
           - disc.sample_g[:, None])
    scale = max(np.max(np.abs(local)), np.max(np.abs(nonlocal_)), np.max(np.abs(rhs)),
                1e-300)
    return float(np.max(np.abs(local + nonlocal_ - rhs)) / scale)


def _extrapolated_error(diffs: list[float]) -> float:
    """Error of the last level from the differences of consecutive levels.

    With a convergence ratio rho = d_k/d_{k-1} per level the remaining error after level k
    is about d_k rho/(1 - rho) (a geometric tail); rho is kept in [0.05, 0.9] so neither a
    lucky cancellation nor a stall makes the estimate absurd. The graded basis converges
    in steps, so this reads up to ~3x low or ~6x high (measured on the hard cases of
    tests/test_hard_cases.py); ``SUCCESS_MARGIN`` keeps a claim of success honest.
    """
    if len(diffs) < 2:
        return diffs[-1] if diffs else np.inf
    d_prev, d_last = diffs[-2], diffs[-1]
    if d_prev <= 0:
        return d_last
    rho = min(max(d_last / d_prev, 0.05), 0.9)
    return d_last * rho / (1.0 - rho)


# ----------------------------------------------------------------------- the solver


def _fast_kernel(inp: _Inputs) -> tuple[_Inputs, float]:
    """The kernel to step with, and the error of its fit (see core.kernel_fit.stepping_kernel)."""
    from core.kernel_fit import stepping_kernel

    kernel, fit_error = stepping_kernel(inp.kernel, float(inp.times[-1]),
                                        0.5 * inp.tol / SUCCESS_MARGIN)
    return replace(inp, kernel=kernel), fit_error


def solve_dimensionless(lam: float, m: Scalar, g: Scalar, times: Sequence[float] | np.ndarray,
                        *, c: Scalar = 1.0, kernel: Callable | None = None,
                        settlement: Scalar | None = None, tilt: Scalar | None = None,
                        force: Scalar | None = None, moment: Scalar | None = None,
                        breakpoints: Sequence[float] = (), tol: float = 1e-8,
                        basis: str = "graded", n_modes: int | None = None,
                        method: str | None = None, contact: str = "auto",
                        time_breaks: Sequence[float] = ()) -> ContactSolution:
    """Solve the dimensionless contact problem (Nystrom by default, or the seed's projection).

    Parameters (all dimensionless):
        lam: a/H, half-width over base thickness (> 0).
        m: coating compliance m(x) > 0 on [-1, 1] (number or vectorized callable).
        g: gap g(x) (number or vectorized callable); may jump at ``breakpoints``.
        times: output times, increasing, the first >= 1 (t = 1 is the moment of loading).
        c: relative base modulus c(t) = E(t)/E0 > 0 (number or callable of t).
        kernel: None (elastic base) or the creep kernel K(t, tau) of ``V``; a
            :class:`core.creep.DegenerateKernel` is stepped in O(1) per mode and step.
        settlement, tilt, force, moment: exactly two, numbers or callables of t
            (delta, alpha, P, M).
        breakpoints: points of (-1, 1) where m or g may jump.
        tol: relative accuracy target for delta, alpha (relative to max(|delta|, |alpha|)),
            P, M (relative to max(|P|, |M|)) and q (relative to max|q| over interior points).
        basis: "graded" (default: continuous piecewise polynomials on meshes graded toward
            the edges and jumps), "piecewise" (polynomials between breakpoints) or "global"
            (the seed's basis).
        n_modes: a fixed number of basis functions (for studies); default adaptive.
        method: "nystrom" (the default: a direct solve on graded panels, adaptively
            refined, :mod:`core.prepared`) or "projection" (the seed's series; the default
            when ``basis`` or ``n_modes`` is given, which only it uses).
        contact: "full" (q may come out negative: flag ``contact_lost``), "unilateral"
            (q >= 0 with an unknown contact set, :func:`core.contact.solve_unilateral`) or
            "auto" (full contact first, unilateral only when it is lost).
        time_breaks: times where a given load history jumps or kinks; the default engine's
            time steps land on them (a step across a jump loses the order and fools the
            step-doubling estimate).

    Returns a :class:`ContactSolution` (or, when the unilateral model answered, a
    :class:`core.contact.UnilateralSolution` with the same attributes); ``contact_set``
    and ``info["contact"]`` say which contact model answered. Raises ``ValueError``
    naming the argument on bad input.
    """
    from core.contact import check_contact_model, solve_unilateral, with_contact_model
    from core.statements import UnresolvedOperator

    t_start = _time.perf_counter()
    contact = check_contact_model(contact)
    method_defaulted = method is None
    if method is None:
        method = "projection" if (n_modes is not None or basis != "graded") else "nystrom"
    if method not in ("nystrom", "projection"):
        raise ValueError(f"method: must be 'nystrom' or 'projection', got {method!r}")
    if method == "nystrom":
        from core.prepared import solve_with_prepared

        unilateral_args = dict(lam=lam, m=m, g=g, times=times, c=c, kernel=kernel,
                               settlement=settlement, tilt=tilt, force=force, moment=moment,
                               breakpoints=breakpoints, tol=tol)
        if contact == "unilateral":
            return solve_unilateral(**unilateral_args)
        try:
            full = solve_with_prepared(lam, m, g, times, c=c, kernel=kernel,
                                       settlement=settlement, tilt=tilt, force=force,
                                       moment=moment, breakpoints=breakpoints, tol=tol,
                                       time_breaks=time_breaks)
        except UnresolvedOperator as exc:
            if not method_defaulted:
                raise
            # the symmetric Galerkin projection steps such a scene (positive definite by
            # construction); say which engine answered and why
            full = solve_dimensionless(lam, m, g, times, c=c, kernel=kernel,
                                       settlement=settlement, tilt=tilt, force=force,
                                       moment=moment, breakpoints=breakpoints, tol=tol,
                                       method="projection", contact="full",
                                       time_breaks=time_breaks)
            full.info["method"] = "projection"
            full.info["fallback"] = f"default engine declined ({exc}); projection answered"
            return with_contact_model(full, contact, unilateral_args)
        return with_contact_model(full, contact, unilateral_args)
    inp = _validate(lam, m, g, times, c, kernel,
                    {"settlement": settlement, "tilt": tilt, "force": force, "moment": moment},
                    breakpoints, tol)
    unilateral_args = dict(lam=lam, m=m, g=g, times=times, c=c, kernel=kernel,
                           settlement=settlement, tilt=tilt, force=force, moment=moment,
                           breakpoints=breakpoints, tol=tol)
    if contact == "unilateral":
        return solve_unilateral(**unilateral_args)
    if basis not in ("piecewise", "global", "graded"):
        raise ValueError(f"basis: must be 'piecewise', 'global' or 'graded', got {basis!r}")
    inp, kernel_fit_error = _fast_kernel(inp)
    if n_modes is not None and (isinstance(n_modes, bool) or not isinstance(n_modes, int)
                                or not 2 <= n_modes <= BASIS_CAPS[-1]):
        raise ValueError(f"n_modes: must be an integer in [2, {BASIS_CAPS[-1]}], got {n_modes}")
    stages: dict[str, dict] = {}
    times_arr = inp.times
    c_t = inp.c(times_arr)
    # Probe times for choosing the mode count: all of them for an elastic base (cheap),
    # else the first, last and a few in between.
    if inp.kernel is None or times_arr.size <= 5:
        probe_idx = np.arange(times_arr.size)
    else:
        probe_idx = np.unique(np.linspace(0, times_arr.size - 1, 5).round().astype(int))
    probe_times = times_arr[probe_idx]
    # Time error budget: the step-doubling estimate adds local errors (an upper bound that
    # read up to ~20x the true error on decaying creep), so the steps aim ten times lower
    # than the share they would need, keeping the reported estimate close to the truth.
    time_tol = tol / 30

    flags: list[str] = []
    chosen: _LevelResult | None = None
    spatial_error = np.inf
    disc = None
    n_used = 0
    # The basis built (and, for the seed's bases, the panels) depends on the cap, so a
    # fixed mode count always uses the same one whatever tol says.
    if n_modes is not None:
        caps = next((cap,) for cap in BASIS_CAPS if n_modes <= cap)
    elif inp.tol < DIRECT_LARGEST_BELOW:
        caps = BASIS_CAPS[-1:]
    else:
        caps = BASIS_CAPS
    for cap in caps:
        disc = _discretize(inp, cap, basis, stages)
        size = disc.basis.size
        if n_modes is not None:
                        levels = [lv for lv in MODE_LEVELS if lv < min(n_modes, size)][-2:] + [
                min(n_modes, size)]
        else:
            levels = [lv for lv in MODE_LEVELS if lv < size] + [size]
        diffs: list[float] = []
        prev_probe: _LevelResult | None = None
        probe_chain: list[_LevelResult] = []
        c_probe = c_t[probe_idx]
        t_probe = _time.perf_counter()
        probe_stage = _Superposition(replace(inp, kernel=None), disc, probe_times, time_tol)
        for n in levels:
            ms = _modes(disc, inp.given, n, stages)
            res = probe_stage.solve([ms])[0][0]
            if prev_probe is not None:
                diffs.append(_difference(res, prev_probe, disc, c_probe))
            probe_chain.append(res)
            prev_probe = res
            if n_modes is None and len(diffs) >= 2:
                est = max(_extrapolated_error(diffs), ERROR_FLOOR)
                if est <= 0.5 * tol / SUCCESS_MARGIN and _relative_residual(
                        res, disc, inp, probe_times) <= 0.5 * tol / SUCCESS_MARGIN:
                    break
        entry = stages.setdefault("mode_selection", {"seconds": 0.0, "cached": False})
        entry["seconds"] += _time.perf_counter() - t_probe
        est = max(_extrapolated_error(diffs), ERROR_FLOOR,
                  _relative_residual(probe_chain[-1], disc, inp, probe_times))
        n_used = probe_chain[-1].n
        if est <= 0.5 * tol / SUCCESS_MARGIN or n_modes is not None or cap == BASIS_CAPS[-1]:
            spatial_error = est
            n_prev = probe_chain[-2].n if len(probe_chain) > 1 else None
            break

    assert disc is not None
    t_time = _time.perf_counter()
    time_cached = False
    if inp.kernel is None and probe_idx.size == times_arr.size:
        chosen = probe_chain[-1]
    else:
        systems = [_modes(disc, inp.given, n_used, stages)]
        if n_prev is not None and inp.kernel is not None:
            # The spatial estimate above is elastic; check it on the creeping answer.
            systems.append(_modes(disc, inp.given, n_prev, stages))
        results, time_cached = _Superposition(inp, disc, times_arr, time_tol).solve(systems)
        chosen = results[0]
        if len(results) > 1:
            d_creep = _difference(chosen, results[1], disc, c_t)
            creep_diffs = [d_creep * diffs[-2] / diffs[-1], d_creep] if (
                len(diffs) >= 2 and diffs[-1] > 0) else [d_creep]
            spatial_error = max(spatial_error, _extrapolated_error(creep_diffs), ERROR_FLOOR)
    stages["time"] = {"seconds": _time.perf_counter() - t_time, "cached": time_cached}

    error_estimate = float(spatial_error + chosen.time_error + kernel_fit_error)
    success = error_estimate * SUCCESS_MARGIN <= tol and chosen.time_success
    if not disc.resolved:
        flags.append("unresolved_input")
    if not success:
        flags.append("tol_not_met")
    # Contact: q >= 0 must hold on the whole of [-1, 1] at every time.
    x_check = disc.check_x
    phi_check = disc.check_phi[:, : chosen.n]
    q_check = (phi_check @ chosen.coefficients
               - np.outer(inp.g(x_check), 1.0 / c_t)) / inp.m(x_check)[:, None]
    q_scale = max(float(np.max(np.abs(q_check))), 1e-300)
    min_q = float(np.min(q_check))
    if min_q < -max(error_estimate, 1e-12) * q_scale:
        flags.append("contact_lost")
    if success:
        message = (f"converged: estimated error {error_estimate:.1e} <= tol {tol:.1e}/"
                   f"{SUCCESS_MARGIN:g} with {chosen.n} modes")
    else:
        reasons = []
        if spatial_error * SUCCESS_MARGIN > tol:
            reasons.append(f"the basis reached {chosen.n} modes with estimated error "
                           f"{spatial_error:.1e}")
        if chosen.time_error * SUCCESS_MARGIN > tol or not chosen.time_success:
            reasons.append(f"time stepping: {chosen.time_message} (estimated error "
                           f"{chosen.time_error:.1e})")
        if kernel_fit_error * SUCCESS_MARGIN > tol:
            reasons.append(f"the creep kernel's exponential fit has error {kernel_fit_error:.1e}")
        message = (f"tol {tol:.1e} not met (success needs the estimate below tol/"
                   f"{SUCCESS_MARGIN:g}): " + "; ".join(reasons))
    if not disc.resolved:
        message += ("; m or g has features finer than the quadrature could resolve "
                    "(declare jumps in breakpoints)")
    info = {
        "error_estimate": error_estimate,
        "spatial_error_estimate": float(spatial_error),
        "time_error_estimate": float(chosen.time_error),
        "kernel_fit_error": float(kernel_fit_error),
        "seconds": _time.perf_counter() - t_start,
        "flags": flags,
        "success": bool(success),
        "message": message,
        "n_modes": int(chosen.n),
        "n_steps": int(chosen.steps),
        "n_nodes": int(disc.panels.size),
        "statement": statement_number(inp.given),
        "given": sorted(inp.given),
        "min_pressure": min_q,
        "max_pressure": q_scale,
        "basis": disc.basis.kind,
        # Where q may have a kink (element ends of the basis) or a jump (breakpoints).
        "element_ends": sorted(set(disc.cuts) | set(inp.breakpoints)),
        "orthonormality_error": disc.basis.orthonormality_error,
        "stages": stages,
    }
    full = ContactSolution(times_arr.copy(), chosen.settlement, chosen.tilt, chosen.force,
                           chosen.moment, info, disc.basis, chosen.coefficients, c_t, inp.m,
                           inp.g)
    return with_contact_model(full, contact, unilateral_args)
