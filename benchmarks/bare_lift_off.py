"""Speed against error of a punch lifting off the bare base, against closed forms.

    OPENBLAS_NUM_THREADS=1 python -m benchmarks.bare_lift_off [--no-write]

Two scenes whose answers are known in closed form on a half-space, solved on a layer so
thick (``H = 1e4 a``, the thickest a scene takes; ``1000 m``, ``1.6e5 b``, for the crown)
that the layer's own correction, ``(a / H)^2`` (``(b / H)^2``), is ~1e-9 or less (the
heel's errors below are that correction: 1.3e-9, falling 100x for each tenfold ``H``,
tests/engines/test_bare_lift_off.py):

* *heel*: a flat punch (a = 1 m) under P at e = M / P = 0.75 a: the zone ``[c, a]`` with
  ``c = 4 e - 3 a``, the pressure ``P sqrt((x - c) / (a - x)) / (pi b)`` and the tilt
  ``2 M' / (pi b^2) / theta`` (``b`` the zone's half-width, ``M'`` the moment about its
  middle);
* *crown*: a parabolic punch of radius R = 1000 m under P = 1 kN/m (Hertz): the half-width
  ``b = sqrt(4 R P / (pi E*))`` and the elliptic pressure of peak ``2 P / (pi b)``.

For each tol: the median CPU time of ``core.solve`` [ms] (caches cleared before each
solve), the solver's estimate, the error of the zone's ends [half-widths of the punch],
of the pressure (largest relative error over the zone's inner 80 %) and of the tilt.

And the crown on a base that creeps (a standard linear solid, ``tests/support/
creep_laws.CREEP``, 8 output times to 365 days, ``H = 100 m``): its zone grows as the base
creeps (``core/engines/layered/bare_growing_zone.py``), against Lee and Radok's
hereditary integral by quadrature (``tests.support.creep_laws.lee_radok_pressure``): the
half-width ``b0 sqrt(E J(t))`` and the pressure at 40 points over the last zone, in
contact from the start or reached later (error relative to the largest pressure, over the
output times). One solve each (seconds).

And zones that only recede on that creeping base (``H = a``, 8 output times to 365
days): a flat punch under a constant force and a growing moment, a flat punch held at its
settlement under a constant moment, and a gently crowned one (R = 200 km) held at its
settlement while its tilt grows; against ``tests.support.creep_laws.receding_reference``
(Chebyshev collocation of ``(I - V)^-1`` with the exact kernel and elastic solves at tol
1e-10, apart from the solver's time grids): the largest error of the settlement and tilt
(relative to the larger of the two, as the estimate reads them) and of the force and
moment likewise, of q over ``|x| <= 0.9 a`` (relative to its largest there) and of the
zone ends [half-widths]. One solve each (seconds).

And a zone that recedes and grows again on that base (Ting's problem, marched step by
step): the flat punch under 500 kN/m as the moment rises from 300 to 400 kN m/m at 100
days and falls back by 365 (12 output times): up to the turn against the exact receding
path at tol 1e-6, over the whole history against the march at tol 1e-5 (answered whatever
its estimate); tighter than the march meets, the refusal and why.

Written to ``benchmarks/results/bare_lift_off.md`` unless ``--no-write``.
"""

from __future__ import annotations

import os
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from benchmarks import run_lines
from core.cache import clear_caches
from core.presets import read_preset
from core.scene import solve

TOLS = (1e-4, 1e-6, 1e-8, 1e-10)
SOLVES = 5
RESULTS = Path(__file__).resolve().parent / "results" / "bare_lift_off.md"
E, NU = 3.0e10, 0.2


def _scene(kind: str, tol: float) -> dict:
    d = read_preset("bare_layer")
    d["solver"] = {"tol": tol}
    d["base"]["thickness"] = 1e4 if kind == "heel" else 1000.0
    if kind == "heel":
        d["loading"] = {"force": 1e6, "moment": 0.75e6}
    else:
        d["punch"]["shape"] = {"kind": "polynomial", "coefficients": [0.0, 0.0, 0.5e-3]}
        d["loading"] = {"force": 1e3, "moment": 0.0}
    return d


