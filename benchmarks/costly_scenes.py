"""Time and peak memory of the costliest scenes a user can write, each solved in a fresh process.

    python benchmarks/costly_scenes.py              # all cases
    python benchmarks/costly_scenes.py nested simple

Cases: ``nested`` (a creep kernel as a nested formula, 2000 output times, tol 1e-6),
``simple`` (a plain kernel formula, 2000 output times, tol 1e-2), ``sine-0.5`` and
``sine-0.35`` (a sine force of period 0.5 or 0.35 day over a year on the uniform preset,
tol 1e-6: just under and just over the time stepper's step limit). Each line: the case,
wall seconds, the peak resident memory of its process [MB] and the outcome.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

_CHILD = """
import json, resource, sys, time
sys.path.insert(0, {root!r})
from core.scene.pipeline import scene_from_dict, solve
d = json.loads({scene!r})
t0 = time.perf_counter()
try:
    r = solve(scene_from_dict(d))
    outcome = f"solved, {{r.info['n_steps']}} steps: {{r.info['message'][:120]}}"
except ValueError as exc:
    outcome = f"refused: {{str(exc)[:160]}}"
seconds = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps([seconds, peak, outcome]))
"""


def _scene(case: str) -> dict:
    d = json.loads((ROOT / "core" / "presets" / "scenes" / "uniform_flat.json").read_text())
    if case in ("nested", "simple"):
        expr = "-0.01*exp(-0.03*(t-tau))"
        if case == "nested":
            e = "exp(-0.03*(t-tau))"
            for k in range(8):
                e = f"(0.5+0.5*{e})*(1+0*(t-tau+{k}))"
            expr = f"-0.01*{e}"
        d["base"]["creep"] = {"model": "kernel", "modulus": 3e10, "expr": expr}
        d["times"] = {"end": 365.0, "count": 2000}
        d["solver"] = {"tol": 1e-6 if case == "nested" else 1e-2}
    else:
        d["loading"]["force"] = {"kind": "sine", "mean": 5e5, "amplitude": 2e5,
                                 "wavelength": float(case.split("-")[1])}
    return d


def main(cases: list[str]) -> None:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    for case in cases:
        code = _CHILD.format(root=str(ROOT), scene=json.dumps(_scene(case)))
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              env=env, timeout=600)
        if proc.returncode:
            print(f"{case}: failed: {proc.stderr[-300:]}")
            continue
        seconds, peak, outcome = json.loads(proc.stdout.splitlines()[-1])
        print(f"{case:10s} {seconds:7.1f} s {peak:7.0f} MB  {outcome}")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    from benchmarks import help_requested

    help_requested(__doc__)
    main(sys.argv[1:] or ["nested", "simple", "sine-0.5", "sine-0.35"])
