"""The JSON Schema (draft 2020-12) of scene files, made from the tables the validator reads.

:func:`scene_json_schema` builds it from :data:`core.scene.schema.FIELDS` (objects,
fields, units, ranges, defaults), the profile families (:data:`core.profiles.FAMILIES`)
and the creep models (:data:`core.creep.SPEC_FIELDS`, :data:`core.creep.RANGES`); the
study files' schema (:mod:`core.study.json_schema`) embeds it. The generated files are
shipped in ``core/scene/schemas/`` (:func:`load_json_schema`), so editors and other
programs can check a file without this package; a test keeps them equal to the tables.

The schema expresses the rules of single fields (types, ranges, choices, required and
unknown fields, list sizes, the four statements); the rules that join fields or need a
computation (a profile's values over its whole domain, ``a / H``, increasing times, the
solver's limits; core/SCENES.md, "JSON Schema") are :func:`core.scene.scene_from_dict`'s
alone. :func:`schema_errors` checks a value against a schema and words each violation
as the validator would: ``coating[0].modulus: must be > 0, got -1``.
"""

from __future__ import annotations

import difflib
import itertools
import json
import re
from collections.abc import Iterator, Mapping
from functools import cache
from importlib import resources
from typing import Any

from core import limits
from core.creep import (
    CEMENT_CLASSES,
    CODE_SPEC_FIELDS,
    KNOWN_MODELS,
    MAX_RATE,
    MAX_TERMS,
    RANGES,
    SPEC_FIELDS,
    STRENGTH_CLASS,
    TERM_FIELDS,
)
from core.problem import QUANTITIES, STATEMENTS
from core.profiles import (
    FAMILIES,
    INTERPOLATIONS,
    KINDS,
    MAX_POLYNOMIAL_COEFFICIENTS,
    MAX_TABLE_ROWS,
)
from core.scene.schema import FIELDS, MAX_DAYS, SCHEMA_KEY, SCHEMA_VERSION, FieldRule
from core.validation import show_value

#: The JSON Schema dialect of the shipped schemas.
DIALECT = "https://json-schema.org/draft/2020-12/schema"
#: The ``$id`` of each shipped schema (a URN: no web address is implied).
SCHEMA_IDS: Mapping[str, str] = {"scene": f"urn:coated-punch:schema:scene:{SCHEMA_VERSION}",
                                 "study": "urn:coated-punch:schema:study:1"}
#: The file of each schema in ``core/scene/schemas/``.
SCHEMA_FILES: Mapping[str, str] = {"scene": "scene.schema.json",
                                   "study": "study.schema.json"}

_NUMBER: dict[str, Any] = {"type": "number"}
_POSITIVE: dict[str, Any] = {"type": "number", "exclusiveMinimum": 0}
_NONNEGATIVE: dict[str, Any] = {"type": "number", "minimum": 0}
_NOT_BLANK = r"\S"


def _numbers(least: int, most: int) -> dict[str, Any]:
    return {"type": "array", "items": _NUMBER, "minItems": least, "maxItems": most}


def _formula(variables: str) -> dict[str, Any]:
    return {"type": "string", "pattern": _NOT_BLANK, "maxLength": limits.MAX_FORMULA_CHARS,
            "description": f"A formula in {variables} (core/profiles/expressions.py)."}


#: The value of each field of the profile families (the fields: :data:`FAMILIES`).
_PROFILE_FIELDS: dict[str, dict[str, Any]] = {
    "value": _NUMBER, "start": _NUMBER, "end": _NUMBER, "mean": _NUMBER,
    "amplitude": _NUMBER, "center": _NUMBER,
    "phase": {"type": "number", "default": 0.0, "description": "Phase [rad]."},
    "wavelength": _POSITIVE, "width": _POSITIVE, "duration": _POSITIVE,
    "values": _numbers(1, MAX_TABLE_ROWS + 1),
    "breaks": _numbers(0, MAX_TABLE_ROWS),
    "coefficients": _numbers(1, MAX_POLYNOMIAL_COEFFICIENTS),
    "points": {"type": "array", "minItems": 2, "maxItems": MAX_TABLE_ROWS,
               "items": {"type": "array", "prefixItems": [_NUMBER, _NUMBER],
                         "minItems": 2, "maxItems": 2,
                         "description": "A row [position, value]."}},
    "interpolation": {"enum": list(INTERPOLATIONS), "default": "linear"},
    "expr": _formula("the variable (x [m] or t [day after loading])"),
}


