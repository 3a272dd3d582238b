"""The Radau IIA step of the modal Volterra equations, batched (see core.time.integration).

Every mode ``w_k`` of :mod:`core.time.integration` with a kernel
``K(t, tau) = b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))`` is a small linear ODE in
the states ``S_0' = b z``, ``S_r' = -rate_r S_r + a_r z`` (``z = (r + V w)/d``, ``V w`` the
sum of the states). One step of the 3-stage Radau IIA method (order 5, L-stable) is built
here in two parts:

* :func:`_stage_values` reads the kernel and the histories at the stage times of B steps
  at once (a step, its two halves and the side steps to the output times inside it) and
  builds their step operators (:func:`_step_operators`, the stage operators by their
  adjugate, no inversion);
* :func:`_advance` takes steps from given states: one 3x3 system per mode and step,
  solved by Cramer's rule over the arrays (:func:`_solve_stages`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_S6 = np.sqrt(6.0)
RADAU_C = np.array([(4 - _S6) / 10, (4 + _S6) / 10, 1.0])
RADAU_A = np.array([
    [(88 - 7 * _S6) / 360, (296 - 169 * _S6) / 1800, (-2 + 3 * _S6) / 225],
    [(296 + 169 * _S6) / 1800, (88 + 7 * _S6) / 360, (-2 - 3 * _S6) / 225],
    [(16 - _S6) / 36, (16 + _S6) / 36, 1 / 9],
])
RADAU_ORDER = 5
# inv(I + x A) = adj(I + x A) / det(I + x A) with, for a 3x3 matrix (Cayley-Hamilton),
# adj(I + x A) = I + x P1 + x^2 P2, P1 = a I - A, P2 = (a^2 - b)/2 I - a A + A^2
# (a = tr A, b = tr A^2), and det = 1 + a x + (a^2 - b)/2 x^2 + det(A) x^3, whose
# coefficients are positive (the eigenvalues of A have positive real parts): no
# cancellation for any x >= 0. _Q = _P A gives inv A = (A + x Q1 + x^2 Q2) / det.
_TR, _TR2 = float(np.trace(RADAU_A)), float(np.trace(RADAU_A @ RADAU_A))
_P1 = _TR * np.eye(3) - RADAU_A
_P2 = 0.5 * (_TR**2 - _TR2) * np.eye(3) - _TR * RADAU_A + RADAU_A @ RADAU_A
_Q1, _Q2 = _P1 @ RADAU_A, _P2 @ RADAU_A
_P1_ROWS, _P2_ROWS = _P1.sum(axis=1), _P2.sum(axis=1)
_DET = (_TR, 0.5 * (_TR**2 - _TR2), float(np.linalg.det(RADAU_A)))
#: h * decay beyond which a state is fully relaxed within a step (inv ~ 1/x): capped so
#: that x^3 stays finite
_X_MAX = 1e60
#: Relative distance from a jump at which a history is read on the side before it (and,
#: at an output time on a jump, after it): far above the rounding of converting times
#: (days to the dimensionless time and back), far below any tolerance.
JUMP_SIDE = 1e-12



def _kernel_factors(kernel, t_stage: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``beta`` (states, stages): forcing factors; ``decay`` (states,): state decay rates."""
    rates = np.asarray(kernel.rates, dtype=float)
    if hasattr(kernel, "factors"):  # b and a_r in one evaluation (a fitted kernel)
        b, a = kernel.factors(t_stage)
    else:
        b, a = kernel.tau_part(t_stage), kernel.exponential_parts(t_stage)
    beta = np.concatenate([np.asarray(b, dtype=float)[None, :],
                           np.asarray(a, dtype=float).reshape(len(rates), -1)], axis=0)
    return beta, np.concatenate([[0.0], rates])


@dataclass(frozen=True)
class _Stages:
    """What B Radau steps read at their stage times, and the step operators built from it.

    ``hs`` (B,) step lengths; the histories ``d``, ``r`` (B, modes, 3) and ``u``
    (B, known, 3) (None where there are no modes or knowns); for every step and kernel
    state s, with ``inv_s = inv(I + h decay_s A)``: ``carry`` (B, states, 3) = ``inv_s 1``,
    ``total`` (B, 3, 3) = sum over s of ``inv_s h A diag(beta_s)``, and the step's end row
    of the latter, ``last_drive`` (B, states, 3), with its sum ``drive_sum`` (B, 3).
    """

    hs: np.ndarray
    d: np.ndarray | None
    r: np.ndarray | None
    u: np.ndarray | None
    carry: np.ndarray
    total: np.ndarray
    last_drive: np.ndarray
    drive_sum: np.ndarray

    def take(self, which: slice) -> _Stages:
        """The steps ``which`` (a slice: views, no copies) of these."""
        return _Stages(*(None if v is None else v[which] for v in (
            self.hs, self.d, self.r, self.u, self.carry, self.total, self.last_drive,
            self.drive_sum)))


