"""The tokenizer and recursive-descent parser of user formulas (never ``eval``).

Reads a formula's text, one token at a time in a single linear pass, into a
:class:`FormulaNode`: its normal form, the stack program that evaluates it, its folded
value when it has no variables, and the arguments of its switching functions. The grammar
and the rules of the normal form are in :mod:`core.profiles.expressions`, which builds the public
:class:`~core.profiles.Expression` from the node; the whitelist is
:mod:`core.profiles.whitelist`.
"""

from __future__ import annotations

import difflib
import string
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from core.profiles.whitelist import (
    ALIASES,
    BINARY,
    CONSTANTS,
    FUNCTIONS,
    MAX_CONSTANT_EXPONENT,
    MAX_DEPTH,
    MAX_NODES,
    SWITCH_ONE,
    SWITCH_TWO,
)

# Explicit ASCII sets: str.isdigit/isalpha accept non-ASCII digits and letters, which
# would let look-alike characters through.
_DIGITS = frozenset(string.digits)
NAME_START = frozenset(string.ascii_letters + "_")
NAME_CHARS = NAME_START | _DIGITS
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


#: An instruction of the stack program: ("c", value), ("v", index) or ("f", function, n).
Instruction = tuple[Any, ...]


class FormulaNode(NamedTuple):
    """A parsed part of a formula: normal form, precedence level, stack program, folded
    value, 1-based position and switching functions (normal form and program)."""

    text: str
    level: int
    code: tuple[Instruction, ...]
    value: float | None  # the folded value when the node has no variables
    pos: int
    switches: tuple[tuple[str, tuple[Instruction, ...]], ...]


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
        elif ch in NAME_START:
            start = i
            while i < n and text[i] in NAME_CHARS:
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


def _wrap(node: FormulaNode, level: int) -> str:
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

    def apply(self, function: Callable[..., Any], args: list[FormulaNode], text: str,
              level: int, pos: int,
              switches: tuple[tuple[str, tuple[Instruction, ...]], ...] = ()) -> FormulaNode:
        switches = sum((a.switches for a in args), ()) + switches
        values = [a.value for a in args]
        if all(v is not None for v in values):
            with np.errstate(all="ignore"):
                value = float(function(*(np.float64(v) for v in values)))
            if not np.isfinite(value):
                raise self.fail(f"{text[:60]!r} evaluates to {value}, not a finite number",
                                pos)
            return FormulaNode(text, level, (("c", value),), value, pos, ())
        code = sum((a.code for a in args), ()) + (("f", function, len(args)),)
        return FormulaNode(text, level, code, None, pos, switches)

    # -- grammar

    def parse(self) -> FormulaNode:
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

    def expr(self) -> FormulaNode:
        return self.left_to_right(("+", "-"), self.term, _ADD, _MUL)

    def term(self) -> FormulaNode:
        return self.left_to_right(("*", "/"), self.unary, _MUL, _UNARY)

    def left_to_right(self, ops: tuple[str, ...], operand: Callable[[], FormulaNode], level: int,
                      right_level: int) -> FormulaNode:
        """Operands joined by the operators ``ops`` of one precedence ``level``, grouped
        from the left (``a - b - c`` is ``(a - b) - c``); a right operand is wrapped in
        parentheses below ``right_level``."""
        node = operand()
        while self.tok.kind == "op" and self.tok.text in ops:
            op = self.advance()
            self.count(op.pos)
            right = operand()
            text = f"{_wrap(node, level)} {op.text} {_wrap(right, right_level)}"
            node = self.apply(BINARY[op.text], [node, right], text, level, node.pos)
        return node

    def unary(self) -> FormulaNode:
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

    def power(self) -> FormulaNode:
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

    def atom(self) -> FormulaNode:
        tok = self.tok
        if tok.kind == "num":
            self.advance()
            self.count(tok.pos)
            return FormulaNode(_format_number(tok.value), _ATOM, (("c", tok.value),), tok.value,
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

    def name(self) -> FormulaNode:
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
                return FormulaNode(name, _ATOM, (("v", index),), None, tok.pos, ())
            value = CONSTANTS[name]
            return FormulaNode(name, _ATOM, (("c", value),), value, tok.pos, ())
        canonical = ALIASES.get(name, name)
        function, arity = FUNCTIONS[canonical]
        if not follows_call:
            raise self.fail(f"function {name!r} must be followed by '('", tok.pos)
        opening = self.advance()
        self.enter(opening.pos)
        args: list[FormulaNode] = []
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
        switches: tuple[tuple[str, tuple[Instruction, ...]], ...] = ()
        if canonical in SWITCH_ONE and args[0].value is None:
            switches = ((args[0].text, args[0].code),)
        elif canonical in SWITCH_TWO and (args[0].value is None or args[1].value is None):
            difference = f"{_wrap(args[0], _ADD)} - {_wrap(args[1], _MUL)}"
            code = args[0].code + args[1].code + (("f", np.subtract, 2),)
            switches = ((difference, code),)
        return self.apply(function, args, text, _ATOM, tok.pos, switches)



def read_formula(text: str, variables: tuple[str, ...], field: str) -> FormulaNode:
    """Parse the whole of ``text`` (a formula in ``variables``; units are the caller's).

    Raises :class:`ExpressionError` naming ``field`` at the first problem in reading
    order. The caller checks the length first, which bounds the work.
    """
    return _Parser(_Lexer(text, field), variables, field).parse()
