"""One batch of a design study: its points solved in order, in one task.

:func:`run_batch` is what a Dask task (or the serial loop) of :func:`core.study.sweep`
runs. Points that differ only in given loads share one validated scene (the loads
replaced with :func:`core.scene.replace_loads`: the same checks and
messages); on a scene the exact layered kernel answers, their full-contact answers come
at once (:func:`core.study.solve_load_batch`). Every other point is solved on its
own with :func:`core.scene.solve`, except that on a flat punch over an elastic base a
point whose eccentricity ``M / P`` an earlier point of the batch shares is that point's
answer scaled by the ratio of the forces (:func:`answers_scale_with_loads`), and where a
geometry's batch holds many lift-off eccentricities of one sign they are answered as one
family (:func:`core.study.liftoff.liftoff_family`: the smallest and the largest solved by
:func:`core.scene.solve`, the ones between located along the zone end and solved on
their zones). A point that fails is recorded with its message.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from core.scene import (
    LARGE_TILT,
    PunchesSolution,
    Scene,
    replace_loads,
    scene_from_dict,
    solve,
    strain_share,
)
from core.study.definition import apply_point
from core.study.liftoff import (
    FAMILY_MIN_ECCENTRICITIES,
    family_applies,
    family_flags,
    liftoff_family,
)
from core.study.loads import _dimensionless_loads, load_batch_applies, solve_load_batch
from core.study.outputs import point_outputs

__all__ = ["answers_scale_with_loads", "run_batch"]


def _load_only_base(base: Mapping[str, Any], paths: Sequence[str]) -> Scene | None:
    """The validated base scene when every varied field is one of its given loads
    (``loading.force``, ...), else None (each point's scene is then validated whole, as
    is a base scene that does not validate on its own)."""
    given = base.get("loading", {})
    if not paths or not all(path.startswith("loading.") and path.count(".") == 1
                            and path.split(".", 1)[1] in given for path in paths):
        return None
    try:
        scene = scene_from_dict(base)
    except Exception:  # noqa: BLE001 - each point then reports its own message
        return None
    scene.sample_extremes  # noqa: B018 - computed once here, kept by every point's scene
    return scene


def _given_load_paths(base: Mapping[str, Any], paths: Sequence[str]) -> list[int]:
    """The indices of ``paths`` that name one of the base scene's given loads."""
    given = base.get("loading", {})
    return [j for j, path in enumerate(paths) if path.startswith("loading.")
            and path.count(".") == 1 and path.split(".", 1)[1] in given]


def _geometry_groups(base: Mapping[str, Any], paths: Sequence[str],
                     values: np.ndarray) -> list[tuple[Mapping[str, Any] | None, np.ndarray]]:
    """The batch's points grouped by their values of the fields that are not given loads
    (in order of first appearance), each with its scene dict but for the loads (None when
    it cannot be built: its points then report their own messages). Without a given load
    among ``paths`` every point is its own geometry: one group, no shared scene."""
    loads = _given_load_paths(base, paths)
    others = [j for j in range(len(paths)) if j not in loads]
    if not loads:
        return [(None, np.arange(len(values)))]
    if not others:
        return [(base, np.arange(len(values)))]
    keys: dict[tuple, list[int]] = {}
    for i, row in enumerate(values):
        keys.setdefault(tuple(float(row[j]) for j in others), []).append(i)
    groups = []
    for key, rows in keys.items():
        try:
            scene = apply_point(base, {paths[j]: v for j, v in zip(others, key, strict=True)})
        except Exception:  # noqa: BLE001 - each point then reports its own message
            scene = None
        groups.append((scene, np.array(rows)))
    return groups


#: Outputs that do not scale with the loads on a flat punch (the others are proportional).
_LOAD_FREE_OUTPUTS = ("contact_width",)
#: Digits of ``M / (P a)`` that make two points one eccentricity: the scaled answer is then
#: that of an eccentricity ~1e-12 off, far below any solver tolerance.
_ECCENTRICITY_DIGITS = 12
#: Points with ``|M / (P a)|`` above this are solved on their own: at the punch edge the
#: checks refuse ``|M / P| >= a`` as rounded for each point, so one eccentricity can hold
#: both a refused point and an answered one.
_SCALED_ECCENTRICITY_MAX = 1.0 - 1e-6


