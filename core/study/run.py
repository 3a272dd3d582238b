"""Running a design study (:mod:`core.study.definition`) on Dask, resumable, with bounded memory.

:func:`sweep` (exported as ``core.sweep``) expands a study into points, orders them so
that points sharing a geometry (every varied field but the loads) are neighbours, cuts
them into batches and runs each batch as one task: inside a task the points run in
order, so the solver's cached geometric stages (panels, operator, basis, Galerkin
matrices) are prepared once per geometry and a load-only variation costs a few array
operations. When only given loads vary (``loading.force``, ``loading.moment``, ...), a
batch validates the base scene once and builds each point's scene by replacing its loads
(:func:`core.scene.replace_loads`, the same checks and messages); when the
exact layered kernel answers the scene and the loads are constants, the batch's
full-contact points are answered at once (:func:`core.study.solve_load_batch`: the
problem is linear in the loads) and only the others are solved one by one, one per
eccentricity ``M / P`` on a flat punch over an elastic base (the others of that
eccentricity scaled from it; batches follow the eccentricity when force and moment both
vary), and a batch's many lift-off eccentricities are answered as one family, their zone
ends located along a Chebyshev interpolant (:mod:`core.study.liftoff`). A point that
fails (an invalid scene drawn from a distribution, a solver error) is recorded with its
message; it never stops the study.

The points and the batches are made batch by batch from the study's description
(:class:`core.study.definition.StudyPoints`, :class:`core.study.BatchPlan`): the client holds no
array over all the points, whatever the study's size.

Each finished batch is written atomically to a work directory (``parts/batch_NNNNNN.npz``
next to a ``manifest.json`` naming the study), so a study that was interrupted (a killed
process, a lost worker) resumes from what was written, and the results stream to disk
rather than into memory. The result is an ``xarray.Dataset`` over ``point`` and ``time``
with units in its attributes (see :func:`study_dataset`) and the package version, the
study, the base scene and the solver settings in the dataset's (:func:`study_metadata`,
also in a parquet file's metadata); ``.csv`` and ``.parquet``
outputs are written batch by batch in long form, ``.nc`` (netCDF 3, scipy engine) from
the assembled dataset.

Dask, distributed and xarray are imported only when a study runs: ``import core`` and
``python -m core solve`` do not load them.
"""

from __future__ import annotations

import json
import math
import os
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from core.files import atomic_write_text
from core.optional import import_optional
from core.scene import FLAG_MESSAGES
from core.study.batch import run_batch
from core.study.definition import (
    LIMITS_NOT_CHECKED,
    OUTPUT_NAMES,
    PUNCH_OUTPUT,
    Study,
    field_unit,
    load_study,
    output_unit,
)
from core.study.plan import PLAN_ORDER, BatchPlan, batch_plan
from core.study.points import StudyPoints, point_table
from core.version import VERSION

if TYPE_CHECKING:
    import xarray

#: Most points in one batch (one task). Small enough that a lost task costs little and
#: the workers share the work evenly, large enough that a load-only batch amortizes the
#: task overhead (a load-only point solves in ~3 ms one by one, ~0.1 ms in a batch of
#: full-contact points, 18 ms when it lifts off).
MAX_BATCH_POINTS = 500
#: Batches the default plan aims at (more batches than workers balance the load).
TARGET_BATCHES = 64
#: Batches in flight per worker thread: bounds the results held in memory at once.
BATCHES_IN_FLIGHT_PER_THREAD = 3
#: Known flags, each recorded as a boolean per point.
FLAG_NAMES = tuple(FLAG_MESSAGES)
_MANIFEST_FORMAT = "coated-punch study parts"

class StudyInterrupted(RuntimeError):
    """A study stopped before its end (cancelled); what was finished is in the work
    directory and a new :func:`sweep` with the same ``work_dir`` resumes from it."""


# ------------------------------------------------------------------------- planning


def default_batch_points(n_points: int) -> int:
    """Points per batch for a study of ``n_points``: about :data:`TARGET_BATCHES` batches."""
    return max(1, min(MAX_BATCH_POINTS, math.ceil(n_points / TARGET_BATCHES)))


# ---------------------------------------------------------------------- work directory


