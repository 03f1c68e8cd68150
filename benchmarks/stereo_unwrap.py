"""Stereo phase unwrapping on the virtual rig: coverage, order errors, the depth range check
and time.

Every scene rendered by both cameras of the two-camera rig (default imaging: noise, blur,
gamma 2.2 compensated) with one four-step set of one period, the projector halfway between
the cameras (the rig's default) or at 0.3 of the baseline. The depth range is the truth's
depths +-10 mm; the share of the valid left pixels decided, and of those an order off
(absolute phase more than pi off the truth, or no truth there: pixels at an object's
silhouette), and the same on the truth's mask (bistair's score), the decided pixels left
undecided as mixed at depth steps (:func:`bistair.geometry.unwrap.mixed_pixels`), the
range check's share of points outside (over 0.5 refuses), and three wrong ranges (just beyond, just
before, far beyond): their check share, points, decided share and order errors. Time: process CPU of
:func:`bistair.geometry.unwrap.unwrap_stereo` (min of three rounds) and its ratio to the
wrapped-phase measurement of both cameras in the same run.

    python benchmarks/stereo_unwrap.py [--camera 640x480] [--scenes plane,sphere-on-plane]

Done when (issue 34): at most 0.1% of the decided pixels an order off (default optics), the
undecided NaN; no right range refused.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

from bistair.core.phase import phase_shift_patterns
from bistair.geometry.calibration import StereoCalibration
from bistair.geometry.unwrap import absolute_phase, unwrap_stereo, wrapped_of
from bistair.sim import preset, scene_names, trace
from bistair.sim.render import Imaging, expose
from bistair.sim.stereo import StereoRig

CONFIGS = ((0.5, 16.0), (0.5, 48.0), (0.3, 48.0))  # projector_at, period


class _Spec:
    method, frame_count, steps, shift_sign, phase_offset = "multifreq", 4, 4, 1, 0.0


def _cpu(fn, rounds: int = 3):
    best, out = math.inf, None
    for _ in range(rounds):
        start = time.process_time()
        out = fn()
        best = min(best, time.process_time() - start)
    return best, out


def case(scene: str, camera: tuple[int, int], projector_at: float, period: float) -> str:
    rig, geometry = preset(scene, camera_size=camera)
    srig = StereoRig.default(camera_size=rig.camera.size, projector_size=rig.projector.size,
                             projector_at=projector_at)
    im = Imaging()
    pw, ph = rig.projector.size
    x = np.broadcast_to(np.arange(pw, dtype=float), (ph, pw))
    patterns = (phase_shift_patterns(x, period, 4) ** (1 / im.gamma)).astype(np.float32)
    captures, truth = [], None
    for i, side in enumerate(("left", "right")):
        cam = dataclasses.replace(im, seed=im.seed + i)
        traced = trace(srig.rig(side), geometry, cam)
        captures.append(expose(traced, patterns, cam))
        truth = traced.truth if side == "left" else truth
    cal = StereoCalibration.from_rig(srig)
    base, maps = _cpu(lambda: [wrapped_of(c, _Spec) for c in captures])
    (lp, lfs), (rp, rfs) = maps
    noise = tuple(float(np.median(fs.phase_noise[fs.valid])) for fs in (lfs, rfs))
    valid = max(int(np.isfinite(lp).sum()), 1)
    z = truth.depth[np.isfinite(truth.depth)]
    low, high = math.floor(z.min() - 10), math.ceil(z.max() + 10)

    def scored(lo: float, hi: float, fill: bool = True):
        found = unwrap_stereo(lp, rp, cal, period, lo, hi, noise, force=True,
                              continue_unseen=fill)
        Phi, order = absolute_phase(found, lp, cal, period)
        decided = order >= 0
        err = Phi - 2 * np.pi * truth.coord_x / period
        wrong = decided & (~np.isfinite(err) | (np.abs(err) > np.pi))
        on = decided & truth.mask
        return found.info, int(decided.sum()), int(wrong.sum()), int(on.sum()), int(
            (wrong & on).sum())

    cpu, _ = _cpu(lambda: unwrap_stereo(lp, rp, cal, period, low, high, noise, force=True))
    info, decided, wrong, on, wrong_on = scored(low, high)
    check = info["range_check"]
    _, plain, plain_wrong, _, plain_wrong_on = scored(low, high, fill=False)
    width = high - low
    others = []
    for lo, hi in ((high + 20, high + 20 + width), (max(low - 20 - width, 50), low - 20),
                   (high + 100, high + 100 + 2 * width)):
        winfo, wdec, wwrong, _, _ = scored(lo, hi)
        wc = winfo["range_check"]
        others.append(f"{lo}:{hi} {wc['outside']:.3f}/{wc['points']} "
                      f"{100 * wdec / valid:.1f}% {wwrong}")
    return (f"{scene:17s} at {projector_at} T {period:g} {low}:{high} decided "
            f"{100 * decided / valid:5.1f}% (mixed {info['mixed']}: "
            f"{100 * (decided + info['mixed']) / valid:.1f}% with them) wrong {wrong} "
            f"({100 * wrong / max(decided, 1):.3f}%;"
            f" on the truth's mask {wrong_on} of {on}, {100 * wrong_on / max(on, 1):.3f}%)"
            f" continued {info['continued']} (without: decided {100 * plain / valid:.1f}%, "
            f"wrong {plain_wrong}, on the mask {plain_wrong_on})"
            f" check {check['outside']:.3f}/{check['points']} cpu {cpu:.3f} s "
            f"(x{cpu / base:.0f}) | wrong ranges: " + "; ".join(others))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="640x480")
    parser.add_argument("--scenes", default=",".join(scene_names()))
    args = parser.parse_args()
    camera = tuple(int(v) for v in args.camera.split("x"))
    for scene in args.scenes.split(","):
        for at, period in CONFIGS:
            print(case(scene, camera, at, period), flush=True)


if __name__ == "__main__":
    main()
