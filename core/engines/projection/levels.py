"""The projection engine's time stage: mode levels, superposition of loads, error estimates.

Solves the modal Volterra equations for a chosen mode count (:mod:`core.time.integration`)
and compares consecutive levels for the spatial error estimate (used by
:mod:`core.engines.projection.solve`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from core.cache import fingerprint
from core.engines.projection.caches import _RESPONSE
from core.engines.projection.matrices import GapTerms
from core.engines.projection.stages import _Discretization, _Inputs
from core.problem import QUANTITIES, ModalSystem
from core.time import ModalProblem, history_key_times, solve_degenerate, solve_general

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
        return self.ms.given_drive(rows, loads, size)

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
        sol = solve_degenerate(inp.kernel, problem, times, tol=time_tol,
                               breaks=inp.time_breaks)
    else:
        sol = solve_general(inp.kernel, problem, times, tol=time_tol, breaks=inp.time_breaks)
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
        # (the histories over the march's span, geometric samples too: steps at t* 1.02
        # and 1.08 met at every even sample, and one took the other's answer)
        probe = history_key_times(times, inp.time_breaks)
        self.base_key = (disc.galerkin_key, tuple(sorted(inp.given)),
                         fingerprint(times, inp.c(probe), repr(kernel_key), time_tol,
                                     inp.time_breaks))
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
    is about d_k rho/(1 - rho) (a geometric tail), rho kept at most 0.9 so that a stall
    does not make the estimate absurd. The graded basis converges in steps: a level may
    add functions away from where the error is largest, so two levels can share that
    error and their difference drops while the error does not. The estimate is therefore
    never below the last difference: q on the whole of [-1, 1] read up to 11x low with
    the geometric tail alone (a rough punch: differences 1.4e-3, 5.0e-4, 3.1e-5, error
    3.6e-5; ten layers: 1.6e-5, 2.5e-6, error 2.6e-6), and reads 1.5-66x the error with
    this floor on the hard cases of tests/engines/test_hard_cases.py (0.4-25x on eleven
    scenes at tol 1e-4 to 1e-8, where ``SUCCESS_MARGIN`` covers the lowest).
    """
    if len(diffs) < 2:
        return diffs[-1] if diffs else np.inf
    d_prev, d_last = diffs[-2], diffs[-1]
    if d_prev <= 0:
        return d_last
    rho = min(d_last / d_prev, 0.9)
    return d_last * max(1.0, rho / (1.0 - rho))
