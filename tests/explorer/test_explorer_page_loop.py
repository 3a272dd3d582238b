"""Callbacks dispatched to a served page's loop from other threads run in the order they
were dispatched (explorer/views/loop.py): scheduled one by one, a study's last progress
line once ran after its result, and the page read "Done: running: 3 of 3 points"."""

from __future__ import annotations

import threading

from explorer.solving import StudyRun
from explorer.views.loop import PageLoop


class _ServedLoop(PageLoop):
    """A served page whose loop runs what was scheduled when the test says, last first
    (the order the one-by-one scheduling could take)."""

    def __init__(self) -> None:
        super().__init__(doc=None)
        self.scheduled: list = []

    @property
    def served(self) -> bool:
        return True

    def later(self, callback, delay_ms: float) -> None:
        self.scheduled.append(callback)

    def run_last_first(self) -> None:
        while self.scheduled:
            self.scheduled.pop()()


def test_dispatched_callbacks_run_in_order_and_a_study_ends_done():
    loop = _ServedLoop()
    run = StudyRun(dispatch=loop.dispatch)
    thread = threading.Thread(target=lambda: (
        run._set(done=3, message="running: 3 of 3 points"),
        run._set(status="done", done=3, message="3 points in 1.0 s")))
    thread.start()
    thread.join()
    assert len(loop.scheduled) == 1  # one drain for both
    loop.run_last_first()
    assert run.status == "done" and run.message == "3 points in 1.0 s"


def test_a_failing_callback_leaves_the_others_and_later_ones_run():
    loop = _ServedLoop()
    seen: list[str] = []
    loop.dispatch(lambda: seen.append("a"))
    loop.dispatch(lambda: 1 / 0)
    loop.dispatch(lambda: seen.append("c"))
    loop.run_last_first()
    loop.dispatch(lambda: seen.append("d"))  # the queue drained: a new drain is scheduled
    loop.run_last_first()
    assert seen == ["a", "c", "d"]
