"""
A real Gray code capture: OpenCV's GrayCodePattern
==================================================

procam-calibration's pose 0 (``../shared/data/procam-calibration``, MIT): a chessboard under
OpenCV's ``GrayCodePattern`` for a 1024 x 768 projector, 10 column bits and 10 row bits,
each followed by its inverse, then white and black (42 frames, camera 1280 x 1024). The
spec is what ``bistair patterns graycode --steps 0 --inverse 1 --white 1 --orientation both
--width 1024 --height 768`` writes (``examples/procam-graycode.json``): a Gray code alone,
cells of one projector pixel. Each pixel is decoded only where every bit is clear.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import bistair
from bistair.io.read import read_with_spec

ROOT = Path.cwd()
while not (ROOT / "examples").is_dir() and ROOT != ROOT.parent:  # the repository's root
    ROOT = ROOT.parent
POSE = ROOT.parent / "shared" / "data" / "procam-calibration" / "capture_0"

if POSE.is_dir():
    stack, spec = read_with_spec(POSE, ROOT / "examples" / "procam-graycode.json")
    result = bistair.decode(stack, spec)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6), layout="constrained")
    axes[0].imshow(stack[spec.frames.index("white")], cmap="gray")
    axes[0].set_title("white frame")
    for ax, axis, label in ((axes[1], result.x, "projector column"),
                            (axes[2], result.y, "projector row")):
        shown = ax.imshow(axis.coord, cmap="viridis")
        fig.colorbar(shown, ax=ax, label=f"{label} (px)")
        ax.set_title(f"{label}: {100 * axis.mask.mean():.1f}% decoded")
    for ax in axes:
        ax.set_axis_off()
    plt.show()
    print("columns decoded:", int(np.nanmin(result.x.coord)), "..",
          int(np.nanmax(result.x.coord)))
else:
    print(f"{POSE} is not here: this example reads the shared real captures")
