"""The explorer's Bokeh figures, built once per session and updated in place.

- ``figures``: :class:`Figures`, every figure of the results column (scene drawing,
  q(x) and q(x, t), the four histories, the contact figures) and what they show.
- ``scene``: the scene drawing; ``contact``: the contact zone's bar, width plot and the
  inset of small features; ``pins``: the pinned results' lines and legend entries.
- ``time_axis``: the histories' log time axis, switched in place.
- ``classical``: classical answers drawn next to the computed pressure.
- ``bokeh_data``: plot data as float32, sent only when the numbers changed.
- ``study``: the Study tab's design chart; ``study_png``: the same chart as a PNG file.
"""

from .figures import Figures
from .pins import PIN_COLORS
from .scene import PUNCH_COLORS
from .study import DesignChart, flag_note
from .study_png import design_chart_png
from .time_axis import LogTime

__all__ = ["PIN_COLORS", "PUNCH_COLORS", "DesignChart", "Figures", "LogTime",
           "design_chart_png", "flag_note"]
