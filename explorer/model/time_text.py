"""Times after loading as the page writes them: positional digits, never an exponent.

A history over decades reaches 18262.5 days; ``f"{t:.4g}"`` wrote that "1.826e+04", which
an engineer has to decode. Here it reads "18260 days (50.0 years)": four significant
digits written out (the report's numbers do the same, ``core.report``), and the years
beside the days once the span is long enough for years to be the natural reading.
"""

from __future__ import annotations

import math

from core.scene import number_text

#: [day] per year (the Julian year: 50 years of loading are 18262.5 days).
DAYS_PER_YEAR = 365.25

#: From this time on [day] the years are written beside the days: below two years the
#: days are the natural reading (28 days, 365 days), beyond it the years.
YEARS_FROM_DAYS = 2 * DAYS_PER_YEAR


def days_text(t: float, digits: int = 4) -> str:
    """A time ``t`` [day] after loading in words: "28 days", "1 day", "18260 days (50.0
    years)"."""
    shown = number_text(t, digits)
    text = f"{shown} {'day' if shown == '1' else 'days'}"
    if math.isfinite(t) and abs(t) >= YEARS_FROM_DAYS:
        text += f" ({t / DAYS_PER_YEAR:.1f} years)"
    return text
