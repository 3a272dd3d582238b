"""The modes of the exponential collocation marched over the steps (:mod:`core.time.exponential`).

Every mode carries its memory in ``S`` states (one per exponential of the kernel, and
the kernel's constant part). At a step's start the states are known; ``z`` at the
step's four points follows from them by a small solve (:func:`point_values`, formed for
all steps at once) and the states take the step's drive by ``z``. :func:`mode_march`
does this step after step and returns the outputs' reads of the states at their steps'
starts and ``z`` at every point; two ways, chosen by the number of states
(:data:`AFFINE_STATES`):

* few states: the step is an affine map of each mode's states, ``s' = A s + e``
  (``A`` S x S per mode), formed for a block of steps at once, so the march is one
  small product a step and ``z`` is read afterwards for all steps at once;
* many states (the fitted code-creep kernels, 36): ``A`` would cost ``S**2`` a mode and
  step against ``~8 S`` for forming ``z`` on the way, so the step forms ``z`` from the
  state sums and moves the states by it, keeping two steps' states (all of them were
  27 MB on the 50-year two-punch preset: 36 states, 504 channels, ~200 steps, whose
  first touch cost more than the march).
"""

from __future__ import annotations

import numpy as np

#: Kernels with at most this many states are marched by affine maps. Measured (CPU, one
#: thread): the aging scene (2 states, 284 modes) 7.6 -> 7.3 ms for its three grids at
#: 100 outputs; the 50-year fib MC2010 preset (36 states, 126 modes) 27 -> 190 ms with
#: maps, so it keeps the step-by-step form. The flops of the two cross near 8 states.
AFFINE_STATES = 8


def by_step(values: np.ndarray, points: int) -> np.ndarray:
    """(channels, steps * points) values at the points of consecutive steps, as
    (steps, channels, points)."""
    return values.reshape(values.shape[0], -1, points).transpose(1, 0, 2)