def _creep_fields(model: str) -> dict[str, dict[str, Any]]:
    """The value of each field of a creep model (the fields: :data:`SPEC_FIELDS`)."""
    if model in CODE_SPEC_FIELDS:
        ranges = RANGES[model]

        def within(name: str, unit: str, what: str) -> dict[str, Any]:
            low, high, source = ranges[name]
            return {"type": "number", "minimum": low, "maximum": high,
                    "description": f"{what} [{unit}], in [{low:g}, {high:g}] ({source})."}

        return {
            "fcm": within("fcm", "MPa", "Mean cylinder strength at 28 days"),
            "strength_class": {"type": "string", "pattern": STRENGTH_CLASS.pattern,
                               "description": "Strength class 'C<fck>/<fck,cube>' [MPa]; "
                                              "fcm = fck + 8 MPa."},
            "cement": {"enum": list(CEMENT_CLASSES), "default": "N",
                       "description": "Cement: S slow, N normal, R rapid hardening."},
            "relative_humidity": within("relative_humidity", "%", "Ambient relative "
                                        "humidity"),
            "notional_size": within("notional_size", "mm", "Notional size h = 2 A_c / u"),
            "temperature": {**within("temperature", "deg C", "Constant temperature"),
                            "default": 20.0},
        }
    rate = {"type": "number", "exclusiveMinimum": 0, "maximum": MAX_RATE,
            "description": f"Creep rate gamma [1/day], in (0, {MAX_RATE:g}]."}
    term_values = {"compliance": {**_NONNEGATIVE, "description": "C_r [1/Pa], >= 0."},
                   "aging": {**_NONNEGATIVE, "default": 0.0,
                             "description": "A_r [day/Pa], >= 0."},
                   "rate": rate}
    required, optional = TERM_FIELDS
    term = {"type": "object", "required": list(required),
            "properties": {name: term_values[name] for name in required + optional},
            "additionalProperties": False}
    return {
        "modulus": {**_POSITIVE, "description": "Instantaneous modulus E [Pa], > 0."},
        "modulus_final": {**_POSITIVE, "description": "Final modulus E_inf [Pa], > 0."},
        "beta": {"type": "number", "minimum": 0, "exclusiveMaximum": 1,
                 "description": "Aging of the modulus beta [-], in [0, 1)."},
        "alpha": {**_NONNEGATIVE, "description": "Rate of aging of the modulus alpha "
                                                 "[1/day], >= 0."},
        "compliance": {**_NONNEGATIVE, "description": "Final creep compliance C_inf "
                                                      "[1/Pa], >= 0."},
        "compliance_final": {**_NONNEGATIVE, "description": "Final creep compliance "
                                                            "C_inf [1/Pa], >= 0."},
        "aging": {**_NONNEGATIVE, "description": "Aging coefficient A [day/Pa], >= 0."},
        "rate": rate,
        "terms": {"type": "array", "items": term, "minItems": 1, "maxItems": MAX_TERMS,
                  "description": f"Prony terms, 1 to {MAX_TERMS}."},
        "expr": _formula("t and tau (ages [day]) giving K(t, tau) [1/day]"),
    }


def _bounds(rule: FieldRule) -> dict[str, Any]:
    out: dict[str, Any] = {}
    if rule.low is not None:
        out["exclusiveMinimum" if rule.low_open else "minimum"] = rule.low
    if rule.high is not None:
        out["exclusiveMaximum" if rule.high_open else "maximum"] = rule.high
    return out


def _describe(rule: FieldRule) -> str:
    return rule.description if rule.unit == "-" else f"{rule.description} [{rule.unit}]"


