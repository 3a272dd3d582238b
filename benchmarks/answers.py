"""Record or compare the solver's answers bit for bit (a guard for code moves).

``python -m benchmarks.answers save FILE`` solves every benchmark scene (both engines,
two tolerances, and lift-off where the loads allow it) and every preset scene, and
stores every number of the answers (pressure on a fixed grid, settlement, tilt, force,
moment, the error estimates and flags) in ``FILE`` (``.npz``).
``python -m benchmarks.answers compare FILE`` solves again and reports every array that
differs by a single bit; it exits 1 if any does. A move of code that changes no numerics
must compare equal; a change of numerics shows here what it changed.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

import core
from tests.support.scenes import suite

PRESETS = Path(__file__).resolve().parent.parent / "core" / "presets" / "scenes"
X = np.linspace(-1.0, 1.0, 41)


#: Keys of ``info`` that measure the run (times, cache hits), not the answer.
RUN_KEYS = ("seconds", "cached", "builds", "stages")
#: Top-level keys of a solution's JSON that record what made the file (the program, its
#: version, the solver's settings), not the answer: a new version changes them alone.
RECORD_KEYS = ("program", "version", "solver")


def _answer_only(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _answer_only(v) for k, v in value.items()
                if not any(word in k for word in RUN_KEYS)}
    if isinstance(value, list):
        return [_answer_only(v) for v in value]
    return value


def _numbers(prefix: str, info: dict[str, Any], out: dict[str, np.ndarray]) -> None:
    for key, value in sorted(_answer_only(info).items()):
        if isinstance(value, bool | int | float | np.number | np.bool_):
            out[f"{prefix}.info.{key}"] = np.asarray(value, dtype=float)
        elif isinstance(value, str):
            out[f"{prefix}.info.{key}"] = np.asarray(value)
        elif isinstance(value, list | tuple) and all(isinstance(v, str) for v in value):
            out[f"{prefix}.info.{key}"] = np.asarray(json.dumps(list(value)))


def _dimensionless(out: dict[str, np.ndarray]) -> None:
    for scene in suite():
        args = scene.arguments()
        for method in ("nystrom", "projection"):
            for tol in (1e-4, 1e-7):
                key = f"{scene.key}.{method}.{tol:g}"
                sol = core.solve_dimensionless(scene.lam, scene.m, scene.g, scene.times,
                                               tol=tol, method=method, **args)
                _solution(key, sol, out)


def _solution(key: str, sol: Any, out: dict[str, np.ndarray]) -> None:
    for name in ("times", "settlement", "tilt", "force", "moment"):
        out[f"{key}.{name}"] = np.asarray(getattr(sol, name), dtype=float)
    out[f"{key}.q"] = np.asarray(sol.pressure(X), dtype=float)
    out[f"{key}.success"] = np.asarray(float(sol.success))
    out[f"{key}.flags"] = np.asarray(json.dumps(list(sol.flags)))
    out[f"{key}.contact_set"] = np.asarray(json.dumps(sol.contact_set))
    _numbers(key, sol.info, out)


def _presets(out: dict[str, np.ndarray]) -> None:
    for path in sorted(PRESETS.glob("*.json")):
        scene = core.load_scene(path)
        for tol in (None, 1e-7):
            if tol is not None:
                data = json.loads(path.read_text())
                data.setdefault("solver", {})["tol"] = tol
                scene = data  # core.solve reads either form (one punch or several)
            key = f"preset.{path.stem}.{tol}"
            result = core.solve(scene)
            document = json.loads(result.to_json())
            for name in RECORD_KEYS:
                document.pop(name, None)
            out[f"{key}.json"] = np.asarray(json.dumps(_answer_only(document)))
            out[f"{key}.csv"] = np.asarray(result.to_csv(header=False))
            out[f"{key}.q"] = np.asarray(result.pressure_on_grid, dtype=float)


def collect() -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    _dimensionless(out)
    _presets(out)
    return out


def compare(saved: dict[str, np.ndarray], now: dict[str, np.ndarray]) -> list[str]:
    problems = [f"missing now: {k}" for k in sorted(set(saved) - set(now))]
    problems += [f"new: {k}" for k in sorted(set(now) - set(saved))]
    for key in sorted(set(saved) & set(now)):
        a, b = saved[key], now[key]
        if a.shape != b.shape or a.dtype.kind != b.dtype.kind:
            problems.append(f"{key}: shape/type {a.shape}/{a.dtype} -> {b.shape}/{b.dtype}")
        elif a.dtype.kind == "f":
            if not np.array_equal(a.view(np.uint64) if a.dtype == np.float64 else a,
                                  b.view(np.uint64) if b.dtype == np.float64 else b):
                diff = np.nanmax(np.abs(a - b)) if a.size else 0.0
                problems.append(f"{key}: differs (max |diff| {diff:.3e})")
        elif not np.array_equal(a, b):
            problems.append(f"{key}: differs")
    return problems


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("action", choices=("save", "compare"))
    parser.add_argument("file", type=Path)
    args = parser.parse_args(argv)
    now = collect()
    if args.action == "save":
        np.savez_compressed(args.file, **now)
        print(f"saved {len(now)} arrays to {args.file}")
        return 0
    with np.load(args.file) as data:
        saved = {k: data[k] for k in data.files}
    problems = compare(saved, now)
    for line in problems:
        print(line)
    print(f"{len(saved)} arrays compared: {len(problems)} differ")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
