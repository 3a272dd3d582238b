"""Several punches on a creeping (or aging) base: the coupled nodal equations in modal form.

The coupled nodal equations of :mod:`core.engines.nystrom.multi` read, over all zones,

    c(t) D q + (I - V) A q = B x(t) - g,        B^T W q = y(t),

with ``D = diag(m)``, ``A`` the coupled operator (self and coupling blocks), ``B`` the
columns ``[1, x]`` of every zone (zero elsewhere), ``x = (delta_p, alpha_p)`` and
``y = (P_p, M_p)`` of every punch. With ``q = S u``, ``S = diag(1/sqrt(w m))``, and the
rows scaled by ``sqrt(w/m)`` this becomes

    c u + (I - V) G u = E x - s g,     E^T u = y,     G = s A S,  E = s B,  s = sqrt(w/m),

the same vectors ``E`` carrying the drive and the balance (as in
:mod:`core.engines.nystrom.modal` for one punch). For each punch a given force fixes the
component of ``u`` along its column ``E_delta``, a given moment along ``E_alpha``, and an
unknown settlement (tilt) drives along that same column (each statement pairs them: a
given force with an unknown settlement or a given tilt, ...; an unknown drive always lies
in the span of the fixed columns). An orthonormal ``Q = [Q_k, Q_f]`` with ``Q_k`` spanning
the fixed columns ``E_k`` splits ``u = Q_k a_k + Q_f a_f``:

- ``a_k = R_k^-T y_given`` (``E_k = Q_k R_k``) is known from the loads;
- the free rows hold no unknown drive: ``c a_f + (I - V)(G_ff a_f + G_fk a_k) = Q_f^T (E
  x_given - s g)``; with ``G_ff = Psi Gamma Psi^-1`` each modal coordinate obeys one scalar
  Volterra equation (:class:`core.time.ModalProblem`), stepped by :mod:`core.time`;
- the fixed rows then give the unknown drives, and ``y = E^T u`` the unknown forces and
  moments.

The modes are those of the whole coupled operator, so the punches creep together.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from core.engines.nystrom.modal import MODAL_ROUNDING_SHARE
from core.problem import (
    QUANTITIES,
    TimeInputs,
    UnresolvedOperator,
    check_mode_probe,
    mode_probe,
    real_modes,
)
from core.time import ModalProblem, solve_degenerate, solve_general

#: Per punch: the column of ``E`` (0: ``1``, 1: ``x``) a given force or moment fixes, and
#: the one an unknown settlement or tilt drives along.
_FIXES = {"force": 0, "moment": 1}
_DRIVES = {"settlement": 0, "tilt": 1}


@dataclass(frozen=True)
class CoupledModalAnswer:
    """The time-stepped answer: nodal q and ``q - V q`` (N, T) over all zones, the four
    scalars of every punch (dict per punch, arrays over the times), and the stepping's
    report (``time_error`` relative to the size of the modal unknowns; ``time_errors``,
    where known, each punch's relative to its own answer)."""

    nodal: np.ndarray
    effective: np.ndarray
    scalars: list[dict[str, np.ndarray]]
    time_error: float
    steps: int
    success: bool
    message: str
    time_errors: tuple[float, ...] = ()


class CoupledModalForm:
    """The modal form of the coupled equations for the punches' statements ``givens``.

    ``operator`` (N, N): the coupled ``A``; ``m``, ``weights``, ``nodes`` (N,) over all
    zones; ``offsets`` the zones' first nodes (and N); ``gap`` (N,) the gap at the nodes.
    """

    def __init__(self, operator: np.ndarray, m: np.ndarray, weights: np.ndarray,
                 nodes: np.ndarray, gap: np.ndarray, offsets: np.ndarray,
                 givens: Sequence[frozenset[str]], tol: float) -> None:
        n = m.size
        self.givens = tuple(givens)
        self.n_punches = len(givens)
        s_in = np.sqrt(weights / m)
        self.s_out = 1.0 / np.sqrt(weights * m)
        columns = np.zeros((n, 2 * self.n_punches))
        for p in range(self.n_punches):
            zone = slice(offsets[p], offsets[p + 1])
            columns[zone, 2 * p] = s_in[zone]
            columns[zone, 2 * p + 1] = s_in[zone] * nodes[zone]
        self.columns = columns  # E
        fixed = [2 * p + _FIXES[q] for p, given in enumerate(givens)
                 for q in ("force", "moment") if q in given]
        drives = [2 * p + _DRIVES[q] for p, given in enumerate(givens)
                  for q in ("settlement", "tilt") if q not in given]
        self.fixed, self.driven = fixed, drives
        self.k = k = len(fixed)
        self.given_drives = [2 * p + _DRIVES[q] for p, given in enumerate(givens)
                             for q in ("settlement", "tilt") if q in given]
        if k:
            q_full, r_full = np.linalg.qr(columns[:, fixed], mode="complete")
            self.r_k = r_full[:k]
        else:
            q_full, self.r_k = np.eye(n), np.zeros((0, 0))
        self.q = q_full
        g_rot = q_full.T @ ((s_in[:, None] * operator * self.s_out[None, :]) @ q_full)
        self.g_kk, self.g_kf = g_rot[:k, :k], g_rot[:k, k:]
        gamma, psi = np.linalg.eig(g_rot[k:, k:])
        if np.max(np.abs(gamma.imag), initial=0.0) > 1e-8 * np.max(np.abs(gamma)):
            raise UnresolvedOperator("operator: the coupled operator has complex modes; "
                                     "the grid does not resolve the problem")
        # (two equal punches make nearly double eigenvalues, which eig may return as a
        # pair a +- ib with |b| at rounding: psi.real would hold one vector twice and its
        # inverse be garbage, q -7.3e6 Pa for 1.16e6 at tol 1e-9 on the two-footing preset)
        self.gamma, self.psi = gamma.real, real_modes(gamma, psi)
        rounding = np.finfo(float).eps * float(np.max(np.abs(self.gamma), initial=0.0))
        if rounding > MODAL_ROUNDING_SHARE * tol or np.min(self.gamma, initial=1.0) <= 0:
            raise UnresolvedOperator(
                f"operator: its modes reach {float(np.max(np.abs(self.gamma))):.1e} (a nearly "
                "first-kind equation); the grid does not resolve the problem")
        psi_lu = np.linalg.inv(self.psi)
        probe = mode_probe(self.psi.shape[1])
        check_mode_probe(psi_lu @ (self.psi @ probe), probe, MODAL_ROUNDING_SHARE * tol)
        rotated_e = q_full.T @ columns  # (N, 2n)
        self.e_k, self.e_f = rotated_e[:k], rotated_e[k:]
        gap_rot = -(q_full.T @ (s_in * gap))
        self.gap_k = gap_rot[:k]
        self.gap_free = psi_lu @ gap_rot[k:]
        self.drive_free = psi_lu @ self.e_f  # (F, 2n): per unit of each x column
        self.coupling = psi_lu @ g_rot[k:, :k] if k else np.zeros((n - k, 0))
        # the unknown drives, from the fixed rows: e_k[:, driven] x_unknown = ...
        self.unknown_matrix = self.e_k[:, drives] if k else np.zeros((0, 0))

    def _given(self, inputs: Sequence[TimeInputs], t: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
        """The given drives x (2n, T) (zero where unknown) and fixed coordinates a_k (k, T)."""
        x = np.zeros((2 * self.n_punches, t.size))
        y = np.zeros((self.k, t.size))
        i = 0
        for p, one in enumerate(inputs):
            for q in ("settlement", "tilt"):
                if q in one.given:
                    x[2 * p + _DRIVES[q]] = np.broadcast_to(one.loads[q](t), t.shape)
            for q in ("force", "moment"):
                if q in one.given:
                    y[i] = np.broadcast_to(one.loads[q](t), t.shape)
                    i += 1
        a_k = np.linalg.solve(self.r_k.T, y) if self.k else y
        return x, a_k

    def solve(self, inputs: Sequence[TimeInputs], times: np.ndarray, c: Callable,
              kernel: object, time_tol: float, breaks: Sequence[float] = ()
              ) -> CoupledModalAnswer:
        """The answer at ``times`` for relative modulus ``c(t)`` and the stepping kernel
        ``kernel`` (None: no creep, ``c`` varying)."""
        return self.solve_parts([(inputs, 1.0)], times, c, kernel, time_tol, breaks)[0]

    def solve_parts(self, parts: Sequence[tuple[Sequence[TimeInputs], float]],
                    times: np.ndarray, c: Callable, kernel: object, time_tol: float,
                    breaks: Sequence[float] = ()) -> list[CoupledModalAnswer]:
        """:meth:`solve` for several ``(inputs, gap)`` at once, in one time march.

        ``inputs``: every punch's loads (``.given`` and ``.loads`` as a
        :class:`core.problem.TimeInputs` has them); ``gap``: the weight of the gap in the
        part. The parts share ``c``, the kernel and the times, so their modal equations
        are stepped together as one problem with the modes of every part, each part's
        error against its own size (``ModalProblem.parts``), as the single punch's
        :meth:`core.engines.nystrom.modal.ModalSet.solve_parts` does.
        """
        gamma = self.gamma
        n_parts, n_free = len(parts), gamma.size
        single = self.coupling / gamma[:, None]
        n_known = max(self.k, 1)
        memo: dict[bytes, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

        def evaluate(tt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            key = tt.tobytes()
            if key not in memo:
                memo.clear()
                d = 1.0 + np.asarray(c(tt), dtype=float)[None, :] / gamma[:, None]
                r = np.empty((n_parts * n_free, tt.size))
                us = np.zeros((n_parts * n_known, tt.size))
                for j, (inputs, gap) in enumerate(parts):
                    x, a_k = self._given(inputs, tt)
                    rows = r[j * n_free:(j + 1) * n_free]
                    rows[:] = (self.drive_free @ x + gap * self.gap_free[:, None]) \
                        / gamma[:, None]
                    if self.k:
                        rows -= single @ a_k
                        us[j * n_known:(j + 1) * n_known] = a_k
                memo[key] = (np.tile(d, (n_parts, 1)) if n_parts > 1 else d, r, us)
            return memo[key]

        c_t = np.asarray(c(times), dtype=float)
        if kernel is None:
            d, r, _ = evaluate(times)
            z = r / d
            vz, vu = np.zeros_like(z), np.zeros((n_parts * n_known, times.size))
            estimates: tuple[float, ...] = (0.0,) * n_parts
            steps, success, message = 0, True, "no creep: no time stepping"
        else:
            coupling = single if self.k else np.zeros((n_free, 1))
            problem = ModalProblem(d=lambda tt: evaluate(tt)[0], r=lambda tt: evaluate(tt)[1],
                                   u=lambda tt: evaluate(tt)[2],
                                   coupling=(np.kron(np.eye(n_parts), coupling)
                                             if n_parts > 1 else coupling), parts=n_parts)
            jumps = tuple(float(b) for b in breaks)
            if hasattr(kernel, "rates") and hasattr(kernel, "exponential_parts"):
                sol = solve_degenerate(kernel, problem, times, tol=time_tol, breaks=jumps)
            else:
                sol = solve_general(kernel, problem, times, tol=time_tol, breaks=jumps)
            z, vz, vu = sol.w, sol.vw, sol.vu
            estimates = tuple(sol.part_errors) or (float(sol.error_estimate),) * n_parts
            steps, success, message = int(sol.steps), bool(sol.success), sol.message
        answers = []
        for j, (inputs, gap) in enumerate(parts):
            rows = slice(j * n_free, (j + 1) * n_free)
            known = slice(j * n_known, j * n_known + self.k)
            answers.append(self._finish(inputs, times, c_t, z[rows], vz[rows], vu[known],
                                        gap, float(estimates[j]), steps, success, message))
        return answers

    def _finish(self, inputs: Sequence[TimeInputs], times: np.ndarray, c_t: np.ndarray,
                z: np.ndarray, vz: np.ndarray, va_k: np.ndarray, gap: float, error: float,
                steps: int, success: bool, message: str) -> CoupledModalAnswer:
        """The answer of one part from its stepped modal coordinates."""
        x, a_k = self._given(inputs, times)
        a_f, va_f = self.psi @ z, self.psi @ vz
        if self.k:
            # fixed rows: c a_k + (I - V)(G_kf a_f + G_kk a_k) = e_k x + gap_k
            lhs = (c_t[None, :] * a_k + self.g_kf @ (a_f - va_f) + self.g_kk @ (a_k - va_k)
                   - self.e_k @ x - gap * self.gap_k[:, None])
            x[self.driven] = np.linalg.solve(self.unknown_matrix, lhs)
        u_all = np.vstack([a_k, a_f])
        u_eff = np.vstack([a_k - va_k, a_f - va_f])
        nodal = self.s_out[:, None] * (self.q @ u_all)
        effective = self.s_out[:, None] * (self.q @ u_eff)
        y = self.columns.T @ (self.q @ u_all)  # force and moment of every punch
        scalars = []
        for p in range(self.n_punches):
            values = {"settlement": x[2 * p], "tilt": x[2 * p + 1],
                      "force": y[2 * p], "moment": y[2 * p + 1]}
            for q in ("force", "moment"):
                if q in self.givens[p]:
                    values[q] = np.broadcast_to(inputs[p].loads[q](times),
                                                times.shape).astype(float)
            scalars.append({q: np.asarray(values[q], dtype=float) for q in QUANTITIES})
        return CoupledModalAnswer(nodal, effective, scalars, error, steps, success, message)

    @property
    def has_gap(self) -> bool:
        """Whether any zone's base has a gap (its response is a part of its own)."""
        return bool(np.any(self.gap_free) or np.any(self.gap_k))
