"""The views of the explorer page: one small view per sidebar tab, one for the results, and
the widgets they are made of.

Each view is given the model objects it reads and edits (the state, the screen, the
controller, ...), never the whole session; it builds its widgets over them and knows how
to refresh them. :mod:`explorer.app` builds the views and assembles the page from them.

- Sidebar tabs: ``scene`` (presets, undo, the loading, with the slider of
  ``eccentricity``), ``punch`` (with ``punches``, the section of a scene of several
  punches, and the note standing in for what is for one punch only), ``coating`` (with
  the coating-model check), ``base`` (with ``creep``, the design codes' creep),
  ``times``, ``check``, ``files``, ``lessons``, ``study``, ``fit`` (back-analysis from
  readings); ``fidelity``: the model-fidelity widgets of the Coating and Time tabs.
- The results column: ``results`` (messages, plots, player, readout, design check),
  ``contact`` (the contact figures' slots), ``pins`` (pin, remove, pin every step, pins
  of a link), ``busy`` (the busy indicator), ``status`` (the status line in words).
- The page: ``loop`` (the session's document and event loop), ``tabs`` (tabs filled when
  first opened), ``link`` (the address follows the view), ``style`` (the page's CSS and
  HTML panes).
- Widgets: ``widgets`` (widgets bound both ways to the state), ``upload`` (a one-file
  upload box).
"""

from .base import BaseView
from .busy import BUSY_AFTER_MS
from .check import CheckView
from .coating import CoatingView
from .fidelity import CONTACT_LABELS, FidelityView
from .files import FilesView
from .fit import FitView
from .lessons import LessonsView
from .link import LINK_EVERY_MS, AddressLink
from .loop import PageLoop
from .pins import PinsView
from .punch import PunchView
from .results import HELD_AFTER_MS, ResultsView, badges_html, readout_html
from .scene import SceneView
from .status import status_html
from .study import StudyView
from .style import html_pane
from .tabs import COMPLETE_CLASS, FILL_TABS_AFTER_MS, DeferredTabs
from .times import TimesView
from .widgets import PromptToggle

__all__ = ["BUSY_AFTER_MS", "CONTACT_LABELS", "FILL_TABS_AFTER_MS", "LINK_EVERY_MS",
           "HELD_AFTER_MS",
           "AddressLink", "BaseView", "COMPLETE_CLASS", "CheckView", "CoatingView",
           "DeferredTabs", "FidelityView", "FilesView", "FitView", "LessonsView",
           "PageLoop", "PinsView", "PromptToggle", "PunchView", "ResultsView", "SceneView",
           "StudyView", "TimesView", "badges_html", "html_pane", "readout_html", "status_html"]