def _errors(kind: str, result) -> tuple[float, float, float]:
    """Errors of the zone's ends [half-widths], the pressure and the tilt [relative]."""
    (lo, hi), = result.contact_set[0]
    theta = E / (2 * (1 - NU**2))
    if kind == "heel":
        p, e = 1e6, 0.75
        c = 4 * e - 3
        b, x0 = (1 - c) / 2, (1 + c) / 2
        ends = max(abs(lo - c), abs(hi - 1.0))
        x = c + (1 - c) * np.linspace(0.1, 0.9, 17)
        exact = p * np.sqrt((x - c) / (1 - x)) / (np.pi * b)
        tilt = 2 * p * (e - x0) / (np.pi * b**2) / theta
        tilt_error = abs(float(result.tilt[0]) / tilt - 1)
    else:
        p, radius = 1e3, 1000.0
        b = np.sqrt(4 * radius * p / (np.pi * E / (1 - NU**2)))
        ends = max(abs(lo + b), abs(hi - b))
        x = b * np.linspace(-0.8, 0.8, 17)
        exact = 2 * p / (np.pi * b) * np.sqrt(1 - (x / b) ** 2)
        tilt_error = float("nan")  # centred: no tilt
    pressure = float(np.max(np.abs(result.pressure(x)[:, 0] / exact - 1)))
    return ends, pressure, tilt_error


def measure() -> list[tuple]:
    rows = []
    for kind in ("heel", "crown"):
        for tol in TOLS:
            cpu = []
            for _ in range(SOLVES):
                clear_caches()
                started = time.process_time()
                result = solve(_scene(kind, tol))
                cpu.append(time.process_time() - started)
            ends, pressure, tilt = _errors(kind, result)
            rows.append((kind, tol, 1e3 * float(np.median(cpu)),
                         float(result.info["error_estimate"]),
                         float(result.info["zone_end_error"]), ends, pressure, tilt,
                         bool(result.info["success"])))
    return rows


CREEP_TOLS = (1e-3, 1e-4, 1e-5)


def measure_creeping() -> list[tuple]:
    """(tol, CPU [s], time steps, estimate, half-width error, q error, success) of the
    crown growing on the creeping layer (module docstring)."""
    from tests.support.creep_laws import CREEP, laws, lee_radok_pressure

    radius, force = 1000.0, 1e3
    rows = []
    for tol in CREEP_TOLS:
        d = _scene("crown", tol)
        d["base"]["thickness"] = 100.0
        d["base"]["creep"] = dict(CREEP)
        d["times"] = {"end": 365.0, "count": 8, "spacing": "log"}
        clear_caches()
        started = time.process_time()
        result = solve(d)
        cpu = time.process_time() - started
        growth, _ = laws(result.times)
        b0 = np.sqrt(4 * radius * force / (np.pi * E / (1 - NU**2)))
        b = np.array([zones[0][1] for zones in result.contact_set])
        width = float(np.max(np.abs(b / (b0 * np.sqrt(growth / growth[0])) - 1)))
        x = b0 * np.linspace(0.0, 1.37, 40)
        exact = lee_radok_pressure(x, result.times, b0, 2 * force / (np.pi * b0))
        q = float(np.max(np.abs(result.pressure(x) - exact)) / np.max(np.abs(exact)))
        rows.append((tol, cpu, int(result.info["n_steps"]),
                     float(result.info["error_estimate"]), width, q,
                     bool(result.info["success"])))
    return rows


RECEDING_TOLS = (1e-4, 1e-6, 1e-8)
#: The receding cases: name, given loads, crown radius [m] (None: flat).
RECEDING = (
    ("flat, force and a growing moment",
     {"force": 5e5, "moment": {"kind": "linear", "start": 3e5, "end": 4e5}}, None),
    ("flat, settlement held, constant moment", {"settlement": 1e-5, "moment": 3e5}, None),
    ("crown R = 200 km, settlement held, growing tilt",
     {"settlement": 1e-5, "tilt": {"kind": "linear", "start": 2e-5, "end": 3e-5}}, 2e5),
)


