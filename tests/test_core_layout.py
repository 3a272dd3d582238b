"""The layout of ``core``: its map in core/README.md, its APIs, no reach into other parts.

Import-linter (run by tests/run.sh) checks the layers; these checks cover what it does
not: the map cannot go stale, and a part uses another part only through the names its
``__init__`` exports.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

CORE = Path(__file__).resolve().parent.parent / "core"
README = CORE / "README.md"


def _parts() -> set[str]:
    """Top-level modules and subpackages of core, as the map names them."""
    names = {p.name for p in CORE.glob("*.py") if p.name != "__init__.py"}
    names |= {p.name + "/" for p in CORE.iterdir() if (p / "__init__.py").is_file()}
    return names


def _map_rows() -> set[str]:
    text = README.read_text(encoding="utf-8")
    table = text.split("<!-- map:", 1)[1]
    names: set[str] = set()
    for line in table.splitlines():
        if line.startswith("| `"):
            names |= set(re.findall(r"`([^`]+)`", line.split("|")[1]))
    return names


def test_the_map_names_every_part_once() -> None:
    assert _map_rows() == _parts()


def test_every_path_in_the_readme_exists() -> None:
    for path in re.findall(r"`(core/[\w/.]+)`", README.read_text(encoding="utf-8")):
        assert (CORE.parent / path).exists(), path


def _module_name(path: Path) -> str:
    parts = path.relative_to(CORE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _part(module: str) -> str:
    """The package a module belongs to (a top-level module is its own part)."""
    parent = module.rpartition(".")[0]
    return module if parent == "core" else parent


def _core_modules() -> dict[str, Path]:
    return {_module_name(p): p for p in CORE.rglob("*.py")}


def test_every_subpackage_says_what_it_is() -> None:
    for path in CORE.rglob("__init__.py"):
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
        assert doc and len(doc.split()) >= 8, f"{path}: a docstring saying what it holds"


def test_parts_import_each_other_only_through_their_apis() -> None:
    """``from core.a.b import x`` in another part than ``core.a`` is a reach past the API;
    so is any ``_private`` name taken from another part."""
    modules = _core_modules()
    packages = {m for m, p in modules.items() if p.name == "__init__.py"}
    reaches = []
    for name, path in modules.items():
        if path.name == "__init__.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not (isinstance(node, ast.ImportFrom) and node.level == 0 and node.module
                    and node.module.startswith("core.")):
                continue
            target = node.module
            if _part(target) == _part(name) or target == "core":
                continue
            if target not in packages and _part(target) != target:
                reaches.append(f"{name}: from {target} import ...")
            reaches += [f"{name}: {target}.{a.name}" for a in node.names
                        if a.name.startswith("_")]
    assert not reaches, "\n".join(reaches)


def test_the_public_names_the_readmes_use_resolve() -> None:
    """``core.solve``, ``from core import solve_dimensionless``, ... in the README, the
    scene guide, the documentation's pages and its gallery stay working through every
    move of the code."""
    import importlib

    core = importlib.import_module("core")
    root = CORE.parent
    sources = [root / "README.md", root / "core/SCENES.md", *sorted(root.glob("docs/*.md")),
               *sorted(root.glob("docs/guides/*.md")), *sorted(root.glob("docs/examples/*.py"))]
    assert root / "docs/guide.md" in sources
    text = "".join(path.read_text(encoding="utf-8") for path in sources)
    names = set(re.findall(r"\bcore\.([a-z_]\w*)\(", text))
    for line in re.findall(r"from core import ([\w, ]+)", text):
        names |= {n.strip() for n in line.split(",")}
    assert names >= {"solve", "load_scene", "prepare", "solve_dimensionless", "sweep"}
    for name in sorted(names):
        assert getattr(core, name) is not None, name


def test_the_documented_calls_name_presets_not_paths_into_the_source_tree() -> None:
    """A wheel's user has no ``core/presets/scenes/`` below the current folder: the
    guide's ``core.load_scene("core/presets/scenes/eccentric_creep.json")`` ended in
    FileNotFoundError when run as a script elsewhere. ``preset:NAME`` reads the shipped
    file wherever the program starts."""
    root = CORE.parent
    sources = [root / "README.md", root / "core/SCENES.md", *sorted(root.glob("docs/*.md")),
               *sorted(root.glob("docs/guides/*.md")), *sorted(root.glob("docs/examples/*.py"))]
    calls = re.compile(r"""(load_scene|sweep|load_study|read_scene)\(\s*["']core/presets/"""
                       r"""|python -m core \w+ core/presets/|coated-punch \w+ core/presets/""")
    found = [f"{path.name}: {m.group(0)}" for path in sources
             for m in calls.finditer(path.read_text(encoding="utf-8"))]
    assert not found, found
