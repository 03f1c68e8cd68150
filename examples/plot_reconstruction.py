"""
From captures to points
=======================

Decode a scene of the virtual rig and triangulate it with the rig's calibration
(:class:`~bistair.geometry.calibration.Calibration`, ``X_p = R X_c + T`` in mm; here the
exact one, ``Calibration.from_rig``): a depth map and a point cloud, against the
ray-traced depth.
"""

import matplotlib.pyplot as plt
import numpy as np

import bistair
from bistair.geometry.calibration import Calibration
from bistair.geometry.triangulate import reconstruct
from bistair.sim import Imaging, expose, preset, trace

rig, scene = preset("sphere-on-plane", camera_size=(400, 320))
calibration = Calibration.from_rig(rig)
spec = bistair.make_spec("bidirectional", width=1920, height=1080, period=30, partitions=8,
                         stairs=8, gamma=2.2, white=1)
imaging = Imaging(read_noise=0.01, camera_blur=1.0, seed=2)
traced = trace(rig, scene, imaging)
result = bistair.decode(expose(traced, bistair.encode(spec), imaging), spec)
rec = reconstruct(result, calibration, spec)

truth = traced.truth.depth
both = np.isfinite(rec.depth) & traced.truth.mask
error = (rec.depth - truth)[both]
print(f"{int(both.sum())} points; depth error median {np.median(np.abs(error)):.3f} mm, "
      f"99th percentile {np.percentile(np.abs(error), 99):.3f} mm")

fig = plt.figure(figsize=(12, 4), layout="constrained")
ax = fig.add_subplot(1, 3, 1)
shown = ax.imshow(rec.depth, cmap="turbo")
fig.colorbar(shown, ax=ax, label="depth z (mm)")
ax.set_title("depth map")
ax.set_axis_off()
ax = fig.add_subplot(1, 3, 2)
shown = ax.imshow(rec.depth - truth, cmap="coolwarm", vmin=-0.5, vmax=0.5)
fig.colorbar(shown, ax=ax, label="mm")
ax.set_title("depth minus the truth")
ax.set_axis_off()
points, colors = rec.cloud()
ax = fig.add_subplot(1, 3, 3, projection="3d")
step = slice(None, None, 17)
ax.scatter(points[step, 0], points[step, 2], -points[step, 1], c=colors[step] / 255.0, s=1)
ax.set_xlabel("x (mm)")
ax.set_ylabel("z (mm)")
ax.set_zlabel("-y (mm)")
ax.set_title("point cloud")
plt.show()
