"""Profiles: families, breakpoints, specs, validation messages, range checks, CSV uploads."""

from __future__ import annotations

import math
import os
import pickle
import subprocess
import sys
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from scipy.interpolate import PchipInterpolator

from core import limits
from core.profiles import Profile, check_range, profile_from_csv, profile_from_spec
from core.profiles.base import INTERPOLATIONS, MAX_TABLE_ROWS, profile_key
from core.profiles.build import KINDS
from core.scene import scene_from_dict
from tests.conftest import elastic_dict

D = (-0.15, 0.25)
LO, HI = D
V = np.linspace(LO, HI, 401)


def make(spec: Any, *, variable: str = "x", domain: tuple[float, float] = D) -> Profile:
    return profile_from_spec(spec, field="f", variable=variable, domain=domain)


def assert_round_trip(p: Profile) -> None:
    q = profile_from_spec(p.spec, field="g", variable=p.variable, domain=p.domain)
    assert q == p and hash(q) == hash(p) and profile_key(q) == profile_key(p)
    assert q.spec == p.spec and q.breakpoints == p.breakpoints and q.kind == p.kind
    np.testing.assert_array_equal(q(V), p(V))
    assert pickle.loads(pickle.dumps(p)) == p


# ----------------------------------------------------------------------------- families


def test_constant_forms() -> None:
    for spec in (2, 2.0, {"kind": "constant", "value": 2}, np.float64(2.0)):
        p = make(spec)
        assert p.kind == "constant" and p.spec == 2.0 and p.breakpoints == ()
        out = p(V.reshape(401, 1))
        assert out.shape == (401, 1) and out.dtype == np.float64 and np.all(out == 2.0)
        assert_round_trip(p)
    assert make(-0.0).spec == 0.0 and make(-0.0) == make(0)
    # scalars and lists are accepted as input; NaN positions give NaN
    assert make(2)(0.1).shape == ()
    assert np.isnan(make(2)([0.0, np.nan])).tolist() == [False, True]


def test_linear() -> None:
    p = make({"kind": "linear", "start": 2e-3, "end": 5e-3})
    # measured max relative difference from the textbook form: 3.8e-16 (two roundings)
    np.testing.assert_allclose(p(V), 2e-3 + 3e-3 * (V - LO) / (HI - LO), rtol=1e-15, atol=0)
    assert p(np.array(D)).tolist() == [2e-3, 5e-3]  # exact at both ends
    assert p.breakpoints == () and p.kind == "linear"
    assert p.spec == {"kind": "linear", "start": 2e-3, "end": 5e-3}
    assert_round_trip(p)


def test_step() -> None:
    p = make({"kind": "step", "values": [1, 2, 3], "breaks": [-0.05, 0.1]})
    assert p.breakpoints == (-0.05, 0.1)
    below = np.nextafter(np.array([-0.05, 0.1]), -np.inf)
    assert p(below).tolist() == [1.0, 2.0]
    assert p(np.array([LO, -0.05, 0.0, 0.1, HI])).tolist() == [1.0, 2.0, 2.0, 3.0, 3.0]
    assert p.spec == {"kind": "step", "values": [1.0, 2.0, 3.0], "breaks": [-0.05, 0.1]}
    assert_round_trip(p)
    assert make({"kind": "step", "values": [4], "breaks": []})(V).tolist() == [4.0] * 401


def test_sine() -> None:
    p = make({"kind": "sine", "mean": 1.0, "amplitude": 0.3, "wavelength": 0.07, "phase": 0.4})
    # measured 1.1e-15: 2 pi v / L and (2 pi / L) v differ by rounding in an argument of up
    # to 22 rad; the bound |A| |arg| 2 eps / min|y| = 0.3 * 22 * 4.4e-16 / 0.7 = 4.1e-15
    np.testing.assert_allclose(p(V), 1.0 + 0.3 * np.sin(2 * np.pi * V / 0.07 + 0.4),
                               rtol=5e-15, atol=0)
    assert p.breakpoints == ()
    q = make({"kind": "sine", "mean": 1.0, "amplitude": 0.3, "wavelength": 0.07})
    assert q.spec["phase"] == 0.0
    assert_round_trip(p)
    assert_round_trip(q)


def test_polynomial() -> None:
    c = [1.0, -2.0, 3.0, 0.5, -4.0]
    p = make({"kind": "polynomial", "coefficients": c})
    # measured 3.2e-16 (Horner against the power sum); with sum |c_k v^k| <= 1.6 and
    # |p| >= 0.6 on the domain, 5 operations bound it by 5 * 2.2e-16 * 1.6 / 0.6 = 3e-15
    np.testing.assert_allclose(p(V), sum(ck * V**k for k, ck in enumerate(c)), rtol=3e-15,
                               atol=0)
    assert p.breakpoints == ()
    assert_round_trip(p)
    assert make({"kind": "polynomial", "coefficients": [0.0] * 16}) is not None


def test_bump() -> None:
    p = make({"kind": "bump", "mean": 1.0, "amplitude": -0.5, "center": 0.05, "width": 0.02})
    # same expression evaluated with the same operations: measured difference 0
    np.testing.assert_array_equal(p(V), 1.0 - 0.5 * np.exp(-(((V - 0.05) / 0.02) ** 2)))
    assert p(np.array([0.05]))[0] == 0.5 and p.breakpoints == ()
    assert_round_trip(p)


