"""The printable report of a solved scene: what an engineer files with a design check.

- :func:`report_html`: one self-contained HTML file (Bokeh plots inline, no network);
- :func:`report_pdf`: the same as PDF (its plots drawn with Matplotlib);
- :func:`write_report`: either, by the file name;
- :func:`sections`: the report's text, for other layouts;
- :func:`output_index`: the output time a chosen time stands for (checked).

What it says is in ``content`` (the sections), ``inputs`` (the scene's inputs in
engineering units) and ``contact`` (the contact zone at a chosen time, lift-off); its
plots are one HoloViews layout (``plots``) that ``html`` and ``pdf`` print. A scene of
several punches (:class:`core.scene.PunchesSolution`) is reported by the same functions,
its sections and plots made in ``punches`` (a results section per punch, q(x) over the
whole surface, the histories with a line per punch). Every
function takes an optional ``time`` [day after loading]: the output time nearest to it is
the one whose contact the report describes and whose q(x) it draws (default: the last).

Both need the ``report`` extra (HoloViews, Bokeh, Matplotlib); the command line's
``coated-punch report SCENE.json -o REPORT.pdf`` calls :func:`write_report`.
"""

from core.report.contact import output_index
from core.report.content import Section, sections
from core.report.html import report_html
from core.report.pdf import report_pdf, write_report

__all__ = ["Section", "output_index", "report_html", "report_pdf", "sections",
           "write_report"]
