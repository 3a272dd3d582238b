"""Measured readings of a loaded footing: times [day after loading] with settlements [m]
and/or tilts [rad], optionally with the standard deviation of each reading.

:func:`read_readings` reads a CSV or JSON file (format in ``core/SCENES.md``, "Readings
files"), :func:`readings_from_mapping` a mapping of lists; both give :class:`Readings`
in SI units or a ``ValueError`` naming the row and the column (``readings.csv: line 7,
column settlement: ...``, ``settlement[3]: ...``).
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from core.files import read_regular_file
from core.limits import DAYS_PER_YEAR, MAX_READINGS, MAX_READINGS_BYTES
from core.validation import finite_number, show_value

#: The series a readings file may hold, with their SI units.
SERIES_UNITS: dict[str, str] = {"settlement": "m", "tilt": "rad"}
#: Columns of a readings file: the time, each series and its standard deviation.
COLUMNS = ("time", "settlement", "settlement_std", "tilt", "tilt_std")
#: Units a column may be given in, as factors to SI (time to days).
UNIT_FACTORS: dict[str, dict[str, float]] = {
    "time": {"day": 1.0, "days": 1.0, "d": 1.0, "h": 1 / 24, "hour": 1 / 24,
             "hours": 1 / 24, "week": 7.0, "weeks": 7.0, "year": DAYS_PER_YEAR,
             "years": DAYS_PER_YEAR, "a": DAYS_PER_YEAR},
    "settlement": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6},
    "tilt": {"rad": 1.0, "mrad": 1e-3, "urad": 1e-6, "µrad": 1e-6, "μrad": 1e-6,
             "deg": math.pi / 180, "°": math.pi / 180},
}
#: Largest settlement reading [m]: a punch that sinks 10 m is no small-strain problem;
#: a larger number is almost surely given in the wrong unit (mm read as m).
MAX_SETTLEMENT = 10.0
#: Largest tilt reading [rad] (about 29 degrees): beyond any small-angle model.
MAX_TILT = 0.5
#: Latest reading [day after loading]: 1000 years.
MAX_TIME = 1000 * DAYS_PER_YEAR
#: ``name [unit]`` or ``name (unit)`` in a header cell.
_HEADER = re.compile(r"\s*([A-Za-z_]+)\s*(?:[\[(]\s*([^\])]*?)\s*[\])])?\s*")
#: Columns of this program's own history files that are not readings (forces, moments,
#: the contact zone, flags): a history written by ``solve`` or the explorer reads as
#: readings with these left out.
_OUTPUT_COLUMNS = re.compile(r"\s*(force|moment|contact|lifted|lift_off|zone\d+)(_.*)?\s*"
                             r"|\s*flags\s*", re.IGNORECASE)
_MAX_RANGE = {"settlement": MAX_SETTLEMENT, "tilt": MAX_TILT}


@dataclass(frozen=True)
class Readings:
    """Readings in SI units, sorted by time.

    ``time`` [day after loading]; ``settlement`` [m] and ``tilt`` [rad] are arrays of the
    length of ``time`` with NaN where a row has no reading of that series (None when
    the series is absent); ``settlement_std`` [m] and ``tilt_std`` [rad] the standard
    deviation of each reading (None when not given). ``source`` names where they came
    from, in messages.
    """

    time: np.ndarray
    settlement: np.ndarray | None
    tilt: np.ndarray | None
    settlement_std: np.ndarray | None
    tilt_std: np.ndarray | None
    source: str = "readings"

    @property
    def series(self) -> tuple[str, ...]:
        """The series present, in the order of :data:`SERIES_UNITS`."""
        return tuple(name for name in SERIES_UNITS if getattr(self, name) is not None)

    @property
    def count(self) -> int:
        """The number of readings (settlements and tilts together)."""
        return sum(int(np.isfinite(getattr(self, name)).sum()) for name in self.series)

    @property
    def has_std(self) -> bool:
        """Whether every series present gives its standard deviations."""
        return all(getattr(self, f"{name}_std") is not None for name in self.series)

    def to_dict(self) -> dict[str, Any]:
        """The readings as lists (None where a row has no reading) with their units."""
        out: dict[str, Any] = {"time": self.time.tolist()}
        units = {"time": "day"}
        for name in self.series:
            for key in (name, f"{name}_std"):
                value = getattr(self, key)
                if value is not None:
                    out[key] = [None if math.isnan(v) else float(v) for v in value]
                    units[key] = SERIES_UNITS[name]
        return out | {"units": units}


# ------------------------------------------------------------------------- checks


def _column(cell: str) -> tuple[str | None, str | None]:
    """The column and its unit of a header cell: ``name``, ``name [unit]``, ``name
    (unit)`` or ``name_unit`` as this program writes its histories (``time_day``,
    ``settlement_m``, ``tilt_mrad``); (None, None) for anything else."""
    match = _HEADER.fullmatch(cell)
    if match is None:
        return None, None
    name = match.group(1).lower()
    if name in COLUMNS:
        return name, match.group(2)
    if match.group(2) is None and "_" in name:
        base, unit = name.rsplit("_", 1)
        kind = "time" if base == "time" else base.removesuffix("_std")
        if base in COLUMNS and unit in UNIT_FACTORS[kind]:
            return base, unit
    return None, None


def _unit_factor(column: str, unit: str | None, where: str) -> float:
    kind = "time" if column == "time" else column.removesuffix("_std")
    if unit is None or unit == "":
        return 1.0
    factors = UNIT_FACTORS[kind]
    if unit not in factors:
        raise ValueError(f"{where}: unknown unit {unit!r} for {column} (known: "
                         f"{', '.join(factors)})")
    return factors[unit]


def _check_values(columns: Mapping[str, list[float | None]], where: Any) -> Readings:
    """Readings from columns of numbers in SI units (None: no reading), checked;
    ``where(column, i)`` names row ``i`` of a column in messages."""
    if "time" not in columns:
        raise ValueError(f"{where('time', None)}: required (days after loading)")
    series = [name for name in SERIES_UNITS if name in columns]
    if not series:
        raise ValueError(f"{where('settlement', None)}: give settlement [m] and/or tilt "
                         "[rad] readings")
    for name in SERIES_UNITS:
        if f"{name}_std" in columns and name not in columns:
            raise ValueError(f"{where(name + '_std', None)}: standard deviations without "
                             f"{name} readings")
    time = columns["time"]
    n = len(time)
    if n == 0:
        raise ValueError(f"{where('time', None)}: no readings")
    if n > MAX_READINGS:
        raise ValueError(f"{where('time', None)}: at most {MAX_READINGS} readings (each is "
                         f"an output time of every solve of the fit), got {n}")
    for i, t in enumerate(time):
        if t is None:
            raise ValueError(f"{where('time', i)}: missing (every row needs its time)")
        if not 0.0 <= t <= MAX_TIME:
            raise ValueError(f"{where('time', i)}: must be in [0, {MAX_TIME:g}] days after "
                             f"loading, got {show_value(t)}")
        if i and t == time[i - 1]:
            raise ValueError(f"{where('time', i)}: {t:g} days repeats the previous row's "
                             "time (one row per time: put its settlement and tilt in one "
                             "row)")
        if i and t < time[i - 1]:
            raise ValueError(f"{where('time', i)}: {t:g} days comes before the previous "
                             f"row's {time[i - 1]:g} days (rows must be in time order)")
    arrays: dict[str, np.ndarray | None] = {}
    for name in SERIES_UNITS:
        values = columns.get(name)
        stds = columns.get(f"{name}_std")
        if values is None:
            arrays[name] = arrays[f"{name}_std"] = None
            continue
        for i, v in enumerate(values):
            if v is not None and not abs(v) <= _MAX_RANGE[name]:
                raise ValueError(f"{where(name, i)}: must be at most {_MAX_RANGE[name]:g} "
                                 f"{SERIES_UNITS[name]} in size, got {show_value(v)} (a "
                                 "reading in another unit? give it in the header, e.g. "
                                 f"'{name} [{'mm' if name == 'settlement' else 'urad'}]')")
            if stds is not None:
                s = stds[i]
                if v is not None and s is None:
                    raise ValueError(f"{where(name + '_std', i)}: missing for the {name} "
                                     "reading of this row")
                if s is not None and not s > 0:
                    raise ValueError(f"{where(name + '_std', i)}: must be > 0, got "
                                     f"{show_value(s)}")
        arrays[name] = np.array([np.nan if v is None else v for v in values], dtype=float)
        arrays[f"{name}_std"] = None if stds is None else \
            np.array([np.nan if s is None else s for s in stds], dtype=float)
    for i in range(n):
        if all(columns[name][i] is None for name in series):
            raise ValueError(f"{where(series[0], i)}: the row has no reading")
    return Readings(np.array(time, dtype=float), arrays["settlement"], arrays["tilt"],
                    arrays["settlement_std"], arrays["tilt_std"])


def _number(value: Any, field: str) -> float | None:
    """A reading's number (None: no reading); a ValueError naming ``field`` otherwise."""
    return None if value is None else finite_number(value, field)


