"""What every file of an answer records besides the numbers: the program's version, the
scene solved and the solver settings, so that a file can be traced and solved again.

The command line (:mod:`core.cli`) and the explorer's downloads write these: JSON files
carry :func:`provenance` at the top level (:meth:`SceneSolution.to_dict`), CSV files start with
the ``#`` lines of :func:`provenance_lines` (``pandas.read_csv(path, comment="#")`` reads
the table; each line is ``# key: value``).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from core.coating import model_error_quantity
from core.scene.validate import scene_from_dict
from core.version import VERSION

if TYPE_CHECKING:
    from core.scene.model import Scene
    from core.scene.punches import PunchesScene

#: The program's name in the files it writes.
PROGRAM = "coated-punch"


def _validated(scene: Scene | PunchesScene | Mapping[str, Any]) -> Scene | PunchesScene:
    """``scene`` validated, of either form (one punch, or ``punches``)."""
    # here, not at the top: core.scene.punches builds on the results, which import this
    from core.scene.punches import has_punches, punches_from_dict

    return punches_from_dict(scene) if has_punches(scene) else scene_from_dict(scene)


def solver_settings(scene: Scene | PunchesScene | Mapping[str, Any]) -> dict[str, Any]:
    """The solver settings of a scene, defaults filled in: ``tol`` and ``model_tol`` [-],
    ``contact`` (``"auto"``, ``"full"`` or ``"unilateral"``); of several punches, the
    settings they share."""
    scene = _validated(scene)
    # the punches of one scene share its solver section
    first = scene.scenes[0] if hasattr(scene, "scenes") else scene
    return {"tol": first.tol, "model_tol": first.model_tol, "contact": first.contact}


def provenance(scene: Scene | PunchesScene | Mapping[str, Any]) -> dict[str, Any]:
    """``program``, ``version`` (``core.__version__``) and ``solver`` (the settings) of a
    file written for ``scene``."""
    return {"program": PROGRAM, "version": VERSION, "solver": solver_settings(scene)}


def provenance_lines(scene: Scene | PunchesScene | Mapping[str, Any]) -> list[str]:
    """The ``#`` lines of a CSV file written for ``scene``: ``version``, ``scene_json``
    (the canonical scene, one line of JSON) and ``solver`` (the settings, JSON)."""
    scene = _validated(scene)
    compact = {"separators": (",", ":"), "allow_nan": False}
    return [f"# version: {VERSION}",
            f"# scene_json: {json.dumps(scene.to_dict(), **compact)}",
            f"# solver: {json.dumps(solver_settings(scene), **compact)}"]


#: Shares below this many percent are written as "< 0.001 %" (a numerical estimate of
#: 5e-10 read "5e-08 %").
PERCENT_FLOOR = 1e-3
#: Shares above this many percent are written as "> 10000 %": an estimated coating-model
#: error of a 1000 km coating read "16556648 %", digits that mean nothing but "no model".
PERCENT_CEILING = 1e4


def percent_text(share: float, digits: int = 3) -> str:
    """A relative error or share [-] in percent for people: ``digits`` significant
    figures, "< 0.001 %" below :data:`PERCENT_FLOOR`, "> 10000 %" above
    :data:`PERCENT_CEILING`, never in exponent notation."""
    value = 100.0 * float(share)
    if not math.isfinite(value):
        return f"{value} %"
    if value == 0:
        return "0 %"
    if abs(value) < PERCENT_FLOOR:
        return f"> -{PERCENT_FLOOR:g} %" if value < 0 else f"< {PERCENT_FLOOR:g} %"
    if abs(value) > PERCENT_CEILING:
        return f"< -{PERCENT_CEILING:g} %" if value < 0 else f"> {PERCENT_CEILING:g} %"
    if abs(float(f"{value:.{digits}g}")) >= 10.0 ** digits:  # "g" would write an exponent
        return f"{value:.0f} %"
    return f"{value:.{digits}g} %"


def model_error_line(solution: Any, symbols: bool = False) -> str:
    """The coating model's estimated error of one punch's answer in words, with whose it
    is and the tolerance: "0.92 % of the tilt (solver.model_tol 2 %)", or that it is
    extrapolated (flag ``beyond_model_map``), which bounds nothing. ``symbols``: the
    paper's symbols beside the names (not on a console, whose character set may not hold
    them)."""
    error = solution.model_error
    quantity = model_error_quantity(solution.scene.given, error.get("part"), symbols=symbols)
    text = f"{percent_text(error['estimate'], 2)}{' of ' + quantity if quantity else ''}"
    if "beyond_model_map" in getattr(solution, "flags", ()):
        # read off the map beyond what was measured: no ground for "within model_tol"
        # (a coating of 1e-3 Pa read "0.98 % of the tilt (solver.model_tol 2 %)")
        return (f"{text}, extrapolated beyond the measured map: no bound (measure it with "
                "coated-punch check)")
    return f"{text} (solver.model_tol {100 * solution.scene.model_tol:g} %)"


def csv_header(result: Any, what: str) -> str:
    """The ``#`` lines before a CSV table of ``result`` (a ``SceneSolution`` or a
    ``PunchesSolution``): what it is (``what``), the version, the scene, the solver
    settings, the answer's contact and coating models, its estimated error, its flags and,
    with limits, its design check (one per punch of several)."""
    info = result.info
    estimate = info.get("error_estimate")
    several = hasattr(result, "punches")
    contact = ", ".join(sorted({str(p.info.get("contact", "full")) for p in result.punches})) \
        if several else info.get("contact", "full")
    name = " ".join(str(result.scene.name).split())
    lines = [f"# {PROGRAM} {VERSION}: {what}",
             f"# scene: {name}",
             *provenance_lines(result.scene),
             f"# answered: contact {contact}, coating model "
             f"{info.get('coating_model', '')}, estimated relative error "
             + (f"{float(estimate):.1e}" if isinstance(estimate, (int, float)) else "n/a")]
    # the coating model's error too: a table's reader saw "estimated relative error
    # 4.3e-07" beside a bare "model_error" flag, where the answer erred by 2.5 %
    for who, one in ([(f"punches[{k}] ", p) for k, p in enumerate(result.punches)]
                     if several else [("", result)]):
        if one.scene.coating:
            lines.append(f"# {who}coating model error (estimate): {model_error_line(one)}")
    lines.append("# flags: " + (", ".join(result.flags) or "none"))
    checks = [(f"punches[{k}] ", c, p.flags) for k, (c, p) in
              enumerate(zip(result.design_checks(), result.punches, strict=True))] \
        if several else [("", result.design_check(), result.flags)]
    for who, check, flags in checks:
        if check is not None:
            lines.append(f"# {who}design_check: {check.summary(flags)}")
    return "\n".join(lines) + "\n"
