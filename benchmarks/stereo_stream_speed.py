"""Depth maps per second of a two-camera stream (issue 34): ``stereo --window`` at 640 x 480.

two-masks seen by the virtual rig's two cameras (640 x 480 each, 200 mm apart, the
projector halfway), a four-step stream of period 48 (uint8 frames, default imaging: frame
``i`` shows shift ``i mod 4``, each frame its own noise), depth range 520:650 mm; still,
and moving ``--motion`` mm a frame towards the cameras and back (a triangle wave over the
``--frames`` frames, so that they repeat without a jump; 2 mm a frame moves a disparity
about 1.3 px at 600 mm, 0.18 m/s at 90 frames a second). The
steady state is timed: each new frame pair updates both cameras' sums, unwraps (the search
near the previous disparity, the full range where that fails, the confirmations) and
triangulates (the projector's column planes). Process CPU time, the minimum of interleaved
rounds, per depth map, beside two bare baselines of the same run: one ``cv2.remap`` of a
640 x 480 float32 image and a NumPy sum of four 640 x 480 frames. Then where the time goes:
each stage of a depth map (both cameras) timed inside the stream's steps, the minimum over
``--frames`` depth maps (the stages' minima need not add up to the whole's): its work (CPU
on one numba and OpenCV thread), its CPU and wall time on the machine's threads, and the
share of its work that runs in parallel (Amdahl's law from the two). The rate a dedicated
machine of that many cores gets is each stage's work at its parallel share (the rest of a
depth map serial), beside the wall time measured here and the load average: other jobs on
the cores lower the measured share and the rate. The row searches of one depth map (both
grids, one thread) are timed again as they were before the fast path: every interval of a
search tested and each candidate projected as the full search does (``track_rows(...,
skip=False)``, the same result). The decided pixels an order off are counted against the
renderer's truth after the timing (a moving window's truth: the mean of the true columns
of the frames about its middle).

    python benchmarks/stereo_stream_speed.py [--camera 640x480] [--frames 24] [--rounds 5]
        [--motion 2]
"""

from __future__ import annotations

import argparse
import math
import os
import time
from collections import defaultdict
from collections.abc import Callable

import cv2
import numba
import numpy as np

from bistair.codecs import encode, make_spec
from bistair.core.motion import PhaseStream
from bistair.geometry import unwrap_stream
from bistair.geometry.stereo_calibration import StereoCalibration
from bistair.geometry.unwrap_stream import StereoStream
from bistair.sim import Imaging, expose, preset, trace
from bistair.sim.motion import parse_motion, trace_frames
from bistair.sim.stereo import StereoRig

RANGE = (520.0, 650.0)
MOVING = ", moving"  # the moving scene's streams: "4, moving"
WHOLE = "whole depth map"
STAGES = {  # what each stage of a depth map calls (module or class, name)
    "running sums (PhaseStream)": [(PhaseStream, "update")],
    "resampling (resample_wrapped)": [(unwrap_stream, "resample_wrapped")],
    "row searches (track_rows)": [(unwrap_stream, "track_rows")],
    "confirmation (confirm)": [(unwrap_stream, "confirm")],
    "growth (grow)": [(unwrap_stream, "grow")],
    "depth (projector_pixels, plane_depth)": [(unwrap_stream, "projector_pixels"),
                                              (unwrap_stream, "plane_depth")],
    "mixed pixels (mixed_pixels)": [(unwrap_stream, "mixed_pixels")],
}