# --------------------------------------------------------------------------- mapping


def readings_from_mapping(data: Mapping[str, Any], source: str = "readings") -> Readings:
    """Readings from a mapping of lists: ``time`` [day after loading], ``settlement``
    [m] and/or ``tilt`` [rad]; optionally ``settlement_std`` / ``tilt_std`` (a list or
    one number for every reading) and ``units`` (``{"settlement": "mm", ...}``, the
    units of the lists; SI and days by default). ``None`` in a list marks a row without
    that reading. Raises ValueError naming the entry (``settlement[3]: ...``)."""
    if not isinstance(data, Mapping):
        raise ValueError(f"{source}: must be an object of lists (time, settlement, tilt, "
                         f"...), got {show_value(data)}")
    unknown = [k for k in data if k not in COLUMNS and k != "units"]
    if unknown:
        raise ValueError(f"{unknown[0]}: unknown field (known: {', '.join(COLUMNS)}, units)")
    units = data.get("units", {})
    if not isinstance(units, Mapping):
        raise ValueError(f"units: must be an object such as {{\"settlement\": \"mm\"}}, "
                         f"got {show_value(units)}")
    for key in units:
        if key not in COLUMNS:
            raise ValueError(f"units.{key}: unknown column (known: {', '.join(COLUMNS)})")
    columns: dict[str, list[float | None]] = {}
    scalar_std: dict[str, float] = {}
    for key in COLUMNS:
        if key not in data:
            continue
        value = data[key]
        if isinstance(value, np.ma.MaskedArray):
            # a masked entry is a row without that reading (np.asarray would read the
            # value under the mask as one)
            under, hidden = np.ma.getdata(value), np.ma.getmaskarray(value)
            value = (None if hidden.item() else under.item()) if value.ndim == 0 else [
                None if m else v for v, m in zip(under.tolist(), hidden.tolist(),
                                                 strict=True)]
        elif hasattr(value, "__array__") and not isinstance(value, (str, bytes)):
            # an array of any kind (numpy's 0-d array for one deviation, a table's column)
            value = np.asarray(value)
            value = value.item() if value.ndim == 0 else value
        unit = units.get(key, units.get(key.removesuffix("_std")))
        if unit is not None and not isinstance(unit, str):
            raise ValueError(f"units.{key}: must be a unit name, got {show_value(unit)}")
        factor = _unit_factor(key, unit, f"units.{key}")
        if key.endswith("_std") and not isinstance(value, (list, tuple, np.ndarray)):
            std = _number(value, key)
            if std is not None:
                scalar_std[key] = std * factor  # one deviation for every reading
            continue
        if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple,
                                                                      np.ndarray)):
            raise ValueError(f"{key}: must be a list of numbers, got {show_value(value)}")
        if len(value) > MAX_READINGS:
            raise ValueError(f"{key}: at most {MAX_READINGS} readings, got {len(value)}")
        column = [_number(v, f"{key}[{i}]") for i, v in enumerate(value)]
        if "time" in columns and len(column) != len(columns["time"]):
            raise ValueError(f"{key}: has {len(column)} entries, time has "
                             f"{len(columns['time'])} (one per reading time)")
        columns[key] = [None if v is None else v * factor for v in column]
    for key, std in scalar_std.items():
        series = columns.get(key.removesuffix("_std"))
        if series is not None:
            columns[key] = [None if v is None else std for v in series]
        else:
            columns[key] = []  # refused below: deviations without their readings

    def where(column: str, i: int | None) -> str:
        return column if i is None else f"{column}[{i}]"

    readings = _check_values(columns, where)
    return _with_source(readings, source)


