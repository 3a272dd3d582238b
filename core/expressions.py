"""A whitelisting parser for user formulas (never ``eval``).

Scene files and the browser explorer let users type formulas such as
``0.002 + 0.001 * sin(2 * pi * x / 0.05)`` or ``exp(-t / 30)``. The explorer is served to
untrusted users, so the text is read by the hand-written tokenizer and recursive-descent
parser below; Python's compiler, ``eval``, ``exec`` and ``ast`` are never involved.

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

import difflib
import string
from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any, NamedTuple

import numpy as np

from core import limits
from core.immutable import Immutable

#: Longest accepted formula, in characters.
MAX_LENGTH = limits.MAX_FORMULA_CHARS
#: Deepest accepted nesting; parentheses, function calls and exponents each add a level.
MAX_DEPTH = limits.MAX_FORMULA_DEPTH
#: Most accepted parts (numbers, names, operators, calls).
MAX_NODES = limits.MAX_FORMULA_PARTS
#: Largest accepted magnitude of an exponent that does not depend on the variables.
MAX_CONSTANT_EXPONENT = limits.MAX_CONSTANT_EXPONENT

# The tables are read-only views, so no other code can widen the whitelist at run time.

#: Named constants.
CONSTANTS: Mapping[str, float] = MappingProxyType({"pi": float(np.pi), "e": float(np.e)})


def _heaviside(v: Any) -> Any:
    return np.heaviside(v, 1.0)


#: Functions of one argument that are numpy's functions of the same name.
_NUMPY_UNARY = ("sin", "cos", "tan", "exp", "log", "log10", "sqrt", "abs", "tanh", "sinh",
                "cosh", "arctan", "sign")

#: Functions: name -> (numpy implementation, number of arguments).
FUNCTIONS: Mapping[str, tuple[Callable[..., Any], int]] = MappingProxyType({
    **{name: (getattr(np, name), 1) for name in _NUMPY_UNARY},
    "heaviside": (_heaviside, 1),
    "min": (np.minimum, 2),
    "max": (np.maximum, 2),
})
#: Other spellings accepted for a function; the normalized text uses the main name.
ALIASES: Mapping[str, str] = MappingProxyType({"atan": "arctan"})

# Functions whose value or slope jumps where their argument changes sign; min and max
# switch where their two arguments cross.
_SWITCH_ONE = frozenset({"abs", "sign", "heaviside"})
_SWITCH_TWO = frozenset({"min", "max"})

_BINARY: Mapping[str, Callable[..., Any]] = MappingProxyType({
    "+": np.add, "-": np.subtract, "*": np.multiply, "/": np.divide, "**": np.power,
})

# Explicit ASCII sets: str.isdigit/isalpha accept non-ASCII digits and letters, which
# would let look-alike characters through.
_DIGITS = frozenset(string.digits)
_NAME_START = frozenset(string.ascii_letters + "_")
_NAME_CHARS = _NAME_START | _DIGITS
_SPACE = frozenset(" \t\r\n")
_SINGLE_OPS = frozenset("+-*/^(),")

# Levels of the normalized text, used to put back only the parentheses that matter.
_ADD, _MUL, _UNARY, _POW, _ATOM = 1, 2, 3, 4, 5


class ExpressionError(ValueError):
    """A refused formula. ``field``, ``reason`` and ``position`` (1-based) are attributes."""

    def __init__(self, field: str, reason: str, position: int, hint: str = "") -> None:
        super().__init__(f"{field}: {reason} at position {position}"
                         + (f"; {hint}" if hint else ""))
        self.field = field
        self.reason = reason
        self.position = position


class _Token(NamedTuple):
    kind: str  # "num", "name", "op" or "end"
    text: str
    pos: int  # 1-based
    value: float = 0.0


# An instruction of the stack program: ("c", value), ("v", index) or ("f", function, n).
_Instr = tuple[Any, ...]


class _Node(NamedTuple):
    text: str
    level: int
    code: tuple[_Instr, ...]
    value: float | None  # the folded value when the node has no variables
    pos: int
    switches: tuple[tuple[str, tuple[_Instr, ...]], ...]


def _show_name(name: str) -> str:
    return repr(name if len(name) <= 40 else name[:40] + "...")


def _format_number(value: float) -> str:
    # the shortest of forms that all round-trip exactly: repr, an integer without ".0",
    # and a compact exponent form (1e-3, 2.5e7), which keeps the normal form short
    text = str(int(value)) if value.is_integer() and abs(value) < 1e16 else repr(value)
    mantissa, _, exponent = np.format_float_scientific(value, unique=True,
                                                       trim="-").partition("e")
    compact = f"{mantissa}e{int(exponent)}"
    return compact if len(compact) < len(text) else text


class _Lexer:
    """Reads tokens one at a time, so the first problem in reading order is reported."""

    def __init__(self, text: str, field: str) -> None:
        self.text = text
        self.field = field
        self.i = 0

    def next(self) -> _Token:
        text, n = self.text, len(self.text)
        i = self.i
        while i < n and text[i] in _SPACE:
            i += 1
        if i >= n:
            self.i = i
            return _Token("end", "", n + 1)
        ch = text[i]
        pos = i + 1
        if ch in _DIGITS or (ch == "." and i + 1 < n and text[i + 1] in _DIGITS):
            start = i
            while i < n and text[i] in _DIGITS:
                i += 1
            if i < n and text[i] == ".":
                i += 1
                while i < n and text[i] in _DIGITS:
                    i += 1
            if i < n and text[i] in "eE":
                j = i + 1
                if j < n and text[j] in "+-":
                    j += 1
                if j < n and text[j] in _DIGITS:
                    while j < n and text[j] in _DIGITS:
                        j += 1
                    i = j
            literal = text[start:i]
            # the literal matched the ASCII decimal syntax above, so float() only converts
            value = float(literal)
            if not np.isfinite(value):
                shown = literal if len(literal) <= 40 else literal[:40] + "..."
                raise ExpressionError(self.field, f"number {shown} is out of range", pos)
            token = _Token("num", literal, pos, value)
        elif ch in _NAME_START:
            start = i
            while i < n and text[i] in _NAME_CHARS:
                i += 1
            token = _Token("name", text[start:i], pos)
        elif ch == "*" and i + 1 < n and text[i + 1] == "*":
            token = _Token("op", "**", pos)
            i += 2
        elif ch in _SINGLE_OPS:
            token = _Token("op", "**" if ch == "^" else ch, pos)
            i += 1
        else:
            raise ExpressionError(self.field, f"unexpected character {ch!r}", pos)
        self.i = i
        return token


def _wrap(node: _Node, level: int) -> str:
    return node.text if node.level >= level else f"({node.text})"


class _Parser:
    def __init__(self, lexer: _Lexer, variables: tuple[str, ...], field: str) -> None:
        self.lexer = lexer
        self.tok = lexer.next()
        self.variables = variables
        self.field = field
        self.depth = 0
        self.nodes = 0

    # -- helpers

    def fail(self, reason: str, pos: int, hint: str = "") -> ExpressionError:
        return ExpressionError(self.field, reason, pos, hint)

    def advance(self) -> _Token:
        tok = self.tok
        self.tok = self.lexer.next()
        return tok

    def count(self, pos: int) -> None:
        self.nodes += 1
        if self.nodes > MAX_NODES:
            raise self.fail(f"formula has more than {MAX_NODES} parts", pos)

    def enter(self, pos: int) -> None:
        # checked before recursing, so the Python stack stays shallow for any input
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.fail(f"formula is nested more than {MAX_DEPTH} levels deep", pos)

    def leave(self) -> None:
        self.depth -= 1

    def describe(self, tok: _Token) -> str:
        if tok.kind == "end":
            return "unexpected end of formula"
        if tok.kind == "name":
            return f"unexpected name {_show_name(tok.text)}"
        if tok.kind == "num":
            return f"unexpected number {tok.text[:40]}"
        return f"unexpected {tok.text!r}"

    def known(self, name: str) -> bool:
        return (name in self.variables or name in CONSTANTS or name in FUNCTIONS
                or name in ALIASES)

    def unknown(self, tok: _Token) -> ExpressionError:
        hint = ""
        if len(tok.text) >= 3:
            choices = [*self.variables, *CONSTANTS, *FUNCTIONS, *ALIASES]
            close = difflib.get_close_matches(tok.text[:40], choices, n=1, cutoff=0.75)
            if close:
                hint = f"did you mean {close[0]!r}?"
        return self.fail(f"unknown name {_show_name(tok.text)}", tok.pos, hint)

    def apply(self, function: Callable[..., Any], args: list[_Node], text: str, level: int,
              pos: int, switches: tuple[tuple[str, tuple[_Instr, ...]], ...] = ()) -> _Node:
        switches = sum((a.switches for a in args), ()) + switches
        values = [a.value for a in args]
        if all(v is not None for v in values):
            with np.errstate(all="ignore"):
                value = float(function(*(np.float64(v) for v in values)))
            if not np.isfinite(value):
                raise self.fail(f"{text[:60]!r} evaluates to {value}, not a finite number",
                                pos)
            return _Node(text, level, (("c", value),), value, pos, ())
        code = sum((a.code for a in args), ()) + (("f", function, len(args)),)
        return _Node(text, level, code, None, pos, switches)

    # -- grammar

    def parse(self) -> _Node:
        node = self.expr()
        if self.tok.kind != "end":
            raise self.misplaced(self.tok)
        return node

    def misplaced(self, tok: _Token) -> ExpressionError:
        """The error for a token that follows a complete operand but is no operator."""
        if tok.text == ")":
            return self.fail("unmatched ')'", tok.pos)
        if tok.text == ",":
            return self.fail("',' outside a function call", tok.pos)
        if tok.kind == "name" and not self.known(tok.text):
            return self.unknown(tok)
        if tok.kind in ("name", "num") or tok.text == "(":
            return self.fail(f"missing operator before {tok.text[:40]!r}", tok.pos)
        return self.fail(self.describe(tok), tok.pos)

    def expr(self) -> _Node:
        return self.left_to_right(("+", "-"), self.term, _ADD, _MUL)

    def term(self) -> _Node:
        return self.left_to_right(("*", "/"), self.unary, _MUL, _UNARY)

    def left_to_right(self, ops: tuple[str, ...], operand: Callable[[], _Node], level: int,
                      right_level: int) -> _Node:
        """Operands joined by the operators ``ops`` of one precedence ``level``, grouped
        from the left (``a - b - c`` is ``(a - b) - c``); a right operand is wrapped in
        parentheses below ``right_level``."""
        node = operand()
        while self.tok.kind == "op" and self.tok.text in ops:
            op = self.advance()
            self.count(op.pos)
            right = operand()
            text = f"{_wrap(node, level)} {op.text} {_wrap(right, right_level)}"
            node = self.apply(_BINARY[op.text], [node, right], text, level, node.pos)
        return node

    def unary(self) -> _Node:
        # a loop, not recursion: a run of signs costs no stack depth
        signs: list[_Token] = []
        while self.tok.kind == "op" and self.tok.text in ("+", "-"):
            sign = self.advance()
            self.count(sign.pos)
            signs.append(sign)
        node = self.power()
        for sign in reversed(signs):
            if sign.text == "-":
                text = f"-{_wrap(node, _UNARY)}"
                node = self.apply(np.negative, [node], text, _UNARY, sign.pos)
            # a unary plus changes nothing and is dropped from the normalized text
        return node

    def power(self) -> _Node:
        base = self.atom()
        if self.tok.kind == "op" and self.tok.text == "**":
            op = self.advance()
            self.count(op.pos)
            self.enter(op.pos)
            exponent = self.unary()
            self.leave()
            if exponent.value is not None and abs(exponent.value) > MAX_CONSTANT_EXPONENT:
                raise self.fail(
                    f"constant exponent {_format_number(exponent.value)} is too large "
                    f"(at most {MAX_CONSTANT_EXPONENT:g} in magnitude)", exponent.pos)
            text = f"{_wrap(base, _ATOM)} ** {_wrap(exponent, _UNARY)}"
            return self.apply(np.power, [base, exponent], text, _POW, base.pos)
        return base

    def atom(self) -> _Node:
        tok = self.tok
        if tok.kind == "num":
            self.advance()
            self.count(tok.pos)
            return _Node(_format_number(tok.value), _ATOM, (("c", tok.value),), tok.value,
                         tok.pos, ())
        if tok.kind == "name":
            return self.name()
        if tok.kind == "op" and tok.text == "(":
            self.advance()
            self.enter(tok.pos)
            inner = self.expr()
            self.expect_close(tok)
            self.leave()
            return inner._replace(pos=tok.pos)
        raise self.fail(self.describe(tok), tok.pos)

    def expect_close(self, opening: _Token) -> None:
        tok = self.tok
        if tok.kind == "op" and tok.text == ")":
            self.advance()
            return
        if tok.kind == "end":
            raise self.fail("'(' is never closed", opening.pos)
        raise self.misplaced(tok)

    def name(self) -> _Node:
        tok = self.tok
        name = tok.text
        if not self.known(name):
            # reported before reading on, so 'lambda: 1' is refused for 'lambda', not ':'
            raise self.unknown(tok)
        self.advance()
        self.count(tok.pos)
        follows_call = self.tok.kind == "op" and self.tok.text == "("
        if name in self.variables or name in CONSTANTS:
            if follows_call:
                raise self.fail(f"{name!r} is not a function (use '*' to multiply)",
                                self.tok.pos)
            if name in self.variables:
                index = self.variables.index(name)
                return _Node(name, _ATOM, (("v", index),), None, tok.pos, ())
            value = CONSTANTS[name]
            return _Node(name, _ATOM, (("c", value),), value, tok.pos, ())
        canonical = ALIASES.get(name, name)
        function, arity = FUNCTIONS[canonical]
        if not follows_call:
            raise self.fail(f"function {name!r} must be followed by '('", tok.pos)
        opening = self.advance()
        self.enter(opening.pos)
        args: list[_Node] = []
        if not (self.tok.kind == "op" and self.tok.text == ")"):
            args.append(self.expr())
            while self.tok.kind == "op" and self.tok.text == "," and len(args) < arity:
                self.advance()
                args.append(self.expr())
        if len(args) != arity:
            plural = "s" if arity > 1 else ""
            raise self.fail(f"function {name!r} takes {arity} argument{plural}, "
                            f"got {len(args)}", tok.pos)
        if self.tok.kind == "op" and self.tok.text == ",":
            plural = "s" if arity > 1 else ""
            raise self.fail(f"function {name!r} takes {arity} argument{plural}, got more",
                            self.tok.pos)
        self.expect_close(opening)
        self.leave()
        text = f"{canonical}({', '.join(a.text for a in args)})"
        switches: tuple[tuple[str, tuple[_Instr, ...]], ...] = ()
        if canonical in _SWITCH_ONE and args[0].value is None:
            switches = ((args[0].text, args[0].code),)
        elif canonical in _SWITCH_TWO and (args[0].value is None or args[1].value is None):
            difference = f"{_wrap(args[0], _ADD)} - {_wrap(args[1], _MUL)}"
            code = args[0].code + args[1].code + (("f", np.subtract, 2),)
            switches = ((difference, code),)
        return self.apply(function, args, text, _ATOM, tok.pos, switches)


def _live_arrays(program: tuple[_Instr, ...]) -> int:
    """Most arrays alive at once while ``program`` runs: its deepest stack, plus the
    result of the operation that empties it."""
    height = peak = 0
    for ins in program:
        height += 1 if ins[0] in ("c", "v") else 1 - ins[2]
        peak = max(peak, height)
    return peak + 1


def _run(program: tuple[_Instr, ...], arrays: list[np.ndarray]) -> Any:
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
                 _program: tuple[_Instr, ...], _value: float | None,
                 _switches: tuple[tuple[str, tuple[_Instr, ...]], ...]) -> None:
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
        if (not isinstance(name, str) or not name or name[0] not in _NAME_START
                or name.startswith("_") or any(c not in _NAME_CHARS for c in name)
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
    node = _Parser(_Lexer(text, field), variables, field).parse()
    if len(node.text) > MAX_LENGTH:
        # the normal form is what specs store, so it must parse again
        raise ExpressionError(
            field, f"formula is too long in normal form ({len(node.text)} characters, "
            f"at most {MAX_LENGTH})", 1)
    return Expression(_text=node.text, _variables=variables, _program=node.code,
                      _value=node.value, _switches=node.switches)
