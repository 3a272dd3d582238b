"""The whitelisting formula parser: values, precedence, limits, refusals, robustness."""

from __future__ import annotations

import builtins
import os
import pickle
import sys
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import core.profiles.expressions as ex
from core.profiles import parse_expression
from core.profiles.expressions import Expression
from core.profiles.parser import ExpressionError
from core.profiles.whitelist import MAX_DEPTH, MAX_LENGTH, MAX_NODES

X = np.linspace(-2.0, 2.0, 41)

# The references call the same numpy ufuncs in the same order as the evaluator, so the
# results are bitwise equal (measured: max |difference| = 0 for every row); exact
# equality is asserted, NaN matching NaN.
CASES: list[tuple[str, Callable[[np.ndarray], np.ndarray]]] = [
    ("x", lambda x: x),
    ("2*x + 1", lambda x: 2 * x + 1),
    ("x**2 - 3*x", lambda x: np.power(x, 2.0) - 3 * x),
    ("x^3", lambda x: np.power(x, 3.0)),
    ("sin(x) + cos(x)", lambda x: np.sin(x) + np.cos(x)),
    ("tan(x/3)", lambda x: np.tan(x / 3)),
    ("exp(-x**2)", lambda x: np.exp(-np.power(x, 2.0))),
    ("log(x)", np.log),
    ("log10(abs(x) + 1)", lambda x: np.log10(np.abs(x) + 1)),
    ("sqrt(x)", np.sqrt),
    ("tanh(x)", np.tanh),
    ("sinh(x) - cosh(x)", lambda x: np.sinh(x) - np.cosh(x)),
    ("arctan(x)", np.arctan),
    ("atan(x)", np.arctan),
    ("sign(x)", np.sign),
    ("heaviside(x)", lambda x: np.heaviside(x, 1.0)),
    ("min(x, 0.5)", lambda x: np.minimum(x, 0.5)),
    ("max(x, -x)", lambda x: np.maximum(x, -x)),
    ("pi*x", lambda x: np.pi * x),
    ("e**x", lambda x: np.power(np.e, x)),
    ("1e-3*x", lambda x: 1e-3 * x),
    ("2.5E+2", lambda x: np.full_like(x, 250.0)),
    (".5*x + 5.", lambda x: 0.5 * x + 5.0),
    ("x/(1+x**2)", lambda x: x / (1 + np.power(x, 2.0))),
    ("2**x", lambda x: np.power(2.0, x)),
    ("x**x", lambda x: np.power(x, x)),
    ("x**-2", lambda x: np.power(x, -2.0)),
    ("1/x", lambda x: 1 / x),
    ("exp(-((x - 0.1)/0.02)**2)", lambda x: np.exp(-np.power((x - 0.1) / 0.02, 2.0))),
    ("0.001 + 0.0005 * sin(2 * pi * x / 0.05)",
     lambda x: 0.001 + 0.0005 * np.sin(2 * np.pi * x / 0.05)),
]


@pytest.mark.parametrize(("text", "reference"), CASES, ids=[c[0] for c in CASES])
def test_values_match_numpy(text: str, reference: Callable[[np.ndarray], np.ndarray]) -> None:
    with np.errstate(all="ignore"):
        expected = reference(X)
    got = parse_expression(text)(X)
    assert got.dtype == np.float64 and got.shape == X.shape
    np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize(("text", "value"), [
    ("2**3**2", 512.0), ("2^3^2", 512.0), ("-2**2", -4.0), ("(-2)**2", 4.0),
    ("2**-1", 0.5), ("1 - 2 - 3", -4.0), ("8 / 4 / 2", 1.0), ("2*3 + 4*5", 26.0),
    ("-3**2 + 10", 1.0), ("2 * -3", -6.0), ("--2", 2.0), ("+-+2", -2.0), ("(1 + 2) * 3", 9.0),
    ("2**-1**2", 0.5), ("min(3, max(1, 2))", 2.0), ("heaviside(0)", 1.0), ("sign(0)", 0.0),
    ("e", float(np.e)), ("pi", float(np.pi)), ("  7\t\n", 7.0),
])
def test_precedence_and_constants(text: str, value: float) -> None:
    # constant results are folded with the same float operations: exact
    assert parse_expression(text)(X[:3]).tolist() == [value] * 3


