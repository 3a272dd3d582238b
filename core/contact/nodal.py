"""The nodal active set of an elastic lift-off solve: its rule's operator (cached) and
its start.

The start is predicted on the next coarser rule (:func:`coarse_start`), from full contact
there, so it depends on the scene and the loads alone: a scene gives the same digits
whatever was solved before it (in the explorer, the CLI or a study).
"""

from __future__ import annotations

import numpy as np

from core.cache import StageCache
from core.contact.active_set import NoContact, NodalState, nodal_active_set, zones_from_nodes
from core.contact.step import Space, Step
from core.contact.zones import Resolution
from core.discretize import Panels, base_panels, kernel_operator

#: The operator of the nodal rule depends on lam and the panels only (not on m, g or the
#: loads): kept, so that moving a load (the explorer's eccentricity slider) rebuilds only
#: what the zone ends need.
_NODAL_OPERATORS = StageCache("contact_nodal_operator", max_items=8, max_bytes=64 * 2**20)


def nodal_operator(lam: float, breakpoints: tuple[float, ...], res: Resolution
                   ) -> tuple[Panels, np.ndarray]:
    """The panels of ``res`` on [-1, 1] and the Nystrom matrix of F there (cached)."""
    key = (float(lam), tuple(float(b) for b in breakpoints), float(res.width),
           float(res.edge))

    def build() -> tuple[Panels, np.ndarray]:
        panels = base_panels(lam, breakpoints, edge_width=res.edge, max_width=res.width)
        matrix = kernel_operator(lam, panels).matrix
        matrix.flags.writeable = False  # shared by every solve on this rule
        return panels, matrix

    return _NODAL_OPERATORS.get_or_compute(key, build)[0]


#: The coarse prediction of :func:`coarse_start` is made when the coarser rule has at
#: most this share of the nodes (its sweeps cost ~share^3 of the fine ones; the rule for
#: the thinnest coatings, m = 1e-3, has 320 against 416).
COARSE_SHARE = 0.8


def coarse_start(space: Space, step: Step, base: Panels, nodal_res: Resolution
                 ) -> np.ndarray | None:
    """A start of the nodal active set on ``base`` (the rule of ``nodal_res``): the
    zones found by the active set on the next coarser rule, from full contact there, as
    the nodes of ``base`` inside them (x dimensionless); None when that rule is not much
    smaller or finds no contact.

    It depends on the scene and the loads alone. The coarse sweeps cost ~1/5 of the
    fine ones, and from the coarse zones (ends interpolated between nodes) the fine set
    settles in 1-3 sweeps instead of 4-8 from full contact (measured on the eccentric
    footing, e = 0.45-0.8, lam = 0.3-3; one sweep on 153 of 158 lift-off points of the
    loads study).
    """
    coarse, coarse_op = nodal_operator(space.lam, space.breakpoints, nodal_res.coarser())
    if coarse.size > COARSE_SHARE * base.size:
        return None
    try:
        state, _, _ = nodal_active_set(coarse, coarse_op, space.m(coarse.nodes),
                                       space.g(coarse.nodes), step)
    except NoContact:
        return None
    if not state.active.any():
        return None
    ends = zones_from_nodes(state, space.breakpoints)[0]
    x = base.nodes
    start = np.zeros(x.size, dtype=bool)
    for lo, hi in zip(ends[0::2], ends[1::2], strict=True):
        start |= (x >= lo) & (x <= hi)
    return start if np.count_nonzero(start) >= 3 else None


def nodal_state(space: Space, step: Step, base: Panels, op: np.ndarray, m_nodes: np.ndarray,
                g_nodes: np.ndarray, nodal_res: Resolution | None) -> NodalState:
    """The nodal active set on ``base`` (Nystrom matrix ``op``, m and g at its nodes,
    dimensionless), started from :func:`coarse_start` when ``nodal_res`` (the rule of
    ``base``) is given. A start that does not settle is retried from full contact, which
    raises :class:`NoContact` when the loads leave none."""
    start = None if nodal_res is None else coarse_start(space, step, base, nodal_res)
    if start is not None:
        try:
            state, _, settled = nodal_active_set(base, op, m_nodes, g_nodes, step,
                                                 start=start)
            if settled:
                return state
        except NoContact:
            pass
    return nodal_active_set(base, op, m_nodes, g_nodes, step)[0]
