"""The command line ``coated-punch`` (also ``python -m core``): ``solve SCENE.json``,
``validate FILE`` (a scene or a study file), ``calibrate SCENE.json READINGS.csv --fit
PATH`` (fit scene fields to measured settlements and tilts: :mod:`core.back_analysis`),
``report SCENE.json -o REPORT.pdf`` (the
printable report, HTML or PDF: :mod:`core.report`), ``sweep STUDY.json --output
RESULT.nc`` (a design study, see :mod:`core.study.run`), ``check SCENE.json`` (the
coating model against resolved finite elements) and ``schema scene|study`` (the JSON
Schema of the files); ``--version``. A scene or study argument may name a shipped one as
``preset:NAME`` (:mod:`core.presets`).

``solve`` writes the solution to ``--output`` (``.json``: everything, see
:meth:`core.scene.SceneSolution.to_dict`, with the contact set per time and the design
check; ``.csv``: the histories of settlement, tilt, force and moment, and the contact
zones when the punch lifts off) and optionally the pressure ``q(x, t)`` to
``--pressure-csv``; without ``--output`` it prints a short summary. A scene of several
punches is written the same way, every punch in one file (columns ``punches[k].*``, q
over the whole surface in the global x), its design check and flags per punch. Every file records
the program's version, the scene and the solver settings (:mod:`core.scene.records`:
top-level keys of the JSON, ``# key: value`` lines before a CSV table). ``-`` as the
scene reads it from standard input, ``-`` as an output writes it to standard output
(``--format`` chooses JSON or CSV, default JSON). ``validate`` checks a file against its
JSON Schema, then validates it fully; every problem is one line naming the field.

Files: an output may not be the scene file itself, two outputs may not name one file,
and an existing output must be a regular, writable file (a read-only file is refused,
never replaced); a symbolic link is written through (its target is replaced, the link
stays). The scene file must be a regular file (a named pipe is refused at once). All of
this is checked before solving (see :mod:`core.files`).

Exit codes: 0 success, 1 the solver failed (or an internal error), 2 bad input (an
unreadable, oversized or invalid file, or bad arguments), and with ``solve --strict``: 3
a limit of the design check is exceeded, 4 the answer carries a validity flag (4 wins
when both hold: a flagged answer's check cannot be trusted); ``calibrate --strict``
exits with 4 when the fit carries a warning (``warning: calibrate: ...`` lines on
stderr: a field not identifiable, a bound reached, the solver's error near the noise).
Every error is one line ``error: <field>: <reason>`` on stderr; validity flags of a
solution (for instance ``contact_lost``) and exceeded limits are reported as
``warning: <flag>: <explanation>`` and ``warning: design_check: <line>`` lines on
stderr, with exit code 0 unless ``--strict``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import shutil
import signal
import sys
from collections.abc import Iterator, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, NoReturn

from core import limits
from core.files import (
    atomic_write_bytes,
    atomic_write_text,
    read_regular_file,
    same_file,
    writable_target,
)
from core.limits import MAX_SCENE_TIMES
from core.optional import MissingDependency
from core.presets import PRESET_PREFIX, preset_names, shipped_file, study_names
from core.problem import QUANTITIES
from core.scene import (
    MAX_SCENE_BYTES,
    SCHEMA_FILES,
    PunchesScene,
    PunchesSolution,
    Scene,
    SceneSolution,
    check_loads_touch,
    check_settled,
    corner_note,
    days_text,
    flags_with_evidence,
    has_punches,
    largest_pressure,
    load_json_schema,
    load_scene,
    migrate,
    model_error_evidence,
    model_error_line,
    percent_text,
    punches_from_dict,
    read_scene_json,
    scene_from_dict,
    scene_json_schema,
    scene_to_json,
    schema_errors,
    schema_text,
    solve,
    thin_edge_note,
    verdict_words,
)
from core.version import VERSION
from core.work import PER_CORE_BYTES, address_space_bound, bound_memory

EXIT_OK = 0
EXIT_SOLVER_FAILED = 1
EXIT_BAD_INPUT = 2
#: ``solve --strict``: a limit of the design check is exceeded.
EXIT_DESIGN_FAILED = 3
#: ``solve --strict``: the answer carries a validity flag (wins over a failed check).
EXIT_FLAGGED = 4
#: The reader of standard output left before the end (``| head``): the shell's code of a
#: process ended by a closed pipe (128 + SIGPIPE).
EXIT_BROKEN_PIPE = 141
#: The name standing for standard input (a scene) or standard output (a file written).
STDIO = "-"
#: How standard input is named in messages.
STDIN_NAME = "<stdin>"
#: FE mesh level of ``check`` by default and of ``report --fe-check`` (0: ~1 s, P to ~2e-4).
FE_CHECK_LEVEL = 0

#: Units of the histories in the text tables (the CSV columns keep ``moment_N``: N·m/m is N).
_UNITS = {"settlement": "m", "tilt": "rad", "force": "N/m", "moment": "N·m/m"}


class _InputError(Exception):
    """Bad input: reported as one line, exit code 2."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line and exit with code 2."""

    def error(self, message: str) -> NoReturn:
        # (a bare `coated-punch` said only which arguments were missing)
        raise _InputError(f"{self.prog}: {message} (see '{self.prog} --help')")


#: The address-space bound [bytes] this run set on itself (None: none, as when
#: :func:`main` is called from Python).
_MEMORY_BOUND: int | None = None
#: The ``--max-memory`` it was set from [GiB].
_MEMORY_ASKED: float | None = None


def _one_line(text: str | BaseException) -> str:
    """``text`` on one line; a ``MemoryError`` says which bound it met, and how to raise
    it (numpy's own text names only the array it could not allocate)."""
    if isinstance(text, MemoryError) and _MEMORY_BOUND is not None:
        # the bound is the asked one plus the threads' share per core: both said, so that
        # "--max-memory 0.5" is not answered "the 0.75 GiB" unexplained
        cores = os.cpu_count() or 1
        asked = (limits.MAX_RUN_MEMORY_BYTES / 2**30 if _MEMORY_ASKED is None
                 else _MEMORY_ASKED)
        if _MEMORY_BOUND < address_space_bound(int(asked * 2**30)):
            # a hard limit set outside (ulimit -Hv, a container) is lower: no option of
            # this run raises it
            why = ("the hard limit of this process's address space, set outside this "
                   "program (ulimit -Hv or the container), lower than --max-memory asked")
        else:
            why = (f"--max-memory {asked:g} GiB plus {PER_CORE_BYTES / 2**20:g} MiB for "
                   f"each of the {cores} cores; --max-memory GIB raises it, default "
                   f"{limits.MAX_RUN_MEMORY_BYTES / 2**30:g}")
        text = (f"needed more than the {_MEMORY_BOUND / 2**30:.3g} GiB of memory this run "
                f"may take ({why})" + (f": {text}" if str(text) else ""))
    return " ".join(str(text).split())


