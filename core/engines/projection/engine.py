"""The projection method as an engine of :func:`core.solver.solve_dimensionless`.

It has no costly prepared form of its own: every spatial stage (panels, operator, basis,
Galerkin rows, gap, modes) is kept in the stage caches of
:mod:`core.engines.projection.caches`, keyed by content, so a second solve of the same
geometry finds them there whatever object carried it. ``prepare`` only checks the
engine's options and keeps them with the geometry.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from core.engines.projection.solve import SUCCESS_MARGIN, check_options, solve_projection
from core.engines.projection.stages import joined_inputs
from core.problem import ContactSolution, Geometry, TimeInputs


@dataclass(frozen=True)
class ProjectionSetup:
    """A validated geometry with the projection's options: ``basis`` (``"graded"``,
    ``"piecewise"`` or ``"global"``) and ``n_modes`` (a fixed mode count, or None:
    adaptive)."""

    geometry: Geometry
    basis: str = "graded"
    n_modes: int | None = None


class ProjectionEngine:
    """The seed's Galerkin projection on an orthonormal basis for the weight ``1/m``, one
    Volterra equation per mode; error from consecutive mode levels (read up to ~3x low,
    hence ``success_margin`` 3)."""

    name = "projection"
    prepare_options = ("basis", "n_modes")
    solve_options = ("time_breaks",)
    success_margin = SUCCESS_MARGIN

    def prepare(self, geometry: Geometry, *, basis: str = "graded",
                n_modes: int | None = None) -> ProjectionSetup:
        """Check the options (``ValueError`` naming a bad one) and keep them."""
        check_options(basis, n_modes)
        return ProjectionSetup(geometry, basis, n_modes)

    def solve(self, prepared: ProjectionSetup, inputs: TimeInputs, *,
              time_breaks: Sequence[float] = ()) -> ContactSolution:
        """The full-contact answer for the time side ``inputs`` (dimensionless);
        ``time_breaks``: times where a given history jumps or kinks, which the time steps
        land on."""
        return solve_projection(joined_inputs(prepared.geometry, inputs, time_breaks),
                                prepared.basis, prepared.n_modes)


#: The engine registered as ``"projection"`` in :data:`core.engines.ENGINES`.
PROJECTION = ProjectionEngine()
