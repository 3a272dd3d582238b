"""The engines behind ``solve_dimensionless(..., method=...)``: one protocol, one registry.

An engine answers the full-contact dimensionless problem in two steps, as
:func:`core.prepare` does for the default one: ``prepare`` takes the validated geometry
(:class:`core.problem.Geometry`: ``lam``, ``m(x)``, ``g(x)``, breakpoints, ``tol``) and
``solve`` the validated time side (:class:`core.problem.TimeInputs`: times, ``c(t)``, the
creep kernel, the two given loads), returning a :class:`core.problem.ContactSolution`
whose ``info`` carries :data:`core.problem.INFO_KEYS`. ``success`` follows
:func:`core.problem.accepts` with the engine's ``success_margin``. Options of one engine
only (the projection's ``basis``, the collocation's ``panels_per_unit``, ...) are keywords
of its ``prepare`` or ``solve``, named in ``prepare_options`` and ``solve_options``.

An engine declines a problem it cannot discretize by raising
:class:`core.problem.UnresolvedOperator`; with the method defaulted,
:func:`core.solver.solve_dimensionless` then asks the next engine of
:data:`DEFAULT_ORDER`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol

from core.engines.collocation import COLLOCATION
from core.engines.nystrom import NYSTROM
from core.engines.projection import PROJECTION
from core.problem import ContactSolution, Geometry, TimeInputs


class Engine(Protocol):
    """What :func:`core.solver.solve_dimensionless` asks of an engine (all dimensionless).

    Attributes
    ----------
    name : str
        The ``method`` that selects it.
    prepare_options, solve_options : tuple of str
        Keywords of :meth:`prepare` and :meth:`solve` beyond the common inputs: the
        engine's own options, each with a default.
    success_margin : float
        ``margin`` of :func:`core.problem.accepts` (>= 1): how far the engine's error
        estimate may read low.
    """

    name: str
    prepare_options: tuple[str, ...]
    solve_options: tuple[str, ...]
    success_margin: float

    def prepare(self, geometry: Geometry, **options: Any) -> Any:
        """The engine's prepared form of a validated geometry (whatever its ``solve``
        takes; may be cached and shared between calls). Raises ``ValueError`` naming a
        bad option, :class:`core.problem.UnresolvedOperator` to decline."""
        ...

    def solve(self, prepared: Any, inputs: TimeInputs, **options: Any) -> ContactSolution:
        """The full-contact answer for a validated time side on ``prepared``."""
        ...


#: The registered engines by name (the ``method`` of ``solve_dimensionless``).
ENGINES: dict[str, Engine] = {}
#: The engine of a defaulted ``method``.
DEFAULT_METHOD = "nystrom"
#: The engines a defaulted ``method`` tries in turn, each when the one before declined.
#: The projection's Galerkin matrix is symmetric positive definite by construction, so it
#: steps what the Nystrom matrix (not symmetric) may not; the collocation, a cross-check
#: of O(N steps^2), is never tried unasked.
DEFAULT_ORDER = ("nystrom", "projection")


def register_engine(engine: Engine, *, replace: bool = False) -> Engine:
    """Add ``engine`` to :data:`ENGINES` under ``engine.name`` and return it.

    Raises ``ValueError`` when the name is taken (unless ``replace``) or the object lacks
    a part of :class:`Engine`.
    """
    name = getattr(engine, "name", None)
    if not isinstance(name, str) or not name:
        raise ValueError(f"engine: needs a name (a non-empty string), got {name!r}")
    for part in ("prepare", "solve"):
        if not callable(getattr(engine, part, None)):
            raise ValueError(f"engine: {name!r} has no {part}() method")
    for part in ("prepare_options", "solve_options"):
        options = getattr(engine, part, None)
        if not isinstance(options, tuple) or not all(isinstance(o, str) for o in options):
            raise ValueError(f"engine: {name!r} needs {part} as a tuple of names")
    margin = getattr(engine, "success_margin", None)
    if isinstance(margin, bool) or not isinstance(margin, (int, float)) or not margin >= 1.0:
        raise ValueError(f"engine: {name!r} needs a success_margin >= 1, got {margin!r}")
    if name in ENGINES and not replace:
        raise ValueError(f"engine: {name!r} is registered already")
    ENGINES[name] = engine
    return engine


def get_engine(method: object) -> Engine:
    """The engine registered as ``method``; ``ValueError`` naming ``method`` and the
    registered ones otherwise."""
    if not isinstance(method, str) or method not in ENGINES:
        names = ", ".join(repr(name) for name in ENGINES)
        raise ValueError(f"method: must be one of {names}, got {method!r}")
    return ENGINES[method]


def engine_options(engine: Engine, options: Mapping[str, Any]
                   ) -> tuple[dict[str, Any], dict[str, Any]]:
    """``options`` split into the keywords of ``engine.prepare`` and ``engine.solve``;
    ``ValueError`` naming an option the engine does not take."""
    prepare, solve = {}, {}
    for name, value in options.items():
        if name in engine.prepare_options:
            prepare[name] = value
        elif name in engine.solve_options:
            solve[name] = value
        else:
            taken = ", ".join(engine.prepare_options + engine.solve_options) or "none"
            raise ValueError(f"{name}: not an option of the {engine.name!r} engine "
                             f"(its options: {taken})")
    return prepare, solve


for _engine in (NYSTROM, PROJECTION, COLLOCATION):
    register_engine(_engine)