def test_power_binds_tighter_than_unary_minus_on_arrays() -> None:
    x = np.array([3.0])
    assert parse_expression("-x**2")(x)[0] == -9.0
    assert parse_expression("(-x)**2")(x)[0] == 9.0
    assert parse_expression("2**-x**2")(x)[0] == 2.0 ** -9


def test_broadcasting_and_variable_order() -> None:
    e = parse_expression("x - 10 * t", ("x", "t"))
    x = np.array([1.0, 2.0, 3.0])
    t = np.array([[0.0], [1.0]])
    out = e(x, t)
    assert out.shape == (2, 3)
    np.testing.assert_array_equal(out, x[None, :] - 10 * t)
    # a constant formula takes the broadcast shape of its inputs, as a new writable array
    c = parse_expression("2 * pi", ("x", "t"))
    assert c.is_constant and c.constant_value == 2 * np.pi
    out = c(x, t)
    assert out.shape == (2, 3) and out.flags.writeable
    assert parse_expression("3", ())().shape == ()
    # scalars and integer arrays come back as float arrays
    assert parse_expression("x / 2")(3).dtype == np.float64
    assert parse_expression("x / 2")(np.array([1, 2])).tolist() == [0.5, 1.0]


def test_wrong_number_of_arrays_is_a_type_error() -> None:
    with pytest.raises(TypeError):
        parse_expression("x")(X, X)


def test_normalized_text_round_trips() -> None:
    cases = {
        "2^3^2": "2 ** 3 ** 2",
        "(-2)**2": "(-2) ** 2",
        "-2**2": "-2 ** 2",
        "atan( x )+ 1E-3": "arctan(x) + 1e-3",
        "0.001 + 100 + 1e2 + 2.50 + 1.5e-07 + 12000.0": "1e-3 + 100 + 100 + 2.5 + 1.5e-7 + 12000",
        "a - (b - c)": "a - (b - c)",
        "(a - b) - c": "a - b - c",
        "a / (b * c)": "a / (b * c)",
        "+x": "x",
        "((x))": "x",
        "(2**3)**2": "(2 ** 3) ** 2",
        "min(x,a)": "min(x, a)",
        "1e16": "1e16",
        "1000000000000000": "1e15",
    }
    for text, normal in cases.items():
        e = parse_expression(text, ("x", "a", "b", "c"))
        assert e.text == normal
        again = parse_expression(e.text, ("x", "a", "b", "c"))
        assert again == e and hash(again) == hash(e) and again.text == e.text


def test_expression_is_immutable_hashable_and_picklable() -> None:
    e = parse_expression("sin(x) + 1")
    with pytest.raises(AttributeError):
        e.text = "os"  # type: ignore[misc]
    with pytest.raises(AttributeError):
        e._program = ()  # type: ignore[misc]
    assert e == parse_expression("sin( x )+1")
    assert e != parse_expression("sin(x) + 2")
    assert e != parse_expression("sin(t) + 1", ("t",))
    assert {e: 1}[parse_expression("sin(x)+1")] == 1
    assert pickle.loads(pickle.dumps(e)) == e
    assert e.variables == ("x",)


def test_switching_functions() -> None:
    e = parse_expression("abs(x - 1) + min(x, 2*x) + heaviside(x) + sign(x**2) + abs(3)")
    assert [g.text for g in e.switching_functions] == ["x - 1", "x - 2 * x", "x", "x ** 2"]
    g = e.switching_functions[1]
    assert isinstance(g, Expression) and g(np.array([2.0]))[0] == -2.0
    assert parse_expression("sin(x)").switching_functions == ()


# ----------------------------------------------------------------------------- limits


def test_length_limit() -> None:
    assert parse_expression("0" * (MAX_LENGTH - 1) + "7").constant_value == 7.0
    assert parse_expression(" " * (MAX_LENGTH - 1) + "x")(X).tolist() == X.tolist()
    with pytest.raises(ExpressionError, match=r"too long \(501 characters, at most 500\)"):
        parse_expression("1" * (MAX_LENGTH + 1))


def test_normal_form_must_fit_the_length_limit() -> None:
    # specs store the normal form, so a formula whose normal form (with spaces around
    # operators) would be refused on reading is refused now
    fits = "+".join(["tau"] * 75)
    assert len(parse_expression(fits, ("t", "tau")).text) <= MAX_LENGTH
    with pytest.raises(ExpressionError, match=r"too long in normal form \(597 characters"):
        parse_expression("+".join(["tau"] * 100), ("t", "tau"))


