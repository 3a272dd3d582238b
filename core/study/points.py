"""The points of a design study (:class:`core.study.Study`) from its description: all of
them as a table (:func:`point_table`) or any of them on demand (:class:`StudyPoints`).

Order: grid axes in the order of the study (the last fastest), the samples innermost.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from core.study.definition import Parameter, Study

#: Samples drawn from one random stream: a study of more samples draws each block of this
#: many from its own stream, so that a batch's draws need neither the others nor a table
#: of all of them (at most 0.5 MB per distribution held at once).
DRAW_BLOCK = 65_536


def _draws(p: Parameter, rng: np.random.Generator, n: int) -> np.ndarray:
    args = dict(p.args)
    if p.kind == "normal":
        return rng.normal(args["mean"], args["std"], n)
    if p.kind == "lognormal":
        return args["median"] * np.exp(rng.normal(0.0, args["sigma"], n))
    return rng.uniform(args["low"], args["high"], n)


def _block_draws(study: Study, block: int) -> dict[str, np.ndarray]:
    """The draws of every distribution over one block of samples (``block`` -1: all the
    samples of a study of at most :data:`DRAW_BLOCK`, one stream in the study's order)."""
    dists = [p for p in study.parameters if not p.is_grid]
    if block < 0:
        rng = np.random.default_rng(study.seed)
        return {p.path: _draws(p, rng, study.samples) for p in dists}
    size = min(DRAW_BLOCK, study.samples - block * DRAW_BLOCK)
    # one stream per distribution and block, keyed by both: a block's draws need no other
    return {p.path: _draws(p, np.random.default_rng(
        np.random.SeedSequence(study.seed, spawn_key=(j, block))), size)
        for j, p in enumerate(dists)}


class StudyPoints:
    """The points of a study made on demand from its description: ``points(index)`` gives
    the field values of the points ``index`` (flat point numbers of :func:`point_table`'s
    order) by index arithmetic on the grid, and their draws from the sample's block of
    random streams, so that no array over all the points is ever held (the last block of
    draws is kept: at most :data:`DRAW_BLOCK` values per distribution)."""

    def __init__(self, study: Study) -> None:
        self.study = study
        grids = [p for p in study.parameters if p.is_grid]
        self.shape = tuple(len(p.values) for p in grids) + (study.samples,)
        self._grids = [(p.path, np.asarray(p.values, dtype=float)) for p in grids]
        self._block: tuple[int, dict[str, np.ndarray]] | None = None

    def draws(self, sample: np.ndarray) -> dict[str, np.ndarray]:
        """Each distribution's draws for the samples ``sample`` (ints in [0, samples))."""
        study = self.study
        if not any(not p.is_grid for p in study.parameters):
            return {}
        blocks = np.full(len(sample), -1) if study.samples <= DRAW_BLOCK \
            else sample // DRAW_BLOCK
        out: dict[str, np.ndarray] = {}
        for b in np.unique(blocks):
            if self._block is None or self._block[0] != b:
                self._block = (int(b), _block_draws(study, int(b)))
            here = blocks == b
            offset = sample[here] - max(int(b), 0) * DRAW_BLOCK
            for path, values in self._block[1].items():
                out.setdefault(path, np.empty(len(sample)))[here] = values[offset]
        return out

    def __call__(self, index: np.ndarray) -> dict[str, np.ndarray]:
        """``path -> values`` of the points ``index``, plus ``"sample"``."""
        coords = np.unravel_index(np.asarray(index, dtype=np.int64), self.shape)
        out = {path: values[c] for (path, values), c in zip(self._grids, coords[:-1],
                                                            strict=True)}
        sample = coords[-1].astype(np.int64)
        out |= self.draws(sample)
        return {p.path: out[p.path] for p in self.study.parameters} | {"sample": sample}


def point_table(study: Study) -> dict[str, np.ndarray]:
    """Every point's value of every varied field: ``path -> array`` of length
    :attr:`Study.n_points`, plus ``"sample"`` (the draw's index, 0 for a pure grid).

    Order: grid axes in the order of the study (the last fastest), the samples innermost.
    Draws: with at most :data:`DRAW_BLOCK` samples, from ``numpy.random.default_rng(seed)``,
    each distribution's in turn in the order of the study; with more, each block of
    :data:`DRAW_BLOCK` samples from its own stream (``SeedSequence(seed, spawn_key=
    (distribution, block))``). The same study always gives the same points, and
    :class:`StudyPoints` gives any of them without this table.
    """
    grids = [p for p in study.parameters if p.is_grid]
    shape = tuple(len(p.values) for p in grids) + (study.samples,)

    def spread(values: np.ndarray, axis: int) -> np.ndarray:
        # each point's value along one axis, without an index array per axis (at 1e6
        # points those held 8 MB an axis at once, the client's largest share of memory)
        view = [1] * len(shape)
        view[axis] = shape[axis]
        return np.array(np.broadcast_to(values.reshape(view), shape)).reshape(-1)

    table: dict[str, np.ndarray] = {}
    for axis, p in enumerate(grids):
        table[p.path] = spread(np.asarray(p.values, dtype=float), axis)
    sample = np.arange(study.samples, dtype=np.int64)
    for path, draws in StudyPoints(study).draws(sample).items():
        table[path] = spread(draws, len(shape) - 1)
    table["sample"] = spread(sample, len(shape) - 1)
    return {p.path: table[p.path] for p in study.parameters} | {"sample": table["sample"]}
