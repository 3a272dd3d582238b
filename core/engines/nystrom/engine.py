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

import numpy as np

from core.cache import StageCache, fingerprint
from core.creep import integrated_kernel
from core.engines.nystrom.prepared import PreparedContact, cached_prepared, prepared_for
from core.engines.nystrom.result import SUCCESS_MARGIN
from core.problem import ContactSolution, Geometry, TimeInputs

#: Steps per octave of the relative modulus a creeping problem's grid is refined at: a
#: creep parameter moved a little keeps its grid (rounded down: the finer side).
REFERENCE_STEPS_PER_OCTAVE = 4

_REFERENCES = StageCache("creep_reference", max_items=256, max_bytes=2**16,
                         sizeof=lambda _: 8)


def creep_reference(inputs: TimeInputs) -> float:
    """The relative modulus [-] a creeping problem's grid is refined at: the smallest of
    ``c(t) / F(t)`` over the output times, ``F(t) = 1 - int_1^t K(t, u) du`` the compliance
    of a stress held since loading relative to the elastic one (rounded down to
    :data:`REFERENCE_STEPS_PER_OCTAVE` steps an octave); 1 without creep or where it is
    not below 1.

    The coating's term is ``c(t) m q`` against the base's ``(I - V) A q``: as the base
    creeps its compliance grows by about ``F``, so the coating counts as ``m c / F`` and
    the pressure at the punch's edges sharpens. A grid refined at loading (``c = 1``) then
    misses ``tol`` at late times: measured on ``lam = 1, m = 0.1, g = 0.01 x^2`` with an
    exponential kernel (``F`` up to 2.5), the error of q at ``x = 1`` grew from 1.9e-7 at
    loading to 1.6e-6 at ``t = 12`` under an estimate of 9.0e-7 (tol 1e-6).
    """
    if inputs.kernel is None:
        return 1.0
    key = getattr(inputs.kernel, "key", None)

    def compute() -> float:
        t = np.asarray(inputs.times, dtype=float)
        held = 1.0 + integrated_kernel(inputs.kernel, t, np.ones_like(t))
        ratio = float(np.min(np.asarray(inputs.c(t), dtype=float) / held))
        if not ratio < 1.0:
            return 1.0
        steps = REFERENCE_STEPS_PER_OCTAVE
        return float(2.0 ** (np.floor(steps * np.log2(ratio)) / steps))

    if key is None:  # a plain callable: no content to key it by
        return compute()
    # a fitted kernel's key holds the creep law's inputs (a dataclass): its repr is its
    # content
    cache_key = fingerprint("creep reference", repr(key), inputs.times,
                            np.asarray(inputs.c(inputs.times), dtype=float))
    return _REFERENCES.get_or_compute(cache_key, compute)[0]


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
