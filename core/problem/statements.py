"""The four statements of the problem and the modal decomposition of each.

Given two of settlement ``delta``, tilt ``alpha``, force ``P`` and moment ``M`` (seed,
section 3), find the other two and the pressure. With ``m q = -g/c + sum_j a_j p_j``
(``p_j`` orthonormal for ``1/m``, ``p_0 ~ 1``, ``p_1 ~ x``) the Galerkin rows read

    c a_i + (I - V)[sum_j R_ij a_j - G_i / c] = delta e0_i + alpha e1_i,
    P = e0 . a - (1/c) int g/m,      M = e1 . a - (1/c) int x g/m,

with ``e0_i = <1, p_i>`` and ``e1_i = <x, p_i>``, both zero for ``i >= 2``. A given force
or moment fixes one combination of ``(a_0, a_1)``. We rotate the plane of ``(a_0, a_1)`` so
that each fixed combination is one *known* coordinate and the rest are *free*; by
construction the unknown one of ``delta, alpha`` then appears only in the known rows.
The free block of ``R`` is diagonalized once, ``R_FF = Psi diag(gamma) Psi^T``, and each
modal coordinate obeys its own scalar Volterra equation (the seed's (13)-(17) for
statement 4, generalized). The known rows then give the unknown of ``delta, alpha``
explicitly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: The loads, in the order the histories are reported (the one definition; core.scene.pipeline
#: and the explorer import it from here).
QUANTITIES = ("settlement", "tilt", "force", "moment")

#: Statement number (seed, section 3) for each pair of given quantities.
STATEMENTS: dict[frozenset[str], int] = {
    frozenset({"settlement", "tilt"}): 1,
    frozenset({"settlement", "moment"}): 2,
    frozenset({"tilt", "force"}): 3,
    frozenset({"force", "moment"}): 4,
}


def statement_number(given: frozenset[str]) -> int:
    """The statement (1-4, numbered as in the seed) for a pair of given quantities.

    The pairs settlement+force and tilt+moment are not among the seed's statements and
    are refused (their unknown would enter the free rows of the decomposition below).
    """
    if len(given) != 2:
        raise ValueError(
            "given: exactly two of settlement, tilt, force, moment are needed, got "
            + (", ".join(sorted(given)) or "none")
        )
    if given not in STATEMENTS:
        raise ValueError(
            "given: " + " and ".join(sorted(given)) + " is not one of the four statements "
            "(settlement+tilt, settlement+moment, tilt+force, force+moment)"
        )
    return STATEMENTS[given]


class UnresolvedOperator(ValueError):
    """The discrete operator has no real, positive spectrum: it cannot be stepped in modal
    form. Seen with a Nystrom grid on a first-kind limit (no coating, m ~ 1e-15, thin
    base), where product integration leaves spurious complex eigenvalues near zero."""


@dataclass(frozen=True)
class ModalSystem:
    """The decoupled form of one statement at ``n`` basis functions.

    Coefficients ``a = T b`` with ``T = blockdiag(Q, I)``; ``b[free] = psi @ z`` (modal
    coordinates ``z``, one per eigenvalue ``gamma``), ``b[known]`` from the given force and
    moment through ``constraint`` (``constraint @ b[known] = [P~, M~]`` for the given ones).
    ``unknown_rhs`` (k x k) multiplies the unknown of ``delta, alpha`` in the known rows.
    """

    given: frozenset[str]
    n: int
    rotation: np.ndarray  # Q (2 x 2)
    free: np.ndarray
    known: np.ndarray
    gamma: np.ndarray
    psi: np.ndarray
    r_rot: np.ndarray  # T^T R T
    e0_rot: np.ndarray
    e1_rot: np.ndarray
    constraint: np.ndarray  # (k x k)
    constraint_names: tuple[str, ...]  # which of force, moment each row fixes
    unknown_names: tuple[str, ...]  # which of settlement, tilt the known rows determine
    unknown_rhs: np.ndarray  # (k x k)
    #: ``psi^-1``: ``psi.T`` for a symmetric ``R``; the inverse for a Nystrom ``R`` (None
    #: when not asked for).
    psi_inv: np.ndarray | None = None

    def to_coefficients(self, b: np.ndarray) -> np.ndarray:
        """Map rotated coefficients ``b`` (n, ...) back to ``a = T b``."""
        a = b.copy()
        a[:2] = np.tensordot(self.rotation, b[:2], axes=(1, 0))
        return a

    def given_drive(self, rows: np.ndarray, loads: dict[str, np.ndarray],
                    size: int) -> np.ndarray:
        """``delta e0 + alpha e1`` (of the given ones) in the rotated ``rows``, shape
        ``(len(rows), size)`` for load histories over ``size`` times (dimensionless)."""
        out = np.zeros((len(rows), size))
        if "settlement" in loads:
            out += np.outer(self.e0_rot[rows], loads["settlement"])
        if "tilt" in loads:
            out += np.outer(self.e1_rot[rows], loads["tilt"])
        return out

    def rotate(self, v: np.ndarray) -> np.ndarray:
        """``T^T v`` for a vector over the basis (n,)."""
        out = v.copy()
        out[:2] = self.rotation.T @ v[:2]
        return out


def check_mode_probe(back: np.ndarray, probe: np.ndarray, limit: float) -> float:
    """Refuse modes that are nearly dependent; the probe's relative defect otherwise.

    A mode matrix whose columns are nearly dependent maps every modal march back
    wrongly, and no comparison of two time grids sees it (both pass through its
    inverse): the probe vector taken through ``psi`` and back must come back.

    Parameters
    ----------
    back : numpy.ndarray
        ``psi^-1 (psi @ probe)`` as the caller's inverse or factors give it.
    probe : numpy.ndarray
        The probe vector (:func:`mode_probe`).
    limit : float
        The largest relative defect allowed (a share of tol).

    Returns
    -------
    float
        How far the probe came back, relative to its size (at most ``limit``).

    Raises
    ------
    UnresolvedOperator
        When the probe comes back more than ``limit`` times its size off.
    """
    defect = float(np.max(np.abs(back - probe), initial=0.0))
    size = float(np.max(np.abs(probe), initial=1.0))
    if defect > limit * size:
        raise UnresolvedOperator(
            f"operator: its modes are nearly dependent (a probe vector comes back "
            f"{defect:.1e} off); the grid does not resolve the problem")
    return defect / size


def mode_probe(size: int) -> np.ndarray:
    """The probe vector of :func:`check_mode_probe` (fixed: the same answer every run)."""
    return np.random.default_rng(0).standard_normal(size)


def real_modes(gamma: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Real eigenvectors from those of ``np.linalg.eig``.

    A nearly double eigenvalue may come out as a complex pair ``a +- ib`` (``b`` at
    rounding) with eigenvectors ``v, conj(v)``: their real parts are one vector twice, so
    ``psi.real`` is singular and its inverse garbage (measured: cond 1e17 and a settlement
    off by 60 % on a grid of 622 modes, where the operator's rounding alone decided
    between a real and a complex pair; two equal punches, cond 1.6e16). ``Re v`` and
    ``Im v`` span the same invariant plane; on it the matrix is ``a`` up to the rotation
    ``b``, which the callers bound (imaginary parts below 1e-8 of the largest eigenvalue).

    Parameters
    ----------
    gamma : numpy.ndarray
        The eigenvalues (complex), as ``np.linalg.eig`` returns them.
    psi : numpy.ndarray
        The eigenvectors, one per column, in the same order.

    Returns
    -------
    numpy.ndarray
        Real eigenvectors of unit length, one per column: ``Re v`` and ``Im v`` for a pair.
    """
    out = psi.real.copy()
    # LAPACK returns a pair next to each other, the one with positive imaginary part first
    for j in np.nonzero(gamma.imag > 0)[0]:
        out[:, j + 1] = psi[:, j].imag
    norms = np.linalg.norm(out, axis=0)
    return out / np.where(norms > 0, norms, 1.0)[None, :]


