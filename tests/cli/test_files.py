"""The command line's files (core/files.py): it never overwrites its own input or a
read-only file, never writes two outputs to one path, writes through symbolic links and
refuses files that are not regular (a named pipe would block a read forever)."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from core.cli import main
from core.scene import load_scene, save_scene
from tests.conftest import write_scene

ROOT = Path(__file__).resolve().parents[2]


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


def test_cli_refuses_an_output_in_a_missing_folder_before_solving(tmp_path: Path, capsys,
                                                                   monkeypatch):
    """The folder was found missing only after the solve (12-14 s of a creeping scene,
    then "cannot write"): the check runs before it, for every command's outputs."""
    import core.cli

    scene = write_scene(tmp_path / "scene.json")
    solved: list[object] = []
    monkeypatch.setattr(core.cli, "solve", lambda *a, **k: solved.append(a))
    missing = tmp_path / "nofolder" / "x.json"
    assert main(["solve", str(scene), "--output", str(missing)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --output:") and "the folder" in err and "does not exist" in err
    assert main(["report", str(scene), "--output", str(tmp_path / "none" / "r.html")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not solved and not missing.parent.exists()
    with pytest.raises(ValueError, match="does not exist"):
        save_scene(load_scene(scene), missing)


def test_cli_writes_through_a_symlink(tmp_path: Path):
    scene = write_scene(tmp_path / "scene.json")
    target = tmp_path / "data" / "result.csv"
    target.parent.mkdir()
    target.write_text("old\n")
    link = tmp_path / "result.csv"
    link.symlink_to(target)
    assert main(["solve", str(scene), "--output", str(link)]) == 0
    assert link.is_symlink()  # still a link, not replaced by a regular file
    assert target.read_text().startswith("# coated-punch ")
    assert "\ntime_day," in target.read_text()


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
