"""A session's long run on a thread of its own (a study, a fit): what both share.

The run's thread hands its updates to the page through ``dispatch`` (a callback on the
session's event loop); without one they are applied from the thread (tests, scripts).

Nothing here imports Panel.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import param


class BackgroundRun(param.Parameterized):
    """The lifecycle of one run of a session: started on a thread of its own, waited for,
    its updates dispatched to the page. Subclasses hold the run's own parameters."""

    #: How long :meth:`wait` waits by default [s].
    WAIT_S = 300.0

    def __init__(self, dispatch: Callable[[Callable[[], None]], None] | None = None,
                 **params: Any) -> None:
        super().__init__(**params)
        self._dispatch = dispatch or (lambda callback: callback())
        self._thread: threading.Thread | None = None

    @property
    def running(self) -> bool:
        """Whether the run is waiting or running."""
        return self._thread is not None and self._thread.is_alive()

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for the run to end; False if it still runs after ``timeout`` [s]
        (default :attr:`WAIT_S`)."""
        thread = self._thread
        if thread is not None:
            thread.join(self.WAIT_S if timeout is None else timeout)
        return not self.running

    def _launch(self, work: Callable[..., None], args: tuple, name: str) -> None:
        """Run ``work(*args)`` on a daemon thread named ``name``."""
        self._thread = threading.Thread(target=work, args=args, name=name, daemon=True)
        self._thread.start()

    def _set(self, **values: Any) -> None:
        """Update the run's parameters on the session's event loop."""
        self._dispatch(lambda: self.param.update(**values))