class WorkDir:
    """The parts of one study on disk: ``manifest.json`` and one ``.npz`` per batch."""

    def __init__(self, path: str | os.PathLike, study: Study, batch_points: int,
                 durable: bool = True) -> None:
        self.path = Path(path)
        # a scratch directory removed at the end serves no resume: no need to wait for
        # the disk after every batch (41 fsyncs were a quarter of the 1.4 s of an
        # 81-point study of the explorer's Study tab, measured at load 8)
        self.durable = durable
        self.parts = self.path / "parts"
        self.parts.mkdir(parents=True, exist_ok=True)
        manifest = self.path / "manifest.json"
        want = {"format": _MANIFEST_FORMAT, "study_key": study.key,
                "n_points": study.n_points, "batch_points": batch_points,
                "plan": batch_plan(study), "order": PLAN_ORDER}
        if manifest.exists():
            have = json.loads(manifest.read_text(encoding="utf-8"))
            if have.get("study_key") != study.key:
                raise ValueError(f"work_dir: {self.path} holds the parts of another study; "
                                 "remove it or choose another directory")
            # parts cut by another plan hold other points under the same batch numbers
            # (parts written before the order was named are in it when a sort of all
            # the points gave the same order)
            order = have.get("order") or ("" if not BatchPlan(
                study, int(have["batch_points"])).same_as_whole_sort else PLAN_ORDER)
            if have.get("plan", "lexicographic") != want["plan"] or order != PLAN_ORDER:
                raise ValueError(f"work_dir: {self.path} holds parts planned in another "
                                 f"order ({have.get('plan', 'lexicographic')}, "
                                 f"{order or 'one sort of all the points'}; now "
                                 f"{want['plan']}, {PLAN_ORDER}); remove it or choose "
                                 "another directory")
            self.batch_points = int(have["batch_points"])
        else:
            atomic_write_text(manifest, json.dumps(want, indent=1) + "\n")
            self.batch_points = batch_points

    def part(self, k: int) -> Path:
        """The file of batch ``k``."""
        return self.parts / f"batch_{k:06d}.npz"

    def done(self, k: int) -> bool:
        """Whether batch ``k`` was written."""
        return self.part(k).exists()

    def write(self, k: int, index: np.ndarray, arrays: Mapping[str, np.ndarray]) -> None:
        """Write batch ``k`` atomically (a temporary file renamed into place)."""
        fd, tmp = tempfile.mkstemp(dir=self.parts, prefix=f".batch_{k:06d}.", suffix=".npz")
        try:
            with os.fdopen(fd, "wb") as fh:
                np.savez(fh, index=index, **arrays)
                fh.flush()
                if self.durable:
                    os.fsync(fh.fileno())
            os.replace(tmp, self.part(k))
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise

    def read(self, k: int) -> dict[str, np.ndarray]:
        """The arrays of batch ``k``."""
        with np.load(self.part(k), allow_pickle=False) as data:
            return {name: data[name] for name in data.files}


# -------------------------------------------------------------------------- executors


def _resolve_client(client: Any, scheduler: str | None) -> tuple[Any, Callable[[], None]]:
    """A distributed client and a function that releases what was started here."""
    Client = import_optional("distributed", "a study on Dask").Client  # noqa: N806

    if client is not None:
        return client, lambda: None
    dask = import_optional("dask", "a study on Dask")
    address = scheduler or dask.config.get("scheduler-address", None)
    if address:
        try:
            own = Client(address)
        except (OSError, ValueError, TypeError) as exc:
            # an address that does not answer, or is not one (Dask's own words say which)
            where = "scheduler" if scheduler else "the Dask config's scheduler-address"
            raise ValueError(f"{where}: cannot connect to {address!r} "
                             f"({' '.join(str(exc).split())})") from None
        return own, own.close
    # workers warmed as the cluster starts: imports and shared tables are not paid on
    # each worker's first batch (see core.study.warm)
    from core.study.warm import start_local_cluster

    return start_local_cluster()


def _run_serial(todo: list[int], plan: BatchPlan, job: Callable) -> Iterator[tuple]:
    for k in todo:
        index = plan.batch(k)
        yield k, index, job(index), None


