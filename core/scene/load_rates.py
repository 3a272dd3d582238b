"""How fast a given load history varies, against the time stepping's step limit.

A load that oscillates fast forces the time stepper (:mod:`core.time.integration`) to
take a few steps per period, however smooth the creep: a sine force of period 1 day
over a year took 8500 steps at tol 1e-6. Beyond the step limit
(:data:`core.limits.MAX_TIME_STEPS`) the stepping stops, after a minute of work, with
nothing to show. :func:`check_step_limit` refuses such a load *before* solving, naming
the field, from a lower bound of the steps its history needs.

Steps per period of a sine force on the uniform preset (``benchmarks``-style runs of
``core.scene.solve``, wavelength 5 days over 365 days): 3.8 at tol 1e-2, 9.5 at 1e-4,
23.3 at 1e-6, 48.7 at 1e-8; the same per period for wavelengths 1 to 20 days. That is
``3.8 (1e-2 / tol)^0.185`` for that relative amplitude (0.29). A smaller oscillation is
cheaper: the step count falls about as ``amplitude^(1/6)``, so a full-amplitude sine needs
``3.8 / 0.29^(1/6) = 4.7`` steps per period at tol 1e-2; the bound takes 3.0 of them
(about 2/3, for scenes that differ from the preset).

A design code's creep law (fib MC2010, Eurocode 2: a fitted kernel of tens of
exponentials, some fast) needs more: on the 50-year preset, sines of periods 30 to 365
days, relative amplitudes 0.09 to 0.33, tol 1e-2 to 1e-6, loaded at 7 to 365 days, read
10.8 to 43 steps per period in the same terms (full amplitude, tol 1e-2; the fewest: fib
MC2010 loaded at 365 days, a 30-day period); the bound takes 7 of them. With the
exponential law's 3.0 a 10-day sine over 50 years passed the check and ran ~28 s into the
step limit (~35 steps a period) before its refusal.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from core.profiles import Profile

#: Steps per period of a full-amplitude oscillation at tol 1e-2 (measured 4.7, about
#: 2/3 of it for a lower bound) and their growth with 1/tol (measured exponent 0.185
#: from 1e-2 to 1e-8).
STEPS_PER_PERIOD = 3.0
#: The same for a design code's creep law (measured at least 10.8; see the module notes).
CODE_STEPS_PER_PERIOD = 7.0
STEPS_GROWTH = 0.185
#: Samples of a formula history when counting its oscillations.
FORMULA_SAMPLES = 2**15 + 1


def oscillations(profile: Profile, lo: float, hi: float) -> float:
    """Periods of ``profile`` on ``[lo, hi]`` (unit of its variable): exact for a sine
    (none for a sine of amplitude 0, a constant: it was flagged ``undersampled_load``),
    half the number of extrema of the samples for a formula (a formula faster than the
    samples counts as at least a quarter of them), 0 for the other families (their
    jumps and kinks are counted by :func:`required_steps`)."""
    if profile.kind == "sine":
        if profile.spec["amplitude"] == 0:
            return 0.0
        return (hi - lo) / profile.spec["wavelength"]
    if profile.kind != "expr":
        return 0.0
    values = profile(np.linspace(lo, hi, FORMULA_SAMPLES))
    slope = np.sign(np.diff(values))
    slope = slope[slope != 0]
    extrema = int(np.count_nonzero(slope[1:] != slope[:-1]))
    return extrema / 2.0


def _relative_amplitude(profile: Profile) -> float:
    if profile.kind != "sine":
        return 1.0
    spec = profile.spec
    amplitude, mean = abs(spec["amplitude"]), abs(spec["mean"])
    return amplitude / (amplitude + mean) if amplitude > 0 else 0.0


def required_steps(profile: Profile, lo: float, hi: float, tol: float,
                   steps_per_period: float = STEPS_PER_PERIOD) -> float:
    """A lower bound of the time steps the history ``profile`` forces on ``[lo, hi]`` at
    the relative tolerance ``tol``: its periods times the steps one period needs
    (``steps_per_period`` at full amplitude and tol 1e-2: :data:`STEPS_PER_PERIOD`, or
    :data:`CODE_STEPS_PER_PERIOD` for a design code's law), plus one step per point where
    it jumps or kinks."""
    per_period = steps_per_period * (1e-2 / tol) ** STEPS_GROWTH
    periods = oscillations(profile, lo, hi)
    scaled = periods * per_period * _relative_amplitude(profile) ** (1 / 6)
    return scaled + len([b for b in profile.breakpoints if lo < b < hi])


def check_step_limit(loads: Mapping[str, Profile], lo: float, hi: float, tol: float,
                     max_steps: int, what: str = "the time stepping's limit",
                     steps_per_period: float = STEPS_PER_PERIOD) -> None:
    """Refuse a load history that needs more than ``max_steps`` time steps.

    ``loads`` maps field paths (``"loading.force"``) to histories in days; ``[lo, hi]`` is
    the solved time range [day], ``tol`` the solver's tolerance, ``steps_per_period`` as
    :func:`required_steps` takes it. Raises ValueError naming the field (``.wavelength``
    for a sine) and the cause.
    """
    for field, profile in loads.items():
        steps = required_steps(profile, lo, hi, tol, steps_per_period)
        if steps <= max_steps:
            continue
        periods = oscillations(profile, lo, hi)
        name = f"{field}.wavelength" if profile.kind == "sine" else field
        cause = (f"about {periods:.3g} oscillations over {hi - lo:g} days"
                 if periods else f"{len(profile.breakpoints)} jumps or kinks")
        raise ValueError(
            f"{name}: the load varies faster than the time stepping can follow: "
            f"{cause} need at least {steps:.3g} time steps at tol {tol:g}, more than "
            f"{what} of {max_steps}; use a slower or smoother load, fewer jumps, a "
            "shorter time range or a larger solver.tol")


#: Output times per period of an oscillating load below which its histories are
#: flagged: eight draw a sine recognisably and read its peaks within 1 - cos(pi/8) = 8 %
#: of its amplitude; at two (Nyquist's bound) a sine sampled at its zeros reads flat.
SAMPLES_PER_PERIOD = 8


def undersampled_loads(loads: Mapping[str, Profile], times: np.ndarray) -> list[str]:
    """The fields of ``loads`` (field paths to histories in days) that oscillate faster
    than the output ``times`` [day] sample them: a period (a sine's wavelength, a
    formula's mean period over the times) under :data:`SAMPLES_PER_PERIOD` times the
    widest spacing of the times.

    The answer is right at every output time (the time stepping follows the load), but
    drawn through them such a history is aliased, and the largest values read there (the
    design check's) can miss the load's peaks between them."""
    times = np.asarray(times, dtype=float)
    if times.size < 2:
        return []
    widest = float(np.max(np.diff(times)))
    out = []
    for field, profile in loads.items():
        periods = oscillations(profile, float(times[0]), float(times[-1]))
        period = (float(times[-1]) - float(times[0])) / periods if periods > 0 else math.inf
        if widest * SAMPLES_PER_PERIOD > period:
            out.append(field)
    return out
