"""A run of the command line bounds its own memory (core.limits.MAX_RUN_MEMORY_BYTES,
``--max-memory``): a punch touching at 200 crests under creep took a run to 3.8 GiB
before its CPU bound stopped it, where no memory bound was stated."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from core.cli import EXIT_BAD_INPUT, EXIT_SOLVER_FAILED
from tests.cli_runs import run_cli
from tests.conftest import scene_file


def _wavy_lift_off(tmp_path: Path) -> Path:
    """The lift-off preset under a 10 um wave of 10 mm: 34-51 contact zones under creep,
    ~1 GiB resident at its peak (measured)."""
    d = scene_file("eccentric_footing_liftoff")
    d["punch"]["shape"] = {"kind": "sine", "mean": 0.0, "amplitude": 1e-5,
                           "wavelength": 0.01, "phase": 0.0}
    path = tmp_path / "wavy.json"
    path.write_text(json.dumps(d))
    return path


@pytest.mark.slow
def test_a_run_past_its_memory_bound_stops_saying_which_and_how_to_raise_it(
        tmp_path: Path) -> None:
    """Bounded to 0.5 GiB (0.75 GiB with two cores' share), the run stops within seconds
    with one line naming the bound."""
    done = run_cli("solve", _wavy_lift_off(tmp_path), "--max-memory", "0.5", "-o",
                   tmp_path / "out.json", subprocess=True, timeout=120)
    assert done.returncode == EXIT_SOLVER_FAILED, done.stderr
    assert done.stderr.startswith("error: solve: needed more than the "), done.stderr
    # the bound from the value given and the cores' share, both said (it read "the 0.75
    # GiB" beside a --max-memory of 0.5, unexplained)
    cores = os.cpu_count() or 1
    assert (f"the {0.5 + cores * 0.125:.3g} GiB of memory this run may take (--max-memory "
            f"0.5 GiB plus 128 MiB for each of the {cores} cores; --max-memory GIB raises "
            "it, default 4)") in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
    assert not (tmp_path / "out.json").exists()


def test_the_bound_is_a_number_of_gibibytes_a_run_can_start_in() -> None:
    """0.001 GiB left the BLAS library retrying its work buffer forever (10 minutes at
    full CPU, found by a review): the least bound is 0.5 GiB."""
    for bad in ("0", "-1", "0.001", "0.49", "nan", "inf", "lots"):
        done = run_cli("solve", "preset:uniform_flat", "--max-memory", bad)
        assert done.returncode == EXIT_BAD_INPUT
        assert "--max-memory: must be a number of GiB >= 0.5" in done.stderr, done.stderr


def test_a_run_called_from_python_leaves_its_caller_unbounded() -> None:
    """``core.cli.main(argv)`` in a caller's process (a notebook, these tests) sets no
    bound on that process: only a run as a program does."""
    import resource

    before = resource.getrlimit(resource.RLIMIT_AS)
    done = run_cli("solve", "preset:uniform_flat", "--max-memory", "0.6")
    assert done.returncode == 0, done.stderr
    assert resource.getrlimit(resource.RLIMIT_AS) == before


@pytest.mark.slow
def test_a_bound_set_outside_is_not_explained_as_the_options(tmp_path: Path) -> None:
    """Under a hard address-space limit set outside (ulimit -Hv, a container) lower than
    --max-memory asks, the message explained the bound as "--max-memory X GiB plus ..."
    and said the option raises it (a review); it now names the outside limit."""
    import resource
    import subprocess
    import sys

    from tests.cli_runs import ROOT

    hard = int(0.75 * 2**30)

    def lower_the_hard_limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (hard, hard))

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT))
    done = subprocess.run([sys.executable, "-m", "core", "solve", str(_wavy_lift_off(tmp_path)),
                           "--max-memory", "2", "-o", str(tmp_path / "out.json")],
                          env=env, capture_output=True, text=True, timeout=120,
                          preexec_fn=lower_the_hard_limit)
    assert done.returncode == EXIT_SOLVER_FAILED, done.stderr
    assert "the 0.75 GiB of memory this run may take (the hard limit of this process's " \
           "address space, set outside this program" in done.stderr, done.stderr
    assert "--max-memory GIB raises it" not in done.stderr