def _run_dask(todo: list[int], plan: BatchPlan, job_args: Callable, client: Any,
              key: str) -> Iterator[tuple]:
    from distributed import as_completed

    threads = sum(client.nthreads().values()) or 1
    window = max(2, BATCHES_IN_FLIGHT_PER_THREAD * threads)
    shared = client.scatter([job_args.shared], broadcast=True)[0]
    pending = iter(todo)
    running = as_completed()
    meta: dict[str, tuple[int, np.ndarray]] = {}

    def submit_next() -> None:
        k = next(pending, None)
        if k is not None:
            item = k, plan.batch(k)
            index = item[1]
            fut = client.submit(_run_shared, shared, job_args.values(index),
                                key=f"study-{key[:12]}-batch-{k}", pure=False, retries=1)
            meta[fut.key] = item
            running.add(fut)

    for _ in range(window):
        submit_next()
    for fut in running:
        k, index = meta.pop(fut.key)
        try:
            yield k, index, fut.result(), None
        except Exception as exc:  # noqa: BLE001 - a lost batch is reported, not fatal
            yield k, index, None, f"{type(exc).__name__}: {' '.join(str(exc).split())}"[:500]
        finally:
            fut.release()
        submit_next()


def _run_shared(shared: Mapping[str, Any], values: np.ndarray) -> dict[str, np.ndarray]:
    return run_batch(shared["base"], shared["paths"], values, shared["outputs"],
                     shared["n_times"])


class _Job:
    """What every batch of one study needs, and its point values."""

    def __init__(self, study: Study, points: StudyPoints) -> None:
        self.paths = [p.path for p in study.parameters]
        self.shared = {"base": study.base, "paths": self.paths, "outputs": study.outputs,
                       "n_times": len(study.times)}
        self.points = points

    def values(self, index: np.ndarray) -> np.ndarray:
        point = self.points(index)
        return np.stack([point[p] for p in self.paths], axis=1)

    def __call__(self, index: np.ndarray) -> dict[str, np.ndarray]:
        return _run_shared(self.shared, self.values(index))


def _terminal_progress(done: int, total: int, started: float) -> None:
    width = 30
    filled = int(width * done / max(total, 1))
    elapsed = time.monotonic() - started
    sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} points, "
                     f"{elapsed:.1f} s")
    if done >= total:
        sys.stderr.write("\n")
    sys.stderr.flush()


# ------------------------------------------------------------------------------ sweep


def sweep(study: Study | Mapping[str, Any] | str | os.PathLike, client: Any = None, *,
          scheduler: str | None = None, work_dir: str | os.PathLike | None = None,
          output: str | os.PathLike | None = None, batch_points: int | None = None,
          progress: bool | Callable[[int, int], Any] = False,
          return_dataset: bool = True) -> xarray.Dataset | dict[str, Any]:
    """Run a study and return its results as an ``xarray.Dataset`` (see :func:`study_dataset`).

    ``study``: a :class:`Study`, a study dict or the path of a study file. ``client``: a
    ``distributed.Client``; ``"serial"`` runs in this process without Dask; ``None``
    connects to ``scheduler`` (``tcp://HOST:PORT``) or to the Dask config's
    ``scheduler-address``, else starts a local cluster (one single-threaded worker process
    per core, warmed before the study: :mod:`core.study.warm`) for the study. ``work_dir``
    keeps the finished batches (default: a temporary directory, removed at the end); with
    the same ``work_dir`` an interrupted study resumes and recomputes nothing already
    written. ``output`` (``.nc``, ``.csv``,
    ``.parquet``) is written at the end. ``progress``: ``True`` draws a bar on stderr; a
    callable gets ``(points done, points in all)`` after every batch and cancels the study
    by returning ``False`` (raising :class:`StudyInterrupted`). With ``return_dataset``
    false only a summary dict is returned (batches, points failed and flagged, seconds),
    and memory stays bounded by a batch for ``.csv``/``.parquet`` outputs.
    """
    from core.study.definition import study_from_dict

    if isinstance(study, (str, os.PathLike)):
        study = load_study(study)
    elif not isinstance(study, Study):
        study = study_from_dict(study)
    if output is not None:
        check_output(Path(output))
    with tempfile.TemporaryDirectory(prefix="study-") as scratch:
        parts = WorkDir(work_dir or scratch, study,
                        batch_points or default_batch_points(study.n_points),
                        durable=work_dir is not None)
        # the points and batches are made batch by batch from the study: the client's
        # memory does not grow with the study (a 1e6-point index was ~32 MB)
        points = StudyPoints(study)
        plan = BatchPlan(study, parts.batch_points, points)
        job = _Job(study, points)
        todo = [k for k in range(plan.n_batches) if not parts.done(k)]
        reused = plan.n_batches - len(todo)
        done = sum(plan.size(k) for k in range(plan.n_batches) if parts.done(k))
        started = time.monotonic()
        lost: dict[int, str] = {}
        release: Callable[[], None] = lambda: None  # noqa: E731
        try:
            if isinstance(client, str) and client == "serial":
                results = _run_serial(todo, plan, job)
            else:
                client, release = _resolve_client(client, scheduler)
                results = _run_dask(todo, plan, job, client, study.key)
            for k, index, arrays, failure in results:
                if arrays is None:
                    lost[k] = failure
                else:
                    parts.write(k, index, arrays)
                done += len(index)
                if progress is True:
                    _terminal_progress(done, study.n_points, started)
                elif callable(progress) and progress(done, study.n_points) is False:
                    raise StudyInterrupted(f"study cancelled after {done} of "
                                           f"{study.n_points} points")
        finally:
            release()
        info = {"batches": plan.n_batches, "batches_reused": reused,
                "batches_computed": len(todo) - len(lost), "batches_lost": len(lost),
                "seconds": time.monotonic() - started} | _counts(parts, plan.n_batches)
        if output is not None:
            write_output(study, parts, plan, lost, Path(output), info)
        if not return_dataset:
            return info
        return study_dataset(study, parts, plan, lost, info)


