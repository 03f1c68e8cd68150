"""
A moving object: plain four-step against motion compensation
=============================================================

A stream whose phase shift advances one step per frame (frame ``i`` shows shift ``i mod 4``
of one four-step set, as high-speed rigs project), the sphere of sphere-on-plane moving
sideways 2 camera pixels per frame, every frame rendered at its own pose. The phase of one
window of four frames (plain four-step) takes a ripple at twice the fringe frequency;
binomial self-compensation of order 4 (:func:`bistair.core.motion.compensate`: five
overlapping windows averaged with the weights 1, 4, 6, 4, 1 / 16) removes most of it, at a
lag of 3.5 frames. Each is compared with the ray-traced truth at the time it describes
(frame 1.5 and frame 3.5); ``bistair decode FOLDER --window 4+4`` writes the same phases
for every window of a stream on disk.
"""

import matplotlib.pyplot as plt
import numpy as np

from bistair.app.simulate_motion import stream_patterns
from bistair.core.motion import compensate, window_phases
from bistair.core.phase import wrap
from bistair.sim import Imaging, preset
from bistair.sim.motion import parse_motion, render_moving, trace_frames

PERIOD, STEPS, ORDER = 60, 4, 4
rig, scene = preset("sphere-on-plane", camera_size=(320, 256))
imaging = Imaging(gamma=2.2, read_noise=0.01, camera_blur=1.0, seed=0)
spec, patterns = stream_patterns(rig.projector.size, gamma=2.2, steps=STEPS, period=PERIOD)
motion = parse_motion("2px")
count = STEPS + ORDER
frames, truths = render_moving(patterns[np.arange(count) % STEPS], rig, scene, motion, imaging)
phi, mod = window_phases(frames.astype(np.float32) / 255, STEPS)  # 8-bit camera
results = {"plain four-step": (phi[0], (STEPS - 1) / 2),
           f"order {ORDER}": (compensate(phi[:ORDER + 1], ORDER)[0], (STEPS + ORDER - 1) / 2)}

# the sphere's pixels at every frame used (its moving edge belongs to no one surface)
inside = np.logical_and.reduce([(t.object_id == 1) & t.mask for t in truths])
inside &= mod[0] > 0.05

fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), layout="constrained")
row = 128
for ax, (name, (phase, time)) in zip(axes, results.items(), strict=False):
    truth = trace_frames(rig, scene, motion, [time], imaging)[0].truth
    error = np.where(inside, wrap(phase - 2 * np.pi * truth.coord_x / PERIOD), np.nan)
    rms = float(np.sqrt(np.nanmean(error**2)))
    print(f"{name}: time {time:g}, phase error RMS on the sphere {rms:.4f} rad")
    shown = ax.imshow(error, cmap="coolwarm", vmin=-0.3, vmax=0.3)
    ax.set_title(f"{name} (time {time:g}): RMS {rms:.3f} rad")
    ax.axhline(row, color="k", lw=0.5)
    ax.set_axis_off()
    axes[2].plot(error[row], label=name)
fig.colorbar(shown, ax=axes[:2], label="phase error (rad)", shrink=0.8)
axes[2].set_xlabel("camera column")
axes[2].set_ylabel("phase error (rad)")
axes[2].set_title(f"along row {row}")
axes[2].legend()
plt.show()
