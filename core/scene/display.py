"""A :class:`~core.scene.SceneSolution` for people and for data tools: its key figures as
text (``repr``) and as an HTML table (notebooks), its metadata (the package version, the
scene, the solver settings, flags and error estimates) and its arrays as an
``xarray.Dataset`` or a ``pandas.DataFrame``.

xarray and pandas are imported only by :func:`to_xarray` and :func:`to_dataframe`: a
missing one raises ``ImportError`` naming the extra to install.
"""

from __future__ import annotations

import html
import json
import math
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from core.coating import THIN_LAYER
from core.engines.layered import NO_COATING
from core.limits import DAYS_PER_YEAR
from core.optional import import_optional
from core.scene.contact_zone import LIFT_OFF_SHARE
from core.scene.files import scene_to_json
from core.scene.records import percent_text, solver_settings
from core.scene.schema import SCHEMA_VERSION, _jsonable

# the package root only, for its version: its imports of the upper layers are for type
# checkers (the layers contract ignores this import)
from core.version import VERSION

if TYPE_CHECKING:
    import pandas
    import xarray

    from core.scene.results import SceneSolution

#: The histories over time: (unit, long name, the paper's symbol).
HISTORIES: dict[str, tuple[str, str, str]] = {
    "settlement": ("m", "settlement of the punch centre", "delta"),
    "tilt": ("rad", "tilt of the punch", "alpha"),
    "force": ("N/m", "force per unit length", "P"),
    "moment": ("N", "moment per unit length (N m/m)", "M"),
}
#: The figures of the summary: (attribute, factor from SI, unit shown).
SHOWN: tuple[tuple[str, float, str], ...] = (
    ("settlement", 1e3, "mm"),
    ("tilt", 1e3, "mrad"),
    ("force", 1e-3, "kN/m"),
    ("moment", 1e-3, "kN m/m"),
)


def number_text(value: float, digits: int = 4) -> str:
    """``value`` with ``digits`` significant digits ("not finite" for NaN and infinity),
    without an exponent from 0.001 to a million (50 years read "18260 d" at 4 digits, not
    "1.826e+04 d")."""
    if not np.isfinite(value):
        return "not finite"
    if value == 0 or 1e-3 <= abs(value) < 1e6:
        return np.format_float_positional(float(value), precision=digits, unique=False,
                                          fractional=False, trim="-")
    return f"{value:.{digits}g}"


#: From this time on [day] the years are written beside the days: below two years the
#: days are the natural reading (28 days, 365 days), beyond it the years.
YEARS_FROM_DAYS = 2 * DAYS_PER_YEAR


def days_text(t: float, digits: int = 4, years: bool = True) -> str:
    """A time ``t`` [day] after loading in words: "28 days", "1 day", "18262.5 days (50.0
    years)" (:func:`number_text`'s digits, never fewer than the whole days and one
    decimal: never "1.826e+04 d", which an engineer has to decode, nor "18260 days" for
    the 18262.5 a time span box reads); ``years``: the years beside long times."""
    if math.isfinite(t) and abs(t) >= 1.0:
        digits = max(digits, int(math.log10(abs(t))) + 2)
    shown = number_text(t, digits)
    text = f"{shown} {'day' if shown == '1' else 'days'}"
    if years and math.isfinite(t) and abs(t) >= YEARS_FROM_DAYS:
        text += f" ({t / DAYS_PER_YEAR:.1f} years)"
    return text


def known_contact_width(result: SceneSolution) -> np.ndarray | None:
    """:attr:`SceneSolution.contact_width` [m] at every output time (None if the answer
    has no contact set)."""
    if len(result.contact_set) != len(result.times):
        return None
    return result.contact_width


def lifts_off_at(result: SceneSolution, k: int = -1) -> bool:
    """Whether the contact set at ``times[k]`` is narrower than the punch base
    (:func:`core.scene.contact_zone.lifts_off`)."""
    if len(result.contact_set) != len(result.times):
        return False
    # the result's own length lifted off: a punch of several measures its zones from its
    # own centre, not from x = 0
    return bool(result.lift_off_length[k] > LIFT_OFF_SHARE * 2.0 * result.scene.half_width)


def zones_text(result: SceneSolution, k: int = -1) -> str:
    """The contact zones at ``times[k]`` as ``[lo, hi]`` in metres."""
    return ", ".join(f"[{number_text(lo)}, {number_text(hi)}]" for lo, hi in result.contact_set[k])