def measure_receding() -> list[tuple]:
    """(case, tol, CPU [s], time steps, estimate, histories error, q error, zone-end
    error, success) of the zones that only recede (module docstring)."""
    from tests.support.creep_laws import CREEP, receding_errors

    rows = []
    for name, loading, radius in RECEDING:
        for tol in RECEDING_TOLS:
            d = read_preset("bare_layer")
            d["loading"] = dict(loading)
            d["solver"] = {"tol": tol}
            d["base"]["creep"] = dict(CREEP)
            d["times"] = {"end": 365.0, "count": 8, "spacing": "log"}
            if radius is not None:
                d["punch"]["shape"] = {"kind": "polynomial",
                                       "coefficients": [0.0, 0.0, 0.5 / radius]}
            clear_caches()
            started = time.process_time()
            result = solve(d)
            cpu = time.process_time() - started
            errors = receding_errors(result)
            rows.append((name, tol, cpu, int(result.info["n_steps"]),
                         float(result.info["error_estimate"]), errors["histories"],
                         errors["q"], errors["ends"],
                         bool(result.info["success"])))
    return rows


#: The turning zone's tolerances (the march meets 1e-3 on this heel; at 5e-4 the zones' own
#: estimate is over half of tol and the turn is refused).
TURNING_TOLS = (3e-3, 1e-3, 5e-4)
#: Its reference: the march itself at this tol, answered whatever its estimate.
TURNING_REFERENCE_TOL = 1e-5


def measure_turning() -> list[tuple]:
    """(tol, CPU [s], time steps, estimate, zone-end estimate, errors up to the turn against
    the exact receding path (histories, ends), errors over the whole history against the
    march at :data:`TURNING_REFERENCE_TOL` (histories, ends, q on |x| <= 0.9 a), outcome) of
    the zone that recedes and grows again, marched step by step."""
    from core.engines.layered.bare_growing_zone import solve_growing_zone
    from tests.support.creep_laws import growing_zone_calls, turning_scene

    rows = []
    for tol in TURNING_TOLS:
        clear_caches()
        with growing_zone_calls() as seen:
            started = time.process_time()
            try:
                result = solve(turning_scene(tol))
            except ValueError as refused:
                cpu = time.process_time() - started
                reason = str(refused).split("followed step by step, ")[-1].split(" (it")[0]
                rows.append((tol, cpu) + (np.nan,) * 8 + (f"refused: {reason}",))
                continue
            cpu = time.process_time() - started
        ours = seen["answer"]
        before = [float(t) for t in result.times if t <= 100.0]
        exact = solve(turning_scene(1e-6, before))
        k = len(before)
        hist_turn = max(np.max(np.abs(getattr(result, n)[:k] - getattr(exact, n)))
                        / np.max(np.abs(getattr(exact, n))) for n in ("settlement", "tilt"))
        ends_turn = np.max(np.abs(np.array([z[0][0] for z in result.contact_set[:k]])
                                  - np.array([z[0][0] for z in exact.contact_set])))
        args = list(seen["args"])
        args[8] = TURNING_REFERENCE_TOL
        fine = solve_growing_zone(*args, march=True)
        hist = max(np.max(np.abs(ours.histories[n] - fine.histories[n]))
                   / np.max(np.abs(fine.histories[n])) for n in ("settlement", "tilt"))
        ends = np.max(np.abs(np.array([z[0] for z in ours.zones])
                             - np.array([z[0] for z in fine.zones])))
        x = np.linspace(-0.9, 0.9, 37)
        q_fine = fine.pressure(x, args[9])
        q = np.max(np.abs(ours.pressure(x, args[9]) - q_fine)) / np.max(np.abs(q_fine))
        rows.append((tol, cpu, int(result.info["n_steps"]),
                     float(result.info["error_estimate"]),
                     float(result.info["zone_end_error"]), hist_turn, ends_turn, hist, ends,
                     q, "success" if result.info["success"] else "tol not met"))
    return rows


