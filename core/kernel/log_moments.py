"""Moments of the log kernel against Legendre polynomials (product integration on a panel).

    M_n(z) = int_{-1}^{1} ln|z - t| P_n(t) dt = 2 [Q_{n+1}(z) - Q_{n-1}(z)] / (2n + 1),

with ``Q_n`` the Legendre functions of the second kind (dimensionless, ``z`` the target
in the panel's reference coordinate).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.polynomial import legendre as npleg

#: Points outside [-1.05, 1.05] from which Miller's recurrence runs in bands of |z|.
_MILLER_BANDS_FROM = 2048
#: Gauss points of the plain rule that may replace Miller's recurrence for
#: 1.05 < |z| <= OUTER_RULE_REACH: ln|z - t| P_n(t) is analytic in the Bernstein ellipse
#: through z (rho >= 1.37), so 72 points leave rho^(15 - 144) < 1e-17 of quadrature error;
#: what remains is rounding, measured <= 1.4e-14 absolute against the recurrence for
#: n <= 15 (it grows with ln|z|: 1e-12 at |z| = 870).
_OUTER_RULE_POINTS = 72
OUTER_RULE_REACH = 3.0
#: The rule's error in the moments (absolute), with a margin over the measured 1.4e-14.
OUTER_RULE_ERROR = 2.5e-14


@lru_cache(maxsize=8)
def _outer_rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes (K,) and weights times P_n at the nodes (K, degree + 1) of the outer rule."""
    t, w = npleg.leggauss(_OUTER_RULE_POINTS)
    weighted = npleg.legvander(t, degree) * w[:, None]
    for shared in (t, weighted):  # cached: every caller gets these very arrays
        shared.setflags(write=False)
    return t, weighted


def _q_outside(z: np.ndarray, nq: int, own_start: bool = False) -> np.ndarray:
    """``Q_n(z)``, n < nq, for |z| > 1 by Miller's backward recurrence (shape (len(z), nq)).

    ``own_start``: each point starts the recurrence at its own index (else all at the one
    the smallest rho needs), so its values do not depend on the other points passed.
    """
    zo = np.abs(z)
    rho = zo + np.sqrt(zo * zo - 1.0)
    # Start index so that rho^-2(start - n) < 1e-18 for every needed n.
    starts = nq + np.ceil(18 * np.log(10) / (2 * np.log(rho))).astype(int) + 5
    start = int(starts.max())
    # points that start later than the first ones: (re)started at their own index
    begins = ({int(s): np.nonzero(starts == s)[0] for s in np.unique(starts) if s < start}
              if own_start else {})
    qa = np.zeros(zo.size)
    qb = np.full(zo.size, 1e-280)
    vals = np.empty((zo.size, nq))
    for n in range(start, 0, -1):
        if n in begins:
            qa[begins[n]] = 0.0
            qb[begins[n]] = 1e-280
        # (n) Q_{n-1} = (2n+1) z Q_n - (n+1) Q_{n+1}, in place: qa becomes Q_{n-1}
        qa *= -(n + 1) / n
        qa += ((2 * n + 1) / n) * zo * qb
        qa, qb = qb, qa
        if n - 1 < nq:
            vals[:, n - 1] = qb
        # Rescale every 4th step: 4 steps grow |Q| by less than (3 |z| + 3)^4, far below
        # the 1e108 left above 1e200 for any |z| < 1e20.
        if n % 4 == 0:
            big = np.abs(qb) > 1e200
            if big.any():
                qa[big] *= 1e-200
                qb[big] *= 1e-200
                vals[big] *= 1e-200
    exact0 = 0.5 * np.log((zo + 1.0) / (zo - 1.0))
    vals *= (exact0 / vals[:, 0])[:, None]
    # Q_n(-z) = (-1)^(n+1) Q_n(z)
    neg = z < 0
    if neg.any():
        vals[neg] *= ((-1.0) ** (np.arange(nq) + 1))[None, :]
    return vals