def answers_scale_with_loads(scene: Scene | None) -> bool:
    """Whether every answer of ``scene`` under other constant loads is proportional to the
    force at a fixed eccentricity ``M / P``: a flat punch on uniform coatings (no gap) over
    an elastic base, with exactly a constant force and moment given. The problem (full or
    unilateral contact) is then homogeneous: loads ``(s P, s M)`` give ``s`` times the
    settlement, tilt, forces and pressures and the same contact zone."""
    if scene is None or set(scene.loading) != {"force", "moment"}:
        return False
    if not all(getattr(p, "kind", None) == "constant" for p in scene.loading.values()):
        return False
    profiles = [scene.shape] + [layer.thickness for layer in scene.coating]
    if not all(getattr(p, "kind", None) == "constant" for p in profiles):
        return False
    return scene.dimensionless.kernel is None


def _eccentricity_key(scene: Scene, point: Mapping[str, float]) -> tuple[int, float] | None:
    """The point's eccentricity on ``scene``, rounded (:data:`_ECCENTRICITY_DIGITS`), with
    the scene's id; None when the force is not positive or a load is not finite (such
    points are solved, or refused, on their own)."""
    loads = {name: point.get(name, float(profile.spec))
             for name, profile in scene.loading.items()}
    force, moment = loads["force"], loads["moment"]
    if not (np.isfinite(force) and np.isfinite(moment) and force > 0.0):
        return None
    eccentricity = moment / (force * scene.half_width)
    if abs(eccentricity) > _SCALED_ECCENTRICITY_MAX:
        return None
    return id(scene), round(eccentricity, _ECCENTRICITY_DIGITS)


def _scaled(answer: tuple[float, np.ndarray, float, list[str], float, float], force: float,
            outputs: Sequence[str]) -> tuple[np.ndarray, float, str]:
    """Outputs, error estimate and flags of a point with ``force`` [N/m] at the
    eccentricity of ``answer`` (its force, outputs, estimate, flags, largest |tilt|,
    :func:`core.scene.strain_share`)."""
    base_force, values, estimate, flags, tilt, share = answer
    ratio = force / base_force
    scale = np.array([1.0 if name in _LOAD_FREE_OUTPUTS else ratio for name in outputs])
    # large_settlement and large_tilt are the flags that depend on the size of the
    # answer, in the order core.scene.SceneSolution raises them
    kept = [f for f in flags if f not in ("large_settlement", "large_tilt")]
    if abs(ratio) * share > 1.0:
        kept.append("large_settlement")
    if abs(ratio * tilt) > LARGE_TILT:
        kept.append("large_tilt")
    return values * scale[:, None], estimate, ",".join(kept)


def _kept_answer(result: Any, outputs: Sequence[str]
                 ) -> tuple[float, np.ndarray, float, list[str], float, float]:
    """What a solved point keeps to answer the points of its eccentricity: its force
    [N/m], outputs, error estimate, flags, largest |tilt| [rad] and
    :func:`core.scene.strain_share` (of several punches, whose points are never
    scaled, NaN for the force, the tilt and the share)."""
    if isinstance(result, PunchesSolution):
        return (np.nan, point_outputs(result, outputs),
                float(result.info.get("error_estimate", np.nan)), list(result.flags), np.nan,
                np.nan)
    tilt = max(float(np.max(np.abs(result.tilt))) if result.tilt.size else 0.0,
               float(result.info.get("max_abs_tilt", 0.0)))
    force = result.scene.loading.get("force")
    return (float(force.spec) if force is not None else np.nan, point_outputs(result, outputs),
            float(result.info.get("error_estimate", np.nan)), list(result.flags), tilt,
            strain_share(result.scene, result.settlement, tilt,
                         float(np.nanmax(result.pressure_on_grid, initial=0.0))))


