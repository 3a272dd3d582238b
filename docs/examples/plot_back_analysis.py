"""
Back-analysis: fit creep to two years of readings, forecast 50 years
====================================================================

A footing on young concrete (the preset ``young_concrete_50_years``) was levelled 30
times over its first two years. Which relative humidity and which age at loading explain
the readings, how well are they known, and where will the settlement be after 50
years? ``core.calibrate`` fits the scene fields by weighted least squares, gives their
standard errors and correlation, and ``forecast`` carries their uncertainty to any time
as a band.

The readings here are synthetic: the scene at 70 % humidity, loaded at 10 days, plus
noise. The footing settles only ~0.07 mm in two years (600 kN/m on 4 m of concrete),
so a 1 mm levelling noise would bury it; the readings are those of a displacement
transducer, 1 um (~1.5 % of the settlement).
"""

import matplotlib.pyplot as plt
import numpy as np

import core
from core.presets import read_preset
from core.study import apply_point

scene = read_preset("young_concrete_50_years")
truth = {"base.creep.relative_humidity": 70.0, "base.age_at_loading": 10.0}
times = np.linspace(730 / 30, 730, 30)
measured = core.solve(apply_point(scene, truth) | {"times": times.tolist()})
noise = 1e-6  # [m]
rng = np.random.default_rng(2026)
readings = {"time": times.tolist(),
            "settlement": (measured.settlement
                           + noise * rng.standard_normal(times.size)).tolist(),
            "settlement_std": noise}

# %%
# The fit starts from the preset's values (60 %, 7 days); the bounds keep the humidity
# physical.
fit = core.calibrate(scene, readings, fit=list(truth),
                     bounds={"base.creep.relative_humidity": (20.0, 100.0)})
print(fit.summary())

# %%
# The forecast to 50 years, with the 95 % band of the fitted fields' uncertainty
# (linearised: the delta method).
forecast = fit.forecast({"end": 18262.5, "count": 60, "spacing": "log"})
lower, upper = forecast.band("settlement")
shown = forecast.times > 0
fig, ax = plt.subplots(figsize=(6, 3.5))
ax.fill_between(forecast.times[shown], 1e3 * lower[shown], 1e3 * upper[shown],
                color="C0", alpha=0.25, label="95 % band")
ax.semilogx(forecast.times[shown], 1e3 * forecast.settlement[shown], color="C0",
            label="fitted scene")
ax.errorbar(times, 1e3 * np.array(readings["settlement"]), yerr=1e3 * noise, fmt=".",
            color="k", ms=3, label="readings")
ax.set_xlabel("time after loading [day]")
ax.set_ylabel("settlement [mm]")
ax.legend()
fig.tight_layout()
print(f"after 50 years: {1e3 * forecast.settlement[-1]:.4f} mm, 95 % band "
      f"[{1e3 * lower[-1]:.4f}, {1e3 * upper[-1]:.4f}] mm")
plt.show()
