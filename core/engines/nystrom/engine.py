"""The Nystrom method as an engine of :func:`core.solver.solve_dimensionless` (the default).

``prepare`` is :func:`core.engines.nystrom.prepared.prepared_for`: the graded, adaptively
refined grid of the geometry, kept in :data:`core.engines.nystrom.PREPARED` (so a later
solve of the same geometry with other loads reuses it); ``solve`` is
:meth:`core.engines.nystrom.prepared.PreparedContact.solve_validated`.
"""

from __future__ import annotations

from collections.abc import Sequence

from core.engines.nystrom.prepared import PreparedContact, prepared_for
from core.engines.nystrom.result import SUCCESS_MARGIN
from core.problem import ContactSolution, Geometry, TimeInputs


class NystromEngine:
    """Direct Nystrom discretization on graded panels, refined until the two-grid estimate
    of q meets ``tol``; modal time stepping under creep. Declines (raises
    :class:`core.problem.UnresolvedOperator`) a nodal operator it cannot step in modal
    form."""

    name = "nystrom"
    prepare_options = ()
    solve_options = ("time_breaks",)
    success_margin = SUCCESS_MARGIN

    def prepare(self, geometry: Geometry) -> PreparedContact:
        """The prepared grid of ``geometry`` (built once, then found in the cache)."""
        return prepared_for(geometry)

    def solve(self, prepared: PreparedContact, inputs: TimeInputs, *,
              time_breaks: Sequence[float] = ()) -> ContactSolution:
        """The full-contact answer for ``inputs``; ``time_breaks``: times where a given load
        history jumps or kinks, which the time steps land on (a step across a jump loses
        the order and fools the step-doubling estimate)."""
        return prepared.solve_validated(inputs, time_breaks)


#: The engine registered as ``"nystrom"`` in :data:`core.engines.ENGINES`.
NYSTROM = NystromEngine()
