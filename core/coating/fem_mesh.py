"""The mesh of the resolved-coating check: P2 triangles on a graded tensor grid.

The ``x`` grid is geometric toward the punch edges and the coating's breakpoints
(:func:`x_grid`), the base rows geometric toward its top, and every coating layer has its
own rows (:func:`build_mesh`); lengths in half-widths, moduli relative to the base's.
Used by :func:`core.coating.solve_stack`.
"""

from __future__ import annotations

import numpy as np

from core.coating.fem_stack import CoatingStrip, Stack

#: Smallest element next to a punch edge, in half-widths (level 0).
EDGE_SIZE = 1e-5
#: Growth of the element size away from a punch edge or breakpoint.
GROWTH = 1.6
#: Largest element under the punch, in half-widths (level 0).
INTERIOR_SIZE = 0.08
#: Element rows per coating layer (level 0).
COATING_ROWS = 2


def _graded(lo: float, hi: float, grade_lo: bool, grade_hi: bool, smallest: float,
            largest: float) -> np.ndarray:
    """Points of [lo, hi] (ends included) with sizes growing by GROWTH from ``smallest``
    at a graded end up to ``largest``."""
    def from_end(length: float) -> list[float]:
        d, step, out = 0.0, smallest, []
        while d + step < length:
            d += step
            out.append(d)
            step = min(step * GROWTH, largest)
        return out

    length = hi - lo
    if not grade_lo and not grade_hi:
        n = max(1, int(np.ceil(length / largest)))
        return np.linspace(lo, hi, n + 1)
    if grade_lo and grade_hi:
        half = 0.5 * length
        left = [lo + d for d in from_end(half) if d < half - 0.3 * smallest]
        right = [hi - d for d in from_end(half) if d < half - 0.3 * smallest]
        pts = [lo] + left + [lo + half] + right[::-1] + [hi]
        return np.unique(np.array(pts))
    dist = from_end(length)
    if grade_lo:
        pts = [lo] + [lo + d for d in dist] + [hi]
    else:
        pts = [lo] + [hi - d for d in dist[::-1]] + [hi]
    pts = np.array(pts)
    # a last sliver would be a needle element
    if pts.size > 2 and pts[-1] - pts[-2] < 0.3 * (pts[-2] - pts[-3] if pts.size > 3 else 1):
        pts = np.delete(pts, -2 if grade_lo else 1)
    return pts


def _bisect(points: np.ndarray, times: int) -> np.ndarray:
    for _ in range(times):
        points = np.sort(np.concatenate([points, 0.5 * (points[1:] + points[:-1])]))
    return points


def x_grid(stack: Stack, extent: float, level: int) -> np.ndarray:
    """The x grid in half-widths: graded toward +-1 and the breakpoints."""
    a = stack.half_width
    h_scale = stack.base_thickness / a
    inner = sorted({-1.0, 1.0} | {float(b) / a for b in stack.breakpoints if -a < b < a})
    total = total_thickness(stack, a * np.linspace(-1, 1, 201)) / a
    # outside the punch the coating bends with the base: keep its elements within a few
    # tens of its thickness long (stretched P2 elements grow too stiff in bending)
    thickest = float(np.max(total, initial=0.0))
    outer_size = 0.5 * h_scale if thickest == 0 else \
        min(0.5 * h_scale, max(INTERIOR_SIZE, 25.0 * thickest))
    pieces = [_graded(-extent, -1.0, False, True, EDGE_SIZE, outer_size)]
    for lo, hi in zip(inner[:-1], inner[1:], strict=True):
        pieces.append(_graded(lo, hi, True, True, EDGE_SIZE, min(INTERIOR_SIZE, h_scale)))
    pieces.append(_graded(1.0, extent, True, False, EDGE_SIZE, outer_size))
    return _bisect(np.unique(np.concatenate(pieces)), level)


def total_thickness(stack: Stack, x: np.ndarray) -> np.ndarray:
    """Summed thickness [m] of the coating layers at ``x`` [m], held at the edge values
    outside ``[-a, a]``."""
    a = stack.half_width
    xc = np.clip(x, -a, a)
    total = np.zeros(np.shape(x))
    for layer in stack.coating:
        total = total + np.broadcast_to(np.asarray(layer.thickness(xc), dtype=float), xc.shape)
    return total


