"""The files of an answer for several punches (:class:`core.scene.PunchesSolution`): the
histories of every punch as CSV, and the contact pressure q over the whole surface.

The columns follow :meth:`core.scene.SceneSolution.to_csv`, each named by the punch's
path in the scene file (``punches[1].tilt_rad``); the pressure is written as
:meth:`core.scene.SceneSolution.pressure_csv` writes it (long form, ``time_day, x_m,
pressure_Pa``), with ``x`` the global x [m]: on each punch's own plotting grid, punches
in order along x. Between the punches the surface is free (q = 0) and no row is written
there: a row is a point of a contact zone.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from core.optional import import_optional
from core.scene.design import (
    DesignCheck,
    DesignLimits,
    answer_accuracy,
    check_design,
    without_round_off,
)
from core.scene.display import HISTORIES
from core.scene.files import scene_to_json
from core.scene.results import history_columns, pressure_points
from core.version import VERSION

#: The ``format`` of a solution of several punches, in its JSON and its dataset's
#: attributes.
SOLUTION_OF_PUNCHES = "coated-punch solution of several punches"

if TYPE_CHECKING:
    from core.scene.punches import PunchesSolution

#: How far past a punch's edge [share of its half-width] a point still counts as on the
#: punch: the rounding of ``center + x`` at ``x = +-a`` (as :meth:`SceneSolution.pressure`).
EDGE_ROUNDING = 1e-12


def in_order(result: PunchesSolution) -> list[int]:
    """The punches' indices in order of their centres along x."""
    return sorted(range(len(result.punches)), key=lambda k: result.punches[k].center)


def surface_x(result: PunchesSolution) -> np.ndarray:
    """The plotting points of the whole surface [m, global x]: every punch's grid
    (:attr:`SceneSolution.x`) about its centre, punches in order along x."""
    return np.concatenate([result.punches[k].center + result.punches[k].x
                           for k in in_order(result)])


def surface_pressure_on_grid(result: PunchesSolution) -> np.ndarray:
    """q [Pa] at :func:`surface_x`, shape ``(len(x), len(times))``: each punch's
    ``pressure_on_grid``, in the same order."""
    return np.concatenate([result.punches[k].pressure_on_grid for k in in_order(result)])


def surface_pressure(result: PunchesSolution, x: Any) -> np.ndarray:
    """Contact pressure q [Pa] at points ``x`` [m] of the global x, shape
    ``(len(x), len(times))``: each punch's q on its zone ``[center - a, center + a]``,
    0 elsewhere (the free surface carries no pressure).

    Raises ValueError naming ``x``: a point that is not finite, or more points than
    :data:`core.limits.MAX_PRESSURE_VALUES` values allow (checked before any work).
    """
    times = result.times.size
    xs = pressure_points(x, times)
    q = np.zeros((xs.size, times))
    for punch in result.punches:
        a = punch.scene.half_width
        on = np.abs(xs - punch.center) <= a * (1 + EDGE_ROUNDING)
        if on.any():
            q[on] = punch.pressure_at(xs[on])
    return q


def histories_csv(result: PunchesSolution) -> str:
    """The histories of every punch as CSV: ``time_day``, then for each punch ``k`` in
    the scene's order ``punches[k].settlement_m``, ``punches[k].tilt_rad``,
    ``punches[k].force_N_per_m``, ``punches[k].moment_N`` (and, where the unilateral
    contact model answered that punch, its contact length and zone ends in the global x,
    ``punches[k].zone1_start_m``, ...), as :meth:`SceneSolution.to_csv`."""
    names: list[str] = []
    columns: list[list[float]] = []
    for k, punch in enumerate(result.punches):
        more_names, more_columns = history_columns(punch, f"punches[{k}].")
        names += more_names
        columns += more_columns
    lines = ["time_day," + ",".join(names)]
    lines.extend(",".join(repr(float(v)) for v in (t, *row))
                 for t, row in zip(result.times, zip(*columns, strict=True), strict=True))
    return "\n".join(lines) + "\n"


