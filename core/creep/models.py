"""Creep models of the aging base layer and the Volterra kernel they produce.

A model gives the instantaneous modulus ``E(age)`` [Pa] and the creep function
``C(t, tau)`` [1/Pa], where ``t`` and ``tau`` are *ages* in days (time since the base was
made). With the creep law

    eps(t) = sigma(t)/E(t) - int_{tau0}^t sigma(tau) d/dtau [1/E(tau) + C(t, tau)] dtau

and the dimensionless stress ``s = sigma / E`` this is ``eps = (I - V) s`` with

    V s(t) = int_{tau0}^t K(t, tau) s(tau) dtau,
    K(t, tau) = E(tau) d/dtau [1/E(tau) + C(t, tau)]
              = -E'(tau)/E(tau) + E(tau) dC/dtau (t, tau)            [1/day],

zero for ``t < tau`` and ``K <= 0`` for a material that creeps.

Every shipped model is a special case of the aging Prony series

    E(tau)    = E_inf (1 - beta exp(-alpha tau)),
    C(t, tau) = sum_r (C_r + A_r / tau) (1 - exp(-gamma_r (t - tau))),

(``beta = alpha = 0`` for a constant modulus). Differentiating by hand, with
``e_r = exp(-gamma_r (t - tau))`` and ``d e_r / dtau = gamma_r e_r``,

    dC/dtau = sum_r [ -A_r/tau^2 (1 - e_r) - gamma_r (C_r + A_r/tau) e_r ],
    -E'/E   = -alpha beta exp(-alpha tau) / (1 - beta exp(-alpha tau)),

so the kernel is degenerate, ``K(t, tau) = b(tau) + sum_r a_r(tau) e_r`` with

    b(tau)   = -alpha beta exp(-alpha tau) / (1 - beta exp(-alpha tau))
               - E(tau) sum_r A_r / tau^2,
    a_r(tau) = E(tau) (A_r / tau^2 - gamma_r (C_r + A_r / tau)).

In the solver's time ``t* = age / tau0`` (``tau0`` the age at loading)
``K*(t*, tau*) = tau0 K(tau0 t*, tau0 tau*)``: ``b* (tau*) = tau0 b(tau0 tau*)``,
``a*_r(tau*) = tau0 a_r(tau0 tau*)`` and the rates become ``gamma_r tau0``. The relative
modulus is ``c(t*) = E(tau0 t*) / E(tau0)``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.creep.design_codes import SPEC_FIELDS as _CODE_SPEC_FIELDS
from core.creep.design_codes import CodeCreep
from core.creep.inputs import (
    Terms,
    _age_at_loading,
    _check_arutyunyan,
    _check_exponential,
    _check_terms,
    _positive,
)
from core.creep.kernels import CausalKernel, DegenerateKernel, RelativeModulus, _set
from core.validation import show_python

ArrayLike = Any


# ----------------------------------------------------------------------------- the models


class _AgingSeries:
    """What the models that are aging Prony series share (see the module docstring).

    A subclass provides ``_series() -> (E_inf [Pa], beta [-], alpha [1/day], terms)``.
    """

    def _series(self) -> tuple[float, float, float, Terms]:
        raise NotImplementedError

    def modulus(self, age: ArrayLike) -> np.ndarray:
        """Instantaneous modulus ``E(age)`` [Pa] at ages [day]."""
        e_inf, beta, alpha, _ = self._series()
        return e_inf * (1.0 - beta * np.exp(-alpha * np.asarray(age, dtype=float)))

    def compliance(self, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
        """Creep function ``C(t, tau)`` [1/Pa] at ages ``t, tau > 0`` [day]; 0 where ``t < tau``."""
        t, tau = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(tau, dtype=float))
        lag = np.maximum(t - tau, 0.0)
        total = np.zeros(t.shape)
        for c, a, g in self._series()[3]:
            # expm1 keeps the relative accuracy for lags much shorter than 1/gamma
            total = total - (c + a / tau) * np.expm1(-g * lag)
        return total

    def kernel(self, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
        """``K(t, tau) = E(tau) d/dtau [1/E(tau) + C(t, tau)]`` [1/day] at ages [day].

        The derivative is exact (taken by hand, see the module docstring); 0 where
        ``t < tau``. Ages must be > 0.
        """
        return self._degenerate(1.0)(t, tau)

    def relative_modulus(self, age_at_loading: float, *,
                         field: str = "age_at_loading") -> float | RelativeModulus:
        """``c(t*) = E(tau0 t*) / E(tau0)`` [-]; the float 1.0 when the modulus does not age.

        ``age_at_loading`` is ``tau0`` [day], ``t* = age / tau0``.
        """
        tau0 = _age_at_loading(age_at_loading, field)
        _, beta, alpha, _ = self._series()
        if beta == 0.0 or alpha == 0.0:
            return 1.0
        return RelativeModulus(tau0, beta, alpha)

    def dimensionless_kernel(self, age_at_loading: float, *,
                             field: str = "age_at_loading",
                             tol: float | None = None) -> DegenerateKernel:
        """``K*(t*, tau*) = tau0 K(tau0 t*, tau0 tau*)`` [-] in degenerate (exponential) form.

        ``age_at_loading`` is ``tau0`` [day], ``t* = age / tau0``; ``tol`` (the solver's)
        is not needed: the form is exact.
        """
        return self._degenerate(_age_at_loading(age_at_loading, field))

    def _degenerate(self, tau0: float) -> DegenerateKernel:
        e_inf, beta, alpha, terms = self._series()
        return DegenerateKernel(tau0, e_inf, beta, alpha, terms)


class _ConstantModulus:
    """What the models with a modulus that does not age share (``instantaneous_modulus``)."""

    instantaneous_modulus: float

    def modulus(self, age: ArrayLike) -> np.ndarray:
        """Instantaneous modulus ``E(age)`` [Pa] at ages [day] (constant)."""
        return np.full(np.shape(age), self.instantaneous_modulus)

    def relative_modulus(self, age_at_loading: float, *,
                         field: str = "age_at_loading") -> float:
        """``c(t*) = 1.0``: the modulus does not age. ``age_at_loading`` in days."""
        _age_at_loading(age_at_loading, field)
        return 1.0


@dataclass(frozen=True, init=False)
class Elastic(_ConstantModulus):
    """No creep: constant ``modulus`` [Pa], ``C = 0``, ``K = 0``."""

    instantaneous_modulus: float

    def __init__(self, modulus: float) -> None:
        _set(self, instantaneous_modulus=_positive(modulus, "Elastic.modulus"))

    def compliance(self, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
        """Creep function ``C(t, tau) = 0`` [1/Pa] at ages [day]."""
        return np.zeros(np.broadcast_shapes(np.shape(t), np.shape(tau)))

    def kernel(self, t: ArrayLike, tau: ArrayLike) -> np.ndarray:
        """Creep kernel ``K(t, tau) = 0`` [1/day] at ages [day]."""
        return np.zeros(np.broadcast_shapes(np.shape(t), np.shape(tau)))

    def dimensionless_kernel(self, age_at_loading: float, *,
                             field: str = "age_at_loading",
                             tol: float | None = None) -> None:
        """``None``: there is no creep operator. ``age_at_loading`` in days (``tol``
        unused)."""
        _age_at_loading(age_at_loading, field)
        return None

    @property
    def spec(self) -> dict:
        """JSON-able description, inverse of :func:`creep_model_from_spec` (SI, days)."""
        return {"model": "elastic", "modulus": self.instantaneous_modulus}


@dataclass(frozen=True, init=False)
class ExponentialCreep(_AgingSeries):
    """Non-aging creep: ``E = modulus`` [Pa], ``C(t, tau) = compliance (1 - exp(-rate (t - tau)))``.

    ``compliance`` is the final creep compliance ``C_inf`` [1/Pa] (stored as
    ``compliance_final``), ``rate`` is ``gamma`` [1/day].
    """

    instantaneous_modulus: float
    compliance_final: float
    rate: float

    def __init__(self, modulus: float, compliance: float, rate: float) -> None:
        v = _check_exponential({"modulus": modulus, "compliance": compliance, "rate": rate},
                               "ExponentialCreep")
        _set(self, instantaneous_modulus=v["modulus"], compliance_final=v["compliance"],
             rate=v["rate"])

    def _series(self) -> tuple[float, float, float, Terms]:
        return self.instantaneous_modulus, 0.0, 0.0, ((self.compliance_final, 0.0, self.rate),)

    @property
    def spec(self) -> dict:
        """JSON-able description, inverse of :func:`creep_model_from_spec` (SI, days)."""
        return {"model": "exponential", "modulus": self.instantaneous_modulus,
                "compliance": self.compliance_final, "rate": self.rate}


@dataclass(frozen=True)
class Arutyunyan(_AgingSeries):
    """Arutyunyan's aging creep of concrete.

    ``E(age) = modulus_final (1 - beta exp(-alpha age))`` [Pa] and
    ``C(t, tau) = (compliance_final + aging / tau)(1 - exp(-rate (t - tau)))`` [1/Pa];
    ``alpha`` and ``rate`` in 1/day, ``compliance_final`` in 1/Pa, ``aging`` in day/Pa.
    """

    modulus_final: float
    beta: float
    alpha: float
    compliance_final: float
    aging: float
    rate: float

    def __post_init__(self) -> None:
        _set(self, **_check_arutyunyan(self.__dict__, "Arutyunyan"))

    def _series(self) -> tuple[float, float, float, Terms]:
        return (self.modulus_final, self.beta, self.alpha,
                ((self.compliance_final, self.aging, self.rate),))

    @property
    def spec(self) -> dict:
        """JSON-able description, inverse of :func:`creep_model_from_spec` (SI, days)."""
        return {"model": "arutyunyan", "modulus_final": self.modulus_final,
                "beta": self.beta, "alpha": self.alpha,
                "compliance_final": self.compliance_final, "aging": self.aging,
                "rate": self.rate}


@dataclass(frozen=True, init=False)
class PronySeries(_AgingSeries):
    """Constant modulus and an aging Prony series of creep terms.

    ``E = modulus`` [Pa], ``C(t, tau) = sum_r (C_r + A_r/tau)(1 - exp(-gamma_r (t - tau)))``
    with ``terms = ((C_r [1/Pa], A_r [day/Pa], gamma_r [1/day]), ...)``, 1 to 12 terms.
    """

    instantaneous_modulus: float
    terms: Terms

    def __init__(self, modulus: float, terms: Any) -> None:
        _set(self, instantaneous_modulus=_positive(modulus, "PronySeries.modulus"),
             terms=_check_terms(terms, "PronySeries.terms"))

    def _series(self) -> tuple[float, float, float, Terms]:
        return self.instantaneous_modulus, 0.0, 0.0, self.terms

    @property
    def spec(self) -> dict:
        """JSON-able description, inverse of :func:`creep_model_from_spec` (SI, days)."""
        return {"model": "prony", "modulus": self.instantaneous_modulus,
                "terms": [{"compliance": c, "aging": a, "rate": g} for c, a, g in self.terms]}


@dataclass(frozen=True, init=False, eq=False)
class UserKernel(_ConstantModulus):
    """Constant ``modulus`` [Pa] and the creep kernel given directly (Python API).

    ``kernel`` is a vectorized callable ``K(t, tau)`` [1/day] of ages ``t >= tau`` [day];
    it is stored made causal (a :class:`CausalKernel`), so ``model.kernel(t, tau)`` is 0
    where ``t < tau``. ``expr`` is the formula text when the kernel came from a spec; a
    kernel given only as a Python callable has no spec. There is no creep function.
    """

    instantaneous_modulus: float
    kernel: CausalKernel
    expr: str | None

    def __init__(self, modulus: float, kernel: Callable[[np.ndarray, np.ndarray], Any],
                 expr: str | None = None) -> None:
        if not callable(kernel):
            raise ValueError(f"UserKernel.kernel: must be callable, got {show_python(kernel)}")
        if expr is not None and not isinstance(expr, str):
            raise ValueError(f"UserKernel.expr: must be a string, got {show_python(expr)}")
        if not isinstance(kernel, CausalKernel):
            kernel = CausalKernel(kernel)
        _set(self, instantaneous_modulus=_positive(modulus, "UserKernel.modulus"),
             kernel=kernel, expr=expr)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, UserKernel) or \
                other.instantaneous_modulus != self.instantaneous_modulus:
            return False
        if self.expr is not None or other.expr is not None:
            return self.expr == other.expr
        return self.kernel == other.kernel

    def __hash__(self) -> int:
        return hash((self.instantaneous_modulus,
                     self.expr if self.expr is not None else self.kernel))

    def dimensionless_kernel(self, age_at_loading: float, *,
                             field: str = "age_at_loading",
                             tol: float | None = None) -> CausalKernel:
        """``K*(t*, tau*) = tau0 K(tau0 t*, tau0 tau*)`` [-] as a general (causal) callable.

        ``age_at_loading`` is ``tau0`` [day], ``t* = age / tau0``; ``tol`` unused (the
        time stepping fits the callable itself, within its own budget).
        """
        tau0 = _age_at_loading(age_at_loading, field)
        return CausalKernel(self.kernel.function, tau0)

    @property
    def spec(self) -> dict:
        """JSON-able description, inverse of :func:`creep_model_from_spec` (SI, days).

        Raises ValueError for a kernel given as a Python callable: it has no JSON form.
        """
        if self.expr is None:
            raise ValueError(
                "UserKernel.spec: a kernel given as a Python callable has no JSON form; "
                "give it as {'model': 'kernel', 'modulus': ..., 'expr': ...} instead")
        return {"model": "kernel", "modulus": self.instantaneous_modulus, "expr": self.expr}


CreepModel = Elastic | ExponentialCreep | Arutyunyan | PronySeries | UserKernel | CodeCreep

#: Spec fields of each model: (required, optional) (the JSON Schema of scene files is
#: made from this table too, :mod:`core.scene.json_schema`).
SPEC_FIELDS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "arutyunyan": (("modulus_final", "beta", "alpha", "compliance_final", "aging", "rate"),
                   ()),
    "elastic": (("modulus",), ()),
    "exponential": (("modulus", "compliance", "rate"), ()),
    "kernel": (("modulus", "expr"), ()),
    "prony": (("modulus", "terms"), ()),
    **_CODE_SPEC_FIELDS,
}
KNOWN_MODELS: tuple[str, ...] = tuple(sorted(SPEC_FIELDS))
#: Fields of a Prony term: (required, optional).
TERM_FIELDS = (("compliance", "rate"), ("aging",))


def _check_keys(spec: Mapping[str, Any], fields: tuple[tuple[str, ...], tuple[str, ...]],
                field: str, what: str, ignore: tuple[str, ...] = ()) -> None:
    """Refuse unknown and missing keys of a spec object."""
    required, optional = fields
    allowed = set(required) | set(optional)
    for key in spec:
        if key in ignore:
            continue
        if key not in allowed:
            raise ValueError(f"{field}.{key}: unknown field for {what}; allowed: "
                             + ", ".join(sorted(allowed)))
    for key in required:
        if key not in spec:
            raise ValueError(f"{field}.{key}: missing (required for {what})")


def creep_model_from_spec(spec: dict, *, field: str = "base.creep") -> CreepModel:
    """Build a creep model from its JSON-able spec (SI units, ages in days).

    Forms: ``{"model": "elastic", "modulus"}``, ``{"model": "exponential", "modulus",
    "compliance", "rate"}``, ``{"model": "arutyunyan", "modulus_final", "beta", "alpha",
    "compliance_final", "aging", "rate"}``, ``{"model": "prony", "modulus", "terms":
    [{"compliance", "aging" (default 0), "rate"}, ...]}``, ``{"model": "kernel",
    "modulus", "expr"}`` (``expr`` a formula in ``t`` and ``tau`` giving ``K`` in 1/day),
    and the design-code models ``{"model": "fib_mc2010" | "eurocode2", "fcm" [MPa] or
    "strength_class" ("C30/37"), "cement" ("S", "N", "R"; default "N"),
    "relative_humidity" [%], "notional_size" [mm], "temperature" [deg C, default 20]}``
    (code units, see :mod:`core.creep.design_codes`).
    Errors are ValueErrors whose message starts with the offending field under ``field``.
    """
    if not isinstance(spec, Mapping):
        raise ValueError(f"{field}: must be an object with a 'model' field, "
                         f"got {show_python(spec)}")
    known = ", ".join(KNOWN_MODELS)
    if "model" not in spec:
        raise ValueError(f"{field}.model: missing; known models: {known}")
    name = spec["model"]
    if not isinstance(name, str) or name not in SPEC_FIELDS:
        raise ValueError(f"{field}.model: unknown model {name!r}; known models: {known}")
    _check_keys(spec, SPEC_FIELDS[name], field, f"model {name!r}", ignore=("model",))

    if name in _CODE_SPEC_FIELDS:
        return CodeCreep(name, dict(spec), field)
    if name == "elastic":
        return Elastic(_positive(spec["modulus"], f"{field}.modulus"))
    if name == "exponential":
        return ExponentialCreep(**_check_exponential(spec, field))
    if name == "arutyunyan":
        return Arutyunyan(**_check_arutyunyan(spec, field))
    if name == "prony":
        modulus = _positive(spec["modulus"], f"{field}.modulus")
        terms = spec["terms"]
        if isinstance(terms, (str, bytes)) or not isinstance(terms, (list, tuple)):
            raise ValueError(f"{field}.terms: must be a list of terms, got {show_python(terms)}")
        triples = []
        for r, term in enumerate(terms):
            where = f"{field}.terms[{r}]"
            if not isinstance(term, Mapping):
                raise ValueError(f"{where}: must be an object with compliance, aging, rate; "
                                 f"got {show_python(term)}")
            _check_keys(term, TERM_FIELDS, where, "a Prony term")
            triples.append((term["compliance"], term.get("aging", 0.0), term["rate"]))
        return PronySeries(modulus, _check_terms(triples, f"{field}.terms"))
    # name == "kernel"
    modulus = _positive(spec["modulus"], f"{field}.modulus")
    text = spec["expr"]
    if not isinstance(text, str) or not text.strip():
        raise ValueError(f"{field}.expr: must be a formula in t and tau, got {show_python(text)}")
    # imported here so that the rest of the module does not depend on the parser
    from core.profiles import parse_expression

    expression = parse_expression(text, variables=("t", "tau"), field=f"{field}.expr")
    return UserKernel(modulus, expression, expr=text)