def test_depth_limit() -> None:
    assert parse_expression("(" * MAX_DEPTH + "x" + ")" * MAX_DEPTH)(X).tolist() == X.tolist()
    with pytest.raises(ExpressionError, match="nested more than 20 levels deep at position 21"):
        parse_expression("(" * (MAX_DEPTH + 1) + "x" + ")" * (MAX_DEPTH + 1))
    parse_expression("sin(" * MAX_DEPTH + "x" + ")" * MAX_DEPTH)
    with pytest.raises(ExpressionError, match="nested"):
        parse_expression("sin(" * (MAX_DEPTH + 1) + "x" + ")" * (MAX_DEPTH + 1))
    parse_expression("x**" * MAX_DEPTH + "x")
    with pytest.raises(ExpressionError, match="nested"):
        parse_expression("x**" * (MAX_DEPTH + 1) + "x")
    # a run of signs is a loop in the parser and costs no depth
    assert parse_expression("-" * 100 + "x")(X).tolist() == X.tolist()


def test_node_limit() -> None:
    # "x+x+...+x" with k terms has 2k - 1 parts
    k = (MAX_NODES + 1) // 2
    parse_expression("+".join(["x"] * k))
    with pytest.raises(ExpressionError, match="more than 200 parts"):
        parse_expression("+".join(["x"] * (k + 1)))


def test_constant_exponent_limit() -> None:
    assert parse_expression("x**64")(np.array([1.0]))[0] == 1.0
    assert parse_expression("x**-64")(np.array([1.0]))[0] == 1.0
    assert parse_expression("x**(8*8)")(np.array([1.0]))[0] == 1.0
    for text in ("x**64.5", "x**-65", "x**(8*9)", "2**100", "x**1e10", "9**9**9**9"):
        with pytest.raises(ExpressionError, match="constant exponent .* too large"):
            parse_expression(text)
    # a non-constant exponent is evaluated; overflow gives inf, left to the range check
    big = parse_expression("10**(x*400)")(np.array([0.0, 1.0]))
    assert big[0] == 1.0 and big[1] == np.inf


def test_non_finite_constants_are_refused() -> None:
    for text in ("1/0", "log(0)", "sqrt(-1)", "exp(1000)", "1e308*10", "x + 0/0"):
        with pytest.raises(ExpressionError, match="not a finite number"):
            parse_expression(text)
    with pytest.raises(ExpressionError, match="out of range"):
        parse_expression("1e999")


def test_recursion_is_bounded() -> None:
    # Parsing at the depth limit was measured to need at most 130 frames; with a stack
    # allowance of 200 frames, inputs 10000 deep must be refused by the depth check, not
    # by a RecursionError.
    def frames() -> int:
        n, f = 0, sys._getframe()
        while f is not None:
            n, f = n + 1, f.f_back
        return n

    deep = ["(" * 10_000 + "x" + ")" * 10_000, "sin(" * 120 + "x" + ")" * 120,
            "x**" * 160 + "x", "-(" * 120 + "x" + ")" * 120, "min(x, " * 60 + "x" + ")" * 60,
            "(" * 20 + "x" + ")" * 20, "sin(" * 20 + "x" + ")" * 20]
    old = sys.getrecursionlimit()
    sys.setrecursionlimit(frames() + 200)
    try:
        outcomes = []
        for text in deep:
            try:
                parse_expression(text)
                outcomes.append("ok")
            except ExpressionError:
                outcomes.append("refused")
    finally:
        sys.setrecursionlimit(old)
    assert outcomes == ["refused"] * 5 + ["ok"] * 2


def test_work_is_linear_in_the_length() -> None:
    # Counting Python and C calls is a deterministic measure of work. The worst inputs of
    # MAX_LENGTH characters were measured at <= 5702 calls (~11.4 per character); the
    # bound of 20 calls per character leaves room for interpreter differences while still
    # excluding anything quadratic in the length (which would be ~500 per character).
    def calls(text: str) -> int:
        count = 0

        def profiler(frame: object, event: str, arg: object) -> None:
            nonlocal count
            if event in ("call", "c_call"):
                count += 1

        sys.setprofile(profiler)
        try:
            try:
                parse_expression(text)
            except ExpressionError:
                pass
        finally:
            sys.setprofile(None)
        return count

    worst = ["x+" * 249 + "x", "-" * 199 + "x", "sin(x)+" * 71 + "x", "min(x,1)+" * 55 + "x",
             "abs(x)*" * 71 + "x", "1" * 500, "(" * 500, "a" * 500, " " * 499 + "x",
             "x+" * 99 + "x$", "sinn" * 125, "exp(1)*" * 70 + "x"]
    for text in worst:
        text = text[:MAX_LENGTH]
        assert calls(text) <= 20 * MAX_LENGTH, text[:30]


