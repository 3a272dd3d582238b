"""The Python examples of the documentation run as written: each block of the guides, the
getting-started page, the method and the scene format, on its own, in an empty folder
(a new user's audit found blocks using ``core`` without importing it, a placeholder call
``solve_dimensionless(..., method="projection")``, and names never defined).

The blocks run in this process (their imports are then paid once), each in a fresh
namespace named ``__main__``. A block reading the user's own files (``scene.json``,
``readings.csv``) finds such files in its folder. Not run here: a block marked
``<!-- a sketch of the interface, not a script -->`` just above it, and the blocks that
run a design study on a local cluster (~40 s each; the README's study example runs as a
script in tests/test_readme.py, and they were run by hand as written): those are compiled,
and every name they use must be imported or defined in them.
"""

from __future__ import annotations

import copy
import json
import os
import re
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "docs" / "getting_started.md", ROOT / "docs" / "guide.md",
         ROOT / "docs" / "method.md", ROOT / "core" / "SCENES.md",
         *sorted((ROOT / "docs" / "guides").glob("*.md"))]
#: The comment that keeps a block out (a sketch, not a script).
SKETCH = "<!-- a sketch of the interface, not a script -->"


def _blocks() -> list[tuple[str, str, str]]:
    """(id, code, why not run or '') of every Python block of :data:`PAGES`."""
    found = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for match in re.finditer(r"^( *)```python\n(.*?)^ *```", text, flags=re.S | re.M):
            line = text[:match.start()].count("\n") + 1
            before = text[:match.start()].rstrip().rsplit("\n", 1)[-1].strip()
            code = textwrap.dedent(match.group(2))
            why = ("a sketch" if before == SKETCH else
                   "a design study on a local cluster" if "core.sweep(" in code else "")
            found.append((f"{page.relative_to(ROOT)}:{line}", code, why))
    return found


BLOCKS = _blocks()
#: The blocks run here.
RUN = [(name, code) for name, code, why in BLOCKS if not why]


def test_the_pages_have_their_examples():
    assert len(BLOCKS) >= 15, [b[0] for b in BLOCKS]
    assert len(RUN) >= 12
    # left out: one sketch (the method's kernel interface) and the studies on a cluster
    assert sorted(why for _, _, why in BLOCKS if why) == [
        "a design study on a local cluster"] * 3 + ["a sketch"]
    # those on a cluster are Python at least, and name only what they import or define
    # (a block used study_dict and my_dask_client, defined nowhere)
    import builtins
    import symtable

    for name, code, why in BLOCKS:
        if why != "a design study on a local cluster":
            continue
        table = symtable.symtable(code, name, "exec")
        bound = {s.get_name() for s in table.get_symbols() if s.is_assigned()
                 or s.is_imported()} | set(dir(builtins))
        used = {s.get_name() for s in table.get_symbols() if s.is_referenced()}
        assert used <= bound, (name, used - bound)


def _users_files(folder: Path) -> None:
    """A scene file and a levelling record of it, where a block reads the user's own: the
    young-concrete preset (a design code's creep law, whose humidity and age at loading
    the back-analysis guide fits) and its settlements at 30 % humidity, to four digits."""
    import core
    from core.presets import read_preset

    scene = read_preset("young_concrete_50_years")
    (folder / "scene.json").write_text(json.dumps(scene))
    truth = copy.deepcopy(scene)
    truth["base"]["creep"]["relative_humidity"] = 50.0
    truth["times"] = [30.0, 100.0, 300.0, 1000.0]
    settlement = core.solve(truth).settlement
    rows = "".join(f"{t:g}, {1e3 * s:.4g}\n" for t, s in zip(truth["times"], settlement,
                                                            strict=True))
    (folder / "readings.csv").write_text("time [day], settlement [mm]\n" + rows)


@pytest.mark.parametrize("code", [code for _, code in RUN], ids=[name for name, _ in RUN])
def test_each_example_runs_as_written(code: str, tmp_path: Path,
                                      monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    if "scene.json" in code or "readings.csv" in code:
        _users_files(tmp_path)
    compiled = compile(code, "<example>", "exec")
    exec(compiled, {"__name__": "__main__"})  # noqa: S102 (the project's own docs)
    assert os.getcwd() == str(tmp_path)