def _liftoff_families(validated: Sequence[Scene | None],
                      keys: Sequence[tuple[int, float] | None], values: np.ndarray,
                      loads: Sequence[str], load_columns: Sequence[int],
                      outputs: Sequence[str],
                      solved: dict[tuple[int, float], tuple]) -> dict[tuple[int, float], float]:
    """Answer the lift-off eccentricities of each scaled geometry of the batch at once
    where there are enough of them (:func:`core.study.liftoff.liftoff_family`), filling
    ``solved``; returns the seconds [s] each point of an answered eccentricity is charged
    (the family's time over the points it answered)."""

    first: dict[tuple[int, float], int] = {}
    count: dict[tuple[int, float], int] = {}
    for i, key in enumerate(keys):
        if key is not None:
            first.setdefault(key, i)
            count[key] = count.get(key, 0) + 1
    charged: dict[tuple[int, float], float] = {}
    scenes = {id(g): g for g in validated if g is not None}
    for scene_id, scene in scenes.items():
        for sign in (1.0, -1.0):
            picked = sorted((key for key in first if key[0] == scene_id
                             and key[1] * sign > 0), key=lambda k: abs(k[1]))
            if len(picked) < FAMILY_MIN_ECCENTRICITIES + 2:
                continue
            start = time.perf_counter()
            rows = {key: values[first[key]] for key in picked}
            done = _one_family(scene, picked, rows, loads, load_columns, outputs, solved)
            # the family's time shared by every point it answered (a key may hold several)
            points = sum(count[key] for key in done)
            share = (time.perf_counter() - start) / max(points, 1)
            charged.update({key: share for key in done})
    return charged


#: Points of the smallest eccentricities solved one by one, at most, to find the first
#: that lifts off (the ones below keep full contact in the thin-layer model's check).
_FULL_CONTACT_TRIES = 3


def _one_family(scene: Scene, picked: list[tuple[int, float]],
                rows: Mapping[tuple[int, float], np.ndarray], loads: Sequence[str],
                load_columns: Sequence[int], outputs: Sequence[str],
                solved: dict[tuple[int, float], tuple]) -> list[tuple[int, float]]:
    """One sign of eccentricity of one geometry: its smallest and largest eccentricities
    solved by :func:`core.scene.solve` (they fix the zone ends' range and the topology),
    the ones between by :func:`core.study.liftoff.liftoff_family`. Returns the keys it
    answered (into ``solved``); any doubt leaves the rest one by one."""

    if not family_applies(scene):
        return []
    points = [{name: float(rows[key][j]) for name, j in zip(loads, load_columns,
                                                            strict=True)} for key in picked]
    both = [{name: p.get(name, float(scene.loading[name].spec)) for name in ("force", "moment")}
            for p in points]
    forces = np.array([p["force"] for p in both])
    a = scene.half_width
    eccentricity = np.array([p["moment"] for p in both]) / (forces * a)
    _, plain = _dimensionless_loads(scene, {q: np.array([p[q] for p in both])
                                            for q in ("force", "moment")}, len(picked))
    if not plain.all():
        return []  # a point the checks may refuse: each one then speaks for itself
    sign = 1.0 if eccentricity[0] > 0 else -1.0

    def one(k: int) -> Any:
        try:
            sub = replace_loads(scene, points[k])
            result = solve(sub)
        except Exception:  # noqa: BLE001 - the loop solves it again and records it
            return None
        solved[picked[k]] = _kept_answer(result, outputs)
        return result

    def zone_end(result: Any) -> float | None:
        zones = {tuple(z) for z in result.contact_set}
        if result.info.get("contact") != "unilateral" or len(zones) != 1:
            return None
        (zone,) = zones
        if len(zone) != 1:
            return None
        lo, hi = zone[0]
        if sign > 0 and hi == a:
            return lo / a
        if sign < 0 and lo == -a:
            return hi / a
        return None

    low, low_result = None, None
    for k in range(min(_FULL_CONTACT_TRIES, len(picked) - 2)):
        low_result = one(k)
        if low_result is None:
            return []
        if low_result.info.get("contact") == "unilateral":
            low = k
            break
    if low is None or len(picked) - low < 3:
        return []
    high_result = one(len(picked) - 1)
    if high_result is None:
        return []
    ends = (zone_end(low_result), zone_end(high_result))
    flags = family_flags(low_result.flags)
    if None in ends or flags is None or flags != family_flags(high_result.flags):
        return []
    middle = slice(low + 1, len(picked) - 1)
    answers, _ = liftoff_family(scene, eccentricity[middle], forces[middle], ends, outputs,
                                flags)
    done = []
    for key, answer in zip(picked[middle], answers, strict=True):
        if answer is not None:
            solved[key] = (answer.force, answer.values, answer.estimate, answer.flags,
                           answer.tilt, answer.strain_share)
            done.append(key)
    return done


