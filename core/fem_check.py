"""A resolved-coating check: plane-strain finite elements of the punch on its layers.

The thin-coating model of the solver treats the coating as a local (Winkler) layer on the
base's nonlocal kernel. This module computes the same contact problem with the coating
resolved: each coating layer is an elastic strip whose thickness, modulus and Poisson ratio
may vary along ``x``, lying on the next layer (or on the base) either ``"smooth"``
(frictionless: the vertical displacement is continuous, the layers slide freely) or
``"bonded"`` (all displacement continuous); the base is an elastic layer of thickness ``H``
lying without friction on a rigid bed (vertical displacement 0, horizontal free), and the
rigid punch presses the top surface on ``[-a, a]`` without friction in full contact (the
statement-1 kinematics ``u_y = g(x) - delta - alpha x`` there, no tangential traction). The
rest of the top surface and the lateral ends of the truncated domain are traction free.

Discretization: quadratic (P2) triangles on a tensor grid in ``x`` times per-region rows in
``y``; the ``x`` grid is geometric toward the punch edges and toward the coating's
breakpoints, the base rows are geometric toward its top, every coating layer has its own
rows (so the mesh is as thin as the coating). Coating profiles are defined on ``[-a, a]``;
outside the punch the coating continues with its edge values. The problem is linear, so
one factorization gives three responses: to the gap ``g`` alone, to a unit settlement and
to a unit tilt; any of the four statements then follows from two equations.

Measured against the project's kernel solution of the uncoated layer (``nu = 0.3``,
``benchmarks/coating_validity.py --fe-study``): relative error of P per unit settlement /
M per unit tilt at H = a: level 0 1.0e-4 / 2.3e-4 (25k unknowns, ~1 s), level 1 8.2e-6 /
2.0e-5 (99k, ~7 s); at H = 4a: 2.0e-4 / 3.3e-4 (32k, ~2 s) and 1.5e-5 / 2.6e-5 (129k, ~14 s):
observed order 3.6-3.7 in the element size (timings on a shared 2-core machine).
Coated, ``sum h / 2a = 0.02``, ``E_c / E = 0.05``, ``nu_c = 0.45``, H = a: levels 0 and
1 differ by 4e-5 / 9e-5 (smooth) and 5e-5 / 1.3e-4 (bonded).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

#: Interfaces of a coating layer with what lies under it.
INTERFACES = ("smooth", "bonded")
#: Lateral extent of the base beyond the punch edge, in base thicknesses (the kernel of
#: the layer decays like exp(-2.1 x / H); ``--fe-study`` measured the change of the force
#: against 10 H: 2.5e-4 / 6.2e-4 at 2 H, 4e-8 / 8e-8 at 4 H, 6e-11 / 7e-11 at 6 H for
#: H = a / H = 4a).
TRUNCATION_DEPTHS = 6.0
#: Smallest element next to a punch edge, in half-widths (level 0).
EDGE_SIZE = 1e-5
#: Growth of the element size away from a punch edge or breakpoint.
GROWTH = 1.6
#: Largest element under the punch, in half-widths (level 0).
INTERIOR_SIZE = 0.08
#: Element rows per coating layer (level 0).
COATING_ROWS = 2

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


# ---------------------------------------------------------------------------- the mesh


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


def _x_grid(stack: Stack, extent: float, level: int) -> np.ndarray:
    """The x grid in half-widths: graded toward +-1 and the breakpoints."""
    a = stack.half_width
    h_scale = stack.base_thickness / a
    inner = sorted({-1.0, 1.0} | {float(b) / a for b in stack.breakpoints if -a < b < a})
    total = _total_thickness(stack, a * np.linspace(-1, 1, 201)) / a
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


def _total_thickness(stack: Stack, x: np.ndarray) -> np.ndarray:
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


def _build_mesh(stack: Stack, extent: float, level: int):
    """Vertices, triangles, per-triangle Lame parameters, and each region's bottom and top
    rows (vertex indices in x order). Region 0 is the base, then the coating bottom-up."""
    a, e_ref = stack.half_width, stack.base_modulus
    xs = _x_grid(stack, extent, level)
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


# --------------------------------------------------------------------------- the solve


def _row_dofs(basis, facet_of: dict, row: np.ndarray, component: int) -> np.ndarray:
    """DOFs of one displacement component along a row of vertices: vertex, edge midpoint,
    vertex, ... in x order."""
    edges = [facet_of[(min(p, q), max(p, q))] for p, q in zip(row[:-1], row[1:], strict=True)]
    out = np.empty(2 * row.size - 1, dtype=np.int64)
    out[0::2] = basis.nodal_dofs[component, row]
    out[1::2] = basis.facet_dofs[component, edges]
    return out


def _elasticity_form():
    from skfem import BilinearForm
    from skfem.helpers import ddot, sym_grad, trace

    @BilinearForm
    def form(u, v, w):
        eu, ev = sym_grad(u), sym_grad(v)
        return 2.0 * w.mu * ddot(eu, ev) + w.lmbda * trace(eu) * trace(ev)
    return form


def solve_stack(stack: Stack, *, level: int = 0, extent: float | None = None) -> FEResponse:
    """Solve the resolved model of ``stack`` for the gap, a unit settlement and a unit tilt.

    ``level`` bisects every element edge of the base mesh ``level`` times (0: the default
    check, ~3e4 unknowns, force error ~2e-4; 1: ~1e5 unknowns, ~2e-5); ``extent`` is the half-length
    of the truncated base in half-widths (default ``1 + TRUNCATION_DEPTHS H / a``).
    Returns an :class:`FEResponse` in SI units.
    """
    from skfem import Basis, ElementTriP2, ElementVector, MeshTri, asm

    start = time.perf_counter()
    a, e_ref = stack.half_width, stack.base_modulus
    for k, layer in enumerate(stack.coating):
        if layer.interface not in INTERFACES:
            raise ValueError(f"coating[{k}].interface: must be 'smooth' or 'bonded', "
                             f"got {layer.interface!r}")
    if extent is None:
        extent = 1.0 + TRUNCATION_DEPTHS * stack.base_thickness / a
    xs, p, t, lam, mu, rows, layers = _build_mesh(stack, extent, level)
    mesh = MeshTri(p, t.astype(np.int64))
    # MeshTri may reorder a triangle's vertices but keeps the triangles' order
    basis = Basis(mesh, ElementVector(ElementTriP2()), intorder=2)
    nq = basis.X.shape[1]
    stiffness = asm(_elasticity_form(), basis, lmbda=np.repeat(lam[:, None], nq, axis=1),
                    mu=np.repeat(mu[:, None], nq, axis=1)).tocsr()
    facet_of = {(int(i), int(j)): f for f, (i, j) in enumerate(np.sort(mesh.facets, axis=0).T)}

    n = basis.N
    master = np.arange(n)
    pins: list[int] = []
    body_start = 0  # the lowest region of the current bonded body
    for r in range(1, len(rows)):
        below_top, above_bottom = rows[r - 1][1], rows[r][0]
        bonded = layers[r - 1].interface == "bonded"
        for comp in ((0, 1) if bonded else (1,)):
            lo = _row_dofs(basis, facet_of, below_top, comp)
            hi = _row_dofs(basis, facet_of, above_bottom, comp)
            master[hi] = lo
        if not bonded:
            pins.append(body_start)
            body_start = r
    pins.append(body_start)
    # resolve chains of ties down to the base
    for _ in range(len(rows)):
        master = master[master]
    reps, reduced_of = np.unique(master, return_inverse=True)
    tie = sp.csr_matrix((np.ones(n), (np.arange(n), reduced_of)), shape=(n, reps.size))
    k_red = (tie.T @ stiffness @ tie).tocsc()

    fixed_full: dict[int, np.ndarray] = {}
    bottom = _row_dofs(basis, facet_of, rows[0][0], 1)
    values = np.zeros((3, bottom.size))
    fixed_full.update({int(d): values[:, i] for i, d in enumerate(bottom)})
    centre = int(np.argmin(np.abs(xs)))
    for r in set(pins):
        d = int(basis.nodal_dofs[0, rows[r][0][centre]])
        fixed_full[d] = np.zeros(3)
    top = _row_dofs(basis, facet_of, rows[-1][1], 1)
    x_top = np.empty(top.size)
    x_top[0::2] = xs
    x_top[1::2] = 0.5 * (xs[1:] + xs[:-1])
    y_top = np.empty(top.size)
    y_top[0::2] = p[1, rows[-1][1]]
    y_top[1::2] = 0.5 * (y_top[0:-1:2] + y_top[2::2])
    contact = np.flatnonzero(np.abs(x_top) <= 1.0 + 1e-12)
    xc = x_top[contact]
    f = np.zeros(xc.shape) if stack.shape is None else \
        np.broadcast_to(np.asarray(stack.shape(a * xc), dtype=float), xc.shape) / a
    # the punch touches the highest point of f - top first (the scene's gap minimum)
    dense = np.linspace(-a, a, 4001)
    f_dense = np.zeros(dense.shape) if stack.shape is None else \
        np.broadcast_to(np.asarray(stack.shape(dense), dtype=float), dense.shape)
    lowest = min(float(np.min(f_dense - _total_thickness(stack, dense))) / a,
                 float(np.min(f - y_top[contact])))
    gap = f - y_top[contact] - lowest
    for i, d in enumerate(top[contact]):
        # u_y = g - delta - alpha x, the three columns: gap, delta = a, alpha = 1 rad
        fixed_full[int(d)] = np.array([gap[i], -1.0, -xc[i]])

    fixed_red = np.array([reduced_of[d] for d in fixed_full])
    fixed_vals = np.array(list(fixed_full.values()))
    free = np.setdiff1d(np.arange(reps.size), fixed_red)
    u = np.zeros((reps.size, 3))
    u[fixed_red] = fixed_vals
    lu = splu(k_red[free][:, free].tocsc())
    u[free] = lu.solve(-(k_red[free][:, fixed_red] @ fixed_vals))
    reaction = tie.T @ (stiffness @ (tie @ u))  # reduced forces; nonzero on fixed only
    r_top = np.asarray(reaction[reduced_of[top[contact]]])  # (nodes, 3)
    load = -r_top  # the punch presses down: q = -traction_y
    force = load.sum(axis=0)
    moment = (xc[:, None] * load).sum(axis=0)
    pressure = _recover_pressure(xc, load)
    # back to SI: lengths * a, stresses * E; columns per (gap, delta [m], alpha [rad])
    col = np.array([a, 1.0, a])
    return FEResponse(
        half_width=a, x_nodes=a * xc, pressure_parts=(pressure * e_ref * col / a).T,
        force_parts=force * e_ref * col, moment_parts=moment * e_ref * a * col,
        dofs=int(free.size), seconds=time.perf_counter() - start, extent=extent)


def _recover_pressure(xc: np.ndarray, nodal_forces: np.ndarray) -> np.ndarray:
    """Nodal values of the P2 pressure whose consistent nodal forces are ``nodal_forces``
    (the L2 projection of the contact traction onto the boundary's P2 space)."""
    nseg = (xc.size - 1) // 2
    local = np.array([[4.0, 2.0, -1.0], [2.0, 16.0, 2.0], [-1.0, 2.0, 4.0]]) / 30.0
    rows, cols, vals = [], [], []
    for s in range(nseg):
        idx = np.array([2 * s, 2 * s + 1, 2 * s + 2])
        length = xc[2 * s + 2] - xc[2 * s]
        rows.append(np.repeat(idx, 3))
        cols.append(np.tile(idx, 3))
        vals.append((length * local).ravel())
    mass = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(xc.size, xc.size))
    return splu(mass).solve(nodal_forces)
