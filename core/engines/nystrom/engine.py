"""The Nystrom method as an engine of :func:`core.solver.solve_dimensionless` (the default).

``prepare`` gives the geometry's graded, adaptively refined grid when
:data:`core.engines.nystrom.PREPARED` holds it, else the geometry itself; ``solve``
builds the grid it needs (:func:`core.engines.nystrom.prepared.prepared_for`, refined at
:func:`creep_reference`, kept in ``PREPARED`` so that a later solve of the same geometry
with other loads reuses it) and answers with
:meth:`core.engines.nystrom.prepared.PreparedContact.solve_validated`.
"""

from __future__ import annotations

from collections.abc import Sequence

from core.engines.nystrom.prepared import (
    PreparedContact,
    cached_prepared,
    creep_reference,
    prepared_for,
)
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

    def prepare(self, geometry: Geometry) -> Geometry | PreparedContact:
        """The prepared grid of ``geometry`` when it is in the cache, else ``geometry``
        itself: which grid a solve needs depends on its time side (a creeping base is
        refined at :func:`creep_reference`), so :meth:`solve` builds it, once, and the
        cache keeps it (building the grid at loading as well cost a creeping scene's
        new geometry a second refinement: 2.6 of 22.8 ms on ``eccentric_creep``)."""
        return cached_prepared(geometry) or geometry

    def solve(self, prepared: Geometry | PreparedContact, inputs: TimeInputs, *,
              time_breaks: Sequence[float] = ()) -> ContactSolution:
        """The full-contact answer for ``inputs``; ``time_breaks``: times where a given load
        history jumps or kinks, which the time steps land on (a step across a jump loses
        the order and fools the step-doubling estimate). A creeping base is solved on the
        grid refined at :func:`creep_reference` (prepared once, then cached)."""
        c_ref = creep_reference(inputs)
        if isinstance(prepared, Geometry):
            prepared = prepared_for(prepared, c_ref)
        elif c_ref < prepared.c_ref:
            prepared = prepared_for(prepared.geometry, c_ref)
        return prepared.solve_validated(inputs, time_breaks)


#: The engine registered as ``"nystrom"`` in :data:`core.engines.ENGINES`.
NYSTROM = NystromEngine()