def run_batch(base: Mapping[str, Any], paths: Sequence[str], values: np.ndarray,
              outputs: Sequence[str], n_times: int) -> dict[str, np.ndarray]:
    """Solve the points of one batch in order (``values[i]`` holds point i's value of each
    of ``paths``). Points that differ only in given loads share one validated scene
    (:func:`_geometry_groups`); on a scene of the exact layered kernel their full-contact
    answers come at once (:func:`core.study.solve_load_batch`). Returns arrays:
    ``values`` ``(m, len(outputs), n_times)``, ``error_estimate`` (relative, -), ``flags``
    (comma-joined), ``error`` (the message of a failed point, else empty), ``seconds``
    (per point)."""

    m = len(values)
    out = np.full((m, len(outputs), n_times), np.nan)
    estimate = np.full(m, np.nan)
    flags = [""] * m
    errors = [""] * m
    seconds = np.zeros(m)
    load_columns = _given_load_paths(base, paths)
    loads = [paths[j].split(".", 1)[1] for j in load_columns]
    load_paths = [paths[j] for j in load_columns]
    batched = np.zeros(m, dtype=bool)
    validated: list[Scene | None] = [None] * m
    for scene_dict, rows in _geometry_groups(base, paths, values):
        if scene_dict is None or (scene_dict is not base and len(rows) < 2):
            continue  # nothing shared: the point's whole scene is validated on its own
        group = _load_only_base(scene_dict, load_paths)
        for i in rows:
            validated[i] = group
        if group is None or not load_batch_applies(group):
            continue
        # a linear problem: the whole group at once, the points it leaves one by one
        start = time.perf_counter()
        answer = solve_load_batch(group, {q: values[rows, j] for q, j in
                                          zip(loads, load_columns, strict=True)}, outputs)
        done = rows[answer.answered]
        batched[done] = True
        out[done] = answer.values[answer.answered]
        estimate[done] = answer.error_estimate[answer.answered]
        for i, k in zip(rows, range(len(rows)), strict=True):
            if answer.answered[k]:
                flags[i] = answer.flags[k]
        seconds[done] = (time.perf_counter() - start) / max(done.size, 1)
    scaling = {id(g): answers_scale_with_loads(g) for g in validated if g is not None}
    # per eccentricity, the first solved point's answer (a flat punch, elastic base)
    solved: dict[tuple[int, float], tuple[float, np.ndarray, float, list[str], float]] = {}
    keys: list[tuple[int, float] | None] = [None] * m
    for i, row in enumerate(values):
        if not batched[i] and validated[i] is not None and scaling[id(validated[i])]:
            point = {q: float(row[j]) for q, j in zip(loads, load_columns, strict=True)}
            keys[i] = _eccentricity_key(validated[i], point)
    family_seconds = _liftoff_families(validated, keys, values, loads, load_columns,
                                       outputs, solved)
    for i, row in enumerate(values):
        if batched[i]:
            continue
        start = time.perf_counter()
        key = keys[i]
        if key is not None and key in solved:
            point = {q: float(row[j]) for q, j in zip(loads, load_columns, strict=True)}
            out[i], estimate[i], flags[i] = _scaled(
                solved[key], point.get("force", float(validated[i].loading["force"].spec)),
                outputs)
            seconds[i] = time.perf_counter() - start + family_seconds.get(key, 0.0)
            continue
        try:
            if validated[i] is not None:
                # only the loads change: the group's scene was validated once
                scene = replace_loads(validated[i], {q: float(row[j]) for q, j in
                                                     zip(loads, load_columns, strict=True)})
            else:
                scene = apply_point(base, dict(zip(paths, row, strict=True)))
            result = solve(scene)
            answer = _kept_answer(result, outputs)
            out[i], estimate[i], flags[i] = answer[1], answer[2], ",".join(answer[3])
            if key is not None:
                solved[key] = answer
        except Exception as exc:  # noqa: BLE001 - a failed point is recorded, never fatal
            errors[i] = (" ".join(str(exc).split()) or type(exc).__name__)[:500]
            flags[i] = "failed"
        seconds[i] = time.perf_counter() - start
    return {"values": out, "error_estimate": estimate, "flags": np.array(flags, dtype=str),
            "error": np.array(errors, dtype=str), "seconds": seconds}