def _material(layer: CoatingStrip, xs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    e = np.broadcast_to(np.asarray(layer.modulus(xs), dtype=float), xs.shape)
    nu = np.broadcast_to(np.asarray(layer.poisson(xs), dtype=float), xs.shape)
    return e, nu


def build_mesh(stack: Stack, extent: float, level: int) -> tuple[
        np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
        list[tuple[np.ndarray, np.ndarray]], list[CoatingStrip]]:
    """The x grid, vertices, triangles, per-triangle Lame parameters, each region's bottom
    and top rows (vertex indices in x order) and the coating layers bottom-up; lengths in
    half-widths (``extent`` the half-length of the truncated base), ``level`` bisections.
    Region 0 is the base, then the coating bottom-up."""
    a, e_ref = stack.half_width, stack.base_modulus
    xs = x_grid(stack, extent, level)
    nx = xs.size
    h_base = stack.base_thickness / a
    rows_base = -_graded(0.0, h_base, True, False, EDGE_SIZE, min(0.5, 0.25 * h_base))[::-1]
    rows_base = _bisect(np.sort(rows_base), level)
    fractions = np.linspace(0.0, 1.0, COATING_ROWS * 2**level + 1)
    points, triangles, lam, mu, rows = [], [], [], [], []
    offset = 0
    bottom = np.zeros(nx)
    xm = np.clip(a * xs, -a, a)
    layers = list(stack.coating)[::-1]  # bottom-up
    regions = [(None, rows_base)] + [(layer, fractions) for layer in layers]
    for number, (layer, ys) in enumerate(regions):
        if number == len(regions) - 1 and layer is not None:
            # the punch edge's singularity lies in the top layer: rows geometric toward
            # its top (sized on its thinnest point)
            h_min = float(np.min(np.asarray(layer.thickness(xm), dtype=float))) / a
            ys = 1.0 - _graded(0.0, 1.0, True, False, EDGE_SIZE / h_min,
                               1.0 / COATING_ROWS)[::-1]
            ys = _bisect(np.sort(ys), level)
        if layer is None:
            yy = ys[:, None] + 0 * xs[None, :]
        else:
            h = np.broadcast_to(np.asarray(layer.thickness(xm), dtype=float), xs.shape) / a
            yy = bottom[None, :] + ys[:, None] * h[None, :]
        ny = ys.size
        index = offset + np.arange(ny * nx).reshape(ny, nx)
        points.append(np.stack([np.broadcast_to(xs, yy.shape).ravel(), yy.ravel()]))
        i0, i1 = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
        i2, i3 = index[1:, :-1].ravel(), index[1:, 1:].ravel()
        # alternate the diagonals so that no direction is preferred
        flip = ((np.arange(ny - 1)[:, None] + np.arange(nx - 1)[None, :]) % 2).ravel() == 1
        t1 = np.where(flip, np.stack([i0, i1, i3]), np.stack([i0, i1, i2]))
        t2 = np.where(flip, np.stack([i0, i3, i2]), np.stack([i1, i3, i2]))
        tri = np.concatenate([t1, t2], axis=1)
        triangles.append(tri)
        cell_x = np.tile(0.5 * (xs[1:] + xs[:-1]), ny - 1)
        cell_x = np.concatenate([cell_x, cell_x])
        if layer is None:
            e = np.full(cell_x.shape, 1.0)
            nu = np.full(cell_x.shape, stack.base_poisson)
        else:
            e, nu = _material(layer, np.clip(a * cell_x, -a, a))
            e = e / e_ref
        lam.append(e * nu / ((1 + nu) * (1 - 2 * nu)))
        mu.append(e / (2 * (1 + nu)))
        rows.append((index[0], index[-1]))
        bottom = yy[-1]
        offset += ny * nx
    return (xs, np.concatenate(points, axis=1), np.concatenate(triangles, axis=1),
            np.concatenate(lam), np.concatenate(mu), rows, layers)

