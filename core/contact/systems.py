"""The bordered systems of the nodal active set, and their solver that keeps factors.

On the contact nodes ``idx`` of a panel rule (q = 0 elsewhere) one solve is

    (c m + s F) q - delta - alpha x = rhs   on idx,   int q = P,  int x q = M

with the unknown ones of delta, alpha as border columns and the given ones of P, M as
border rows (:func:`bordered_solve`). :class:`StepSolver` carries the LU factors from one
creep step to the next, also across a few contact nodes gained or lost
(:class:`_FactorUpdate`). A solver made with a :class:`Mirror` solves a problem even in
x on the nodes x > 0 alone.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.linalg import lu_factor
from scipy.linalg.lapack import dgetrs

from core.discretize import even_overall, even_per_node, mirrored_rule


def restrict(op: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """``op`` on the nodes ``idx`` (sorted): a view when they are one run of nodes (one
    contact zone, the usual case: no copy of the block), a copy otherwise, made block by
    block when the nodes form a few runs (several zones)."""
    if idx.size and int(idx[-1]) - int(idx[0]) + 1 == idx.size:
        return op[idx[0]:idx[-1] + 1, idx[0]:idx[-1] + 1]
    cuts = np.flatnonzero(np.diff(idx) != 1) + 1
    if not idx.size or cuts.size >= MAX_RUNS:
        return op[np.ix_(idx, idx)]
    # slices copy at the memory's speed, fancy indexing ~3x slower: 6.6 of the 44 s of a
    # stepped punch whose outer steps come into contact (three zones, ~2000 nodes)
    starts, stops = np.r_[0, cuts], np.r_[cuts, idx.size]
    runs = [(int(a), int(b), slice(int(idx[a]), int(idx[b - 1]) + 1))
            for a, b in zip(starts, stops, strict=True)]
    out = np.empty((idx.size, idx.size), dtype=op.dtype)
    for a0, a1, rows in runs:
        for b0, b1, cols in runs:
            out[a0:a1, b0:b1] = op[rows, cols]
    return out


#: Runs of consecutive nodes up to which :func:`restrict` copies block by block.
MAX_RUNS = 16


@dataclass(frozen=True)
class Mirror:
    """The even half of a unilateral problem symmetric about x = 0.

    On a panel rule symmetric about 0 (``2 h`` nodes, none at 0: 16 per panel), with F,
    the coating compliance m and the gap g even and a centred load (moment or tilt 0),
    the pressure is even: q at node ``i < h`` is q at its mirror ``2 h - 1 - i``. The
    bordered systems are then solved for the nodes x > 0 alone, with F folded,
    ``F[h:, h:] + F[h:, :h]`` with its columns mirrored (:attr:`op`), the force row's
    weights doubled and no tilt: a quarter of the entries (a factorization ~8x
    cheaper), and answers even to the last digit. The rule must be symmetric itself:
    ``core.contact.bands.even_rule`` makes it so (the band rule of a stepped punch under
    a centred force was 7e-4 half-widths off, and its answer 1.2e-10 asymmetric in q).
    """

    half: int
    op: np.ndarray  # (h, h): F folded onto the nodes x > 0

    @classmethod
    def of(cls, x: np.ndarray, w: np.ndarray, op: np.ndarray, m: np.ndarray,
           g: np.ndarray) -> Mirror | None:
        """The mirror of the rule with nodes ``x``, weights ``w`` and operator ``op`` for
        the node values ``m`` and ``g``, or None when one of them is not symmetric
        (:func:`~core.discretize.mirrored_rule`, m node by node and g and F overall to
        :data:`~core.discretize.MIRROR_TOL`)."""
        n = x.size
        if (n % 2 or n == 0 or not mirrored_rule(x, w) or not even_per_node(m, m[::-1])
                or not even_overall(g, g[::-1])):
            return None
        h = n // 2
        # (by halves: the whole mirrored matrix at once would be a copy of F)
        for rows in (slice(0, h), slice(h, n)):
            if not even_overall(op[rows], op[::-1, ::-1][rows]):
                return None
        folded = op[h:, h:] + op[h:, :h][:, ::-1]
        folded.flags.writeable = False
        return cls(h, folded)

    def fold_nodes(self, idx: np.ndarray) -> np.ndarray | None:
        """The contact nodes ``idx`` (sorted) on the half x > 0, counted from its first
        node; None when ``idx`` is not symmetric."""
        h = self.half
        right = idx[idx >= h]
        if right.size * 2 != idx.size or not np.array_equal(idx[:right.size],
                                                          2 * h - 1 - right[::-1]):
            return None
        return right - h

    def even(self, values: np.ndarray) -> np.ndarray:
        """The even part of node ``values`` on the half x > 0."""
        h = self.half
        return 0.5 * (values[h:] + values[:h][::-1])

    def unfold(self, half_values: np.ndarray) -> np.ndarray:
        """The even node values whose half x > 0 is ``half_values``."""
        return np.concatenate([half_values[::-1], half_values])

    def apply(self, q: np.ndarray) -> np.ndarray:
        """``F q`` at the nodes x > 0 for an even ``q`` (the nodes x < 0: its mirror)."""
        return self.op @ q[self.half:]

    @staticmethod
    def given(given: dict[str, float]) -> dict[str, float]:
        """The given ones of a centred statement on the half: force (or settlement), and
        the tilt 0 (a moment of 0 holds by symmetry)."""
        out = {name: given[name] for name in ("settlement", "force") if name in given}
        out["tilt"] = 0.0
        return out

    @staticmethod
    def centred(given: Sequence[str], loads: dict[str, np.ndarray]) -> bool:
        """Whether the loads ``loads`` (given ones, by name, at every time) are centred:
        a moment or a tilt of 0 throughout, with a force or a settlement."""
        zero = [name for name in ("moment", "tilt")
                if name in given and not np.any(np.asarray(loads[name]) != 0.0)]
        return len(zero) == 1 and len(set(given) & {"force", "settlement"}) == 1


def _lu_solve(lu: tuple[np.ndarray, np.ndarray], r: np.ndarray) -> np.ndarray:
    """``r`` solved with the LU factors ``lu`` (of ``lu_factor``). LAPACK directly: the
    checked wrapper costs more than the O(N^2) solve here."""
    x, _ = dgetrs(lu[0], lu[1], r)
    return x


@dataclass(frozen=True)
class BorderedLayout:
    """The bordered matrix of one step over all nodes of a panel rule, read by blocks.

    Its indices: node ``i`` is ``i``, border unknown ``t`` (an unknown settlement or
    tilt as a column, a given force or moment as a row; :func:`_bordered_system`) is
    ``n + t``. The matrix is ``op + diag(diagonal)`` between nodes, ``border_cols`` from
    the border unknowns into the nodes' rows, ``border_rows`` from the nodes into the
    border rows, and 0 between border entries. ``idx``: the contact nodes of the system
    solved (its indices are ``idx`` and then the border's)."""

    op: np.ndarray
    diagonal: np.ndarray      # (c / s) m at every node
    border_cols: np.ndarray   # (n, k)
    border_rows: np.ndarray   # (k, n)
    idx: np.ndarray

    @property
    def indices(self) -> np.ndarray:
        n, k = self.op.shape[0], self.border_cols.shape[1]
        return np.concatenate([self.idx, n + np.arange(k)])

    def block(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """The matrix's entries in ``rows`` and ``cols`` (indices as above)."""
        n = self.op.shape[0]
        node_r, node_c = rows < n, cols < n
        r, c = rows[node_r], cols[node_c]
        out = np.zeros((rows.size, cols.size))
        nodes = self.op[np.ix_(r, c)]
        same = r[:, None] == c[None, :]
        if same.any():
            nodes = nodes + np.where(same, self.diagonal[r][:, None], 0.0)
        out[np.ix_(node_r, node_c)] = nodes
        out[np.ix_(node_r, ~node_c)] = self.border_cols[np.ix_(r, cols[~node_c] - n)]
        out[np.ix_(~node_r, node_c)] = self.border_rows[np.ix_(rows[~node_r] - n, c)]
        return out


class _FactorUpdate:
    """The LU factors of one system made to solve another whose contact nodes differ by
    a few: an exact solve of the new system (up to its diagonal's drift since the
    factors, which the refinement takes out) from the old factors and a small Schur
    complement.

    With ``K`` the factored matrix on the indices ``A``, the new system on ``A'`` is the
    augmented one

        [[K, E_R, B], [E_R^T, 0, 0], [C, 0, D]] [z; r; y] = [b_A; 0; b_N]

    where ``R = A - A'`` (the nodes left: ``z_R = 0`` and their rows free, their
    multipliers ``r``), ``N = A' - A`` (the nodes gained: ``B = K[A, N]``,
    ``C = K[N, A]``, ``D = K[N, N]``); eliminating ``z`` with ``K``'s factors leaves a
    Schur system of ``|R| + |N|`` unknowns. ``K^-1`` of the columns ``E_R`` and ``B``
    are kept per anchor (:attr:`StepSolver._columns`) while its factors stay.
    """

    def __init__(self, solver: StepSolver, layout: BorderedLayout) -> None:
        anchor, new = solver._anchor, layout.indices
        # the factors themselves: a snapshot's update must outlive a refactoring
        self.lu = solver._lu
        in_old = np.isin(anchor, new)
        in_new = np.isin(new, anchor)
        self.kept_old = np.flatnonzero(in_old)          # positions in the anchor
        self.kept_new = np.flatnonzero(in_new)          # the same indices' positions here
        self.removed = np.flatnonzero(~in_old)          # positions in the anchor
        self.added = np.flatnonzero(~in_new)            # positions here
        added_ids = new[self.added]
        self.size = anchor.size
        columns = solver._columns
        wanted = [("out", int(p)) for p in self.removed] + [("in", int(j)) for j in added_ids]
        missing = [key for key in wanted if key not in columns]
        if missing:
            rhs = np.zeros((anchor.size, len(missing)))
            for col, (kind, value) in enumerate(missing):
                if kind == "out":
                    rhs[value, col] = 1.0
            gained = [col for col, (kind, _) in enumerate(missing) if kind == "in"]
            if gained:
                ids = np.array([missing[col][1] for col in gained])
                rhs[:, gained] = layout.block(anchor, ids)
            solved = self._back(rhs)
            solver.back_substitutions += len(missing)
            for col, key in enumerate(missing):
                columns[key] = solved[:, col]
        self.ku = (np.column_stack([columns[key] for key in wanted]) if wanted
                   else np.zeros((anchor.size, 0)))
        r = self.removed.size
        self.c = layout.block(added_ids, anchor)
        schur = np.zeros((len(wanted), len(wanted)))
        schur[r:, r:] = layout.block(added_ids, added_ids)
        schur[:r] -= self.ku[self.removed]
        schur[r:] -= self.c @ self.ku
        self.schur = lu_factor(schur, check_finite=False) if len(wanted) else None

    def _back(self, r: np.ndarray) -> np.ndarray:
        return _lu_solve(self.lu, r)

    def __call__(self, b: np.ndarray) -> np.ndarray:
        """The augmented system's solution for right-hand sides ``b`` (a vector, or
        columns) on the new indices."""
        b_old = np.zeros((self.size,) + b.shape[1:])
        b_old[self.kept_old] = b[self.kept_new]
        y0 = self._back(b_old)
        out = np.zeros_like(b, dtype=float)
        if self.schur is None:
            out[self.kept_new] = y0[self.kept_old]
            return out
        r = self.removed.size
        rhs = np.concatenate([-y0[self.removed], b[self.added] - self.c @ y0])
        s = _lu_solve(self.schur, rhs)
        z = y0 - self.ku @ s
        out[self.kept_new] = z[self.kept_old]
        out[self.added] = s[r:]
        return out


class StepSolver:
    """Solves the bordered systems of one panel rule, keeping the last factorization.

    Consecutive creep steps change only ``c`` and ``scale`` by a little, and the contact
    set by a few nodes at a time: the kept LU factors of the last matrix precondition a
    few steps of iterative refinement (each O(N^2)) instead of a new factorization
    (O(N^3)). Where the contact nodes changed since the factors were made (up to
    ``MAX_UPDATE`` of them gained or lost, the statement the same), the factors solve the
    new system through a small Schur complement (:class:`_FactorUpdate`; a crown whose
    zone grows node by node as the base creeps made a new factorization at 286 of its
    302 solves), on systems of ``UPDATE_MIN_SIZE`` unknowns and more. A new factorization
    is made when the refinement does not converge within ``_REFINE_STEPS`` steps, or took
    more than ``REFRESH_AFTER``.
    """

    _REFINE_STEPS = 12
    _RESIDUAL = 1e-13
    REFRESH_AFTER = 6
    CHANGE_RESIDUAL = 1e-9
    #: start the refinement from the line through the last two solutions
    EXTRAPOLATE = True
    #: Contact nodes gained or lost since the factors beyond which new ones are made (the
    #: Schur complement's columns cost a back-substitution each; the crowned default of
    #: ~1000 unknowns: 6.4, 6.0, 4.9 and 5.0 s of CPU at 16, 48, 96 and 160).
    MAX_UPDATE = 96
    #: Systems smaller than this are factored anew at every new contact set: there a
    #: factorization costs less than the update and the refinement steps it adds
    #: (measured, CPU: the lift-off preset's ~300 unknowns 0.37 s factored anew, 0.51 s
    #: updated; a crowned default of ~1000 6.6 -> 4.8 s, a receding heel of ~1200
    #: 14.6 -> 10.1 s; ~450-600 unknowns alike either way).
    UPDATE_MIN_SIZE = 400

    def __init__(self, mirror: Mirror | None = None) -> None:
        #: the systems are solved on the half x > 0 (all of a march's, and their changes)
        self.mirror = mirror
        self._key: tuple | None = None
        self._lu = None
        self._sub: np.ndarray | None = None  # F on the contact nodes of _key
        self._last: np.ndarray | None = None  # the last solution with these contact nodes
        self._prev: np.ndarray | None = None  # the one before it (same contact nodes)
        # The factors' own contact nodes and statement (_lu_key), their indices in the
        # layout (_anchor, None when they were made without one), K^-1 of the columns
        # an update asked for (_columns), and the solve of the current contact nodes
        # with them (_precondition: the factors themselves or an update).
        self._lu_key: tuple | None = None
        self._anchor: np.ndarray | None = None
        self._columns: dict[tuple[str, int], np.ndarray] = {}
        self._precondition: Callable[[np.ndarray], np.ndarray] | None = None
        self.factorizations = 0
        self.updates = 0
        self.back_substitutions = 0

    def submatrix(self, op: np.ndarray, idx: np.ndarray, key: tuple) -> np.ndarray:
        """``op`` restricted to the nodes ``idx`` (kept while the contact nodes stay)."""
        if self._key != key or self._sub is None:
            self._sub = restrict(op, idx)
            self._key = key
            self._last = None
            self._prev = None
            self._precondition = self._back if self._lu_key == key else None
        return self._sub

    def snapshot(self) -> StepSolver:
        """A solver holding this one's current factors and contact nodes (shared, not
        copied: a new factorization replaces them here, never changes them), so that a
        change on this step (:func:`bordered_change`) can be solved after later steps."""
        kept = StepSolver(self.mirror)
        kept._key, kept._lu, kept._sub, kept._last = self._key, self._lu, self._sub, self._last
        kept._lu_key, kept._anchor = self._lu_key, self._anchor
        # an update solves with the factors it was made from: the same ones, shared
        kept._precondition = (kept._back if self._precondition == self._back
                              else self._precondition)
        return kept

    def _back(self, r: np.ndarray) -> np.ndarray:
        return _lu_solve(self._lu, r)

    def _prepare(self, layout: BorderedLayout | None) -> Callable[[np.ndarray], np.ndarray] | None:
        """The solve of the current contact nodes with the kept factors, if they serve."""
        if self._precondition is not None or self._lu is None:
            return self._precondition
        if (layout is None or self._anchor is None or self._key is None
                or self._lu_key is None or self._lu_key[1] != self._key[1]
                or self._anchor.size < self.UPDATE_MIN_SIZE):
            return None
        new = layout.indices
        changed = (self._anchor.size + new.size
                   - 2 * np.intersect1d(self._anchor, new, assume_unique=True).size)
        if changed > self.MAX_UPDATE:
            return None
        self._precondition = _FactorUpdate(self, layout)
        self.updates += 1
        return self._precondition

    def solve(self, build: Callable[[], np.ndarray], apply: Callable[[np.ndarray], np.ndarray],
              b: np.ndarray, layout: BorderedLayout | None = None) -> np.ndarray:
        """Solve ``A x = b`` for the matrix ``build()`` whose product is ``apply``.

        The refinement starts from the last solution on the same contact nodes (the next
        step's is close to it; extrapolated from the last two when there are two) and
        stops at a residual of ``_RESIDUAL`` relative to ``b``. ``layout``: the system
        in the indices of all nodes, with which factors of other contact nodes serve.
        """
        if self._lu is None and self._sub is not None and self._last is not None:
            self._factor(build, layout)
        precondition = self._prepare(layout)
        if precondition is not None:
            scale = max(float(np.abs(b).max()), 1e-300)
            if self._last is None:
                x = precondition(b)
            elif self._prev is not None and self.EXTRAPOLATE:
                # the solutions of successive steps change smoothly: their line starts
                # the refinement closer than the last alone (in the 202-step march of
                # the lift-off preset 816 -> 728 back-substitutions)
                x = 2.0 * self._last - self._prev
            else:
                x = self._last
            for count in range(self._REFINE_STEPS):
                r = b - apply(x)
                if float(np.abs(r).max()) <= self._RESIDUAL * scale:
                    self._prev, self._last = self._last, x
                    if count > self.REFRESH_AFTER:
                        self._drop_factors()  # c/s has drifted: new factors next time
                    return x
                x = x + precondition(r)
                self.back_substitutions += 1
        self._factor(build, layout)
        self._last = self._back(b)
        self._prev = None
        return self._last

    def _drop_factors(self) -> None:
        self._lu = self._lu_key = self._anchor = self._precondition = None
        self._columns = {}

    def _factor(self, build: Callable[[], np.ndarray], layout: BorderedLayout | None = None
                ) -> None:
        self._drop_factors()
        self._lu = lu_factor(build(), check_finite=False)
        self._lu_key = self._key
        self._anchor = None if layout is None else layout.indices
        self._precondition = self._back
        self.factorizations += 1

    def solve_change(self, build: Callable[[], np.ndarray],
                     apply: Callable[[np.ndarray], np.ndarray], b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` for a small change ``b`` of a right-hand side just solved on
        the same contact nodes: refinement from zero with the kept factors to a residual
        of ``CHANGE_RESIDUAL`` relative to ``b`` (the change is itself small, so its
        error enters the total far below ``_RESIDUAL`` of it). The last solution and the
        factors are left as they were for the next step (new factors are kept only when
        there were none)."""
        if self._precondition is None:
            self._factor(build)
        precondition = self._precondition
        scale = max(float(np.abs(b).max()), 1e-300)
        x = precondition(b)
        self.back_substitutions += 1
        for _ in range(self._REFINE_STEPS):
            r = b - apply(x)
            if float(np.abs(r).max()) <= self.CHANGE_RESIDUAL * scale:
                return x
            x = x + precondition(r)
            self.back_substitutions += 1
        # the kept factors no longer precondition well (c/s drifted): exact ones
        return np.linalg.solve(build(), b)


def bordered_operator(sub: np.ndarray, diagonal: np.ndarray, border_cols: np.ndarray,
                      border_rows: np.ndarray
                      ) -> tuple[Callable[[], np.ndarray], Callable[[np.ndarray], np.ndarray]]:
    """``build()``, the bordered matrix ``[[diag + sub, cols], [rows, 0]]``, and
    ``apply(z)``, its product with ``z`` without building it (the refinement of
    :meth:`StepSolver.solve` needs only products)."""
    n, k = sub.shape[0], border_cols.shape[1]

    def build() -> np.ndarray:
        a = np.zeros((n + k, n + k))
        a[:n, :n] = sub
        a[np.arange(n), np.arange(n)] += diagonal
        a[:n, n:] = border_cols
        a[n:, :n] = border_rows
        return a

    def apply(z: np.ndarray) -> np.ndarray:
        zq = z[:n]
        top = diagonal * zq + sub @ zq + border_cols @ z[n:]
        return np.concatenate([top, border_rows @ zq])

    return build, apply


def _bordered_system(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray, c: float,
                     scale: float, given: Sequence[str], idx: np.ndarray,
                     solver: StepSolver | None):
    """(build, apply, layout) of the system on ``idx``, divided by ``scale``: see
    :func:`bordered_solve`; ``layout`` (:class:`BorderedLayout`, None without ``solver``)
    the same system over all nodes."""
    cols, rows = [], []
    if "settlement" not in given:
        cols.append(-np.ones(x.size))
    if "tilt" not in given:
        cols.append(-x)
    if "force" in given:
        rows.append(w)
    if "moment" in given:
        rows.append(w * x)
    k = len(cols)
    all_cols = np.array(cols).T.reshape(x.size, k)
    all_rows = np.array(rows).reshape(k, x.size)
    key = (idx.tobytes(), tuple(sorted(given)))
    sub = restrict(op, idx) if solver is None else solver.submatrix(op, idx, key)
    # Divided by the weight s of F, the system depends on c and s only through c/s (and
    # the border unknowns come out divided by s): kept factors then precondition the
    # next steps up to the change of c/s alone.
    ratio = c / scale
    build, apply = bordered_operator(sub, ratio * m[idx], all_cols[idx], all_rows[:, idx])
    layout = None if solver is None else BorderedLayout(op, ratio * m, all_cols, all_rows, idx)
    return build, apply, layout


def bordered_solve(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray, c: float,
                   scale: float, given: dict[str, float], rhs: np.ndarray, idx: np.ndarray,
                   solver: StepSolver | None = None) -> tuple[np.ndarray, float, float]:
    """Solve the equation on the nodes ``idx`` (q = 0 elsewhere) with the given loads.

    Returns (q on idx, settlement, tilt). ``rhs`` = ``delta_g + alpha_g x - g + e`` at all
    nodes (with the given ones of delta, alpha; 0 for the unknown ones). With a
    ``solver`` made for a :class:`Mirror`, solved on the half x > 0.
    """
    folded = _folded(solver, x, w, m, given, rhs, idx)
    if folded is not None:
        mirror, m_h, x_h, w_h, given_h, rhs_h, idx_h = folded
        q_h, delta, _ = bordered_solve(mirror.op, m_h, x_h, w_h, c, scale, given_h, rhs_h,
                                       idx_h, solver)
        return mirror.unfold(q_h), delta, 0.0
    build, apply, layout = _bordered_system(op, m, x, w, c, scale, tuple(given), idx, solver)
    extra = [given[name] for name in ("force", "moment") if name in given]
    b = np.concatenate([rhs[idx] / scale, extra])
    sol = (np.linalg.solve(build(), b) if solver is None
           else solver.solve(build, apply, b, layout))
    return _unpack(sol, idx.size, scale, given)


def bordered_change(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray, c: float,
                    scale: float, given: dict[str, float], rhs: np.ndarray,
                    idx: np.ndarray, solver: StepSolver) -> tuple[np.ndarray, float, float]:
    """The change of :func:`bordered_solve`'s answer when its ``rhs`` and given loads
    change by ``rhs`` and ``given`` (the system is linear; given settlement or tilt change
    by their entries), solved with the kept factors of ``solver`` to a residual of
    ``StepSolver.CHANGE_RESIDUAL`` of the change, and leaving its state for the next step.
    Returns (change of q on idx, of the settlement, of the tilt)."""
    folded = _folded(solver, x, w, m, given, rhs, idx)
    if folded is not None:
        mirror, m_h, x_h, w_h, given_h, rhs_h, idx_h = folded
        dq_h, d_delta, _ = bordered_change(mirror.op, m_h, x_h, w_h, c, scale, given_h,
                                           rhs_h, idx_h, solver)
        return mirror.unfold(dq_h), d_delta, 0.0
    build, apply, _ = _bordered_system(op, m, x, w, c, scale, tuple(given), idx, solver)
    extra = [given[name] for name in ("force", "moment") if name in given]
    b = np.concatenate([rhs[idx] / scale, extra])
    return _unpack(solver.solve_change(build, apply, b), idx.size, scale, given)


def _folded(solver: StepSolver | None, x: np.ndarray, w: np.ndarray, m: np.ndarray,
            given: dict[str, float], rhs: np.ndarray, idx: np.ndarray) -> tuple | None:
    """The system of :func:`bordered_solve` on the half x > 0 when ``solver`` was made
    for a :class:`Mirror` and is handed the whole rule: (mirror, m, x, doubled weights,
    given, even part of rhs, contact nodes) there; else None. The contact nodes of such
    a solver are symmetric (:func:`core.contact.active_set.nodal_active_set` keeps them
    so)."""
    mirror = None if solver is None else solver.mirror
    if mirror is None or x.size == mirror.half:  # (the half's own system)
        return None
    if x.size != 2 * mirror.half:
        # its kept systems are the half's: another rule's would be taken for them
        raise ValueError("a solver made for a mirrored rule is given another rule")
    idx_h = mirror.fold_nodes(idx)
    if idx_h is None:
        raise ValueError("contact nodes not symmetric in a mirrored solve")
    h = mirror.half
    return (mirror, m[h:], x[h:], 2.0 * w[h:], mirror.given(given), mirror.even(rhs),
            idx_h)


def _unpack(sol: np.ndarray, n: int, scale: float, given: dict[str, float]
            ) -> tuple[np.ndarray, float, float]:
    tail = list(sol[n:] * scale)
    delta = tail.pop(0) if "settlement" not in given else given["settlement"]
    alpha = tail.pop(0) if "tilt" not in given else given["tilt"]
    return sol[:n], float(delta), float(alpha)
