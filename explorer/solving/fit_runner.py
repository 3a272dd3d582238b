"""Running a fit of the Fit tab off the page's event loop.

A fit is 10-100 solves at the readings' times (0.3-6 s of CPU, measured on the presets
with one to three fields): on a thread of its own it leaves the page's loop free, and its
answer comes back through ``dispatch``. Served with worker processes, the fit runs in one
of them at a lower CPU priority than the pages' slider solves
(:mod:`explorer.solving.priority`): in the server's own process it held Python's lock for
seconds beside the event loop. At most :data:`MAX_RUNNING_FITS` run at once in
a server (a fit started meanwhile waits): the machine also serves every page's slider
solves. A fit cannot be stopped half way (the core's least-squares solver has no hook);
its work is bounded by ``core.limits.MAX_FIT_SOLVES``.

Nothing here imports Panel.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Mapping, Sequence
from typing import Any

import param

from core.back_analysis import Readings

from .background import BackgroundRun
from .controller import run_in_background
from .worker_side import fit_outcome

log = logging.getLogger(__name__)

#: Fits running at once in one server: each takes a core while it runs.
MAX_RUNNING_FITS = 1

_SLOTS = threading.BoundedSemaphore(MAX_RUNNING_FITS)


class FitRun(BackgroundRun):
    """The fit of one session: its status, a message, and the last outcome.

    ``dispatch`` runs a callback on the session's event loop (the app's); without one the
    updates are applied from the fit's thread (tests, scripts).
    """

    status = param.Selector(default="idle", objects=["idle", "running", "done", "failed"])
    message = param.String(default="", doc="What the fit did, or why it failed.")
    outcome = param.Parameter(default=None, doc="The last FitOutcome.")

    def start(self, scene: Mapping[str, Any], readings: Readings,
              keys: Sequence[str | None], background: bool = True) -> None:
        """Fit the fields ``keys`` of ``scene`` to ``readings`` (on a thread of its own
        when ``background``, else now)."""
        if self.running:
            raise RuntimeError("a fit is already running")
        self.param.update(status="running", message="fitting")
        args = (dict(scene), readings, list(keys))
        if not background:
            self._work(*args)
            return
        self._launch(self._work, args, "fit")

    def _work(self, scene: dict[str, Any], readings: Readings, keys: list[str | None]
              ) -> None:
        with _SLOTS:
            try:
                outcome = run_in_background(fit_outcome, scene, readings, keys)
            except ValueError as exc:
                self._set(status="failed", message=str(exc))
                return
            except Exception as exc:  # noqa: BLE001 - the page says so; the server goes on
                log.exception("fit failed")
                self._set(status="failed", message=f"the fit could not run: "
                                                   f"{type(exc).__name__}: {exc}"[:500])
                return
        calibration = outcome.calibration
        self._set(status="done", outcome=outcome,
                  message=f"fitted in {outcome.seconds:.1f} s ({calibration.solves} "
                          "solves)")