def engine_text(result: SceneSolution) -> str:
    """The engine, the contact model and the coating model that answered."""
    info = result.info
    contact = str(info.get("contact", "full"))
    parts = ([f"{info['method']} engine", f"{contact} contact"] if "method" in info
             else [f"{contact} contact solver"])
    model = str(info.get("coating_model", THIN_LAYER))
    parts.append("no coating" if model == NO_COATING else f"{model} coating model")
    if info.get("fallback"):
        parts.append(f"fallback: {info['fallback']}")
    return ", ".join(parts)


def error_text(result: SceneSolution) -> str:
    """The numerical and the coating-model error estimates with their tolerances."""
    numerical = float(result.info.get("error_estimate", math.nan))
    if result.info.get("coating_model") == NO_COATING:
        return (f"{numerical:.2g} numerical (tol {result.scene.tol:.2g}), 0 coating model "
                "(no coating)")
    return (f"{numerical:.2g} numerical (tol {result.scene.tol:.2g}), "
            f"{result.model_error['estimate']:.2g} coating model "
            f"(model_tol {result.scene.model_tol:.2g})")


def headline(result: SceneSolution) -> str:
    """The scene's name, its statement and its output times."""
    scene, times = result.scene, result.times
    given = ", ".join(sorted(scene.given))
    span = (f"{number_text(times[0])} to {days_text(times[-1])}" if len(times) > 1
            else days_text(times[0]))
    return (f"'{scene.name}': statement {scene.statement} ({given} given), {len(times)} "
            f"output time{'s' * (len(times) != 1)}, {span} after loading")


def key_figures(result: SceneSolution) -> list[tuple[str, str]]:
    """The figures at the last output time as ``(name, value with unit)``."""
    rows = [(name, f"{number_text(float(getattr(result, name)[-1]) * factor)} {unit}")
            for name, factor, unit in SHOWN]
    q_max = float(np.max(result.pressure_on_grid[:, -1]))
    rows.append(("max pressure", f"{number_text(q_max * 1e-6)} MPa"))
    if lifts_off_at(result):
        width = float(result.contact_width[-1])
        rows.append(("contact width", f"{number_text(width)} m of 2a = "
                     f"{number_text(2 * result.scene.half_width)} m (lift-off; contact on "
                     f"{zones_text(result)} m)"))
    return rows


def text_summary(result: SceneSolution) -> str:
    """The readable ``repr``: a few lines of key figures, errors, flags and engine."""
    figures = key_figures(result)
    at_last = ", ".join(f"{name} {value}" for name, value in figures
                        if name != "contact width")
    lines = [f"SceneSolution {headline(result)}",
             f"  at t = {days_text(result.times[-1])}: {at_last}"]
    lines += [f"  {name} {value}" for name, value in figures if name == "contact width"]
    lines.append(f"  estimated error: {error_text(result)}")
    lines.append("  flags: " + (", ".join(result.flags) or "none"))
    lines.append(f"  engine: {engine_text(result)}")
    return "\n".join(lines)


#: The colour of a flag in the HTML summary.
FLAG_COLOUR = "#c00000"


def html_summary(result: SceneSolution) -> str:
    """The key figures, errors, flags (in red, with their messages) and engine as an HTML
    table; every text from the scene or the solver is escaped."""
    e = html.escape

    def row(name: str, value_html: str) -> str:
        return (f'<tr><th style="text-align:left">{e(name)}</th>'
                f'<td style="text-align:left">{value_html}</td></tr>')

    rows = [f'<tr><th colspan="2" style="text-align:left">at t = '
            f"{e(days_text(result.times[-1]))} after loading</th></tr>"]
    rows += [row(name, e(value)) for name, value in key_figures(result)]
    rows.append(row("estimated error", e(error_text(result))))
    if result.flags:
        flags = "<br>".join(
            f'<span style="color:{FLAG_COLOUR}"><b>{e(name)}</b>: '
            f"{e(result.flag_messages.get(name, ''))}</span>" for name in result.flags)
    else:
        flags = "none"
    rows.append(row("flags", flags))
    rows.append(row("engine", e(engine_text(result))))
    return ('<div class="coated-punch-solution"><table>'
            f'<caption style="text-align:left"><b>SceneSolution</b> {e(headline(result))}'
            "</caption>" + "".join(rows) + "</table></div>")


# ------------------------------------------------------------------------------ metadata


def answered_settings(result: SceneSolution) -> dict[str, Any]:
    """The scene's ``solver`` settings (defaults filled in) and what the solver chose: the
    engine (``method``), the contact model that answered (``contact_model``: the
    setting ``contact`` may be ``"auto"``), the coating model, its discretization."""
    settings: dict[str, Any] = solver_settings(result.scene)
    info = result.info
    chosen = {"method": "method", "contact": "contact_model", "coating_model": "coating_model",
              "basis": "basis", "n_modes": "n_modes", "n_nodes": "n_nodes",
              "n_panels": "n_panels", "n_steps": "n_steps", "fallback": "fallback"}
    for name, key in chosen.items():
        if name in info:
            settings[key] = info[name]
    return _jsonable(settings)


