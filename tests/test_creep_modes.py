"""The modes of the creeping Nystrom operator: eigh of the symmetric part refined by Newton."""

import numpy as np
import pytest

import core
from core.creep_modes import near_symmetric_modes
from core.statements import UnresolvedOperator, _nonsymmetric_modes


def _check_decomposition(a: np.ndarray, modes) -> None:
    gamma, psi, psi_inv = modes
    n = a.shape[0]
    # a few hundred ulp, as eig leaves (2.5e-15 and 7.8e-16 measured on the aging scene)
    assert np.max(np.abs(a @ psi - psi * gamma)) <= 1e-12 * np.max(np.abs(a))
    assert np.max(np.abs(psi_inv @ psi - np.eye(n))) <= 1e-12
    reference = np.sort(np.linalg.eigvals(a).real)
    # measured 7.3e-15 of the largest eigenvalue on the aging scene
    assert np.max(np.abs(np.sort(gamma) - reference)) <= 1e-12 * np.max(np.abs(reference))


def test_nearly_symmetric_matrix_matches_eig():
    rng = np.random.default_rng(3)
    n = 60
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    symmetric = q @ np.diag(np.linspace(1e-3, 5.0, n)) @ q.T
    a = symmetric + 1e-4 * rng.standard_normal((n, n))
    modes = near_symmetric_modes(a)
    assert modes is not None
    _check_decomposition(a, modes)


def test_operator_of_a_creep_scene_matches_eig():
    """The free block of the aging creep scene's Nystrom operator (antisymmetric part 7e-4
    of the whole) is decomposed by the refinement, not by the fallback."""
    from benchmarks.scenes import suite

    scene = next(s for s in suite() if s.key == "aging_creep")
    prepared = core.prepare(scene.lam, scene.m, scene.g, tol=1e-6)
    ms = prepared.modal(frozenset({"force", "moment"})).ms
    block = ms.r_rot[np.ix_(ms.free, ms.free)]
    modes = near_symmetric_modes(block)
    assert modes is not None
    _check_decomposition(block, modes)
    assert np.allclose(np.sort(ms.gamma), np.sort(modes[0]), rtol=0, atol=1e-13)


def test_far_from_symmetric_falls_back_to_eig():
    # real eigenvalues 1 and 2, but nothing like its symmetric part's modes
    a = np.array([[1.0, 5.0], [0.0, 2.0]])
    assert near_symmetric_modes(a) is None
    gamma, psi, psi_inv = _nonsymmetric_modes(a)
    assert np.allclose(np.sort(gamma), [1.0, 2.0], rtol=0, atol=1e-14)
    assert np.allclose(psi_inv @ a @ psi, np.diag(gamma), rtol=0, atol=1e-13)


def test_complex_or_negative_modes_are_refused():
    rotation = np.array([[1.0, 2.0], [-2.0, 1.0]])  # eigenvalues 1 +- 2i
    with pytest.raises(UnresolvedOperator, match="operator"):
        _nonsymmetric_modes(rotation)
    with pytest.raises(UnresolvedOperator, match="operator"):
        _nonsymmetric_modes(np.diag([1.0, -1.0]))
