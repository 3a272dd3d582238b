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
With :func:`solve_stack_contact` the punch holds only the surface nodes where it presses
(unilateral contact, the contact set found by active-set sweeps).

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

This module assembles and solves (:func:`solve_stack`); the inputs and results are in
:mod:`core.coating.fem_stack`, the mesh in :mod:`core.coating.fem_mesh`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from core.coating.fem_mesh import (
    build_mesh,
    total_thickness,
)
from core.coating.fem_stack import INTERFACES, FEContact, FEResponse, Stack
from core.optional import import_optional

#: Lateral extent of the base beyond the punch edge, in base thicknesses (the kernel of
#: the layer decays like exp(-2.1 x / H); ``--fe-study`` measured the change of the force
#: against 10 H: 2.5e-4 / 6.2e-4 at 2 H, 4e-8 / 8e-8 at 4 H, 6e-11 / 7e-11 at 6 H for
#: H = a / H = 4a).
TRUNCATION_DEPTHS = 6.0
#: Most meshes :func:`solve_stack_contact` grades toward the zone ends it found, and
#: how little [half-widths] the ends must move between two to stop.
MAX_CONTACT_PASSES = 4
CONTACT_END_TOL = 1e-3
#: Most active-set sweeps of :func:`solve_stack_contact` (each one factorization).
MAX_CONTACT_SWEEPS = 12
#: A node's force or clearance within this fraction of the largest keeps its state
#: (round-off of the solve, ~1e-13 of the scale, must not flip a node).
CONTACT_SIGN_TOL = 1e-9


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
    The punch holds the whole top surface under it (full contact).
    Returns an :class:`FEResponse` in SI units.
    """
    model = _Assembled.build(stack, level, extent)
    return model.solve(np.ones(model.xc.size, dtype=bool))


def solve_stack_contact(stack: Stack, given: Mapping[str, float], *, level: int = 0,
                        extent: float | None = None,
                        start: Sequence[tuple[float, float]] | None = None) -> FEContact:
    """The resolved model of ``stack`` with unilateral contact: the punch may lift off.

    The punch holds the surface only where it presses (nodal force >= 0) and the surface
    stays under the punch elsewhere; the contact set is found by primal-dual active-set
    sweeps over the top nodes under the punch, each sweep one factorization with the held
    nodes fixed. ``given`` holds two of settlement [m], tilt [rad], force [N/m], moment [N];
    ``start`` the contact intervals [m] to start from (default: all of ``[-a, a]``).

    A zone end lies between a held and a free node, so the mesh is graded toward the
    expected ends (they become breakpoints of the mesh) and, once found, toward the ends
    found (midway between the last held and the first free node), until they move less
    than ``CONTACT_END_TOL`` half-widths (at most ``MAX_CONTACT_PASSES`` meshes). Measured
    on an 80 mm coating lifting off to a 0.17 m contact zone: the settlement and the tilt of
    the second and third meshes differ by 1e-4 of their size.
    """
    began = time.perf_counter()
    a = stack.half_width
    intervals = [(-a, a)] if start is None else [(float(lo), float(hi)) for lo, hi in start]
    answer, moved = None, np.inf
    for _ in range(MAX_CONTACT_PASSES):
        ends = {x for interval in intervals for x in interval if -a < x < a}
        graded = replace(stack, breakpoints=tuple(sorted(set(stack.breakpoints) | ends)))
        answer = _active_set(_Assembled.build(graded, level, extent), dict(given), intervals)
        found = answer.contact
        moved = zone_ends_apart(intervals, found)
        intervals = found
        if moved < CONTACT_END_TOL * a:
            break
    answer.end_moved = float(moved)
    answer.seconds = time.perf_counter() - began
    return answer


def zone_ends_apart(first: Sequence[tuple[float, float]],
                    second: Sequence[tuple[float, float]]) -> float:
    """The largest distance [m] between the zone ends of two contact sets (inf when they
    have different numbers of zones)."""
    if len(first) != len(second):
        return float("inf")
    return max((abs(x - y) for f, s in zip(first, second, strict=True)
                for x, y in zip(f, s, strict=True)), default=0.0)


def _active_set(model: _Assembled, given: dict[str, float],
                intervals: list[tuple[float, float]]) -> FEContact:
    """Primal-dual active-set sweeps on one mesh, from the held set ``intervals`` [m]."""
    a = model.half_width
    xs = model.xc * a
    held = np.zeros(xs.size, dtype=bool)
    for lo, hi in intervals:
        held |= (xs >= lo - 1e-9 * a) & (xs <= hi + 1e-9 * a)
    seen: set[bytes] = set()
    for sweep in range(1, MAX_CONTACT_SWEEPS + 1):
        if not held.any():
            raise ValueError("the punch lifts off everywhere in the finite-element model: no "
                             "contact carries the given loads")
        response = model.solve(held)
        state = response.complete(given)
        force = response.nodal_force(state["settlement"], state["tilt"])
        clearance = response.clearance(state["settlement"], state["tilt"])
        # relative thresholds: a node whose force or clearance is round-off keeps its state
        f_tol = CONTACT_SIGN_TOL * max(float(np.max(np.abs(force))), 1e-300)
        u_tol = CONTACT_SIGN_TOL * max(abs(state["settlement"]), a * abs(state["tilt"]),
                                       float(np.max(np.abs(clearance))), 1e-300)
        update = (held & (force >= -f_tol)) | (~held & (clearance < -u_tol))
        if np.array_equal(update, held):
            return FEContact(response, state, _zone_ends(xs, held), sweep, True)
        if update.tobytes() in seen:  # a cycle: the sweeps will not settle
            break
        seen.add(held.tobytes())
        held = update
    return FEContact(response, state, _zone_ends(xs, held), sweep, False)


def _zone_ends(xs: np.ndarray, held: np.ndarray) -> list[tuple[float, float]]:
    """The contact zones [m] of a held set: each run of held nodes, its ends midway to the
    next free node (or at the punch edge)."""
    zones = []
    on = np.flatnonzero(held)
    if on.size == 0:
        return zones
    breaks = np.flatnonzero(np.diff(on) > 1)
    firsts = np.concatenate([[on[0]], on[breaks + 1]])
    lasts = np.concatenate([on[breaks], [on[-1]]])
    for i, j in zip(firsts, lasts, strict=True):
        lo = xs[i] if i == 0 else 0.5 * (xs[i] + xs[i - 1])
        hi = xs[j] if j == xs.size - 1 else 0.5 * (xs[j] + xs[j + 1])
        zones.append((float(lo), float(hi)))
    return zones


@dataclass
class _Assembled:
    """The reduced stiffness of a stack's mesh and its top nodes under the punch, before
    the punch's held nodes are chosen (dimensionless: lengths in a, stresses in E)."""

    half_width: float
    base_modulus: float
    extent: float
    stiffness: Any
    tie: Any
    reduced: Any
    reduced_of: np.ndarray
    supports: dict[int, np.ndarray]
    top: np.ndarray
    xc: np.ndarray
    gap: np.ndarray
    started: float

    @classmethod
    def build(cls, stack: Stack, level: int, extent: float | None) -> _Assembled:
        # Imported here: scipy.sparse costs ~0.07 s at start-up, which no other path needs.
        import scipy.sparse as sp

        import_optional("skfem", "the finite-element check of the coating model")
        from skfem import Basis, ElementTriP2, ElementVector, MeshTri, asm

        start = time.perf_counter()
        a = stack.half_width
        for k, layer in enumerate(stack.coating):
            if layer.interface not in INTERFACES:
                raise ValueError(f"coating[{k}].interface: must be 'smooth' or 'bonded', "
                                 f"got {layer.interface!r}")
        if extent is None:
            extent = 1.0 + TRUNCATION_DEPTHS * stack.base_thickness / a
        xs, p, t, lam, mu, rows, layers = build_mesh(stack, extent, level)
        mesh = MeshTri(p, t.astype(np.int64))
        # MeshTri may reorder a triangle's vertices but keeps the triangles' order
        basis = Basis(mesh, ElementVector(ElementTriP2()), intorder=2)
        nq = basis.X.shape[1]
        stiffness = asm(_elasticity_form(), basis, lmbda=np.repeat(lam[:, None], nq, axis=1),
                        mu=np.repeat(mu[:, None], nq, axis=1)).tocsr()
        facet_of = {(int(i), int(j)): f
                    for f, (i, j) in enumerate(np.sort(mesh.facets, axis=0).T)}

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

        supports: dict[int, np.ndarray] = {}
        bottom = _row_dofs(basis, facet_of, rows[0][0], 1)
        supports.update({int(d): np.zeros(3) for d in bottom})
        centre = int(np.argmin(np.abs(xs)))
        for r in set(pins):
            supports[int(basis.nodal_dofs[0, rows[r][0][centre]])] = np.zeros(3)
        top = _row_dofs(basis, facet_of, rows[-1][1], 1)
        x_top = np.empty(top.size)
        x_top[0::2] = xs
        x_top[1::2] = 0.5 * (xs[1:] + xs[:-1])
        y_top = np.empty(top.size)
        y_top[0::2] = p[1, rows[-1][1]]
        y_top[1::2] = 0.5 * (y_top[0:-1:2] + y_top[2::2])
        under = np.flatnonzero(np.abs(x_top) <= 1.0 + 1e-12)
        xc = x_top[under]
        f = np.zeros(xc.shape) if stack.shape is None else \
            np.broadcast_to(np.asarray(stack.shape(a * xc), dtype=float), xc.shape) / a
        # the punch touches the highest point of f - top first (the scene's gap minimum)
        dense = np.linspace(-a, a, 4001)
        f_dense = np.zeros(dense.shape) if stack.shape is None else \
            np.broadcast_to(np.asarray(stack.shape(dense), dtype=float), dense.shape)
        lowest = min(float(np.min(f_dense - total_thickness(stack, dense))) / a,
                     float(np.min(f - y_top[under])))
        return cls(half_width=a, base_modulus=stack.base_modulus, extent=extent,
                   stiffness=stiffness, tie=tie, reduced=(tie.T @ stiffness @ tie).tocsc(),
                   reduced_of=reduced_of, supports=supports,
                   top=top[under], xc=xc, gap=f - y_top[under] - lowest, started=start)

    def solve(self, held: np.ndarray) -> FEResponse:
        """The three unit responses with the punch holding the top nodes ``held`` (a mask
        over ``xc``); the other top nodes are traction free."""
        from scipy.sparse.linalg import splu

        fixed_full = dict(self.supports)
        for i in np.flatnonzero(held):
            # u_y = g - delta - alpha x, the three columns: gap, delta = a, alpha = 1 rad
            fixed_full[int(self.top[i])] = np.array([self.gap[i], -1.0, -self.xc[i]])
        reduced_of, tie, stiffness, k_red = self.reduced_of, self.tie, self.stiffness, self.reduced
        fixed_red = np.array([reduced_of[d] for d in fixed_full])
        fixed_vals = np.array(list(fixed_full.values()))
        free = np.setdiff1d(np.arange(k_red.shape[0]), fixed_red)
        u = np.zeros((k_red.shape[0], 3))
        u[fixed_red] = fixed_vals
        # The stiffness is symmetric positive definite (the pins remove every rigid motion):
        # a symmetric ordering without pivoting, measured on the default preset's check
        # (63.5k unknowns): factors 6.4M entries instead of 18.3M, 1.4-1.8 s instead of
        # 3.6 s, the answer the same to 2e-7 of its size (the conditioning; the check's own
        # error is 1e-4)
        lu = splu(k_red[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A",
                  diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        u[free] = lu.solve(-(k_red[free][:, fixed_red] @ fixed_vals))
        reaction = tie.T @ (stiffness @ (tie @ u))  # reduced forces; nonzero on fixed only
        top_red = reduced_of[self.top]
        load = -np.asarray(reaction[top_red])  # the punch presses down: q = -traction_y
        load[~held] = 0.0  # free nodes carry no load (round-off of the reaction there)
        force = load.sum(axis=0)
        moment = (self.xc[:, None] * load).sum(axis=0)
        pressure = _recover_pressure(self.xc, load)
        # back to SI: lengths * a, stresses * E; columns per (gap, delta [m], alpha [rad])
        a, e_ref = self.half_width, self.base_modulus
        col = np.array([a, 1.0, a])
        punch = np.stack([self.gap, -np.ones_like(self.xc), -self.xc], axis=1)
        return FEResponse(
            half_width=a, x_nodes=a * self.xc, pressure_parts=(pressure * e_ref * col / a).T,
            force_parts=force * e_ref * col, moment_parts=moment * e_ref * a * col,
            dofs=int(free.size), seconds=time.perf_counter() - self.started,
            extent=self.extent, nodal_force_parts=(load * e_ref * col).T,
            clearance_parts=((punch - u[top_red]) * col).T)


def _recover_pressure(xc: np.ndarray, nodal_forces: np.ndarray) -> np.ndarray:
    """Nodal values of the P2 pressure whose consistent nodal forces are ``nodal_forces``
    (the L2 projection of the contact traction onto the boundary's P2 space)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import splu

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