def test_ramp() -> None:
    p = make({"kind": "ramp", "start": 1.0, "end": 3.0, "duration": 0.1})
    expected = np.where(V < LO + 0.1, 1.0 + 2.0 * (V - LO) / 0.1, 3.0)
    np.testing.assert_array_equal(p(V), expected)  # measured difference 0
    assert p.breakpoints == (LO + 0.1,)
    assert p(np.array([LO, LO + 0.1, HI])).tolist() == [1.0, 3.0, 3.0]
    assert_round_trip(p)
    # a ramp longer than the domain has its corner outside: no breakpoint
    assert make({"kind": "ramp", "start": 0, "end": 1, "duration": 10}).breakpoints == ()


POINTS = [[-0.2, 1.0], [0.0, 3.0], [0.1, 2.0], [0.3, 2.5]]


def test_table_linear() -> None:
    p = make({"kind": "table", "points": POINTS, "interpolation": "linear"})
    xs, ys = np.array(POINTS).T
    np.testing.assert_array_equal(p(V), np.interp(V, xs, ys))
    assert p(np.array([-5.0, 5.0])).tolist() == [1.0, 2.5]  # held outside the table
    assert p.breakpoints == (0.0, 0.1)  # interior rows inside the domain
    # a table that ends inside the domain has kinks at its ends as well
    inner = make({"kind": "table", "points": [[-0.1, 1], [0.0, 2], [0.2, 2]]})
    assert inner.breakpoints == (-0.1, 0.0, 0.2)
    assert inner.spec["interpolation"] == "linear"  # the default
    assert_round_trip(p)


def test_table_step() -> None:
    p = make({"kind": "table", "points": POINTS, "interpolation": "step"})
    assert p(np.array([LO, -0.2, 0.0, 0.05, 0.1, HI, 0.3, 9.0])).tolist() == \
        [1.0, 1.0, 3.0, 3.0, 2.0, 2.0, 2.5, 2.5]
    assert p(np.nextafter(np.array([0.0, 0.1]), -np.inf)).tolist() == [1.0, 3.0]
    assert p.breakpoints == (0.0, 0.1)
    assert_round_trip(p)


def test_table_pchip() -> None:
    points = [[-0.1, 1.0], [0.0, 2.0], [0.1, 2.5], [0.2, 4.0]]
    p = make({"kind": "table", "points": points, "interpolation": "pchip"})
    xs, ys = np.array(points).T
    inside = V[(V >= -0.1) & (V <= 0.2)]
    # the same scipy interpolant; measured difference 0 except at the last row, which is
    # held at the table value
    np.testing.assert_array_equal(p(inside), np.where(
        inside >= 0.2, 4.0, PchipInterpolator(xs, ys)(inside)))
    assert p(xs).tolist() == ys.tolist()
    assert p(np.array([-9.0, 9.0])).tolist() == [1.0, 4.0]
    assert np.all(np.diff(p(V)) >= 0)  # monotone data, monotone interpolant
    assert p.breakpoints == (-0.1, 0.2)  # only the ends, where the held value begins
    assert_round_trip(p)


def test_expr_profiles_and_their_breakpoints() -> None:
    p = make({"expr": "0.001 + 0.0005*heaviside(x - 0.02) + abs(x - 0.1)"})
    assert p.kind == "expr"
    assert p.spec == {"kind": "expr", "expr": "1e-3 + 5e-4 * heaviside(x - 0.02) + "
                                              "abs(x - 0.1)"}
    assert p == make({"kind": "expr", "expr": "0.001+0.0005*heaviside(x-0.02)+abs(x-0.1)"})
    np.testing.assert_array_equal(
        p(V), 0.001 + 0.0005 * np.heaviside(V - 0.02, 1.0) + np.abs(V - 0.1))
    # the bisection stops at adjacent floating-point numbers: within one spacing
    assert len(p.breakpoints) == 2
    for found, true in zip(p.breakpoints, (0.02, 0.1), strict=True):
        assert abs(found - true) <= np.spacing(true)
    assert_round_trip(p)
    # min/max switch where their arguments cross; a zero run switches nothing
    assert make({"expr": "min(x, 0.05)"}).breakpoints == (0.05,)
    assert make({"expr": "min(x, x)"}).breakpoints == ()
    # smooth formulas have none; time profiles use t
    assert make({"expr": "sin(x)"}).breakpoints == ()
    t = make({"expr": "exp(-t / 30)"}, variable="t", domain=(0.0, 100.0))
    np.testing.assert_array_equal(t(np.array([0.0, 30.0])), np.exp([-0.0, -1.0]))
    assert_round_trip(make({"expr": "2 * pi"}))


def test_equality_depends_on_variable_and_domain() -> None:
    spec = {"kind": "linear", "start": 0, "end": 1}
    assert make(spec) == make(dict(spec))
    assert make(spec) != make(spec, domain=(0.0, 1.0))
    assert make({"expr": "1"}, variable="t") != make({"expr": "1"})
    assert len({make(spec), make(dict(spec)), make(3)}) == 2
    assert make(spec) != spec


def test_profile_key_is_stable_across_processes() -> None:
    spec = {"kind": "table", "points": POINTS, "interpolation": "pchip"}
    key = profile_key(make(spec))
    assert len(key) == 64 and all(c in "0123456789abcdef" for c in key)
    code = ("from core.profiles import profile_from_spec; "
            "from core.profiles.base import profile_key; "
            f"print(profile_key(profile_from_spec({spec!r}, field='f', domain={D!r})))")
    env = dict(os.environ, PYTHONHASHSEED="12345")
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, cwd=root, check=True).stdout.strip()
    assert out == key
    assert profile_key(make(1)) != profile_key(make(2))