def legendre_log_moments(z: np.ndarray, degree: int, rounding: float = 0.0, *,
                         own_start: bool = False) -> np.ndarray:
    """``M_n(z) = int_{-1}^{1} ln|z - t| P_n(t) dt`` for n = 0..degree (shape (len(z), degree+1)).

    Uses Legendre functions of the second kind ``Q_n``: forward recurrence where it is
    stable (|z| <= 1.05) and Miller's backward recurrence outside, where ``Q_n`` is the
    minimal solution and the forward recurrence loses ~2n log10(|z| + sqrt(z^2 - 1)) digits.
    ``rounding``: the absolute error the caller accepts; at OUTER_RULE_ERROR or above, a
    few points just outside are integrated by a fixed Gauss rule instead (one small
    matrix product against Miller's ~90 sequential steps: 0.27 -> 0.03 ms for 150 points).
    ``own_start``: every point's moments are the same whatever other points are passed
    with it (Miller's recurrence starts at each point's own index): for cached values.
    """
    z = np.asarray(z, dtype=float)
    ends = np.abs(np.abs(z) - 1.0) < 1e-13
    # M_n is continuous at |z| = 1 but Q_n is not defined there: step just inside (the
    # exact end values replace the result below).
    z = np.where(ends, np.sign(z) * (1.0 - 1e-13), z)
    nq = degree + 2
    q = np.empty((z.size, nq))
    with np.errstate(divide="ignore", invalid="ignore"):
        q0 = 0.5 * np.log(np.abs((1.0 + z) / (1.0 - z)))
    inner = np.abs(z) <= 1.05
    if inner.any():
        zi = z[inner]
        # one row per degree (contiguous), each step in place: the same operations in the
        # same order as ((2n + 1) z Q_n - n Q_(n-1)) / (n + 1), a third fewer passes
        qi = np.empty((nq, zi.size))
        qi[0] = q0[inner]
        np.multiply(zi, qi[0], out=qi[1])
        qi[1] -= 1.0
        term = np.empty(zi.size)
        for n in range(1, nq - 1):
            row = qi[n + 1]
            np.multiply(zi, 2 * n + 1, out=row)
            row *= qi[n]
            np.multiply(qi[n - 1], n, out=term)
            row -= term
            row /= n + 1
        q[inner] = qi.T
    outer = ~inner
    by_rule = None
    rule = outer & (np.abs(z) <= OUTER_RULE_REACH)
    if rounding >= OUTER_RULE_ERROR and 0 < rule.sum() <= _MILLER_BANDS_FROM:
        t, weighted = _outer_rule(degree)
        by_rule = np.log(np.abs(z[rule, None] - t[None, :])) @ weighted
        q[rule] = 0.0  # not used: replaced below
        outer = outer & ~rule
    # Miller's recurrence from an index set by the smallest rho of a group. Many points:
    # in bands of |z|, so that the many well outside a panel do not run the ~90 steps the
    # few just outside need; few points: one group (the steps' overhead dominates).
    bands = (1.05, 1.2, 1.5, 2.2, np.inf) if outer.sum() > _MILLER_BANDS_FROM else (
        1.05, np.inf)
    for low, high in zip(bands[:-1], bands[1:], strict=True):
        group = outer & (np.abs(z) > low) & (np.abs(z) <= high)
        if group.any():
            q[group] = _q_outside(z[group], nq, own_start)
    m = np.empty((z.size, degree + 1))
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (1.0 + z) * np.log(np.abs(1.0 + z))
        b = (1.0 - z) * np.log(np.abs(1.0 - z))
    a = np.where(np.isfinite(a), a, 0.0)
    b = np.where(np.isfinite(b), b, 0.0)
    m[:, 0] = a + b - 2.0
    n = np.arange(1, degree + 1)
    m[:, 1:] = 2.0 * (q[:, 2 : degree + 2] - q[:, 0:degree]) / (2 * n + 1)
    # On a panel end the recurrence ran just inside; use the exact end values instead:
    # M_0(1) = 2 ln 2 - 2, M_n(1) = -2/(n (n + 1)), M_n(-1) = (-1)^n M_n(1).
    if ends.any():
        exact = np.concatenate([[2.0 * np.log(2.0) - 2.0], -2.0 / (n * (n + 1.0))])
        parity = np.where(z[ends, None] < 0, (-1.0) ** np.arange(degree + 1)[None, :], 1.0)
        m[ends] = exact[None, :] * parity
    if by_rule is not None:
        m[rule] = by_rule
    return m
