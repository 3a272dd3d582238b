"""The Nystrom modal form where the eigensolver returns a nearly double eigenvalue as a
complex pair ``a +- ib`` (|b| at rounding).

Taking the real parts of such a pair's eigenvectors ``v, conj(v)`` gave one vector twice:
the mode matrix was singular (cond 1e17) and the creep answer garbage. Whether a pair came
out real or complex depended on the operator's last bits, which depended on what the
quadrature's reference tables held from earlier solves: an order-dependent wrong answer
(a contact check read min q = -1.5e11 after one set of earlier tests).
"""

from __future__ import annotations

import numpy as np


def test_a_complex_pair_of_rounding_size_gives_well_conditioned_modes():
    from core.problem import modal_system

    rng = np.random.default_rng(7)
    n = 12
    free = n - 2  # force and moment given: the first two coefficients are known
    # eigenvalues 1..8 and a pair a +- ib, b far below the 1e-8 the check allows but above
    # the transform's rounding (at 1e-18 the eigensolver returns two real ones)
    a, b = 0.5, 1e-10
    block = np.diag(np.concatenate([np.arange(1.0, free - 1), [0.0, 0.0]]))
    block[-2:, -2:] = [[a, b], [-b, a]]
    basis = np.eye(free) + 0.1 * rng.standard_normal((free, free))
    r_ff = basis @ block @ np.linalg.inv(basis)
    r = np.eye(n)
    r[2:, 2:] = r_ff
    assert np.sum(np.linalg.eigvals(r_ff).imag != 0) == 2  # the eigensolver sees the pair
    ms = modal_system(r, (2.0, 0.0, 2.0 / 3.0), frozenset({"force", "moment"}), n,
                      symmetric=False)
    # measured: cond 1.8 (with the real parts of the pair: 4e17)
    assert np.linalg.cond(ms.psi) < 1e3
    residual = ms.psi_inv @ r_ff @ ms.psi - np.diag(ms.gamma)
    # what is left is the rotation b of the pair, dropped: measured 1.35e-10
    assert np.max(np.abs(residual)) < 2 * b


def test_creep_at_loading_equals_the_elastic_answer_from_empty_tables():
    """At t = 1 the base has not crept: the creep answer is the elastic one. On this grid
    (624 nodes) the eigensolver met such a pair when the reference tables of the
    quadrature started empty (a fresh process): 0.0904 instead of 0.2416."""
    from core.creep.models import ExponentialCreep
    from core.discretize import pair_tables
    from core.engines.nystrom.prepared import PreparedContact
    from core.problem import validate_geometry

    pair_tables.clear()  # the state in which the pair appeared
    law = ExponentialCreep(modulus=3e10, compliance=3e-11, rate=0.05).dimensionless_kernel(28.0)
    prepared = PreparedContact(validate_geometry(1.0, 0.05, 0.0, (), 1e-10))
    elastic = prepared.solve([1.0], force=1.0, moment=0.1).settlement[0]
    creep = prepared.solve([1.0, 2.0], kernel=law, force=1.0, moment=0.1)
    # measured: 1.1e-16 relative (the modal and the bordered solve agree to rounding)
    assert abs(creep.settlement[0] - elastic) < 1e-12 * elastic
    assert "contact_lost" not in creep.info["flags"]
    assert creep.settlement[1] > creep.settlement[0]  # it creeps


def test_several_punches_modes_take_a_complex_pair_of_rounding_size_too():
    """The coupled modal form (several punches) took the real parts of its eigenvectors:
    two equal footings (preset new_footing_beside_old at tol 1e-9, 1020 nodes) made two
    such pairs, and the answer had q = -7.3e6 Pa where it is 1.16e6 and a settlement 5 %
    off, with a time estimate of 5.7e-8 (both time grids pass through the same inverse).
    """
    from core.engines.nystrom.multi_modal import CoupledModalForm

    rng = np.random.default_rng(7)
    n = 10
    a, b = 0.5, 1e-10
    block = np.diag(np.concatenate([np.arange(1.0, n - 1), [0.0, 0.0]]))
    block[-2:, -2:] = [[a, b], [-b, a]]
    basis = np.eye(n) + 0.1 * rng.standard_normal((n, n))
    operator = basis @ block @ np.linalg.inv(basis)
    assert np.sum(np.linalg.eigvals(operator).imag != 0) == 2
    # settlement and tilt given: no fixed columns, the free block is the operator itself
    form = CoupledModalForm(operator, np.ones(n), np.ones(n), np.linspace(-1.0, 1.0, n),
                            np.zeros(n), np.array([0, n]), [frozenset({"settlement", "tilt"})],
                            1e-6)
    # measured: cond 2.0 (with the real parts of the pair: 1e17, and the probe of the
    # decomposition then refuses it)
    assert np.linalg.cond(form.psi) < 1e3
    assert np.allclose(np.sort(form.gamma), np.sort(np.linalg.eigvals(operator).real))


def test_modes_that_are_nearly_dependent_are_refused_not_marched(monkeypatch):
    """Whatever makes the mode matrix singular, a probe vector taken through it and back
    refuses the modes (the time grids' estimate cannot see it: both grids go through the
    same inverse)."""
    import pytest

    import core.problem.statements as statements
    from core.creep.models import ExponentialCreep
    from core.engines.nystrom.prepared import PreparedContact
    from core.problem import UnresolvedOperator, validate_geometry

    real = statements.real_modes

    def one_vector_twice(gamma, psi):
        out = real(gamma, psi)
        out[:, 1] = out[:, 0]
        return out

    from core.cache import clear_caches

    clear_caches()  # (modes of this grid kept by an earlier test would not be rebuilt)
    monkeypatch.setattr(statements, "real_modes", one_vector_twice)
    law = ExponentialCreep(modulus=3e10, compliance=3e-11, rate=0.05).dimensionless_kernel(28.0)
    prepared = PreparedContact(validate_geometry(1.0, 0.05, 0.0, (), 1e-8))
    with pytest.raises(UnresolvedOperator, match="nearly dependent"):
        prepared.solve([1.0, 2.0], kernel=law, force=1.0, moment=0.1)