def test_profiles_are_immutable() -> None:
    p = make({"kind": "step", "values": [1, 2], "breaks": [0.0]})
    with pytest.raises(AttributeError):
        p.kind = "constant"  # type: ignore[misc]
    spec = p.spec
    spec["values"][0] = 99  # the returned spec is a copy
    assert p.spec["values"] == [1.0, 2.0]


def test_large_table() -> None:
    rows = [[i * 1e-4 - 0.5, math.sin(i)] for i in range(MAX_TABLE_ROWS)]
    p = make({"kind": "table", "points": rows})
    assert len(p.breakpoints) == sum(1 for r in rows if LO < r[0] < HI)
    assert_round_trip(p)
    with pytest.raises(ValueError, match=r"f.points: must have at most 10000 rows, has 10001"):
        make({"kind": "table", "points": rows + [[10.0, 0.0]]})


# ----------------------------------------------------------------------------- messages


@pytest.mark.parametrize(("spec", "message"), [
    ({"kind": "sine", "mean": 1, "amplitud": 1, "wavelength": 1},
     "punch.shape: unknown field 'amplitud'; did you mean 'amplitude'?"),
    ({"kind": "bump", "mean": 1, "amplitude": 1, "center": 0},
     "punch.shape: missing field 'width' (required for kind 'bump')"),
    ({"kind": "constant", "value": float("nan")},
     "punch.shape.value: must be a finite number, is nan"),
    ({"kind": "constant", "value": float("-inf")},
     "punch.shape.value: must be a finite number, is -inf"),
    ({"kind": "polynomial", "coefficients": [1, float("inf")]},
     "punch.shape.coefficients[1]: must be a finite number, is inf"),
    ({"kind": "linear", "start": True, "end": 1},
     "punch.shape.start: must be a number, not a boolean"),
    ({"kind": "linear", "start": "1", "end": 1},
     "punch.shape.start: must be a number, not a string"),
    ({"kind": "linear", "start": None, "end": 1}, "punch.shape.start: must be a number, not null"),
    ({"kind": "linear", "start": [1], "end": 1}, "punch.shape.start: must be a number, not a list"),
    ({"kind": "constant", "value": 10**400},
     "punch.shape.value: must be a finite number, is too large"),
    ({"kind": "table", "points": [[0, 1], [1, 2], [1, 3], [2, 1]]},
     "punch.shape.points: must be strictly increasing in x (row 2)"),
    ({"kind": "table", "points": [[0, 1]]}, "punch.shape.points: must have at least 2 rows, has 1"),
    ({"kind": "table", "points": [[0, 1], [1, 2]], "interpolation": "cubic"},
     "punch.shape.interpolation: must be one of linear, step, pchip, is 'cubic'"),
    ({"kind": "table", "points": [[0, 1], [1, 2]], "interpolation": 3},
     "punch.shape.interpolation: must be one of linear, step, pchip, is a number"),
    ({"kind": "table", "points": [[0, 1], [1]]},
     "punch.shape.points[1]: must be a pair [x, value], not a list of 1"),
    ({"kind": "table", "points": [[0, 1], {"x": 1}]},
     "punch.shape.points[1]: must be a pair [x, value], not an object"),
    ({"kind": "table", "points": [[0, 1], [1, False]]},
     "punch.shape.points[1][1]: must be a number, not a boolean"),
    ({"kind": "table", "points": "0,1;1,2"}, "punch.shape.points: must be a list, not a string"),
    ({"kind": "step", "values": [1, 2], "breaks": [0.0, 0.1]},
     "punch.shape.values: must have one entry more than breaks (3), has 2"),
    ({"kind": "step", "values": [1, 2], "breaks": [0.25]},
     "punch.shape.breaks[0]: must lie strictly inside the domain (-0.15, 0.25) of x, is 0.25"),
    ({"kind": "step", "values": [1, 2, 3], "breaks": [0.1, 0.0]},
     "punch.shape.breaks: must be strictly increasing in x (entry 1)"),
    ({"kind": "sine", "mean": 1, "amplitude": 1, "wavelength": 0},
     "punch.shape.wavelength: must be > 0, is 0"),
    ({"kind": "bump", "mean": 1, "amplitude": 1, "center": 0, "width": -1},
     "punch.shape.width: must be > 0, is -1"),
    ({"kind": "ramp", "start": 1, "end": 1, "duration": 0},
     "punch.shape.duration: must be > 0, is 0"),
    ({"kind": "polynomial", "coefficients": [1] * 17},
     "punch.shape.coefficients: must have at most 16 coefficients, has 17"),
    ({"kind": "polynomial", "coefficients": []},
     "punch.shape.coefficients: must not be empty"),
    ({"expr": "x + os"}, "punch.shape.expr: unknown name 'os' at position 5"),
    ({"kind": "expr", "expr": 3},
     "punch.shape.expr: must be a string (a formula in x), not a number"),
    ({"kind": "cosine"}, "punch.shape.kind: unknown kind 'cosine'; known kinds: constant, "
                         "linear, step, sine, polynomial, bump, ramp, table, expr"),
    ({"kind": 1}, "punch.shape.kind: must be a string, not a number"),
    ({"value": 1}, "punch.shape: missing field 'kind' (one of constant, linear, step, sine, "
                   "polynomial, bump, ramp, table, expr), or give a number or {'expr': ...}"),
    ({"expr": "x", "kind2": 1}, "punch.shape: unknown field 'kind2'; did you mean 'kind'?"),
    ({"kind": "constant", "value": 1, 3: 4},
     "punch.shape: field names must be strings, not a number"),
    ([1, 2], "punch.shape: must be a number or an object with a 'kind' field, not a list"),
    ("1", "punch.shape: must be a number or an object with a 'kind' field, not a string"),
    (True, "punch.shape: must be a number or an object with a 'kind' field, not a boolean"),
    (None, "punch.shape: must be a number or an object with a 'kind' field, not null"),
    (float("nan"), "punch.shape: must be a finite number, is nan"),
])
def test_spec_errors(spec: Any, message: str) -> None:
    with pytest.raises(ValueError) as info:
        profile_from_spec(spec, field="punch.shape", domain=D)
    assert str(info.value) == message