# ----------------------------------------------------------------------------- results


def _counts(parts: WorkDir, n_batches: int) -> dict[str, int]:
    """Points failed and points flagged (any flag) over the written batches."""
    failed = flagged = 0
    for k in range(n_batches):
        if parts.done(k):
            with np.load(parts.part(k), allow_pickle=False) as data:
                flags = data["flags"]
            failed += int(np.sum(flags == "failed"))
            flagged += int(np.sum((flags != "") & (flags != "failed")))
    return {"points_failed": failed, "points_flagged": flagged}


def check_output(path: Path) -> None:
    """Refuse an output path whose extension is not ``.nc``, ``.csv`` or ``.parquet``, or
    whose directory does not exist (a mistyped one was created, with the study's parts
    beside the output); :class:`core.optional.MissingDependency` for ``.parquet`` without
    pyarrow."""
    if path.suffix.lower() not in (".nc", ".csv", ".parquet"):
        raise ValueError(f"output: unsupported extension {path.suffix!r} (use .nc, .csv or "
                         ".parquet)")
    if not path.parent.is_dir():
        raise ValueError(f"output: the directory {str(path.parent)!r} does not exist (create "
                         "it first, or choose another path)")
    if path.suffix.lower() == ".parquet":
        # before the study, not after it (its points were all solved, then refused)
        import_optional("pyarrow.parquet", "a study's Parquet table")


def _variable_name(path: str) -> str:
    """A netCDF-safe name for a field path: ``coating[0].modulus`` -> ``coating_0_modulus``."""
    return "_".join(part for part in path.replace("[", "_").replace("]", "").split(".")
                    if part)


def _gather(study: Study, parts: WorkDir, plan: BatchPlan,
            lost: Mapping[int, str]) -> dict[str, np.ndarray]:
    n, n_out, n_t = study.n_points, len(study.outputs), len(study.times)
    data = {"values": np.full((n, n_out, n_t), np.nan), "error_estimate": np.full(n, np.nan),
            "seconds": np.zeros(n), "flags": np.full(n, "failed", dtype=object),
            "error": np.full(n, "not computed", dtype=object)}
    for k in range(plan.n_batches):
        if k in lost or not parts.done(k):
            data["error"][plan.batch(k)] = f"not computed: {lost.get(k, 'batch missing')}"
            continue
        arrays = parts.read(k)
        for name in data:
            data[name][arrays["index"]] = arrays[name]
    return data


