"""
First solve: a flat punch on a coated layer
===========================================

Load a preset scene (SI units, time in days after loading), solve it, and draw the
contact pressure q(x) [Pa] under the punch at the last output time.
"""

from pathlib import Path

import matplotlib.pyplot as plt

import core

# the preset scenes of the checkout that holds this core
SCENES = Path(core.__file__).resolve().parents[1] / "assets" / "scenes"

result = core.solve(core.load_scene(SCENES / "uniform_flat.json"))
print(result.settlement[-1], result.info["error_estimate"], result.flags)

fig, ax = plt.subplots()
ax.plot(result.x, result.pressure(result.x)[:, -1] / 1e3)
ax.set_xlabel("x [m]")
ax.set_ylabel("q [kPa]")
plt.show()
