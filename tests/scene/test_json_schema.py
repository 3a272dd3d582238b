"""The JSON Schema of scene and study files: the shipped files are the generator's output,
every shipped scene and study conforms, and a file the validator refuses is refused by
the schema too wherever the schema can say the rule (the others are listed, as in
core/SCENES.md, "JSON Schema")."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from jsonschema import Draft202012Validator

from core.scene import (
    SCHEMA_FILES,
    SCHEMA_IDS,
    load_json_schema,
    load_scene,
    save_scene,
    scene_from_dict,
    scene_json_schema,
    schema_errors,
    schema_text,
)
from core.study import load_study, study_from_dict, study_json_schema
from tests.conftest import DELETE, base_scene, edited, scene_file
from tests.scene.test_scene_refusals import BAD_VALUES

ROOT = Path(__file__).resolve().parents[2]
SCENES = sorted((ROOT / "core" / "presets" / "scenes").glob("*.json"))
STUDIES = sorted((ROOT / "core" / "presets" / "studies").glob("*.json"))
SHIPPED = ROOT / "core" / "scene" / "schemas"


@pytest.fixture(scope="module")
def scene_schema() -> dict:
    return load_json_schema("scene")


@pytest.fixture(scope="module")
def study_schema() -> dict:
    return load_json_schema("study")


@pytest.mark.parametrize("kind", ["scene", "study"])
def test_the_shipped_schemas_are_the_generators_output(kind: str) -> None:
    made = scene_json_schema() if kind == "scene" else study_json_schema()
    # regenerate with: python -m core schema KIND > core/scene/schemas/KIND.schema.json
    assert (SHIPPED / SCHEMA_FILES[kind]).read_text(encoding="utf-8") == schema_text(made)
    assert load_json_schema(kind) == made
    Draft202012Validator.check_schema(made)
    assert made["$id"] == SCHEMA_IDS[kind] and made["$id"].startswith("urn:coated-punch:")
    assert made["$schema"] == "https://json-schema.org/draft/2020-12/schema"


def test_the_schemas_are_package_data() -> None:
    text = (ROOT / "pyproject.toml").read_text()
    assert '"core.scene" = ["schemas/*.json"]' in text
    assert '"jsonschema>=4.18"' in text


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_every_preset_conforms(path: Path, scene_schema: dict) -> None:
    data = json.loads(path.read_text())
    assert schema_errors(data, scene_schema) == []
    # the canonical form the program writes conforms too (defaults filled in)
    assert schema_errors(load_scene(path).to_dict(), scene_schema) == []


@pytest.mark.parametrize("path", STUDIES, ids=lambda p: p.stem)
def test_every_study_conforms(path: Path, study_schema: dict) -> None:
    data = json.loads(path.read_text())
    assert schema_errors(data, study_schema, root="study") == []
    # with its base scene inline, as study_from_dict makes it
    study = load_study(path)
    data["scene"] = study.base
    assert schema_errors(data, study_schema, root="study") == []


def test_descriptions_carry_units(scene_schema: dict) -> None:
    defs = scene_schema["$defs"]
    assert defs["punch"]["properties"]["half_width"]["description"].endswith("[m]")
    assert defs["layer"]["properties"]["modulus"]["description"].endswith("[Pa]")
    assert defs["limits"]["properties"]["allowable_pressure"]["description"].endswith("[Pa]")
    assert defs["limits"]["properties"]["tilt_limit"]["description"].endswith("[rad]")
    assert defs["base"]["properties"]["age_at_loading"]["description"].endswith("[day]")
    assert defs["solver"]["properties"]["tol"]["default"] == 1e-6


def test_a_schema_key_is_accepted_and_ignored(tmp_path: Path, scene_schema: dict) -> None:
    plain = base_scene()
    tagged = {"$schema": "../../core/scene/schemas/scene.schema.json", **plain}
    assert schema_errors(tagged, scene_schema) == []
    assert scene_from_dict(tagged) == scene_from_dict(plain)
    assert "$schema" not in scene_from_dict(tagged).to_dict()
    file = tmp_path / "scene.json"
    save_scene(plain, file, schema=SCHEMA_IDS["scene"])
    text = file.read_text()
    assert text.startswith('{\n  "$schema": "urn:coated-punch:schema:scene:1",')
    assert load_scene(file) == scene_from_dict(plain)
    with pytest.raises(ValueError, match=r"^\$schema: must be a string"):
        scene_from_dict({**plain, "$schema": 3})
    assert schema_errors({**plain, "$schema": 3}, scene_schema) == [
        "$schema: must be a string, got 3"]


# The validator's own refusals (tests/scene/test_scene_refusals.py) that the schema
# cannot say: finiteness (JSON has no NaN or infinity; the reader makes a 400-digit
# integer infinite), a profile's values over its domain, increasing rows and times, a
# formula's values. Their messages name the field either way. (An infinite age at loading
# is past the schema's maximum age.)
PYTHON_ONLY_BAD_VALUES = {
    "punch.half_width=nan", "loading.force=-inf",
    "punch.half_width=10**400", "base.creep.modulus=10**400",
    "coating[0].thickness=table decreasing", "base.creep=kernel positive",
    "base.creep=kernel not finite", "times=decreasing",
    # the base's modulus at loading, which most creep models derive from their fields
    "base.creep.modulus=30.0", "base.creep.modulus=300000000000000.0",
    "base.creep=arutyunyan modulus",
}


def _bad_value_id(path: str, value: Any) -> str:
    if isinstance(value, float) or (isinstance(value, int) and value == 10**400):
        text = "10**400" if value == 10**400 else repr(value)
        return f"{path}={text}"
    if path == "coating[0].thickness" and isinstance(value, dict) \
            and len(value["points"]) == 2:
        return f"{path}=table decreasing"
    if path == "base.creep" and isinstance(value, dict) and "expr" not in value:
        return f"{path}={value['model']} modulus"
    if path == "base.creep" and isinstance(value, dict):
        return f"{path}=kernel " + ("positive" if "exp" in value["expr"] else "not finite")
    if path == "times" and value[0] == 0.0:
        return "times=decreasing"
    return f"{path}={value!r}"


# More refusals, each with the field the validator names; None: the schema cannot say it.
MORE_BAD: list[tuple[str, Any, str, bool]] = [
    ("punch.colour", "red", "punch", True),
    ("coating[0].interface", "glued", "coating[0].interface", True),
    ("coating[0].thickness", {"kind": "stepp", "values": [1]}, "coating[0].thickness", True),
    ("coating[0].thickness", {"kind": "linear", "start": 0.01}, "coating[0].thickness", True),
    ("coating[0].thickness", {"kind": "constant", "value": -0.01}, "coating[0].thickness",
     True),
    ("coating[0].thickness", "0.01", "coating[0].thickness", True),
    ("coating[0].modulus", {"kind": "table", "points": [[0, 1e9], [1, 2e9, 3]]},
     "coating[0].modulus", True),
    ("loading", {"force": 5e5}, "loading", True),
    ("loading", {"force": 5e5, "settlement": 0.01}, "loading", True),
    ("loading", {"tilt": 0.0, "moment": 0.0}, "loading", True),
    ("loading.forse", 1.0, "loading", True),
    ("times", {"end": 10.0}, "times", True),
    ("times", {"end": 10.0, "count": 0}, "times.count", True),
    ("times", {"end": 10.0, "count": 3, "spacing": "cubic"}, "times.spacing", True),
    ("times", [], "times", True),
    ("solver", {"tol": 0.5}, "solver.tol", True),
    ("solver", {"contact": "sticky"}, "solver.contact", True),
    ("solver", {"model_tol": 0.0}, "solver.model_tol", True),
    ("name", "   ", "name", True),
    ("name", "n" * 201, "name", True),
    ("description", 7, "description", True),
    ("limits", {"allowable_pressure": -1.0}, "limits.allowable_pressure", True),
    ("limits", {"settlement": 0.01}, "limits", True),
    ("limits", {"tilt_limit": "0.001"}, "limits.tilt_limit", True),
    ("base.creep", {"model": "elastc", "modulus": 3e10}, "base.creep.model", True),
    ("base.creep", {"model": "exponential", "modulus": 3e10, "compliance": 1e-11,
                    "rate": 0.0}, "base.creep.rate", True),
    ("base.creep", {"model": "arutyunyan", "modulus_final": 3e10, "beta": 1.0,
                    "alpha": 0.03, "compliance_final": 9e-12, "aging": 4.8e-10,
                    "rate": 0.03}, "base.creep.beta", True),
    ("base.creep", {"model": "prony", "modulus": 3e10, "terms": []}, "base.creep.terms",
     True),
    ("base.creep", {"model": "prony", "modulus": 3e10,
                    "terms": [{"compliance": 1e-11, "rate": 0.1, "speed": 1}]},
     "base.creep.terms[0]", True),
    ("base.creep", {"model": "fib_mc2010", "relative_humidity": 60, "notional_size": 300},
     "base.creep", True),
    ("base.creep", {"model": "eurocode2", "fcm": 38, "relative_humidity": 30,
                    "notional_size": 300}, "base.creep.relative_humidity", True),
    ("base.creep", {"model": "fib_mc2010", "strength_class": "C30", "relative_humidity": 60,
                    "notional_size": 300}, "base.creep.strength_class", True),
    ("base.creep", {"model": "kernel", "modulus": 3e10, "expr": "x" * 501},
     "base.creep.expr", True),
    # the schema cannot say these: they join fields or need the profile's values
    ("base.thickness", 1e-5, "base.thickness", False),            # a / H
    ("coating[0].thickness", {"kind": "linear", "start": 0.01, "end": -0.01},
     "coating[0].thickness", False),                               # values over [-a, a]
    ("coating[0].thickness", {"kind": "step", "values": [0.01, 0.02], "breaks": [5.0]},
     "coating[0].thickness.breaks[0]", False),                     # inside the domain
    ("coating[0].thickness", {"kind": "step", "values": [0.01], "breaks": [0.1]},
     "coating[0].thickness.values", False),                        # one value more
    ("coating[0].thickness", {"kind": "expr", "expr": "0.01 +"}, "coating[0].thickness",
     False),                                                       # a formula that parses
    ("coating[0].thickness", {"kind": "step", "values": [0.01 + 0.001 * k for k in range(18)],
                              "breaks": [-0.85 + 0.1 * k for k in range(17)]},
     "coating[0].thickness", False),                               # 16 breakpoints
    ("times", [0.0, 0.0], "times[1]", False),                      # increasing
    ("base.creep", {"model": "fib_mc2010", "strength_class": "C150/170",
                    "relative_humidity": 60, "notional_size": 300},
     "base.creep.strength_class", False),                          # fck + 8 in range
]


def _cases() -> list[tuple[str, dict, str, bool]]:
    cases = []
    for path, value, message in BAD_VALUES:
        name = _bad_value_id(path, value)
        field = message.split(":")[0]
        if path == "schema_version" and value is not DELETE:
            continue  # refused by the version's migration, before any schema
        cases.append((name, edited(path, value), field, name not in PYTHON_ONLY_BAD_VALUES))
    for path, value, field, says in MORE_BAD:
        cases.append((f"{path}={value!r}"[:60], edited(path, value), field, says))
    return cases


CASES = _cases()


@pytest.mark.parametrize(("scene", "field", "says"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_the_schema_refuses_what_the_validator_refuses_where_it_can_say_it(
        scene: dict, field: str, says: bool, scene_schema: dict) -> None:
    with pytest.raises(ValueError) as refused:
        scene_from_dict(json.loads(json.dumps(scene)))
    assert str(refused.value).startswith(field), str(refused.value)
    problems = schema_errors(scene, scene_schema)
    if not says:
        assert problems == [], problems
        return
    assert problems, "the schema accepts a scene the validator refuses"
    # the schema's problems name the validator's field, or a field inside or around it
    paths = [p.split(": ")[0] for p in problems]
    assert any(p.startswith(field) or field.startswith(p) for p in paths), (paths, field)


def test_the_code_models_bound_the_age_at_loading_in_the_schema(scene_schema: dict) -> None:
    scene = edited("base.creep", {"model": "eurocode2", "fcm": 38, "relative_humidity": 60,
                                  "notional_size": 300})
    scene = edited("base.age_at_loading", 0.5, scene)
    with pytest.raises(ValueError, match="age_at_loading"):
        scene_from_dict(scene)
    assert schema_errors(scene, scene_schema) == [
        "base.age_at_loading: must be in [1, 3650] days, got 0.5 days"]
    # the solver says the code's range first too: it said "must be > 0" for 0 days and
    # "must be <= 100000 days" for 1e9 (the page showed those beside the code's range)
    for age in (0, 0.5, -3, 1e9):
        with pytest.raises(ValueError, match=r"^base\.age_at_loading: must be in \[1, 3650\] "
                                             r"\(EN 1992-1-1 Figure 3\.1"):
            scene_from_dict(edited("base.age_at_loading", age, scene))
    # (its type first, in a scene file's words)
    with pytest.raises(ValueError, match=r"^base\.age_at_loading: must be a number, got null$"):
        scene_from_dict(edited("base.age_at_loading", None, scene))
    # one line a field: at 0 the code's bound, not the general "> 0 days" as well
    assert schema_errors(edited("base.age_at_loading", 0, scene), scene_schema) == [
        "base.age_at_loading: must be in [1, 3650] days, got 0 days"]


def test_a_strength_class_is_a_class_and_three_loads_one_line(scene_schema: dict) -> None:
    """"c30/37" was refused with the pattern's regular expression, "C30/99" taken as
    C30/37; three loads gave a second line "tilt and moment is not one of the four
    statements"."""
    def code(strength_class: str) -> dict:
        return edited("base.creep", {"model": "fib_mc2010", "strength_class": strength_class,
                                     "relative_humidity": 60, "notional_size": 300})

    assert schema_errors(code("c30/37"), scene_schema) == []
    assert scene_from_dict(code("c30/37")).to_dict()["base"]["creep"]["strength_class"] \
        == "c30/37"
    assert schema_errors(code("Cxx"), scene_schema) == [
        "base.creep.strength_class: must look like 'C30/37' (cylinder/cube strength in MPa), "
        "got 'Cxx'"]
    with pytest.raises(ValueError, match=r"^base\.creep\.strength_class: 'C30/99' is not a "
                                         r"strength class \(C12/15, .*C30/37, .*C120/140\); "
                                         r"give fcm \[MPa\] for another concrete$"):
        scene_from_dict(code("C30/99"))
    three = edited("loading", {"tilt": 0.0, "force": 1.0, "moment": 0.1})
    assert schema_errors(three, scene_schema) == [
        "loading: exactly two of settlement, tilt, force, moment are needed, got tilt, "
        "force, moment"]


