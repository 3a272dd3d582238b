"""What a link keeps besides the scene: the output time shown, the open tab, the pins,
the Study tab's settings, the Fit tab's readings and fields.

``?scene=…&t=12&tab=3&pin=…&study=…``: ``t`` is the index of the output time, ``tab`` the
index of the open sidebar tab, ``pin`` the pinned results' scenes (encoded as the scene
is, see :mod:`explorer.model.links`: one pin as its scene, several as ``{"pins": [scene,
...]}``, which deflates to little more than one scene since pins differ in a few fields;
the pins are solved again when the link is opened), ``study`` the Study tab's parameters
(field, from, to, points, spacing of each) and output, encoded the same way (see
:func:`study_settings`; the study is not run when the link is opened), ``fit`` the Fit
tab's readings (in SI units, as ``Readings.to_dict`` gives them) and fields to fit,
encoded the same way (:func:`fit_settings`; drawn on the histories when the link is
opened, not fitted). Anything odd is ignored with a message, never fatal: the scene is
what matters. No Panel import.
"""

from __future__ import annotations

import json
from typing import Any

from core.back_analysis import Readings, readings_from_text
from core.study import PUNCH_OUTPUT

from .fit import MAX_FIT_FIELDS
from .links import MAX_ENCODED, decode_scene, encode_scene
from .pins import MAX_PINS
from .punches_state import SCREEN_PUNCHES
from .study import MAX_POINTS, OUTPUTS, SPACINGS

#: Largest output-time index a link may ask for (the scene schema's limit is lower).
MAX_INDEX = 100_000


#: Longest field key of a study parameter in a link (the page's keys are ~25 characters).
MAX_STUDY_KEY = 100
#: Most parameters of the Study tab.
MAX_STUDY_AXES = 2
#: Most readings a link may hold. What bounds a link in practice is its length
#: (:data:`explorer.model.links.MAX_ENCODED`, 6000 characters): readings of settlement
#: with a standard deviation take ~22 characters each once deflated (measured on 200 and
#: 500 noisy synthetic readings), so ~260 fit; more stay with the page that uploaded them.
MAX_LINK_READINGS = 1000


def view_query(scene: dict[str, Any], time_index: int, tab: int,
               pins: list[dict[str, Any]],
               study: dict[str, Any] | None = None,
               fit: dict[str, Any] | None = None) -> dict[str, str]:
    """The query arguments of a link to this view (``pins``: the pinned scenes; ``study``:
    the Study tab's settings, :func:`study_settings`; ``fit``: the Fit tab's, ``{"fields":
    [...], "readings": Readings.to_dict(), "source": name}``, left out of the link when
    its encoding is longer than a link may be, ``MAX_ENCODED``)."""
    query = {"scene": encode_scene(scene), "t": str(int(time_index)), "tab": str(int(tab))}
    if len(pins) == 1:
        query["pin"] = encode_scene(pins[0])
    else:
        query["pin"] = encode_scene({"pins": list(pins)}) if pins else ""
    query["study"] = encode_scene(study_settings(study)) if study else ""
    encoded = encode_scene(fit) if fit is not None else ""
    query["fit"] = encoded if len(encoded) <= MAX_ENCODED else ""
    return query