def _rotated_groups(blocks: tuple[np.ndarray, ...] | None, rotation: np.ndarray, n: int
                    ) -> np.ndarray | None:
    """The group of each rotated coordinate (n,), or None where there are no groups or the
    rotation mixes two of them (it then takes each of the first two coordinates from
    one basis function alone, exactly)."""
    if blocks is None:
        return None
    label = np.full(n, -1)
    for g, members in enumerate(blocks):
        label[np.asarray(members)] = g
    if np.any(label < 0):
        raise ValueError("blocks: every basis function must be in one group")
    rotated = label.copy()
    for j in range(2):
        column = np.abs(rotation[:, j])
        if np.count_nonzero(column) != 1:
            return None
        rotated[j] = label[int(np.argmax(column))]
    return rotated


def _free_modes(r_rot: np.ndarray, free: np.ndarray, groups: np.ndarray | None
                ) -> tuple[np.ndarray, np.ndarray]:
    """``eig`` of the free block (gamma, psi), group by group where ``groups`` are given
    (``psi`` block-diagonal), with real eigenvectors; ``UnresolvedOperator`` where the
    eigenvalues are not real and positive."""
    parts = ([np.arange(free.size)] if groups is None
             else [np.flatnonzero(groups[free] == g) for g in np.unique(groups[free])])
    gamma = np.empty(free.size, dtype=complex)
    psi = np.zeros((free.size, free.size))
    for part in parts:
        values, vectors = np.linalg.eig(r_rot[np.ix_(free[part], free[part])])
        gamma[part] = values
        psi[np.ix_(part, part)] = real_modes(values, vectors)
    scale = float(np.max(np.abs(gamma))) if gamma.size else 1.0
    if gamma.size and (np.max(np.abs(gamma.imag)) > 1e-8 * scale or np.min(gamma.real) <= 0):
        raise UnresolvedOperator("operator: eigenvalues not real and positive; the grid does "
                                 "not resolve the problem")
    return gamma.real, psi