# ----------------------------------------------------------------------------- messages


@pytest.mark.parametrize(("text", "message"), [
    ("1 + os", "coating[0].thickness.expr: unknown name 'os' at position 5"),
    ("x.real", "coating[0].thickness.expr: unexpected character '.' at position 2"),
    ("sinn(x)", "coating[0].thickness.expr: unknown name 'sinn' at position 1; "
                "did you mean 'sin'?"),
    ("2x", "coating[0].thickness.expr: missing operator before 'x' at position 2"),
    ("(x + 1", "coating[0].thickness.expr: '(' is never closed at position 1"),
    ("x)", "coating[0].thickness.expr: unmatched ')' at position 2"),
    ("x, 1", "coating[0].thickness.expr: ',' outside a function call at position 2"),
    ("min(x)", "coating[0].thickness.expr: function 'min' takes 2 arguments, got 1 "
               "at position 1"),
    ("sin(x, 1)", "coating[0].thickness.expr: function 'sin' takes 1 argument, got more "
                  "at position 6"),
    ("sin", "coating[0].thickness.expr: function 'sin' must be followed by '(' at position 1"),
    ("x(2)", "coating[0].thickness.expr: 'x' is not a function (use '*' to multiply) "
             "at position 2"),
    ("x *", "coating[0].thickness.expr: unexpected end of formula at position 4"),
    ("", "coating[0].thickness.expr: empty formula at position 1"),
    ("x ** 100", "coating[0].thickness.expr: constant exponent 100 is too large "
                 "(at most 64 in magnitude) at position 6"),
])
def test_error_messages(text: str, message: str) -> None:
    with pytest.raises(ExpressionError) as info:
        parse_expression(text, field="coating[0].thickness.expr")
    assert str(info.value) == message
    assert isinstance(info.value, ValueError)
    assert info.value.field == "coating[0].thickness.expr"


def test_error_attributes_and_non_string() -> None:
    with pytest.raises(ExpressionError) as info:
        parse_expression("x + y")
    assert (info.value.reason, info.value.position) == ("unknown name 'y'", 5)
    with pytest.raises(ExpressionError, match="must be a string"):
        parse_expression(3)  # type: ignore[arg-type]


def test_bad_variable_names_are_a_programming_error() -> None:
    for variables in (("pi",), ("sin",), ("_x",), ("x", "x"), ("x y",), "x", ("é",)):
        with pytest.raises(ValueError, match="variable"):
            parse_expression("1", variables)  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- attacks

SENTINEL_VALUE = "untouched"


def _attacks(sentinel: str) -> list[str]:
    return [
        f"__import__('os').system('touch {sentinel}')",
        f"open('{sentinel}', 'w').write('x')",
        "().__class__.__bases__[0].__subclasses__()",
        "x.__class__",
        "x.__class__.__mro__",
        "lambda: 1",
        "(lambda: 1)()",
        "[i for i in range(9)]",
        "9**9**9**9",
        "x**1e10",
        "(" * 10_000 + "x" + ")" * 10_000,
        "x+" * 500_000 + "x",  # about 1 MB
        "open('f')",
        "exec('1')",
        "eval('1')",
        "eval",
        "globals()",
        "globals().update(SENTINEL_VALUE='hacked')",
        "import os",
        "x; y",
        "x if 1 else 2",
        "'a'",
        '"a"',
        "b'a'",
        "x\u0430",  # Cyrillic a
        "\uff53\uff49\uff4e(x)",  # fullwidth sin, which NFKC would turn into sin
        "\u0435xp(x)",  # Cyrillic e
        "x\u200b+1",  # zero-width space
        "x\u00b2",  # superscript two
        "\u0661 + x",  # Arabic-Indic digit one
        "sin.__call__(x)",
        "sin.__self__",
        "1 and 2",
        "not x",
        "x or 1",
        "x[0]",
        "{1: 2}",
        "x == 1",
        "x < 1",
        "x @ x",
        "x % 2",
        "x // 2",
        "~x",
        "x << 2",
        "x := 1",
        "f'{x}'",
        "x\\\n+1",
        "__builtins__",
        "getattr(x, 'real')",
        "__import__",
        "os.system",
        "sys.exit()",
        "breakpoint()",
        "compile('1', 'f', 'eval')",
        "vars()",
        "locals()",
        "type(x)",
        "x\x00",
        "# comment",
        "min(x, 1, 2)",
        "sin(x)(1)",
        "1 if x else 2",
        "yield x",
        "await x",
        "*x",
        "**x",
        "x,",
        "0x10",
        "1_000",
        "1j",
        "inf",
        "nan",
        "True",
        "None",
    ]


