"""
Real captures of another rig: three frequencies, twelve steps
=============================================================

CFPE's plaster bust (``../shared/data/cfpe/david``, MIT): twelve-step phase shifting at
periods of 42, 45 and 48 projector pixels (a 1920 x 1080 projector whose gamma is not
compensated), then a fully lit frame. The spec describes the rig's own patterns: the
heterodyne (beat) method unwraps them, the beats of 42 and 45 (630 px) and 45 and 48
(720 px) beating again to 5040 px, wider than the projector.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import bistair
from bistair.io.read import read_captures

ROOT = Path.cwd()
while not (ROOT / "examples").is_dir() and ROOT != ROOT.parent:  # the repository's root
    ROOT = ROOT.parent
BUST = ROOT.parent / "shared" / "data" / "cfpe" / "david"

spec = bistair.make_spec("multifreq", width=1920, height=1080, periods=(42, 45, 48), steps=12,
                         unwrap="heterodyne", white=1, offset=128 / 255, amplitude=96 / 255)
if BUST.is_dir():
    result = bistair.decode(read_captures(BUST), spec)
    print(f"the three periods agree on {100 * result.info['period_agreement']:.1f}% of the "
          f"well-modulated pixels; {100 * result.mask.mean():.1f}% decoded")
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.5), layout="constrained")
    axes[0].imshow(result.texture, cmap="gray")
    axes[0].set_title("the fully lit frame")
    shown = axes[1].imshow(result.coord, cmap="viridis")
    fig.colorbar(shown, ax=axes[1], label="projector column (px)")
    axes[1].set_title("projector column")
    # the bust's relief: the column minus a plane fitted to the board around it
    yy, xx = np.nonzero(result.mask)
    design = np.c_[xx, yy, np.ones(xx.size)]
    fit, *_ = np.linalg.lstsq(design, result.coord[result.mask], rcond=None)
    plane = np.full(result.coord.shape, np.nan)
    plane[result.mask] = design @ fit
    shown = axes[2].imshow(result.coord - plane, cmap="coolwarm", vmin=-40, vmax=40)
    fig.colorbar(shown, ax=axes[2], label="projector px")
    axes[2].set_title("column minus a plane: the relief")
    for ax in axes:
        ax.set_axis_off()
    plt.show()
else:
    print(f"{BUST} is not here: this example reads the shared real captures")
