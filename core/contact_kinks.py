"""Zone ends of a creep step without the kink error of the fixed panel rule.

Under creep the contact set is found on the nodes of one fixed panel rule
(:mod:`core.contact_creep`). At a free zone end the pressure ``q = max(Q, 0)`` has a kink
inside a panel, and that panel's Gauss rule integrates ``F q`` and the resultants only to
a low order: on the lift-off preset with 0.04-wide band panels this left the ends ~4e-6
half-widths off, and only ~0.005-wide panels (8 times the cost) met 1e-6 that way.

The Nystrom pressure ``Q`` itself is smooth across the end (it is ``q`` on the zone and
``-gap / (c m)`` off it), so on the panel holding an end the pressure is the panel's
interpolant of the nodal ``Q`` cut at its root, ``q = P_Q`` on the contact part. Its
integrals there are taken exactly by a Gauss rule of that part alone (with the product
weights of the log kernel where a node is near), and the difference from the panel's
rule is a defect of the discrete equation. One solve with the step's kept factors
(:class:`core.contact_systems.StepSolver`) removes it. Measured on the preset (20 output
times, two time grids Richardson-extrapolated): against each output time re-solved on
panels graded toward its end (with the same memory), the ends of 0.04 / 0.02 / 0.005
band panels were 3.8e-6 / 8.7e-7 / 3.4e-7 off before and 3.8e-7 / 1.9e-7 / 1.5e-8 after.
What is left is the kinks of past pressures in the creep memory, which this leaves: it
halves with the band panels.
"""

from __future__ import annotations

import numpy as np

from core.contact_systems import StepSolver, bordered_solve
from core.contact_zones import _BARYCENTRIC, _T, NodalState, Space, Step, zones_from_nodes
from core.log_moments import legendre_log_moments
from core.panels import _TO_COEF, _W
from core.quadrature import NEAR_FIELD, NODES_PER_PANEL, Panels, _rows

#: Passes of the defect correction. The defect moves with the end only to second order
#: (the ends move by ~4e-6): one pass, the ends then read from the corrected Q.
PASSES = 1


#: Log moments at targets just off a part (1.05 < |z| <= NEAR_FIELD in its coordinate)
#: by a 64-point Gauss rule: ln|z - t| is analytic within the ellipse through z (rho >=
#: 1.37), so the rule errs like rho^(15 - 128) < 1e-15 against P_15's growth. The exact
#: moments there need Miller's backward recurrence, whose ~90 steps cost ~0.4 ms a part.
_OVER_T, _OVER_W = np.polynomial.legendre.leggauss(64)
_OVER_P = np.polynomial.legendre.legvander(_OVER_T, NODES_PER_PANEL - 1)


def _part_rows(lam: float, part: Panels, targets: np.ndarray) -> np.ndarray:
    """Rows of F (len(targets) x 16) on the one panel ``part``: as
    :func:`core.quadrature.operator_rows`, its near-field moments computed as above."""
    z = (targets - part.centers[0]) / part.half_widths[0]
    near_t = np.nonzero(np.abs(z) <= NEAR_FIELD)[0]
    zn = z[near_t]
    moments = np.empty((zn.size, NODES_PER_PANEL))
    inner = np.abs(zn) <= 1.05
    if inner.any():
        moments[inner] = legendre_log_moments(zn[inner], NODES_PER_PANEL - 1)
    if (~inner).any():
        outer = zn[~inner]
        moments[~inner] = (np.log(np.abs(outer[:, None] - _OVER_T[None, :]))
                           * _OVER_W[None, :]) @ _OVER_P
    h = part.half_widths[0]
    log_weights = h * (np.log(h) * _W[None, :] + moments @ _TO_COEF)
    return _rows(lam, part, targets, np.zeros(1, dtype=np.intp), near_t,
                 np.zeros(near_t.size, dtype=np.intp), log_weights)


