"""A run of the creep march's rule selection again, from the band width an earlier run
chose, starts from that run's rule (core.contact.creep._select_rule).

Its first candidate was built on the scene's base whatever width it started from, where
the earlier run's rule of that width was on a halved one: a heel lifting off under strong
creep (C = 1e-9 /Pa, tol 1e-6) was answered on panels twice as wide at the toe as the
rule the first run had checked, q at x = +a 1.5e-6 off (against a reference graded four
times finer there) with an estimate of 2.2e-7, success True. With the fix the answer is
the first run's rule (1168 nodes) and q at the toe is 3.9e-7 off (a researcher's audit:
a flat punch 2 m wide, 15 mm of coating at 400 MPa, 6 m of base at 30 GPa with C 1e-9
/Pa and rate 0.05 /day, 800 kN/m and 500 kN m/m, 20 times to 1000 days). That solve takes
14 s of CPU, so the logic is held here on a stand-in of the marches."""

from __future__ import annotations

import numpy as np

from core.contact.bands import BAND_WIDTHS
from core.contact.creep import _select_rule


class _Marches:
    """Records the rules built; every check passes at once."""

    def __init__(self) -> None:
        self.built: list[tuple[object, float]] = []

    def rule(self, res, bands, width):
        self.built.append((res, width))
        return (res, width)

    @staticmethod
    def halved(res):
        return ("halved", res)

    @staticmethod
    def banded(bands) -> bool:
        return bool(bands)

    @staticmethod
    def nodes(rule) -> int:
        return 16

    def run(self, rule, grid, widths, index, exact_ends=True, first=None):
        return {}, {}

    @staticmethod
    def rule_distance(rule, out, finer, finer_out, bands):
        return 0.0, 0.0


def _first_rules(bands, start_width):
    marches = _Marches()
    _select_rule(marches, np.array([1.0, 2.0, 5.0]), "res", 4, 1e-6, 1e-6, bands=bands,
                 start_width=start_width)
    return marches.built[:2]


def test_a_first_run_starts_on_the_scenes_base():
    assert _first_rules([(0.4, 0.5)], BAND_WIDTHS[0]) == [
        ("res", BAND_WIDTHS[0]), (("halved", "res"), BAND_WIDTHS[0] / 2)]


def test_a_run_again_with_bands_starts_on_the_halved_base_as_the_first_run_chose():
    # the first run's rules after its first candidate were all on the halved base, their
    # checks too (with bands the base is halved once, the bands' panels then)
    width = BAND_WIDTHS[2]
    assert _first_rules([(0.4, 0.5)], width) == [
        (("halved", "res"), width), (("halved", "res"), width / 2)]


def test_a_run_again_without_bands_starts_on_the_base_halved_once_per_step():
    width = BAND_WIDTHS[2]          # two steps from the first width
    assert _first_rules([], width) == [
        (("halved", ("halved", "res")), width),
        (("halved", ("halved", ("halved", "res"))), width / 2)]


class _Converging(_Marches):
    """The checks fail until the candidate's band width is ``enough``."""

    def __init__(self, enough: float) -> None:
        super().__init__()
        self.enough = enough

    def rule_distance(self, rule, out, finer, finer_out, bands):
        return (1.0, 1.0) if rule[1] > self.enough * (1 + 1e-9) else (0.0, 0.0)


def test_a_run_again_starts_from_the_rule_the_first_run_chose():
    # what the module's docstring says, end to end: the first run halves its band width
    # until its check passes; a run from the width it chose starts from the same rule
    for bands in ([(0.4, 0.5)], []):
        first = _Converging(BAND_WIDTHS[2])
        chosen, _, _, note = _select_rule(first, np.array([1.0, 2.0, 5.0]), "res", 4, 1e-6,
                                          1e-6, bands=bands)
        assert note["width"] == BAND_WIDTHS[2] and chosen[1] == BAND_WIDTHS[2]
        again = _Converging(BAND_WIDTHS[2])
        rerun, *_ = _select_rule(again, np.array([1.0, 2.0, 5.0]), "res", 4, 1e-6, 1e-6,
                                 bands=bands, start_width=note["width"])
        assert again.built[0] == chosen and rerun == chosen, bands


def test_a_near_miss_of_tol_is_mended_by_the_time_grids_not_refused():
    """Each part of the estimate met its own budget and their sum (with q's residue at
    the free ends) missed: a force stepping down into lift-off on an exponential kernel
    was refused at tol 1e-6, 3 x 3.44e-7 over it, its answer 1.2e-7 off (a researcher's
    audit). The time grids are now asked for the shortfall too: success, estimate 2.0e-7,
    against a tol 1e-8 answer q 7.9e-9, settlement 1.0e-7 and tilt 3.2e-7 off (of their
    largest values; 2.8 s of CPU against 2.0 for the refusal)."""
    from core import solve
    from tests.conftest import scene_file

    scene = scene_file("eccentric_creep")  # its base given an exponential law
    scene["base"]["creep"] = {"model": "exponential", "modulus": 3e10, "compliance": 3e-11,
                              "rate": 0.05}
    scene["loading"] = {"force": {"kind": "step", "values": [8e5, 2e5], "breaks": [10.0]},
                        "moment": {"kind": "step", "values": [1.2e5, 1.4e5], "breaks": [10.0]}}
    scene["times"] = [0, 0.5, 1, 9.99, 10, 10.01, 10.5, 20, 100, 1000, 10000]
    info = solve(scene).info
    assert info["contact"] == "unilateral" and info["success"], info["message"]
    assert 3 * info["error_estimate"] <= 1e-6
