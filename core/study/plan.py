"""The order in which :func:`core.study.sweep` runs a study's points, and its batches,
made batch by batch from the study's description: no array over all the points is held.

Points sharing a geometry (every varied field but the loads) are neighbours, so that the
solver's cached geometric stages serve them all. The plan is a walk over the study's axes
in closed form: the geometry's grid axes outermost (in the order of the study, each in
ascending order of its values), then the samples when a non-load field is drawn (each
sample is then its own geometry), then the loads' grid axes (same rule) and the samples
of drawn loads. When force and moment both vary (the ``"eccentricity"`` plan), a
geometry's loads are sorted by the eccentricity ``M / P`` (then by the loads) within
windows of at most :data:`PLAN_WINDOW` points, so that points of one eccentricity share a
batch (on a flat punch one answer serves them all) and a batch's lift-off eccentricities
are close; a study of at most that many loads per geometry is sorted as a whole.
"""

from __future__ import annotations

import math

import numpy as np

from core.study.definition import Study
from core.study.points import DRAW_BLOCK, StudyPoints

#: Most points of one geometry sorted together by eccentricity: bounds the client's
#: memory of planning whatever the study's size (at the peak, a batch straddling two
#: windows, a dozen arrays of twice this many points: 6.3 MB measured by tracemalloc).
PLAN_WINDOW = 32_768
#: The manifest's name of this way of ordering points and drawing samples: parts written
#: in another order hold other points under the same batch numbers.
PLAN_ORDER = f"axes, eccentricity windows of {PLAN_WINDOW}, draws in blocks of {DRAW_BLOCK}"


def batch_plan(study: Study) -> str:
    """How a geometry's loads are ordered: ``"eccentricity"`` when both ``loading.force``
    and ``loading.moment`` vary, else ``"lexicographic"``."""
    paths = {p.path for p in study.parameters}
    return "eccentricity" if {"loading.force", "loading.moment"} <= paths else "lexicographic"


class BatchPlan:
    """The batches of a study of ``batch_points`` points each: :meth:`batch` gives the
    point numbers (flat, in :func:`core.study.definition.point_table`'s order) of batch ``k``.
    Asking for the batches in order costs about one or two sorts of each window; the
    windows last sorted are kept (the point numbers of at most 2 :data:`PLAN_WINDOW`)."""

    def __init__(self, study: Study, batch_points: int,
                 points: StudyPoints | None = None) -> None:
        self.study = study
        self.batch_points = int(batch_points)
        self.points = points or StudyPoints(study)
        self.plan = batch_plan(study)
        self.n_points = study.n_points
        self.n_batches = math.ceil(self.n_points / self.batch_points)
        grid_axes = [(i, p) for i, p in enumerate(p for p in study.parameters if p.is_grid)]
        sample_axis = len(grid_axes)
        drawn = [p for p in study.parameters if not p.is_grid]
        sample_is_geometry = any(not p.is_load for p in drawn)

        def axis(i: int, p: object) -> tuple[int, int, np.ndarray | None]:
            values = np.asarray(p.values, dtype=float)
            ascending = np.argsort(values, kind="stable")
            same = np.array_equal(ascending, np.arange(len(values)))
            return i, len(values), None if same else ascending

        outer = [axis(i, p) for i, p in grid_axes if not p.is_load]
        inner = [axis(i, p) for i, p in grid_axes if p.is_load]
        samples = (sample_axis, study.samples, None)
        (outer if sample_is_geometry else inner).append(samples)
        self._axes = outer + inner
        self.loads_per_geometry = math.prod(n for _, n, _ in inner)
        self._load_paths = [p.path for p in study.parameters if p.is_load]
        self._window: tuple[int, int, np.ndarray] | None = None

    def size(self, k: int) -> int:
        """Points in batch ``k``."""
        return min(self.batch_points, self.n_points - k * self.batch_points)

    def batch(self, k: int) -> np.ndarray:
        """The point numbers of batch ``k`` (int64), in the order they run."""
        if not 0 <= k < self.n_batches:
            raise IndexError(f"batch {k} of a plan of {self.n_batches}")
        start = k * self.batch_points
        stop = start + self.size(k)
        if self.plan != "eccentricity" or self.loads_per_geometry == 1:
            return self._flat(np.arange(start, stop, dtype=np.int64))
        if self._window is None or not (self._window[0] <= start
                                        and stop <= self._window[1]):
            # the windows this batch meets: one, two where it straddles their boundary
            first, last = self._window_start(start), self._window_end(stop - 1)
            self._window = (first, last, self._sorted(first, last))
        first, _, order = self._window
        return order[start - first:stop - first]

    @property
    def same_as_whole_sort(self) -> bool:
        """Whether this plan equals a sort of all the points at once (by geometry, then
        eccentricity, then the loads): no field is drawn and a geometry's loads fit in one
        window. Parts written before the windows came are then still in this order."""
        return (all(p.is_grid for p in self.study.parameters)
                and (self.plan != "eccentricity" or self.loads_per_geometry <= PLAN_WINDOW))

    # ---------------------------------------------------------------------- internals

    def _flat(self, position: np.ndarray) -> np.ndarray:
        """The point numbers at the plan's positions ``position`` (before any window sort)."""
        coords: list[np.ndarray] = [np.empty(0)] * len(self._axes)
        rest = position
        for axis, n, ascending in reversed(self._axes):
            rest, digit = np.divmod(rest, n)
            coords[axis] = digit if ascending is None else ascending[digit]
        return np.ravel_multi_index(tuple(coords), self.points.shape).astype(np.int64)

    def _window_start(self, position: int) -> int:
        geometry, load = divmod(position, self.loads_per_geometry)
        return geometry * self.loads_per_geometry + (load // PLAN_WINDOW) * PLAN_WINDOW

    def _window_end(self, position: int) -> int:
        geometry, load = divmod(position, self.loads_per_geometry)
        return geometry * self.loads_per_geometry + min((load // PLAN_WINDOW + 1) * PLAN_WINDOW,
                                                        self.loads_per_geometry)

    def _sorted(self, first: int, last: int) -> np.ndarray:
        """Point numbers of positions [first, last) (whole windows), each window sorted by
        eccentricity, then by the loads in the order of the study (ties: position)."""
        position = np.arange(first, last, dtype=np.int64)
        flat = self._flat(position)
        values = self.points(flat)
        geometry, load = np.divmod(position, self.loads_per_geometry)
        window = geometry * (self.loads_per_geometry // PLAN_WINDOW + 1) + load // PLAN_WINDOW
        force = values["loading.force"]
        with np.errstate(all="ignore"):
            eccentricity = np.where(force > 0, values["loading.moment"]
                                    / np.where(force > 0, force, 1.0), np.inf)
        keys = [values[p] for p in reversed(self._load_paths)] + [eccentricity, window]
        return flat[np.lexsort(keys)]
