"""The whitelist of user formulas: their limits, constants and functions.

Everything a formula may name or do is listed here, as read-only tables, so no other code
can widen the whitelist at run time. The tokenizer and parser are in
:mod:`core.profiles.parser`; the parsed value and its evaluation in
:mod:`core.profiles.expressions`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from core import limits

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
SWITCH_ONE = frozenset({"abs", "sign", "heaviside"})
SWITCH_TWO = frozenset({"min", "max"})

#: The binary operators: token -> numpy implementation.
BINARY: Mapping[str, Callable[..., Any]] = MappingProxyType({
    "+": np.add, "-": np.subtract, "*": np.multiply, "/": np.divide, "**": np.power,
})
