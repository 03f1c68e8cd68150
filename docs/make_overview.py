"""The picture of the README and the documentation's front page (docs/_static/overview.png):
a capture of the virtual rig's paper scene, its decoded projector columns and its depth
map. Run: ``python docs/make_overview.py``."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bistair  # noqa: E402
from bistair.geometry.calibration import Calibration  # noqa: E402
from bistair.geometry.triangulate import reconstruct  # noqa: E402
from bistair.sim import Imaging, expose, preset, trace  # noqa: E402

OUT = Path(__file__).resolve().parent / "_static" / "overview.png"


def main() -> None:
    rig, scene = preset("paper-sim", camera_size=(640, 512))
    spec = bistair.make_spec("bidirectional", width=rig.projector.width,
                             height=rig.projector.height, period=30, gamma=2.2)
    imaging = Imaging(read_noise=0.01, camera_blur=1.0, seed=0)
    captures = expose(trace(rig, scene, imaging), bistair.encode(spec), imaging)
    result = bistair.decode(captures, spec)
    depth = reconstruct(result, Calibration.from_rig(rig), spec).depth
    fig, axes = plt.subplots(1, 4, figsize=(14, 2.9), layout="constrained")
    for ax, image, title in ((axes[0], captures[0], "shift-0"),
                             (axes[1], captures[5], "stair-sin")):
        ax.imshow(image, cmap="gray")
        ax.set_title(title)
    shown = axes[2].imshow(result.coord, cmap="viridis")
    fig.colorbar(shown, ax=axes[2], label="projector column (px)", shrink=0.9)
    axes[2].set_title("decoded")
    shown = axes[3].imshow(depth, cmap="turbo", vmin=np.nanpercentile(depth, 1),
                           vmax=np.nanpercentile(depth, 99))
    fig.colorbar(shown, ax=axes[3], label="depth (mm)", shrink=0.9)
    axes[3].set_title("3-D")
    for ax in axes:
        ax.set_axis_off()
    fig.savefig(OUT, dpi=90)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
