"""The Nystrom modal form of a grid symmetric about the punch's centre: its even and odd
modes are found apart (two eigendecompositions of half the size), and the answer is the
one found with all modes at once, to rounding."""

from __future__ import annotations

import numpy as np
import pytest

from core.cache import clear_caches
from core.presets import read_preset
from core.scene import solve


@pytest.mark.parametrize("n", [7, 8, 64])
def test_the_mirror_basis_is_orthonormal_and_starts_with_the_two_given_vectors(n):
    from core.engines.nystrom.modal import _MirrorBasis

    x = np.linspace(-1.0, 1.0, n)
    even = 1.0 + x ** 2
    basis = _MirrorBasis(np.column_stack([even, even * x]))
    q = basis.times(np.eye(n))
    # measured: 5.6e-16 at most (64 nodes)
    assert np.max(np.abs(q.T @ q - np.eye(n))) < 1e-14
    assert np.max(np.abs(q[:, 0] - even / np.linalg.norm(even))) < 1e-14
    assert np.max(np.abs(q[:, 1] - even * x / np.linalg.norm(even * x))) < 1e-14
    assert np.max(np.abs(basis.transposed_times(np.eye(n)) - q.T)) < 1e-14
    assert np.max(np.abs(basis.times_right(np.eye(n)) - q)) < 1e-14


def _answer(scene, monkeypatch, mirror: bool):
    import core.engines.nystrom.modal as modal

    sizes: list[int] = []
    eig = np.linalg.eig

    def counted(a):
        sizes.append(a.shape[0])
        return eig(a)

    clear_caches()
    with monkeypatch.context() as patch:
        patch.setattr(np.linalg, "eig", counted)
        if not mirror:
            patch.setattr(modal, "mirrored", lambda grid: False)
        result = solve(scene)
    clear_caches()
    return result, sizes


def _statement(name: str, given: tuple[str, str]) -> dict:
    scene = read_preset(name)
    # loads under which the whole base stays in contact (the modal form's answer)
    values = {"settlement": 1e-4, "tilt": 1e-7, "force": 5e5, "moment": 1e4}
    scene["loading"] = {k: values[k] for k in given}
    return scene


@pytest.mark.parametrize("scene", [
    read_preset("stepped_punch"),                               # settlement and moment
    _statement("stepped_punch", ("settlement", "tilt")),
    _statement("uniform_flat", ("force", "moment")),
    _statement("uniform_flat", ("tilt", "force")),
    read_preset("young_concrete_50_years"),                     # aging, 50 years
], ids=["stepped", "stepped-settlement-tilt", "creep-force-moment", "creep-tilt-force",
        "aging"])
def test_a_symmetric_geometry_finds_its_even_and_odd_modes_apart_with_the_same_answer(
        scene, monkeypatch):
    split, halves = _answer(scene, monkeypatch, mirror=True)
    whole, full = _answer(scene, monkeypatch, mirror=False)
    assert whole.info["contact"] == "full" and full
    # two decompositions of about half the size where there was one
    assert len(halves) == 2 * len(full) and max(halves) <= (max(full) + 2) // 2
    x = np.linspace(-1.0, 1.0, 201) * scene["punch"]["half_width"]
    q_split, q_whole = np.asarray(split.pressure(x)), np.asarray(whole.pressure(x))
    # measured: q 3.4e-15 to 1.1e-14 of its largest value, the scalars 1.7e-15 of their
    # pair's largest (settlement and tilt, force and moment): rounding
    assert np.max(np.abs(q_split - q_whole)) < 5e-14 * np.max(np.abs(q_whole))
    for pair in (("settlement", "tilt"), ("force", "moment")):
        size = max(np.max(np.abs(np.asarray(getattr(whole, k)))) for k in pair)
        for k in pair:
            assert np.max(np.abs(np.asarray(getattr(split, k))
                                 - np.asarray(getattr(whole, k)))) < 5e-14 * size, k
    assert split.flags == whole.flags
    assert split.info["error_estimate"] == pytest.approx(whole.info["error_estimate"],
                                                         rel=1e-6)


def test_a_geometry_that_is_not_symmetric_is_decomposed_whole(monkeypatch):
    scene = read_preset("patched_insert")
    scene["coating"][0]["modulus"]["breaks"] = [-0.15, 0.2]  # the insert off the centre
    _, sizes = _answer(scene, monkeypatch, mirror=True)
    _, whole = _answer(scene, monkeypatch, mirror=False)
    assert sizes == whole and sizes


def test_a_stiff_part_not_quite_mirrored_beside_a_soft_one_is_decomposed_whole(monkeypatch):
    """A stiff coating beside a soft one (5e11 and 5e7 Pa), 3e-11 stiffer on the right:
    its compliance is symmetric to 3e-15 of the largest one but not node by node, and the
    split would drop 1e-11 of the Galerkin matrix (q 2.7e-10 off, 18 times what the
    asymmetry itself changes). It is decomposed whole: the same answer as without the
    split, to the last bit."""
    scene = read_preset("patched_insert")
    scene["coating"][0]["modulus"]["values"] = [5e11, 5e7, 5e11 * (1.0 + 3e-11)]
    scene["loading"] = {"force": 5e5, "moment": 0.0}
    split, sizes = _answer(scene, monkeypatch, mirror=True)
    whole, full = _answer(scene, monkeypatch, mirror=False)
    assert whole.info["contact"] == "full" and sizes == full
    assert np.array_equal(np.asarray(split.pressure_on_grid), np.asarray(whole.pressure_on_grid))
