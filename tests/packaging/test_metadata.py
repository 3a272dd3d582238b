"""What the package declares against what its code does: requirements against imports,
the solver's lean install, the shipped data, the version in every place it is written."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest
import tomllib

import core
from core.optional import DISTRIBUTION_OF, EXTRA_OF, MissingDependency, import_optional
from core.presets import preset_names, read_preset, read_study, study_names

ROOT = Path(__file__).resolve().parents[2]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
PROJECT = PYPROJECT["project"]

#: Modules each optional feature brings; blocked together they leave the solver's install.
OPTIONAL_MODULES = ("dask", "distributed", "xarray", "pandas", "pyarrow", "skfem", "holoviews",
                    "bokeh", "matplotlib", "panel", "param", "tornado", "PIL")


def _name(requirement: str) -> str:
    """The distribution a requirement names (``dask[distributed]>=1`` -> ``dask``)."""
    for stop in "[<>=!~; ":
        requirement = requirement.split(stop)[0]
    return requirement.strip().lower().replace("_", "-")


def _extra(name: str, seen: frozenset[str] = frozenset()) -> set[str]:
    """The distributions an extra installs, following ``coated-punch[...]`` references."""
    found: set[str] = set()
    for requirement in PROJECT["optional-dependencies"][name]:
        if _name(requirement) == PROJECT["name"]:
            inner = requirement.split("[")[1].split("]")[0].split(",")
            for other in inner:
                if other not in seen:
                    found |= _extra(other.strip(), seen | {name})
        else:
            found.add(_name(requirement))
    return found


def _third_party_imports(package: str) -> dict[str, set[str]]:
    """Top-level module -> the files of ``package`` that import it (absolute imports of
    modules outside the standard library and the project)."""
    found: dict[str, set[str]] = {}
    for path in (ROOT / package).rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.split(".")[0]
                if top not in sys.stdlib_module_names and top not in ("core", "explorer"):
                    found.setdefault(top, set()).add(str(path.relative_to(ROOT)))
    return found


def _distribution(module: str) -> str:
    return DISTRIBUTION_OF.get(module) or metadata.packages_distributions()[module][0].lower()


def test_every_import_of_the_solver_is_declared_in_the_base_or_its_extra():
    base = {_name(r) for r in PROJECT["dependencies"]}
    for module, files in _third_party_imports("core").items():
        dist = _distribution(module)
        if dist in base:
            continue
        assert module in EXTRA_OF, f"{module} (imported by {sorted(files)}) is neither a " \
                                   "requirement nor an optional module of core.optional"
        assert dist in _extra(EXTRA_OF[module]), \
            f"{module}: the extra {EXTRA_OF[module]!r} does not install {dist}"


def test_every_import_of_the_explorer_is_installed_by_its_extra():
    explorer = _extra("explorer") | {_name(r) for r in PROJECT["dependencies"]}
    for module, files in _third_party_imports("explorer").items():
        assert _distribution(module) in explorer, \
            f"{module} (imported by {sorted(files)}) is not installed by the explorer extra"


def test_the_test_extra_installs_everything():
    assert _extra("all") <= _extra("test")
    assert {"panel", "bokeh", "holoviews", "dask", "xarray", "scikit-fem"} <= _extra("all")


def test_the_solver_runs_without_any_optional_package(tmp_path):
    """The base install (numpy, scipy): every part of core imports, a preset solves and
    validates; a feature that needs an extra says which."""
    script = f"""
import importlib.abc, importlib.machinery, sys
BLOCKED = {OPTIONAL_MODULES!r}
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
sys.meta_path.insert(0, Block())
import pkgutil, core
for info in pkgutil.walk_packages(core.__path__, "core."):
    if info.name not in ("core.study.warm", "core.__main__"):  # a Dask worker; the CLI run
        importlib.import_module(info.name)
from core.presets import read_preset
result = core.solve(read_preset("uniform_flat"))
assert result.settlement[-1] > 0
from core.optional import MissingDependency, import_optional
try:
    import_optional("xarray", "a study's dataset")
except MissingDependency as error:
    print(error)
leaked = sorted(m for m in BLOCKED if m in sys.modules)
assert not leaked, leaked
print("ok")
"""
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    run = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    assert "xarray is needed for a study's dataset and is not installed: " \
           "pip install 'coated-punch[data]'" in run.stdout
    assert run.stdout.strip().endswith("ok")


def test_a_missing_optional_package_names_its_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "skfem", None)  # import raises ModuleNotFoundError
    with pytest.raises(MissingDependency, match=r"pip install 'coated-punch\[fem\]'"):
        import_optional("skfem", "the finite-element check")


def test_every_optional_module_maps_to_a_declared_extra():
    for module, extra in EXTRA_OF.items():
        assert extra in PROJECT["optional-dependencies"], (module, extra)


def test_the_shipped_presets_and_studies_are_valid():
    assert len(preset_names()) >= 8 and "worn_coating" in preset_names()
    for name in preset_names():
        # either form: one punch, or several (core.scene.punches_from_dict)
        core.load_scene(f"preset:{name}")
    for name in study_names():
        assert read_study(name)["scene"].startswith("../scenes/")
    with pytest.raises(KeyError, match="known: bare_layer, eccentric_creep"):
        read_preset("no_such_preset")


def test_the_version_has_one_source():
    assert metadata.version("coated-punch") == core.__version__
    citation = (ROOT / "CITATION.cff").read_text()
    assert f'version: "{core.__version__}"' in citation
    version = PYPROJECT["tool"]["setuptools"]["dynamic"]["version"]
    assert version == {"attr": "core.version.VERSION"}


def test_license_and_metadata():
    assert "BSD 3-Clause License" in (ROOT / "LICENSE").read_text()
    assert PROJECT["license"] == "BSD-3-Clause"
    assert PROJECT["scripts"] == {"coated-punch": "core.cli:main",
                                  "coated-punch-explorer": "explorer.__main__:main"}
    assert any("Programming Language :: Python :: 3.11" == c for c in PROJECT["classifiers"])
    package_data = PYPROJECT["tool"]["setuptools"]["package-data"]
    assert "scenes/*.json" in package_data["core.presets"]
    assert "SCENES.md" in package_data["core"]


def test_every_scene_is_json_an_editor_reads():
    # the shipped files stay plain JSON objects (no comments, no trailing commas)
    for name in preset_names():
        path = ROOT / "core" / "presets" / "scenes" / f"{name}.json"
        assert isinstance(json.loads(path.read_text()), dict)


def test_a_shipped_scene_or_study_is_named_preset_colon_name():
    assert core.load_scene("preset:worn_coating").to_dict() \
        == core.scene_from_dict(read_preset("worn_coating")).to_dict()
    assert core.load_study("preset:eccentric_design").n_points > 0
    with pytest.raises(ValueError, match="preset:nope: no shipped scene of that name; known: "
                                         "bare_layer, eccentric_creep"):
        core.load_scene("preset:nope")
    # solve reads one as the commands do (it refused the string, sweep took it)
    assert core.solve("preset:worn_coating").settlement.tolist() \
        == core.solve(core.load_scene("preset:worn_coating")).settlement.tolist()
    with pytest.raises(ValueError, match="preset:nope: no shipped scene of that name"):
        core.solve("preset:nope")
    # (the study's own word: it read "no shipped studie")
    with pytest.raises(ValueError, match="preset:nope: no shipped study of that name; known: "
                                         "eccentric_design"):
        core.load_study("preset:nope")
