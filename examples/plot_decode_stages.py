"""
The stages of a decode
======================

OpenCV's structured-light decoders expose their stages (``computePhaseMap``,
``computeFloorMap``); so does every bistair codec: stage 1 the wrapped phase
(:meth:`~bistair.codecs.Codec.phase_map`), stage 2 the code word per pixel
(:meth:`~bistair.codecs.Codec.code_map`: for the bidirectional code, the quantised stair
phase ``k_s``), stage 3 the fringe order and the absolute phase
(:meth:`~bistair.codecs.Codec.decode`). Here on the sphere-on-plane scene of the virtual rig.
"""

import matplotlib.pyplot as plt

import bistair
from bistair.codecs import get_codec
from bistair.sim import Imaging, expose, preset, trace

rig, scene = preset("sphere-on-plane", camera_size=(400, 320))
spec = bistair.make_spec("bidirectional", width=1920, height=1080, period=30, partitions=8,
                         stairs=8, gamma=2.2)
imaging = Imaging(read_noise=0.01, camera_blur=1.0, seed=1)
captures = expose(trace(rig, scene, imaging), bistair.encode(spec), imaging)

codec = get_codec("bidirectional")
fringes = codec.phase_map(captures, spec)  # stage 1
code = codec.code_map(captures, spec)  # stage 2
result = codec.decode(captures, spec)  # all three stages

panels = [(fringes.phi, "wrapped phase (rad)", "twilight"),
          (code.maps["stair_phase"], "stair phase (rad)", "twilight"),
          (code.code, "stair level k_s", "tab10"),
          (result.order, "fringe order k", "nipy_spectral"),
          (result.phase, "absolute phase (rad)", "viridis"),
          (result.modulation, "modulation (full scale)", "gray")]
fig, axes = plt.subplots(2, 3, figsize=(12, 6.2), layout="constrained")
for ax, (image, label, cmap) in zip(axes.ravel(), panels, strict=True):
    shown = ax.imshow(image, cmap=cmap)
    fig.colorbar(shown, ax=ax, shrink=0.8, label=label)
    ax.set_axis_off()
plt.show()
print(result.info["regions"], "fringe regions,", result.info["jump_violations"], "of",
      result.info["jump_links"], "links across the phase jumps not stepping by one")
