"""
The bidirectional stair-phase code
==================================

Re-making the paper's figure of the coded pair: down the pattern, groups of rows alternate
between the local fringe-order stair (``k mod S``, one step every fringe) and the partition
stair (``k // S``, one step every ``S`` fringes). Every small region of the image holds both,
so ``k = k_s1 + S * k_s2`` is read from a few rows.
"""

import matplotlib.pyplot as plt
import numpy as np

import bistair

spec = bistair.make_spec("bidirectional", width=480, height=90, period=20, partitions=4,
                         stairs=6, group_rows=30, local_rows=20)
patterns = bistair.encode(spec)
names = spec.frames

fig, axes = plt.subplots(2, 3, figsize=(12, 4), layout="constrained")
for ax, image, name in zip(axes.ravel(), patterns, names, strict=True):
    ax.imshow(image, cmap="gray", vmin=0, vmax=1)
    ax.set_title(name)
    ax.set_axis_off()
plt.show()

# %%
# The stair phase of the pair (Eq. 19 of the paper) along a local row and a partition row:
# the local stair steps every fringe, the partition stair every six.
avg = patterns[:4].mean(axis=0)
theta = np.arctan2(patterns[5] - avg, patterns[4] - avg)
x = np.arange(spec.width)
fig, ax = plt.subplots(figsize=(10, 3), layout="constrained")
ax.plot(x, theta[5], label="local row (k mod S)")
ax.plot(x, theta[25], label="partition row (k // S)")
for edge in range(0, spec.width, int(spec.period)):
    ax.axvline(edge, color="0.85", lw=0.5, zorder=0)
ax.set_xlabel("projector column x (px)")
ax.set_ylabel("stair phase (rad)")
ax.legend(loc="lower right")
plt.show()

# %%
# Decoding the patterns themselves gives every projector column back.
result = bistair.decode(patterns, spec)
print(np.abs(result.coord - x).max(), result.order[45, ::20].tolist())
