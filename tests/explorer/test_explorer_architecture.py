"""The explorer's shape, read from its source with ``ast`` (nothing is imported).

- It imports ``core`` only through ``core`` itself, a subpackage's ``__init__`` or a
  top-level module of ``core`` (``core.cache``): never a module inside a subpackage.
- Its own subpackages are used from outside only through their ``__init__`` (their API),
  and only by the names listed in their ``__all__``.
- Its modules import each other without a cycle, counting imports inside functions and
  under ``TYPE_CHECKING`` (a function-level import only postpones a cycle).
- ``explorer/README.md`` maps exactly the subpackages there are, and each subpackage's
  docstring names every module in it.

The layers themselves are import-linter's contracts (``pyproject.toml``).
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXPLORER = ROOT / "explorer"
CORE = ROOT / "core"


def _modules() -> dict[str, Path]:
    """Dotted name -> file of every module of the explorer (a package by its __init__)."""
    out = {}
    for path in sorted(EXPLORER.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()
SUBPACKAGES = sorted(name.split(".")[1] for name, path in MODULES.items()
                     if path.name == "__init__.py" and name != "explorer")


def _package_of(name: str) -> str:
    return name if MODULES[name].name == "__init__.py" else name.rsplit(".", 1)[0]


def _imports(name: str) -> Iterator[tuple[int, str, list[str]]]:
    """(line, absolute module, names imported from it) of every import in module ``name``,
    wherever it stands; ``import a.b`` gives ``("a.b", [])``."""
    tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name, []
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = _package_of(name).split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            yield node.lineno, target, [alias.name for alias in node.names]


def _is_core_package(dotted: str) -> bool:
    return (ROOT / dotted.replace(".", "/") / "__init__.py").is_file()


def _all_of(package: str) -> set[str]:
    tree = ast.parse(MODULES[package].read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
            return set(ast.literal_eval(node.value))
    return set()


def test_the_explorer_imports_core_only_through_its_packages_apis() -> None:
    wrong = []
    for name, path in MODULES.items():
        for line, target, names in _imports(name):
            parts = target.split(".")
            if parts[0] != "core":
                continue
            where = f"{path.relative_to(ROOT)}:{line}"
            if len(parts) > 2 and _is_core_package(".".join(parts[:2])):
                wrong.append(f"{where}: {target} is inside the package core.{parts[1]}")
            elif len(parts) == 2 and _is_core_package(target):
                wrong += [f"{where}: {target}.{n} is a module of the package {target}"
                          for n in names if (CORE / parts[1] / f"{n}.py").is_file()]
    assert not wrong, "\n".join(wrong)


def test_the_explorer_subpackages_are_used_through_their_api() -> None:
    wrong = []
    for name, path in MODULES.items():
        home = _package_of(name)
        for line, target, names in _imports(name):
            parts = target.split(".")
            if parts[0] != "explorer" or len(parts) < 2 or parts[1] not in SUBPACKAGES:
                continue
            package = ".".join(parts[:2])
            if home == package:
                continue  # a module of the package itself
            where = f"{path.relative_to(ROOT)}:{line}"
            if len(parts) > 2:
                wrong.append(f"{where}: {target} (use {package})")
                continue
            missing = sorted(set(names) - _all_of(package))
            if missing:
                wrong.append(f"{where}: {', '.join(missing)} not in {package}.__all__")
    assert not wrong, "\n".join(wrong)


def _edges() -> dict[str, set[str]]:
    """Module -> the explorer modules it imports (a package: its __init__; a name that is
    a submodule: that module)."""
    edges: dict[str, set[str]] = {name: set() for name in MODULES}
    for name in MODULES:
        for _, target, names in _imports(name):
            if target in MODULES:
                edges[name].add(target)
            for imported in names:
                if f"{target}.{imported}" in MODULES:
                    edges[name].add(f"{target}.{imported}")
        edges[name].discard(name)
    return edges


def test_the_explorer_modules_import_each_other_without_a_cycle() -> None:
    edges = _edges()
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    cycles: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for name in sorted(MODULES):
        if name not in index:
            visit(name)
    assert not cycles, cycles


def test_the_readme_maps_exactly_the_subpackages_there_are() -> None:
    text = (EXPLORER / "README.md").read_text(encoding="utf-8")
    mapped = re.findall(r"^\| `([a-z_]+)/` \|", text, flags=re.MULTILINE)
    assert sorted(mapped) == SUBPACKAGES
    assert len(mapped) == len(set(mapped))
    # every file the README names (the way from a slider to a solve) is there
    named = set(re.findall(r"`([a-z_/]+\.py)`", text))
    assert named and all((EXPLORER / path).is_file() for path in named), named


def test_each_subpackage_names_its_modules() -> None:
    for package in SUBPACKAGES:
        doc = ast.get_docstring(ast.parse(
            (EXPLORER / package / "__init__.py").read_text(encoding="utf-8"))) or ""
        modules = sorted(p.stem for p in (EXPLORER / package).glob("*.py")
                         if p.name != "__init__.py")
        unnamed = [m for m in modules if f"``{m}``" not in doc]
        assert not unnamed, f"explorer/{package}/__init__.py does not name {unnamed}"
