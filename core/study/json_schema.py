"""The JSON Schema (draft 2020-12) of study files, made from the tables the validator reads.

:func:`study_json_schema` builds it from :mod:`core.study.definition` (kinds of grids and
distributions, outputs, limits of a study) and embeds the scene schema
(:func:`core.scene.json_schema.scene_json_schema`) for an inline base scene. The shipped
file is ``core/scene/schemas/study.schema.json`` (beside the scene's, read with
:func:`core.scene.json_schema.load_json_schema`). Rules the schema cannot express (a
varied field must exist in the base scene and hold a number, the scenes at the ends of
every grid must be valid, the number of points, ``high > low``) are
:func:`core.study.study_from_dict`'s alone (core/SCENES.md, "JSON Schema").
"""

from __future__ import annotations

from typing import Any

from core.scene import (
    JSON_SCHEMA_DIALECT,
    SCHEMA_IDS,
    SCHEMA_KEY,
    scene_definitions,
    scene_root,
)
from core.study.definition import (
    DISTRIBUTIONS,
    FIXED_ROOTS,
    GRID_KINDS,
    MAX_PARAMETERS,
    MAX_STUDY_POINTS,
    OUTPUT_UNITS,
    PATH_PART,
    PUNCH_OUTPUT,
    STUDY_VERSION,
)

_NUMBER = {"type": "number"}
_POSITIVE = {"type": "number", "exclusiveMinimum": 0}


def _spec(description: str, **fields: dict[str, Any]) -> dict[str, Any]:
    return {"type": "object", "description": description, "required": list(fields),
            "properties": fields, "additionalProperties": False}


def _kinds() -> dict[str, dict[str, Any]]:
    """The schema of each grid kind and distribution of a varied field."""
    count = {"type": "integer", "minimum": 1, "maximum": MAX_STUDY_POINTS}
    kinds = {
        "values": {"type": "array", "items": _NUMBER, "minItems": 1,
                   "maxItems": MAX_STUDY_POINTS, "description": "The values, in order."},
        "linspace": _spec("count values evenly spaced from start to stop.", start=_NUMBER,
                          stop=_NUMBER, count=count),
        "logspace": _spec("count values geometrically spaced from start to stop (values, "
                          "not exponents).", start=_POSITIVE, stop=_POSITIVE, count=count),
        "normal": _spec("A normal distribution.", mean=_NUMBER, std=_POSITIVE),
        "lognormal": _spec("A lognormal distribution: the median and the spread sigma of "
                           "the log.", median=_POSITIVE,
                           sigma={"type": "number", "exclusiveMinimum": 0, "maximum": 5}),
        "uniform": _spec("A uniform distribution on [low, high].", low=_NUMBER,
                         high=_NUMBER),
    }
    assert tuple(kinds) == GRID_KINDS + DISTRIBUTIONS  # one entry per kind of the validator
    return kinds


def _field_path() -> dict[str, Any]:
    part = PATH_PART.pattern
    fixed = "|".join(FIXED_ROOTS)
    return {"type": "string", "maxLength": 200,
            "description": "Path of a number in the base scene's canonical form, e.g. "
                           "coating[0].modulus, loading.moment, base.age_at_loading; not "
                           f"under {', '.join(FIXED_ROOTS)}.",
            "allOf": [{"pattern": f"^{part}(\\.{part})*$",
                       "description": "is not a field path (names joined by '.', list "
                                      "items as [k], e.g. 'coating[0].modulus')"},
                      {"not": {"pattern": f"^({fixed})([.\\[]|$)"},
                       "description": "cannot be varied (the output times are the study's "
                                      "'times'; names and versions are not numbers; limits "
                                      "do not change an answer)"}]}


def study_json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of study files, with the scene schema embedded."""
    kinds = _kinds()
    parameter = {
        "type": "object", "description": "One varied field: its path and one kind of grid "
                                         "or distribution.",
        "required": ["field"],
        "properties": {"field": _field_path(), **kinds},
        "additionalProperties": False,
        "oneOf": [{"required": [k]} for k in kinds],
    }
    defs = {
        "scene": scene_root(),
        **scene_definitions(),
        "parameter": parameter,
    }
    random = {"anyOf": [{"required": [k]} for k in DISTRIBUTIONS]}
    return {
        "$schema": JSON_SCHEMA_DIALECT, "$id": SCHEMA_IDS["study"],
        "title": f"coated-punch study file, version {STUDY_VERSION}",
        "type": "object",
        "description": "A design study: one base scene run many times with some of its "
                       "numbers varied over grids or drawn from distributions "
                       "(core/SCENES.md, 'Study files').",
        "required": ["study_version", "name", "scene", "vary"],
        "properties": {
            "study_version": {"type": "integer", "const": STUDY_VERSION,
                              "description": f"Version of the study format: {STUDY_VERSION}."},
            "name": {"type": "string", "pattern": r"\S", "description": "Name of the study."},
            "description": {"type": "string", "description": "What the study is for."},
            "scene": {"anyOf": [{"type": "string", "minLength": 1},
                                {"$ref": "#/$defs/scene"}],
                      "description": "The base scene, inline or the path of a scene file "
                                     "relative to the study file."},
            "vary": {"type": "array", "items": {"$ref": "#/$defs/parameter"},
                     "minItems": 1, "maxItems": MAX_PARAMETERS,
                     "description": f"The varied fields, 1 to {MAX_PARAMETERS}; grids "
                                    "combine as a Cartesian product."},
            "samples": {"type": "integer", "minimum": 1, "maximum": MAX_STUDY_POINTS,
                        "description": "Draws per grid point; only (and then required) "
                                       "with a distribution."},
            "seed": {"type": "integer", "minimum": 0, "maximum": 2**63 - 1, "default": 0,
                     "description": "Seed of the draws."},
            "outputs": {"type": "array", "minItems": 1,
                        "items": {"anyOf": [
                            {"enum": list(OUTPUT_UNITS)},
                            {"type": "string", "pattern": "^" + PUNCH_OUTPUT.pattern.replace(
                                "[a-z_]+", "|".join(OUTPUT_UNITS)) + "$"}]},
                        "description": "Outputs to record (default all): "
                                       + ", ".join(f"{k} [{u}]"
                                                   for k, u in OUTPUT_UNITS.items())
                                       + "; of a scene of several punches, each under "
                                         "every punch, or one punch's as "
                                         "punches[k].<output>."},
            "times": {"$ref": "#/$defs/times",
                      "description": "Output times replacing the base scene's [day after "
                                     "loading]."},
            SCHEMA_KEY: {"type": "string", "description": "The JSON Schema of the file "
                                                          "(ignored by the program)."},
        },
        "additionalProperties": False,
        "if": {"required": ["vary"],
               "properties": {"vary": {"type": "array", "contains": random}}},
        "then": {"required": ["samples"]},
        "else": {"properties": {"samples": {
            "not": {}, "description": "only for distributions (every field here is a grid)"}}},
        "$defs": defs,
    }