def test_unknown_field_without_a_close_match_lists_the_allowed_ones() -> None:
    with pytest.raises(ValueError, match=r"unknown field 'zzz' for kind 'linear'; allowed: "
                                         r"end, kind, start"):
        make({"kind": "linear", "start": 0, "end": 1, "zzz": 0})


def test_bad_domain_and_variable_are_refused() -> None:
    for domain in ((1.0, 1.0), (2.0, 1.0), (0.0, float("inf")), (0.0,), "ab"):
        with pytest.raises(ValueError, match="domain"):
            make(1, domain=domain)  # type: ignore[arg-type]
    for variable in ("pi", "sin", "", "x y", 3):
        with pytest.raises(ValueError, match="variable"):
            make(1, variable=variable)  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- range checks


def test_check_range_message_names_field_value_and_place() -> None:
    p = make({"kind": "linear", "start": -0.001, "end": 0.001}, domain=(0.12, 0.3))
    with pytest.raises(ValueError) as info:
        check_range(p, field="coating[0].thickness", domain=(0.12, 0.3), lower=0)
    assert str(info.value) == "coating[0].thickness: must be > 0, is -0.001 at x = 0.12"
    check_range(p, field="c", domain=(0.3 - 0.01, 0.3), lower=0)  # a sub-domain


def test_check_range_refuses_non_finite_values() -> None:
    with pytest.raises(ValueError, match=r"^c: must be finite, is nan at x = -1$"):
        check_range(make({"expr": "sqrt(x)"}, domain=(-1.0, 1.0)), field="c", lower=0)
    with pytest.raises(ValueError, match=r"^c: must be finite, is inf at t = 0$"):
        check_range(make({"expr": "1/t"}, variable="t", domain=(0.0, 1.0)), field="c")


def test_check_range_bounds_and_inclusive_flags() -> None:
    zero = make(0)
    check_range(zero, field="c", lower=0, lower_inclusive=True)
    check_range(zero, field="c", upper=0, upper_inclusive=True)
    with pytest.raises(ValueError, match=r"must be > 0, is 0 at x = -0.15"):
        check_range(zero, field="c", lower=0)
    with pytest.raises(ValueError, match=r"must be < 0, is 0 at x = -0.15"):
        check_range(zero, field="c", upper=0)
    with pytest.raises(ValueError, match=r"must be <= 1, is 2 at x = 0.1"):
        check_range(make({"kind": "step", "values": [1, 2], "breaks": [0.1]}), field="c",
                    upper=1, upper_inclusive=True)


def test_check_range_sees_features_narrower_than_the_grid() -> None:
    # a dip between two breaks 1e-12 apart: found on the breakpoints
    dip = make({"kind": "step", "values": [1, -1, 1], "breaks": [0.1, 0.1 + 1e-12]})
    with pytest.raises(ValueError, match=r"must be > 0, is -1 at x = 0.1$"):
        check_range(dip, field="c", lower=0)
    # a bump 1e-9 wide: found at its centre
    spike = make({"kind": "bump", "mean": 1, "amplitude": -2, "center": 0.0123456,
                  "width": 1e-9})
    with pytest.raises(ValueError, match=r"must be > 0, is -1 at x = 0.0123456$"):
        check_range(spike, field="c", lower=0)
    # a polynomial whose minimum -1e-10 at x = 0.3 lies between grid points (where it is
    # >= 2.5e-9): found at its turning point
    bowl = make({"kind": "polynomial", "coefficients": [0.09 - 1e-10, -0.6, 1.0]},
                domain=(0.0, 1.0))
    assert np.all(bowl(np.linspace(0.0, 1.0, 4097)) > 0)
    with pytest.raises(ValueError, match=r"must be > 0, is -1e-10 at x = 0.3$"):
        check_range(bowl, field="c", lower=0)
    # a sine of twice the grid spacing is ~0 on the whole grid: its crests are sampled
    wave = make({"kind": "sine", "mean": 0, "amplitude": 1, "wavelength": 1 / 2048},
                domain=(0.0, 1.0))
    assert np.max(np.abs(wave(np.linspace(0.0, 1.0, 4097)))) < 1e-9
    with pytest.raises(ValueError, match=r"must be < 0.999999, is 1 at x = "):
        check_range(wave, field="c", upper=0.999999)


