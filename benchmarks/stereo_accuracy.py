"""Binocular accuracy on the virtual rig (issue 22's figures): two 1280 x 1024 cameras with
the projector between them, baselines 100-250 mm, objects at 500-900 mm, default and hard
optics; every scene decoded by both cameras and matched by ``bistair.stereo`` with the rig's
exact calibration, scored against the left camera's truth
(:mod:`bistair.evaluation.stereo`).

Scenes: ``sphere`` (sphere-on-plane: a sphere at 470-570 mm before a plane at 700 mm),
``mugs`` (mugs-on-wall: two mugs at 545-690 mm, one hiding the other, a wall at 720 mm) and
``far`` (a sphere, a box and a plane at 765-900 mm; the cameras aimed at 850 mm). Optics:
``default`` (:class:`bistair.sim.Imaging`'s defaults: 0.5% read noise, shot noise, 1 px
camera blur) and ``hard`` (gamma 2.2, 3% read noise, camera blur 1.2 px, projector blur
1.0 px, 15% ambient: ``tests/support/pre_speed.py``'s HARD). Pattern set: Gray code with the
complementary pattern, 4 steps, period 30 (``--method`` for another).

Columns: matched (share of the left pixels both cameras decode that got a point), depth
error RMS over all points and over those within 1% (relative to the distance), p99 of the
absolute relative error, wrong (points off by more than 1%), median absolute error. Targets:
matched >= 95%, RMS <= 0.05%, p99 <= 0.2%, wrong <= 0.05%; hard optics within twice those.

    python benchmarks/stereo_accuracy.py [--scenes sphere,mugs,far] [--baselines 100,175,250]
        [--optics default,hard] [--camera 1280x1024] [--method graycode] [--smooth 0]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import bistair
from bistair.evaluation.stereo import score_stereo
from bistair.geometry.calibration import StereoCalibration
from bistair.geometry.stereo import stereo
from bistair.sim import Box, Imaging, Plane, Scene, Sphere, euler, preset
from bistair.sim.stereo import StereoRig, render_stereo

HARD = dict(gamma=2.2, read_noise=0.03, camera_blur=1.2, projector_blur=1.0, ambient=0.15)
PARAMS = {"graycode": dict(period=30, complementary=1),
          "bidirectional": dict(period=30, partitions=8, stairs=8),
          "multifreq": dict(periods=(1920, 240, 30))}


def far_scene() -> Scene:
    return Scene([Sphere(center=(-70, -30, 820), radius=55, albedo=0.6),
                  Box(center=(80, 40, 850), size=(70, 60, 50), rotation=euler(y=25),
                      albedo=0.55),
                  Plane(center=(0, 0, 900), size=(1400, 1200), albedo=0.75)])


SCENES = {"sphere": (lambda: preset("sphere-on-plane")[1], 600.0),
          "mugs": (lambda: preset("mugs-on-wall")[1], 640.0),
          "far": (far_scene, 850.0)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default="sphere,mugs,far")
    parser.add_argument("--baselines", default="100,175,250")
    parser.add_argument("--optics", default="default,hard")
    parser.add_argument("--camera", default="1280x1024")
    parser.add_argument("--method", default="graycode", choices=sorted(PARAMS))
    parser.add_argument("--smooth", type=float, default=0.0,
                        help="bistair.stereo's smoothing sigma (px)")
    args = parser.parse_args()
    camera = tuple(int(v) for v in args.camera.split("x"))
    spec = bistair.make_spec(args.method, width=1920, height=1080, gamma=2.2,
                             **PARAMS[args.method])
    patterns = bistair.encode(spec)
    print(f"{args.method} {spec.frame_count} frames, cameras {camera[0]}x{camera[1]}, "
          f"smoothing {args.smooth:g} px")
    print(f"{'scene':7s} {'base':>5s} {'optics':8s} {'depths mm':>10s} {'matched':>8s} "
          f"{'RMS':>8s} {'RMS in':>8s} {'p99':>7s} {'wrong':>8s} {'median':>8s} {'time':>6s}")
    worst: dict[str, dict[str, float]] = {}
    for name in args.scenes.split(","):
        make, distance = SCENES[name]
        for baseline in (float(b) for b in args.baselines.split(",")):
            rig = StereoRig.default(camera_size=camera, baseline=baseline,
                                    working_distance=distance)
            cal = StereoCalibration.from_rig(rig)
            for optics in args.optics.split(","):
                imaging = Imaging(**(HARD if optics == "hard" else {}), seed=7)
                left, right, lt, rt = render_stereo(patterns, rig, make(), imaging)
                start = time.perf_counter()
                res = stereo(left, right, spec, cal, smooth=args.smooth)
                seconds = time.perf_counter() - start
                s = score_stereo(res, rig, lt, rt)
                near, far = np.nanpercentile(lt.depth[lt.mask], [2, 98])
                print(f"{name:7s} {baseline:5.0f} {optics:8s} {near:4.0f}-{far:<5.0f} "
                      f"{100 * s['matched']:7.2f}% {100 * s['rms']:7.4f}% "
                      f"{100 * s['rms_inliers']:7.4f}% {100 * s['p99']:6.3f}% "
                      f"{100 * s['wrong_share']:7.4f}% {s['median_mm']:6.3f}mm "
                      f"{seconds:5.2f}s", flush=True)
                w = worst.setdefault(optics, {"matched": 1.0, "rms": 0.0, "p99": 0.0,
                                              "wrong_share": 0.0})
                w["matched"] = min(w["matched"], s["matched"])
                for key in ("rms", "p99", "wrong_share"):
                    w[key] = max(w[key], s[key])
    for optics, w in worst.items():
        k = 2.0 if optics == "hard" else 1.0
        checks = [("matched", w["matched"] >= 1 - 0.05 * k), ("RMS", w["rms"] <= 5e-4 * k),
                  ("p99", w["p99"] <= 2e-3 * k), ("wrong", w["wrong_share"] <= 5e-4 * k)]
        print(f"worst, {optics} optics: matched {100 * w['matched']:.2f}%, RMS "
              f"{100 * w['rms']:.4f}%, p99 {100 * w['p99']:.3f}%, wrong "
              f"{100 * w['wrong_share']:.4f}%; targets"
              f"{' (x2)' if k > 1 else ''}: "
              + ", ".join(f"{n} {'met' if ok else 'MISSED'}" for n, ok in checks))


if __name__ == "__main__":
    main()