def test_attacks_are_refused_without_side_effects(tmp_path: os.PathLike) -> None:
    sentinel = os.path.join(str(tmp_path), "pwned")
    payloads = _attacks(sentinel)
    assert len(payloads) >= 30
    modules = set(sys.modules)
    builtin_names = set(vars(builtins))
    for text in payloads:
        with pytest.raises(ExpressionError):
            parse_expression(text, field="scene.expr")
    assert not os.path.exists(sentinel)
    assert os.listdir(str(tmp_path)) == []
    assert SENTINEL_VALUE == "untouched"
    assert set(sys.modules) == modules
    assert set(vars(builtins)) == builtin_names
    # the parser's own tables are not changed by refusals
    assert sorted(ex.FUNCTIONS) == sorted(
        ["sin", "cos", "tan", "exp", "log", "log10", "sqrt", "abs", "tanh", "sinh", "cosh",
         "arctan", "sign", "heaviside", "min", "max"])
    assert dict(ex.ALIASES) == {"atan": "arctan"}
    assert dict(ex.CONSTANTS) == {"pi": float(np.pi), "e": float(np.e)}


def test_the_whitelist_is_read_only() -> None:
    with pytest.raises(TypeError):
        ex.FUNCTIONS["system"] = (os.system, 1)  # type: ignore[index]
    with pytest.raises(TypeError):
        ex.CONSTANTS["os"] = 1.0  # type: ignore[index]
    assert "system" not in ex.FUNCTIONS


def test_the_modules_never_use_pythons_compiler() -> None:
    import core.profiles.parser
    import core.profiles.whitelist

    for module in (ex, core.profiles.parser, core.profiles.whitelist):
        source = open(module.__file__, encoding="utf-8").read()
        for word in ("eval(", "exec(", "compile(", "import ast", "literal_eval",
                     "__import__"):
            assert word not in source, (module.__name__, word)


# ----------------------------------------------------------------------------- hypothesis

TOKENS = [
    "x", "t", "1", "0", "2.5", ".5", "1e-3", "1E+2", "e", "pi", "+", "-", "*", "/", "**",
    "^", "(", ")", ",", " ", "sin", "cos", "exp", "log", "sqrt", "abs", "min", "max",
    "heaviside", "sign", "atan", "arctan", "tanh", "__import__", "os", "'", '"', "[", "]",
    ".", ":", ";", "lambda", "if", "else", "=", "__class__", "\u0430", "\uff53", "\t", "#",
    "9**9", "64", "65",
]


def _check_outcome(text: str) -> None:
    try:
        e = parse_expression(text)
    except ExpressionError:
        event("refused")
        return
    event("parsed")
    out = e(np.array([-1.5, -0.25, 0.0, 0.5, 2.0]))
    assert isinstance(out, np.ndarray) and out.dtype == np.float64 and out.shape == (5,)
    again = parse_expression(e.text)
    assert again == e
    np.testing.assert_array_equal(again(np.array([-1.5, 0.5])), e(np.array([-1.5, 0.5])))


@pytest.mark.slow
@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.text(max_size=120))
def test_random_text_is_parsed_or_refused(text: str) -> None:
    _check_outcome(text)


# mostly well-formed pieces, so that a fair share of the soup parses
GOOD_TOKENS = ["x", "2", "0.5", "1e-3", "pi", "+", "-", "*", "/", "**", "(", ")", "sin(",
               "min(x, ", "abs(", "exp(-"]


@pytest.mark.slow
@settings(max_examples=600, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(st.lists(st.sampled_from(TOKENS), max_size=40),
                 st.lists(st.sampled_from(GOOD_TOKENS), max_size=30)).map("".join))
