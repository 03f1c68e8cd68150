"""
Height above a reference plane, without a calibration
=====================================================

The classical phase-to-height setup: decode the empty reference plane, two planes at known
heights above it, then an object on the plane; the height per pixel follows from the shift
of the projector coordinate against the reference, ``h = d / (a - c d)`` with ``a`` and
``c`` measured per pixel on the planes (:class:`~bistair.geometry.height.HeightModel`), as
``bistair height OBJECT --reference REF --plane P20:20 --plane P45:45`` does.
"""

import matplotlib.pyplot as plt
import numpy as np

import bistair
from bistair.geometry.height import HeightModel
from bistair.sim import Imaging, Plane, Scene, Sphere, expose, preset, trace

rig, _ = preset("plane", camera_size=(400, 320))
spec = bistair.make_spec("graycode", width=1920, height=1080, period=30, complementary=1,
                         gamma=2.2)
board = dict(size=(700, 600), albedo=0.8)
imaging = Imaging(read_noise=0.005, camera_blur=0.7, seed=2)


def coord(*surfaces):
    traced = trace(rig, Scene(list(surfaces)), imaging)
    result = bistair.decode(expose(traced, bistair.encode(spec), imaging), spec)
    return result.coord.astype(np.float64), traced.truth


reference, _ = coord(Plane(center=(0, 0, 600), **board))
planes = [coord(Plane(center=(0, 0, 600 - h), **board))[0] for h in (20, 45)]
model = HeightModel.fit(reference, planes, [20.0, 45.0])
obj, truth = coord(Sphere(center=(20, 10, 575), radius=40, albedo=0.6),
                   Plane(center=(0, 0, 600), **board))
height = model.height(obj)
error = height - (600.0 - truth.depth)
print(f"median error on the sphere {np.nanmedian(np.abs(error[truth.depth < 595])):.3f} mm")

fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), layout="constrained")
shown = axes[0].imshow(height, cmap="turbo")
fig.colorbar(shown, ax=axes[0], label="height above the plane (mm)")
shown = axes[1].imshow(error, cmap="coolwarm", vmin=-0.5, vmax=0.5)
fig.colorbar(shown, ax=axes[1], label="error (mm)")
for ax in axes:
    ax.set_axis_off()
plt.show()
