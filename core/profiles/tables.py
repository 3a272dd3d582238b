"""Profiles from uploaded CSV files: two numeric columns read strictly into a ``table``
profile (:func:`core.profiles.profile_from_spec`), with limits on size, rows and jumps.

``from core.profiles.build import profile_from_csv`` stays the public path.
"""

from __future__ import annotations

import math
import re

from core import limits
from core.profiles.base import MAX_TABLE_BYTES, MAX_TABLE_ROWS, Profile, _fmt, _json_type
from core.profiles.build import profile_from_spec

# Unambiguous (no nested quantifiers), so matching is linear in the cell length.
_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


def _split(line: str, separator: str | None) -> list[str]:
    if separator is None:
        cells = line.split()
    else:
        cells = [c.strip() for c in line.split(separator)]
        while cells and cells[-1] == "":  # spreadsheets often end rows with a separator
            cells.pop()
    if separator == ";":
        # semicolon files come from locales that write a decimal comma
        cells = [c.replace(",", ".") for c in cells]
    return cells


def _cell_number(cell: str) -> float | None:
    if len(cell) > 400 or not _NUMBER.fullmatch(cell):
        return None
    return float(cell)




def profile_from_csv(data: bytes | str, *, field: str, variable: str = "x",
                     domain: tuple[float, float], interpolation: str = "linear",
                     max_bytes: int = MAX_TABLE_BYTES, max_rows: int = MAX_TABLE_ROWS,
                     max_breakpoints: int | None = None) -> Profile:
    """A table profile from an uploaded CSV file of two numeric columns.

    Columns: the variable (unit of the variable) and the value (unit of the quantity).
    Cells are separated by commas, semicolons (then a decimal comma is accepted) or
    white space; one header line is allowed; blank lines are skipped. The result is the
    ``table`` profile with ``interpolation``. Raises ValueError naming ``field`` and the
    1-based line for: a file over ``max_bytes`` bytes, over ``max_rows`` data rows, fewer
    than 2 rows, a wrong number of columns, a cell that is not a number, values not
    strictly increasing in the variable; and naming the limit for a table with more
    than ``max_breakpoints`` points inside the domain where its value or slope jumps
    (default: :data:`core.limits.MAX_BREAKPOINTS` for an x-profile, which the solver
    allows for a whole scene, so such a table could never be solved; none for ``t``).
    """
    if isinstance(data, (bytes, bytearray, memoryview)):
        raw = bytes(data)
        if len(raw) > max_bytes:
            raise ValueError(f"{field}: file is too large ({len(raw)} bytes, at most "
                             f"{max_bytes})")
        if b"\x00" in raw:
            raise ValueError(f"{field}: file is not text (upload a plain CSV file)")
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            # only the header can hold non-ASCII text, and it is not used
            text = raw.decode("latin-1")
    elif isinstance(data, str):
        if len(data) > max_bytes or len(data.encode("utf-8", "replace")) > max_bytes:
            raise ValueError(f"{field}: file is too large (more than {max_bytes} bytes)")
        text = data.removeprefix("\ufeff")
    else:
        raise ValueError(f"{field}: file content must be bytes or text, not "
                         f"{_json_type(data)}")

    lines = [(n, line.strip()) for n, line in enumerate(text.splitlines(), start=1)]
    lines = [(n, line) for n, line in lines if line]
    if not lines:
        raise ValueError(f"{field}: file is empty")
    first = lines[0][1]
    separator = ";" if ";" in first else "," if "," in first else None
    first_cells = _split(first, separator)
    header = not first_cells or any(_cell_number(c) is None for c in first_cells)
    if header:
        lines = lines[1:]  # a header; later lines must all be data
        if lines:
            first = lines[0][1]
            separator = ";" if ";" in first else "," if "," in first else None
    if len(lines) > max_rows:
        raise ValueError(f"{field}: file has too many rows ({len(lines)}, at most "
                         f"{max_rows})")
    if len(lines) < 2:
        # a line of words after the header is named as such (two lines of words read
        # "needs at least 2 data rows, has 1", which did not say what was wrong)
        for n, line in lines:
            for column, cell in enumerate(_split(line, separator), start=1):
                if _cell_number(cell) is None:
                    shown = cell if len(cell) <= 40 else cell[:40] + "..."
                    raise ValueError(f"{field}: line {n}, column {column}: {shown!r} is "
                                     "not a number")
        said = " (its first line, not numbers, is read as a header)" if header else ""
        raise ValueError(f"{field}: file needs at least 2 data rows, has {len(lines)}{said}")

    points: list[list[float]] = []
    for n, line in lines:
        cells = _split(line, separator)
        row = []
        for column, cell in enumerate(cells, start=1):
            value = _cell_number(cell)
            if value is None:
                shown = cell if len(cell) <= 40 else cell[:40] + "..."
                raise ValueError(f"{field}: line {n}, column {column}: {shown!r} is not a "
                                 "number")
            if not math.isfinite(value):
                raise ValueError(f"{field}: line {n}, column {column}: {cell[:40]!r} is out "
                                 "of range")
            row.append(value)
        if len(row) != 2:
            shown = "white space" if separator is None else repr(separator)
            raise ValueError(f"{field}: line {n}: expected 2 columns separated by {shown}, "
                             f"found {len(row)}")
        if points and not row[0] > points[-1][0]:
            raise ValueError(f"{field}: {variable} values must be strictly increasing "
                             f"(line {n}: {_fmt(row[0])} after {_fmt(points[-1][0])})")
        points.append(row)
    profile = profile_from_spec({"kind": "table", "points": points,
                                 "interpolation": interpolation},
                                field=field, variable=variable, domain=domain)
    if max_breakpoints is None and variable == "x":
        max_breakpoints = limits.MAX_BREAKPOINTS
    jumps = len(profile.breakpoints)
    if max_breakpoints is not None and jumps > max_breakpoints:
        raise ValueError(
            f"{field}: a table of {len(points)} rows with {interpolation!r} interpolation "
            f"has {jumps} points inside the domain where its value or slope jumps, more "
            f"than the {max_breakpoints} the solver allows in a whole scene: use at most "
            f"{max_breakpoints} rows inside the domain, or 'pchip' interpolation (smooth "
            "between its end rows)")
    return profile
