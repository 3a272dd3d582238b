"""``solve_dimensionless``: the dimensionless problem, answered by one of the engines.

The dimensionless problem (model notes; the seed's (9)-(12)):

    c(t) m(x) q(x,t) + (I - V) F q = delta(t) + alpha(t) x - g(x),   -1 <= x <= 1,  t >= 1,
    int q dx = P(t),   int x q dx = M(t).

:func:`solve_dimensionless` checks the common arguments, picks the engine(s) of
:data:`core.engines.ENGINES` (the default :mod:`core.engines.nystrom`, the seed's
:mod:`core.engines.projection`, the cross-check :mod:`core.engines.collocation`), asks them
in turn until one answers, and applies the contact model (:mod:`core.contact`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from core.contact import (
    check_contact_model,
    predicted_unilateral,
    refuse_loads_without_contact,
    solve_unilateral,
    with_contact_model,
)
from core.engines import DEFAULT_METHOD, DEFAULT_ORDER, Engine, engine_options, get_engine
from core.problem import (
    ContactSolution,
    Geometry,
    TimeInputs,
    UnresolvedOperator,
    validate_geometry,
    validate_time_inputs,
)
from core.time import undeclared_jumps
from core.work import one_blas_thread

Scalar = float | Callable[[np.ndarray], np.ndarray]

#: Engine options that stay keywords of the common signature, so calls written before the
#: registry keep working, with the value of each that asks nothing of an engine: an engine
#: that does not take one accepts that value (it is what its own answer assumes) and
#: refuses any other.
SIGNATURE_OPTIONS: dict[str, Any] = {"basis": "graded", "n_modes": None, "time_breaks": ()}


@one_blas_thread()
def solve_dimensionless(lam: float, m: Scalar, g: Scalar, times: Sequence[float] | np.ndarray,
                        *, c: Scalar = 1.0, kernel: Callable | None = None,
                        settlement: Scalar | None = None, tilt: Scalar | None = None,
                        force: Scalar | None = None, moment: Scalar | None = None,
                        breakpoints: Sequence[float] = (), tol: float = 1e-8,
                        basis: str = "graded", n_modes: int | None = None,
                        method: str | None = None, contact: str = "auto",
                        time_breaks: Sequence[float] = (), find_jumps: bool = True,
                        **options: Any) -> ContactSolution:
    """Solve the dimensionless contact problem of a rigid punch on the coated base.

    Parameters
    ----------
    lam : float
        ``a/H``, the punch's half-width over the base's thickness (> 0).
    m : float or callable
        Coating compliance ``m(x) > 0`` on [-1, 1] (vectorized callable of ``x = X/a``).
    g : float or callable
        Gap ``g(x)`` between punch and coating; may jump at ``breakpoints``.
    times : array_like
        Output times ``t = (age - tau0) / tau0 + 1``, increasing, the first >= 1
        (``t = 1`` is the moment of loading).
    c : float or callable, optional
        Relative base modulus ``c(t) = E(t)/E0 > 0``.
    kernel : callable or None, optional
        None (elastic base) or the creep kernel ``K(t, tau)`` of the Volterra operator
        ``V`` (vectorized); a :class:`core.creep.models.DegenerateKernel` is stepped in
        O(1) per mode and step. The compliance of a stress held since loading relative
        to the elastic one, ``1 - int_1^t K(t, u) du``, must stay > 0
        (:func:`core.problem.check_held_compliance`: a plain callable's at
        ``core.problem.inputs.HELD_CHECKS`` of the output times, and every output time
        by the default engine).
    settlement, tilt, force, moment : float or callable, optional
        Exactly two of ``delta``, ``alpha``, ``P``, ``M`` (numbers or callables of t):
        one of the four statements; the other two are solved for.
    breakpoints : sequence of float, optional
        Points of (-1, 1) where ``m`` or ``g`` may jump.
    tol : float, optional
        Relative accuracy target of delta, alpha (relative to ``max(|delta|, |alpha|)``),
        P, M (relative to ``max(|P|, |M|)``) and q (relative to ``max|q|``).
    method : str or None, optional
        The engine, a name of :data:`core.engines.ENGINES`: ``"nystrom"`` (the default:
        direct solve on graded panels, adaptively refined), ``"projection"`` (the seed's
        series; the default when ``n_modes`` is given or ``basis`` is not ``"graded"``)
        or ``"collocation"`` (a cross-check on fixed panels). With ``method`` defaulted,
        an engine that declines the problem (:class:`core.problem.UnresolvedOperator`)
        hands it to the next of :data:`core.engines.DEFAULT_ORDER`, and
        ``info["fallback"]`` says so.
    contact : {"auto", "full", "unilateral"}, optional
        ``"full"``: the full-contact model, a linear equation that holds for any loads
        (a bonded punch; q may come out negative: flag ``contact_lost``);
        ``"unilateral"``: q >= 0 with an unknown contact set
        (:func:`core.contact.solve_unilateral`, which answers whatever the engine);
        ``"auto"``: full contact first, unilateral only when it is lost.
    basis, n_modes, time_breaks : optional
        Engine options kept as keywords (see ``**options``): the projection's basis
        (``"graded"``, ``"piecewise"``, ``"global"``) and fixed mode count, and the times
        where a given load history jumps or kinks (every engine's time grids land on
        them; give a narrow pulse's times too, which the steps could pass over). Under
        creep, a jump of a history given as a callable (a load, ``c``) that is not
        among them is found by sampling and bisection and added
        (``info["time_breaks_found"]``; ``find_jumps``); a pulse narrower than ~1/2000
        of the span can hide between the samples. An engine that does not take one
        accepts its default value only. A cached creep
        response to a load is found again by the load's values at the output times and
        at :func:`core.time.history_key_times` (the march's span and both sides of each
        of ``time_breaks``): two callables that agree at all of them share it.
    find_jumps : bool, optional
        Whether jumps of the histories given as callables that ``time_breaks`` lacks are
        looked for under creep (0.6-0.7 ms of a load change on the aging presets); False
        where the caller declares every one, as a scene does from its load profiles.
    **options
        Options of the chosen engine only (its ``prepare_options`` and
        ``solve_options``, documented with its ``prepare`` and ``solve``), e.g. the
        collocation's ``panels_per_unit``, ``edge_width``, ``time_points``.

    Returns
    -------
    ContactSolution
        With ``info`` as documented in :mod:`core.problem.result` (``method``,
        ``success``, ``error_estimate``, ...) and ``info["contact"]``; when the unilateral
        model answered, a :class:`core.contact.result.UnilateralSolution` with the same
        attributes, its ``contact_set`` the contact zones per time.

    Raises
    ------
    ValueError
        Naming the argument on bad input: ``method`` for an unknown engine, an option the
        chosen engine does not take, and ``force`` or ``moment`` with ``contact``
        ``"auto"`` or ``"unilateral"`` when the loads leave no contact (P < 0, P = 0
        throughout, ``|M/P| >= 1``: :func:`core.contact.refuse_loads_without_contact`).
    """
    contact = check_contact_model(contact)
    if contact != "full":
        refuse_loads_without_contact(times, kernel, force, moment)
    engines = _engines(method, basis, n_modes)
    asked = _asked_options(engines[0], {"basis": basis, "n_modes": n_modes,
                                        "time_breaks": time_breaks}, options)
    loads = {"settlement": settlement, "tilt": tilt, "force": force, "moment": moment}
    unilateral_args = dict(lam=lam, m=m, g=g, times=times, c=c, kernel=kernel,
                           breakpoints=breakpoints, tol=tol, time_breaks=time_breaks,
                           **loads)
    geometry = validate_geometry(lam, m, g, breakpoints, tol)
    inputs = validate_time_inputs(times, c, kernel, loads)
    found = (_undeclared_jumps(inputs, {"c": c, **loads}, geometry.tol, time_breaks)
             if find_jumps else ())
    if found:
        # the march lands on them as on declared ones (an engine without time breaks
        # steps adaptively, or on its own grid)
        time_breaks = tuple(sorted({*(float(b) for b in time_breaks), *found}))
        unilateral_args["time_breaks"] = time_breaks
        if "time_breaks" in asked:
            asked["time_breaks"] = time_breaks
    result = _answer(contact, engines, geometry, inputs, asked, unilateral_args, c)
    if found:
        result.info["time_breaks_found"] = list(found)
    return result


def _answer(contact: str, engines: list[Engine], geometry: Geometry, inputs: TimeInputs,
            asked: dict[str, Any], unilateral_args: dict[str, Any], c: Scalar
            ) -> ContactSolution:
    """The answer of the contact model ``contact`` (see :func:`solve_dimensionless`)."""
    if contact == "unilateral":
        return solve_unilateral(**unilateral_args)
    # The check runs on the Nystrom engine's prepared geometry, which its full answer then
    # reuses. On an elastic base with a constant modulus that answer costs what the check
    # would (one combination of the prepared unit responses): no check first.
    if (contact == "auto" and engines[0].name == "nystrom"
            and (inputs.kernel is not None or callable(c))):
        predicted = predicted_unilateral(unilateral_args, geometry, inputs)
        if predicted is not None:
            return predicted
    full = _first_answer(engines, geometry, inputs, asked)
    return with_contact_model(full, contact, unilateral_args)


def _undeclared_jumps(inputs: TimeInputs, given: dict[str, Any], tol: float,
                      declared: Sequence[float]) -> tuple[float, ...]:
    """The jumps of the histories given as callables (``c`` and the loads of ``given``,
    as the caller passed them) that ``declared`` does not hold
    (:func:`core.time.undeclared_jumps`); none without creep, where each output time's
    answer depends on the histories at that time alone."""
    if inputs.kernel is None:
        return ()
    histories = [inputs.c if name == "c" else inputs.loads[name]
                 for name, value in given.items()
                 if callable(value) and (name == "c" or name in inputs.loads)]
    end = float(inputs.times[-1])
    found: set[float] = set()
    for history in histories:
        found.update(undeclared_jumps(history, 1.0, end, tol, declared))
    return tuple(sorted(found))


def _engines(method: object, basis: object, n_modes: object) -> list[Engine]:
    """The engine asked for, or with ``method`` defaulted those of ``DEFAULT_ORDER`` from
    the default one on (the projection when ``n_modes`` or a basis other than the
    graded one asks for it: the other engines have neither)."""
    if method is not None:
        return [get_engine(method)]
    first = "projection" if (n_modes is not None or basis != "graded") else DEFAULT_METHOD
    return [get_engine(name) for name in DEFAULT_ORDER[DEFAULT_ORDER.index(first):]]


def _asks_nothing(value: Any, default: Any) -> bool:
    if default is None:
        return value is None
    if isinstance(default, str):
        return isinstance(value, str) and value == default
    return np.size(value) == 0  # an empty sequence of times


def _asked_options(engine: Engine, signature: dict[str, Any], options: dict[str, Any]
                   ) -> dict[str, Any]:
    """The options for ``engine``: every one it takes, and no other unless it is a keyword
    of the common signature at the value that asks nothing (ValueError names it)."""
    taken = engine.prepare_options + engine.solve_options
    asked = {name: value for name, value in signature.items()
             if name in taken or not _asks_nothing(value, SIGNATURE_OPTIONS[name])}
    asked.update(options)
    engine_options(engine, asked)  # refuses what the engine does not take
    return asked


def _first_answer(engines: list[Engine], geometry: Geometry, inputs: TimeInputs,
                  asked: dict[str, Any]) -> ContactSolution:
    """The full-contact answer of the first engine that does not decline.

    The options were asked of the first engine; a later one gets those it takes (the
    projection takes the default engine's ``time_breaks``, not its other options).
    """
    declined: UnresolvedOperator | None = None
    for engine in engines:
        taken = engine.prepare_options + engine.solve_options
        prepare_options, solve_options = engine_options(
            engine, {k: v for k, v in asked.items() if k in taken})
        try:
            full = engine.solve(engine.prepare(geometry, **prepare_options), inputs,
                                **solve_options)
        except UnresolvedOperator as exc:
            if engine is engines[-1]:
                raise
            declined = declined or exc
            continue
        if declined is not None:
            # say which engine answered and why
            full.info["method"] = engine.name
            full.info["fallback"] = (f"default engine declined ({declined}); "
                                     f"{engine.name} answered")
        return full
    raise AssertionError("unreachable: the last engine answers or raises")
