"""The benchmark and accuracy pages, made at build time from ``benchmarks/results/``.

No figure on these pages is typed by hand:

- every Markdown report ``benchmarks/results/NAME.md`` becomes the page
  ``benchmarks/reports/NAME`` (git-ignored): what the report says of how it was made (its
  command, commit, date, machine and load) as a table, then the report itself;
- ``.. report-index::`` lists every file of ``benchmarks/results/`` with that metadata;
- ``.. engine-accuracy::`` (``engines.json``): the default engine's measured error against
  its own estimate at each ``tol``, per scene;
- ``.. reference-agreement::`` (``work_precision.json``): how far the independent
  reference answers of the work-precision scenes agree with the cross-check;
- ``.. engine-goals::`` (``engines.json``): the speed goals' measured figures;
- ``.. report-section:: FILE.md`` with the heading as content: one section of a report,
  shown where it is needed (its text as the report has it; for Markdown pages).
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from docutils import nodes
from docutils.parsers.rst import directives
from docutils.statemachine import StringList
from generated_pages import write_if_changed
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "benchmarks" / "results"
OUT_DIR = Path("benchmarks") / "reports"

_COMMAND = re.compile(
    r"((?:[A-Z_]+=\S+ )*python3? (?:-m benchmarks\.\w+|benchmarks/\w+\.py)[^`\n(]*)")
_COMMIT = re.compile(r"\bcommit ([0-9a-f]{7,40})\b")
_DATE = re.compile(r"\b(20\d\d-\d\d-\d\d)(?:[ ,T]+(\d\d:\d\d)(?: UTC)?)?")
_LOAD = re.compile(r"(?i:load average)(?: \(1 min\))?[^\d\n]{0,30}?"
                   r"(\d+(?:\.\d+)?(?:(?: ?(?:-|->|to) ?| )\d+(?:\.\d+)?)*)")
_MACHINE = re.compile(r"^\s*-?\s*machine: ([^\n]+)", re.MULTILINE)
_HEADING = re.compile(r"^(#{1,6}) +(.+?)\s*$", re.MULTILINE)


def _opening(text: str) -> str:
    """The part of a report that says how it was made: the text before its first section,
    or with the first section (reports that put their latest run first) when that text
    says nothing of it."""
    body = _without_fences(text)
    sections = [m.start() for m in re.finditer(r"^## ", body, re.MULTILINE)]
    head = body[: sections[0]] if sections else body
    if sections and not (_COMMIT.search(head) or _LOAD.search(head) or _DATE.search(head)):
        return body[: sections[1]] if len(sections) > 1 else body
    return head


def _first_current(pattern: re.Pattern[str], text: str) -> re.Match[str] | None:
    """The first match outside tables (rows of several runs) and not in a sentence about
    an earlier version ("Before (commit ...")."""
    for m in pattern.finditer(text):
        if text[text.rfind("\n", 0, m.start()) + 1:].startswith("|"):
            continue
        sentence = re.split(r"(?:[.;]\s|\n\n|^- )", text[: m.start()])[-1].lower()
        if not any(word in sentence for word in ("before", "earlier", "parent")):
            return m
    return None


def report_metadata(text: str) -> dict[str, str]:
    """What a report's opening says of how it was made, each where it says it."""
    meta: dict[str, str] = {}
    opening = _opening(text)
    if m := _COMMAND.search(text):
        meta["command"] = m.group(1).strip()
    if m := _first_current(_COMMIT, opening):
        meta["commit"] = m.group(1)
    if m := _first_current(_DATE, opening):
        meta["date"] = m.group(1) + (f" {m.group(2)}" if m.group(2) else "")
    if m := _first_current(_LOAD, opening):
        meta["load average"] = m.group(1).strip()
    if m := _MACHINE.search(opening):
        meta["machine"] = m.group(1).strip()
    return meta


def _title(text: str, fallback: str) -> str:
    m = _HEADING.search(text)
    return m.group(2).strip() if m else fallback


def _top_level(text: str) -> int:
    levels = [len(m.group(1)) for m in _HEADING.finditer(_without_fences(text))]
    return min(levels) if levels else 1


def _without_fences(text: str) -> str:
    return re.sub(r"^```.*?^```", "", text, flags=re.MULTILINE | re.DOTALL)