def point_values(d: np.ndarray, r: np.ndarray, total: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """``z`` at a step's four points as ``constant + sum_j response[:, j] sums[j]``.

    ``d`` (B, 4, F), ``r`` (B, 4, M) at the points (``r`` with the drive of ``V u``),
    ``total`` (B, 3, 4) the step's drive of ``V w`` at its three later points by ``z`` at
    its four; ``sums`` (4, M) are the carried states' sums at the points. The first point
    is explicit (``d z = r + sums``), the three others solve ``(diag(d) - total[:, 1:]) z
    = r + sums + total[:, 0] z_0`` (by the adjugate: ``d >= 1`` on the diagonal, the
    step's creep off it); both for all steps at once, so the march only applies them.
    Returns ``constant`` (B, 4, M) and ``response`` (B, 4, 4, F), modes last (contiguous
    for the march).

    ``d`` may hold the first F of the M channels only, when the M = P F channels are P
    groups of the same modes with the same ``d`` (the parts of a load stepped together):
    ``response`` depends on ``d`` alone and is then formed once for all groups. Both
    should be contiguous: with the modes strided (the layout of the histories as read,
    modes first) the products here cost ~3x more (measured 1.8 against 0.6 ms a call on
    the aging scene's 56 steps of 284 channels).
    """
    t = total[:, :, :, None]                                      # (B, 3, 4, 1)
    m = [[(d[:, i + 1] if i == j else 0.0) - t[:, i, j + 1] for j in range(3)]
         for i in range(3)]
    adj = [[m[1][1] * m[2][2] - m[1][2] * m[2][1], m[0][2] * m[2][1] - m[0][1] * m[2][2],
            m[0][1] * m[1][2] - m[0][2] * m[1][1]],
           [m[1][2] * m[2][0] - m[1][0] * m[2][2], m[0][0] * m[2][2] - m[0][2] * m[2][0],
            m[0][2] * m[1][0] - m[0][0] * m[1][2]],
           [m[1][0] * m[2][1] - m[1][1] * m[2][0], m[0][1] * m[2][0] - m[0][0] * m[2][1],
            m[0][0] * m[1][1] - m[0][1] * m[1][0]]]
    inv_det = 1.0 / (m[0][0] * adj[0][0] + m[0][1] * adj[1][0] + m[0][2] * adj[2][0])
    inv_d0 = 1.0 / d[:, 0]                                        # (B, M)
    n_steps, nm = inv_d0.shape
    response = np.zeros((n_steps, 4, 4, nm))
    response[:, 0, 0] = inv_d0
    for i in range(3):
        for j in range(3):
            np.multiply(adj[i][j], inv_det, out=response[:, i + 1, j + 1])
    # the later points' response to the first: through the drive total[:, j, 0] z_0
    np.multiply(np.einsum("bijf,bj->bif", response[:, 1:, 1:], total[:, :, 0]),
                inv_d0[:, None, :], out=response[:, 1:, 0])
    # response times r, point by point (its first row is inv_d0 at the first point alone)
    r = r.reshape(n_steps, 4, -1, nm)                             # (B, 4, P, F)
    constant = np.einsum("bikf,bkpf->bipf", response, r)
    return constant.reshape(n_steps, 4, -1), response


def mode_march(problem, at_steps: np.ndarray, total: np.ndarray, reads: np.ndarray,
               end_drive: np.ndarray, end_carry: np.ndarray, vu_nodes: np.ndarray | None,
               block_elements: int, restart: np.ndarray | None,
               read_at: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The outputs' reads of the states (R, M) and ``z`` at each step's points (B, 4, M).

    ``read_at`` (``bounds`` (B + 1,), ``weights`` (R, S)): the outputs of step ``b`` are
    ``rows[bounds[b]:bounds[b + 1]] = weights[bounds[b]:bounds[b + 1]] @ states[b]``,
    ``states[b]`` (S, M) the states at the step's start.

    ``at_steps`` (B, 4) the times of the points; ``total`` (B, 3, 4) the step's drive of
    ``V w`` at its later points by ``z`` at its four; ``reads`` (B, S, 4) the states'
    weights at the points (ones at the start); ``end_drive`` (B, 4, S), ``end_carry``
    (B, S) how the states reach the step's end; ``vu_nodes`` (B, K, 4) ``V u`` at the
    points or None; the point systems are formed for blocks of steps of at most
    ``block_elements`` floats; ``restart`` (B,) bools: the states after that step start
    again from zero (the steps of several grids marched in one pass), None: never.
    Dimensionless throughout.
    """
    n_steps, n_states = end_carry.shape
    nm = problem.n_modes
    affine = n_states <= AFFINE_STATES
    per_step = 16 + (n_states**2 if affine else 0)
    block = max(1, block_elements // (per_step * nm))
    reads_t = reads.transpose(0, 2, 1).copy()                     # (B, 4, S)
    drive_t = end_drive.transpose(0, 2, 1).copy()                 # (B, S, 4)
    # the many-state march keeps two steps' states (see the module notes)
    states = np.zeros((n_steps + 1 if affine else 2, n_states, nm))
    bounds, weights = read_at
    rows = np.empty((weights.shape[0], nm))
    z_all = np.empty((n_steps, 4, nm))
    diagonal = np.arange(n_states)
    if restart is None:
        restart = np.zeros(n_steps, dtype=bool)
    for first in range(0, n_steps, block):
        steps = slice(first, min(n_steps, first + block))
        times_block = at_steps[steps].ravel()
        n_block = times_block.size // 4
        d = problem.d(times_block)                               # (M, 4 b)
        # the parts stepped together share the modes and d: one response for all
        by_part = d.reshape(problem.parts, -1, d.shape[1])
        shared = problem.parts > 1 and bool(np.all(by_part == by_part[:1]))
        groups = problem.parts if shared else 1
        r = problem.r(times_block)                               # (M, 4 b)
        if vu_nodes is not None:  # the drive of V u at the points: one product
            r = r + problem.coupling @ vu_nodes[steps].transpose(1, 0, 2).reshape(
                vu_nodes.shape[1], -1)
        # points before channels, contiguous (see point_values)
        constant, response = point_values(
            np.ascontiguousarray((by_part[0] if shared else d).T).reshape(n_block, 4, -1),
            np.ascontiguousarray(r.T).reshape(n_block, 4, -1), total[steps])
        n_block, n_each = response.shape[0], response.shape[-1]
        drive_b, reads_b = drive_t[steps], reads_t[steps]
        if not affine:
            for k in range(n_block):
                b = first + k
                now, after = states[b % 2], states[(b + 1) % 2]
                if bounds[b + 1] > bounds[b]:
                    rows[bounds[b]:bounds[b + 1]] = weights[bounds[b]:bounds[b + 1]] @ now
                # z at the step's four points: affine in the state sums there
                sums = (reads_b[k] @ now).reshape(4, groups, n_each)
                z = z_all[b] = constant[k] + np.einsum(
                    "ikf,kpf->ipf", response[k], sums).reshape(4, nm)
                if restart[b]:
                    after.fill(0.0)  # the next grid starts from rest
                    continue
                np.multiply(now, end_carry[b][:, None], out=after)
                after += drive_b[k] @ z
            continue
        # A[s, t] = carry_s delta_st + sum_ik drive[s, i] response[i, k] reads[k, t]
        through = (drive_b @ response.reshape(n_block, 4, -1)).reshape(
            n_block, n_states, 4, n_each)                              # (b, S, 4, F)
        maps = reads_b.transpose(0, 2, 1)[:, None] @ through           # (b, S, S, F)
        maps[:, diagonal, diagonal, :] += end_carry[steps][:, :, None]
        shifts = (drive_b @ constant).reshape(n_block, n_states, groups, n_each)
        for k in range(n_block):
            if restart[first + k]:
                continue
            after = states[first + k + 1].reshape(n_states, groups, n_each)
            np.einsum("stf,tpf->spf", maps[k],
                      states[first + k].reshape(n_states, groups, n_each), out=after)
            after += shifts[k]
        # z at the four points of the block's steps, from the states at their starts
        sums = (reads_b @ states[steps]).reshape(n_block, 4, groups, n_each)
        z = constant.reshape(n_block, 4, groups, n_each) + np.einsum(
            "bikf,bkpf->bipf", response, sums)
        z_all[steps] = z.reshape(n_block, 4, nm)
    if affine:
        for b in np.flatnonzero(bounds[1:] > bounds[:-1]):
            rows[bounds[b]:bounds[b + 1]] = weights[bounds[b]:bounds[b + 1]] @ states[b]
    return rows, z_all
