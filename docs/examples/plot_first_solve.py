"""
First solve: a flat punch on a coated slab
==========================================

Load a preset scene (SI units, time in days after loading), solve it, read the answer
with its error estimate and validity flags, and draw the contact pressure q(x) [Pa]
under the punch at loading and at the last output time.
"""


import matplotlib.pyplot as plt

import core

# the preset scenes of the checkout this core comes from

scene = core.load_scene("preset:uniform_flat")
result = core.solve(scene)

print(f"settlement at loading {result.settlement[0] * 1e3:.4f} mm, "
      f"after {result.times[-1]:g} days {result.settlement[-1] * 1e3:.4f} mm")
print(f"tilt {result.tilt[-1]:.2e} rad, error estimate {result.info['error_estimate']:.1e}, "
      f"flags {result.flags}")

# %%
# ``result.pressure(x)`` has one column per output time; ``result.x`` is a grid over
# the punch [m], refined toward its edges, where the pressure is largest.
q = result.pressure(result.x)

fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(result.x, q[:, 0] / 1e3, label=f"at loading (t = {result.times[0]:g} d)")
ax.plot(result.x, q[:, -1] / 1e3, label=f"t = {result.times[-1]:g} d")
ax.set_xlabel("x [m]")
ax.set_ylabel("contact pressure q [kPa]")
ax.set_title(scene.name)
ax.legend()
fig.tight_layout()
plt.show()
