"""
Design codes' creep: reproducing a published coefficient
========================================================

The creep coefficient phi(t, t0) [-] of concrete C30/37, normal cement, relative
humidity 60 %, notional size 300 mm, loaded at 28 days, by the fib Model Code 2010 and
by EN 1992-1-1 Annex B (``core.creep_coefficient_curve``: the codes' formulas, clause by
clause). EN 1992-1-1 Figure 3.1 reads about 2.0 for this concrete after 50 years
(between its inside and outside curves); the test suite checks both values by hand,
formula by formula.
"""

import matplotlib.pyplot as plt
import numpy as np

import core

concrete = {"strength_class": "C30/37", "cement": "N", "relative_humidity": 60,
            "notional_size": 300}
durations = np.geomspace(0.1, 18262.5, 200)  # [day] after loading, up to 50 years

fig, ax = plt.subplots(figsize=(6, 3.5))
for model, label in (("fib_mc2010", "fib Model Code 2010"),
                     ("eurocode2", "EN 1992-1-1, Annex B")):
    phi = core.creep_coefficient_curve({"model": model, **concrete}, 28.0, durations)
    ax.semilogx(durations, phi, label=label)
    print(f"{label}: phi(28 d + 50 years, 28 d) = {phi[-1]:.3f}")
ax.set_xlabel("load duration t - t0 [day]")
ax.set_ylabel("creep coefficient phi [-]")
ax.legend()
fig.tight_layout()
plt.show()