def scene_frames(width: int, height: int, count: int, motion: float = 0.0
                 ) -> tuple[StereoCalibration, object, np.ndarray, np.ndarray, np.ndarray]:
    """The calibration, the spec, ``count`` frames of each camera and the left camera's
    true projector column of each frame (NaN where it sees no surface). With ``motion``
    (mm a frame towards the cameras), the masks move there and back: frame ``i`` shows them
    at the time of a triangle wave of period ``count`` (``count`` a multiple of 4), so the
    frames repeat without a jump and frame ``i`` still shows shift ``i mod 4``."""
    rig, scene = preset("two-masks", camera_size=(width, height))
    srig = StereoRig.default(camera_size=(width, height), projector_size=rig.projector.size)
    spec = make_spec("multifreq", width=rig.projector.size[0], height=rig.projector.size[1],
                     periods=(48,), steps=4)
    patterns = encode(spec)[np.arange(count) % 4]
    times = [min(i, count - i) for i in range(count)]
    moving = parse_motion(f"0,0,{-motion:g}mm")
    frames, columns = [], []
    for i, side in enumerate(("left", "right")):
        imaging = Imaging(seed=i)
        if motion:
            traces = trace_frames(srig.rig(side), scene, moving, times, imaging)
            frames.append(np.stack([expose(tr, patterns[k:k + 1], imaging, first_frame=k)[0]
                                    for k, tr in enumerate(traces)]))
            columns.append(np.stack([tr.truth.coord_x for tr in traces]))
        else:
            traced = trace(srig.rig(side), scene, imaging)
            frames.append(expose(traced, patterns, imaging))
            columns.append(np.broadcast_to(traced.truth.coord_x, (count, height, width)))
    return StereoCalibration.from_rig(srig), spec, frames[0], frames[1], columns[0]


def cpu(fn, repeat: int = 1) -> float:
    """Process CPU seconds of one call, over ``repeat`` calls."""
    start = time.process_time()
    for _ in range(repeat):
        fn()
    return (time.process_time() - start) / repeat


def stage_split(stream: StereoStream, left: np.ndarray, right: np.ndarray, first: int,
                count: int) -> dict[str, tuple[float, float]]:
    """Process CPU and wall seconds of each stage of a depth map, each the minimum over
    ``count`` depth maps (frames ``first ..``, wrapping), and of the whole ``push``."""
    spent: dict[str, list[float]] = defaultdict(lambda: [0.0, 0.0])
    saved: list[tuple[object, str, Callable]] = []

    def timed(stage: str, fn: Callable) -> Callable:
        def call(*args: object, **kwargs: object) -> object:
            start, clock = time.process_time(), time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                spent[stage][0] += time.process_time() - start
                spent[stage][1] += time.perf_counter() - clock
        return call

    for stage, places in STAGES.items():
        for owner, name in places:
            saved.append((owner, name, getattr(owner, name)))
            setattr(owner, name, timed(stage, getattr(owner, name)))
    best = {name: [float("inf"), float("inf")] for name in (*STAGES, WHOLE)}
    try:
        for i in range(first, first + count):
            spent.clear()
            start, clock = time.process_time(), time.perf_counter()
            stream.push(left[i % len(left)], right[i % len(right)])
            spent[WHOLE] = [time.process_time() - start, time.perf_counter() - clock]
            for name in best:
                best[name] = [min(a, b) for a, b in zip(best[name], spent[name], strict=True)]
    finally:
        for owner, name, fn in saved:
            setattr(owner, name, fn)
    return {name: (v[0], v[1]) for name, v in best.items()}


def threads(count: int) -> None:
    """Run numba's and OpenCV's parallel loops on ``count`` threads."""
    numba.set_num_threads(count)
    cv2.setNumThreads(count)


def parallel_split(stream: StereoStream, left: np.ndarray, right: np.ndarray, first: int,
                   count: int, cores: int) -> dict[str, tuple[float, float, float]]:
    """Each stage's work (CPU seconds on one thread), its CPU and wall seconds on
    ``cores`` threads, and the share of its work that runs in parallel (Amdahl's law from
    the wall time on ``cores`` threads: ``wall = work * (1 - p + p / cores)``; a loaded
    machine lowers it)."""
    threads(1)
    one = stage_split(stream, left, right, first, count)
    threads(cores)
    many = stage_split(stream, left, right, first + count, count)
    out = {}
    for name in one:
        work, (cpu_many, wall) = one[name][0], many[name]
        share = min(max((1 - wall / max(work, 1e-12)) * cores / (cores - 1), 0.0), 1.0)
        out[name] = (work, cpu_many, wall, share)
    return out


