"""Unilateral contact: the punch may lift off, and the contact set is part of the answer.

:func:`solve_unilateral` solves the dimensionless problem of ``docs/method.md`` with
``q >= 0`` and an unknown contact set ``S(t)`` in [-1, 1] (may have several pieces):

    c m q + (I - V) F q = delta + alpha x - g   on S(t),  q > 0 there,
    (I - V) F q >= delta + alpha x - g          off S(t), q = 0 there (the gap is open),
    int q dx = P,  int x q dx = M               (two of delta, alpha, P, M given).

Elastic base (``kernel=None``): each time is solved on its own
(:mod:`core.contact.elastic`), the zone ends located to ``ZONE_END_TOL`` by
:mod:`core.contact.zones`. Creep: implicit stepping with the active
set found at every step, on a rule refined where the zone ends travel
(:mod:`core.contact.creep`, :mod:`core.contact.bands`), the zone ends located to
``ZONE_END_TOL`` or, at a looser tol, to tol / 10 (:func:`core.contact.creep.march_end_tol`).

The answer is a :class:`UnilateralSolution` (:mod:`core.contact.result`, which also holds
:func:`contact_set_from_pressure`: sampled pressures of any engine into contact sets);
:mod:`core.contact.switch` holds the ``contact=`` switch of
:func:`core.solver.solve_dimensionless`.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable, Sequence

import numpy as np

from core.contact.elastic import _solve_elastic
from core.contact.result import UnilateralSolution
from core.contact.step import Space, check_loads
from core.contact.zones import NODAL_PANEL_WIDTH, ZONE_EDGE_WIDTH, ZONE_PANEL_WIDTH, Resolution
from core.kernel import FULL_ACCURACY

#: The contact models of ``solve_dimensionless(..., contact=...)``.
CONTACT_MODELS = ("full", "unilateral", "auto")
#: The contact set of full contact.
FULL_CONTACT: list[tuple[float, float]] = [(-1.0, 1.0)]
#: The base of the fixed rule of creep steps: panels at most this wide, graded to this
#: width at +-1 and the breakpoints (finer for a thin coating); the bands the zone ends
#: sweep get finer panels (core/contact/bands.py: outside them 0.5 and 0.0625 gave the
#: same ends to 1e-14 on the lift-off preset).
_CREEP_WIDTH = 0.5
_CREEP_EDGE = 1e-2

Scalar = float | Callable[[np.ndarray], np.ndarray]



def solve_unilateral(lam: float, m: Scalar, g: Scalar, times: Sequence[float] | np.ndarray,
                     *, c: Scalar = 1.0, kernel: Callable | None = None,
                     settlement: Scalar | None = None, tilt: Scalar | None = None,
                     force: Scalar | None = None, moment: Scalar | None = None,
                     breakpoints: Sequence[float] = (), tol: float = 1e-8,
                     time_steps: int | None = None,
                     time_breaks: Sequence[float] = ()) -> UnilateralSolution:
    """Solve the dimensionless problem with unilateral contact (the punch may lift off).

    Arguments as :func:`core.solver.solve_dimensionless` (all dimensionless): ``lam`` =
    a/H; ``m(x) > 0`` coating compliance; ``g(x)`` gap; ``times`` >= 1 increasing; ``c(t)``
    relative modulus; ``kernel`` K(t, tau) of V or None (elastic); exactly two of
    ``settlement`` (delta), ``tilt`` (alpha), ``force`` (P), ``moment`` (M); ``breakpoints``
    where m or g may jump; ``tol`` for delta, alpha, P, M (relative, as in the solver).
    ``time_steps``: nominal steps of the first creep grid over ``[1, times[-1]]`` (default
    ``core.contact.creep.FIRST_STEPS``; the grid is then halved until ``tol`` is met).
    ``time_breaks``: times where a given load jumps (under creep, no time step straddles
    one; elastic answers read each time on its own).

    Returns a :class:`UnilateralSolution` whose ``contact_set`` gives the contact zones
    at each time (free ends located to ``ZONE_END_TOL`` half-widths on an elastic base).
    Raises ``ValueError`` naming the argument on bad input and naming the load when the
    loads pull the punch away (``force <= 0`` in statement 4 or 3, ``|moment/force| >= 1``).
    """
    from core.engines.projection import validate_inputs

    started = _time.perf_counter()
    if time_steps is not None and (isinstance(time_steps, bool) or not isinstance(
            time_steps, (int, np.integer)) or not 1 <= time_steps <= 4096):
        raise ValueError(f"time_steps: must be an integer in [1, 4096], got {time_steps!r}")
    inp = validate_inputs(lam, m, g, times, c, kernel,
                    {"settlement": settlement, "tilt": tilt, "force": force,
                     "moment": moment}, breakpoints, tol)
    times_arr = inp.times
    c_t = inp.c(times_arr)
    loads = {name: np.asarray(fn(times_arr), dtype=float) for name, fn in inp.loads.items()}
    check_loads(inp.given, loads, times_arr)
    space = Space(inp.lam, inp.m, inp.g, inp.breakpoints)
    res = zone_resolution(inp.lam, inp.m)
    nodal_res = nodal_resolution(inp.lam, inp.m)
    if inp.kernel is None:
        out = _solve_elastic(space, c_t, loads, times_arr, nodal_res, res, inp.tol)
    else:
        from core.contact.creep import solve_creep

        out = solve_creep(space, inp, c_t, loads, creep_resolution(inp.lam, inp.m),
                          **({} if time_steps is None else {"first_steps": time_steps}),
                          jumps=tuple(float(b) for b in time_breaks))
    out["info"]["seconds"] = _time.perf_counter() - started
    return UnilateralSolution(times_arr.copy(), out["settlement"], out["tilt"], out["force"],
                              out["moment"], out["contact_set"], out["info"], space,
                              out["snapshots"], out.get("kernel_accuracy", FULL_ACCURACY))


def zone_resolution(lam: float, m: Callable[[np.ndarray], np.ndarray]) -> Resolution:
    """The first rule of the zone ends: panels at most ``ZONE_PANEL_WIDTH`` (and 3/lam)
    wide, graded to ``ZONE_EDGE_WIDTH`` at +-1, the breakpoints and the ends, finer for a
    thin coating (its boundary layer is ~m wide)."""
    m_probe = m(np.linspace(-1.0, 1.0, 257))
    return Resolution(min(ZONE_PANEL_WIDTH, 3.0 / lam),
                      min(ZONE_EDGE_WIDTH, 0.25 * float(np.min(m_probe))))


def creep_resolution(lam: float, m: Callable[[np.ndarray], np.ndarray]) -> Resolution:
    """The base of the fixed rule of creep steps: panels at most ``_CREEP_WIDTH`` (and
    3/lam) wide, graded to ``_CREEP_EDGE`` at +-1 and the breakpoints, finer for a thin
    coating (never coarser than :func:`zone_resolution`'s grading)."""
    m_probe = m(np.linspace(-1.0, 1.0, 257))
    res = zone_resolution(lam, m)
    return Resolution(min(_CREEP_WIDTH, 3.0 / lam), max(res.edge, min(
        _CREEP_EDGE, 0.25 * float(np.min(m_probe)))))


def nodal_resolution(lam: float, m: Callable[[np.ndarray], np.ndarray]) -> Resolution:
    """The rule of the nodal active set: panels at most ``NODAL_PANEL_WIDTH`` (and 3/lam)
    wide, graded to ``ZONE_EDGE_WIDTH`` at +-1 and the breakpoints, finer for a thin
    coating."""
    m_probe = m(np.linspace(-1.0, 1.0, 257))
    return Resolution(min(NODAL_PANEL_WIDTH, 3.0 / lam),
                      min(ZONE_EDGE_WIDTH, 0.25 * float(np.min(m_probe))))
