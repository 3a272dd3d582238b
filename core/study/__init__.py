"""Design studies: a base scene and fields to vary, solved in batches on Dask.

``sweep(study)`` (``run.py``) runs a study, resumable from its work directory, and
returns an xarray Dataset (netCDF, CSV, parquet).

- ``definition.py``: the study file (grids, distributions), validated, and its points;
- ``points.py``: the points, generated per batch; ``plan.py``: batches sorted by geometry;
- ``batch.py``: one batch of points (geometry shared, loads varied);
- ``loads.py``: a batch whose points differ only in their loads, as one combination of
  unit responses;
- ``liftoff.py``: a batch of lift-off eccentricities as one family;
- ``warm.py``: warming Dask workers when a study's cluster starts;
- ``json_schema.py``: the JSON Schema of study files (``study_json_schema``).
"""

from __future__ import annotations

from core.study.definition import (
    FIELD_UNITS,
    FIXED_ROOTS,
    LIMITS_NOT_CHECKED,
    PUNCH_OUTPUT,
    Study,
    apply_point,
    field_unit,
    get_field,
    load_study,
    number_at,
    numeric_fields,
    parse_path,
    study_from_dict,
)
from core.study.json_schema import study_json_schema
from core.study.run import check_output, sweep

__all__ = [
    "apply_point",
    "check_output",
    "FIELD_UNITS",
    "LIMITS_NOT_CHECKED",
    "field_unit",
    "FIXED_ROOTS",
    "PUNCH_OUTPUT",
    "get_field",
    "load_study",
    "numeric_fields",
    "number_at",
    "parse_path",
    "Study",
    "study_from_dict",
    "study_json_schema",
    "sweep",
]
