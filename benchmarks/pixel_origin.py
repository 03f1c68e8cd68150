"""The cameras' pixel origin from the data: stereo phase unwrapping's check on the virtual
rig, with the calibration right and one pixel off both ways.

Each scene rendered by both cameras (default imaging, one four-step set of period 48, the
projector halfway and at 0.3 of the baseline, two noise seeds); the calibration given as
it is (origin 0 recorded), as MATLAB's 1-based matrices read 0-based (the cameras'
principal points one pixel too far, origin 0 recorded) and as 0-based matrices read
1-based (one pixel too near, origin 1 recorded). For each: the share of the left pixels
the projector confirms (``consistent_share``) under the given origin and the other, the
origin used, the decided share and its order errors.

    python benchmarks/pixel_origin.py [--camera 320x240] [--scenes plane,sphere-on-plane]
    python benchmarks/pixel_origin.py --shares [--scenes all]

``--shares``: only the shares the projector confirms (``consistent_share``, every eighth
row) per scene, projector place and period (16 and 48 px): as rendered, with the cameras
one pixel off both ways, and with the phase negated (the wrong ``shift_sign``): the margins
of the origin and the sign checks, cheaply, on every scene.

Done when the right origin is kept in every right case and taken in every wrong one
(:data:`bistair.geometry.unwrap.ORIGIN_RATIO`, :data:`~bistair.geometry.unwrap.ORIGIN_MIN`).
"""

from __future__ import annotations

import argparse
import dataclasses
import math

import numpy as np

from bistair.core.phase import phase_shift_patterns
from bistair.geometry.projection_matrices import with_pixel_origin
from bistair.geometry.stereo_calibration import StereoCalibration
from bistair.geometry.unwrap import (
    MIN_TOLERANCE,
    ORIGIN_MIN,
    ORIGIN_RATIO,
    TOLERANCE_SIGMAS,
    absolute_phase,
    consistent_share,
    unwrap_stereo,
    wrapped_of,
)
from bistair.sim import preset, scene_names, trace
from bistair.sim.render import Imaging, expose
from bistair.sim.stereo import StereoRig

SCENES = "plane,sphere-on-plane,two-masks,two-sculptures"
PERIOD = 48.0
#: (name, principal points' move, recorded origin, the right answer)
CASES = (("right", 0.0, 0, 0), ("1-based read as 0", -1.0, 0, 1),
         ("0-based read as 1", 1.0, 1, 0))


class _Spec:
    method, frame_count, steps, shift_sign, phase_offset = "multifreq", 4, 4, 1, 0.0


def render(scene: str, camera: tuple[int, int], projector_at: float, seed: int):
    rig, geometry = preset(scene, camera_size=camera)
    srig = StereoRig.default(camera_size=rig.camera.size, projector_size=rig.projector.size,
                             projector_at=projector_at)
    im = dataclasses.replace(Imaging(), seed=seed)
    pw, ph = rig.projector.size
    x = np.broadcast_to(np.arange(pw, dtype=float), (ph, pw))
    patterns = (phase_shift_patterns(x, PERIOD, 4) ** (1 / im.gamma)).astype(np.float32)
    phases, noise, truth = [], [], None
    for i, side in enumerate(("left", "right")):
        cam = dataclasses.replace(im, seed=im.seed + i)
        traced = trace(srig.rig(side), geometry, cam)
        phase, fs = wrapped_of(expose(traced, patterns, cam), _Spec)
        phases.append(phase)
        noise.append(float(np.median(fs.phase_noise[fs.valid])))
        truth = traced.truth if side == "left" else truth
    return phases, tuple(noise), StereoCalibration.from_rig(srig), truth


def shares(scenes: list[str], camera: tuple[int, int]) -> None:
    """The confirmed shares of every case (``--shares``)."""
    global PERIOD
    low_right, high_wrong, low_sign_gap = 1.0, 0.0, math.inf
    for scene in scenes:
        for at in (0.5, 0.3):
            for period in (16.0, 48.0):
                PERIOD = period
                (lp, rp), noise, cal, truth = render(scene, camera, at, 1)
                z = truth.depth[np.isfinite(truth.depth)]
                low, high = math.floor(z.min() - 10), math.ceil(z.max() + 10)
                tol = max(MIN_TOLERANCE, TOLERANCE_SIGMAS * math.hypot(*noise))
                right = consistent_share(lp, rp, cal, period, tol, low, high)
                off = [consistent_share(lp, rp, with_pixel_origin(cal, m), period, tol, low,
                                        high) for m in (-1.0, 1.0)]
                neg = [np.where(np.isfinite(p), np.mod(-p, 2 * np.pi), np.nan)
                       .astype(np.float32) for p in (lp, rp)]
                negated = consistent_share(*neg, cal, period, tol, low, high)
                low_right = min(low_right, right)
                high_wrong = max(high_wrong, *off, negated)
                low_sign_gap = min(low_sign_gap, right / max(negated, 1e-9))
                print(f"{scene:17s} at {at} T {period:g}: right {right:.4f}, one pixel off "
                      f"{off[0]:.4f} / {off[1]:.4f}, negated {negated:.4f}", flush=True)
    print(f"right inputs confirm at least {low_right:.4f}; wrong origins or sign at most "
          f"{high_wrong:.4f}; right over negated at least {low_sign_gap:.1f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="320x240")
    parser.add_argument("--scenes", default=SCENES)
    parser.add_argument("--shares", action="store_true")
    args = parser.parse_args()
    camera = tuple(int(v) for v in args.camera.split("x"))
    if args.shares:
        names = scene_names() if args.scenes == "all" else args.scenes.split(",")
        shares(names, camera)
        return
    worst = {"right": 0.0, "wrong": math.inf}  # the other's share over the given's
    misses = 0
    for scene in args.scenes.split(","):
        for at in (0.5, 0.3):
            for seed in (1, 2):
                (lp, rp), noise, cal, truth = render(scene, camera, at, seed)
                z = truth.depth[np.isfinite(truth.depth)]
                low, high = math.floor(z.min() - 10), math.ceil(z.max() + 10)
                for name, move, given, want in CASES:
                    given_cal = with_pixel_origin(cal, move)
                    found = unwrap_stereo(lp, rp, given_cal, PERIOD, low, high, noise,
                                          force=True, pixel_origin=given)
                    reg = found.info["consistent"]
                    Phi, order = absolute_phase(found, lp, given_cal, PERIOD)
                    decided = order >= 0
                    err = Phi - 2 * np.pi * truth.coord_x / PERIOD
                    wrong = decided & (~np.isfinite(err) | (np.abs(err) > np.pi))
                    used = found.info["pixel_origin"]
                    misses += used != want
                    r_given, r_other = reg[str(given)], reg[str(1 - given)]
                    if r_given is not None:
                        ratio = r_other / max(r_given, 1e-9)
                        key = "right" if name == "right" else "wrong"
                        worst[key] = (max if key == "right" else min)(worst[key], ratio)
                    print(f"{scene:15s} at {at} seed {seed} {name:18s} confirmed with the "
                          f"given {given}: {r_given}, the other: {r_other} -> {used} (want "
                          f"{want}); "
                          f"decided {100 * decided.mean():.1f}% wrong {int(wrong.sum())}",
                          flush=True)
    print(f"confirmed share, the other origin's over the given one's: right cases at most "
          f"{worst['right']:.3f}, wrong cases at least {worst['wrong']:.1f} (the other taken "
          f"above {ORIGIN_RATIO:g} and {ORIGIN_MIN:g}); wrong origin kept or right one left: "
          f"{misses}")


if __name__ == "__main__":
    main()
