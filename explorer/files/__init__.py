"""The files the page hands out, written from the result on screen in the units on screen.

- ``exports``: the CSV files of a result (histories, q(x, t)) and of a design study.
- ``report``: the printable report, one self-contained HTML file.
"""

from .exports import (
    flag_message,
    histories_csv,
    number,
    parse_csv,
    pressure_csv,
    project_version,
    study_csv,
)
from .report import report_html

__all__ = ["flag_message", "histories_csv", "number", "parse_csv", "pressure_csv",
           "project_version", "report_html", "study_csv"]