#: The least ``--max-memory`` [GiB]: a run maps ~0.27 GiB before it solves (Python,
#: numpy, scipy); a bound met while the BLAS library takes its work buffer left it
#: retrying forever (0.001 GiB, spinning for 10 minutes), where a bound met by the
#: solver's own arrays stops the run with a message.
MIN_RUN_MEMORY_GIB = 0.5


def _gibibytes(text: str) -> float:
    """The value of ``--max-memory`` [GiB]: a finite number >= :data:`MIN_RUN_MEMORY_GIB`."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= MIN_RUN_MEMORY_GIB):
        raise argparse.ArgumentTypeError(f"must be a number of GiB >= {MIN_RUN_MEMORY_GIB:g}, "
                                         f"got {text!r}")
    return value


def _stdin_text() -> str:
    """Standard input as text, at most a scene file's size."""
    stream = getattr(sys.stdin, "buffer", None)
    raw = stream.read(MAX_SCENE_BYTES + 1) if stream is not None else \
        sys.stdin.read(MAX_SCENE_BYTES + 1).encode("utf-8")
    if len(raw) > MAX_SCENE_BYTES:
        raise _InputError(f"{STDIN_NAME}: over the limit of {MAX_SCENE_BYTES} bytes for a "
                          "scene file")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise _InputError(f"{STDIN_NAME}: not text in UTF-8 (a scene file is JSON)") from None


@contextlib.contextmanager
def _input_errors(path: str) -> Iterator[None]:
    """A file that cannot be read, or does not hold a valid scene, is the user's input
    error: one line naming the file (exit code 2)."""
    try:
        yield
    except ValueError as exc:
        raise _InputError(str(exc)) from None
    except IsADirectoryError:
        raise _InputError(f"{path}: is a directory, not a scene file") from None
    except OSError as exc:
        raise _InputError(f"{path}: {exc.strerror or exc}") from None


def _read(path: str) -> Scene | PunchesScene:
    """The scene of ``path``, validated; a load no contact model answers (a pulled punch,
    a resultant outside it) is the user's input too, refused before any solve."""
    with _input_errors(path):
        if path == STDIO:
            data = read_scene_json(_stdin_text(), STDIN_NAME)
            scene = punches_from_dict(data) if has_punches(data) else scene_from_dict(data)
        else:
            scene = load_scene(path)
        check_loads_touch(scene)
        return scene


def _read_document(path: str) -> Any:
    """The JSON value of a file (or of standard input), read strictly, not validated."""
    if path == STDIO:
        return read_scene_json(_stdin_text(), STDIN_NAME)
    with _input_errors(path):
        raw = read_regular_file(path, MAX_SCENE_BYTES)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise _InputError(f"{path}: not a text file in UTF-8 (a scene file is JSON)") from None
    try:
        return read_scene_json(text, path)
    except ValueError as exc:
        raise _InputError(str(exc)) from None


def _check_outputs(scene: str, outputs: Sequence[tuple[str, Path | None]]) -> None:
    """Refuse, before solving, an output that is the scene file itself, two outputs to
    one file, and an output that may not be replaced (read-only, not a regular file)."""
    given = [(option, path) for option, path in outputs if path is not None]
    if sum(str(path) == STDIO for _, path in given) > 1:
        raise _InputError(f"{given[-1][0]}: only one output may be '-' (standard output)")
    given = [(option, path) for option, path in given if str(path) != STDIO]
    for i, (option, path) in enumerate(given):
        if scene != STDIO and same_file(path, scene):
            raise _InputError(f"{option}: {path} is the scene file being solved; it is not "
                              "overwritten (choose another file)")
        for earlier, other in given[:i]:
            if same_file(path, other):
                raise _InputError(f"{option}: {path} is also the {earlier} file; give two "
                                  "different files")
        try:
            writable_target(path)
        except ValueError as exc:
            raise _InputError(f"{option}: {exc}") from None


def _write(path: Path, content: str | bytes) -> None:
    """Write text or bytes to ``path`` atomically, or to standard output for ``-``."""
    if str(path) == STDIO:
        if isinstance(content, bytes):
            sys.stdout.buffer.write(content)
        else:
            sys.stdout.write(content)
        sys.stdout.flush()
        return
    try:
        if isinstance(content, bytes):
            atomic_write_bytes(path, content)
        else:
            atomic_write_text(path, content)
    except ValueError as exc:
        raise _InputError(str(exc)) from None
    except OSError as exc:
        raise _InputError(f"{path}: cannot write ({exc.strerror or exc})") from None


def _describe(scene: Scene | PunchesScene) -> str:
    if isinstance(scene, PunchesScene):
        first = scene.scenes[0]
        count = len(scene.scenes)
        return (f"{scene.name!r}: {count} punch{'es' if count > 1 else ''} (statements "
                f"{', '.join(str(s.statement) for s in scene.scenes)}), "
                f"{len(first.coating)} coating layer(s), {first.times.size} time(s) up to "
                f"{days_text(first.times[-1])} after loading")
    given = " and ".join(q for q in QUANTITIES if q in scene.loading)
    return (f"{scene.name!r}: statement {scene.statement} ({given} given), "
            f"{len(scene.coating)} coating layer(s), {scene.times.size} time(s) up to "
            f"{days_text(scene.times[-1])} after loading")


