"""The scene in a link: a compact, URL-safe encoding and a defensive decoder.

``encode_scene`` writes the scene dict as compact JSON, deflates it and encodes it with
the URL-safe base64 alphabet (no padding), prefixed by a version tag: a typical scene
becomes 400-700 characters. ``decode_scene`` refuses anything oversized before doing
work on it (text length, inflated size), then parses JSON into a dict; validating the
scene itself is left to ``core.scene_from_dict``. Formulas inside a scene are handled by
the core's whitelisting parser, never evaluated as code.
"""

from __future__ import annotations

import base64
import binascii
import json
import re
import zlib
from typing import Any

PREFIX = "1."
_ALPHABET = re.compile(r"[A-Za-z0-9_-]*")
#: Longest accepted encoded scene (characters); browsers and proxies cope with 8 k.
MAX_ENCODED = 6000
#: Largest accepted inflated scene JSON (bytes).
MAX_JSON = 200_000


def encode_scene(scene: dict[str, Any]) -> str:
    """The scene as a short URL-safe string (see the module docstring)."""
    text = json.dumps(scene, separators=(",", ":"), ensure_ascii=False, allow_nan=False)
    packed = zlib.compress(text.encode("utf-8"), 9)
    return PREFIX + base64.urlsafe_b64encode(packed).decode("ascii").rstrip("=")


def decode_scene(value: str) -> dict[str, Any]:
    """Inverse of :func:`encode_scene`; raises ValueError with a reason a user can read."""
    if not isinstance(value, str) or not value:
        raise ValueError("the scene in the link is empty")
    if len(value) > MAX_ENCODED:
        raise ValueError(f"the scene in the link is too long ({len(value)} characters, at "
                         f"most {MAX_ENCODED})")
    if not value.startswith(PREFIX):
        raise ValueError("the scene in the link has an unknown format (expected it to "
                         f"start with {PREFIX!r})")
    body = value[len(PREFIX):]
    if not _ALPHABET.fullmatch(body):
        raise ValueError("the scene in the link is not valid base64 (unexpected characters)")
    try:
        packed = base64.urlsafe_b64decode(body + "=" * (-len(body) % 4))
    except (binascii.Error, ValueError) as exc:
        raise ValueError("the scene in the link is not valid base64") from exc
    inflater = zlib.decompressobj()
    try:
        raw = inflater.decompress(packed, MAX_JSON)
    except zlib.error as exc:
        raise ValueError("the scene in the link is damaged (cannot be inflated)") from exc
    if inflater.unconsumed_tail:
        raise ValueError(f"the scene in the link is too large once inflated (over "
                         f"{MAX_JSON} bytes)")
    if not inflater.eof:
        raise ValueError("the scene in the link is truncated")
    try:
        scene = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"the scene in the link is not valid JSON ({exc})") from exc
    except RecursionError:
        # 100000 nested brackets deflate to a few hundred characters
        raise ValueError("the scene in the link is not valid JSON (nested too deeply)") from None
    if not isinstance(scene, dict):
        raise ValueError("the scene in the link is not a JSON object")
    return scene
