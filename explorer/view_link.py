"""What a link keeps besides the scene: the output time shown, the open tab, the pin.

``?scene=…&t=12&tab=3&pin=…``: ``t`` is the index of the output time, ``tab`` the index
of the open sidebar tab, ``pin`` the pinned result's scene (encoded as the scene is, see
:mod:`explorer.links`; the pin is solved again when the link is opened). Anything odd is
ignored with a message, never fatal: the scene is what matters. No Panel import.
"""

from __future__ import annotations

from typing import Any

from .links import decode_scene, encode_scene

#: Largest output-time index a link may ask for (the scene schema's limit is lower).
MAX_INDEX = 100_000


def view_query(scene: dict[str, Any], time_index: int, tab: int,
               pin: dict[str, Any] | None) -> dict[str, str]:
    """The query arguments of a link to this view."""
    query = {"scene": encode_scene(scene), "t": str(int(time_index)), "tab": str(int(tab))}
    query["pin"] = encode_scene(pin) if pin is not None else ""
    return query


def _index(text: str | None, limit: int) -> int | None:
    if not text or len(text) > 6 or not text.isdigit():
        return None
    value = int(text)
    return value if value <= limit else None


def read_view_query(query: dict[str, str], tabs: int) -> tuple[int | None, int | None,
                                                                dict[str, Any] | None, str]:
    """(time index, tab index, pinned scene, message) from a link's query arguments."""
    message = ""
    time_index = _index(query.get("t"), MAX_INDEX)
    tab = _index(query.get("tab"), tabs - 1)
    pin = None
    if query.get("pin"):
        try:
            pin = decode_scene(query["pin"])
        except ValueError as exc:
            message = f"The pinned result in the link was not used: {exc}."
    return time_index, tab, pin, message
