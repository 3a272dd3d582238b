"""Links between the repository's Markdown files, made to work inside the documentation.

The Markdown sources (``docs/guide.md``, ``core/SCENES.md``, ``CHANGELOG.md``, the reports
in ``benchmarks/results/``, ...) link to each other by their paths in the repository, as a
code host shows them. Read into the documentation, a link to a file that has a page
(:data:`PAGES`, and every report) is pointed at that page, a link to any other file of
the repository becomes its plain text, and an image is found from the page that shows it.
"""

from __future__ import annotations

import os
import re
from pathlib import Path, PurePosixPath
from typing import Any

from sphinx.application import Sphinx

ROOT = Path(__file__).resolve().parents[2]

#: Repository files shown as pages of their own (path from the root -> document name).
PAGES = {
    "docs/guide.md": "guide",
    "docs/method.md": "method",
    "core/SCENES.md": "reference/scenes",
    "core/README.md": "reference/core_map",
    "explorer/README.md": "reference/explorer_map",
    "CHANGELOG.md": "changelog",
}
#: Each report ``benchmarks/results/NAME.md`` is the page ``benchmarks/reports/NAME``.
REPORTS = ("benchmarks/results/", "benchmarks/reports/")

_LINK = re.compile(r"(!?)\[([^\]\n]*)\]\(([^)\s]+)\)")
#: A path in code quotes, outside a link: `benchmarks/results/sweep.md`, `core/SCENES.md`
_QUOTED_PATH = re.compile(r"(?<!\[)`((?:\.\./)*[\w./-]+\.md)`(?![\]\w])")
_FENCE = re.compile(r"^\s*(```|~~~)")


def page_of(path: str) -> str | None:
    """The document name of the page showing the repository file ``path``, if any."""
    if path in PAGES:
        return PAGES[path]
    source, target = REPORTS
    if path.startswith(source) and path.endswith(".md") and "/" not in path[len(source):]:
        return target + path[len(source):-3]
    return None


def _rewrite(text: str, file_dir: PurePosixPath, page_dir: PurePosixPath) -> str:
    """``text`` (Markdown read from ``file_dir``) as shown by a page in ``page_dir`` (both
    relative to the repository root)."""

    def link(match: re.Match[str]) -> str:
        bang, label, target = match.groups()
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            return match.group(0)  # a web address or an anchor on the same page
        path, _, anchor = target.partition("#")
        resolved = PurePosixPath(os.path.normpath(file_dir / path).replace(os.sep, "/"))
        if bang:
            return f"![{label}]({os.path.relpath(resolved, page_dir)})"
        page = page_of(str(resolved))
        if page is None:
            return label  # a source file or folder: no page shows it
        return f"[{label}](/{page}.md{'#' + anchor if anchor else ''})"

    def quoted(match: re.Match[str]) -> str:
        """A quoted path of a file with a page, from the repository's root as the
        sources write them, becomes a link to that page."""
        page = page_of(os.path.normpath(match.group(1)).replace(os.sep, "/"))
        return match.group(0) if page is None else f"[{match.group(0)}](/{page}.md)"

    out: list[str] = []
    fenced = False
    for line in text.splitlines(keepends=True):
        if _FENCE.match(line):
            fenced = not fenced
        out.append(line if fenced else _QUOTED_PATH.sub(quoted, _LINK.sub(link, line)))
    return "".join(out)


def _repo_dir(path: Path) -> PurePosixPath:
    return PurePosixPath(path.resolve().parent.relative_to(ROOT).as_posix())


def _doc_dir(app: Sphinx, docname: str) -> PurePosixPath:
    return _repo_dir(Path(app.srcdir) / docname)


def on_source_read(app: Sphinx, docname: str, source: list[str]) -> None:
    if not str(app.env.doc2path(docname)).endswith(".md"):
        return
    page_dir = _doc_dir(app, docname)
    source[0] = _rewrite(source[0], page_dir, page_dir)


def on_include_read(app: Sphinx, relative_path: Path, parent_docname: str,
                    content: list[str]) -> None:
    included = (Path(app.srcdir) / relative_path).resolve()
    if included.suffix != ".md":
        return
    # the document being read shows the text (MyST's include names its parent by the
    # last part of its name only)
    content[0] = _rewrite(content[0], _repo_dir(included), _doc_dir(app, app.env.docname))


def setup(app: Sphinx) -> dict[str, Any]:
    app.connect("source-read", on_source_read)
    app.connect("include-read", on_include_read)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
