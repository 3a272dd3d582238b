"""A whitelisting parser for user formulas (never ``eval``).

Scene files and the browser explorer let users type formulas such as
``0.002 + 0.001 * sin(2 * pi * x / 0.05)`` or ``exp(-t / 30)``. The explorer is served to
untrusted users, so the text is read by the hand-written tokenizer and recursive-descent
parser of :mod:`core.profiles.parser`; Python's compiler, ``eval``, ``exec`` and
``ast`` are never involved. This module holds the parsed :class:`Expression` (its
evaluation as a stack program) and :func:`parse_expression`; the whitelist is
:mod:`core.profiles.whitelist`.

Grammar (highest precedence last, as in Python)::

    expr   := term (('+' | '-') term)*
    term   := unary (('*' | '/') unary)*
    unary  := ('+' | '-')* power
    power  := atom [('**' | '^') unary]          right-associative: 2**3**2 = 512
    atom   := NUMBER | VARIABLE | CONSTANT | FUNCTION '(' expr [',' expr] ')' | '(' expr ')'

so ``-2**2 = -4`` and ``2**-1 = 0.5``. Numbers are ASCII decimals (``3``, ``0.5``, ``.5``,
``1e-3``, ``2.5E+4``). Constants: ``pi``, ``e``. Functions (all vectorized numpy ufuncs):

    sin cos tan exp log (natural) log10 sqrt abs tanh sinh cosh arctan (alias atan)
    sign heaviside (1 at 0)   -- one argument
    min max                   -- two arguments, elementwise

Anything else (other names, attribute access, strings, brackets, keywords, semicolons,
non-ASCII characters, ...) is refused with an :class:`ExpressionError` naming the field,
the reason and the 1-based character position. Work is bounded for every input: the
length is checked before anything else, the tokenizer is a single linear pass, and the
parser checks the nesting depth before it recurses (:data:`MAX_LENGTH`,
:data:`MAX_DEPTH`, :data:`MAX_NODES`, :data:`MAX_CONSTANT_EXPONENT`).

``Expression.text`` is the normal form: canonical spacing, ``**`` for powers, main
function names, the shortest exact spelling of each number (``1e-3``, ``12000``), only
the parentheses that matter. Specs store it, so a formula whose normal form is longer
than :data:`MAX_LENGTH` is refused too; parsing a normal form gives it back unchanged.

Sub-expressions without variables are folded to numbers at parse time; a folded value
that is not finite (``1/0``, ``exp(1000)``) is refused, and so is a constant exponent
larger than 64 in magnitude (``9**9**9``, ``x**1e10``). A non-constant exponent is
evaluated as is; non-finite results are left for the caller's range check.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from core import limits
from core.immutable import Immutable
from core.profiles.parser import NAME_CHARS, NAME_START, ExpressionError, Instruction, read_formula
from core.profiles.whitelist import (
    ALIASES,
    CONSTANTS,
    FUNCTIONS,
    MAX_LENGTH,
)


def _live_arrays(program: tuple[Instruction, ...]) -> int:
    """Most arrays alive at once while ``program`` runs: its deepest stack, plus the
    result of the operation that empties it."""
    height = peak = 0
    for ins in program:
        height += 1 if ins[0] in ("c", "v") else 1 - ins[2]
        peak = max(peak, height)
    return peak + 1


def _run(program: tuple[Instruction, ...], arrays: list[np.ndarray]) -> Any:
    stack: list[Any] = []
    for ins in program:
        tag = ins[0]
        if tag == "c":
            stack.append(np.float64(ins[1]))
        elif tag == "v":
            stack.append(arrays[ins[1]])
        else:
            _, function, n = ins
            if n == 1:
                stack[-1] = function(stack[-1])
            else:
                right = stack.pop()
                stack[-1] = function(stack[-1], right)
    return stack[0]


class Expression(Immutable):
    """A parsed formula: an immutable, vectorized callable of its variables.

    Build it with :func:`parse_expression`. ``expression(*arrays)`` takes one array per
    variable (in the order of ``.variables``; the units are the caller's, e.g. metres or
    days), broadcasts them, and returns a new float array of the broadcast shape,
    evaluated under ``np.errstate(all="ignore")``: results may be non-finite (``sqrt(x)``
    for ``x < 0``) and are for the caller to range-check. Two expressions are equal when
    their normalized texts and variables are. One evaluation may hold at most
    :data:`core.limits.MAX_FORMULA_ELEMENTS` values (the points times
    :attr:`live_arrays`); a larger request is refused before any work (ValueError), so
    callers with many points evaluate in blocks.
    """

    __slots__ = ("_text", "_variables", "_program", "_value", "_switches", "_live")

    def __init__(self, *, _text: str, _variables: tuple[str, ...],
                 _program: tuple[Instruction, ...], _value: float | None,
                 _switches: tuple[tuple[str, tuple[Instruction, ...]], ...]) -> None:
        object.__setattr__(self, "_text", _text)
        object.__setattr__(self, "_variables", _variables)
        object.__setattr__(self, "_program", _program)
        object.__setattr__(self, "_value", _value)
        object.__setattr__(self, "_switches", _switches)
        object.__setattr__(self, "_live", _live_arrays(_program))

    @property
    def text(self) -> str:
        """The normal form of the formula (see the module docstring). Parsing it again
        gives an equal expression with the same text."""
        return self._text

    @property
    def variables(self) -> tuple[str, ...]:
        """The variable names, in the order ``__call__`` takes them."""
        return self._variables

    @property
    def live_arrays(self) -> int:
        """Most intermediate arrays of the evaluated shape one evaluation holds at once."""
        return self._live

    @property
    def is_constant(self) -> bool:
        """True when the formula uses none of its variables."""
        return self._value is not None

    @property
    def constant_value(self) -> float | None:
        """The value of a constant formula (same unit as the formula), else None."""
        return self._value

    @property
    def switching_functions(self) -> tuple[Expression, ...]:
        """Formulas whose sign changes mark where this one may jump or kink.

        One per ``abs``, ``sign`` or ``heaviside`` (its argument) and per ``min`` or
        ``max`` (the difference of its arguments) that depends on the variables. A caller
        that needs the breakpoints of a formula finds the zeros of these.
        """
        return tuple(
            Expression(_text=text, _variables=self._variables, _program=code, _value=None,
                       _switches=())
            for text, code in self._switches)

    def __call__(self, *arrays: Any) -> np.ndarray:
        """Evaluate on arrays (one per variable, broadcasting); returns a float array."""
        if len(arrays) != len(self._variables):
            raise TypeError(f"expression {self._text!r} takes {len(self._variables)} "
                            f"array(s) ({', '.join(self._variables)}), got {len(arrays)}")
        args = [np.asarray(a, dtype=float) for a in arrays]
        shape = np.broadcast_shapes(*(a.shape for a in args)) if args else ()
        # checked before any work: the evaluation holds live_arrays arrays of this shape
        size = int(np.prod(shape, dtype=np.int64)) if shape else 1
        if size * self._live > limits.MAX_FORMULA_ELEMENTS:
            raise ValueError(
                f"formula {self._text[:60]!r}: evaluating it at {size} points holds "
                f"{self._live} arrays of that size, more than the "
                f"{limits.MAX_FORMULA_ELEMENTS} values allowed at once; evaluate it in "
                f"blocks of at most {limits.MAX_FORMULA_ELEMENTS // self._live} points")
        with np.errstate(all="ignore"):
            result = _run(self._program, args)
        return np.array(np.broadcast_to(result, shape), dtype=float)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Expression):
            return NotImplemented
        return self._text == other._text and self._variables == other._variables

    def __hash__(self) -> int:
        return hash((self._text, self._variables))

    def __repr__(self) -> str:
        return f"Expression({self._text!r}, variables={self._variables!r})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (parse_expression, (self._text, self._variables))


def _check_variables(variables: tuple[str, ...]) -> tuple[str, ...]:
    if isinstance(variables, str) or not isinstance(variables, (tuple, list)):
        raise ValueError(f"variables must be a tuple of names, got {variables!r}")
    variables = tuple(variables)
    for name in variables:
        if (not isinstance(name, str) or not name or name[0] not in NAME_START
                or name.startswith("_") or any(c not in NAME_CHARS for c in name)
                or name in CONSTANTS or name in FUNCTIONS or name in ALIASES):
            raise ValueError(f"variable name {name!r} is not allowed")
    if len(set(variables)) != len(variables):
        raise ValueError(f"variable names repeat: {variables!r}")
    return variables


def parse_expression(text: str, variables: tuple[str, ...] = ("x",), *,
                     field: str = "expr") -> Expression:
    """Parse a user formula in ``variables`` into an :class:`Expression`.

    The formula's units are whatever the caller documents for ``field`` (e.g. metres of
    thickness as a function of ``x`` in metres, or a factor as a function of ``t`` in
    days). Raises :class:`ExpressionError` (a ValueError) whose message names ``field``,
    the reason and the 1-based position; a refusal has no side effect. Raises ValueError
    for an invalid ``variables`` tuple (a programming error).
    """
    variables = _check_variables(variables)
    if not isinstance(text, str):
        raise ExpressionError(field, f"must be a string, got {type(text).__name__}", 1)
    # checked first, so the work below is bounded for any input
    if len(text) > MAX_LENGTH:
        raise ExpressionError(
            field, f"formula is too long ({len(text)} characters, at most {MAX_LENGTH})",
            MAX_LENGTH + 1)
    if not text.strip(" \t\r\n"):
        raise ExpressionError(field, "empty formula", 1)
    node = read_formula(text, variables, field)
    if len(node.text) > MAX_LENGTH:
        # the normal form is what specs store, so it must parse again
        raise ExpressionError(
            field, f"formula is too long in normal form ({len(node.text)} characters, "
            f"at most {MAX_LENGTH})", 1)
    return Expression(_text=node.text, _variables=variables, _program=node.code,
                      _value=node.value, _switches=node.switches)
