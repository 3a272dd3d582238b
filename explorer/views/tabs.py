"""Sidebar tabs that get their widgets when first opened, or soon after the page loads."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import panel as pn

from ..fixes import gc_policy
from .loop import PageLoop
from .style import TAB_COLUMN

#: How long a page must be left alone before the sidebar tabs not yet opened are filled in
#: the background [ms] (see DeferredTabs.fill_idle). Filling them costs ~1.8 s of the
#: server's CPU and ~1.5 s of the browser's per page; 3 s after the page connected, it
#: came just as a user's first moves did (which then took seconds, explorer_latency's
#: note), and it came in nearly every one of the browser tests' ~50 short-lived pages.
FILL_TABS_AFTER_MS = 15000
#: CSS class the sidebar gets once every tab has its widgets: the page is complete, no
#: more background work of its own is due (a signal for scripts and tests that drive it).
COMPLETE_CLASS = "sidebar-complete"
#: Width of the sidebar [px], the same in presentation mode: a width changed on a page
#: left the tabs' widgets at their old width, running over the plots (at 1024 px: the
#: description through the scene's axis label, the readout's heading cut).
SIDEBAR_WIDTH = 340
#: Style of the sidebar's tab titles: several lines when they do not fit one.
WRAP_TITLES = (".bk-header, .bk-headers-wrapper, .bk-headers {flex-wrap: wrap; "
               "overflow: visible; height: auto;}")
#: Style of the sidebar: a closed tab takes no space. Panel stacks the tabs in one cell and
#: only hides the closed ones, so the page's root grew with each tab filled in the
#: background (1693 -> 3973 px, the tallest tab), each growth laying out the whole page
#: again: 7 layouts of 30-140 ms of the page's CPU (see explorer/fixes/bokeh_fixes.py).
CLOSED_TABS_TAKE_NO_SPACE = "[aria-hidden='true'] {display: none !important;}"


class DeferredTabs:
    """The sidebar: a served page arrives with the first tab's widgets only.

    That is a fifth of the widget models, 0.4 s less to the first paint; another tab gets
    its widgets when first opened, or once the page has been left alone for
    :data:`FILL_TABS_AFTER_MS`, and keeps them. Panel's dynamic tabs would rebuild a tab at
    every switch: measured 110 ms of server time each, which made 20 sessions 8x slower.

    A tab is given as its column, or as a function that makes it: that function is called
    when the tab is filled, so the view behind it (its widgets and their watchers) is not
    even made for a page that never shows it (see ``explorer.app.ExplorerApp``). Outside a
    server (a notebook, a script) there is no page to fill tabs in the background: a tab
    is filled when opened, and every tab when the page is first shown
    (``ExplorerApp.__panel__`` calls :meth:`fill_all`); a session that is never shown (a
    script driving the state) makes only the views it asks for."""

    def __init__(self, loop: PageLoop,
                 tabs: list[tuple[str, pn.Column | Callable[[], pn.Column]]]) -> None:
        self.loop = loop
        self.used = False  # the page was used since the background filling was scheduled
        # a tab not filled yet: its column, and its widgets (made, not shown yet) or the
        # function that makes its column
        self.deferred: dict[int, tuple[pn.Column, list[Any] | Callable[[], pn.Column]]] = {}
        columns = []
        for k, (_title, content) in enumerate(tabs):
            if not k:
                column = content if isinstance(content, pn.Column) else content()
            elif isinstance(content, pn.Column):
                column = content
                self.deferred[k] = (column, list(column.objects))
                column.objects = []
            else:
                # (the views' columns all share these options: the tab's column is the same)
                column = pn.Column(**TAB_COLUMN)
                self.deferred[k] = (column, content)
            columns.append(column)
        tabs = [(title, column) for (title, _), column in zip(tabs, columns, strict=True)]
        # the tab titles wrap onto a second line: in one line the last tabs were out of
        # reach at 1024 px (presentation mode) and behind the first ones' width at 1400
        self.sidebar = pn.Tabs(*tabs, dynamic=False, width=SIDEBAR_WIDTH, margin=(0, 10, 0, 0),
                               css_classes=["sidebar-tabs"],
                               stylesheets=[WRAP_TITLES, CLOSED_TABS_TAKE_NO_SPACE])
        self.sidebar.param.watch(self._opened, "active")

    def _opened(self, event: Any) -> None:
        self.fill(event.new)
        self.touch()

    def touch(self) -> None:
        """Note that the page is in use: the background filling waits until it has been
        left alone for :data:`FILL_TABS_AFTER_MS` again."""
        self.used = True

    def fill(self, index: int) -> None:
        """Give the tab at ``index`` its widgets (they then stay); the page is complete
        once the last tab has them, whether opened or filled in the background."""
        content = self.deferred.get(index)
        if content is not None:
            column, objects = content
            # (made before it leaves the queue: a view that fails to be made is tried again)
            column.objects = objects if isinstance(objects, list) else objects().objects
            del self.deferred[index]
            if not self.deferred:
                self._complete()

    def fill_all(self) -> None:
        """Give every tab its widgets now (a page shown outside a server)."""
        for index in sorted(self.deferred):
            self.fill(index)

    def _complete(self) -> None:
        """Mark the page complete (:data:`COMPLETE_CLASS`): no more background work of
        its own is due, and it lives as long as the session."""
        if not self.loop.served or COMPLETE_CLASS in self.sidebar.css_classes:
            return
        self.sidebar.css_classes = [*self.sidebar.css_classes, COMPLETE_CLASS]
        gc_policy.page_built(getattr(self.loop.doc, "session_context", None))

    def parts(self) -> list[Any]:
        """The widgets of the tabs not filled yet that exist (made, not shown yet: part of
        the page all the same)."""
        return [obj for _, objects in self.deferred.values() if isinstance(objects, list)
                for obj in objects]

    def fill_when_idle(self) -> None:
        """Start the background filling (:meth:`fill_idle`) once the page has been left
        alone for :data:`FILL_TABS_AFTER_MS` from now."""
        self.used = False
        self.loop.later(self.fill_idle, FILL_TABS_AFTER_MS)

    def fill_idle(self) -> None:
        """Fill the next unopened tab, then the others one per turn of the event loop, as
        long as the page is left alone (:meth:`fill_when_idle` schedules it); once the page
        is used (:meth:`touch`) the filling waits that long again.

        Under load the server can miss a tab click (measured once in ~600 first openings
        with 20 sessions: the client showed the tab, the server never heard of it), and
        the tab stayed empty; filled in the background it cannot."""
        loop = self.loop
        if self.used or not loop.connected:  # (a closed page's lingering session: no work)
            self.fill_when_idle()
            return
        if self.deferred:
            self.fill(min(self.deferred))
        if self.deferred:
            loop.later(self.fill_idle, 0)
        else:
            self._complete()  # (every tab was opened before the page was left alone)
