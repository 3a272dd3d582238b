"""The API reference pages, generated from each public package's ``__all__``.

One page per package of :data:`PACKAGES` under ``api/packages/`` (git-ignored), written
before autosummary makes its stub pages. A name several packages export is documented
once, on the page of the first package that exports it (the order of :data:`PACKAGES`),
and linked from the others; constants are documented from their ``#:`` comments where
they are defined.
"""

from __future__ import annotations

import importlib
import inspect
import sys
from pathlib import Path
from typing import Any

from generated_pages import write_if_changed
from sphinx.application import Sphinx
from sphinx.ext.autosummary import autosummary_toc
from sphinx.pycode import ModuleAnalyzer
from sphinx.util import logging

logger = logging.getLogger(__name__)

#: The documented packages, in the order a re-exported name is homed; ``core`` last, so
#: that its re-exports link to the package that holds them.
PACKAGES = (
    "core.scene",
    "core.study",
    "core.back_analysis",
    "core.creep",
    "core.profiles",
    "core.coating",
    "core.engines",
    "core.problem",
    "core.report",
    "core.presets",
    "core.optional",
    "core",
)
OUT_DIR = Path("api") / "packages"


def _kind(obj: Any) -> str:
    if inspect.isclass(obj):
        return "class"
    if callable(obj):
        return "function"
    return "data"


def _definition_docs(package: str, name: str, obj: Any) -> list[str]:
    """The ``#:`` comment of a constant where it is defined, found among the package's
    modules (the object itself, not an equal one; the module that defines it was
    imported by the package that exports it)."""
    modules = [package] + sorted(m for m in sys.modules if m.startswith(package + "."))
    for module_name in modules:
        module = sys.modules.get(module_name)
        if module is None or getattr(module, name, None) is not obj:
            continue
        try:
            docs = ModuleAnalyzer.for_module(module_name).find_attr_docs()
        except Exception:  # no source: try the next module
            continue
        lines = docs.get(("", name))
        if lines:
            return list(lines)
    return []


def _homes() -> dict[str, str]:
    home: dict[str, str] = {}
    for package in PACKAGES:
        module = importlib.import_module(package)
        for name in module.__all__:
            if name.startswith("__"):
                continue
            obj = getattr(module, name)
            key = f"{getattr(obj, '__module__', package)}.{name}" if _kind(obj) != "data" \
                else f"{package}.{name}"
            home.setdefault(key, package)
    return home


def _page(package: str, homes: dict[str, str]) -> str:
    module = importlib.import_module(package)
    title = f"``{package}``"
    lines = [title, "=" * len(title), "", f".. automodule:: {package}", "   :no-members:",
             "", f".. currentmodule:: {package}", ""]
    sections: dict[str, list[str]] = {"function": [], "class": [], "data": []}
    elsewhere: list[str] = []
    data_blocks: list[str] = []
    for name in module.__all__:
        if name.startswith("__"):
            continue
        obj = getattr(module, name)
        kind = _kind(obj)
        key = f"{getattr(obj, '__module__', package)}.{name}" if kind != "data" \
            else f"{package}.{name}"
        home = homes.get(key, package)
        if kind == "data" and home == package:
            doc = _definition_docs(package, name, obj)
            data_blocks += [f".. py:data:: {name}", ""]
            data_blocks += [f"   {line}" if line.strip() else "" for line in doc] or [
                f"   ``{package}.{name}``"]
            data_blocks.append("")
        elif home == package:
            sections[kind].append(name)
        else:
            # autosummary wants names below the current module relative to it
            relative = home[len(package) + 1:] if home.startswith(package + ".") else home
            elsewhere.append(f"~{relative}.{name}")
    headings = {"function": "Functions", "class": "Classes"}
    for kind, heading in headings.items():
        if sections[kind]:
            lines += [heading, "-" * len(heading), "", ".. autosummary::",
                      "   :toctree: generated", "   :nosignatures:", ""]
            lines += [f"   {name}" for name in sections[kind]] + [""]
    if data_blocks:
        lines += ["Constants", "---------", ""] + data_blocks
    if elsewhere:
        lines += ["Also exported here", "------------------", "",
                  "Documented with the package that holds them.", "",
                  ".. autosummary::", "   :nosignatures:", ""]
        lines += [f"   {name}" for name in elsewhere] + [""]
    return "\n".join(lines)


def _remove_stale_stubs(folder: Path) -> None:
    """Autosummary's pages of names a package no longer exports: left in the source tree
    from an earlier build, they would fail this one (autodoc cannot import them)."""
    for stub in folder.glob("*.rst") if folder.exists() else []:
        package, _, name = stub.stem.rpartition(".")
        if package not in PACKAGES or name not in importlib.import_module(package).__all__:
            stub.unlink()


def generate(app: Sphinx) -> None:
    out = Path(app.srcdir) / OUT_DIR
    homes = _homes()
    for package in PACKAGES:
        write_if_changed(out / f"{package}.rst", _page(package, homes))
    _remove_stale_stubs(out / "generated")
    # a fresh environment listed its documents before these pages were written
    app.env.find_files(app.config, app.builder)


#: Where autosummary writes the page of each function and class (its ``:toctree:``).
STUBS = (OUT_DIR / "generated").as_posix()


def off_the_tree(app: Sphinx, doctree: Any) -> None:
    """Keep the page of each function and class out of the table of contents: reached
    from its package's page (its table links it) and the search, not from the sidebar.

    In the table of contents, the ~190 such pages made every page's sidebar list each of
    them, and the theme builds that sidebar afresh for every page: ~60 % of the build's
    time (cProfile, 237 pages), a list no reader scans. Each package page's hidden
    toctree of them is taken out before the environment collects it (its collector runs
    at priority 500), and the pages themselves are marked orphans (a page in no toctree
    is otherwise a warning).
    """
    docname = app.env.docname
    if docname.startswith(STUBS + "/"):
        app.env.metadata[docname]["orphan"] = True
    elif docname.startswith(OUT_DIR.as_posix() + "/"):
        for node in list(doctree.findall(autosummary_toc)):
            node.parent.remove(node)


def setup(app: Sphinx) -> dict[str, Any]:
    # before autosummary (priority 500) makes the stub pages these pages ask for
    app.connect("builder-inited", generate, priority=400)
    app.connect("doctree-read", off_the_tree, priority=400)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
