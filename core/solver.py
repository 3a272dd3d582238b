"""``solve_dimensionless``: the dimensionless problem, answered by one of the engines.

The dimensionless problem (model notes; the seed's (9)-(12)):

    c(t) m(x) q(x,t) + (I - V) F q = delta(t) + alpha(t) x - g(x),   -1 <= x <= 1,  t >= 1,
    int q dx = P(t),   int x q dx = M(t).

The default engine is :mod:`core.engines.nystrom`; the seed's projection method is
:mod:`core.engines.projection`; the contact model (full, unilateral, auto) is
:mod:`core.contact`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from core.engines.projection import solve_projection, validate_inputs
from core.problem import ContactSolution

Scalar = float | Callable[[np.ndarray], np.ndarray]


def solve_dimensionless(lam: float, m: Scalar, g: Scalar, times: Sequence[float] | np.ndarray,
                        *, c: Scalar = 1.0, kernel: Callable | None = None,
                        settlement: Scalar | None = None, tilt: Scalar | None = None,
                        force: Scalar | None = None, moment: Scalar | None = None,
                        breakpoints: Sequence[float] = (), tol: float = 1e-8,
                        basis: str = "graded", n_modes: int | None = None,
                        method: str | None = None, contact: str = "auto",
                        time_breaks: Sequence[float] = ()) -> ContactSolution:
    """Solve the dimensionless contact problem (Nystrom by default, or the seed's projection).

    Parameters (all dimensionless):
        lam: a/H, half-width over base thickness (> 0).
        m: coating compliance m(x) > 0 on [-1, 1] (number or vectorized callable).
        g: gap g(x) (number or vectorized callable); may jump at ``breakpoints``.
        times: output times, increasing, the first >= 1 (t = 1 is the moment of loading).
        c: relative base modulus c(t) = E(t)/E0 > 0 (number or callable of t).
        kernel: None (elastic base) or the creep kernel K(t, tau) of ``V``; a
            :class:`core.creep.models.DegenerateKernel` is stepped in O(1) per mode and step.
        settlement, tilt, force, moment: exactly two, numbers or callables of t
            (delta, alpha, P, M).
        breakpoints: points of (-1, 1) where m or g may jump.
        tol: relative accuracy target for delta, alpha (relative to max(|delta|, |alpha|)),
            P, M (relative to max(|P|, |M|)) and q (relative to max|q| over interior points).
        basis: "graded" (default: continuous piecewise polynomials on meshes graded toward
            the edges and jumps), "piecewise" (polynomials between breakpoints) or "global"
            (the seed's basis).
        n_modes: a fixed number of basis functions (for studies); default adaptive.
        method: "nystrom" (the default: a direct solve on graded panels, adaptively
            refined, :mod:`core.engines.nystrom`) or "projection" (the seed's series; the
            default when ``basis`` or ``n_modes`` is given, which only it uses).
        contact: "full" (q may come out negative: flag ``contact_lost``), "unilateral"
            (q >= 0 with an unknown contact set, :func:`core.contact.solve_unilateral`) or
            "auto" (full contact first, unilateral only when it is lost).
        time_breaks: times where a given load history jumps or kinks; the default engine's
            time steps land on them (a step across a jump loses the order and fools the
            step-doubling estimate).

    Returns a :class:`ContactSolution` (or, when the unilateral model answered, a
    :class:`core.contact.unilateral.UnilateralSolution` with the same attributes); ``contact_set``
    and ``info["contact"]`` say which contact model answered. Raises ``ValueError``
    naming the argument on bad input, and naming ``force`` or ``moment`` with ``contact``
    ``"auto"`` or ``"unilateral"`` when the loads leave no contact (P < 0, P = 0
    throughout, |M/P| >= 1: :func:`core.contact.refuse_loads_without_contact`).
    ``contact="full"`` asks for the full-contact model itself, a linear equation that
    holds for any loads (a bonded punch, the model problem of the seed): it answers them
    with the ``contact_lost`` flag where q < 0, as it answers a given settlement that
    lifts the punch.
    """
    from core.contact import (
        check_contact_model,
        refuse_loads_without_contact,
        solve_unilateral,
        with_contact_model,
    )
    from core.problem import UnresolvedOperator

    contact = check_contact_model(contact)
    if contact != "full":
        refuse_loads_without_contact(times, kernel, force, moment)
    method_defaulted = method is None
    if method is None:
        method = "projection" if (n_modes is not None or basis != "graded") else "nystrom"
    if method not in ("nystrom", "projection"):
        raise ValueError(f"method: must be 'nystrom' or 'projection', got {method!r}")
    if method == "nystrom":
        from core.engines.nystrom import solve_with_prepared

        unilateral_args = dict(lam=lam, m=m, g=g, times=times, c=c, kernel=kernel,
                               settlement=settlement, tilt=tilt, force=force, moment=moment,
                               breakpoints=breakpoints, tol=tol)
        if contact == "unilateral":
            return solve_unilateral(**unilateral_args)
        # On an elastic base with a constant modulus the full-contact answer costs what the
        # check would (one combination of the prepared unit responses): no check first.
        if contact == "auto" and (kernel is not None or callable(c)):
            from core.contact import predicted_unilateral

            predicted = predicted_unilateral(unilateral_args)
            if predicted is not None:
                return predicted
        try:
            full = solve_with_prepared(lam, m, g, times, c=c, kernel=kernel,
                                       settlement=settlement, tilt=tilt, force=force,
                                       moment=moment, breakpoints=breakpoints, tol=tol,
                                       time_breaks=time_breaks)
        except UnresolvedOperator as exc:
            if not method_defaulted:
                raise
            # the symmetric Galerkin projection steps such a scene (positive definite by
            # construction); say which engine answered and why
            full = solve_dimensionless(lam, m, g, times, c=c, kernel=kernel,
                                       settlement=settlement, tilt=tilt, force=force,
                                       moment=moment, breakpoints=breakpoints, tol=tol,
                                       method="projection", contact="full",
                                       time_breaks=time_breaks)
            full.info["method"] = "projection"
            full.info["fallback"] = f"default engine declined ({exc}); projection answered"
            return with_contact_model(full, contact, unilateral_args)
        return with_contact_model(full, contact, unilateral_args)
    inp = validate_inputs(lam, m, g, times, c, kernel,
                          {"settlement": settlement, "tilt": tilt, "force": force,
                           "moment": moment}, breakpoints, tol)
    unilateral_args = dict(lam=lam, m=m, g=g, times=times, c=c, kernel=kernel,
                           settlement=settlement, tilt=tilt, force=force, moment=moment,
                           breakpoints=breakpoints, tol=tol)
    if contact == "unilateral":
        return solve_unilateral(**unilateral_args)
    full = solve_projection(inp, basis, n_modes)
    return with_contact_model(full, contact, unilateral_args)
