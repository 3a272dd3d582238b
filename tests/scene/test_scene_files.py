"""Saving a scene writes the whole file or nothing (a failed write, a failed flush, a failed
rename, a process killed before the rename); an invalid scene is never saved; files of
older and newer schema versions are migrated or explained."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

import core.scene.schema as scene_schema
from core.scene import load_scene, save_scene, scene_from_dict
from core.scene.files import parse_scene_json
from core.scene.schema import migrate
from tests.conftest import base_scene, edited

ROOT = Path(__file__).resolve().parents[2]


def test_save_scene_writes_a_complete_file(tmp_path: Path) -> None:
    path = tmp_path / "scene.json"
    save_scene(base_scene(), path)
    assert load_scene(path) == scene_from_dict(base_scene())
    assert json.loads(path.read_text())["schema_version"] == 1
    assert [p.name for p in tmp_path.iterdir()] == ["scene.json"]


def _old_file(tmp_path: Path) -> tuple[Path, bytes]:
    path = tmp_path / "scene.json"
    save_scene(edited("name", "the old scene"), path)
    os.chmod(path, 0o640)
    return path, path.read_bytes()


@pytest.mark.parametrize("failure", ["write", "fsync", "replace"])
def test_a_failed_save_leaves_the_old_file_intact(tmp_path: Path, monkeypatch,
                                                  failure: str) -> None:
    path, old = _old_file(tmp_path)
    if failure == "write":
        real_fdopen = os.fdopen

        class HalfWriter:
            """Writes half of the text, then the disk is full."""

            def __init__(self, fh: Any) -> None:
                self.fh = fh

            def __enter__(self) -> HalfWriter:
                return self

            def __exit__(self, *exc: Any) -> None:
                self.fh.close()

            def write(self, text: str) -> int:
                self.fh.write(text[: len(text) // 2])
                self.fh.flush()
                raise OSError(28, "No space left on device")

        monkeypatch.setattr(os, "fdopen", lambda *a, **k: HalfWriter(real_fdopen(*a, **k)))
    elif failure == "fsync":
        def fsync(fd: int) -> None:
            raise OSError(5, "Input/output error")

        monkeypatch.setattr(os, "fsync", fsync)
    else:
        def replace(src: Any, dst: Any) -> None:
            raise OSError(13, "Permission denied")

        monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(OSError):
        save_scene(edited("name", "the new scene"), path)
    monkeypatch.undo()
    assert path.read_bytes() == old
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    # the temporary file is gone too
    assert [p.name for p in tmp_path.iterdir()] == ["scene.json"]


def test_a_process_killed_during_a_save_leaves_the_old_file_intact(tmp_path: Path) -> None:
    """The process dies after writing the new text and before the rename (power cut)."""
    path, old = _old_file(tmp_path)
    script = textwrap.dedent(f"""
        import json, os, sys
        sys.path.insert(0, {str(ROOT)!r})
        from core.scene import save_scene
        scene = json.loads({json.dumps(json.dumps(edited("name", "the new scene")))})
        os.replace = lambda src, dst: os._exit(9)
        save_scene(scene, {str(path)!r})
    """)
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, timeout=120,
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert proc.returncode == 9, proc.stderr
    assert path.read_bytes() == old
    assert load_scene(path).name == "the old scene"
    # the complete new text is left in a hidden temporary file beside it
    leftovers = [p for p in tmp_path.iterdir() if p.name != "scene.json"]
    assert len(leftovers) == 1 and leftovers[0].name.startswith(".scene.json.")
    assert json.loads(leftovers[0].read_text())["name"] == "the new scene"


def test_an_invalid_scene_is_never_saved(tmp_path: Path) -> None:
    path, old = _old_file(tmp_path)
    with pytest.raises(ValueError, match=r"^coating\[0\]\.thickness: must be > 0"):
        save_scene(edited("coating[0].thickness", -1.0), path)
    assert path.read_bytes() == old


def test_older_and_newer_schema_versions_are_migrated_or_explained(monkeypatch) -> None:
    with pytest.raises(ValueError, match=r"^schema_version: version 0 does not exist \(the "
                                         r"first version of the schema is 1"):
        scene_from_dict(edited("schema_version", 0))
    with pytest.raises(ValueError, match=r"^schema_version: unsupported version 3 \(this "
                                         r"program reads 1\)"):
        parse_scene_json(json.dumps(edited("schema_version", 3)))
    with pytest.raises(ValueError, match=r"^schema_version: must be an integer, got 1\.5"):
        scene_from_dict(edited("schema_version", 1.5))
    # the migration chain: a program reading version 2 brings a version 1 file forward
    # step by step, without changing the caller's dict
    monkeypatch.setattr(scene_schema, "SCHEMA_VERSION", 2)

    def one_to_two(d: dict[str, Any]) -> dict[str, Any]:
        out = dict(d)
        out["title"] = out.pop("name")
        return out

    monkeypatch.setitem(scene_schema._MIGRATIONS, 1, one_to_two)
    old = base_scene()
    new = migrate(old)
    assert new["schema_version"] == 2 and new["title"] == old["name"] and "name" not in new
    assert old["schema_version"] == 1 and "name" in old