#: Fields bounded at both ends, each set past one end and the other.
BOUNDED = [("times.count", 0), ("times.count", 5000),
           ("base.poisson", -2.0), ("base.poisson", 0.7), ("coating[0].poisson", -2.0),
           ("coating[0].poisson", 0.7), ("solver.tol", 0.0), ("solver.tol", 1.0),
           ("solver.model_tol", 0.0), ("solver.model_tol", 5.0),
           ("base.age_at_loading", 0.0), ("base.age_at_loading", 1e6),
           ("times.end", 1e9), ("base.creep.rate", -1.0), ("base.creep.rate", 1e7)]


@pytest.mark.parametrize(("path", "value"), BOUNDED, ids=[f"{p}={v:g}" for p, v in BOUNDED])
def test_a_bound_is_said_by_validate_as_solve_says_it(path: str, value: float,
                                                     scene_schema: dict) -> None:
    """`coated-punch validate` (the schema) and `solve` (the validator) give one reason:
    made general, "must be in (0, 100000] days" stood beside "must be > 0"."""
    scene = edited(path, value, scene_file("eccentric_creep"))
    with pytest.raises(ValueError) as refused:
        scene_from_dict(scene)
    (problem,) = schema_errors(scene, scene_schema)
    # the reason up to the value (the validator adds units, a place or a why after it)
    said = problem.split(", got ")[0]
    words = said.split(" days")[0] if "days" in said else said
    assert str(refused.value).startswith(words), (problem, str(refused.value))


