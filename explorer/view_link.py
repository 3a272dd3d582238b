"""What a link keeps besides the scene: the output time shown, the open tab, the pins.

``?scene=…&t=12&tab=3&pin=…``: ``t`` is the index of the output time, ``tab`` the index
of the open sidebar tab, ``pin`` the pinned results' scenes (encoded as the scene is, see
:mod:`explorer.links`: one pin as its scene, several as ``{"pins": [scene, ...]}``, which
deflates to little more than one scene since pins differ in a few fields; the pins are
solved again when the link is opened). Anything odd is ignored with a message, never
fatal: the scene is what matters. No Panel import.
"""

from __future__ import annotations

from typing import Any

from .links import decode_scene, encode_scene
from .pins import MAX_PINS

#: Largest output-time index a link may ask for (the scene schema's limit is lower).
MAX_INDEX = 100_000


def view_query(scene: dict[str, Any], time_index: int, tab: int,
               pins: list[dict[str, Any]]) -> dict[str, str]:
    """The query arguments of a link to this view (``pins``: the pinned scenes)."""
    query = {"scene": encode_scene(scene), "t": str(int(time_index)), "tab": str(int(tab))}
    if len(pins) == 1:
        query["pin"] = encode_scene(pins[0])
    else:
        query["pin"] = encode_scene({"pins": list(pins)}) if pins else ""
    return query


def _index(text: str | None, limit: int) -> int | None:
    if not text or len(text) > 6 or not text.isdigit():
        return None
    value = int(text)
    return value if value <= limit else None


def read_view_query(query: dict[str, str], tabs: int) -> tuple[int | None, int | None,
                                                                list[dict[str, Any]], str]:
    """(time index, tab index, pinned scenes, message) from a link's query arguments."""
    message = ""
    time_index = _index(query.get("t"), MAX_INDEX)
    tab = _index(query.get("tab"), tabs - 1)
    pins: list[dict[str, Any]] = []
    if query.get("pin"):
        try:
            decoded = decode_scene(query["pin"])
            pins = decoded["pins"] if "pins" in decoded else [decoded]
            if not isinstance(pins, list) or not all(isinstance(p, dict) for p in pins):
                raise ValueError("the pins in the link are not a list of scenes")
            if len(pins) > MAX_PINS:
                raise ValueError(f"the link has {len(pins)} pins, at most {MAX_PINS}")
        except ValueError as exc:
            pins = []
            message = f"The pinned results in the link were not used: {exc}."
    return time_index, tab, pins, message
