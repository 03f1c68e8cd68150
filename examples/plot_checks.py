"""
A spec that does not fit is refused, never decoded into wrong numbers
=====================================================================

Decode captures of the Gray code with two of their code frames exchanged: the orders then
jump by whole blocks across the phase's wraps and the decode refuses them, naming the
likely cause. ``force=True`` (``--force`` on the command line) decodes anyway, the reasons
kept as warnings and in ``info["forced"]``: the blocks show where the code is misread.
"""

import matplotlib.pyplot as plt
import numpy as np

import bistair
from bistair.sim import Imaging, expose, preset, trace

rig, scene = preset("plane", camera_size=(400, 320))
spec = bistair.make_spec("graycode", width=1920, height=1080, period=30, gamma=2.2)
imaging = Imaging(read_noise=0.01, camera_blur=1.0, seed=0)
traced = trace(rig, scene, imaging)
captures = expose(traced, bistair.encode(spec), imaging)
swapped = captures.copy()
gray = [spec.frames.index(name) for name in ("gray-1", "gray-2")]
swapped[gray] = swapped[gray[::-1]]

try:
    bistair.decode(swapped, spec)
except bistair.BistairError as refusal:
    print(refusal)

forced = bistair.decode(swapped, spec, force=True)
right = bistair.decode(captures, spec)
print(forced.info["forced"])

fig, axes = plt.subplots(1, 2, figsize=(10, 3.4), layout="constrained")
for ax, result, title in ((axes[0], right, "the right frames"),
                          (axes[1], forced, "two code frames exchanged (forced)")):
    shown = ax.imshow(result.coord - traced.truth.coord_x, cmap="coolwarm", vmin=-300,
                      vmax=300)
    ax.set_title(title)
    ax.set_axis_off()
fig.colorbar(shown, ax=axes, label="error against the truth (projector px)")
plt.show()
print(f"forced: {100 * np.mean(np.abs(forced.coord - traced.truth.coord_x)[forced.mask] > 15):.0f}%"
      " of its pixels off by a fringe or more")