def test_the_reasons_are_worded_as_the_validator_words_them(scene_schema: dict) -> None:
    assert schema_errors(edited("punch.hafl_width", 1.0), scene_schema)[0] == (
        "punch: unknown field 'hafl_width' (did you mean 'half_width'?)")
    assert schema_errors(edited("loading", {"force": 1.0}), scene_schema) == [
        "loading: exactly two of settlement, tilt, force, moment are needed, got force"]
    assert schema_errors(edited("loading", {"force": 1.0, "settlement": 0.0}),
                         scene_schema) == [
        "loading: settlement and force is not one of the four statements (settlement+tilt, "
        "settlement+moment, tilt+force, force+moment)"]
    # a field bounded at both ends is said as the validator says it: `coated-punch
    # validate` read "must be < 0.5" where `solve` read "must be in (-1, 0.5)"
    assert schema_errors(edited("coating[0].poisson", 0.5), scene_schema) == [
        "coating[0].poisson: must be < 0.5, got 0.5"]
    with pytest.raises(ValueError) as refused:
        scene_from_dict(edited("base.poisson", -2.0))
    assert schema_errors(edited("base.poisson", -2.0), scene_schema) == [str(refused.value)]
    assert schema_errors(edited("base.thickness", DELETE), scene_schema) == [
        "base.thickness: required field is missing"]
    # every problem of a file at once, not only the first
    scene = edited("base.poisson", 2.0, edited("solver", {"tol": 1.0}))
    assert schema_errors(scene, scene_schema) == [
        "base.poisson: must be in (-1, 0.5), got 2", "solver.tol: must be in [1e-12, 0.01], got 1"]


