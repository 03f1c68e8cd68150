"""The README's picture of a binocular reconstruction: ``docs/_static/stereo-depth.png``.

Renders mugs-on-wall on the two-camera virtual rig (640 x 512 cameras 200 mm apart, the
projector between them; Gray code with the complementary pattern and a white frame), runs
``bistair.stereo`` with the exact calibration and writes, side by side, the left camera's
white frame and the depth on its own image grid (turbo, near red, far blue; black where no
point: the projector's shadow, what the right camera does not see).

    python docs/make_stereo_figure.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import bistair
from bistair.geometry.calibration import StereoCalibration
from bistair.io.atomic import write_image
from bistair.io.previews import colorize
from bistair.sim import Imaging, preset
from bistair.sim.stereo import StereoRig, render_stereo

OUT = Path(__file__).resolve().parent / "_static" / "stereo-depth.png"


def main() -> None:
    rig = StereoRig.default(camera_size=(640, 512), baseline=200)
    spec = bistair.make_spec("graycode", width=1920, height=1080, period=30,
                             complementary=1, white=1, gamma=2.2)
    left, right, truth, _ = render_stereo(bistair.encode(spec), rig,
                                          preset("mugs-on-wall")[1], Imaging(seed=1))
    res = bistair.stereo(left, right, spec, StereoCalibration.from_rig(rig))
    grey = np.repeat(res.grey[..., None], 3, axis=2)
    ok = np.isfinite(res.depth)
    lo, hi = np.percentile(res.depth[ok], [1, 99])
    depth = colorize(res.depth, "turbo_r", float(lo), float(hi))
    err = np.where(ok & truth.mask, res.depth - truth.depth, np.nan)
    gap = np.full((grey.shape[0], 8, 3), 255, np.uint8)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    write_image(OUT, np.concatenate([grey, gap, depth], axis=1))
    print(f"{res.info['matched']} points; median error "
          f"{np.nanmedian(np.abs(err)):.3f} mm; wrote {OUT}")


if __name__ == "__main__":
    main()