def _field(rule: FieldRule) -> dict[str, Any]:
    """The schema of one field of :data:`FIELDS`."""
    out: dict[str, Any]
    if rule.kind in ("number", "integer"):
        out = {"type": rule.kind, **_bounds(rule)}
        if rule.low is not None and rule.low == rule.high:
            out = {"type": rule.kind, "const": rule.low}
    elif rule.kind == "text":
        out = {"type": "string"}
        if rule.least:
            out["pattern"] = _NOT_BLANK
        if rule.most is not None:
            out["maxLength"] = rule.most
    elif rule.kind == "choice":
        out = {"enum": list(rule.choices)}
    elif rule.kind in ("x_profile", "t_profile"):
        # the bounds apply to a number, and to the value of a constant profile object;
        # other forms are checked over their domain by the validator alone
        bounds = _bounds(rule)
        out = {"$ref": f"#/$defs/{rule.kind}", **bounds}
        if bounds:
            out["properties"] = {"value": dict(bounds)}
    elif rule.kind == "object":
        out = {"$ref": f"#/$defs/{rule.name}"}
    elif rule.kind == "layers":
        out = {"type": "array", "items": {"$ref": "#/$defs/layer"},
               "minItems": rule.least, "maxItems": rule.most}
    elif rule.kind == "punches":
        out = {"type": "array", "items": {"$ref": "#/$defs/placed_punch"},
               "minItems": rule.least, "maxItems": rule.most}
    elif rule.kind in ("times", "creep"):
        out = {"$ref": f"#/$defs/{rule.kind}"}
    else:  # a kind the table gained without a schema here
        raise ValueError(f"{rule.name}: no JSON Schema for fields of kind {rule.kind!r}")
    out["description"] = _describe(rule)
    if not rule.required and rule.default is not None:
        out["default"] = rule.default
    return out


def _object(name: str, description: str, extra: Mapping[str, Any] | None = None
            ) -> dict[str, Any]:
    """The schema of the object ``name`` of :data:`FIELDS`: no other fields allowed."""
    rules = FIELDS[name]
    properties = {rule.name: _field(rule) for rule in rules}
    properties.update(extra or {})
    out: dict[str, Any] = {"type": "object", "description": description}
    required = [rule.name for rule in rules if rule.required]
    if required:
        out["required"] = required
    out["properties"] = properties
    out["additionalProperties"] = False
    return out


def _profile(variable: str) -> dict[str, Any]:
    """A function of ``variable``: a number, or an object of one of the families."""
    where = ("x [m] from the punch centre on [-a, a]" if variable == "x" else
             "t [day after loading] on [0, last output time]")
    branches = []
    for kind, family in FAMILIES.items():
        fields = family.required + family.optional
        then: dict[str, Any] = {
            "required": (["kind"] if kind != "expr" else []) + list(family.required),
            "properties": {"kind": {"const": kind},
                           **{f: _PROFILE_FIELDS[f] for f in fields}},
            "additionalProperties": False}
        branches.append({"if": {"type": "object", "required": ["kind"],
                                "properties": {"kind": {"const": kind}}},
                         "then": then})
    expr = FAMILIES["expr"]
    # the short form {"expr": "..."} of a formula
    branches.append({"if": {"type": "object", "not": {"required": ["kind"]}},
                     "then": {"required": list(expr.required),
                              "properties": {f: _PROFILE_FIELDS[f] for f in expr.required},
                              "additionalProperties": False}})
    return {"type": ["number", "object"],
            "description": f"A function of {where}: a number (constant) or an object "
                           f"{{\"kind\": one of {', '.join(KINDS)}, ...}} or "
                           "{\"expr\": formula} (core/SCENES.md, 'Profiles').",
            "properties": {"kind": {"enum": list(KINDS)}},
            "allOf": branches}


def _creep() -> dict[str, Any]:
    branches = []
    for model in KNOWN_MODELS:
        required, optional = SPEC_FIELDS[model]
        values = _creep_fields(model)
        then: dict[str, Any] = {
            "required": list(required),
            "properties": {"model": {"const": model},
                           **{f: values[f] for f in required + optional}},
            "additionalProperties": False}
        if model in CODE_SPEC_FIELDS:
            then["oneOf"] = [{"required": ["fcm"]}, {"required": ["strength_class"]}]
        branches.append({"if": {"required": ["model"],
                                "properties": {"model": {"const": model}}},
                         "then": then})
    return {"type": "object", "required": ["model"],
            "description": "Creep model of the base (core/SCENES.md, 'Creep models'); the "
                           "design-code models take the codes' units.",
            "properties": {"model": {"enum": list(KNOWN_MODELS)}},
            "allOf": branches}


