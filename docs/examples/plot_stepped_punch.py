"""
A stepped punch: pressure with jumps
====================================

The middle 0.8 m of a punch base protrudes 15 micrometres (the preset
``stepped_punch``): the middle touches first and carries more of the load, and the
pressure jumps where the step is. The solver breaks its quadrature at the step's
declared breakpoints, so both sides of each jump are exact. The same scene without the
step is drawn for comparison.
"""

import json

import matplotlib.pyplot as plt
import numpy as np

import core
from core.presets import read_preset

spec = read_preset("stepped_punch")
print("punch shape:", json.dumps(spec["punch"]["shape"]))
stepped = core.solve(core.scene_from_dict(spec))
flat = core.solve(core.scene_from_dict({**spec, "punch": {**spec["punch"], "shape": 0.0}}))

a = stepped.scene.half_width
x = np.linspace(-a, a, 801)
fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(x, stepped.pressure(x)[:, -1] / 1e6, label="stepped punch")
ax.plot(x, flat.pressure(x)[:, -1] / 1e6, "--", label="flat punch, same loads")
ax.set_xlabel("x [m]")
ax.set_ylabel(f"q [MPa] at t = {stepped.times[-1]:g} d")
ax.legend()
fig.tight_layout()
print("error estimates:", f"{stepped.info['error_estimate']:.1e}",
      f"{flat.info['error_estimate']:.1e}")
plt.show()
