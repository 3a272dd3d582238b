"""A guard against messages that Panel queues for a page and then never sends.

Panel (checked with 1.9.4) writes the changes made while a session's websocket is busy
through a queue per document (``panel.io.document._WRITE_MSGS``), emptied by a write task
while a flag (``_WRITE_BLOCK``) is set. A task that finishes clears the flag even if,
while it awaited its writes, a new message was queued and a second task scheduled; that
second task then sees no flag and returns. The message waits until the next change of
the same page triggers another write.

In the explorer that next change used to come anyway (the busy indicator went off 0.5 s
after each result). Without it, the last result of a slider step could wait until the
user's next step: measured with 20 sessions (benchmarks/load_test.py), about 1 step in
300 was not shown within 30 s. The guard below runs after every write task and, when
messages are left queued with no task to send them, schedules one.
"""

from __future__ import annotations

import logging
from typing import Any

log = logging.getLogger(__name__)

_INSTALLED = False


def install() -> bool:
    """Wrap Panel's write task once per process; False if Panel's internals differ (the
    guard is then not installed, and a warning says so)."""
    global _INSTALLED
    if _INSTALLED:
        return True
    from panel.io import document as pdoc

    needed = ("_dispatch_msgs", "_dispatch_write_task", "_WRITE_MSGS", "_WRITE_BLOCK")
    if not all(hasattr(pdoc, name) for name in needed):
        log.warning("Panel's write queue has changed; the guard against unsent messages "
                    "is not installed")
        return False
    original = pdoc._dispatch_msgs

    async def dispatch_msgs(doc: Any) -> None:
        await original(doc)
        if pdoc._WRITE_MSGS.get(doc) and doc not in pdoc._WRITE_BLOCK:
            # queued while the finished task awaited its writes: send them now
            pdoc._WRITE_BLOCK[doc] = True
            pdoc._dispatch_write_task(doc, pdoc._dispatch_msgs, doc)

    dispatch_msgs.__wrapped__ = original  # type: ignore[attr-defined]
    pdoc._dispatch_msgs = dispatch_msgs
    _INSTALLED = True
    return True