def study_dataset(study: Study, parts: WorkDir, plan: BatchPlan, lost: Mapping[int, str],
                  info: Mapping[str, Any]) -> xarray.Dataset:
    """The results as an ``xarray.Dataset``: dims ``point`` and ``time`` [day after
    loading]; one coordinate per varied field (named like ``coating_0_modulus``, the field
    path in its ``field`` attribute) and ``sample``; variables: each output over (point,
    time) with ``units`` (a punch's of several named like ``punches_1_tilt``, the output
    in its ``output`` attribute), ``error_estimate`` (relative), ``flags``
    (comma-joined), ``flag_<name>`` (bool: of any punch), ``failed`` (bool), ``error``
    (message), ``solve_seconds``."""
    xr = import_optional("xarray", "a study's dataset")
    data = _gather(study, parts, plan, lost)
    table = point_table(study)  # the dataset holds every point anyway
    coords: dict[str, Any] = {"point": np.arange(study.n_points),
                              "time": ("time", np.asarray(study.times),
                                       {"units": "day", "long_name": "time after loading"})}
    for p in study.parameters:
        coords[_variable_name(p.path)] = ("point", table[p.path],
                                          {"field": p.path, "kind": p.kind,
                                           "units": field_unit(p.path)})
    coords["sample"] = ("point", table["sample"], {"long_name": "index of the random draw"})
    variables: dict[str, Any] = {}
    for j, name in enumerate(study.outputs):
        match = PUNCH_OUTPUT.fullmatch(name)
        attrs = {"units": output_unit(name),
                 "long_name": (f"punches[{match[1]}]: {OUTPUT_NAMES[match[2]]}" if match
                               else OUTPUT_NAMES[name])}
        if _variable_name(name) != name:
            attrs["output"] = name  # a punch's of several: punches[1].tilt
        variables[_variable_name(name)] = (("point", "time"), data["values"][:, j, :], attrs)
    flags = data["flags"].astype(str)
    # a punch's flag of several (punches[1].large_tilt) counts as the flag
    split = [{f.rsplit(".", 1)[-1] for f in flag.split(",")} for flag in flags]
    variables["error_estimate"] = ("point", data["error_estimate"],
                                   {"units": "1", "long_name": "solver's relative error "
                                                               "estimate"})
    variables["flags"] = ("point", flags, {"long_name": "flags, comma-separated"})
    for name in FLAG_NAMES:
        variables[f"flag_{name}"] = ("point", np.array([name in s for s in split]),
                                     {"long_name": FLAG_MESSAGES[name]})
    variables["failed"] = ("point", np.array(["failed" in s for s in split]),
                           {"long_name": "the point has no result (see error)"})
    variables["error"] = ("point", data["error"].astype(str))
    variables["solve_seconds"] = ("point", data["seconds"], {"units": "s"})
    return xr.Dataset(variables, coords=coords, attrs=study_metadata(study, info))


def study_metadata(study: Study, info: Mapping[str, Any]) -> dict[str, Any]:
    """What every result file of a study records besides its values: the package version,
    the study (name, key, its definition as JSON: :meth:`Study.to_dict`), the base scene
    and its solver settings (JSON), the grid's shape, the samples and seed, and ``info``
    (batches, points failed, seconds). Every value is a string or a number (netCDF
    attributes)."""
    attrs = {"format": "coated-punch study", "version": VERSION,
             "study": study.name, "study_key": study.key,
             "study_definition": json.dumps(study.to_dict(), separators=(",", ":")),
             "base_scene": json.dumps(study.base, separators=(",", ":")),
             "solver_settings": json.dumps(study.base.get("solver", {}), sort_keys=True),
             "grid_shape": json.dumps(list(study.grid_shape)),
             "samples": study.samples, "seed": study.seed}
    if study.base.get("limits"):
        attrs["design_limits"] = LIMITS_NOT_CHECKED
    return attrs | dict(info)


def _one_line(value: Any) -> str:
    return " ".join(str(value).split())


def _column_name(name: str, unit: str) -> str:
    """A long-form column: the name and its unit (``coating_0_modulus_Pa``,
    ``loading_force_N_per_m``, ``base_creep_relative_humidity_percent``); a number of
    unit 1, or of no known unit, keeps its name alone."""
    if unit in ("", "1"):
        return name
    text = unit.replace("/", "_per_").replace("%", "percent").replace("^", "").replace(
        "·", "_")
    return f"{name}_{text}"


