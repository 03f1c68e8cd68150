"""3-D accuracy on the virtual rig: calibration, then a sphere and a plane, for every codec.

1. Calibration: a 9 x 6 checkerboard in eight poses (``bistair simulate --scene calibration``
   captures, multifreq, both orientations) through ``calibrate_folder``; prints the errors of
   the recovered intrinsics, baseline and rotation against the rig's.
2. For every codec on ``sphere-on-plane`` (sphere r = 50 mm at 520 mm, plane at 700 mm,
   1% read noise, 1 px defocus, gamma 2.2 pre-compensated): the fitted sphere radius and
   centre and the plane's flatness, with the rig's exact calibration and with the recovered
   one; errors in mm and as a fraction of the field of view (width of the view at 600 mm).
   Fits use the points within 2 mm of the truth; the share beyond 2 mm is printed (wrong
   fringe orders).

    python benchmarks/accuracy.py [--camera 640x512]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from markdown_page import markdown_page  # noqa: E402

import bistair
from bistair.app.calibrate import calibrate_folder
from bistair.app.simulate import simulate
from bistair.evaluation.benchmark import method_specs
from bistair.evaluation.metrics import fit_plane, fit_sphere
from bistair.geometry.calibration import Calibration
from bistair.geometry.triangulate import reconstruct
from bistair.sim import Imaging, Rig, expose, preset, trace

CODECS = ["bidirectional", "lv", "phase-coding", "graycode", "multifreq"]


def calibration_errors(cal: Calibration, truth: Calibration) -> str:
    def focal(a, b):
        return 100 * (a.K[0, 0] / b.K[0, 0] - 1)

    angle = np.degrees(np.arccos(np.clip((np.trace(cal.R @ truth.R.T) - 1) / 2, -1, 1)))
    return (f"camera focal {focal(cal.camera, truth.camera):+.3f}%, projector focal "
            f"{focal(cal.projector, truth.projector):+.3f}%, principal points within "
            f"{max(np.abs(cal.camera.K[:2, 2] - truth.camera.K[:2, 2]).max(), np.abs(cal.projector.K[:2, 2] - truth.projector.K[:2, 2]).max()):.2f} px, "  # noqa: E501
            f"baseline {cal.baseline - truth.baseline:+.3f} mm of {truth.baseline:.1f}, "
            f"rotation {angle:.3f} deg, stereo RMS {cal.rms:.3f} px")


TITLE = 'Accuracy: calibration and 3-D'
ABOUT = ("A calibration from rendered board poses against the rig's truth, and the sphere "
         'of the sphere-on-plane scene measured with each codec, with the exact and the '
         'estimated calibration.')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", type=Path, default=None,
                        help="also write what is printed as a Markdown page")
    parser.add_argument("--camera", default="640x512")
    args = parser.parse_args()
    with markdown_page(args.markdown, TITLE, ABOUT):
        measure_all(args)


def measure_all(args: argparse.Namespace) -> None:
    camera = tuple(int(v) for v in args.camera.split("x"))
    with tempfile.TemporaryDirectory() as tmp:
        caps = simulate("calibration", ["multifreq"], Path(tmp) / "calib", camera_size=camera)
        recovered = calibrate_folder(caps)
    truth = Calibration.from_rig(Rig.default(camera_size=camera))
    print(f"calibration ({camera[0]}x{camera[1]} camera, 8 poses): "
          + calibration_errors(recovered, truth))
    rig, scene = preset("sphere-on-plane", camera_size=camera)
    imaging = Imaging(gamma=2.2, read_noise=0.01, camera_blur=1.0, seed=0)
    traced = trace(rig, scene, imaging)
    fov = 2 * 600 * np.tan(np.arctan(rig.camera.width / 2 / rig.camera.fx))
    print(f"field of view {fov:.0f} mm at 600 mm")
    print(f"{'codec':<14} {'calibration':<10} {'radius':>9} {'centre':>9} {'centre/FOV':>11} "
          f"{'flatness':>9} {'> 2 mm':>8}")
    specs = method_specs(rig.projector.size, gamma=2.2, methods=CODECS)
    for codec in CODECS:
        spec = specs[codec][0]
        result = bistair.decode(expose(traced, bistair.encode(spec), imaging), spec)
        for name, cal in (("exact", truth), ("recovered", recovered)):
            rec = reconstruct(result, cal, spec)
            t = traced.truth
            ok = rec.mask & t.mask
            err = np.linalg.norm(rec.points - t.points, axis=2)
            good = ok & (err < 2.0)
            centre, radius = fit_sphere(rec.points[good & (t.object_id == 1)])
            _, _, resid = fit_plane(rec.points[good & (t.object_id == 2)])
            dc = float(np.linalg.norm(centre - [0, 0, 520]))
            print(f"{codec:<14} {name:<10} {radius - 50:+8.3f}mm {dc:7.3f}mm {dc / fov:11.1e} "
                  f"{np.sqrt(np.mean(resid**2)):7.3f}mm {100 * np.mean(err[ok] > 2):7.3f}%")


if __name__ == "__main__":
    main()