def _punches_summary(result: PunchesSolution) -> str:
    """The summary of a scene of several punches: each punch's histories at the first and
    last times, its largest pressure, estimate, flags and coating model error."""
    lines = [f"solved {_describe(result.scene)}"]
    rows = sorted({0, result.times.size - 1})
    checks = result.design_checks()
    for k, punch in enumerate(result.punches):
        lines.append(f"punches[{k}] at x = {punch.center:g} m (half-width "
                     f"{punch.scene.half_width:g} m, statement {punch.scene.statement}):")
        lines.append(f"{'time_day':>12} " + " ".join(f"{f'{q}_{_UNITS[q]}':>16}"
                                                     for q in QUANTITIES))
        for i in rows:
            values = [getattr(punch, q)[i] for q in QUANTITIES]
            lines.append(f"{result.times[i]:12.6g} " + " ".join(f"{v:16.8g}" for v in values))
        line = largest_pressure(punch)
        edge = thin_edge_note(line, punch.scene.half_width, punch.info.get("coating_model"),
                              dimensional=punch.info.get("dimensional"))
        line = replace(line, x=punch.center + line.x)  # the global x
        lines.append(f"  largest contact pressure q: {line.value_text(place_first=True)}")
        if edge:
            lines.append(f"    ({edge})")
        lines.append(f"  {punch.info.get('message', '')}")
        lines.append(f"  flags: {', '.join(punch.flags) if punch.flags else 'none'}")
        if punch.scene.coating:
            lines.append(f"  coating model error (estimate): {model_error_line(punch)}")
        if checks[k] is not None:
            lines.append(f"  design check (whole history): "
                         f"{verdict_words(checks[k].passed, punch.flags)}")
            lines.extend(f"    {line.describe()}" for line in checks[k].checks)
    lines.append(f"coating model: {result.info.get('coating_model')}")
    return "\n".join(lines)


def _summary(result: SceneSolution) -> str:
    lines = [f"solved {_describe(result.scene)}",
             f"{'time_day':>12} " + " ".join(f"{f'{q}_{_UNITS[q]}':>16}"
                                             for q in QUANTITIES)]
    rows = sorted({0, result.times.size - 1})
    for i in rows:
        values = [getattr(result, q)[i] for q in QUANTITIES]
        lines.append(f"{result.times[i]:12.6g} " + " ".join(f"{v:16.8g}" for v in values))
    if result.info.get("contact") == "unilateral":
        for i in rows:
            zones = ", ".join(f"[{lo:.6g}, {hi:.6g}]" for lo, hi in result.contact_set[i])
            where = f"{zones} m" if zones else "none (the punch touches nothing)"
            lines.append(f"contact at {days_text(result.times[i])}: {where}")
    largest = largest_pressure(result)
    lines.append(f"largest contact pressure q: {largest.value_text(place_first=True)}")
    edge = thin_edge_note(largest, result.scene.half_width, result.info.get("coating_model"),
                          dimensional=result.info.get("dimensional"))
    if edge:
        lines.append(f"  ({edge})")
    held = corner_note(result.info.get("corner_pressure"))
    if held is not None:
        # what the q table's held rows leave out: a table integrated fell short of P by
        # up to 9 % with nothing said here
        lines.append(held.removeprefix("# "))
    lines.append(str(result.info.get("message", "")))
    lines.append(f"flags: {', '.join(result.flags) if result.flags else 'none'}")
    if result.info.get("model_error_estimate") is not None:
        lines.append(f"coating model error ({result.info.get('coating_model')}, estimate): "
                     f"{model_error_line(result)}")
    check = result.design_check()
    if check is not None:
        lines.append(f"design check (whole history): "
                     f"{verdict_words(check.passed, result.flags)}")
        lines.extend(f"  {line.describe()}" for line in check.checks)
    return "\n".join(lines)


def _shipped_scene_or_study(path: str) -> str:
    """The file of ``preset:NAME``, a shipped scene or else a shipped study."""
    if not path.startswith(PRESET_PREFIX):
        return path
    kind = "studies" if path[len(PRESET_PREFIX):] in study_names() else "scenes"
    try:
        return str(shipped_file(path, kind))
    except ValueError as exc:
        raise _InputError(str(exc)) from None