def _report_page(path: Path) -> str:
    """The page of one report: its metadata, then the report below the page's title."""
    text = path.read_text(encoding="utf-8")
    meta = report_metadata(text)
    include = "../" * (len(OUT_DIR.parts) + 1) + path.relative_to(ROOT).as_posix()
    lines = [f"# {_title(text, path.name)}", "",
             f"*The report `benchmarks/results/{path.name}`, as its command wrote it.*", ""]
    if meta:
        lines += ["| how it was made | |", "| --- | --- |"]
        lines += [f"| {key} | {_cell(value)} |" for key, value in meta.items()]
        lines.append("")
    lines.append(f"```{{include}} {include}")
    first = _HEADING.search(_without_fences(text))
    if first and len(first.group(1)) == 1:
        # the report's title is the page's; its sections stay under it
        lines.append(f":start-line: {text[:first.end()].count(chr(10)) + 1}")
    lines += ["```", ""]
    return "\n".join(lines)


def _cell(value: str) -> str:
    return "`" + value.replace("`", "") + "`" if value.startswith(("python", "OPENBLAS")) \
        else value.replace("|", "\\|")



def generate(app: Sphinx) -> None:
    out = Path(app.srcdir) / OUT_DIR
    wanted = {p.stem for p in RESULTS.glob("*.md")}
    for old in out.glob("*.md") if out.exists() else []:
        if old.stem not in wanted:
            old.unlink()
    for path in sorted(RESULTS.glob("*.md")):
        write_if_changed(out / f"{path.stem}.md", _report_page(path))
    app.env.find_files(app.config, app.builder)


# -- tables --------------------------------------------------------------------------


def _table(headers: list[str], rows: list[list[Any]], caption: str | None = None,
           widths: list[int] | None = None) -> nodes.table:
    table = nodes.table(classes=["generated-table"])
    if caption:
        table += nodes.title(caption, caption)
    group = nodes.tgroup(cols=len(headers))
    table += group
    for width in widths or [1] * len(headers):
        group += nodes.colspec(colwidth=width)
    head = nodes.thead()
    group += head
    head += _row(headers)
    body = nodes.tbody()
    group += body
    for row in rows:
        body += _row(row)
    return table


def _row(cells: list[Any]) -> nodes.row:
    row = nodes.row()
    for cell in cells:
        entry = nodes.entry()
        if isinstance(cell, nodes.Node):
            entry += nodes.paragraph("", "", cell)
        else:
            entry += nodes.paragraph(text=str(cell))
        row += entry
    return row


def _sci(value: float | None) -> str:
    if value is None:
        return "-"
    return "0" if value == 0 else f"{value:.1e}"


class _ResultsDirective(SphinxDirective):
    """A table made from a file of ``benchmarks/results/``, rebuilt when it changes."""

    has_content = False
    option_spec = {"file": directives.unchanged}
    default_file = ""

    def load(self) -> Any:
        path = RESULTS / self.options.get("file", self.default_file)
        self.env.note_dependency(str(path))
        return json.loads(path.read_text(encoding="utf-8"))

    def source_note(self) -> nodes.paragraph:
        name = self.options.get("file", self.default_file)
        para = nodes.paragraph()
        para += nodes.Text("From ")
        para += nodes.literal(text=f"benchmarks/results/{name}")
        meta = _metadata_of(RESULTS / (Path(name).stem + ".md"))
        if meta:
            parts = [f"{key} {value}" for key, value in meta.items()
                     if key in ("commit", "date", "load average")]
            para += nodes.Text(" (" + "; ".join(parts) + ", as its report "
                               f"{Path(name).stem}.md says)" if parts else "")
        if "command" in meta:
            para += nodes.Text(", made by ")
            para += nodes.literal(text=meta["command"])
        para += nodes.Text(".")
        return para


def _metadata_of(path: Path) -> dict[str, str]:
    return report_metadata(path.read_text(encoding="utf-8")) if path.exists() else {}


class EngineAccuracy(_ResultsDirective):
    """Per scene and ``tol``: the measured error / the estimate (a failed solve marked)."""

    default_file = "engines.json"

    def run(self) -> list[nodes.Node]:
        data = self.load()
        tols = sorted({run["tol"] for scene in data["scenes"] for run in scene["runs"]
                       if run["method"] == "nystrom"}, reverse=True)
        rows = []
        for scene in data["scenes"]:
            cells = dict.fromkeys(tols, "-")
            for run in scene["runs"]:
                if run["method"] == "nystrom":
                    mark = "" if run["success"] else " (failed)"
                    cells[run["tol"]] = f"{_sci(run['error'])} / {_sci(run['estimate'])}{mark}"
            rows.append([scene["title"]] + [cells[tol] for tol in tols])
        headers = ["scene"] + [f"tol {tol:.0e}" for tol in tols]
        return [self.source_note(), _table(headers, rows, widths=[3] + [2] * len(tols))]


