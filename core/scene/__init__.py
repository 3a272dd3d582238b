"""Dimensional scenes: the SI-unit problem a user writes, solved through the dimensionless one.

``solve(scene)`` (``pipeline.py``) checks a scene, converts it, picks the engine and
returns a ``SceneSolution``.

- ``schema.py``: the schema version and migrations, accepted ranges, field validators;
- ``validate.py``: ``scene_from_dict``, a whole scene checked field by field;
- ``model.py``: the validated ``Scene`` and ``Layer`` and what follows from them alone;
- ``dimensionless.py``: ``to_dimensionless``, the scene as the dimensionless problem;
- ``punches.py``: several punches on one foundation (``punches``): ``punches_from_dict``,
  ``PunchesScene``, ``PunchesSolution`` (one ``PunchSolution`` per punch);
- ``results.py``: ``SceneSolution``, the answer in SI units with its flags, JSON and CSV;
- ``contact_zone.py``: ``contact_width``, ``lift_off_length``, ``lifts_off`` of a
  contact set: the one definition every output of the contact width uses;
- ``display.py``: its repr and HTML table, its metadata, ``to_xarray``/``to_dataframe``;
- ``plotting.py``: its HoloViews plot (HoloViews is imported here and by core.report only, on use);
- ``files.py``: ``load_scene``, ``save_scene`` (strict JSON, atomic writes);
- ``records.py``: what every file of an answer records (version, scene, solver settings);
- ``load_limits.py``, ``load_rates.py``: loads no contact can carry, and the steps a
  load history forces, refused before any solve;
- ``design.py``: the design check (``DesignLimits``, ``check_design``): the largest
  pressure, settlement and tilt against the scene's ``limits``;
- ``json_schema.py``: the JSON Schema of scene files, made from the tables of
  ``schema.py`` and shipped in ``schemas/``;
- ``coating_check.py``: a scene's fast answer against the finite-element check;
- ``evidence.py``: ``model_error_evidence``, the coating model's error every output shows
  (the FE check's measurement once run on the scene, else the estimate);
- ``golden_section.py``: the least gap between punch and coating;
- ``output_times.py``: ``at_output_times``, the scene at other output times with its
  loads the same functions of time (a ``linear`` history pinned to its own end);
- ``at_loading.py``: ``elastic_at_loading``, the scene whose base answers as at the instant
  of loading (elastic at its modulus then, ``modulus_at_loading``), and ``creeps``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from core.optional import lazy_exports
from core.scene.at_loading import creeps, elastic_at_loading, modulus_at_loading
from core.scene.contact_zone import (
    LIFT_OFF_SHARE,
    contact_width,
    lift_off_length,
    lifts_off,
    narrowest_zone,
)
from core.scene.design import (
    THIN_EDGE_NOTE,
    THIN_EDGE_SHORT,
    THIN_STEP_NOTE,
    THIN_STEP_SHORT,
    DesignCheck,
    DesignLimits,
    LimitCheck,
    answer_accuracy,
    check_design,
    design_check,
    flagged_caution,
    largest_pressure,
    thin_edge_note,
    time_of_largest,
    verdict_words,
    without_round_off,
)
from core.scene.display import (
    corner_note,
    days_text,
    engine_text,
    known_contact_width,
    lifts_off_at,
    number_text,
)
from core.scene.evidence import (
    check_settled,
    checked_key,
    flags_with_evidence,
    model_error_evidence,
)
from core.scene.files import load_scene, read_scene_json, save_scene, scene_to_json
from core.scene.json_schema import DIALECT as JSON_SCHEMA_DIALECT
from core.scene.json_schema import (
    SCHEMA_FILES,
    SCHEMA_IDS,
    load_json_schema,
    scene_definitions,
    scene_json_schema,
    scene_root,
    schema_errors,
    schema_text,
)
from core.scene.load_limits import check_loads_touch
from core.scene.model import Scene
from core.scene.output_times import at_output_times
from core.scene.pipeline import solve
from core.scene.plotting import (
    LIFT_OFF_COLOUR,
    PRESSURE_WIDTH,
    PUNCH_COLOURS,
    holoviews_for_bokeh,
    pressure_unit,
    shown_times,
    time_colours,
)
from core.scene.punches import (
    PunchesScene,
    PunchesSolution,
    PunchSolution,
    has_punches,
    punches_from_dict,
)
from core.scene.records import (
    csv_header,
    model_error_line,
    percent_text,
    provenance,
    provenance_lines,
    solver_settings,
)
from core.scene.results import (
    FLAG_MESSAGES,
    LARGE_COATING_STRAIN,
    LARGE_SETTLEMENT,
    LARGE_TILT,
    SceneSolution,
    coating_strain_per_pressure,
    plotting_grid,
    scene_model_error,
    strain_share,
    thick_coating,
)
from core.scene.schema import (
    MAX_SCENE_BYTES,
    SCHEMA_KEY,
    check_fields,
    integer_in_range,
    migrate,
)
from core.scene.validate import default_tol, replace_loads, scene_from_dict

if TYPE_CHECKING:
    from core.scene.coating_check import check_scene, pressure_caution

# The finite-element check (and its FE modules), loaded on first use: a solve never
# needs it, and the command line starts faster without it.
_LAZY: dict[str, str] = {"check_scene": "core.scene.coating_check",
                         "pressure_caution": "core.scene.coating_check"}

__all__ = [
    "at_output_times",
    "default_tol",
    "LIFT_OFF_COLOUR",
    "PRESSURE_WIDTH",
    "LIFT_OFF_SHARE",
    "engine_text",
    "holoviews_for_bokeh",
    "PUNCH_COLOURS",
    "known_contact_width",
    "days_text",
    "number_text",
    "percent_text",
    "model_error_line",
    "largest_pressure",
    "thin_edge_note",
    "THIN_EDGE_NOTE",
    "THIN_EDGE_SHORT",
    "THIN_STEP_NOTE",
    "THIN_STEP_SHORT",
    "lifts_off_at",
    "answer_accuracy",
    "check_design",
    "flagged_caution",
    "time_of_largest",
    "without_round_off",
    "verdict_words",
    "check_fields",
    "check_loads_touch",
    "check_scene",
    "pressure_caution",
    "checked_key",
    "flags_with_evidence",
    "model_error_evidence",
    "check_settled",
    "contact_width",
    "corner_note",
    "csv_header",
    "creeps",
    "design_check",
    "elastic_at_loading",
    "DesignCheck",
    "DesignLimits",
    "FLAG_MESSAGES",
    "integer_in_range",
    "JSON_SCHEMA_DIALECT",
    "load_json_schema",
    "LARGE_SETTLEMENT",
    "LARGE_COATING_STRAIN",
    "LARGE_TILT",
    "LimitCheck",
    "lift_off_length",
    "lifts_off",
    "narrowest_zone",
    "load_scene",
    "MAX_SCENE_BYTES",
    "migrate",
    "modulus_at_loading",
    "plotting_grid",
    "pressure_unit",
    "provenance",
    "provenance_lines",
    "has_punches",
    "PunchesScene",
    "PunchesSolution",
    "punches_from_dict",
    "PunchSolution",
    "read_scene_json",
    "replace_loads",
    "save_scene",
    "scene_to_json",
    "Scene",
    "scene_definitions",
    "scene_from_dict",
    "scene_json_schema",
    "scene_root",
    "SCHEMA_FILES",
    "SCHEMA_IDS",
    "SCHEMA_KEY",
    "time_colours",
    "schema_errors",
    "schema_text",
    "scene_model_error",
    "strain_share",
    "coating_strain_per_pressure",
    "thick_coating",
    "SceneSolution",
    "shown_times",
    "solve",
    "solver_settings",
]


__getattr__, __dir__ = lazy_exports(__name__, _LAZY, globals())
