"""A scene of several punches says why in ``info["message"]``, where its flags' texts
point ("see info.message"): the punches' one message when one march answered them all,
else each punch's, named."""

from __future__ import annotations

from core.scene import solve
from tests.support.punch_pairs import ELASTIC, wide_and_narrow


def test_the_scene_message_names_each_punchs_own() -> None:
    result = solve(wide_and_narrow(ELASTIC, {"end": 10.0, "count": 2}))
    messages = [p.info["message"] for p in result.punches]
    assert all(messages)
    if len(set(messages)) == 1:
        assert result.info["message"] == messages[0]
    else:
        assert result.info["message"] == "; ".join(
            f"punches[{k}]: {m}" for k, m in enumerate(messages))
    assert result.to_dict()["info"]["message"] == result.info["message"]