def test_token_soup_is_parsed_or_refused(text: str) -> None:
    _check_outcome(text)


@settings(max_examples=100, deadline=None)
@given(st.integers(min_value=MAX_LENGTH - 20, max_value=MAX_LENGTH + 20),
       st.sampled_from(["x+", "(", "-", "1", "0", " ", "sin(", "x*2**"]))
def test_long_inputs_near_the_limit(length: int, unit: str) -> None:
    _check_outcome((unit * length)[:length])


def _formulas() -> st.SearchStrategy[tuple[str, Callable[[np.ndarray], object]]]:
    """Fully parenthesized formulas paired with a numpy reference built alongside."""
    numbers = st.one_of(st.integers(0, 50).map(float),
                        st.floats(0.0, 100.0, allow_nan=False, allow_infinity=False))
    leaves = st.one_of(
        numbers.map(lambda v: (repr(v), lambda x, v=v: np.float64(v))),
        st.just(("x", lambda x: x)),
        st.just(("pi", lambda x: np.float64(np.pi))),
        st.just(("e", lambda x: np.float64(np.e))),
    )
    unary_functions = ["sin", "cos", "tan", "exp", "log", "log10", "sqrt", "abs", "tanh",
                       "sinh", "cosh", "arctan", "sign", "heaviside"]

    def extend(children: st.SearchStrategy) -> st.SearchStrategy:
        def binary(op: str, ufunc: Callable) -> st.SearchStrategy:
            return st.tuples(children, children).map(
                lambda ab, op=op, ufunc=ufunc: (
                    f"({ab[0][0]}) {op} ({ab[1][0]})",
                    lambda x, a=ab[0][1], b=ab[1][1], ufunc=ufunc: ufunc(a(x), b(x))))

        def call(name: str) -> st.SearchStrategy:
            ufunc = ex.FUNCTIONS[name][0]
            return children.map(lambda a, name=name, ufunc=ufunc: (
                f"{name}({a[0]})", lambda x, f=a[1], ufunc=ufunc: ufunc(f(x))))

        return st.one_of(
            binary("+", np.add), binary("-", np.subtract), binary("*", np.multiply),
            binary("/", np.divide),
            st.tuples(children, st.integers(-4, 4)).map(lambda ap: (
                f"({ap[0][0]}) ** {ap[1]}" if ap[1] >= 0 else f"({ap[0][0]}) ** ({ap[1]})",
                lambda x, f=ap[0][1], p=float(ap[1]): np.power(f(x), np.float64(p)))),
            children.map(lambda a: (f"-({a[0]})", lambda x, f=a[1]: np.negative(f(x)))),
            st.tuples(children, children).map(lambda ab: (
                f"min({ab[0][0]}, {ab[1][0]})",
                lambda x, a=ab[0][1], b=ab[1][1]: np.minimum(a(x), b(x)))),
            st.sampled_from(unary_functions).flatmap(call),
        )

    return st.recursive(leaves, extend, max_leaves=6)


@pytest.mark.slow
@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_formulas())
def test_generated_formulas_match_numpy(formula: tuple[str, Callable]) -> None:
    text, reference = formula
    x = np.array([-1.5, -0.25, 0.0, 0.5, 2.0])
    try:
        e = parse_expression(text)
    except ExpressionError as err:
        # the only legitimate refusals of a well-formed formula are its limits
        assert ("not a finite number" in err.reason or "nested more than" in err.reason
                or "constant exponent" in err.reason), str(err)
        event("refused at a limit")
        return
    event("parsed")
    with np.errstate(all="ignore"):
        expected = np.broadcast_to(reference(x), x.shape)
    # same ufuncs in the same order: bitwise equal (see CASES)
    np.testing.assert_array_equal(e(x), expected)
    assert parse_expression(e.text) == e


def test_formula_temporaries_are_bounded():
    from core.profiles import parse_expression
    expr = parse_expression("t - (tau - (t - (tau - (t - tau))))", ("t", "tau"))
    n = 3000  # 9e6 points times the formula's live arrays: over the budget
    with pytest.raises(ValueError, match="evaluate it in blocks"):
        expr(np.ones((n, 1)), np.ones((1, n)))
    assert expr(np.ones((100, 1)), np.ones((1, 100))).shape == (100, 100)
