"""Speed of ``bistair.stereo`` at 2 x 1.3 MP against one ``bistair.decode`` of 1.3 MP,
measured in the same run (the machine is shared and noisy: the ratio is the figure; issue
32's target is at most 2.2, issue 22's was 2.5).

The pair is rendered once on the two-camera virtual rig (mugs-on-wall, 1280 x 1024, 8 bit,
cameras 200 mm apart). Each round times, interleaved: one decode of the left captures;
``stereo`` of both with the calibration's rectification already made (as a batch or a
Python loop over scans with one calibration gets it); and ``stereo`` making the
rectification again (what one ``bistair stereo`` command pays). Medians over the rounds,
their ratios to the decode, and where the stereo time goes (both decodes, rectification,
matching and points) are printed. Freed memory is kept for the next arrays, as on the
command line.

Then, with one kernel thread and process CPU time (what a loaded machine still measures
well), the minimum over interleaved rounds of: one decode, the matching and points
(``reconstruct_stereo``, its checks included) and the OpenCV floor of a 4-step decode
(:func:`bistair.evaluation.speed.opencv_floor`) of the same captures.

    python benchmarks/stereo_speed.py [--rounds 7] [--methods bidirectional,graycode]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import cv2

import bistair
from bistair.core.jit import set_threads
from bistair.core.memory import keep_freed_memory
from bistair.evaluation.speed import opencv_floor
from bistair.geometry import stereo as st
from bistair.geometry.calibration import StereoCalibration
from bistair.sim import Imaging, preset
from bistair.sim.stereo import StereoRig, render_stereo

PARAMS = {"bidirectional": dict(period=30, partitions=8, stairs=8),
          "graycode": dict(period=30, complementary=1),
          "multifreq": dict(periods=(1920, 240, 30))}


def clock(func, *args, **kwargs) -> tuple[float, object]:
    start = time.perf_counter()
    out = func(*args, **kwargs)
    return time.perf_counter() - start, out


def cpu(func, *args, **kwargs) -> float:
    start = time.process_time()
    func(*args, **kwargs)
    return time.process_time() - start


def one_thread(left, res, spec, cal, rounds: int) -> dict[str, float]:
    """Minimum process CPU seconds over ``rounds`` interleaved rounds, one kernel thread."""
    threads = set_threads(1)
    cv_threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    best = {"decode": math.inf, "match": math.inf, "floor": math.inf}
    try:
        for _ in range(rounds):
            best["decode"] = min(best["decode"], cpu(bistair.decode, left, spec))
            best["match"] = min(best["match"], cpu(st.reconstruct_stereo, res.left, res.right,
                                                   cal, spec.orientation))
            best["floor"] = min(best["floor"], cpu(opencv_floor, left))
    finally:
        set_threads(threads)
        cv2.setNumThreads(cv_threads)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--methods", default="bidirectional,graycode")
    args = parser.parse_args()
    keep_freed_memory()
    rig = StereoRig.default(camera_size=(1280, 1024), baseline=200)
    scene = preset("mugs-on-wall")[1]
    for method in args.methods.split(","):
        spec = bistair.make_spec(method, width=1920, height=1080, gamma=2.2, **PARAMS[method])
        left, right, _, _ = render_stereo(bistair.encode(spec), rig, scene, Imaging(seed=1))
        cal = StereoCalibration.from_rig(rig)
        st.stereo(left, right, spec, cal)  # compile, warm
        times: dict[str, list[float]] = {k: [] for k in
                                          ("decode", "stereo", "stereo cold", "rectify",
                                           "match")}
        for _ in range(args.rounds):
            times["decode"].append(clock(bistair.decode, left, spec)[0])
            seconds, res = clock(st.stereo, left, right, spec, cal)
            times["stereo"].append(seconds)
            fresh = cal.replace()  # a new calibration object: its rectification is made
            times["stereo cold"].append(clock(st.stereo, left, right, spec, fresh)[0])
            times["rectify"].append(clock(st.rectify, cal.replace())[0])
            times["match"].append(clock(st.reconstruct_stereo, res.left, res.right, cal,
                                        spec.orientation)[0])
        med = {k: statistics.median(v) for k, v in times.items()}
        base = med["decode"]
        print(f"{method} ({spec.frame_count} frames), 2 x 1280x1024, median of "
              f"{args.rounds} rounds:")
        print(f"  decode (one camera)             {1000 * base:7.1f} ms   1.00")
        for key, label in (("stereo", "stereo, rectification made once"),
                           ("stereo cold", "stereo, rectification each time")):
            print(f"  {label:32s}{1000 * med[key]:7.1f} ms   {med[key] / base:.2f}")
        print(f"  of which: rectification {1000 * med['rectify']:.1f} ms, matching and "
              f"points {1000 * med['match']:.1f} ms "
              f"({med['match'] / base:.2f} of a decode)")
        ratios = [s / d for s, d in zip(times["stereo cold"], times["decode"], strict=True)]
        verdict = "met" if med["stereo cold"] <= 2.2 * base else "MISSED"
        print("  stereo (each time) / decode per round: "
              + ", ".join(f"{r:.2f}" for r in ratios) + f"; target at most 2.2: {verdict}",
              flush=True)
        best = one_thread(left, res, spec, cal, args.rounds)
        print(f"  one thread, CPU (min of {args.rounds}): decode {1000 * best['decode']:.1f} "
              f"ms, matching and points {1000 * best['match']:.1f} ms "
              f"({best['match'] / best['decode']:.2f} of a decode, "
              f"{best['match'] / best['floor']:.1f} x the OpenCV floor of "
              f"{1000 * best['floor']:.1f} ms)", flush=True)
        del left, right, res


if __name__ == "__main__":
    main()
