"""The README's Python examples run as a user runs them: each block as a plain script,
from a folder outside the checkout (a study example without its ``__main__`` guard
crashed in Dask's worker processes)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), flags=re.S)


def test_the_readme_has_its_examples():
    assert len(BLOCKS) >= 3


@pytest.mark.slow
@pytest.mark.parametrize("k", range(len(BLOCKS)))
def test_each_readme_example_runs_as_a_script(k: int, tmp_path: Path):
    script = tmp_path / "example.py"
    script.write_text(BLOCKS[k])
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    # the study example runs 20 points on a local cluster: ~9 s measured on 2 cores
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    assert "Traceback" not in run.stderr
