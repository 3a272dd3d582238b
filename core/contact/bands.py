"""Panel rules for stepping lift-off under creep: fine panels where the zone ends travel.

Under creep the contact set is found node by node on one fixed panel rule (the memory of
every past pressure lives on its nodes). At a free end q = max(Q, 0) has a kink inside a
panel, which the panel's Gauss rule integrates to only a low order, and the kinks of all
past pressures stay in the memory. Measured on the lift-off preset (ends against a rule
with 0.005-wide panels over the band, same time grid): panels 0.125 wide everywhere left
the ends 6.9e-5 off; uniform panels over the band the ends sweep, 0.04 / 0.02 / 0.01
wide, 3.9e-6 / 1.6e-6 / 4.8e-7 (ratio 2.4-3.3 per halving), and the panels outside the
band did not matter (0.5 or 0.0625 wide: the same ends to 1e-14, q is smooth there).

:func:`band_rule` builds such a rule; :func:`bands_from_ends` finds the bands from the
ends of a first, coarse march. For a problem even in x the rule is made symmetric about
0 (:func:`even_rule`), so that the march solves it on the half x > 0
(:class:`core.contact.systems.Mirror`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from core.contact.step import Space
from core.contact.zones import Resolution
from core.discretize import Panels, base_panels

#: Widths of the band panels tried in turn (each checked against half of it). With the
#: kink correction of the ends (core/contact/kinks.py) 0.04 left the preset's ends 3.2e-7
#: off (against 0.0025-wide band panels, 12 output times), and its check estimated
#: 7.7e-7, above the half of the zone ends' 1e-6 the panel rule may take: the check march
#: at 0.04 only ever led to 0.02, so the first width tried is 0.02 (ends 6.4e-8 off,
#: estimate 1.5e-7). The base panels outside the band did not matter (0.5 or 0.25 wide
#: away from it, the ends and outputs the same to 1e-9), so the chosen rule keeps the
#: base of the scene: 304 nodes, against 384 when it took the halved base of its check.
BAND_WIDTHS = (0.02, 0.01, 0.005, 0.0025)
#: ... of which those below this are a last resort: tried only where the zone ends' error
#: that the check finds at the width before would, through the slope of q beside them
#: (``core.contact.creep.free_end_slope``) alone, fail the answer's tol, and while the rule
#: that checks them (their panels halved) has at most ``MAX_CHECK_NODES`` nodes (the
#: marches are dense in them: 4096 nodes, 134 MB for the operator, ~1.5 s a
#: factorization). 0.0025 reaches the ends that 0.005 leaves ~5e-8 off where a free end
#: sits a few thousandths from a breakpoint (the stepped punch's outer parts lifting beside
#: the steps under a 1 GPa coating: its check read 9.4e-8 at 0.005 against the 2e-8 asked,
#: and q beside them 5.5e-7 at tol 1e-6; 6e-9 at 0.0025), on bands a few hundredths wide.
#: Where the ends miss only their own share at 0.005 but the answer meets tol (the crowned
#: default scene at R = 10 km: 0.6 s, 2.6 s at 0.0025), or the band is as wide as a growing
#: eccentricity's (~0.66: its check at 0.0025 has 4300 nodes, 19 s), 0.005 stays the last.
LAST_RESORT_BELOW = 0.005
MAX_CHECK_NODES = 4096
#: An end this near +-1 or a breakpoint [half-widths] is pinned there (a corner of the
#: punch), not free.
PINNED_WITHIN = 1e-12
#: Margin added on both sides of the range an end sweeps [half-widths]: the ends of a
#: finer time grid or of output times the first march skipped move a little further.
BAND_MARGIN = 0.02


def pinned_end(end: float, breakpoints: Sequence[float] = ()) -> bool:
    """Whether a zone end sits at +-1 or at a breakpoint (a corner of the punch, where q
    need not vanish), within :data:`PINNED_WITHIN`; every other end is free."""
    return any(abs(float(end) - p) <= PINNED_WITHIN
               for p in (-1.0, 1.0, *(float(b) for b in breakpoints)))


def bands_from_ends(ends: Sequence[Sequence[float]], breakpoints: Sequence[float] = (),
                    margin: float = BAND_MARGIN) -> list[tuple[float, float]]:
    """Intervals covering every free zone end of ``ends`` (one list of ends per time).

    Ends at +-1 or at a breakpoint are pinned there (a corner of the punch) and need no
    band. Between consecutive times with as many ends, each end free at either time is
    taken to have travelled between its two places (the steps between them put their
    kinks there too).
    Each range, widened by ``margin``, is merged with overlapping ones.
    """
    def free(e: float) -> bool:
        return not pinned_end(e, breakpoints)

    spans = [(float(e), float(e)) for row in ends for e in row if free(e)]
    for before, after in zip(ends[:-1], ends[1:], strict=False):
        if len(before) == len(after):
            # an end that reaches a corner (a zone spreading to full contact) or leaves
            # it swept the way between too: the crowned default (R = 20 km) spread from
            # 0.944 to 1 between two of the first march's times, its ends left the band
            # and the rule was chosen again (2.9 s instead of 1.5 s)
            spans += [(min(a, b), max(a, b)) for a, b in zip(before, after, strict=True)
                      if free(a) or free(b)]
    return merge_bands([(max(a - margin, -1.0), min(b + margin, 1.0)) for a, b in spans])


def merge_bands(bands: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """``bands`` sorted, those that overlap or touch merged into one."""
    merged: list[list[float]] = []
    for lo, hi in sorted(bands):
        if merged and lo <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], hi)
        else:
            merged.append([lo, hi])
    return [(float(lo), float(hi)) for lo, hi in merged]


def band_rule(space: Space, res: Resolution, bands: Sequence[tuple[float, float]],
              width: float) -> Panels:
    """The base rule of ``res`` (panels at most ``res.width``, graded to ``res.edge`` at +-1
    and the breakpoints) with panels at most ``width`` wide over each of ``bands``."""
    base = base_panels(space.lam, space.breakpoints, edge_width=res.edge,
                       max_width=res.width)
    if not bands:
        return base
    hard = sorted({-1.0, 1.0, *(float(b) for b in space.breakpoints)})
    added: list[float] = []
    for lo, hi in bands:
        # A band reaching within half a panel of a hard point ends on it (no sliver).
        for h in hard:
            lo = h if abs(lo - h) < 0.5 * width else lo
            hi = h if abs(hi - h) < 0.5 * width else hi
        cuts = sorted({lo, hi} | {h for h in hard if lo < h < hi})
        for a, b in zip(cuts[:-1], cuts[1:], strict=True):
            count = max(1, math.ceil((b - a) / width - 1e-9))
            added.extend(np.linspace(a, b, count + 1))
    added_arr = np.unique(np.asarray(added))
    inside = np.zeros(base.edges.size, dtype=bool)
    for lo, hi in bands:
        inside |= (base.edges > lo - 0.3 * width) & (base.edges < hi + 0.3 * width)
    near_added = np.min(np.abs(base.edges[:, None] - added_arr[None, :]), axis=1) < 0.3 * width
    # Base edges inside a band go unless they are hard or belong to a grading finer than
    # the band panels (toward +-1 or a breakpoint).
    fine = np.zeros(base.edges.size, dtype=bool)
    widths = np.diff(base.edges)
    fine[:-1] |= widths < width
    fine[1:] |= widths < width
    is_hard = np.isin(base.edges, hard)
    keep = is_hard | ~(inside | near_added) | fine
    edges = np.unique(np.concatenate([base.edges[keep], added_arr]))
    # Merge what is left closer than a tenth of a band panel (never a hard point).
    merged = [edges[0]]
    for e in edges[1:]:
        if e - merged[-1] < 0.1 * width and not np.isin(merged[-1], hard):
            merged[-1] = e
        elif e - merged[-1] < 0.1 * width and not np.isin(e, hard):
            continue
        else:
            merged.append(e)
    return Panels.from_edges(np.asarray(merged))


def mirrored_bands(bands: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """``bands`` and their mirror images about x = 0, merged where they overlap."""
    return merge_bands([*bands, *((-float(b), -float(a)) for a, b in bands)])


def even_rule(rule: Panels) -> Panels:
    """``rule`` made symmetric about x = 0: its edges on x > 0 and their mirror images,
    with 0 an edge where it was one or where the panel across 0 would otherwise be wider
    than it was. :func:`band_rule` on symmetric bands is not symmetric itself: it merges
    close edges scanning from -1, which moved an edge of the stepped punch's rule by 7e-4
    half-widths from the mirror image of its counterpart (and left q 1.2e-10 asymmetric
    under a centred force)."""
    edges = rule.edges
    right = edges[edges > PINNED_WITHIN]
    middle = bool(np.any(np.abs(edges) <= PINNED_WITHIN))
    if not middle:
        k = int(np.searchsorted(edges, 0.0))
        middle = 2.0 * right[0] > (edges[k] - edges[k - 1]) * (1.0 + 1e-9)
    symmetric = np.concatenate([-right[::-1], [0.0] if middle else [], right])
    if symmetric.size == edges.size and np.array_equal(symmetric, edges):
        return rule
    return Panels.from_edges(symmetric)