def test_sample_points_cover_both_sides_of_breakpoints() -> None:
    p = make({"kind": "step", "values": [1, 2], "breaks": [0.1]})
    pts = p.sample_points()
    assert pts[0] == LO and pts[-1] == HI and np.all(np.diff(pts) > 0)
    assert {0.1, np.nextafter(0.1, -1.0), np.nextafter(0.1, 1.0)} <= set(pts.tolist())


# ----------------------------------------------------------------------------- CSV


def csv(data: bytes | str, **kwargs: Any) -> Profile:
    return profile_from_csv(data, field="coating[0].modulus", domain=(0.0, 1.0), **kwargs)


@pytest.mark.parametrize("data", [
    "x,E\n0,1\n0.5,2\n1,3\n",
    "0,1\n0.5,2\n1,3",
    "0, 1\n0.5 , 2\n1,3,\n",  # spaces around cells, a trailing separator
    "x;E\n0;1\n0,5;2\n1;3\n",  # semicolons with a decimal comma
    "x E\n0 1\n0.5\t2\n\n1   3\n",  # white space
    "\r\n0,1\r\n0.5,2\r\n1,3\r\n\r\n",  # CRLF and blank lines
    b"\xef\xbb\xbfx,E\n0,1\n0.5,2\n1,3\n",  # UTF-8 with a byte-order mark
    b"x,\xe9paisseur\n0,1\n5e-1,2\n1E0,3\n",  # a Latin-1 header, exponent forms
    "\ufeffx,E\n+0,1\n.5,2\n1.,3\n",
])
def test_csv_accepted(data: bytes | str) -> None:
    p = csv(data)
    assert p.spec == {"kind": "table", "points": [[0.0, 1.0], [0.5, 2.0], [1.0, 3.0]],
                      "interpolation": "linear"}
    assert p.breakpoints == (0.5,)


def test_csv_interpolation_and_variable() -> None:
    p = profile_from_csv("0,1\n10,2\n", field="f", variable="t", domain=(0.0, 30.0),
                         interpolation="step")
    assert p.spec["interpolation"] == "step" and p.variable == "t"
    with pytest.raises(ValueError, match=r"^f.interpolation: must be one of"):
        profile_from_csv("0,1\n10,2\n", field="f", domain=(0.0, 30.0), interpolation="spline")


@pytest.mark.parametrize(("data", "message"), [
    (b"0,1\n" * 500_000,  # 2 MB
     "coating[0].modulus: file is too large (2000000 bytes, at most 1000000)"),
    ("0,1\n" * 500_000, "coating[0].modulus: file is too large (more than 1000000 bytes)"),
    ("".join(f"{i},{i}\n" for i in range(20_001)),
     "coating[0].modulus: file has too many rows (20001, at most 10000)"),
    ("x,E\n0,1\n1,abc\n", "coating[0].modulus: line 3, column 2: 'abc' is not a number"),
    ("x,E\n0,1\n1,nan\n", "coating[0].modulus: line 3, column 2: 'nan' is not a number"),
    ("0,1\n1,inf\n", "coating[0].modulus: line 2, column 2: 'inf' is not a number"),
    ("0,1\n1,1e999\n", "coating[0].modulus: line 2, column 2: '1e999' is out of range"),
    ("0,1\n1,0x10\n", "coating[0].modulus: line 2, column 2: '0x10' is not a number"),
    ("0,1\n1,1_0\n", "coating[0].modulus: line 2, column 2: '1_0' is not a number"),
    ("0,1\n\u0661,2\n", "coating[0].modulus: line 2, column 1: '\u0661' is not a number"),
    ("x,E\n0,1\n", "coating[0].modulus: file needs at least 2 data rows, has 1 (its first "
                 "line, not numbers, is read as a header)"),
    ("x,E\n", "coating[0].modulus: file needs at least 2 data rows, has 0 (its first line, "
            "not numbers, is read as a header)"),
    ("0,1\n", "coating[0].modulus: file needs at least 2 data rows, has 1"),
    # two lines of words read "needs at least 2 data rows, has 1" (an audit)
    ("hello world\nfoo\n", "coating[0].modulus: line 2, column 1: 'foo' is not a number"),
    ("", "coating[0].modulus: file is empty"),
    (" \n\n", "coating[0].modulus: file is empty"),
    ("0,1\n0.5,2\n0.5,3\n",
     "coating[0].modulus: x values must be strictly increasing (line 3: 0.5 after 0.5)"),
    ("0,1\n1,2,3\n", "coating[0].modulus: line 2: expected 2 columns separated by ',', "
                     "found 3"),
    ("1,2,3\n4,5\n", "coating[0].modulus: line 1: expected 2 columns separated by ',', "
                     "found 3"),
    ("x E\nunits m Pa\n0 1\n1 2\n",
     "coating[0].modulus: line 2, column 1: 'units' is not a number"),
    (b"PK\x03\x04\x00\x00", "coating[0].modulus: file is not text (upload a plain CSV file)"),
])
def test_csv_refused(data: bytes | str, message: str) -> None:
    with pytest.raises(ValueError) as info:
        csv(data)
    assert str(info.value) == message


def test_csv_limits_are_parameters() -> None:
    data = "".join(f"{i / 10},{i}\n" for i in range(11))
    assert len(csv(data).spec["points"]) == 11
    with pytest.raises(ValueError, match=r"too many rows \(11, at most 10\)"):
        csv(data, max_rows=10)
    with pytest.raises(ValueError, match=r"too large \(\d+ bytes, at most 20\)"):
        csv(data.encode(), max_bytes=20)
    with pytest.raises(ValueError, match="must be bytes or text"):
        csv(123)  # type: ignore[arg-type]


