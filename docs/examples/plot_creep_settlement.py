"""
Creep: settlement of a footing over 50 years
============================================

A footing on concrete loaded one week after casting, its creep by the fib Model Code
2010 (the preset ``young_concrete_50_years``). The settlement delta(t) [m] grows as the
concrete creeps and, still young, hardens: fastest in the first weeks, which a log
time axis shows best.
"""


import matplotlib.pyplot as plt

import core
from core.presets import read_preset

spec = read_preset("young_concrete_50_years")
creeping = core.solve(core.scene_from_dict(spec))
print(creeping.scene.name, "| flags:", creeping.flags,
      "| error estimate:", f"{creeping.info['error_estimate']:.1e}")

# %%
# The first output time is the loading instant (t = 0), left out of the log axis.
times = creeping.times[creeping.times > 0]
growth = creeping.settlement[-1] / creeping.settlement[0]
print(f"settlement at loading {creeping.settlement[0] * 1e3:.3f} mm, after 50 years "
      f"{creeping.settlement[-1] * 1e3:.3f} mm (x{growth:.2f})")

fig, ax = plt.subplots(figsize=(6, 3.5))
ax.semilogx(times, creeping.settlement[creeping.times > 0] * 1e3)
ax.axhline(creeping.settlement[0] * 1e3, color="0.6", ls="--", label="at loading")
ax.set_xlabel("time after loading [day]")
ax.set_ylabel("settlement [mm]")
ax.legend()
fig.tight_layout()
plt.show()
