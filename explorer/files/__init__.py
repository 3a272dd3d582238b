"""The files the page hands out, written from the result on screen in the units on screen.

- ``exports``: the CSV files of a result (histories, q(x, t)) and of a design study.

The printable report is the command line's (:mod:`core.report`), built where the
session's scenes are solved (:mod:`explorer.solving`).
"""

from .exports import (
    MAX_PAGE_DOWNLOAD_BYTES,
    flag_message,
    histories_csv,
    number,
    page_words,
    parse_csv,
    pressure_csv,
    project_version,
    study_csv,
)

__all__ = ["flag_message", "histories_csv", "MAX_PAGE_DOWNLOAD_BYTES", "number",
           "page_words", "parse_csv", "pressure_csv", "project_version", "study_csv"]