def test_csv_long_cell_is_refused_quickly() -> None:
    # a 900 kB cell of digits ending in a letter: the number pattern has no nested
    # repetition, so this is one linear scan (and the cell is shortened in the message)
    cell = "1" * 900_000 + "x"
    with pytest.raises(ValueError, match=r"line 2, column 2: '1{40}\.\.\.' is not a number"):
        csv("0,1\n1," + cell + "\n")


# ----------------------------------------------------------------------------- hypothesis

FAMILY_FIELDS = {
    "constant": ["value"], "linear": ["start", "end"], "step": ["values", "breaks"],
    "sine": ["mean", "amplitude", "wavelength", "phase"], "polynomial": ["coefficients"],
    "bump": ["mean", "amplitude", "center", "width"], "ramp": ["start", "end", "duration"],
    "table": ["points", "interpolation"], "expr": ["expr"],
}
ALL_KEYS = sorted({k for keys in FAMILY_FIELDS.values() for k in keys} | {"kind"})

finite = st.floats(-1e6, 1e6, allow_nan=False)
junk = st.one_of(
    st.none(), st.booleans(), st.integers(), st.floats(), st.text(max_size=12),
    st.sampled_from(["x", "sin(x)", "os", "__import__('os')", "linear", "pchip", "1/0"]),
    st.lists(st.floats(), max_size=4), st.dictionaries(st.text(max_size=4), st.integers(),
                                                       max_size=2),
)


def _value_for(key: str) -> st.SearchStrategy:
    if key in ("values", "breaks", "coefficients"):
        return st.lists(st.one_of(finite, st.floats(-0.15, 0.25)), max_size=18)
    if key == "points":
        return st.lists(st.lists(finite, min_size=2, max_size=2), max_size=8)
    if key == "interpolation":
        return st.sampled_from([*INTERPOLATIONS, "cubic"])
    if key == "expr":
        return st.sampled_from(["x", "sin(40*x)", "abs(x - 0.1)", "sqrt(x)", "1/x", "os",
                                "heaviside(x)*2", "x**", "min(x, 0)", "exp(-t / 30)",
                                "abs(t - 3)", "t"])
    if key in ("wavelength", "width", "duration"):
        return st.one_of(st.floats(1e-6, 10.0), finite)
    return finite


@st.composite
def near_specs(draw: st.DrawFn) -> Any:
    """Specs of a real family, then broken in a few random ways."""
    kind = draw(st.sampled_from(KINDS))
    spec: dict[Any, Any] = {"kind": kind}
    for key in FAMILY_FIELDS[kind]:
        spec[key] = draw(_value_for(key))
    if draw(st.booleans()):
        # well-formed lists half of the time, so that tables and steps are accepted too
        if kind == "step":
            spec["breaks"] = sorted(draw(st.lists(st.floats(-0.14, 0.24), unique=True,
                                                  max_size=6)))
            spec["values"] = draw(st.lists(finite, min_size=len(spec["breaks"]) + 1,
                                           max_size=len(spec["breaks"]) + 1))
        elif kind == "table":
            xs = sorted(draw(st.lists(finite, min_size=2, max_size=8, unique=True)))
            spec["points"] = [[x, draw(finite)] for x in xs]
    for _ in range(draw(st.integers(0, 2))):
        action = draw(st.sampled_from(["drop", "add", "junk", "kind"]))
        keys = list(spec)
        if action == "drop" and keys:
            del spec[draw(st.sampled_from(keys))]
        elif action == "add":
            spec[draw(st.one_of(st.sampled_from(ALL_KEYS), st.text(max_size=6),
                                st.integers()))] = draw(junk)
        elif action == "junk" and keys:
            spec[draw(st.sampled_from(keys))] = draw(junk)
        else:
            spec["kind"] = draw(st.one_of(st.sampled_from(KINDS), junk))
    return spec


json_like = st.recursive(
    junk, lambda c: st.lists(c, max_size=4) | st.dictionaries(
        st.one_of(st.sampled_from(ALL_KEYS), st.text(max_size=6)), c, max_size=5),
    max_leaves=12)


@pytest.mark.slow
@settings(max_examples=600, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(near_specs(), json_like),
       st.sampled_from([("x", (-0.15, 0.25)), ("t", (0.0, 30.0))]))
def test_random_specs_are_accepted_or_refused_with_value_error(
        spec: Any, place: tuple[str, tuple[float, float]]) -> None:
    variable, domain = place
    try:
        p = profile_from_spec(spec, field="s", variable=variable, domain=domain)
    except ValueError as err:
        assert str(err).startswith("s")
        event("refused")
        return
    event(f"accepted {p.kind}")
    v = np.linspace(domain[0], domain[1], 7)
    out = p(v)
    assert isinstance(out, np.ndarray) and out.shape == (7,) and out.dtype == np.float64
    assert all(domain[0] < b < domain[1] for b in p.breakpoints)
    assert list(p.breakpoints) == sorted(set(p.breakpoints))
    q = profile_from_spec(p.spec, field="s", variable=variable, domain=domain)
    assert q == p
    np.testing.assert_array_equal(q(v), out)
    try:
        check_range(p, field="s", lower=-1e3, upper=1e3, samples=65)
    except ValueError as err:
        assert str(err).startswith("s: must be")


