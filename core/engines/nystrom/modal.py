"""The Nystrom equations in modal form, for a creeping base or a modulus that varies in time.

With ``D = diag(m_i)`` and ``A`` the discrete layer operator, the nodal equations read

    c(t) D q + (I - V) A q = delta 1 + alpha x - g.

In the inner product ``<u, v> = u^T W D v`` (``W`` the quadrature weights) the vectors
``D^-1 1`` and ``D^-1 x`` carry both the drive (``delta``, ``alpha``) and the balance
(``P = <q, D^-1 1>``, ``M = <q, D^-1 x>``). An orthonormal basis whose first two vectors
span them (the discrete analogue of the seed's ``p_0``, ``p_1``) turns the nodal equations
into exactly the seed's Galerkin rows,

    c a_i + (I - V) sum_j R_ij a_j = delta e0_i + alpha e1_i + f_i,   R = P^T W A P,

with the gap as a constant drive ``f = -P^T W g``, so :func:`core.problem.modal_system`
decouples them (its free block diagonalized as it is: the product-integration rows of
``A`` are not symmetric, but the operator is similar to a symmetric positive one) and
:mod:`core.time.integration` steps one scalar Volterra equation per mode.

The free block is ``eig``-decomposed. Its antisymmetric part is ~7e-4 of the whole, so
``eigh`` of its symmetric part refined by Newton steps of all eigenvectors at once was
tried and measured (CPU, one thread, the work-precision scenes): 0.6-1.2 ms faster at 142
modes (4.2-4.3 against 4.8-5.4 ms), 15-55 % slower from 222 modes on (its matrix
products grow faster than ``eig``), and diverging where eigenvalues cluster (no coating,
and two creep scenes of the tests), where ``eig`` then had to run after it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from core.discretize import MIRROR_TOL, even_per_node, mirrored_rule
from core.engines.nystrom.bordered import NystromGrid
from core.problem import (
    ModalSystem,
    UnresolvedOperator,
    check_mode_probe,
    modal_system,
    mode_probe,
)
from core.time import ModalProblem, solve_degenerate, solve_general

Function = Callable[[np.ndarray], np.ndarray]

#: The modes are declined when the rounding of their decomposition, ``eps max|gamma|``
#: (against ``c + gamma_k >= c``, c ~ 1 at loading), exceeds this share of tol: a coating
#: that makes the equation first kind (m ~ 3e-15: gamma up to 7e12, rounding 1.6e-3)
#: gives modes no time stepping can trust; m = 1e-4 gives 2.7e3 (rounding 6e-13).
MODAL_ROUNDING_SHARE = 0.1
#: The modes of one punch are declined when a probe vector taken through them and back
#: (:func:`core.problem.check_mode_probe`) comes back further off than the larger of
#: ``MODAL_ROUNDING_SHARE`` tol and this share of its size; closer, its defect is carried
#: in the answer's time error (:attr:`ModalForm.mode_defect`). At tol 1e-11 the probe of
#: a coating jump came back 1.8e-11 off, the engine declined, and the projection answered
#: 4.9e-7 where this engine had answered 2.2e-11 (the references of
#: ``benchmarks/creep_honesty.py``).
PROBE_FLOOR = 1e-9


@dataclass(frozen=True)
class ModalAnswer:
    """Nodal pressures (N, T), the four scalars over the times and the time stepping's report.

    ``q - V q`` at the nodes (the density whose ``F`` enters the equation, for the Nystrom
    formula between the nodes) is kept in modal coordinates, ``modal_effective`` = (free
    (F, T), known (k, T)), with ``to_nodes`` = (free (N, F), known (N, k)): it is formed
    at the nodes only where asked (:meth:`effective`), and rows of the operator reach it
    through the modes (:meth:`effective_through`, no N x N x T product).
    """

    nodal_pressures: Callable[[], np.ndarray]
    modal_effective: tuple[np.ndarray, np.ndarray]
    to_nodes: tuple[np.ndarray, np.ndarray]
    scalars: dict[str, np.ndarray]
    time_error: float
    steps: int
    success: bool
    message: str

    @property
    def nodal(self) -> np.ndarray:
        """Nodal pressures (N, T), formed when asked (an N x N x T product)."""
        return self.nodal_pressures()

    def effective(self, at: np.ndarray | slice = slice(None)) -> np.ndarray:
        """``q - V q`` at the nodes (N, len(at)) at the columns ``at`` of the times."""
        return self.effective_through(None, at)

    def effective_through(self, rows: np.ndarray | None, at: np.ndarray | slice = slice(None)
                          ) -> np.ndarray:
        """``rows @ (q - V q)`` at the columns ``at`` (len(rows), len(at)); rows (X, N), or
        None for the nodal values themselves."""
        (free, known), (node_free, node_known) = self.modal_effective, self.to_nodes
        if rows is not None:
            node_free, node_known = rows @ node_free, rows @ node_known
        out = node_free @ free[:, at]
        return out + node_known @ known[:, at] if known.shape[0] else out


class _Basis:
    """The orthonormal basis ``Q`` (N x N) whose first columns span those of ``first``
    (N, k; k = 2 here, 1 for each half of a :class:`_MirrorBasis`), kept as its k
    Householder reflectors ``Q = H_0 ... H_k-1 S`` (``S`` the signs that make R's
    diagonal positive), so products with it cost O(N^2)."""

    #: no groups of basis functions apart (see :class:`_MirrorBasis`)
    blocks: tuple[np.ndarray, ...] | None = None

    def __init__(self, first: np.ndarray) -> None:
        h, tau = np.linalg.qr(first, mode="raw")   # reflectors in LAPACK's (k, N) layout
        n, k = first.shape
        self.k = k
        self.v = np.zeros((k, n))
        self.tau = tau
        for i in range(k):
            self.v[i, i] = 1.0
            self.v[i, i + 1:] = h[i, i + 1:]
        self.signs = np.sign(np.diag(h[:k, :k]))  # R's diagonal (R = h.T's upper triangle)

    def _reflect(self, i: int, y: np.ndarray) -> np.ndarray:
        """``H_i y`` (N, ...) for the reflector ``H_i = I - tau_i v_i v_i^T``."""
        v = self.v[i]
        return y - self.tau[i] * np.multiply.outer(v, v @ y)

    def times(self, y: np.ndarray) -> np.ndarray:
        """``Q y`` for ``y`` (N, ...)."""
        y = np.array(y, dtype=float)
        y[:self.k] *= self.signs.reshape((self.k,) + (1,) * (y.ndim - 1))
        for i in reversed(range(self.k)):
            y = self._reflect(i, y)
        return y

    def transposed_times(self, y: np.ndarray) -> np.ndarray:
        """``Q^T y`` for ``y`` (N, ...)."""
        out = y
        for i in range(self.k):
            out = self._reflect(i, out)
        out[:self.k] *= self.signs.reshape((self.k,) + (1,) * (out.ndim - 1))
        return out

    def times_right(self, y: np.ndarray) -> np.ndarray:
        """``y Q`` for ``y`` (X, N)."""
        return self.transposed_times(y.T).T


def mirrored(grid: NystromGrid) -> bool:
    """Whether ``grid`` may be its own mirror image about the punch's centre: node
    ``N-1-i`` at ``-x_i`` with the same weight (to a few roundings) and coating compliance
    (to :data:`~core.discretize.MIRROR_TOL` of its own value); the operator is judged by
    what the split would drop (:func:`_mirrored_galerkin`)."""
    m = grid.m
    return mirrored_rule(grid.nodes, grid.panels.weights) and even_per_node(m, m[::-1])


class _MirrorBasis:
    """:class:`_Basis` for a mirrored grid (:func:`mirrored`): its functions are even or
    odd about the punch's centre, so the Galerkin matrix has no entries between the two
    kinds (``blocks``: the even ones, the odd ones).

    The even functions are ``(e_i + e_N-1-i) / sqrt 2`` (and the middle node's ``e_i``)
    turned by one Householder reflector so that the first is ``first[:, 0]`` normalized
    (an even vector); the odd ones ``(e_i - e_N-1-i) / sqrt 2`` likewise with
    ``first[:, 1]`` (odd). Coefficients in the order: even first, odd first, the other
    even ones, the other odd ones (the first two span the columns of ``first``, as in
    :class:`_Basis`)."""

    def __init__(self, first: np.ndarray) -> None:
        n = first.shape[0]
        self.n, self.half, self.middle = n, n // 2, n % 2
        self.even = _Basis(self._even_part(first[:, :1]))
        self.odd = _Basis(self._odd_part(first[:, 1:2]))
        evens = self.half + self.middle
        self.even_at = np.concatenate([[0], np.arange(2, evens + 1)])
        self.odd_at = np.concatenate([[1], np.arange(evens + 1, n)])
        self.blocks = (self.even_at, self.odd_at)

    def _even_part(self, v: np.ndarray) -> np.ndarray:
        h = self.half
        pairs = (v[:h] + v[::-1][:h]) / np.sqrt(2.0)
        return np.concatenate([pairs, v[h:h + 1]]) if self.middle else pairs

    def _odd_part(self, v: np.ndarray) -> np.ndarray:
        h = self.half
        return (v[:h] - v[::-1][:h]) / np.sqrt(2.0)

    def _from_parts(self, even: np.ndarray, odd: np.ndarray) -> np.ndarray:
        h = self.half
        out = np.empty((self.n,) + even.shape[1:])
        out[:h] = (even[:h] + odd) / np.sqrt(2.0)
        out[self.n - h:] = ((even[:h] - odd) / np.sqrt(2.0))[::-1]
        if self.middle:
            out[h] = even[h]
        return out

    def times(self, y: np.ndarray) -> np.ndarray:
        """``Q y`` for ``y`` (N, ...)."""
        y = np.asarray(y, dtype=float)
        return self._from_parts(self.even.times(y[self.even_at]), self.odd.times(y[self.odd_at]))

    def transposed_times(self, y: np.ndarray) -> np.ndarray:
        """``Q^T y`` for ``y`` (N, ...)."""
        y = np.asarray(y, dtype=float)
        out = np.empty(y.shape)
        out[self.even_at] = self.even.transposed_times(self._even_part(y))
        out[self.odd_at] = self.odd.transposed_times(self._odd_part(y))
        return out

    def times_right(self, y: np.ndarray) -> np.ndarray:
        """``y Q`` for ``y`` (X, N)."""
        return self.transposed_times(y.T).T


def _mirrored_galerkin(first: np.ndarray, scaled: np.ndarray,
                       moments: tuple[float, float, float]
                       ) -> tuple[_MirrorBasis, np.ndarray] | None:
    """The mirror basis of ``first`` and the Galerkin matrix of the ``scaled`` operator in
    it, its entries between even and odd functions set to zero, where those and ``J_1``
    (``moments``) are within :data:`~core.discretize.MIRROR_TOL`; else None."""
    j0, j1, j2 = moments
    if abs(j1) > MIRROR_TOL * np.sqrt(j0 * j2):
        return None
    basis = _MirrorBasis(first)
    galerkin = basis.transposed_times(basis.times_right(scaled))
    even, odd = basis.blocks
    apart = max(np.max(np.abs(galerkin[np.ix_(even, odd)]), initial=0.0),
                np.max(np.abs(galerkin[np.ix_(odd, even)]), initial=0.0))
    if apart > MIRROR_TOL * np.max(np.abs(galerkin)):
        return None
    galerkin[np.ix_(even, odd)] = 0.0
    galerkin[np.ix_(odd, even)] = 0.0
    return basis, galerkin


class ModalForm:
    """One statement of the Nystrom equations in decoupled modal coordinates."""

    def __init__(self, grid: NystromGrid, given: frozenset[str], tol: float = 1e-8) -> None:
        """``tol``: the relative accuracy the modes serve (see MODAL_ROUNDING_SHARE);
        raises :class:`core.problem.UnresolvedOperator` when they cannot."""
        w, m, x = grid.panels.weights, grid.m, grid.nodes
        s_in = np.sqrt(w / m)  # row scaling S^-1 W
        s_out = 1.0 / np.sqrt(w * m)  # column scaling S^-1
        # the basis Q: two Householder reflectors (the QR of the first two vectors), the
        # signs of its first two columns those of R's diagonal; applied as reflections
        # (rank-one updates, O(N^2)) instead of formed and multiplied (two N^3 products)
        first = np.column_stack([s_in, s_in * x])
        scaled = s_in[:, None] * grid.operator * s_out[None, :]
        moments = (float(np.sum(w / m)), float(np.sum(w * x / m)), float(np.sum(w * x * x / m)))
        # a grid symmetric about the punch's centre: even and odd modes apart (J_1 = 0)
        split = _mirrored_galerkin(first, scaled, moments) if mirrored(grid) else None
        if split is not None:
            basis, galerkin = split
            moments = (moments[0], 0.0, moments[2])
        else:
            basis = _Basis(first)
            galerkin = basis.transposed_times(basis.times_right(scaled))
        self.ms: ModalSystem = modal_system(galerkin, moments, given, grid.size,
                                            symmetric=False, inverse=False,
                                            blocks=basis.blocks)
        ms = self.ms
        rounding = np.finfo(float).eps * float(np.max(np.abs(ms.gamma), initial=0.0))
        if rounding > MODAL_ROUNDING_SHARE * tol:
            raise UnresolvedOperator(
                f"operator: its modes reach {rounding / np.finfo(float).eps:.1e} (m down "
                f"to {float(np.min(m)):.1e}, a nearly first-kind equation) and their "
                f"rounding {rounding:.1e} exceeds 0.1 tol; the grid does not resolve the problem")
        self.gap = ms.rotate(-basis.transposed_times(s_in * grid.g))
        self.k = len(ms.known)
        self.constraint_inv = np.linalg.inv(ms.constraint) if self.k else np.zeros((0, 0))
        # psi^-1 is needed on these few vectors only: one solve with psi (an LU) instead
        # of its inverse (0.6 ms at 142 modes). The modal drive of a unit settlement and
        # tilt: a load history then costs an outer product, not a solve at every time read
        r_fk = ms.r_rot[np.ix_(ms.free, ms.known)]
        # (with a probe vector taken through psi and back: nearly dependent modes map
        # every march back wrongly, and no comparison of two time grids sees it)
        probe = mode_probe(ms.free.size)
        drives = np.linalg.solve(ms.psi, np.column_stack(
            [self.gap[ms.free], ms.e0_rot[ms.free], ms.e1_rot[ms.free], ms.psi @ probe,
             r_fk]))
        #: the probe's relative defect, carried in the answers' time error
        self.mode_defect = check_mode_probe(drives[:, 3], probe,
                                            max(MODAL_ROUNDING_SHARE * tol, PROBE_FLOOR))
        self.gap_free, self.settlement_free, self.tilt_free = drives[:, :3].T.copy()
        self.coupling = drives[:, 4:] if self.k else np.zeros((len(ms.free), 1))
        # nodal values of the modal coordinates (free) and of the known ones, with the
        # rotation and psi folded in: a history then costs one product with the nodes
        # instead of psi, the rotation and the nodes in turn (two N x N x T products)
        # T (identity but for its first 2 x 2 block) applied to psi and to the known
        # columns, then Q and the column scaling: O(N F) besides the reflections
        modes = np.zeros((ms.n, ms.free.size))
        modes[ms.free] = ms.psi
        self.node_modes = s_out[:, None] * basis.times(ms.to_coefficients(modes))
        known_cols = np.zeros((ms.n, ms.known.size))
        known_cols[ms.known, np.arange(ms.known.size)] = 1.0
        self.node_known = s_out[:, None] * basis.times(ms.to_coefficients(known_cols))
        self.nodes = (self.node_modes, self.node_known)
        self.known_modes = (ms.r_rot[np.ix_(ms.known, ms.free)] @ ms.psi if self.k
                            else np.zeros((0, len(ms.free))))
        self.e0 = np.zeros(grid.size)
        self.e1 = np.zeros(grid.size)
        self.e0[0] = np.sqrt(moments[0])
        self.e1[0] = moments[1] / np.sqrt(moments[0])
        self.e1[1] = np.sqrt((moments[0] * moments[2] - moments[1] ** 2) / moments[0])

    def known(self, loads: dict[str, np.ndarray], size: int) -> np.ndarray:
        """Known coordinates from the given force and moment, shape (max(k, 1), T)."""
        if not self.k:
            return np.zeros((1, size))
        return self.constraint_inv @ np.array([loads[name]
                                               for name in self.ms.constraint_names])

    def drive(self, loads: dict[str, np.ndarray], size: int, gap: float = 1.0) -> np.ndarray:
        """Modal drive of the given settlement and tilt and of ``gap`` times the gap (F, T)."""
        out = np.broadcast_to(gap * self.gap_free[:, None], (self.gap_free.size, size))
        if "settlement" in loads:
            out = out + np.outer(self.settlement_free, loads["settlement"])
        if "tilt" in loads:
            out = out + np.outer(self.tilt_free, loads["tilt"])
        return np.array(out)

    def finish(self, c_t: np.ndarray, loads: dict[str, np.ndarray], known: np.ndarray,
               z: np.ndarray, vz: np.ndarray, vu: np.ndarray, gap: float = 1.0
               ) -> tuple[Callable[[], np.ndarray], tuple[np.ndarray, np.ndarray], dict]:
        """Nodal pressures (formed when called), ``q - V q`` in modal coordinates (free,
        known; see :class:`ModalAnswer`) and the four scalars."""
        ms, k = self.ms, self.k
        size = c_t.size

        def nodal() -> np.ndarray:
            out = self.node_modes @ z
            return out + self.node_known @ known[:k] if k else out

        z_eff = z - vz
        known_eff = known[:k] - vu[:k]
        out = {name: np.asarray(v, dtype=float) for name, v in loads.items()}
        if k:
            # Known rows: c b_K + (I - V)[R_KF b_F + R_KK b_K] = drive_K + unknown drive.
            r_kk = ms.r_rot[np.ix_(ms.known, ms.known)]
            lhs = (c_t[None, :] * known[:k] + self.known_modes @ z_eff
                   + r_kk @ known_eff - gap * self.gap[ms.known][:, None]
                   - self.ms.given_drive(ms.known, loads, size))
            unknowns = np.linalg.solve(ms.unknown_rhs, lhs)
            for i, name in enumerate(ms.unknown_names):
                out[name] = unknowns[i]
        if "force" not in out or "moment" not in out:
            # e0 and e1 are zero past the first two coefficients: their rows of a = T b
            b2 = np.zeros((2, size))
            first = ms.free < 2
            b2[ms.free[first]] = ms.psi[first] @ z
            if k:
                b2[ms.known[ms.known < 2]] = known[:k][ms.known < 2]
            a2 = ms.rotation @ b2
            out.setdefault("force", self.e0[:2] @ a2)
            out.setdefault("moment", self.e1[:2] @ a2)
        return nodal, (z_eff, known_eff), out

    def solve(self, times: np.ndarray, c: Function, kernel, loads: dict[str, Function],
              time_tol: float, gap: float = 1.0, breaks: np.ndarray | None = None
              ) -> ModalAnswer:
        """The answer at ``times`` for relative modulus ``c(t)`` and creep kernel ``kernel``.

        ``gap`` scales the gap's drive (0: the response to the loads alone); ``breaks``
        are times where a load jumps, which the time steps land on.
        """
        return self.solve_parts(times, c, kernel, [(loads, gap)], time_tol, breaks)[0]

    def solve_parts(self, times: np.ndarray, c: Function, kernel,
                    parts: list[tuple[dict[str, Function], float]], time_tol: float,
                    breaks: np.ndarray | None = None) -> list[ModalAnswer]:
        """:meth:`solve` for several ``(loads, gap)`` at once, in one time march.

        The parts share ``c``, the kernel and the times, so their modal equations are
        stepped together as one problem with the modes of every part (the force part and
        the moment part of a load in one pass). Each part's error is measured against its
        own size (``ModalProblem.parts``), as in a march of its own.
        """
        c_t = c(times)
        values = [{name: fn(times) for name, fn in loads.items()} for loads, _ in parts]
        known = [self.known(v, times.size) for v in values]
        gamma = self.ms.gamma
        if kernel is None:
            answers = []
            for (_, gap), vals, kn in zip(parts, values, known, strict=True):
                z = (self.drive(vals, times.size, gap) - self.coupling @ kn) / (
                    c_t[None, :] + gamma[:, None])
                nodal, effective, scalars = self.finish(c_t, vals, kn, z, np.zeros_like(z),
                                                        np.zeros_like(kn), gap)
                answers.append(ModalAnswer(nodal, effective, self.nodes, scalars, 0.0, 0, True,
                                           "no creep: no time stepping"))
            return answers
        n_parts, n_free, n_known = len(parts), gamma.size, self.coupling.shape[1]
        memo: dict[bytes, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        single = self.coupling / gamma[:, None]
        # the drives over gamma, once: each history is then one product and a few
        # outer products written into its rows (no (F, T) temporaries a part)
        per_gamma = {"gap": self.gap_free / gamma, "settlement": self.settlement_free / gamma,
                     "tilt": self.tilt_free / gamma}

        def evaluate(tt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            key = tt.tobytes()
            if key not in memo:
                memo.clear()
                d = 1.0 + c(tt)[None, :] / gamma[:, None]
                r = np.empty((n_parts * n_free, tt.size))
                us = []
                for p, (loads, gap) in enumerate(parts):
                    ld = {name: fn(tt) for name, fn in loads.items()}
                    u = self.known(ld, tt.size)
                    rows = r[p * n_free:(p + 1) * n_free]
                    # (drive - coupling u) / gamma
                    np.matmul(-single, u, out=rows)
                    if gap:
                        rows += gap * per_gamma["gap"][:, None]
                    for name in ("settlement", "tilt"):
                        if name in ld:
                            rows += np.multiply.outer(per_gamma[name], ld[name])
                    us.append(u)
                memo[key] = (np.tile(d, (n_parts, 1)) if n_parts > 1 else d, r,
                             np.concatenate(us))
            return memo[key]

        problem = ModalProblem(d=lambda tt: evaluate(tt)[0], r=lambda tt: evaluate(tt)[1],
                               u=lambda tt: evaluate(tt)[2],
                               coupling=(np.kron(np.eye(n_parts), single) if n_parts > 1
                                         else single), parts=n_parts)
        jumps = tuple(np.asarray(breaks, dtype=float).tolist()) if breaks is not None else ()
        if hasattr(kernel, "rates") and hasattr(kernel, "exponential_parts"):
            sol = solve_degenerate(kernel, problem, times, tol=time_tol, breaks=jumps)
        else:
            sol = solve_general(kernel, problem, times, tol=time_tol, breaks=jumps)
        # each part's estimate relative to its own size (the largest when not given)
        estimates = sol.part_errors or (sol.error_estimate,) * n_parts
        answers = []
        for p, (_, gap) in enumerate(parts):
            rows = slice(p * n_free, (p + 1) * n_free)
            known_rows = slice(p * n_known, (p + 1) * n_known)
            nodal, effective, scalars = self.finish(c_t, values[p], known[p], sol.w[rows],
                                                    sol.vw[rows], sol.vu[known_rows], gap)
            answers.append(ModalAnswer(nodal, effective, self.nodes, scalars,
                                       float(estimates[p]),
                                       int(sol.steps), bool(sol.success), sol.message))
        return answers