def _times() -> dict[str, Any]:
    rules = FIELDS["times"]
    most = next(r.high for r in rules if r.name == "count")
    return {"type": ["object", "array"],
            "description": "Output times after loading [day]: {end, count, spacing, start} or a "
                           "list of increasing days after loading (the first >= 0, the "
                           "last > 0).",
            "required": [r.name for r in rules if r.required],
            "properties": {r.name: _field(r) for r in rules},
            "additionalProperties": False,
            "items": {"type": "number", "minimum": 0, "maximum": MAX_DAYS}, "minItems": 1,
            "maxItems": most}


def _loading() -> dict[str, Any]:
    out = _object("loading", _describe(next(r for r in FIELDS["scene"]
                                             if r.name == "loading")))
    out["minProperties"] = out["maxProperties"] = 2
    statements = ", ".join("+".join(q for q in QUANTITIES if q in given)
                           for given in sorted(STATEMENTS, key=STATEMENTS.get))
    out["allOf"] = [
        {"not": {"required": list(pair)},
         "description": f"{' and '.join(pair)} is not one of the four statements "
                        f"({statements})"}
        for pair in itertools.combinations(QUANTITIES, 2) if frozenset(pair) not in STATEMENTS]
    return out


def _base() -> dict[str, Any]:
    out = _object("base", "The aging viscoelastic base layer.")
    # the design codes bound the age at loading: a rule joining two fields
    out["allOf"] = [
        {"if": {"required": ["creep"], "properties": {"creep": {
            "required": ["model"], "properties": {"model": {"const": model}}}}},
         "then": {"properties": {"age_at_loading": {
             "minimum": RANGES[model]["age_at_loading"][0],
             "maximum": RANGES[model]["age_at_loading"][1],
             "description": f"Age at loading under {model} ({RANGES[model]['age_at_loading'][2]}) "
                            "[day]"}}}}
        for model in CODE_SPEC_FIELDS]
    return out


def scene_definitions() -> dict[str, Any]:
    """The ``$defs`` of the scene schema (the study schema embeds them)."""
    return {
        "punch": _object("punch", "The rigid punch."),
        "placed_punch": _object("punches[k]", "One punch of several, at its centre."),
        "layer": _object("coating[k]", "One coating layer; profiles of x [m] on [-a, a]."),
        "base": _base(),
        "loading": _loading(),
        "solver": _object("solver", "Solver settings."),
        "limits": _object("limits", "Limits of the design check [Pa, m, rad]; a limit "
                                    "left out is not checked."),
        "times": _times(),
        "creep": _creep(),
        "x_profile": _profile("x"),
        "t_profile": _profile("t"),
    }


def scene_root() -> dict[str, Any]:
    """The scene object's own schema (without ``$schema``, ``$id`` and ``$defs``)."""
    root = _object("scene", "A scene: a rigid punch on thin coating layers over an aging "
                            "viscoelastic base, per unit length (core/SCENES.md). SI units "
                            "(m, Pa, N/m, N, rad), times in days.",
                   {SCHEMA_KEY: {"type": "string", "description": "The JSON Schema of the "
                                 "file (ignored by the program)."}})
    # one punch (punch and loading) or several (punches), not both
    root["required"] = [name for name in root["required"] if name not in ("punch", "loading")]
    root["oneOf"] = [{"required": ["punch", "loading"], "not": {"required": ["punches"]}},
                     {"required": ["punches"], "not": {"anyOf": [{"required": ["punch"]},
                                                                  {"required": ["loading"]}]}}]
    return root


