"""The preset scenes and studies shipped with the package.

The files are package data (``core/presets/scenes/*.json`` and
``core/presets/studies/*.json``), read through :mod:`importlib.resources`, so an installed
wheel finds them wherever it is started from. The explorer offers the scenes as its
presets and builds its lessons from them; the command line reads them by name
(``coated-punch solve preset:worn_coating``).

The names are the file stems (``uniform_flat``, ``worn_coating``, ...).
"""

from __future__ import annotations

import json
import os
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

__all__ = ["PRESET_PREFIX", "preset_names", "read_preset", "read_study", "shipped_file",
           "study_names"]

#: How a command-line argument names a shipped scene or study instead of a file.
PRESET_PREFIX = "preset:"


def _folder(kind: str) -> Any:
    return resources.files(__name__).joinpath(kind)


@cache
def _names(kind: str) -> tuple[str, ...]:
    return tuple(sorted(item.name[:-5] for item in _folder(kind).iterdir()
                        if item.name.endswith(".json")))


def preset_names() -> tuple[str, ...]:
    """The names of the shipped preset scenes, sorted."""
    return _names("scenes")


def study_names() -> tuple[str, ...]:
    """The names of the shipped studies, sorted."""
    return _names("studies")


#: What one of each kind of shipped file is called in a message.
_ONE = {"scenes": "scene", "studies": "study"}


def _known(kind: str) -> str:
    """The shipped names of ``kind``, as the refusal of another name lists them."""
    return f"known: {', '.join(_names(kind))}"


def _read(kind: str, name: str) -> dict[str, Any]:
    if name not in _names(kind):
        raise KeyError(f"no shipped {_ONE[kind]} named {name!r}; {_known(kind)}")
    data = json.loads(_folder(kind).joinpath(f"{name}.json").read_text(encoding="utf-8"))
    if not isinstance(data, dict):
        raise ValueError(f"the shipped {_ONE[kind]} {name!r} is not a JSON object")
    return data


def read_preset(name: str) -> dict[str, Any]:
    """The preset scene ``name`` as a fresh scene dict (format: ``core/SCENES.md``).

    Raises
    ------
    KeyError
        If no preset has that name (the message lists the known ones).
    """
    return _read("scenes", name)


def read_study(name: str) -> dict[str, Any]:
    """The shipped study ``name`` as a fresh study dict; its ``scene`` is a path relative
    to the study's file (``shipped_file("preset:NAME", "studies")``)."""
    return _read("studies", name)


def shipped_file(path: str | os.PathLike, kind: str) -> str | os.PathLike:
    """``path`` itself, or for ``"preset:NAME"`` the file-system path of the shipped
    ``kind`` (``"scenes"`` or ``"studies"``) of that name.

    Raises
    ------
    ValueError
        If nothing of that name is shipped (the message lists what is).
    """
    if not (isinstance(path, str) and path.startswith(PRESET_PREFIX)):
        return path
    name = path[len(PRESET_PREFIX):]
    if name not in _names(kind):
        raise ValueError(f"{path}: no shipped {_ONE[kind]} of that name; {_known(kind)}")
    # an installed package is a folder of files (a wheel unpacks; a zipped one would not do)
    return Path(str(_folder(kind).joinpath(f"{name}.json")))
