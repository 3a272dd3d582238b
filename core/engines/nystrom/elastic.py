"""The elastic answer of a prepared geometry: cached unit responses times the load histories.

On an elastic base with a constant modulus ``c`` the problem is linear and has no memory:
the answer at every time is the same combination of a few unit responses (each given load
= 1, and the gap), weighted by the loads at that time. :class:`ElasticUnits` keeps those
responses for one statement and ``c`` (nodal pressures, the two unknown scalars, q at the
check points and at any points asked for); :func:`elastic_answer` combines them with the
load histories: one small matrix product per quantity, whatever the number of output
times, and no Python work per time.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.discretize import NODES_PER_PANEL
from core.problem import QUANTITIES, TimeInputs

#: Probe times per block when the extremes of q over the check points are sought: a block
#: of (405 check points x 512 times) is 1.6 MB, so it stays in the cache between the
#: matrix product and the two reductions (the whole 405 x 10,256 array at once was 33 MB).
CHECK_BLOCK = 512
#: Point sets whose unit pressures are kept (a plot's points, a pin, the check points).
KEPT_POINT_SETS = 16


class ElasticUnits:
    """Unit responses of one statement at a constant modulus ``c`` (dimensionless).

    Column ``k`` of every array is the response to the ``k``-th given load (sorted by name)
    = 1 with the other load 0 and no gap, and the last column the response to the gap
    alone. ``nodal`` (N, 3) holds nodal pressures, ``unknowns`` (2, 3) the two quantities
    that are not given (in the order of :data:`core.problem.QUANTITIES`).
    """

    def __init__(self, prepared: Any, given: frozenset[str], c0: float) -> None:
        _, units = prepared.bordered(given, c0)
        n = prepared.grid.size
        self.given = given
        self.names = sorted(given)
        self.unknown_names = [q for q in QUANTITIES if q not in given]
        columns = self.names + ["gap"]
        unit_matrix = np.column_stack([units[k] for k in columns])
        self.nodal = unit_matrix[:n]
        self.unknowns = unit_matrix[n:n + len(self.unknown_names)]
        # delta and alpha of each unit response (a given one: 1 for its own unit)
        delta = np.array([1.0 if k == "settlement" else 0.0 for k in columns])
        alpha = np.array([1.0 if k == "tilt" else 0.0 for k in columns])
        for i, name in enumerate(self.unknown_names):
            if name == "settlement":
                delta = self.unknowns[i]
            elif name == "tilt":
                alpha = self.unknowns[i]
        self._delta, self._alpha = delta, alpha
        self._gap = np.array([1.0 if k == "gap" else 0.0 for k in columns])
        self._c = np.full(len(columns), c0)
        self._prepared = prepared
        self._pressure: dict[bytes, np.ndarray] = {}
        self._check: np.ndarray | None = None
        self._lock = threading.Lock()

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """q at ``x`` of each unit response (len(x), 3), by the Nystrom formula; cached by
        the points, so a load change evaluates q there with one small matrix product."""
        x = np.ascontiguousarray(x, dtype=float)
        key = x.tobytes()
        with self._lock:
            cached = self._pressure.get(key)
        if cached is None:
            drive = (self._delta[None, :] + np.outer(x, self._alpha)
                     - np.outer(self._prepared.geometry.g(x), self._gap))
            cached = self._prepared.nystrom_pressure(x, drive, self._c, self.nodal)
            with self._lock:
                self._pressure[key] = cached
                while len(self._pressure) > KEPT_POINT_SETS:
                    self._pressure.pop(next(iter(self._pressure)))
        return cached

    def check_pressure(self) -> np.ndarray:
        """Unit-response pressures at the prepared check points (X, 3), cached.

        Where the formula is needed (panels touching +-1 or a jump) it is used; elsewhere
        the panel interpolant (see :class:`core.engines.nystrom.PreparedContact`).
        """
        if self._check is None:
            prepared = self._prepared
            x, formula = prepared.check_x, prepared.check_formula
            check = np.empty((x.size, self.nodal.shape[1]))
            # the prepared geometry's interpolation weights, panel by panel (forming them
            # again here cost ~0.07 ms a new scene)
            nodal = self.nodal.reshape(prepared.grid.panels.n_panels, NODES_PER_PANEL, -1)
            for panel, points, weights in prepared._check_interpolation:
                check[points] = weights @ nodal[panel]
            check[formula] = self.pressure(x[formula])
            self._check = check
        return self._check

    def extremes(self, weights: np.ndarray) -> tuple[float, float]:
        """(min q, max |q|) over the check points and the columns of ``weights`` (3, T)."""
        check = self.check_pressure()
        lowest, highest = np.inf, -np.inf
        for start in range(0, weights.shape[1], CHECK_BLOCK):
            block = check @ weights[:, start:start + CHECK_BLOCK]
            lowest = min(lowest, float(block.min()))
            highest = max(highest, float(block.max()))
        return lowest, max(-lowest, highest)


@dataclass(frozen=True)
class ElasticAnswer:
    """Scalars at the output times, q at any points, and the checks over the probe times."""

    scalars: dict[str, np.ndarray]
    pressure: Callable[[np.ndarray], np.ndarray]
    q_extremes: tuple[float, float]  # (min q, max |q|) over check points and probe times
    max_abs_tilt: float


def elastic_answer(units: ElasticUnits, inputs: TimeInputs, probe: np.ndarray
                   ) -> ElasticAnswer:
    """The elastic answer at ``inputs.times``, checked at the ``probe`` times as well.

    ``probe`` holds every output time (and samples between them); the loads are evaluated
    there once, and the output times are a selection of those columns.
    """
    at = np.searchsorted(probe, inputs.times)
    load_values = {k: inputs.loads[k](probe) for k in units.names}
    weights = np.empty((len(units.names) + 1, probe.size))
    for i, name in enumerate(units.names):
        weights[i] = load_values[name]
    weights[-1] = 1.0
    load_matrix = weights[:, at]
    solved = units.unknowns @ load_matrix
    scalars = {k: load_values[k][at] for k in units.names}
    for i, name in enumerate(units.unknown_names):
        scalars[name] = solved[i]
    if "tilt" in units.given:
        tilt_history = load_values["tilt"]
    else:
        tilt_history = units.unknowns[units.unknown_names.index("tilt")] @ weights

    def pressure(x: np.ndarray) -> np.ndarray:
        return units.pressure(x) @ load_matrix

    return ElasticAnswer(scalars, pressure, units.extremes(weights),
                         float(np.max(np.abs(tilt_history))))