csv_text = st.lists(
    st.one_of(
        st.tuples(st.floats(allow_nan=False), st.floats(allow_nan=False)).map(
            lambda r: f"{r[0]!r},{r[1]!r}"),
        st.tuples(st.integers(-5, 20), st.integers()).map(lambda r: f"{r[0]};{r[1]}"),
        st.text(alphabet="0123456789.,;eE+- \tx\r", max_size=12),
        st.text(max_size=8),
    ), max_size=12).map("\n".join)



@st.composite
def near_csv(draw: st.DrawFn) -> str:
    """Valid tables written with a random separator and header, then perhaps one bad line."""
    xs = sorted(draw(st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=10, unique=True)))
    separator = draw(st.sampled_from([",", ", ", ";", "\t", " "]))
    lines = [f"{x!r}{separator}{draw(finite)!r}" for x in xs]
    if separator == ";":
        lines = [line.replace(".", ",") for line in lines]
    if draw(st.booleans()):
        lines.insert(0, draw(st.sampled_from(["x,E", "x;E", "position modulus", "#"])))
    if draw(st.booleans()):
        lines.insert(draw(st.integers(0, len(lines))), draw(st.text(max_size=10)))
    return "\n".join(lines)


@pytest.mark.slow
@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(csv_text, csv_text.map(lambda s: s.encode("utf-8")), st.binary(max_size=64),
                 near_csv()))
def test_random_csv_is_accepted_or_refused_with_value_error(data: bytes | str) -> None:
    try:
        p = csv(data)
    except ValueError as err:
        assert str(err).startswith("coating[0].modulus")
        event("refused")
        return
    event("accepted")
    assert p.kind == "table" and len(p.spec["points"]) >= 2


def test_a_pchip_table_whose_slopes_overflow_is_refused_naming_the_field():
    """Found by the property test: rows 1.6e-304 apart make SciPy's pchip slopes
    infinite, and its own ValueError named no field."""
    spec = {"kind": "table", "points": [[0.0, 0.0], [1.635348361109492e-304, 29399.0]],
            "interpolation": "pchip"}
    with pytest.raises(ValueError, match=r"^punch\.shape\.points: the slopes between rows"):
        profile_from_spec(spec, field="punch.shape", variable="x", domain=(-0.15, 0.25))


# ------------------------------------------------------------------------ the registry

#: One spec of each family on D, with a constant part to drop.
FAMILY_EXAMPLES = {
    "constant": {"kind": "constant", "value": 2.5},
    "linear": {"kind": "linear", "start": 1.0, "end": 3.0},
    "step": {"kind": "step", "values": [1.0, 2.0, 0.5], "breaks": [-0.05, 0.1]},
    "sine": {"kind": "sine", "mean": 4.0, "amplitude": 1.0, "wavelength": 0.1},
    "polynomial": {"kind": "polynomial", "coefficients": [5.0, 1.0, -2.0]},
    "bump": {"kind": "bump", "mean": 3.0, "amplitude": 1.0, "center": 0.05, "width": 0.05},
    "ramp": {"kind": "ramp", "start": 1.0, "end": 2.0, "duration": 0.1},
    "table": {"kind": "table", "points": [[-0.1, 7.0], [0.0, 8.0], [0.2, 6.5]]},
    "expr": {"kind": "expr", "expr": "1 + x**2"},
}


def test_every_family_of_the_registry_is_listed_and_built() -> None:
    from core.profiles.build import FAMILIES

    assert tuple(FAMILIES) == KINDS == tuple(FAMILY_EXAMPLES)
    for kind, spec in FAMILY_EXAMPLES.items():
        p = profile_from_spec(spec, field="f", variable="x", domain=D)
        assert p.kind == kind
        assert profile_from_spec(p.spec, field="f", variable="x", domain=D) == p


def test_without_offset_changes_a_profile_by_a_constant_only() -> None:
    from core.profiles import without_offset
    from core.profiles.build import FAMILIES

    for kind, spec in FAMILY_EXAMPLES.items():
        p = profile_from_spec(spec, field="f", variable="x", domain=D)
        q = without_offset(p)
        difference = p(V) - q(V)
        # rounding of values of size ~5: measured at most 6.7e-16 (linear) here
        assert np.ptp(difference) <= 1e-14, kind
        if FAMILIES[kind].offset is None:
            assert q == p
        else:
            assert difference[0] != 0.0, kind  # every example has a constant part


def test_each_form_of_the_screen_reads_back_what_it_writes() -> None:
    from core.profiles import HISTORY_FORMS, VARIATIONS, history_form_of, variation_of

    assert list(VARIATIONS) == ["none", "linear", "step", "patch", "sine", "bump"]
    assert sorted(HISTORY_FORMS) == ["constant", "ramp", "sine", "step"]
    cases = [(VARIATIONS, variation_of, {"level": 2.0, "amplitude": 0.5, "position": 0.05,
                                         "length": 0.1}, "level", "x", D),
             (HISTORY_FORMS, history_form_of, {"value": 2.0, "second": 0.5, "time": 3.0},
              "value", "t", (0.0, 10.0))]
    for registry, form_of, numbers, main, variable, domain in cases:
        for name, form in registry.items():
            spec = form.spec(numbers)
            found = form_of(spec)
            assert found is not None and found[0] == name
            assert set(found[1]) == {main, *form.uses}, name
            assert all(found[1][k] == pytest.approx(numbers[k]) for k in found[1]), name
            profile_from_spec(spec, field="f", variable=variable, domain=domain)  # valid
    # what no form shows stays a custom profile on screen
    for spec in (FAMILY_EXAMPLES["table"], FAMILY_EXAMPLES["expr"], FAMILY_EXAMPLES["ramp"],
                 {"kind": "sine", "mean": 1.0, "amplitude": 1.0, "wavelength": 1.0,
                  "phase": 0.5}, {"kind": "step", "values": [1.0, "a"], "breaks": [0.0]},
                 {"kind": "bump", "mean": 1.0}, {"kind": "nonsense"}, "text", None, True):
        assert variation_of(spec) is None
    for spec in (FAMILY_EXAMPLES["table"], {"kind": "ramp", "start": 1.0, "end": None,
                                            "duration": 1.0}, {"kind": "step"}, False):
        assert history_form_of(spec) is None