def _cmd_validate(args: argparse.Namespace) -> int:
    args.file = _shipped_scene_or_study(args.file)
    data = _read_document(args.file)
    study = isinstance(data, dict) and "study_version" in data
    if not study:
        try:
            # an older schema version is brought to the current one before its schema
            data = migrate(data)
        except ValueError as exc:
            raise _InputError(str(exc)) from None
    kind = "study" if study else "scene"
    if not study and has_punches(data) and any(k in data for k in ("punch", "loading")):
        # both forms at once: the schema would list the fields of one form missing
        try:
            punches_from_dict(data)
        except ValueError as exc:
            raise _InputError(str(exc)) from None
    problems = schema_errors(data, load_json_schema(kind), root=kind)
    if problems:
        # each problem is one line; the full validation's messages follow once they are gone
        for line in problems:
            print(f"error: {_one_line(line)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        if study:
            from core.study import study_from_dict

            base = Path.cwd() if args.file == STDIO else Path(args.file).resolve().parent
            checked = study_from_dict(data, base_dir=base)
            print(f"ok: study {checked.name!r}: {checked.n_points} points, "
                  f"{len(checked.parameters)} varied field(s)")
        else:
            scene = punches_from_dict(data) if has_punches(data) else scene_from_dict(data)
            check_loads_touch(scene)
            print(f"ok: {_describe(scene)}")
    except ValueError as exc:
        raise _InputError(str(exc)) from None
    return EXIT_OK


def _output_format(option: str, path: Path | None, given: str | None) -> str | None:
    """``json`` or ``csv`` for an output: ``--format``, else the file's extension."""
    if path is None:
        if given is not None:
            # a summary has no format: taken silently, --format csv printed the summary
            raise _InputError(f"--format: is the format of {option}, which is not given "
                              f"(-o - writes {given.upper()} to standard output)")
        return None
    if given is not None:
        return given
    if str(path) == STDIO:
        return "json"
    if path.is_dir():  # (said before its missing extension)
        raise _InputError(f"{option}: {path} is a directory; give a file's path")
    suffix = path.suffix.lower()
    if suffix not in (".json", ".csv"):
        raise _InputError(f"{option}: unsupported extension {path.suffix!r} "
                          "(use .json or .csv, or --format)")
    return suffix[1:]


def _strict_verdict(result: SceneSolution, flags: Sequence[str] | None = None) -> int:
    """The exit code of ``solve --strict`` for ``result``, its reasons on stderr
    (``flags``: the result's flags as the best evidence has them, default its own)."""
    check = result.design_check()
    failed = check is not None and check.passed is False
    flags = result.flags if flags is None else list(flags)
    if flags:
        return _strict_exit(f"the answer is flagged ({', '.join(flags)})", EXIT_FLAGGED)
    if failed:
        names = ", ".join(line.limit_name or line.quantity for line in check.failures)
        return _strict_exit(f"the design check failed ({names})", EXIT_DESIGN_FAILED)
    return EXIT_OK


def _strict_exit(reason: str, code: int) -> int:
    """``code``, after saying on stderr why ``--strict`` gives it."""
    print(f"error: strict: {reason}; exit code {code}", file=sys.stderr)
    return code


def _solve(path: str, scene: Scene | PunchesScene | None = None
           ) -> SceneSolution | PunchesSolution | None:
    """The answer for the scene at ``path`` (``scene``: that scene, read already); None
    (the reason on stderr) when the solver cannot answer a valid scene, which is not the
    user's input error."""
    scene = _read(path) if scene is None else scene
    try:
        return solve(scene)
    except (ArithmeticError, ValueError, RuntimeError, MemoryError,
            NotImplementedError) as exc:
        print(f"error: solve: {_one_line(exc)}", file=sys.stderr)
        return None


def _cmd_solve(args: argparse.Namespace) -> int:
    output = Path(args.output) if args.output else None
    fmt = _output_format("--output", output, args.format)
    pressure_out = Path(args.pressure_csv) if args.pressure_csv else None
    if pressure_out is not None and str(pressure_out) != STDIO \
            and pressure_out.suffix.lower() != ".csv":
        # (q(x, t) was written as CSV into a .json file)
        raise _InputError(f"--pressure-csv: {pressure_out}: q(x, t) is written as CSV; give "
                          "a .csv file (or - for standard output)")
    _check_outputs(args.scene, [("--output", output), ("--pressure-csv", pressure_out)])
    result = _solve(args.scene)
    if result is None:
        return EXIT_SOLVER_FAILED
    if isinstance(result, PunchesSolution):
        return _solved_punches(args, result, output, fmt, pressure_out)
    if output is None:
        print(_summary(result))
    elif fmt == "json":
        _write(output, result.to_json() + "\n")
    else:
        _write(output, result.to_csv())
    if pressure_out is not None:
        _write(pressure_out, result.pressure_csv())
    _say_written(output, pressure_out)
    for name in result.flags:
        print(f"warning: {name}: {_one_line(result.flag_messages[name].replace('see info.message', result.info.get('message', '')))}", file=sys.stderr)  # noqa: E501
    _design_warnings(result)
    return _strict_verdict(result) if args.strict else EXIT_OK


def _say_written(*outputs: Path | None) -> None:
    """``written to ...`` of the files ``solve`` or ``report`` wrote, as ``preset`` and
    ``sweep`` say it (a run with ``-o`` printed nothing); nothing when one of them is
    standard output, whose data the line would spoil."""
    files = [str(path) for path in outputs if path is not None]
    if files and STDIO not in files:
        print(f"written to {' and '.join(files)}")


def _design_warnings(result: SceneSolution) -> None:
    """A ``warning: design_check:`` line on stderr for each limit the answer exceeds."""
    check = result.design_check()
    for line in check.failures if check is not None else ():
        print(f"warning: design_check: {_one_line(line.describe())}", file=sys.stderr)


def _solved_punches(args: argparse.Namespace, result: PunchesSolution, output: Path | None,
                    fmt: str | None, pressure_out: Path | None) -> int:
    """``solve`` of a scene of several punches: the summary, or the answer as JSON or
    CSV (the histories of every punch), and q over the whole surface."""
    if output is None:
        print(_punches_summary(result))
    elif fmt == "json":
        _write(output, result.to_json() + "\n")
    else:
        _write(output, result.to_csv())
    if pressure_out is not None:
        _write(pressure_out, result.pressure_csv())
    _say_written(output, pressure_out)
    _punches_warnings(result)
    return _punches_strict(result) if args.strict else EXIT_OK


def _punches_warnings(result: PunchesSolution) -> None:
    """The flags and the exceeded limits of every punch as ``warning: punches[k].<flag>:
    ...`` and ``warning: punches[k].design_check: ...`` lines on stderr."""
    for k, (punch, check) in enumerate(zip(result.punches, result.design_checks(),
                                           strict=True)):
        for name in punch.flags:
            print(f"warning: punches[{k}].{name}: {_one_line(punch.flag_messages[name])}",
                  file=sys.stderr)
        for line in check.failures if check is not None else ():
            print(f"warning: punches[{k}].design_check: {_one_line(line.describe())}",
                  file=sys.stderr)


def _punches_strict(result: PunchesSolution) -> int:
    """The exit code of ``--strict`` for several punches, as :func:`_strict_verdict`: a
    flag of any punch, else a limit any punch exceeds."""
    if result.flags:
        return _strict_exit(f"the answer is flagged ({', '.join(result.flags)})",
                            EXIT_FLAGGED)
    checks = list(enumerate(result.design_checks()))
    failed = [f"punches[{k}].{line.limit_name or line.quantity}" for k, check in checks
              if check is not None for line in check.failures]
    if failed:
        return _strict_exit(f"the design check failed ({', '.join(failed)})",
                            EXIT_DESIGN_FAILED)
    return EXIT_OK


def _cmd_report(args: argparse.Namespace) -> int:
    output = Path(args.output)
    stdout = str(output) == STDIO
    fmt = args.format or ("pdf" if output.suffix.lower() == ".pdf" else "html")
    if not stdout and output.suffix.lower() not in (".html", ".htm", ".pdf"):
        raise _InputError(f"--output: {output}: a report is .html or .pdf")
    if not stdout and (fmt == "pdf") != (output.suffix.lower() == ".pdf"):
        # (a PDF was written into a .html file)
        raise _InputError(f"--format: {fmt} does not match --output {output}; give a "
                          f".{'pdf' if fmt == 'pdf' else 'html'} file, or leave --format out")
    _check_outputs(args.scene, [("--output", output)])
    # imported here: the report loads HoloViews and Bokeh (or Matplotlib), ~2 s
    from core.report import output_index, report_html, report_pdf

    scene = _read(args.scene)
    try:  # before the solve: a typo must not cost one
        output_index(scene, args.time)
    except ValueError as exc:
        raise _InputError(f"--{exc}") from None
    result = _solve(args.scene, scene)
    if result is None:
        return EXIT_SOLVER_FAILED
    if isinstance(result, PunchesSolution):
        if args.fe_check:
            raise _InputError("--fe-check: the finite-element check is of one punch; run "
                              "it on each punch's own scene")
        _write(output, report_pdf(result, args.time) if fmt == "pdf"
               else report_html(result, args.time))
        _say_written(output)
        _punches_warnings(result)
        return _punches_strict(result) if args.strict else EXIT_OK
    fe_check = None
    if args.fe_check:
        from core.scene import check_scene  # here for start-up speed: the FE modules

        try:
            fe_check = check_scene(result.scene, 0.0, level=FE_CHECK_LEVEL)
        except ValueError as exc:
            reason = _no_contact_then(exc)
            if reason is None:
                print(f"error: check: {_one_line(exc)}", file=sys.stderr)
                return EXIT_SOLVER_FAILED
            # nothing touches at loading: the report is written without a check
            print(f"warning: fe_check: not run: {_one_line(reason)}", file=sys.stderr)
        except (ArithmeticError, RuntimeError, MemoryError) as exc:
            print(f"error: check: {_one_line(exc)}", file=sys.stderr)
            return EXIT_SOLVER_FAILED
    if fmt == "pdf":
        _write(output, report_pdf(result, args.time, check=fe_check))
    else:
        _write(output, report_html(result, args.time, check=fe_check))
    _say_written(output)  # (the report was the one command that wrote a file unsaid)
    evidence = model_error_evidence(result.scene, result.model_error["estimate"], fe_check)
    flags = flags_with_evidence(result.flags, evidence)
    messages = {**result.flag_messages, "model_error": evidence["message"]}
    if fe_check is not None and evidence["source"] == "measured":
        print(f"coating model error: {100 * evidence['error']:.2f} % measured by the FE "
              f"check at loading, {percent_text(evidence['estimate'], 2)} estimated "
              f"(solver.model_tol {100 * evidence['model_tol']:g} %)", file=sys.stderr)
    elif fe_check is not None:
        print("warning: fe_unsettled: the FE check's contact set had not settled: the "
              "report keeps the estimate", file=sys.stderr)
    for name in flags:
        print(f"warning: {name}: {_one_line(messages[name])}", file=sys.stderr)
    # (as solve says them: report said no word of an exceeded limit, --strict included)
    _design_warnings(result)
    return _strict_verdict(result, flags) if args.strict else EXIT_OK


def _cmd_preset(args: argparse.Namespace) -> int:
    """List the shipped scenes, or write one as a scene file to start from."""
    if args.name is None:
        if args.output:
            raise _InputError("--output: give the preset to write (coated-punch preset NAME "
                              "-o FILE.json); without a name the list is printed")
        width = max(len(name) for name in preset_names())
        for name in preset_names():
            print(f"{name:<{width}}  {load_scene(PRESET_PREFIX + name).name}")
        return EXIT_OK
    if args.name.startswith(PRESET_PREFIX):  # (as SCENE takes it)
        args.name = args.name[len(PRESET_PREFIX):]
    try:
        scene = load_scene(PRESET_PREFIX + args.name)
    except ValueError as exc:
        raise _InputError(str(exc)) from None
    output = Path(args.output) if args.output else None
    if output is None or str(output) == STDIO:
        sys.stdout.write(scene_to_json(scene) + "\n")
        return EXIT_OK
    if output.suffix.lower() != ".json":
        raise _InputError(f"--output: {output}: a scene file is .json")
    if output.exists() and not args.force:
        # the file written is the one to edit: a second run wiped the edits
        raise _InputError(f"--output: {output} exists (a scene being edited?); choose "
                          "another file, or --force to replace it")
    _check_outputs(STDIO, [("--output", output)])
    _write(output, scene_to_json(scene) + "\n")
    print(f"written to {output}: the preset {args.name} ({scene.name}), to change and "
          f"solve (coated-punch validate '{output}')")
    return EXIT_OK


def _cmd_schema(args: argparse.Namespace) -> int:
    if args.kind == "study":
        from core.study import study_json_schema

        schema = study_json_schema()
    else:
        schema = scene_json_schema()
    sys.stdout.write(schema_text(schema))
    return EXIT_OK


def _cmd_sweep(args: argparse.Namespace) -> int:
    # imported here: a plain solve must not load Dask
    from core.study import LIMITS_NOT_CHECKED, check_output, load_study, sweep

    output = Path(args.output)
    try:
        check_output(output)
        study = load_study(args.study)
    except ValueError as exc:
        raise _InputError(str(exc)) from None
    except OSError as exc:
        raise _InputError(f"{args.study}: {exc.strerror or exc}") from None
    own_parts = args.work_dir is None
    work_dir = Path(args.work_dir) if args.work_dir else \
        output.with_name(output.name + ".parts")
    try:
        info = sweep(study, scheduler=args.scheduler, work_dir=work_dir, output=output,
                     batch_points=args.batch_points,
                     progress=not args.quiet and sys.stderr.isatty(),
                     return_dataset=False)
    except ValueError as exc:
        if own_parts and not any(work_dir.glob("**/*.npz")):
            shutil.rmtree(work_dir, ignore_errors=True)  # nothing computed: nothing to resume
        message = str(exc)
        if message.startswith("scheduler:"):
            message = "--" + message  # the option that gave it
        raise _InputError(message) from None
    print(f"{study.n_points} points in {info['batches']} batches ({info['batches_reused']} "
          f"reused), {info['points_failed']} failed, {info['points_flagged']} flagged, "
          f"{info['seconds']:.1f} s; written to {output}")
    if study.base.get("limits"):
        print(f"warning: sweep: {LIMITS_NOT_CHECKED}", file=sys.stderr)
    if info["batches_lost"]:
        print(f"error: sweep: {info['batches_lost']} batches were lost; run the same command "
              f"again to compute them (the others are kept in {work_dir})", file=sys.stderr)
        return EXIT_SOLVER_FAILED
    if own_parts:
        shutil.rmtree(work_dir, ignore_errors=True)
    return EXIT_OK


def _check_forecast_times(scene: Any, end: float, count: int) -> None:
    """Refuse, before the fit, a forecast the scene cannot be solved to, named as typed:
    its times as the scene's own (a design code's law is fitted for 100 years, any scene
    for 100000 days), the refusal of ``times.end`` said of ``--forecast`` (it read
    "times.end: must be <= ...", after the whole fit)."""
    try:
        data = scene.to_dict()
    except AttributeError:  # (not a scene of one punch: the fit says what it takes)
        return
    data["times"] = {"end": end, "count": count, "spacing": "log"}
    try:
        scene_from_dict(data)
    except ValueError as exc:
        text = str(exc)
        for field, option in (("times.end", "--forecast"), ("times.count", "--forecast-count"),
                              ("times", "--forecast")):
            if text.startswith(field + ":"):
                raise _InputError(option + text[len(field):]) from None


def _bounds(specs: Sequence[str], fit: Sequence[str]) -> dict[str, tuple[float | None,
                                                                         float | None]]:
    """``--bound PATH=LOW,HIGH`` options as a mapping (an empty end is no bound)."""
    out: dict[str, tuple[float | None, float | None]] = {}
    for spec in specs:
        path, sep, pair = spec.partition("=")
        ends = pair.split(",")
        if not sep or len(ends) != 2:
            raise _InputError(f"--bound: {spec!r} is not PATH=LOW,HIGH (either end may be "
                              "empty)")
        try:
            lo, hi = (float(e) if e.strip() else None for e in ends)
        except ValueError:
            raise _InputError(f"--bound: {spec!r}: the ends must be numbers") from None
        if path.strip() not in fit:
            raise _InputError(f"--bound: {path.strip()!r} is not one of the --fit fields")
        out[path.strip()] = (lo, hi)
    return out


def _cmd_calibrate(args: argparse.Namespace) -> int:
    # imported here: the other commands do not load SciPy's optimiser
    from core.back_analysis import calibrate, read_readings, readings_from_text

    if args.scene == STDIO and args.readings == STDIO:
        raise _InputError("readings: the scene already reads standard input; give the "
                          "readings as a file")
    output = Path(args.output) if args.output else None
    report = Path(args.report) if args.report else None
    if report is not None and report.suffix.lower() not in (".html", ".htm", ".pdf"):
        raise _InputError(f"--report: {report}: a report is .html or .pdf")
    _check_outputs(args.scene, [("--output", output), ("--report", report)])
    if output is not None and str(output) != STDIO and args.readings != STDIO \
            and same_file(output, args.readings):
        raise _InputError(f"--output: {output} is the readings file; it is not "
                          "overwritten (choose another file)")
    scene = _read(args.scene)
    with _input_errors(args.readings):
        readings = readings_from_text(_stdin_text(), STDIN_NAME) \
            if args.readings == STDIO else read_readings(args.readings)
    bounds = _bounds(args.bound or [], args.fit)
    # the forecast's options checked before the fit, named as typed (a forecast of 0 days
    # was left out without a word; -5 was refused as "times.end")
    if args.forecast is not None and not (math.isfinite(args.forecast) and args.forecast > 0):
        raise _InputError(f"--forecast: must be a number of days > 0, got {args.forecast:g}")
    if not 1 <= args.forecast_count <= MAX_SCENE_TIMES:
        raise _InputError(f"--forecast-count: must be a whole number from 1 to "
                          f"{MAX_SCENE_TIMES}, got {args.forecast_count}")
    if args.forecast is not None:
        _check_forecast_times(scene, args.forecast, args.forecast_count)
    try:
        fit = calibrate(scene, readings, fit=args.fit, bounds=bounds)
        forecast = fit.forecast({"end": args.forecast, "count": args.forecast_count,
                                 "spacing": "log"}) if args.forecast is not None else None
    except ValueError as exc:
        message = str(exc)
        if message.startswith(("fit", "bounds", "measurements", "scene", "settlement",
                               "tilt", "time", "times")):
            raise _InputError(message) from None
        print(f"error: calibrate: {_one_line(message)}", file=sys.stderr)
        return EXIT_SOLVER_FAILED
    except (ArithmeticError, RuntimeError, MemoryError, NotImplementedError) as exc:
        print(f"error: calibrate: {_one_line(exc)}", file=sys.stderr)
        return EXIT_SOLVER_FAILED
    summary = fit.summary()
    if forecast is not None:
        lower, upper = forecast.band("settlement")
        band = (f"[{lower[-1]:.6g}, {upper[-1]:.6g}] m (from the fitted fields' uncertainty)"
                if math.isfinite(float(upper[-1] - lower[-1])) else
                "none: the readings do not determine it (see the warnings)")
        summary += (f"\nforecast at {days_text(forecast.times[-1])}: settlement "
                    f"{forecast.settlement[-1]:.6g} m, {100 * forecast.level:g} % band "
                    f"{band}")
    if output is None or str(output) != STDIO:
        print("\n".join(line for line in summary.splitlines()
                        if not line.startswith("warning: ")))
    if output is not None:
        data = fit.to_dict()
        if forecast is not None:
            data["forecast"] = forecast.to_dict()
        _write(output, json.dumps(data, indent=1, allow_nan=False) + "\n")
    if report is not None:
        # imported here: the report loads HoloViews and Bokeh (or Matplotlib), ~2 s
        from core.report import report_html, report_pdf

        try:
            fitted = solve(fit.scene)
        except (ArithmeticError, ValueError, RuntimeError, MemoryError) as exc:
            print(f"error: calibrate: the fitted scene: {_one_line(exc)}", file=sys.stderr)
            return EXIT_SOLVER_FAILED
        _write(report, report_pdf(fitted, calibration=fit)
               if report.suffix.lower() == ".pdf" else report_html(fitted, calibration=fit))
    for warning in fit.warnings:
        print(f"warning: calibrate: {_one_line(warning)}", file=sys.stderr)
    if args.strict and fit.warnings:
        return _strict_exit(f"the fit carries {len(fit.warnings)} warning(s)", EXIT_FLAGGED)
    return EXIT_OK


def _zones(zones: list[list[float]]) -> str:
    """Contact zones [m] as ``[lo, hi] m`` text."""
    return " ".join(f"[{lo:.4g}, {hi:.4g}]" for lo, hi in zones) + " m"


def _no_contact_then(exc: ValueError) -> str | None:
    """Why :func:`core.scene.check_scene` refused the time it was asked for (the punch
    touches nothing then: its refusal names ``time``), None for any other failure."""
    prefix = "time: "
    text = str(exc)
    return text[len(prefix):] if text.startswith(prefix) else None


def _cmd_check(args: argparse.Namespace) -> int:
    scene = _read(args.scene)
    if isinstance(scene, PunchesScene):
        raise _InputError(f"{args.scene}: the finite-element check is of one punch; run it "
                          "on each punch's own scene")
    end = float(scene.times[-1])
    if not 0.0 <= args.time <= end:  # also refuses nan
        raise _InputError(f"--time: must be in [0, {end:g}] days after loading (the scene's "
                          f"output times), got {args.time:g}")
    # imported here: a command that checks nothing starts without the FE modules
    from core.scene import check_scene, pressure_caution

    try:
        report = check_scene(scene, args.time, level=args.level)
    except ValueError as exc:
        reason = _no_contact_then(exc)
        if reason is not None:  # the time asked for: the user's input
            raise _InputError(f"--time (default 0): {reason}; pass --time DAYS") from None
        print(f"error: check: {_one_line(exc)}", file=sys.stderr)
        return EXIT_SOLVER_FAILED
    except (ArithmeticError, RuntimeError, MemoryError) as exc:
        print(f"error: check: {_one_line(exc)}", file=sys.stderr)
        return EXIT_SOLVER_FAILED
    print(f"checked {_describe(scene)}")
    print(f"resolved finite-element model at {days_text(report['time_day'])} after loading "
          f"(base elastic at that modulus): {report['fe_dofs']} unknowns, "
          f"{report['fe_seconds']:.1f} s")
    print(f"{'quantity':>12} {'fast':>16} {'resolved':>16} {'error':>9}")
    for q in QUANTITIES:
        # (+ 0.0: a difference below the digits shown read "-0.00%")
        print(f"{q + '_' + _UNITS[q]:>12} {report['fast'][q]:16.8g} {report['fe'][q]:16.8g} "
              f"{round(100 * report['errors'][q], 2) + 0.0:8.2f}%")
    # the two pressures where they differ most (the columns were empty)
    print(f"{'pressure_Pa':>12} {report['pressure_fast_Pa']:16.8g} "
          f"{report['pressure_fe_Pa']:16.8g} {100 * report['errors']['pressure']:8.2f}% "
          f"(largest on |x| <= 0.9 a, at x = {report['pressure_error_at_m']:.4g} m)")
    caution = pressure_caution(report)
    if caution:  # the verdict below is of the unknown scalars; q is not among them
        print(f"warning: pressure: {caution}", file=sys.stderr)
    lift = report.get("lift_off")
    if lift is not None:
        print(f"{'contact':>12} {_zones(lift['fast']):>16} {_zones(lift['fe']):>16} "
              f"{report['errors']['contact_ends']:8.3g} half-widths between zone ends "
              f"(both with lift-off; resolved ends to {lift['fe_end_uncertainty']:.1g} m)")
        if not check_settled(report):
            print(f"warning: fe_unsettled: the FE contact set had not settled after "
                  f"{lift['fe_sweeps']} sweeps: the errors above are not a measurement",
                  file=sys.stderr)
    print(f"model error of the fast answer: {100 * report['model_error']:.2f} % "
          f"({report['coating_model']}; estimate carried by results: "
          f"{percent_text(report['estimate'], 2)}, "
          f"solver.model_tol {100 * scene.model_tol:g} %)")
    if report["model_error"] > scene.model_tol:
        print("warning: model_error: the fast answer's coating model errs by more than "
              "solver.model_tol", file=sys.stderr)
    return EXIT_OK


#: Where the file formats are documented: ``SCENES.md``, shipped in the package.
FORMAT_DOC = str(Path(__file__).resolve().parent / "SCENES.md")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``python -m core``."""
    parser = _Parser(prog="coated-punch",
                     description="Contact of a rigid punch on a coated, aging viscoelastic "
                                 "layer. A scene is a JSON file, '-' (standard input) or "
                                 "preset:NAME, one of the shipped presets ("
                                 + ", ".join(preset_names()) + ").",
                     epilog=f"The file formats: {FORMAT_DOC} (installed with the package); "
                            "'coated-punch schema scene' prints the JSON Schema.")
    parser.add_argument("--version", action="version", version=f"coated-punch {VERSION}")
    sub = parser.add_subparsers(dest="command",
                                metavar="{solve,validate,report,preset,schema,sweep,calibrate,check}",
                                parser_class=_Parser)
    sub.required = True
    # the commands that solve: the run bounds its own memory (core.limits)
    memory = _Parser(add_help=False)
    memory.add_argument("--max-memory", metavar="GIB", type=_gibibytes,
                        default=limits.MAX_RUN_MEMORY_BYTES / 2**30,
                        help="memory this run may take, as address space [GiB] (default "
                             f"{limits.MAX_RUN_MEMORY_BYTES / 2**30:g}, plus "
                             f"{PER_CORE_BYTES / 2**20:g} MiB per core); past it the run "
                             "stops with a message")
    p_solve = sub.add_parser("solve", help="solve a scene and write the result",
                             parents=[memory])
    p_solve.add_argument("scene", help="scene file (JSON), '-' (standard input) or "
                                       "preset:NAME")
    p_solve.add_argument("--output", "-o", metavar="PATH",
                         help="result file: .json (everything) or .csv (histories of "
                              "settlement [m], tilt [rad], force [N/m], moment [N·m/m, column "
                              "moment_N]); '-' "
                              "writes to standard output; default: print a summary")
    p_solve.add_argument("--format", choices=("json", "csv"),
                         help="format of --output (default: from its extension; JSON "
                              "for '-')")
    p_solve.add_argument("--pressure-csv", metavar="PATH",
                         help="also write the pressure q(x, t) [Pa] as CSV (time [day], "
                              "x [m], pressure [Pa]); '-' writes to standard output")
    p_solve.add_argument("--strict", action="store_true",
                         help=f"exit with {EXIT_DESIGN_FAILED} when a limit of the scene's "
                              f"design check is exceeded, {EXIT_FLAGGED} when the answer "
                              "carries a validity flag (the reason on stderr)")
    p_solve.set_defaults(run=_cmd_solve)
    p_validate = sub.add_parser("validate", help="check a scene or study file against its "
                                                 "JSON Schema, then fully")
    p_validate.add_argument("file", help="scene or study file (JSON), '-' (standard "
                                         "input) or preset:NAME")
    p_validate.set_defaults(run=_cmd_validate)
    p_report = sub.add_parser("report", help="solve a scene and write the printable report "
                                             "(HTML or PDF)",
                              parents=[memory])
    p_report.add_argument("scene", help="scene file (JSON), '-' (standard input) or "
                                        "preset:NAME")
    p_report.add_argument("--output", "-o", metavar="PATH", required=True,
                          help="report file: .html (self-contained, Bokeh plots) or .pdf; "
                               "'-' writes to standard output (--format, default html)")
    p_report.add_argument("--format", choices=("html", "pdf"),
                          help="format of --output (default: from its extension)")
    p_report.add_argument("--time", type=float, metavar="DAYS",
                          help="days after loading: the report describes the contact at "
                               "the output time nearest to it and draws its q(x) (default: "
                               "the last output time)")
    p_report.add_argument("--strict", action="store_true",
                          help=f"exit with {EXIT_DESIGN_FAILED} when a limit is exceeded, "
                               f"{EXIT_FLAGGED} when the answer is flagged (the report is "
                               "written all the same)")
    p_report.add_argument("--fe-check", action="store_true",
                          help="also run the finite-element check of the coating model at "
                               "loading (as 'check': ~1 s, up to ~20 s where the punch lifts "
                               "off) and report its measured error "
                               "next to the estimate; the measurement decides the "
                               "model_error flag")
    p_report.set_defaults(run=_cmd_report)
    p_preset = sub.add_parser("preset", help="list the shipped scenes, or write one as a "
                                             "scene file to start from")
    p_preset.add_argument("name", nargs="?", help="the preset ("
                          + ", ".join(preset_names()) + "); without it, the list")
    p_preset.add_argument("--output", "-o", metavar="FILE.json",
                          help="where to write it (default: standard output); an existing "
                               "file is kept unless --force")
    p_preset.add_argument("--force", action="store_true",
                          help="replace an existing --output file")
    p_preset.set_defaults(run=_cmd_preset)
    p_schema = sub.add_parser("schema", help="print the JSON Schema of scene or study files")
    p_schema.add_argument("kind", nargs="?", choices=tuple(SCHEMA_FILES), default="scene",
                          help="which files (default: scene)")
    p_schema.set_defaults(run=_cmd_schema)
    p_sweep = sub.add_parser("sweep", help="run a design study (format: 'Study files' in "
                                           "the file formats) on Dask",
                             parents=[memory])
    p_sweep.add_argument("study", help="study file (JSON) or preset:NAME, one of the "
                                       "shipped studies ("
                                       + ", ".join(study_names()) + ")")
    p_sweep.add_argument("--output", "-o", metavar="PATH", required=True,
                         help="result file: .nc (xarray dataset), .csv or .parquet (a row "
                              "per point and time)")
    p_sweep.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                         help="an existing Dask scheduler (default: the Dask config's "
                              "scheduler-address, else a local cluster on all cores)")
    p_sweep.add_argument("--work-dir", metavar="DIR",
                         help="keep the finished batches here (default: OUTPUT.parts, "
                              "removed when the study is complete); an interrupted study "
                              "resumes from it")
    p_sweep.add_argument("--batch-points", type=int, metavar="N",
                         help="points per task (default: about 64 tasks, at most 500 points "
                              "each)")
    p_sweep.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    p_sweep.set_defaults(run=_cmd_sweep)
    p_cal = sub.add_parser("calibrate", help="fit scene fields to measured settlements and "
                                             "tilts (back-analysis) and forecast them",
                           parents=[memory])
    p_cal.add_argument("scene", help="scene file (JSON), '-' (standard input) or "
                                     "preset:NAME; its values start the fit")
    p_cal.add_argument("readings", help="readings file: CSV (time [day], settlement [m], "
                                        "tilt [rad], optional *_std columns, units in the "
                                        "header) or JSON; '-' reads standard input")
    p_cal.add_argument("--fit", action="append", required=True, metavar="PATH",
                       help="a scene field to fit, by its path (coating[0].modulus, "
                            "base.creep.relative_humidity, base.age_at_loading, ...); "
                            "repeat for more")
    p_cal.add_argument("--bound", action="append", metavar="PATH=LOW,HIGH",
                       help="bounds of a fitted field in its unit (an empty end is none)")
    p_cal.add_argument("--forecast", type=float, metavar="DAYS",
                       help="also forecast the settlement and tilt to this many days after "
                            "loading with a 95 %% band (written with --output)")
    p_cal.add_argument("--forecast-count", type=int, default=100, metavar="N",
                       help="log-spaced times of the forecast (default 100)")
    p_cal.add_argument("--output", "-o", metavar="PATH",
                       help="write the fit as JSON (fields, standard errors, correlation, "
                            "residuals, the fitted scene, the forecast); '-' writes to "
                            "standard output")
    p_cal.add_argument("--report", metavar="FILE",
                       help="also write the printable report of the fitted scene with the "
                            "back-analysis (.html or .pdf)")
    p_cal.add_argument("--strict", action="store_true",
                       help=f"exit with {EXIT_FLAGGED} when the fit carries a warning (a "
                            "field not identifiable, a bound reached, the solver's error "
                            "near the noise)")
    p_cal.set_defaults(run=_cmd_calibrate)
    p_check = sub.add_parser("check", help="model error of the fast answer against a "
                                           "resolved finite-element model of the coating",
                             parents=[memory])
    p_check.add_argument("scene", help="scene file (JSON), '-' (standard input) or "
                                       "preset:NAME")
    p_check.add_argument("--time", type=float, default=0.0, metavar="DAYS",
                         help="days after loading: base modulus and given loads (default 0)")
    p_check.add_argument("--level", type=int, choices=(0, 1), default=FE_CHECK_LEVEL,
                         help="FE mesh level: 0 (~1 s, force to ~2e-4; up to ~20 s where the punch "
                              "lifts off: the FE model finds its contact too) or 1 "
                              "(~10 s, ~2e-5; longer where it lifts off)")
    p_check.set_defaults(run=_cmd_check)
    return parser


class _Terminated(KeyboardInterrupt):
    """A run asked to stop by SIGTERM: stopped as an interrupt is (a study's cluster
    closed on the way out; it left "leaked semaphore objects" warnings and exit -15)."""


def _terminate(signum: int, frame: Any) -> None:
    raise _Terminated


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); returns the exit code."""
    global _MEMORY_BOUND, _MEMORY_ASKED
    if argv is None:
        # run as a program: SIGTERM stops it as Ctrl-C does (never a caller's handler)
        signal.signal(signal.SIGTERM, _terminate)
    try:
        try:
            args = build_parser().parse_args(argv)
        except SystemExit:
            sys.stdout.flush()  # (--version, --help: as below, a reader that left)
            raise
        if argv is None and getattr(args, "max_memory", None) is not None:
            # run as a program: its own process (never a caller's Python session)
            _MEMORY_BOUND = bound_memory(int(args.max_memory * 2**30))
            _MEMORY_ASKED = float(args.max_memory)
        code = int(args.run(args))
        # what print() left in the buffer is written here, where a reader that left is
        # caught (at exit it read "Exception ignored ... BrokenPipeError", exit 120)
        sys.stdout.flush()
        return code
    except _InputError as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except MissingDependency as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_SOLVER_FAILED
    except _Terminated:
        print("error: terminated", file=sys.stderr)
        return 128 + signal.SIGTERM
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader of standard output left (``| head``): no message (it read "internal
        # error"), the shell's code of a closed pipe, and nothing more written to it
        # (Python's flush at exit would raise again)
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(devnull, sys.stdout.fileno())
            finally:
                os.close(devnull)
        except (OSError, ValueError):  # (a stdout without a descriptor: a caller's)
            pass
        return EXIT_BROKEN_PIPE
    except Exception as exc:  # the promise is one line on stderr, never a traceback
        print(f"error: internal error ({type(exc).__name__}: {_one_line(exc)}); please "
              "report it with the scene file", file=sys.stderr)
        return EXIT_SOLVER_FAILED
