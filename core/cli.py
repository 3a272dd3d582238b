"""The command line: ``python -m core solve SCENE.json`` and ``python -m core validate SCENE.json``.

``solve`` writes the solution to ``--output`` (``.json``: everything, see
:meth:`core.scene.SceneSolution.to_dict`; ``.csv``: the histories of settlement, tilt,
force and moment) and optionally the pressure ``q(x, t)`` to ``--pressure-csv``; without
``--output`` it prints a short summary. ``validate`` only checks the scene file.

Exit codes: 0 success, 1 the solver failed (or an internal error), 2 bad input (an
unreadable, oversized or invalid scene file, or bad arguments). Every error is one line
``error: <field>: <reason>`` on stderr; validity flags of a solution (for instance
``contact_lost``) are reported as ``warning: <flag>: <explanation>`` lines on stderr with
exit code 0.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from core.scene import (
    QUANTITIES,
    Scene,
    SceneSolution,
    atomic_write_text,
    load_scene,
    solve,
)

EXIT_OK = 0
EXIT_SOLVER_FAILED = 1
EXIT_BAD_INPUT = 2

_UNITS = {"settlement": "m", "tilt": "rad", "force": "N/m", "moment": "N"}


class _InputError(Exception):
    """Bad input: reported as one line, exit code 2."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line and exit with code 2."""

    def error(self, message: str) -> NoReturn:
        raise _InputError(f"{self.prog}: {message}")


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _read(path: str) -> Scene:
    try:
        return load_scene(path)
    except ValueError as exc:
        raise _InputError(str(exc)) from None
    except IsADirectoryError:
        raise _InputError(f"{path}: is a directory, not a scene file") from None
    except OSError as exc:
        raise _InputError(f"{path}: {exc.strerror or exc}") from None


def _write(path: Path, text: str) -> None:
    try:
        atomic_write_text(path, text)
    except OSError as exc:
        raise _InputError(f"{path}: cannot write ({exc.strerror or exc})") from None


def _describe(scene: Scene) -> str:
    given = " and ".join(q for q in QUANTITIES if q in scene.loading)
    return (f"{scene.name!r}: statement {scene.statement} ({given} given), "
            f"{len(scene.coating)} coating layer(s), {scene.times.size} time(s) up to "
            f"{scene.times[-1]:g} days after loading")


def _summary(result: SceneSolution) -> str:
    lines = [f"solved {_describe(result.scene)}",
             f"{'time_day':>12} " + " ".join(f"{f'{q}_{_UNITS[q]}':>16}"
                                             for q in QUANTITIES)]
    rows = sorted({0, result.times.size - 1})
    for i in rows:
        values = [getattr(result, q)[i] for q in QUANTITIES]
        lines.append(f"{result.times[i]:12.6g} " + " ".join(f"{v:16.8g}" for v in values))
    lines.append(str(result.info.get("message", "")))
    return "\n".join(lines)


def _cmd_validate(args: argparse.Namespace) -> int:
    scene = _read(args.scene)
    print(f"ok: {_describe(scene)}")
    return EXIT_OK


def _cmd_solve(args: argparse.Namespace) -> int:
    output = Path(args.output) if args.output else None
    if output is not None and output.suffix.lower() not in (".json", ".csv"):
        raise _InputError(f"--output: unsupported extension {output.suffix!r} "
                          "(use .json or .csv)")
    pressure_out = Path(args.pressure_csv) if args.pressure_csv else None
    scene = _read(args.scene)
    try:
        result = solve(scene)
    except (ArithmeticError, ValueError, RuntimeError, MemoryError,
            NotImplementedError) as exc:
        # a valid scene the solver cannot handle: not the user's input error
        print(f"error: solve: {_one_line(exc)}", file=sys.stderr)
        return EXIT_SOLVER_FAILED
    if output is None:
        print(_summary(result))
    elif output.suffix.lower() == ".json":
        _write(output, result.to_json() + "\n")
    else:
        _write(output, result.to_csv())
    if pressure_out is not None:
        _write(pressure_out, result.pressure_csv())
    for name in result.flags:
        print(f"warning: {name}: {_one_line(result.flag_messages[name].replace('see info.message', result.info.get('message', '')))}", file=sys.stderr)  # noqa: E501
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``python -m core``."""
    parser = _Parser(prog="python -m core",
                     description="Contact of a rigid punch on a coated, aging viscoelastic "
                                 "layer (scene files: see core/SCENES.md).")
    sub = parser.add_subparsers(dest="command", metavar="{solve,validate}",
                                parser_class=_Parser)
    sub.required = True
    p_solve = sub.add_parser("solve", help="solve a scene and write the result")
    p_solve.add_argument("scene", help="scene file (JSON)")
    p_solve.add_argument("--output", "-o", metavar="PATH",
                         help="result file: .json (everything) or .csv (histories of "
                              "settlement [m], tilt [rad], force [N/m], moment [N]); "
                              "default: print a summary")
    p_solve.add_argument("--pressure-csv", metavar="PATH",
                         help="also write the pressure q(x, t) [Pa] as CSV (time [day], "
                              "x [m], pressure [Pa])")
    p_solve.set_defaults(run=_cmd_solve)
    p_validate = sub.add_parser("validate", help="check a scene file")
    p_validate.add_argument("scene", help="scene file (JSON)")
    p_validate.set_defaults(run=_cmd_validate)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); returns the exit code."""
    try:
        args = build_parser().parse_args(argv)
        return int(args.run(args))
    except _InputError as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # the promise is one line on stderr, never a traceback
        print(f"error: internal error ({type(exc).__name__}: {_one_line(exc)}); please "
              "report it with the scene file", file=sys.stderr)
        return EXIT_SOLVER_FAILED
