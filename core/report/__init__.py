"""The printable report of a solved scene: what an engineer files with a design check.

- :func:`report_html`: one self-contained HTML file (Bokeh plots inline, no network);
- :func:`report_pdf`: the same as PDF (HoloViews' Matplotlib backend);
- :func:`write_report`: either, by the file name;
- :func:`sections`: the report's text, for other layouts.

Both need the ``report`` extra (HoloViews, Bokeh, Matplotlib); the command line's
``coated-punch report SCENE.json -o REPORT.pdf`` calls :func:`write_report`.
"""

from core.report.content import Section, sections
from core.report.html import report_html
from core.report.pdf import report_pdf, write_report

__all__ = ["Section", "report_html", "report_pdf", "sections", "write_report"]