def _long_rows(study: Study, points: StudyPoints, index: np.ndarray,
               arrays: Mapping[str, np.ndarray] | None, lost: str | None) -> dict[str, Any]:
    """One batch in long form: a row per (point, time)."""
    n_t = len(study.times)
    rows: dict[str, Any] = {"point": np.repeat(index, n_t)}
    point = points(index)
    for p in study.parameters:
        rows[_column_name(_variable_name(p.path), field_unit(p.path))] = np.repeat(
            point[p.path], n_t)
    rows["sample"] = np.repeat(point["sample"], n_t)
    rows["time_day"] = np.tile(np.asarray(study.times), len(index))
    for j, name in enumerate(study.outputs):
        values = np.full((len(index), n_t), np.nan) if arrays is None \
            else arrays["values"][:, j, :]
        rows[_column_name(_variable_name(name), output_unit(name))] = values.reshape(-1)
    estimate = np.full(len(index), np.nan) if arrays is None else arrays["error_estimate"]
    flags = np.full(len(index), "failed") if arrays is None else arrays["flags"]
    error = np.full(len(index), f"not computed: {lost}") if arrays is None else arrays["error"]
    rows["error_estimate"] = np.repeat(estimate, n_t)
    rows["flags"] = np.repeat(flags.astype(str), n_t)
    rows["error"] = np.repeat(error.astype(str), n_t)
    return rows


def write_output(study: Study, parts: WorkDir, plan: BatchPlan, lost: Mapping[int, str],
                 path: Path, info: Mapping[str, Any]) -> None:
    """Write the results to ``path`` atomically: ``.nc`` the dataset of
    :func:`study_dataset`; ``.csv``/``.parquet`` one row per point and time (columns
    ``point``, each varied field and each output with its unit, ``sample``, ``time_day``,
    ``error_estimate``, ``flags``, ``error``), written batch by batch in batch order."""
    suffix = path.suffix.lower()
    directory = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{path.name}.", suffix=suffix)
    os.close(fd)
    try:
        if suffix == ".nc":
            ds = study_dataset(study, parts, plan, lost, info)
            ds.to_netcdf(tmp, engine="scipy")
        else:
            _write_long(study, parts, plan, lost, Path(tmp), suffix,
                        study_metadata(study, info))
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _write_long(study: Study, parts: WorkDir, plan: BatchPlan, lost: Mapping[int, str],
                tmp: Path, suffix: str, attrs: Mapping[str, Any]) -> None:
    writer = None
    # parquet keeps the attributes in its schema: under their own key, and under the one
    # pandas reads back into DataFrame.attrs (pandas.read_parquet)
    text = json.dumps(dict(attrs), allow_nan=True)
    metadata = {"coated_punch": text, "PANDAS_ATTRS": text}
    points = StudyPoints(study)
    with open(tmp, "w" if suffix == ".csv" else "wb") as fh:
        for k in range(plan.n_batches):
            arrays = parts.read(k) if parts.done(k) and k not in lost else None
            index = plan.batch(k) if arrays is None else arrays["index"]
            rows = _long_rows(study, points, index, arrays, lost.get(k, "batch missing"))
            if suffix == ".csv":
                if k == 0:
                    # what made the table, as the other CSV files of the tool say it
                    # (``# key: value``; pandas.read_csv(path, comment="#") skips them)
                    fh.writelines(f"# {key}: {_one_line(value)}\n"
                                  for key, value in attrs.items())
                    fh.write(",".join(rows) + "\n")
                columns = [_csv_column(v) for v in rows.values()]
                fh.writelines(",".join(r) + "\n" for r in zip(*columns, strict=True))
            else:
                pa = import_optional("pyarrow", "a study's Parquet table")
                pq = import_optional("pyarrow.parquet", "a study's Parquet table")

                batch = pa.table(rows).replace_schema_metadata(metadata)
                if writer is None:
                    writer = pq.ParquetWriter(fh, batch.schema)
                writer.write_table(batch)
        if writer is not None:
            writer.close()


def _csv_column(values: np.ndarray) -> list[str]:
    if values.dtype.kind in "iu":
        return [str(int(v)) for v in values]
    if values.dtype.kind == "f":
        return ["" if not math.isfinite(v) else repr(float(v)) for v in values]
    return ['"' + str(v).replace('"', '""') + '"' for v in values]