class ReferenceAgreement(_ResultsDirective):
    default_file = "work_precision.json"

    def run(self) -> list[nodes.Node]:
        data = self.load()
        quantities = ["settlement", "tilt", "force", "moment", "pressure"]
        rows = []
        for key, scene in data.items():
            reference = scene.get("reference") if isinstance(scene, dict) else None
            if not reference:
                continue
            agreement = reference.get("agreement", {})
            rows.append([key, scene.get("description", ""), reference.get("how", "")]
                        + [_sci(agreement.get(q)) for q in quantities])
        headers = ["scene", "problem", "reference"] + quantities
        return [self.source_note(), _table(headers, rows, widths=[2, 6, 4, 1, 1, 1, 1, 1])]


class EngineGoals(_ResultsDirective):
    default_file = "engines.json"

    def run(self) -> list[nodes.Node]:
        goals = self.load()["goals"]
        rows = []
        for key, value in goals.items():
            unit = "ms" if key.endswith("_ms") else "s" if key.endswith("_s") else ""
            rows.append([key.replace("_", " ").removesuffix(f" {unit}"), unit,
                         f"{value:.3g}"])
        return [self.source_note(), _table(["measured", "unit", "value"], rows)]


class ReportIndex(SphinxDirective):
    has_content = False

    def run(self) -> list[nodes.Node]:
        rows = []
        for path in sorted(RESULTS.iterdir()):
            if path.name.startswith("."):
                continue
            self.env.note_dependency(str(path))
            meta: dict[str, str] = {}
            if path.suffix == ".md":
                text = path.read_text(encoding="utf-8")
                meta = report_metadata(text)
                title: nodes.Node | str = _page_link(self.env.docname, path.stem,
                                                     _title(text, path.name))
            elif path.suffix in (".json", ".csv"):
                meta = _metadata_of(path.with_suffix(".md"))
                title = f"data of {path.stem}.md"
            else:
                continue  # figures are shown by their reports
            rows.append([nodes.literal(text=path.name), title, meta.get("commit", "-"),
                         meta.get("date", "-"), meta.get("load average", "-"),
                         nodes.literal(text=meta["command"]) if "command" in meta else "-"])
        headers = ["file", "what", "commit", "date", "load average", "command"]
        return [_table(headers, rows, widths=[3, 5, 2, 2, 2, 6])]


class ReportSection(SphinxDirective):
    required_arguments = 1
    has_content = True

    def run(self) -> list[nodes.Node]:
        path = RESULTS / self.arguments[0]
        self.env.note_dependency(str(path))
        text = path.read_text(encoding="utf-8")
        heading = " ".join(self.content).strip()
        lines = text.splitlines()
        start = level = None
        for i, line in enumerate(lines):
            m = _HEADING.match(line)
            if m and m.group(2).strip() == heading:
                start, level = i + 1, len(m.group(1))
                break
        if start is None or level is None:
            raise self.error(f"{self.arguments[0]} has no heading {heading!r}")
        end = len(lines)
        for i in range(start, len(lines)):
            m = _HEADING.match(lines[i])
            if m and len(m.group(1)) <= level:
                end = i
                break
        note = nodes.paragraph()
        note += nodes.Text("From ")
        note += _page_link(self.env.docname, path.stem, f"benchmarks/results/{path.name}")
        note += nodes.Text(f", section \u201c{heading}\u201d:")
        container = nodes.container(classes=["report-section"])
        self.state.nested_parse(StringList(lines[start:end], str(path)), 0, container)
        return [note, container]


def _page_link(from_doc: str, stem: str, text: str) -> nodes.Node:
    from sphinx.addnodes import pending_xref

    ref = pending_xref("", refdomain="std", reftype="doc",
                       reftarget=f"/{OUT_DIR.as_posix()}/{stem}", refexplicit=True,
                       refdoc=from_doc)
    ref += nodes.inline(text=text)
    return ref


def setup(app: Sphinx) -> dict[str, Any]:
    app.connect("builder-inited", generate, priority=400)
    app.add_directive("report-index", ReportIndex)
    app.add_directive("engine-accuracy", EngineAccuracy)
    app.add_directive("reference-agreement", ReferenceAgreement)
    app.add_directive("engine-goals", EngineGoals)
    app.add_directive("report-section", ReportSection)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
