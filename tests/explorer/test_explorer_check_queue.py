"""One FE coating check at a time on a server (explorer/views/coating.py): a second page's
check waits and says so, and gives up with a message if the first keeps the server."""

from __future__ import annotations

from explorer.views import coating


def test_a_check_waits_for_the_one_running_and_says_so(monkeypatch):
    from tests.conftest import scene_file

    monkeypatch.setattr(coating, "CHECK_WAIT_S", 0.05)
    said: list[str] = []
    assert coating._CHECKS.acquire(blocking=False)  # another page's check runs
    try:
        outcome = coating._check(scene_file("worn_coating"), lambda: said.append("waiting"))
    finally:
        coating._CHECKS.release()
    assert said == ["waiting"]
    assert isinstance(outcome, str) and outcome.startswith("Not checked: other pages'")
    # free again: the check runs (at loading, level 0) and says nothing of waiting
    said.clear()
    outcome = coating._check(scene_file("worn_coating"), lambda: said.append("waiting"))
    assert said == [] and isinstance(outcome, dict) and "model_error" in outcome