def _with_source(readings: Readings, source: str) -> Readings:
    return Readings(readings.time, readings.settlement, readings.tilt,
                    readings.settlement_std, readings.tilt_std, source)


# ------------------------------------------------------------------------------ CSV


def readings_from_csv(text: str, source: str = "readings.csv") -> Readings:
    """Readings from CSV text: ``#`` lines are comments; the first other line is the
    header, naming the columns (``time``, ``settlement``, ``settlement_std``, ``tilt``,
    ``tilt_std``) each with an optional unit (``settlement [mm]`` or ``settlement_mm``; a
    ``_std`` column without one takes its series' unit); an empty cell is no reading.
    The histories this program writes read as they are (their force, moment, contact
    and flag columns are left out). Raises ValueError naming the line and the column."""
    lines = [(k + 1, line) for k, line in enumerate(text.splitlines())
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise ValueError(f"{source}: no header line (e.g. 'time [day], settlement [m]')")
    head_line, head = lines[0]
    names: list[str] = []
    units: dict[str, str | None] = {}
    skipped: set[int] = set()
    for k, cell in enumerate(next(csv.reader([head]))):
        if _OUTPUT_COLUMNS.fullmatch(cell):
            skipped.add(k)
            continue
        name, unit = _column(cell)
        if name is None:
            raise ValueError(f"{source}: line {head_line}, column {k + 1}: unknown column "
                             f"{cell.strip()!r} (known: {', '.join(COLUMNS)}, each with "
                             "an optional unit as 'settlement [mm]' or 'settlement_mm')")
        if name in names:
            raise ValueError(f"{source}: line {head_line}, column {name}: given twice")
        names.append(name)
        units[name] = unit
    factors = {}
    for name in names:
        unit = units[name]
        if name.endswith("_std") and not unit:
            unit = units.get(name.removesuffix("_std"))
        factors[name] = _unit_factor(name, unit,
                                     f"{source}: line {head_line}, column {name}")
    rows = lines[1:]
    if len(rows) > MAX_READINGS:
        raise ValueError(f"{source}: at most {MAX_READINGS} readings (each is an output "
                         f"time of every solve of the fit), got {len(rows)} rows")
    columns: dict[str, list[float | None]] = {name: [] for name in names}
    width = len(names) + len(skipped)
    for line_no, line in rows:
        cells = next(csv.reader([line]))
        if len(cells) != width:
            raise ValueError(f"{source}: line {line_no}: {len(cells)} cells, the header "
                             f"names {width} columns")
        cells = [cell for k, cell in enumerate(cells) if k not in skipped]
        for name, cell in zip(names, cells, strict=True):
            text_value = cell.strip()
            if not text_value:
                columns[name].append(None)
                continue
            try:
                value = float(text_value)
            except ValueError:
                raise ValueError(f"{source}: line {line_no}, column {name}: not a number: "
                                 f"{text_value[:40]!r}") from None
            if not math.isfinite(value):
                raise ValueError(f"{source}: line {line_no}, column {name}: must be a "
                                 f"finite number, got {text_value[:40]!r}")
            columns[name].append(value * factors[name])
    line_of = [line_no for line_no, _ in rows]

    def where(column: str, i: int | None) -> str:
        if i is None:
            return f"{source}: column {column}"
        return f"{source}: line {line_of[i]}, column {column}"

    return _with_source(_check_values(columns, where), source)


# ----------------------------------------------------------------------------- files


def readings_from_text(text: str, source: str = "readings") -> Readings:
    """Readings from the text of a CSV or JSON readings file (JSON when it starts with
    ``{``)."""
    if text.lstrip().startswith("{"):
        from core.scene import read_scene_json  # the strict JSON reader of scene files

        data = read_scene_json(text, source)
        try:
            return readings_from_mapping(data, source)
        except ValueError as exc:
            raise ValueError(f"{source}: {exc}") from None
    return readings_from_csv(text, source)


def read_readings(path: str | os.PathLike) -> Readings:
    """Read a readings file: CSV, or JSON holding the mapping of
    :func:`readings_from_mapping` (by its content). At most
    :data:`core.limits.MAX_READINGS_BYTES`."""
    raw = read_regular_file(path, MAX_READINGS_BYTES)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file in UTF-8 (readings are CSV or JSON)") \
            from None
    return readings_from_text(text, str(path))


def as_readings(measurements: Readings | Mapping[str, Any] | str | os.PathLike
                ) -> Readings:
    """:class:`Readings` from readings, a mapping of lists, or the path of a file."""
    if isinstance(measurements, Readings):
        return measurements
    if isinstance(measurements, Mapping):
        return readings_from_mapping(measurements)
    if isinstance(measurements, (str, os.PathLike)):
        return read_readings(Path(measurements))
    raise ValueError(f"measurements: must be a readings file's path or a mapping of lists "
                     f"(time, settlement, tilt), got {type(measurements).__name__}")


def readings_csv(columns: Mapping[str, Sequence[float]]) -> str:
    """CSV text of readings columns in SI units (the format :func:`readings_from_csv`
    reads), for writing synthetic records."""
    names = [name for name in COLUMNS if name in columns]
    out = io.StringIO()
    out.write(", ".join(f"{name} [{'day' if name == 'time' else SERIES_UNITS[name.removesuffix('_std')]}]"  # noqa: E501
                        for name in names) + "\n")
    for row in zip(*(columns[name] for name in names), strict=True):
        out.write(", ".join("" if v is None or (isinstance(v, float) and math.isnan(v))
                            else repr(float(v)) for v in row) + "\n")
    return out.getvalue()
