"""Decoding speed on 1280x1024 captures: median of several runs, megapixels per second.

Prints, for each codec, its decode time next to bare NumPy 4-step ``arctan2`` on the same
frames (the floor any decoder pays: float conversion and one arctangent per pixel).

    python benchmarks/decode_speed.py [--runs 7]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import bistair
from bistair.sim.warp import Blob, WarpScene, render_warp

SIZE = (1024, 1280)


def scenes() -> dict[str, WarpScene]:
    base = dict(size=SIZE, stretch=1.4, offset=20.0, scale_top=0.8, scale_bottom=1.3,
                roll_deg=1.0, blur=1.0, noise=0.01, seed=0)
    objects = (Blob(450, 500, 380, 450, dome=40, albedo=0.8),
               Blob(1000, 300, 100, 120, shift=30, dome=5, albedo=0.7),
               Blob(1050, 750, 150, 200, shift=-80, dome=20, albedo=0.6))
    return {"full field": WarpScene(**base), "objects": WarpScene(blobs=objects, **base)}


def timed(func, runs: int) -> float:
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def bare_arctan2(frames: np.ndarray) -> np.ndarray:
    f = frames[:4].astype(np.float32)
    return np.arctan2(f[3] - f[1], f[0] - f[2])


def cases() -> list[tuple[str, dict, dict]]:
    """(label, spec parameters, decode options) for every codec measured."""
    return [
        ("bidirectional 8x8 (region)",
         dict(method="bidirectional", width=1920, height=1080, period=30, partitions=8,
              stairs=8), {}),
        ("bidirectional 8x8 (paper)",
         dict(method="bidirectional", width=1920, height=1080, period=30, partitions=8,
              stairs=8), {"strategy": "paper"}),
        ("multifreq 1920/240/30 x4",
         dict(method="multifreq", width=1920, height=1080, periods=(1920, 240, 30)), {}),
        ("phase-coding 64 levels",
         dict(method="phase-coding", width=1920, height=1080, period=30), {}),
        ("lv 64 fringes, 4 levels",
         dict(method="lv", width=1920, height=1080, period=30), {}),
        ("graycode complementary",
         dict(method="graycode", width=1920, height=1080, period=30, complementary=1), {}),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    args = parser.parse_args()
    mpix = SIZE[0] * SIZE[1] / 1e6
    print(f"captures {SIZE[1]}x{SIZE[0]} ({mpix:.2f} MP), median of {args.runs} runs")
    print(f"{'codec':<34} {'scene':<11} {'decode':>9} {'MP/s':>7} {'arctan2':>9} {'MP/s':>7}")
    for label, params, options in cases():
        params = dict(params)
        spec = bistair.make_spec(params.pop("method"), **params)
        for name, scene in scenes().items():
            images, _ = render_warp(spec, scene)
            frames = (images * 255).round().astype(np.uint8)
            bistair.decode(frames, spec, **options)  # warm up
            t_dec = timed(lambda f=frames, s=spec, o=options: bistair.decode(f, s, **o),
                          args.runs)
            t_atan = timed(lambda f=frames: bare_arctan2(f), args.runs)
            print(f"{label:<34} {name:<11} {1e3 * t_dec:7.0f}ms {mpix / t_dec:7.1f} "
                  f"{1e3 * t_atan:7.1f}ms {mpix / t_atan:7.1f}")


if __name__ == "__main__":
    main()