def scene_json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of scene files, made from the tables."""
    root = scene_root()
    return {"$schema": DIALECT, "$id": SCHEMA_IDS["scene"],
            "title": f"coated-punch scene file, schema version {SCHEMA_VERSION}",
            **root, "$defs": scene_definitions()}


def schema_text(schema: Mapping[str, Any]) -> str:
    """The text of a schema file: JSON, two-space indents, a newline at the end."""
    return json.dumps(schema, indent=2, ensure_ascii=False) + "\n"


@cache
def _shipped_text(kind: str) -> str:
    if kind not in SCHEMA_FILES:
        raise ValueError(f"schema: unknown kind {kind!r} (known: {', '.join(SCHEMA_FILES)})")
    return (resources.files("core.scene") / "schemas" / SCHEMA_FILES[kind]).read_text(
        encoding="utf-8")


def load_json_schema(kind: str) -> dict[str, Any]:
    """The shipped JSON Schema of ``kind`` (``"scene"`` or ``"study"``), as a new dict."""
    return json.loads(_shipped_text(kind))


# ------------------------------------------------------------------------ checking


def _path(parts: Any, root: str) -> str:
    out = ""
    for part in parts:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or root


_TYPE_NAMES = {"number": "a number", "integer": "an integer", "string": "a string",
               "object": "an object", "array": "a list", "boolean": "true or false",
               "null": "null"}
_WORDS = {1: "one", 2: "two", 3: "three", 4: "four"}


#: Fields bounded at both ends whose refusal `solve` words as an interval ("must be in
#: (-1, 0.5)"); the others it words by the end passed ("must be > 0"), and so does the
#: schema (tests/scene/test_json_schema.py compares the two).
INTERVAL_FIELDS = frozenset({"base.poisson", "solver.tol", "solver.model_tol"})


def _words(error: Any, root: str) -> Iterator[tuple[str, str]]:
    """``(path, reason)`` of one violation found by the ``jsonschema`` package."""
    from jsonschema.exceptions import best_match

    path = _path(error.absolute_path, root)
    kind, value, instance = error.validator, error.validator_value, error.instance
    got = show_value(instance)
    if kind == "additionalProperties":
        allowed = list(error.schema.get("properties", {}))
        for key in instance:
            if key in allowed:
                continue
            hint = difflib.get_close_matches(str(key), allowed, n=1)
            yield path, (f"unknown field {str(key)[:40]!r}"
                         + (f" (did you mean '{hint[0]}'?)" if hint else
                            f" (allowed: {', '.join(allowed)})"))
    elif kind == "required":
        for key in value:
            if isinstance(instance, Mapping) and key not in instance:
                yield _path([*error.absolute_path, key], root), "required field is missing"
    elif kind == "type":
        types = [value] if isinstance(value, str) else value
        yield path, (f"must be {' or '.join(_TYPE_NAMES.get(t, t) for t in types)}, "
                     f"got {got}")
    elif kind in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
        sign = {"minimum": ">=", "maximum": "<=", "exclusiveMinimum": ">",
                "exclusiveMaximum": "<"}[kind]
        # the field's unit, as its description ends ("... [day]"), on both numbers
        unit = re.search(r"\[([^\]]+)\]\.?$", str(error.schema.get("description", "")))
        unit = "" if unit is None or unit.group(1) == "-" else " " + unit.group(1)
        unit = " days" if unit == " day" else unit
        low = next(((k, error.schema[k]) for k in ("minimum", "exclusiveMinimum")
                    if k in error.schema), None)
        high = next(((k, error.schema[k]) for k in ("maximum", "exclusiveMaximum")
                     if k in error.schema), None)
        code_age = path == "base.age_at_loading" and "then" in error.schema_path
        if (error.schema.get("type") == "integer" and low is not None and high is not None
                and low[0] == "minimum" and high[0] == "maximum"):
            # a count, as the Python checks word one ("times.count: must be an integer
            # from 1 to 2000"; the schema read "must be <= 2000")
            yield path, (f"must be an integer from {low[1]:g} to {high[1]:g}, got "
                         f"{got}{unit if unit else ''}")
        elif low is not None and high is not None and (path in INTERVAL_FIELDS or code_age):
            # both ends said at once where the Python checks say them so ("in (-1,
            # 0.5)"; a design code's age at loading): `validate` read "must be < 0.5"
            # where `solve` read "must be in (-1, 0.5)"
            bounds = (f"{'(' if low[0] == 'exclusiveMinimum' else '['}{low[1]:g}, "
                      f"{high[1]:g}{')' if high[0] == 'exclusiveMaximum' else ']'}")
            yield path, f"must be in {bounds}{unit}, got {got}{unit if unit else ''}"
        else:
            yield path, f"must be {sign} {value:g}{unit}, got {got}{unit if unit else ''}"
    elif kind == "const":
        yield path, f"must be {show_value(value)}, got {got}"
    elif kind == "enum":
        yield path, (f"must be one of {', '.join(show_value(v) for v in value)}, "
                     f"got {got}")
    elif kind in ("minItems", "maxItems"):
        bound = "at least" if kind == "minItems" else "at most"
        yield path, f"must list {bound} {value} entries, got {len(instance)}"
    elif kind == "maxLength":
        yield path, f"must be at most {value} characters, has {len(instance)}"
    elif kind == "pattern" and value == _NOT_BLANK:
        yield path, "must not be empty"
    elif kind == "pattern" and value == STRENGTH_CLASS.pattern:
        yield path, f"must look like 'C30/37' (cylinder/cube strength in MPa), got {got}"
    elif kind == "pattern":
        # a rule with its own reason is a fragment of a field's schema, without a type
        reason = error.schema.get("description") if "type" not in error.schema else None
        yield path, f"{got} {reason}" if reason else f"must match {value}, got {got}"
    elif kind in ("minProperties", "maxProperties"):
        fields = list(error.schema.get("properties", {}))
        n = error.schema.get("minProperties")
        given = ", ".join(k for k in fields if k in instance) or "none"
        yield path, (f"exactly {_WORDS.get(n, n)} of {', '.join(fields)} are needed, "
                     f"got {given}")
    elif kind == "not" and "description" in error.schema:
        yield path, str(error.schema["description"])
    elif kind == "oneOf" and all(set(s) == {"required"} for s in value):
        names = [name for s in value for name in s["required"]]
        yield path, f"give exactly one of {', '.join(names)}"
    elif kind in ("anyOf", "oneOf") and error.context:
        # the branch meant is the one whose type fits: its errors, else the best one
        branches: dict[Any, list[Any]] = {}
        for sub in error.context:
            branches.setdefault(sub.schema_path[0], []).append(sub)
        fitting = [errors for errors in branches.values()
                   if not any(e.validator == "type" and not e.relative_path for e in errors)]
        for sub in (fitting[0] if len(fitting) == 1 else [best_match(error.context)]):
            yield from _words(sub, root)
    else:
        yield path, error.message


#: The keywords of a bound on a number.
_BOUNDS = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")


def schema_errors(instance: Any, schema: Mapping[str, Any], root: str = "scene"
                  ) -> list[str]:
    """Every violation of ``schema`` by ``instance`` as ``"<field>: <reason>"``, the
    field's path written as the validator writes it (``coating[0].modulus``; ``root``
    for the whole file), in the schema's order; empty when ``instance`` conforms."""
    from jsonschema import Draft202012Validator

    validator = Draft202012Validator(schema)
    out: list[str] = []
    errors = list(validator.iter_errors(instance))
    # an object with too few or too many fields: a rule on which pair it holds says no
    # more ("loading: tilt and moment is not one of the four statements" beside "exactly
    # two of ... are needed, got tilt, force, moment")
    counted = {tuple(e.absolute_path) for e in errors
               if e.validator in ("minProperties", "maxProperties")}
    # one line a field: of two bounds on one number the one a rule adds (a design code's
    # age at loading, ">= 1 day") is said, not the general one as well ("> 0 days")
    ruled = {tuple(e.absolute_path) for e in errors
             if "then" in e.schema_path and e.validator in _BOUNDS}
    for error in errors:
        if error.validator == "not" and tuple(error.absolute_path) in counted:
            continue
        if (error.validator in _BOUNDS and "then" not in error.schema_path
                and tuple(error.absolute_path) in ruled):
            continue
        for path, reason in _words(error, root):
            line = f"{path}: {reason}"
            if line not in out:
                out.append(line)
    return out