def search_split(stream: StereoStream, left: np.ndarray, right: np.ndarray, first: int,
                 rounds: int) -> dict[str, float]:
    """CPU seconds (one thread) of one depth map's row searches, both grids, with the fast
    path and with every interval tested: the minimum of ``rounds`` interleaved rounds on
    the arguments of the window of frame ``first``."""
    calls: list[tuple[tuple, dict]] = []
    plain = unwrap_stream.track_rows

    def recorded(*args: object, **kwargs: object) -> object:
        calls.append((args, kwargs))
        return plain(*args, **kwargs)

    unwrap_stream.track_rows = recorded
    try:
        stream.push(left[first % len(left)], right[first % len(right)])
    finally:
        unwrap_stream.track_rows = plain
    before = numba.get_num_threads()
    threads(1)
    best = {"fast": float("inf"), "every interval": float("inf")}
    for _ in range(rounds):
        for name, skip in (("fast", True), ("every interval", False)):
            best[name] = min(best[name], cpu(lambda skip=skip: [
                plain(*args, **kwargs, skip=skip) for args, kwargs in calls]))
    threads(before)
    return best


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="640x480")
    parser.add_argument("--frames", type=int, default=24)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--motion", type=float, default=2.0,
                        help="mm a frame of the moving scene's masks (0: no moving scene)")
    args = parser.parse_args(argv)
    width, height = (int(v) for v in args.camera.lower().split("x"))
    args.frames += -args.frames % 4
    cal, spec, left, right, truth = scene_frames(width, height, args.frames)
    data = {"": (left, right, truth)}
    if args.motion:
        data[MOVING] = scene_frames(width, height, args.frames, args.motion)[2:]
    streams: dict[str, StereoStream] = {}
    for window, order, scene in (("4", 0, ""), ("4+2", 2, ""), ("4", 0, MOVING),
                                 ("4+2", 2, MOVING)):
        if scene not in data:
            continue
        stream = StereoStream(cal, spec, *RANGE, order=order)
        for i in range(8):  # warm: the first window, the kernels
            stream.push(data[scene][0][i], data[scene][1][i])
        streams[window + scene] = stream
    position = {name: 8 for name in streams}
    shares: dict[str, list[float]] = {name: [] for name in streams}
    kept: dict[str, list[tuple[np.ndarray, np.ndarray, np.ndarray]]] = {
        name: [] for name in streams}
    image = left[0].astype(np.float32)
    maps = np.mgrid[:height, :width][::-1].astype(np.float32) + np.float32(0.3)
    four = left[:4]

    def push(name: str) -> None:
        frames = data[MOVING if name.endswith(MOVING) else ""]
        i = position[name] % args.frames
        position[name] += 1
        stream = streams[name]
        result = stream.push(frames[0][i], frames[1][i])
        centre = i - (stream.spec.steps + stream.order - 1) + stream.lag  # the window's time
        seen = 0.5 * (frames[2][math.floor(centre) % args.frames]
                      + frames[2][math.ceil(centre) % args.frames])
        kept[name].append((result.phase, result.mask, seen))
        shares[name].append(result.info["decided_fraction"])

    tasks = {
        "cv2.remap 640x480 float32 (baseline)": lambda: cv2.remap(
            image, maps[0], maps[1], cv2.INTER_LINEAR),
        "numpy sum of 4 frames (baseline)": lambda: four.sum(axis=0, dtype=np.float32),
        **{f"depth map, --window {name}": lambda name=name: push(name) for name in streams},
    }
    repeat = {name: 20 if "baseline" in name else 8 for name in tasks}
    best = {name: float("inf") for name in tasks}
    wall = {name: float("inf") for name in tasks}
    for _ in range(args.rounds):  # interleaved: each round runs every task
        for name, task in tasks.items():
            clock = time.perf_counter()
            best[name] = min(best[name], cpu(task, repeat[name]))
            wall[name] = min(wall[name], (time.perf_counter() - clock) / repeat[name])
    base = best["cv2.remap 640x480 float32 (baseline)"]
    print(f"# two-masks {width}x{height}, both cameras, 4 steps, period 48, "
          f"{RANGE[0]:g}:{RANGE[1]:g} mm"
          + (f" (moving: {args.motion:g} mm a frame towards the cameras and back)"
             if args.motion else "") + f"; min of {args.rounds} interleaved rounds; "
          f"{numba.get_num_threads()} numba threads; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print("| per depth map | CPU ms | / remap | maps/s (CPU) | wall ms | maps/s (wall) |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for name in tasks:
        print(f"| {name} | {1000 * best[name]:.2f} | {best[name] / base:.1f} | "
              f"{1 / best[name]:.0f} | {1000 * wall[name]:.2f} | {1 / wall[name]:.0f} |")
    cores = max(numba.get_num_threads(), 2)
    for name, stream in streams.items():
        if name == "4+2" + MOVING:  # (its stages: as 4+2's and the moving 4's)
            continue
        frames = data[MOVING if name.endswith(MOVING) else ""]
        split = parallel_split(stream, frames[0], frames[1], position[name], args.frames,
                               cores)
        position[name] += 2 * args.frames
        work = split.pop(WHOLE)
        print(f"\n| --window {name}: stage (both cameras) | work ms (1 thread) | CPU ms "
              f"({cores} threads) | wall ms ({cores} threads) | parallel share |")
        print("| --- | ---: | ---: | ---: | ---: |")
        dedicated = work[0] - sum(v[0] for v in split.values())  # the rest: serial
        for stage, (one, many, wall_s, share) in split.items():
            dedicated += one * (1 - share + share / cores)
            print(f"| {stage} | {1000 * one:.2f} | {1000 * many:.2f} | {1000 * wall_s:.2f} "
                  f"| {100 * share:.0f}% |")
        share = (1 - dedicated / work[0]) * cores / (cores - 1)
        print(f"| whole depth map | {1000 * work[0]:.2f} | {1000 * work[1]:.2f} | "
              f"{1000 * work[2]:.2f} | {100 * share:.0f}% |")
        print(f"--window {name}: a dedicated {cores}-core machine: {1000 * dedicated:.1f} ms "
              f"a depth map, {1 / dedicated:.0f} maps/s (each stage's work at its parallel "
              f"share; the rest serial); measured here: {1000 * work[2]:.1f} ms wall "
              f"({1 / work[2]:.0f} maps/s) at load {os.getloadavg()[0]:.1f}; every stage "
              f"wholly parallel: {cores / work[0]:.0f} maps/s")
    searches = search_split(streams["4"], left, right, position["4"], args.rounds)
    position["4"] += 1
    print(f"\nrow searches of a depth map (--window 4, both grids, 1 thread): "
          f"{1000 * searches['fast']:.2f} ms; every interval tested: "
          f"{1000 * searches['every interval']:.2f} ms "
          f"({searches['every interval'] / searches['fast']:.2f}x); / remap: "
          f"{searches['fast'] / base:.1f} and {searches['every interval'] / base:.1f}")
    print()
    off = {name: [0, 0] for name in streams}
    for name, results in kept.items():  # (after the timing)
        for phase, mask, seen in results:
            error = np.abs(phase - 2 * np.pi * seen / 48)[mask]
            off[name][0] += int(np.sum(error[np.isfinite(error)] > np.pi))  # an order off
            off[name][1] += int(mask.sum())
    for name, values in shares.items():
        print(f"decided, --window {name}: {100 * min(values):.1f}-{100 * max(values):.1f}% "
              f"of the decoded left pixels; an order off: {off[name][0]} of {off[name][1]} "
              f"({100 * off[name][0] / max(off[name][1], 1):.3f}%)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