def test_a_bad_variable_name_is_refused_naming_the_field() -> None:
    with pytest.raises(ValueError, match=r"^coating\[0\]\.modulus: the variable name 'sin' "
                                         r"is not allowed"):
        profile_from_spec(1.0, field="coating[0].modulus", variable="sin", domain=D)


def test_profiles_expose_their_jumps_and_kinks():
    from core.profiles import profile_from_spec

    def history(spec):
        return profile_from_spec(spec, field="loading.force", variable="t",
                                 domain=(0.0, 365.0))

    step = history({"kind": "step", "values": [1.0, 3.0], "breaks": [3.3]})
    assert step.nonsmooth_points() == (3.3,)
    assert step.nonsmooth_points(4.0, 365.0) == ()
    assert history({"kind": "ramp", "start": 0, "end": 1, "duration": 7}
                   ).nonsmooth_points() == (7.0,)
    table = history({"kind": "table", "points": [[0, 0], [2, 1], [5, 1]],
                     "interpolation": "step"})
    assert table.nonsmooth_points() == (2.0, 5.0)
    assert history({"expr": "1 + heaviside(t - 10)"}).nonsmooth_points() == \
        pytest.approx((10.0,), abs=1e-9)
    assert history({"kind": "sine", "mean": 1, "amplitude": 1, "wavelength": 9}
                   ).nonsmooth_points() == ()


def test_an_uploaded_shape_table_beyond_the_solver_limit_is_refused_on_upload():
    """A 40-row shape table was accepted by the upload (10,000 rows allowed) and then
    always refused when the scene was built (16 kinks at most in a scene)."""
    from core.profiles import profile_from_csv
    rows = "x,f\n" + "".join(f"{-1 + 2 * k / 39:.6f},{1e-4 * (k % 2)}\n" for k in range(40))
    with pytest.raises(ValueError, match=rf"^punch\.shape: a table of 40 rows with 'linear' "
                                         rf".* more than the {limits.MAX_BREAKPOINTS} .*"
                                         "'pchip'"):
        profile_from_csv(rows, field="punch.shape", variable="x", domain=(-1.0, 1.0))
    smooth = profile_from_csv(rows, field="punch.shape", variable="x", domain=(-1.0, 1.0),
                              interpolation="pchip")
    d = elastic_dict()
    d["punch"]["shape"] = smooth.spec
    scene_from_dict(d)  # the solver's limit agrees: accepted
    # a load history in time has no such limit
    history = "t,f\n" + "".join(f"{k},{k % 2}\n" for k in range(40))
    profile_from_csv(history, field="loading.force", variable="t", domain=(0.0, 50.0))


def test_uploaded_tables_have_limits_and_clear_errors() -> None:
    domain = (-1.0, 1.0)

    def refused(data: bytes | str, match: str, **kwargs: Any) -> None:
        with pytest.raises(ValueError, match=match):
            profile_from_csv(data, field="punch.shape", domain=domain, **kwargs)

    refused(b"x,f\n" + b"0,0\n" * 300_000, r"^punch\.shape: file is too large \(1200004 bytes")
    rows = "".join(f"{k / 20000},{k}\n" for k in range(10_001))
    refused(rows, r"^punch\.shape: file has too many rows \(10001, at most 10000\)")
    refused(b"x,f\n0.1,1\n", r"^punch\.shape: file needs at least 2 data rows, has 1 ")
    refused(b"x,f\n0.1,1\n0.2,=cmd|' /C calc'!A0\n", r"^punch\.shape: line 3, column 2: "
                                                   r"\"=cmd\|' /C calc'!A0\" is not a number")
    refused(b"x,f\n0.2,1\n0.1,2\n", r"^punch\.shape: x values must be strictly increasing "
                                    r"\(line 3: 0\.1 after 0\.2\)")
    refused(b"x,f\n0.1,1\n0.2,nan\n", r"line 3, column 2: 'nan' is not a number")
    refused(b"x,f\n0.1,1\n0.2,1e999\n", r"line 3, column 2: '1e999' is out of range")
    refused(b"x,f\n0.1,1,3\n0.2,1,4\n", r"line 2: expected 2 columns")
    refused(b"\x00\x01binary", r"file is not text")
    refused(b"", r"file is empty")
    # a header with markup is skipped, not echoed
    table = profile_from_csv(b"<img src=x onerror=alert(1)>,f\n-0.5,0\n0.5,1e-5\n",
                             field="punch.shape", domain=domain)
    assert table.spec["points"] == [[-0.5, 0.0], [0.5, 1e-5]]