def pressure_csv(result: PunchesSolution, x: Any = None) -> str:
    """q(x, t) over the whole surface as CSV in long form: ``time_day``, ``x_m`` (global
    x), ``pressure_Pa``; by default on :func:`surface_x` (the contact zones only), else at
    the points ``x`` [m] (0 off the punches: :func:`surface_pressure`)."""
    if x is None:
        xs, q = surface_x(result), surface_pressure_on_grid(result)
    else:
        xs = np.atleast_1d(np.asarray(x, dtype=float))
        q = surface_pressure(result, xs)
    lines = ["time_day,x_m,pressure_Pa"]
    for j, t in enumerate(result.times):
        tt = repr(float(t))
        lines.extend(f"{tt},{float(xi)!r},{float(qi)!r}"
                     for xi, qi in zip(xs, q[:, j], strict=True))
    return "\n".join(lines) + "\n"


def design_checks(result: PunchesSolution, limits: DesignLimits | None = None
                  ) -> list[DesignCheck | None]:
    """The design check of every punch over the whole history (as
    :meth:`SceneSolution.design_check`, positions in the global x [m]) against ``limits``
    (default: the scene's ``limits``, which every punch shares); None for each when
    neither sets a limit."""
    out: list[DesignCheck | None] = []
    for punch in result.punches:
        given = limits if limits is not None else punch.scene.limits
        corners = punch.info.get("corner_pressure")
        if corners:  # in the global x, as the grid
            corners = {**corners, "corners_m": [punch.center + c for c in corners["corners_m"]]}
        # (round-off as zero, as one punch's check and the page read it)
        histories = without_round_off({"settlement": punch.settlement, "tilt": punch.tilt},
                                      punch.scene.half_width)
        out.append(None if given is None or given.empty else check_design(
            punch.times, punch.center + punch.x, punch.pressure_on_grid,
            histories["settlement"], histories["tilt"], given, corners,
            answer_accuracy(punch.info)))
    return out


def to_xarray(result: PunchesSolution) -> Any:
    """``result`` as an ``xarray.Dataset``: every punch's histories over ``punch`` and
    ``time`` [day] (``center`` [m] and the contact width [m] beside them), the contact
    pressure q over the surface on ``x`` [m, global x: each punch's plotting grid, punches
    in order; q = 0 between them], with units and long names as
    :meth:`core.scene.SceneSolution.to_xarray` gives them; the scene (canonical JSON), the
    flags and the largest error estimate in the attributes."""
    xr = import_optional("xarray", "PunchesSolution.to_xarray")
    punches = result.punches
    coords = {
        "punch": ("punch", np.arange(len(punches)),
                  {"long_name": "index of the punch in the scene's punches"}),
        "time": ("time", result.times.copy(), {"units": "day", "long_name": "time after loading"}),
        "x": ("x", result.x.copy(), {"units": "m", "long_name": "position along the surface"}),
    }
    variables: dict[str, Any] = {
        "pressure": (("x", "time"), result.pressure_on_grid.copy(),
                     {"units": "Pa", "long_name": "contact pressure", "symbol": "q"}),
        "center": ("punch", np.array([p.center for p in punches]),
                   {"units": "m", "long_name": "centre of the punch"}),
        "contact_width": (("punch", "time"), np.array([p.contact_width for p in punches]),
                          {"units": "m", "long_name": "length of the punch's contact set"}),
    }
    for name, (unit, long_name, symbol) in HISTORIES.items():
        variables[name] = (("punch", "time"),
                           np.array([np.asarray(getattr(p, name), dtype=float)
                                     for p in punches]),
                           {"units": unit, "long_name": f"{long_name}, of each punch",
                            "symbol": symbol})
    info = result.info
    attrs = {"format": SOLUTION_OF_PUNCHES, "version": VERSION,
             "scene_name": result.scene.name, "scene": scene_to_json(result.scene),
             "flags": ",".join(result.flags),
             "error_estimate": float(info.get("error_estimate", float("nan"))),
             "success": int(bool(info.get("success", False))),
             "coating_model": str(info.get("coating_model", ""))}
    return xr.Dataset(variables, coords=coords, attrs=attrs)