def modal_system(r_matrix: np.ndarray, moments: tuple[float, float, float],
                 given: frozenset[str], n: int, *, symmetric: bool = True,
                 inverse: bool = True, blocks: tuple[np.ndarray, ...] | None = None
                 ) -> ModalSystem:
    """Build the decoupled system for a statement at ``n`` functions of the basis.

    ``r_matrix`` is the Galerkin matrix ``R`` (at least n x n, symmetric positive definite);
    ``moments`` are ``J_0, J_1, J_2``. With ``symmetric=False`` (the Nystrom matrix, whose
    product-integration rows are not symmetric) the free block is diagonalized as it is,
    ``R_FF = psi diag(gamma) psi^-1``; its eigenvalues are real and positive up to
    round-off (the operator is similar to a symmetric positive one), else ``ValueError``;
    ``inverse=False`` leaves ``psi_inv`` None (a caller that applies it to a few vectors
    solves with ``psi`` instead of inverting it). ``blocks``: groups of the basis
    functions (indices, together 0 .. n-1) between which ``R`` has no entries, as a
    geometry symmetric about the punch's centre gives its even and odd functions; each
    group's free block is then diagonalized on its own (``psi`` block-diagonal in their
    order), which ``eig`` does in a fraction of the time (half the size: ~1/2 of the CPU
    measured at 288 modes, ~1/3 at 128). They are used only where the rotation below keeps
    them apart (``J_1 = 0``, as such a geometry has it).
    """
    statement_number(given)
    j0, j1, j2 = moments
    e0 = np.zeros(n)
    e1 = np.zeros(n)
    e0[0] = np.sqrt(j0)
    e1[0] = j1 / np.sqrt(j0)
    e1[1] = np.sqrt((j0 * j2 - j1 * j1) / j0)
    constraint_names = tuple(q for q in ("force", "moment") if q in given)
    unknown_names = tuple(q for q in ("settlement", "tilt") if q not in given)
    rows = {"force": e0[:2], "moment": e1[:2]}
    k = len(constraint_names)
    if k == 0:
        rotation = np.eye(2)
        free = np.arange(n)
        known = np.arange(0)
    elif k == 2:
        rotation = np.eye(2)
        free = np.arange(2, n)
        known = np.array([0, 1])
    else:
        c = rows[constraint_names[0]]
        vk = c / np.linalg.norm(c)
        vf = np.array([-vk[1], vk[0]])
        rotation = np.column_stack([vf, vk])
        free = np.concatenate([[0], np.arange(2, n)])
        known = np.array([1])
    t = np.eye(n)
    t[:2, :2] = rotation
    # T^T R T with T = blockdiag(Q, I): only the first two rows and columns change
    r_rot = np.array(r_matrix[:n, :n], dtype=float)
    r_rot[:2, :] = rotation.T @ r_rot[:2, :]
    r_rot[:, :2] = r_rot[:, :2] @ rotation
    e0_rot = t.T @ e0
    e1_rot = t.T @ e1
    if symmetric:
        r_rot = 0.5 * (r_rot + r_rot.T)
        gamma, psi = np.linalg.eigh(r_rot[np.ix_(free, free)])
        psi_inv = psi.T
    else:
        gamma, psi = _free_modes(r_rot, free, _rotated_groups(blocks, rotation, n))
        psi_inv = np.linalg.inv(psi) if inverse else None
    constraint = np.array([[(e0_rot if name == "force" else e1_rot)[i] for i in known]
                           for name in constraint_names]).reshape(k, k)
    unknown_rhs = np.array([[(e0_rot if name == "settlement" else e1_rot)[i]
                             for name in unknown_names] for i in known]).reshape(k, k)
    return ModalSystem(given, n, rotation, free, known, gamma, psi, r_rot, e0_rot, e1_rot,
                       constraint, constraint_names, unknown_names, unknown_rhs, psi_inv)