def study_settings(settings: Any) -> dict[str, Any]:
    """The Study tab's settings checked: ``{"axes": [[key, from, to, points, spacing],
    ...], "output": key}`` (one or two axes; from and to in the units on screen, finite;
    points an integer in [2, MAX_POINTS]; spacing one of ``SPACINGS``; output one of
    ``OUTPUTS``, or one of a punch of several, ``punches[k].<output>``). Raises ValueError
    naming the setting and the reason."""
    if not isinstance(settings, dict):
        raise ValueError("the study settings are not a JSON object")
    axes = settings.get("axes")
    if not isinstance(axes, list) or not 1 <= len(axes) <= MAX_STUDY_AXES:
        raise ValueError(f"study axes: must be a list of 1 to {MAX_STUDY_AXES} parameters")
    checked = []
    for n, axis in enumerate(axes, start=1):
        if not isinstance(axis, list) or len(axis) != 5:
            raise ValueError(f"study parameter {n}: must be [field, from, to, points, "
                             "spacing]")
        key, start, stop, count, spacing = axis
        if not isinstance(key, str) or not 0 < len(key) <= MAX_STUDY_KEY:
            raise ValueError(f"study parameter {n}: the field must be a text of 1 to "
                             f"{MAX_STUDY_KEY} characters")
        for name, value in (("from", start), ("to", stop)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or value != value or abs(value) == float("inf"):
                raise ValueError(f"study parameter {n}: '{name}' must be a finite number")
        if isinstance(count, bool) or not isinstance(count, int) \
                or not 2 <= count <= MAX_POINTS:
            raise ValueError(f"study parameter {n}: points must be an integer in "
                             f"[2, {MAX_POINTS}]")
        if spacing not in SPACINGS:
            raise ValueError(f"study parameter {n}: spacing must be one of "
                             f"{', '.join(SPACINGS)}")
        checked.append([key, float(start), float(stop), int(count), spacing])
    output = settings.get("output")
    match = PUNCH_OUTPUT.fullmatch(output) if isinstance(output, str) else None
    if output not in OUTPUTS and (match is None or match[2] not in OUTPUTS
                                  or int(match[1]) >= SCREEN_PUNCHES):
        raise ValueError(f"study output: must be one of {', '.join(OUTPUTS)}, or "
                         f"punches[k].<one of them> (k from 0 to {SCREEN_PUNCHES - 1})")
    return {"axes": checked, "output": output}


def fit_settings(settings: Any) -> dict[str, Any]:
    """The Fit tab's settings of a link checked: ``{"fields": [key or None, ...],
    "readings": {...}, "source": name}`` with 1 to ``MAX_FIT_FIELDS`` fields and at most
    :data:`MAX_LINK_READINGS` readings, read as a readings file's JSON
    (``core.back_analysis``: a bad value is named by its column and row). Returns
    ``{"fields": [...], "readings": Readings}``; ValueError naming the setting."""
    if not isinstance(settings, dict):
        raise ValueError("the fit settings are not a JSON object")
    fields = settings.get("fields")
    if not isinstance(fields, list) or not 1 <= len(fields) <= MAX_FIT_FIELDS or not all(
            f is None or (isinstance(f, str) and 0 < len(f) <= MAX_STUDY_KEY)
            for f in fields):
        raise ValueError(f"fit fields: must be a list of 1 to {MAX_FIT_FIELDS} field keys "
                         "(or null)")
    source = settings.get("source", "readings")
    if not isinstance(source, str) or not 0 < len(source) <= MAX_STUDY_KEY:
        raise ValueError(f"fit source: must be a name of 1 to {MAX_STUDY_KEY} characters")
    data = settings.get("readings")
    times = data.get("time") if isinstance(data, dict) else None
    if not isinstance(times, list) or len(times) > MAX_LINK_READINGS:
        raise ValueError(f"fit readings: must hold a list 'time' of at most "
                         f"{MAX_LINK_READINGS} readings")
    readings: Readings = readings_from_text(json.dumps(data), source)
    return {"fields": list(fields), "readings": readings}


def read_fit_query(query: dict[str, str]) -> tuple[dict[str, Any] | None, str]:
    """(the Fit tab's settings or None, message) from a link's query arguments."""
    if not query.get("fit"):
        return None, ""
    try:
        return fit_settings(decode_scene(query["fit"])), ""
    except (ValueError, TypeError) as exc:
        return None, f"The readings in the link were not used: {exc}."


def read_study_query(query: dict[str, str]) -> tuple[dict[str, Any] | None, str]:
    """(the Study tab's settings or None, message) from a link's query arguments."""
    if not query.get("study"):
        return None, ""
    try:
        return study_settings(decode_scene(query["study"])), ""
    except ValueError as exc:
        return None, f"The study settings in the link were not used: {exc}."


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