def main(argv: list[str]) -> None:
    started = datetime.now(timezone.utc)
    before = os.getloadavg()[0]
    rows = measure()
    creeping = measure_creeping()
    receding = measure_receding()
    turning = measure_turning()
    after = os.getloadavg()[0]
    lines = ["# A punch lifting off the bare base: speed against error", "",
             "    OPENBLAS_NUM_THREADS=1 python -m benchmarks.bare_lift_off", "",
             *run_lines(started, before, after, "CPU times move little with the load"),
             "- a layer 1e4 a (heel) or 1.6e5 b (crown) thick against the half-space's closed "
             "forms (module docstring); caches cleared before each solve, medians of "
             f"{SOLVES}", "",
             "| scene | tol | CPU [ms] | estimate | zone-end estimate | zone-end error | "
             "q error | tilt error | success |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for kind, tol, ms, est, end_est, ends, q, tilt, ok in rows:
        lines.append(f"| {kind} | {tol:.0e} | {ms:.1f} | {est:.1e} | {end_est:.1e} | "
                     f"{ends:.1e} | {q:.1e} | {'' if np.isnan(tilt) else f'{tilt:.1e}'} | "
                     f"{'yes' if ok else 'no'} |")
    lines += ["", "## The crown on a creeping layer (its zone grows)", "",
              "Against Lee and Radok's hereditary integral (module docstring); one solve "
              "each.", "",
              "| tol | CPU [s] | time steps | estimate | half-width error | q error | "
              "success |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for tol, seconds, steps, est, width, q, ok in creeping:
        lines.append(f"| {tol:.0e} | {seconds:.1f} | {steps} | {est:.1e} | {width:.1e} | "
                     f"{q:.1e} | {'yes' if ok else 'no'} |")
    lines += ["", "## Zones that only recede on a creeping layer", "",
              "Against an answer computed apart from the solver's time grids (module "
              "docstring); one solve each; errors relative, the zone ends' in half-widths.",
              "", "| case | tol | CPU [s] | time steps | estimate | histories error | "
              "q error | zone-end error | success |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for name, tol, seconds, steps, est, hist, q, ends, ok in receding:
        lines.append(f"| {name} | {tol:.0e} | {seconds:.1f} | {steps} | {est:.1e} | "
                     f"{hist:.1e} | {q:.1e} | {ends:.1e} | {'yes' if ok else 'no'} |")
    lines += ["", "## A zone that recedes and grows again on a creeping layer (marched)", "",
              "The heel under 500 kN/m as the moment rises from 300 to 400 kN m/m at 100 "
              "days and falls back by 365 (`measure_turning`): up to the turn against the "
              "exact receding path (tol 1e-6), over the whole history against the march at "
              f"tol {TURNING_REFERENCE_TOL:.0e} (answered whatever its estimate); caches "
              "cleared, one solve each; errors relative, the zone ends' in half-widths.", "",
              "| tol | CPU [s] | time steps | estimate | zone-end estimate | to the turn: "
              "histories | ends | whole: histories | ends | q | outcome |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for tol, seconds, steps, est, end_est, hist_turn, ends_turn, hist, ends, q, outcome \
            in turning:
        if np.isnan(est):
            lines.append(f"| {tol:.0e} | {seconds:.1f} |  |  |  |  |  |  |  |  | {outcome} |")
            continue
        lines.append(f"| {tol:.0e} | {seconds:.1f} | {steps} | {est:.1e} | {end_est:.1e} | "
                     f"{hist_turn:.1e} | {ends_turn:.1e} | {hist:.1e} | {ends:.1e} | "
                     f"{q:.1e} | {outcome} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if "--no-write" not in argv:
        RESULTS.write_text(text)
        print(f"written: {RESULTS}")


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    main(sys.argv[1:])
