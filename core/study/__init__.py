"""core.study.definition."""

from __future__ import annotations

from core.study.definition import Study, load_study, numeric_fields, study_from_dict
from core.study.run import check_output, sweep

__all__ = [
    "check_output",
    "load_study",
    "numeric_fields",
    "Study",
    "study_from_dict",
    "sweep",
]