def _study(**changes: Any) -> dict:
    data = json.loads(STUDIES[0].read_text())
    data.update(changes)
    return data


STUDY_BAD: list[tuple[dict, str, bool]] = [
    (_study(samples=5), "samples", True),
    (_study(vary=[{"field": "base.age_at_loading", "normal": {"mean": 28, "std": 3}}]),
     "samples", True),
    (_study(vary=[{"field": "times[0]", "values": [1.0]}]), "vary[0].field", True),
    (_study(vary=[{"field": "limits.tilt_limit", "values": [1.0]}]), "vary[0].field", True),
    (_study(vary=[{"field": "coating[0]..modulus", "values": [1.0]}]), "vary[0].field", True),
    (_study(vary=[{"field": "loading.moment", "values": [0.0], "linspace": {}}]), "vary[0]",
     True),
    (_study(vary=[{"field": "loading.moment", "logspace": {"start": 0, "stop": 1,
                                                           "count": 3}}]),
     "vary[0].logspace.start", True),
    (_study(vary=[]), "vary", True),
    (_study(outputs=["q_mx"]), "outputs[0]", True),
    (_study(study_version=2), "study_version", True),
    (_study(description=3), "description", True),
    (_study(colour="red"), "study", True),
    # the schema cannot say these
    (_study(vary=[{"field": "coating[3].modulus", "values": [1.0]}]), "vary[0].field",
     False),
    (_study(vary=[{"field": "loading.moment", "uniform": {"low": 1.0, "high": 0.0}}],
            samples=2), "vary[0].uniform.high", False),
    (_study(vary=[{"field": "coating[0].modulus", "values": [-1e8, 1e8]}]),
     "vary[0].values", False),
]


@pytest.mark.parametrize(("study", "field", "says"), STUDY_BAD,
                         ids=[f"{i}-{c[1]}" for i, c in enumerate(STUDY_BAD)])
def test_the_study_schema_refuses_what_the_validator_refuses(study: dict, field: str,
                                                             says: bool,
                                                             study_schema: dict) -> None:
    with pytest.raises(ValueError) as refused:
        study_from_dict(study, base_dir=STUDIES[0].parent)
    assert str(refused.value).startswith(field), str(refused.value)
    problems = schema_errors(study, study_schema, root="study")
    if not says:
        assert problems == [], problems
        return
    paths = [p.split(": ")[0] for p in problems]
    assert any(p.startswith(field) or field.startswith(p) for p in paths), (paths, field)
