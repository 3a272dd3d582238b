"""
A parameter sweep: eccentricity against tilt and contact
========================================================

Solve the lift-off footing at loading for a range of eccentricities e = M/P [m], one
scene each (a few seconds in one process; a large study would run on Dask with
``core.sweep``, see the researcher's guide). The tilt alpha [rad] grows linearly while
the whole base is in contact, and faster once the heel lifts off; the width in contact
falls from the full 2 m.
"""


import matplotlib.pyplot as plt
import numpy as np

import core
from core.presets import read_preset

spec = read_preset("eccentric_footing_liftoff")
spec["times"] = {"end": 1.0, "count": 1, "spacing": "linear"}  # the first day only
force = spec["loading"]["force"]  # [N/m]

eccentricities = np.linspace(0.0, 0.8, 17)
tilt, width = [], []
for e in eccentricities:
    spec["loading"]["moment"] = force * e  # [N·m/m]
    result = core.solve(core.scene_from_dict(spec))
    tilt.append(result.tilt[0])
    width.append(sum(end - start for start, end in result.contact_set[0]))

full = 2 * result.scene.half_width
first_lift = eccentricities[np.argmax(np.array(width) < full - 1e-9)]
print(f"the heel lifts off by e = {first_lift:.2f} m (the first of these e with less than "
      f"the full {full:.0f} m in contact)")

fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6, 5))
ax1.plot(eccentricities, np.array(tilt) * 1e3, "o-")
ax1.set_ylabel("tilt [mrad]")
ax2.plot(eccentricities, width, "o-")
ax2.set_ylabel("width in contact [m]")
ax2.set_xlabel("eccentricity e = M/P [m]")
fig.tight_layout()
plt.show()
