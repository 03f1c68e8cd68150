"""
A first decode without a projector
==================================

Make the bidirectional stair-phase patterns of a 1920 x 1080 projector, render what a
camera of the virtual rig sees of them on the paper's scene (a mask and three small
objects), decode the captures and compare the projector columns with the truth.
"""

import matplotlib.pyplot as plt
import numpy as np

import bistair
from bistair.sim import Imaging, expose, preset, trace

rig, scene = preset("paper-sim", camera_size=(480, 384))
spec = bistair.make_spec("bidirectional", width=rig.projector.width,
                         height=rig.projector.height, period=30, gamma=2.2)
print(spec.frames)  # four phase shifts and the stair pair

imaging = Imaging(read_noise=0.01, camera_blur=1.0, seed=0)
traced = trace(rig, scene, imaging)  # rays once; any patterns exposed on them
captures = expose(traced, bistair.encode(spec), imaging)
result = bistair.decode(captures, spec)

truth = traced.truth.coord_x
both = result.mask & traced.truth.mask
wrong = np.abs(result.coord - truth)[both] > spec.period / 2
print(f"{100 * result.mask.mean():.1f}% of the pixels decoded, "
      f"{100 * wrong.mean():.3f}% of them off the truth by more than half a period")

fig, axes = plt.subplots(1, 3, figsize=(12, 3.4), layout="constrained")
axes[0].imshow(captures[0], cmap="gray")
axes[0].set_title("a capture (shift-0)")
im = axes[1].imshow(result.coord, cmap="viridis")
axes[1].set_title("projector column")
fig.colorbar(im, ax=axes[1], label="projector px")
im = axes[2].imshow(result.coord - truth, cmap="coolwarm", vmin=-0.5, vmax=0.5)
axes[2].set_title("error against the truth")
fig.colorbar(im, ax=axes[2], label="projector px")
for ax in axes:
    ax.set_axis_off()
plt.show()
