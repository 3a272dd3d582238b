"""Scene files: strict JSON reading, loading, canonical writing (format: core/SCENES.md).

The scene's fields and their validation are :mod:`core.scene.validate`; the public path
of these names is :mod:`core.scene`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from core import limits
from core.files import atomic_write_text, read_regular_file
from core.presets import shipped_file
from core.scene.schema import SCHEMA_KEY
from core.scene.validate import scene_from_dict

if TYPE_CHECKING:
    from core.scene.model import Scene
    from core.scene.punches import PunchesScene


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"duplicate field {key!r} in one JSON object")
        out[key] = value
    return out


def _parse_int(text: str) -> int | float:
    # no double holds more than 309 digits; Python's int() of a few thousand digits raises
    # an error about its own limits, so such a number becomes inf, refused by its field
    return int(text) if len(text) <= 400 else (-math.inf if text[0] == "-" else math.inf)


def read_scene_json(text: str, source: str = "scene") -> Any:
    """The JSON value of a scene file's text, read strictly: a field repeated in one
    object, a nesting too deep or a number beyond any double is refused (``ValueError``
    naming ``source``). The value is not yet validated as a scene."""
    if not text.strip():
        raise ValueError(f"{source}: the file is empty (a scene file is a JSON object)")
    try:
        return json.loads(text, object_pairs_hook=_no_duplicates, parse_int=_parse_int)
    except json.JSONDecodeError as exc:
        # (some of json's messages end in "at": "Unterminated string starting at")
        what = exc.msg.removesuffix(" at")
        raise ValueError(f"{source}: not valid JSON ({what} at line {exc.lineno}, "
                         f"column {exc.colno})") from None
    except ValueError as exc:
        raise ValueError(f"{source}: {exc}") from None
    except RecursionError:
        raise ValueError(f"{source}: not valid JSON (nested too deeply)") from None


def parse_scene_json(text: str, source: str = "scene") -> Scene | PunchesScene:
    """Parse and validate the JSON text of a scene; errors name ``source`` or the field.
    A scene of several punches (``punches``) gives a :class:`core.scene.PunchesScene`."""
    # imported here: the punches' module imports the results, which import this one
    from core.scene.punches import has_punches, punches_from_dict

    data = read_scene_json(text, source)
    return punches_from_dict(data) if has_punches(data) else scene_from_dict(data)


def load_scene(path: str | os.PathLike) -> Scene | PunchesScene:
    """Read and validate a scene file (JSON, UTF-8, at most 1 MB); ``"preset:NAME"`` reads
    the shipped preset of that name (:mod:`core.presets`).

    Raises ``ValueError`` (message starting with the file path or the field path) for a
    file that is too large, not a regular file (a named pipe is refused, not waited on),
    not JSON or not a valid scene, ``OSError`` if it cannot be read.
    """
    path = shipped_file(path, "scenes")
    raw = read_regular_file(path, limits.MAX_SCENE_BYTES)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file in UTF-8 (a scene file is JSON)") from None
    return parse_scene_json(text, str(path))


def scene_to_json(scene: Scene | PunchesScene | Mapping[str, Any],
                  schema: str | None = None) -> str:
    """The canonical JSON text of a scene, of one punch or several (validated first when
    given as a dict); ``schema``: a ``"$schema"`` to write first (the file's JSON Schema,
    for editors)."""
    from core.scene.punches import PunchesScene, has_punches, punches_from_dict

    if isinstance(scene, PunchesScene):
        data = scene.to_dict()
    elif isinstance(scene, Mapping) and has_punches(scene):
        data = punches_from_dict(scene).to_dict()
    else:
        data = scene_from_dict(scene).to_dict()
    if schema is not None:
        if not isinstance(schema, str):
            raise ValueError(f"{SCHEMA_KEY}: must be a string, got {type(schema).__name__}")
        data = {SCHEMA_KEY: schema, **data}
    return json.dumps(data, indent=2, allow_nan=False) + "\n"


def save_scene(scene: Scene | PunchesScene | Mapping[str, Any], path: str | os.PathLike,
               schema: str | None = None) -> None:
    """Write a scene (of one punch or several, as :func:`load_scene` reads them) as JSON
    to ``path`` atomically (a dict is validated first).

    ``schema``: a ``"$schema"`` to write first, naming the file's JSON Schema for an
    editor (e.g. the relative path of ``scene.schema.json``, see core/SCENES.md); the
    program ignores it when reading."""
    atomic_write_text(path, scene_to_json(scene, schema))