def metadata(result: SceneSolution) -> dict[str, Any]:
    """What a file of ``result`` records besides its arrays: the package version, the scene
    (canonical JSON, as scene files hold it), the solver settings (JSON), the flags and the
    error estimates. Every value is a string or a number (netCDF attributes)."""
    info = result.info
    return {
        "format": "coated-punch solution",
        "version": VERSION,
        "schema_version": SCHEMA_VERSION,
        "scene_name": result.scene.name,
        "scene_key": result.scene.key,
        "scene": scene_to_json(result.scene),
        "solver_settings": json.dumps(answered_settings(result), sort_keys=True),
        "statement": int(result.scene.statement),
        "given": ",".join(sorted(result.scene.given)),
        "flags": ",".join(result.flags),
        "flag_messages": json.dumps(result.flag_messages),
        "error_estimate": float(info.get("error_estimate", math.nan)),
        "model_error_estimate": float(result.model_error["estimate"]),
        "model_error": json.dumps(_jsonable(result.model_error), sort_keys=True),
        "success": int(bool(info.get("success", False))),
        "message": str(info.get("message", "")),
    }


def to_xarray(result: SceneSolution) -> xarray.Dataset:
    """``result`` as an ``xarray.Dataset`` over ``time`` [day] and ``x`` [m]: the pressure
    q(x, t) [Pa], the histories, the contact width [m] when the answer has contact sets;
    units and long names in each variable's attributes, :func:`metadata` in the dataset's."""
    xr = import_optional("xarray", "SceneSolution.to_xarray")
    coords = {"time": ("time", result.times.copy(),
                       {"units": "day", "long_name": "time after loading"}),
              "x": ("x", result.x.copy(),
                    {"units": "m", "long_name": "distance from the punch centre"})}
    variables: dict[str, Any] = {
        "pressure": (("x", "time"), result.pressure_on_grid.copy(),
                     {"units": "Pa", "long_name": "contact pressure", "symbol": "q"})}
    for name, (unit, long_name, symbol) in HISTORIES.items():
        variables[name] = ("time", np.array(getattr(result, name)),
                           {"units": unit, "long_name": long_name, "symbol": symbol})
    widths = known_contact_width(result)
    if widths is not None:
        variables["contact_width"] = ("time", widths,
                                      {"units": "m", "long_name": "length of the contact set"})
    return xr.Dataset(variables, coords=coords, attrs=metadata(result))


def to_dataframe(result: SceneSolution) -> pandas.DataFrame:
    """The histories as a ``pandas.DataFrame`` indexed by ``time`` [day]: settlement [m],
    tilt [rad], force [N/m], moment [N] (and contact_width [m]); ``attrs`` hold
    :func:`metadata` and ``units`` (column to unit)."""
    pd = import_optional("pandas", "SceneSolution.to_dataframe")
    columns = {name: np.array(getattr(result, name)) for name in HISTORIES}
    units = {name: unit for name, (unit, _, _) in HISTORIES.items()}
    widths = known_contact_width(result)
    if widths is not None:
        columns["contact_width"] = widths
        units["contact_width"] = "m"
    frame = pd.DataFrame(columns, index=pd.Index(result.times.copy(), name="time"))
    frame.attrs.update(metadata(result))
    frame.attrs["units"] = {"time": "day", **units}
    return frame


def corner_note(corners: Mapping[str, Any] | None,
                number: Callable[[float], str] = number_text) -> str | None:
    """The ``#`` line of a pressure table whose answer has rigid corners in contact
    (``info["corner_pressure"]``: ``corners_m`` [m], ``held_within_m`` [m]): the rows
    there hold q's value at that distance, where q grows without bound, and leave out
    the share of the force and moment it carries there (``held_force_share``,
    ``held_moment_share``: a table integrated fell short of P by 2-9 % under thick
    coatings, unsaid); None without."""
    if not corners:
        return None
    where = " and ".join(f"x = {number(float(c))} m" for c in corners["corners_m"])
    note = (f"# corner: q grows without bound toward the rigid corner at {where}; within "
            f"{number(float(corners['held_within_m']))} m of it the rows hold its value at "
            "that distance")
    force, moment = corners.get("held_force_share"), corners.get("held_moment_share")
    if force is None:
        return note
    left = f"{percent_text(force, 2)} of the force P" + (
        "" if moment is None else f" and {percent_text(moment, 2)} of the moment M")
    return (f"{note}, and so leave out up to {left} (integrated, the rows fall short; the "
            "histories' force and moment are the answer's)")

