"""The step solver's kept factors serve contact sets a few nodes away (a Schur
complement on the nodes gained and lost) with the answers of a direct solve."""

from __future__ import annotations

import numpy as np
import pytest

from core.contact.systems import (
    StepSolver,
    _bordered_system,
    bordered_change,
    bordered_solve,
    restrict,
)

STATEMENTS = [{"force": 1.0, "moment": 0.3}, {"settlement": 0.02, "moment": 0.1},
              {"settlement": 0.02, "tilt": 0.004}, {"tilt": 0.001, "force": 0.8}]


def _contact_sets(n: int) -> list[np.ndarray]:
    """A zone that grows and shrinks at both ends, splits in two and joins again."""
    inside = np.arange(n)
    sets = [inside[10:n - 10], inside[9:n - 10], inside[7:n - 12], inside[12:n - 3],
            np.concatenate([inside[12:40], inside[46:n - 3]]),
            np.concatenate([inside[12:41], inside[44:n - 3]]), inside[11:n - 4]]
    return sets


@pytest.mark.parametrize("given", STATEMENTS, ids=lambda g: "+".join(g))
def test_kept_factors_solve_nearby_contact_sets_as_a_direct_solve(rule, given):
    """Every statement, a zone gaining and losing nodes at both ends, split and joined,
    while c/s drifts by 1e-3 a step: one factorization serves them all, and the answers
    are the direct solve's within what the refinement promises: it stops at a residual
    of 1e-13 of the right-hand side b, so the answers differ by at most
    ``||A^-1|| 1e-13 ||b||`` (infinity norms; ||A^-1|| ~ 40 here; measured: q within
    6.1e-13 of its largest value, the scalars within 8e-15 relative)."""
    op, m, x, w, rhs = rule
    solver = StepSolver()
    for k, idx in enumerate(_contact_sets(x.size)):
        c = 1.0 + 1e-3 * k
        kept = bordered_solve(op, m, x, w, c, 1.0, given, rhs, idx, solver)
        direct = bordered_solve(op, m, x, w, c, 1.0, given, rhs, idx)
        build = _bordered_system(op, m, x, w, c, 1.0, tuple(given), idx, None)[0]
        loads = [given[name] for name in ("force", "moment") if name in given]
        b = np.abs(np.concatenate([rhs[idx], loads])).max()
        bound = np.abs(np.linalg.inv(build())).sum(axis=1).max() * 1e-13 * b
        assert np.abs(kept[0] - direct[0]).max() <= bound
        for a, d in zip(kept[1:], direct[1:], strict=True):
            assert abs(a - d) <= bound
    assert solver.factorizations == 1
    assert solver.updates == len(_contact_sets(x.size)) - 1


def test_a_far_contact_set_or_another_statement_is_factored_anew(rule):
    op, m, x, w, rhs = rule
    solver = StepSolver()
    given = STATEMENTS[0]
    bordered_solve(op, m, x, w, 1.0, 1.0, given, rhs, np.arange(10, x.size - 10), solver)
    far = np.arange(11 + StepSolver.MAX_UPDATE, x.size - 10)
    bordered_solve(op, m, x, w, 1.0, 1.0, given, rhs, far, solver)
    assert solver.factorizations == 2
    bordered_solve(op, m, x, w, 1.0, 1.0, STATEMENTS[1], rhs, far[1:], solver)
    assert solver.factorizations == 3 and solver.updates == 0


def test_a_snapshot_of_an_updated_solve_outlives_new_factors(rule):
    """A step's snapshot (the kink corrections of a batch of output times solve their
    change with it after later steps) solves with the factors of its own step, also
    when later steps made new ones (the update once read the solver's newest factors
    and the march's zones came out as full contact)."""
    op, m, x, w, rhs = rule
    given = STATEMENTS[0]
    solver = StepSolver()
    bordered_solve(op, m, x, w, 1.0, 1.0, given, rhs, np.arange(10, x.size - 10), solver)
    idx = np.arange(8, x.size - 11)
    bordered_solve(op, m, x, w, 1.002, 1.0, given, rhs, idx, solver)
    assert solver.updates == 1
    kept = solver.snapshot()
    bordered_solve(op, m, x, w, 1.5, 1.0, given, rhs, np.arange(60, x.size - 60), solver)
    assert solver.factorizations == 2
    change = {"force": 1e-3, "moment": -2e-4}
    d_rhs = 1e-4 * np.cos(3 * x)
    dq, d_delta, d_alpha = bordered_change(op, m, x, w, 1.002, 1.0, change, d_rhs, idx, kept)
    direct = bordered_solve(op, m, x, w, 1.002, 1.0, change, d_rhs, idx)
    # refined to a residual of CHANGE_RESIDUAL (1e-9) of the change's right-hand side b:
    # within ||A^-1|| 1e-9 ||b|| of the direct solve (measured: q 1.9e-9 of its largest
    # value, the settlement and tilt 5e-12 and 4e-11 relative; ||A^-1|| ~ 40)
    build = _bordered_system(op, m, x, w, 1.002, 1.0, tuple(change), idx, None)[0]
    b = np.abs(np.concatenate([d_rhs[idx], list(change.values())])).max()
    bound = np.abs(np.linalg.inv(build())).sum(axis=1).max() * StepSolver.CHANGE_RESIDUAL * b
    assert np.abs(dq - direct[0]).max() <= bound
    assert abs(d_delta - direct[1]) <= bound and abs(d_alpha - direct[2]) <= bound


