"""The inputs and results of the resolved-coating check (:mod:`core.coating.fem_check`).

:class:`CoatingStrip` and :class:`Stack` describe the punch, the resolved coating layers
and the base in SI units; :class:`FEResponse` holds the three unit responses of one solve
and completes any statement from them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

#: Interfaces of a coating layer with what lies under it.
INTERFACES = ("smooth", "bonded")

Profile = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class CoatingStrip:
    """One resolved coating layer: ``thickness`` [m], ``modulus`` [Pa], ``poisson`` [-] as
    vectorized functions of ``x`` [m] on ``[-a, a]``, and its ``interface`` with what lies
    under it (``"smooth"`` or ``"bonded"``)."""

    thickness: Profile
    modulus: Profile
    poisson: Profile
    interface: str = "smooth"


@dataclass(frozen=True)
class Stack:
    """The geometry and materials of a check (SI units).

    ``half_width`` a [m]; ``shape`` f(x) [m] of the punch base on ``[-a, a]``; ``coating``
    top layer first (as in a scene); the base: ``base_thickness`` H [m], ``base_modulus``
    E [Pa] (elastic, at the chosen time), ``base_poisson`` nu; ``breakpoints`` [m] where a
    profile may jump (the mesh puts element edges there).
    """

    half_width: float
    coating: tuple[CoatingStrip, ...]
    base_thickness: float
    base_modulus: float
    base_poisson: float
    shape: Profile | None = None
    breakpoints: tuple[float, ...] = ()


@dataclass
class FEResponse:
    """The three unit responses of one finite-element solve (SI units).

    ``force_parts``, ``moment_parts``: P [N/m] and M [N] for (the gap alone, a unit
    settlement [per m], a unit tilt [per rad]); ``pressure_parts`` q [Pa] at the contact
    nodes ``x_nodes`` [m] (P2 nodes in order: vertex, midpoint, vertex, ...). ``dofs``,
    ``seconds`` describe the solve.
    """

    half_width: float
    x_nodes: np.ndarray
    pressure_parts: np.ndarray
    force_parts: np.ndarray
    moment_parts: np.ndarray
    dofs: int
    seconds: float
    extent: float = field(default=0.0)
    nodal_force_parts: np.ndarray | None = None
    clearance_parts: np.ndarray | None = None

    def nodal_force(self, settlement: float, tilt: float) -> np.ndarray:
        """The punch's force [N/m] on each node ``x_nodes`` (the consistent nodal forces of
        the contact pressure; zero where the punch does not hold the surface)."""
        return np.array([1.0, settlement, tilt]) @ self.nodal_force_parts

    def clearance(self, settlement: float, tilt: float) -> np.ndarray:
        """The height [m] of the punch's base above the deformed surface at each node
        ``x_nodes`` (zero where the punch holds it, negative where it would penetrate)."""
        return np.array([1.0, settlement, tilt]) @ self.clearance_parts

    def force_moment(self, settlement: float, tilt: float) -> tuple[float, float]:
        """P [N/m] and M [N] for a settlement delta [m] and a tilt alpha [rad]."""
        w = np.array([1.0, settlement, tilt])
        return float(w @ self.force_parts), float(w @ self.moment_parts)

    def kinematics(self, force: float, moment: float) -> tuple[float, float]:
        """delta [m] and alpha [rad] that carry P [N/m] and M [N] (statement 4)."""
        a = np.array([[self.force_parts[1], self.force_parts[2]],
                      [self.moment_parts[1], self.moment_parts[2]]])
        rhs = np.array([force - self.force_parts[0], moment - self.moment_parts[0]])
        delta, alpha = np.linalg.solve(a, rhs)
        return float(delta), float(alpha)

    def complete(self, given: dict[str, float]) -> dict[str, float]:
        """All four of settlement, tilt, force, moment from any two of them (SI units)."""
        known = {k: float(v) for k, v in given.items()}
        # the four quantities are related by two linear equations in (delta, alpha)
        rows = {"force": (self.force_parts, 0), "moment": (self.moment_parts, 0)}
        a_rows, rhs = [], []
        for name, value in known.items():
            if name == "settlement":
                a_rows.append([1.0, 0.0])
                rhs.append(value)
            elif name == "tilt":
                a_rows.append([0.0, 1.0])
                rhs.append(value)
            else:
                parts = rows[name][0]
                a_rows.append([parts[1], parts[2]])
                rhs.append(value - parts[0])
        delta, alpha = np.linalg.solve(np.array(a_rows), np.array(rhs))
        force, moment = self.force_moment(delta, alpha)
        return {"settlement": float(delta), "tilt": float(alpha), "force": force,
                "moment": moment}

    def pressure(self, x: np.ndarray, settlement: float, tilt: float) -> np.ndarray:
        """q [Pa] at points ``x`` [m] of ``[-a, a]`` (the P2 interpolant of the nodal values)."""
        values = np.array([1.0, settlement, tilt]) @ self.pressure_parts
        return _p2_interpolate(self.x_nodes, values, np.asarray(x, dtype=float))


@dataclass
class FEContact:
    """A resolved-model answer with unilateral contact (:func:`core.coating.solve_stack_contact`).

    ``response``: the :class:`FEResponse` on the final contact set; ``state``: settlement
    [m], tilt [rad], force [N/m], moment [N] of the answer; ``contact``: the intervals [m]
    of held nodes (first, last node); ``sweeps``: active-set sweeps made; ``converged``:
    whether the set settled (no node changed in the last sweep); ``end_moved``: how far [m]
    the zone ends moved on the last mesh refinement (their uncertainty); ``seconds``: the
    whole solve's time (every mesh).
    """

    response: FEResponse
    state: dict[str, float]
    contact: list[tuple[float, float]]
    sweeps: int
    converged: bool
    end_moved: float = float("nan")
    seconds: float = float("nan")


def _p2_interpolate(nodes: np.ndarray, values: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Piecewise quadratic through (vertex, midpoint, vertex) triples of ``nodes``."""
    left = nodes[0:-1:2]
    seg = np.clip(np.searchsorted(left, x, side="right") - 1, 0, left.size - 1)
    x0, x1, x2 = nodes[2 * seg], nodes[2 * seg + 1], nodes[2 * seg + 2]
    v0, v1, v2 = values[2 * seg], values[2 * seg + 1], values[2 * seg + 2]
    l0 = (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2))
    l1 = (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2))
    l2 = (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1))
    return v0 * l0 + v1 * l1 + v2 * l2

