"""A one-file upload box for the explorer's pages (scene files, punch shape tables)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import panel as pn
import param

from ..fixes import idle_painter

#: Longest file name kept from an upload [characters] (it is echoed into messages).
MAX_FILENAME_CHARS = 120
#: Size of the pieces an upload is sent in [bytes]: well below the server's limit of one
#: websocket message (``WEBSOCKET_MAX_BYTES`` in explorer/__main__.py).
UPLOAD_CHUNK_BYTES = 256 * 1024


class BoundedUpload(pn.viewable.Viewer):
    """A one-file upload that refuses a file over ``max_bytes`` in the browser, before
    sending it. ``filename`` and ``value`` (the file's bytes) follow the last file.

    A plain FileInput sends the whole file in one websocket message: a file over the
    server's message limit (20 MB) closed the session's connection and left a dead page
    (measured with 25 MB). The dropper checks the size in the page and sends in chunks.
    """

    filename = param.String(default="", doc="Name of the last file.")
    value = param.Bytes(default=None, allow_None=True, doc="Contents of the last file.")

    def __init__(self, accept: Sequence[str], max_bytes: int, css: str = "",
                 **params: Any) -> None:
        """``css``: a class of the box besides ``file-dropper`` (which box a test uses)."""
        super().__init__(**params)
        self.max_bytes = max_bytes
        # chunks well below the server's websocket message limit (explorer/__main__.py)
        self._box = pn.widgets.FileDropper(
            accepted_filetypes=list(accept), multiple=False,
            max_file_size=f"{max(1, max_bytes // 1000)}KB", chunk_size=UPLOAD_CHUNK_BYTES,
            sizing_mode="stretch_width", height=90,
            css_classes=["file-dropper", css] if css else ["file-dropper"])
        self._box.param.watch(self._on_drop, "value")
        # The dropper has no way to be emptied from the server: a hidden counter asks the
        # page to remove its files (a new dropper in its place broke the old one's
        # preview script, still drawing the file it had just sent).
        self._clears = pn.widgets.IntInput(value=0, visible=False)
        self._clears.jscallback(value=idle_painter.WAKE_JS + """
            const view = Bokeh.index.find_one(box);
            if (view && view._file_pond) { view._file_pond.removeFiles(); }""",
                                args={"box": self._box})
        self._holder = pn.Column(self._box, self._clears, sizing_mode="stretch_width",
                                 margin=0)

    def clear(self) -> None:
        """Empty the box on the page, ready for the next file (``filename`` and ``value``
        keep the last file): a refused file no longer shows "Upload complete", and the
        next file needs no click on the first one's x."""
        self._clears.value += 1

    def _on_drop(self, event: Any) -> None:
        # The dropper keeps every file dropped in one dict (a file removed on the page is
        # not taken out of it), and the same name dropped again keeps its first place:
        # a table dropped a second time, after another, read as that other one (an
        # audit). Only the newest is in it now.
        dropped = dict(event.new or {})
        self._box.value.clear()
        self._box.mime_type.clear()
        for name, data in dropped.items():
            raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
            # the same file again is a new request (e.g. after fixing the scene on screen)
            self.param.update(filename=str(name)[:MAX_FILENAME_CHARS], value=None)
            self.value = raw

    def __panel__(self) -> pn.viewable.Viewable:
        return self._holder
