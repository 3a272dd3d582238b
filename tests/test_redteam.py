"""Findings of a red-team pass (issue 19), each reproduced by a test before its fix.

Bounded work (limits checked before the work), files (the CLI never overwrites its own
input or a read-only file, writes through symlinks, refuses non-regular files), text
fields bounded in length, load histories that vary too fast for the time stepper, the
times where a history jumps, and refusals that name the scene field.
"""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from core import limits
from core.cli import main
from core.scene import load_scene, save_scene, scene_from_dict

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "assets" / "scenes"


def scene_dict() -> dict:
    return json.loads((SCENES / "uniform_flat.json").read_text())


def elastic_dict(**changes) -> dict:
    """The uniform preset on an elastic base, few times: a solve of ~0.1 s."""
    d = scene_dict()
    d["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    d["times"] = {"end": 10.0, "count": 3}
    d.update(changes)
    return d


def write_scene(path: Path, d: dict | None = None) -> Path:
    path.write_text(json.dumps(d or elastic_dict()))
    return path


# ------------------------------------------------------------------------ item 8: files


def test_cli_refuses_to_overwrite_its_input(tmp_path: Path, capsys):
    scene = write_scene(tmp_path / "scene.json")
    before = scene.read_text()
    assert main(["solve", str(scene), "--output", str(scene)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --output:") and "scene file" in err
    assert scene.read_text() == before
    # also through another spelling of the same path, and through a link to it
    other = tmp_path / "sub" / ".." / "scene.json"
    (tmp_path / "sub").mkdir()
    assert main(["solve", str(scene), "--pressure-csv", str(other)]) == 2
    link = tmp_path / "link.json"
    link.symlink_to(scene)
    assert main(["solve", str(link), "--output", str(scene)]) == 2
    assert scene.read_text() == before


def test_cli_refuses_two_outputs_to_one_path(tmp_path: Path, capsys):
    scene = write_scene(tmp_path / "scene.json")
    out = tmp_path / "out.csv"
    assert main(["solve", str(scene), "--output", str(out), "--pressure-csv", str(out)]) == 2
    assert "--pressure-csv" in capsys.readouterr().err
    assert not out.exists()


def test_cli_respects_a_read_only_output(tmp_path: Path, capsys):
    scene = write_scene(tmp_path / "scene.json")
    out = tmp_path / "result.csv"
    out.write_text("keep me\n")
    out.chmod(0o444)
    assert main(["solve", str(scene), "--output", str(out)]) == 2
    assert "read-only" in capsys.readouterr().err
    assert out.read_text() == "keep me\n"
    # save_scene too (the explorer's and the library's save)
    with pytest.raises(ValueError, match="read-only"):
        save_scene(load_scene(scene), out)
    assert out.read_text() == "keep me\n"


def test_cli_writes_through_a_symlink(tmp_path: Path):
    scene = write_scene(tmp_path / "scene.json")
    target = tmp_path / "data" / "result.csv"
    target.parent.mkdir()
    target.write_text("old\n")
    link = tmp_path / "result.csv"
    link.symlink_to(target)
    assert main(["solve", str(scene), "--output", str(link)]) == 0
    assert link.is_symlink()  # still a link, not replaced by a regular file
    assert target.read_text().startswith("time_day,")


def test_cli_refuses_non_regular_files(tmp_path: Path):
    """A named pipe as the scene file used to wait forever for a writer."""
    fifo = tmp_path / "scene.json"
    os.mkfifo(fifo)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    for command in (["validate", str(fifo)], ["solve", str(fifo)]):
        proc = subprocess.run([sys.executable, "-m", "core", *command], cwd=ROOT, env=env,
                              capture_output=True, text=True, timeout=60)
        assert proc.returncode == 2
        assert "not a regular file" in proc.stderr
    scene = write_scene(tmp_path / "ok.json")
    with pytest.raises(ValueError, match="not a regular file"):
        load_scene(tmp_path)  # a directory
    out_fifo = tmp_path / "out.csv"
    os.mkfifo(out_fifo)
    assert main(["solve", str(scene), "--output", str(out_fifo)]) == 2
    assert stat.S_ISFIFO(os.lstat(out_fifo).st_mode)


# ------------------------------------------------------------------- item 6: text fields


@pytest.mark.parametrize("field, limit", [("name", limits.MAX_NAME_CHARS),
                                          ("description", limits.MAX_DESCRIPTION_CHARS)])
def test_text_fields_are_bounded(field: str, limit: int, tmp_path: Path):
    scene_from_dict(elastic_dict(**{field: "x" * limit}))
    long = elastic_dict(**{field: "x" * 15_000_000})
    with pytest.raises(ValueError, match=rf"^{field}: .*at most {limit} characters"):
        scene_from_dict(long)
    # the same refusal from a file and from the JSON text of a link
    with pytest.raises(ValueError, match=rf"^{field}: "):
        load_scene(write_scene(tmp_path / "long.json", elastic_dict(**{field: "y" * (
            limit + 1)})))