def _interpolation(center: float, half: float, targets: np.ndarray) -> np.ndarray:
    """Rows mapping a panel's 16 nodal values to ``targets`` (its barycentric form)."""
    d = (targets - center) / half
    diff = d[:, None] - _T[None, :]
    rows = np.zeros((targets.size, _T.size))
    hit = diff == 0.0
    exact = hit.any(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = _BARYCENTRIC[None, :] / diff
    rows[~exact] = ratio[~exact] / ratio[~exact].sum(axis=1, keepdims=True)
    rows[exact] = hit[exact].astype(float)
    return rows


def _contact_parts(panels: Panels, zones: list[tuple[float, float]], free: list[float]
                   ) -> dict[int, list[tuple[float, float]]]:
    """For every panel holding a free end: the parts of it inside the zones."""
    lo_edges = panels.centers - panels.half_widths
    hi_edges = panels.centers + panels.half_widths
    parts: dict[int, list[tuple[float, float]]] = {}
    for end in free:
        p = int(np.clip(np.searchsorted(hi_edges, end), 0, panels.n_panels - 1))
        if p in parts:
            continue
        a, b = float(lo_edges[p]), float(hi_edges[p])
        parts[p] = [(max(a, lo), min(b, hi)) for lo, hi in zones
                    if min(b, hi) > max(a, lo)]
    return parts


def _defect(space: Space, step: Step, state: NodalState, op: np.ndarray,
            parts: dict[int, list[tuple[float, float]]]) -> tuple[np.ndarray, float, float]:
    """(defect of s F q at the nodes, of the force, of the moment): the exact integrals of
    the cut interpolant over the contact parts less the panels' Gauss sums."""
    panels = state.panels
    targets = panels.nodes
    defect = np.zeros(targets.size)
    force = moment = 0.0
    for p, pieces in parts.items():
        cols = slice(p * NODES_PER_PANEL, (p + 1) * NODES_PER_PANEL)
        q_nodes = state.q[cols]
        defect -= op[:, cols] @ q_nodes
        force -= float(panels.weights[cols] @ q_nodes)
        moment -= float((panels.weights[cols] * panels.nodes[cols]) @ q_nodes)
        for lo, hi in pieces:
            sub = Panels.from_edges(np.array([lo, hi]))
            values = _interpolation(panels.centers[p], panels.half_widths[p],
                                    sub.nodes) @ state.nystrom[cols]
            defect += _part_rows(space.lam, sub, targets) @ values
            force += float(sub.weights @ values)
            moment += float((sub.weights * sub.nodes) @ values)
    return step.scale * defect, force, moment


def corrected_ends_state(space: Space, step: Step, state: NodalState, op: np.ndarray,
                         m: np.ndarray, g: np.ndarray, memory: np.ndarray | None,
                         solver: StepSolver | None = None) -> NodalState:
    """The nodal state of a step with the kink defect of its free ends removed.

    ``state`` from :func:`core.contact_zones.nodal_active_set` on the rule whose Nystrom
    matrix is ``op``; ``m``, ``g`` and ``memory`` (the memory displacement e, or None) at
    its nodes. The contact nodes are kept; ``q``, settlement, tilt and ``nystrom`` (Q)
    are those of the corrected equation, for locating the free ends
    (:func:`core.contact_zones.zones_from_nodes`). Returns ``state`` itself when it has
    no free end (dimensionless throughout).
    """
    if not state.active.any():
        return state
    panels = state.panels
    x, w = panels.nodes, panels.weights
    idx = np.nonzero(state.active)[0]
    rhs0 = step.given.get("settlement", 0.0) + step.given.get("tilt", 0.0) * x - g
    if memory is not None:
        rhs0 = rhs0 + memory
    current = state
    for _ in range(PASSES):
        ends, pinned, _ = zones_from_nodes(current, space.breakpoints)
        free = [e for e, p in zip(ends, pinned, strict=True) if not p]
        if not free:
            return state
        zones = [(ends[2 * i], ends[2 * i + 1]) for i in range(len(ends) // 2)]
        defect, d_force, d_moment = _defect(space, step, current, op,
                                            _contact_parts(panels, zones, free))
        given = dict(step.given)
        if "force" in given:
            given["force"] -= d_force
        if "moment" in given:
            given["moment"] -= d_moment
        q_active, delta, alpha = bordered_solve(op, m, x, w, step.c, step.scale, given,
                                                rhs0 - defect, idx, solver)
        q = np.zeros(x.size)
        q[idx] = q_active
        nystrom = (delta + alpha * x - g + (0.0 if memory is None else memory)
                   - step.scale * (op @ q) - defect) / (step.c * m)
        nystrom[idx] = q_active
        current = NodalState(panels, q, delta, alpha, state.active, nystrom)
    return current