def test_a_receding_zone_under_creep_is_answered_alike_with_few_factorizations(monkeypatch):
    """A heel lifting further as the base creeps (e(t) 0.3 -> 0.6 a, an exponential
    kernel): its zone loses nodes at most steps. With every new contact set factored
    anew (updates off) and with updates (on every system size here): the same answer
    (measured: zone ends within 3e-15, settlement 2e-15 relative, estimate 2.4e-8
    relative; 1e-12 and 1e-6 leave margins of 100 and more) with 24 factorizations
    instead of 198."""
    import core.contact.systems as systems
    from benchmarks.creep_honesty import EXPONENTIAL, _growing_moment
    from core.cache import clear_caches
    from core.solver import solve_dimensionless

    counts = {"factor": 0}
    original = systems.StepSolver._factor

    def counted(self, *args):
        counts["factor"] += 1
        return original(self, *args)

    monkeypatch.setattr(systems.StepSolver, "_factor", counted)
    monkeypatch.setattr(systems.StepSolver, "UPDATE_MIN_SIZE", 0)
    answers = []
    for limit in (0, StepSolver.MAX_UPDATE):
        monkeypatch.setattr(systems.StepSolver, "MAX_UPDATE", limit)
        clear_caches()
        counts["factor"] = 0
        answer = solve_dimensionless(1.0, 0.05, 0.0, np.linspace(1.0, 4.0, 4),
                                     kernel=EXPONENTIAL, force=1.0, moment=_growing_moment,
                                     tol=1e-3, contact="unilateral")
        answers.append((answer, counts["factor"]))
    (plain, plain_count), (updated, updated_count) = answers
    assert plain.info["success"] and updated.info["success"]
    assert updated_count < 0.2 * plain_count
    for name in ("settlement", "tilt"):
        a, b = getattr(updated, name), getattr(plain, name)
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max()
    for zones_a, zones_b in zip(updated.contact_set, plain.contact_set, strict=True):
        assert np.abs(np.subtract(zones_a, zones_b)).max() <= 1e-12
    estimate_a, estimate_b = updated.info["error_estimate"], plain.info["error_estimate"]
    assert abs(estimate_a - estimate_b) <= 1e-6 * estimate_b


def test_small_systems_are_factored_anew(rule):
    """Below ``UPDATE_MIN_SIZE`` unknowns a factorization costs less than an update."""
    op, m, x, w, rhs = rule
    solver = StepSolver()
    given = STATEMENTS[0]
    small = StepSolver.UPDATE_MIN_SIZE - 40
    for lo in (0, 1, 2):
        bordered_solve(op, m, x, w, 1.0, 1.0, given, rhs, np.arange(lo, lo + small), solver)
    assert solver.factorizations == 3 and solver.updates == 0


@pytest.mark.parametrize("pattern", ["one run", "three runs", "scattered", "empty"])
def test_the_operator_on_contact_nodes_is_the_submatrix(pattern: str) -> None:
    """:func:`restrict` copies several zones block by block: the same entries as indexing
    by the nodes, for one zone (a view), a few, more runs than it copies by blocks, none."""
    rng = np.random.default_rng(7)
    op = rng.standard_normal((60, 60))
    idx = {"one run": np.arange(5, 41),
           "three runs": np.r_[0:10, 15:30, 52:60],
           "scattered": np.arange(0, 60, 2),
           "empty": np.arange(0)}[pattern]
    assert np.array_equal(restrict(op, idx), op[np.ix_(idx, idx)])