def _step_operators(hs: np.ndarray, beta: np.ndarray, decay: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``carry``, ``total`` and ``last_drive`` of :class:`_Stages` for kernel factors
    ``beta`` (B, states, 3) and decay rates ``decay`` (states,)."""
    # inv(I + x A), x = h decay_s, for every step and state, by the adjugate (module
    # constants): (I + x P1 + x^2 P2) / det(x), det with positive coefficients
    x = np.minimum(hs[:, None] * decay[None, :], _X_MAX)     # (B, states)
    x2 = x * x
    det = 1.0 + x * _DET[0] + x2 * _DET[1] + x2 * x * _DET[2]
    carry = (1.0 + x[..., None] * _P1_ROWS + x2[..., None] * _P2_ROWS) / det[..., None]
    # inv h A diag(beta_s): forcing of the stages of state s by z at the stages
    scaled = beta / det[..., None]                           # (B, states, 3)
    g0 = scaled.sum(axis=1)                                  # (B, 3)
    g1 = (x[:, None, :] @ scaled)[:, 0, :]
    g2 = (x2[:, None, :] @ scaled)[:, 0, :]
    h3 = hs[:, None, None]
    total = h3 * (RADAU_A[None] * g0[:, None, :] + _Q1[None] * g1[:, None, :]
                  + _Q2[None] * g2[:, None, :])              # (B, 3, 3): over the states
    last_drive = h3 * (RADAU_A[2] + x[..., None] * _Q1[2] + x2[..., None] * _Q2[2]) * scaled
    return carry, total, last_drive


def _stage_values(kernel, problem, starts: np.ndarray, hs: np.ndarray,
                  before_jump: np.ndarray | None = None) -> _Stages:
    """Kernel and histories at the stage times of steps ``starts`` -> ``starts + hs``.

    All steps are read in one evaluation of the kernel and of the histories, whatever
    their starts: a step, its two halves and the side steps to the output times inside it
    cost one set of calls. ``before_jump`` (B,) bools: that step ends where a history
    jumps, so its last stage reads the history just before it.
    """
    hs = np.asarray(hs, dtype=float)
    n_steps = hs.size
    ts = np.asarray(starts, dtype=float)[:, None] + hs[:, None] * RADAU_C[None, :]  # (B, 3)
    if before_jump is not None and np.any(before_jump):
        ends = ts[before_jump, -1]
        ts[before_jump, -1] = ends - JUMP_SIDE * np.maximum(1.0, np.abs(ends))
    flat = ts.ravel()
    beta, decay = _kernel_factors(kernel, flat)             # (states, 3B), (states,)
    beta = beta.reshape(decay.size, n_steps, 3).transpose(1, 0, 2)   # (B, states, 3)

    def read(fn) -> np.ndarray:
        return fn(flat).reshape(-1, n_steps, 3).transpose(1, 0, 2)

    u = read(problem.u) if problem.n_known else None
    d = read(problem.d) if problem.n_modes else None
    r = read(problem.r) if problem.n_modes else None
    carry, total, last_drive = _step_operators(hs, beta, decay)
    return _Stages(hs, d, r, u, carry, total, last_drive, last_drive.sum(axis=1))


def _radau_step(kernel, problem, t0: float, h: float,
                s_modes: np.ndarray, s_known: np.ndarray, *, before_jump: bool = False
                ) -> tuple[np.ndarray, np.ndarray]:
    """One Radau IIA step of all channels. Returns the new mode and known-channel states.

    ``s_modes`` (modes, states), ``s_known`` (known, states). ``before_jump``: the step
    ends where a history jumps, so its last stage (at the step's end) reads the history
    just before the jump. See :func:`_radau_steps`, of which this is the case of one step.
    """
    modes, known = _radau_steps(kernel, problem, t0, np.array([float(h)]), s_modes, s_known,
                                before_jump=np.array([before_jump]))
    return modes[0], known[0]


def _radau_steps(kernel, problem, t0: float, hs: np.ndarray,
                 s_modes: np.ndarray, s_known: np.ndarray, *,
                 before_jump: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Radau IIA steps of lengths ``hs`` (B,), all from ``t0`` and the same states, at once.

    Returns the new states, (B, modes, states) and (B, known, states); see
    :func:`_stage_values` for ``before_jump`` and :func:`_advance` for the step.
    """
    hs = np.asarray(hs, dtype=float)
    stages = _stage_values(kernel, problem, np.full(hs.size, float(t0)), hs, before_jump)
    new_modes, new_known, _, _ = _advance(stages, problem.coupling, s_modes, s_known)
    return new_modes, new_known


def _advance(stages: _Stages, coupling: np.ndarray, s_modes: np.ndarray,
             s_known: np.ndarray, keep: int | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The Radau IIA steps ``stages`` from the states ``s_modes`` (modes, states) and
    ``s_known`` (known, states).

    Returns the new states of the first ``keep`` steps (all: None), (keep, modes, states)
    and (keep, known, states), and the sums over the states (``V w``, ``V u``) at the end
    of every step, (B, modes) and (B, known): a step that only reports (a side step to an
    output time, the full step of step doubling) needs no more than these.

    The states of one channel couple only through their sum ``V w``: a state obeys
    ``S_s' = -decay_s S_s + beta_s(t) z(t)`` with ``z = (r + V w)/d`` shared by all of them.
    Eliminating the states, whose stage operator ``I + h decay_s A`` is the same for every
    mode, leaves one 3x3 system in the stage values of ``z`` per mode: a step costs
    O(modes) small operations instead of a (3 states)^2 solve per mode.
    """
    n_steps = stages.hs.size
    carry, total, last_drive = stages.carry, stages.total, stages.last_drive
    last_carry = carry[:, :, 2]                              # (B, states): step's end
    kept = slice(None) if keep is None else slice(0, keep)
    n_kept = len(range(n_steps)[kept])
    drive_sum = stages.drive_sum                             # (B, 3)
    known_stage_sums = None
    if stages.u is None:  # no known channels: nothing to step
        new_known = np.zeros((n_kept,) + s_known.shape)
        known_sums = np.zeros((n_steps, s_known.shape[0]))
    else:
        # known channels: z = u, given
        u = stages.u                                         # (B, known, 3)
        known_stage_sums = s_known @ carry + u @ total.transpose(0, 2, 1)  # V u at stages
        new_known = (s_known[None] * last_carry[kept, None, :]
                     + u[kept] @ last_drive[kept].transpose(0, 2, 1))
        known_sums = last_carry @ s_known.T + (u @ drive_sum[:, :, None])[..., 0]
    if stages.d is None:  # no modes
        new_modes = np.zeros((n_kept,) + s_modes.shape)
        mode_sums = np.zeros((n_steps, s_modes.shape[0]))
    else:
        r = stages.r
        if known_stage_sums is not None:
            r = r + coupling[None] @ known_stage_sums
        # V w = d z - r at the stages, and V w = s @ carry + total z: solve for z
        z = _solve_stages(stages.d, total, s_modes @ carry + r)
        new_modes = (s_modes[None] * last_carry[kept, None, :]
                     + z[kept] @ last_drive[kept].transpose(0, 2, 1))
        mode_sums = last_carry @ s_modes.T + (z @ drive_sum[:, :, None])[..., 0]
    return new_modes, new_known, mode_sums, known_sums


def _solve_stages(d: np.ndarray, total: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve ``(diag(d[b, k]) - total[b]) z[b, k] = rhs[b, k]`` for every step b and mode k.

    ``d``, ``rhs`` (B, modes, 3), ``total`` (B, 3, 3). Cramer's rule over the arrays, which
    avoids a LAPACK call per system: the systems are well conditioned (``d >= 1`` on the
    diagonal, ``total`` the creep of one step), checked against the full stage system in
    tests/time/test_time_integration.py.
    """
    t = total[:, None]                                       # (B, 1, 3, 3)
    m00, m11, m22 = d[..., 0] - t[..., 0, 0], d[..., 1] - t[..., 1, 1], d[..., 2] - t[..., 2, 2]
    m01, m02, m10 = -t[..., 0, 1], -t[..., 0, 2], -t[..., 1, 0]
    m12, m20, m21 = -t[..., 1, 2], -t[..., 2, 0], -t[..., 2, 1]
    # the adjugate (cofactors, transposed) and the determinant by the first row; written
    # out entry by entry: gathering them with index tables was 5x slower on 6000 systems
    c00, c01, c02 = m11 * m22 - m12 * m21, m02 * m21 - m01 * m22, m01 * m12 - m02 * m11
    c10, c11, c12 = m12 * m20 - m10 * m22, m00 * m22 - m02 * m20, m02 * m10 - m00 * m12
    c20, c21, c22 = m10 * m21 - m11 * m20, m01 * m20 - m00 * m21, m00 * m11 - m01 * m10
    det = m00 * c00 + m01 * c10 + m02 * c20
    r0, r1, r2 = rhs[..., 0], rhs[..., 1], rhs[..., 2]
    return np.stack([c00 * r0 + c01 * r1 + c02 * r2, c10 * r0 + c11 * r1 + c12 * r2,
                     c20 * r0 + c21 * r1 + c22 * r2], axis=-1) / det[..., None]
