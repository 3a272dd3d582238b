"""
Eccentric load: the heel lifts off
==================================

A strip footing loaded 0.6 m off its centre (the preset ``eccentric_footing_liftoff``):
in full contact the pressure would turn negative under the heel, so the solver answers
the unilateral problem (q >= 0, an unknown contact zone) instead. As the concrete
creeps, the zone in contact grows and the peak under the toe rises.
"""


import matplotlib.pyplot as plt
import numpy as np

import core

result = core.solve(core.load_scene("preset:eccentric_footing_liftoff"))
print("contact model:", result.info["contact"], "| flags:", result.flags)
for k in (0, len(result.times) - 1):
    (start, end), = result.contact_set[k]
    print(f"t = {result.times[k]:7.1f} d: in contact on [{start:.3f}, {end:.3f}] m, "
          f"{end - start:.2f} m of {2 * result.scene.half_width:.0f} m")

# %%
# The pressure at loading and at the output times nearest 30 and 150 days and the
# last; the contact zone's start is marked on the axis.
x = np.linspace(-result.scene.half_width, result.scene.half_width, 401)
q = result.pressure(x)
shown = [0, *(int(np.argmin(abs(result.times - t))) for t in (30, 150)), len(result.times) - 1]
fig, ax = plt.subplots(figsize=(6, 3.5))
for k in shown:
    line, = ax.plot(x, q[:, k] / 1e6, label=f"t = {result.times[k]:.0f} d")
    ax.plot(result.contact_set[k][0][0], 0, "|", ms=14, color=line.get_color())
ax.set_xlabel("x [m]")
ax.set_ylabel("contact pressure q [MPa]")
ax.legend()
fig.tight_layout()
plt.show()
