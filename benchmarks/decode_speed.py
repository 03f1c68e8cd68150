"""Decoding speed of every codec against bare NumPy ``arctan2`` on the same frames.

For 1.3 MP (1280 x 1024) and 12 MP (4000 x 3000) captures, 8-bit, each codec's decode
time (median of several runs) is printed next to the bare 4-step NumPy phase on the same
frames, measured in the same run (the machine is shared and noisy: the ratio is the
figure), with megapixels per second and the peak memory of a decode in a fresh process,
per camera pixel beyond the input stack. The compiled kernels' first-call cost is measured
in a fresh process with an empty numba cache. ``numpy.show_runtime()`` says which vector
units NumPy's ``arctan2`` uses. If comimag's ``fringes`` package is installed, its
three-frequency decode is timed too.

The decodes are timed as the command line runs them, with freed memory kept for the next
arrays (:func:`bistair.core.memory.keep_freed_memory`); the default decoder is also timed
with glibc's default allocator settings (``system malloc``), which is what
``bistair.decode`` from Python gets unless asked. The memory figure is always measured
with the default settings.

    python benchmarks/decode_speed.py [--runs 5] [--sizes 1.3,12] [--threads N]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import bistair
from bistair.core.jit import set_threads
from bistair.core.memory import keep_freed_memory
from bistair.sim.warp import Blob, WarpScene, render_warp

SIZES = {"1.3": (1024, 1280), "12": (3000, 4000)}
CASES = [  # label, spec parameters, decode options
    ("bidirectional 8x8 (region)", dict(method="bidirectional", width=1920, height=1080,
                                        period=30, partitions=8, stairs=8), {}),
    ("bidirectional 8x8 (paper)", dict(method="bidirectional", width=1920, height=1080,
                                       period=30, partitions=8, stairs=8),
     {"strategy": "paper"}),
    ("multifreq 1920/240/30 x4", dict(method="multifreq", width=1920, height=1080,
                                      periods=(1920, 240, 30)), {}),
    ("phase-coding 64 levels", dict(method="phase-coding", width=1920, height=1080,
                                    period=30), {}),
    ("lv 64 fringes", dict(method="lv", width=1920, height=1080, period=30), {}),
    ("graycode complementary", dict(method="graycode", width=1920, height=1080, period=30,
                                    complementary=1), {}),
]


def spec_of(params: dict) -> bistair.spec.BaseSpec:
    params = dict(params)
    return bistair.make_spec(params.pop("method"), **params)


def captures(spec, size: tuple[int, int]) -> np.ndarray:
    """8-bit captures of a scene: a dome-shaped object and two small ones on a dark field,
    seen with a stretch, a vertical scale and a slight roll (the warp renderer)."""
    h, w = size
    k = w / 1280
    scene = WarpScene(size=size, stretch=1.4 / k, offset=20.0, scale_top=0.8 / k,
                      scale_bottom=1.3 / k, roll_deg=1.0, blur=1.0, noise=0.01, seed=0,
                      supersample=1, bits=None,
                      blobs=(Blob(450 * k, 500 * k, 380 * k, 450 * k, dome=40, albedo=0.8),
                             Blob(1000 * k, 300 * k, 100 * k, 120 * k, shift=30, dome=5,
                                  albedo=0.7),
                             Blob(1050 * k, 750 * k, 150 * k, 200 * k, shift=-80, dome=20,
                                  albedo=0.6)))
    images, _ = render_warp(spec, scene)
    return np.round(np.clip(images, 0, 1) * 255).astype(np.uint8)


def timed(func, runs: int) -> float:
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def bare_arctan2(frames: np.ndarray) -> np.ndarray:
    """The floor any decoder pays: float conversion and one arctangent per pixel."""
    f = frames[:4].astype(np.float32)
    return np.arctan2(f[3] - f[1], f[0] - f[2])


# Peak memory of the second (warm) decode, from /proc/self/status: VmHWM reset (clear_refs
# 5) just before it and VmRSS read then; ru_maxrss would start at the parent's peak
# (inherited over fork) and the first decode also loads the modules and kernels.
_CHILD = """
import json, sys, time
import numpy as np
import bistair
def status(key):
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith(key + ":"))
frames = np.load(sys.argv[1])
spec = bistair.spec_from_dict(json.loads(sys.argv[2]))
options = json.loads(sys.argv[3])
t0 = time.perf_counter()
bistair.decode(frames, spec, **options)
first = time.perf_counter() - t0
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")
before = status("VmRSS")
t0 = time.perf_counter()
bistair.decode(frames, spec, **options)
warm = time.perf_counter() - t0
peak = status("VmHWM")
print(json.dumps({"first": first, "warm": warm, "peak_kb": peak - before}))
"""


def fresh_process(frames: np.ndarray, spec, options: dict, cache: str | None) -> dict:
    """First-call time, warm time and peak resident memory growth of one decode in a new
    process (``cache``: a numba cache folder, empty to count compiling)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "frames.npy"
        np.save(path, frames)
        # a fixed mmap threshold: freed arrays leave the resident set, so the warm decode's
        # peak is its own and not hidden in memory glibc kept from the first
        env = {**os.environ, "MALLOC_MMAP_THRESHOLD_": "131072",
               "MALLOC_TRIM_THRESHOLD_": "131072"}
        if cache is not None:
            env["NUMBA_CACHE_DIR"] = cache
        out = subprocess.run([sys.executable, "-c", _CHILD, str(path), spec.to_json(),
                              json.dumps(options)], capture_output=True, text=True, env=env,
                             check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def fringes_three_frequency(size: tuple[int, int], runs: int) -> str:
    try:
        import fringes  # comimag/Fringes, optional
    except ImportError:
        return "comimag fringes: not installed (pip install fringes to compare)"
    f = fringes.Fringes()
    f.X, f.Y = size[1], size[0]
    f.K = 3
    f.N = 8
    I = f.encode()  # noqa: E741 - their name
    t = timed(lambda: f.decode(I), runs)
    return f"comimag fringes 3 frequencies x 8 steps: {1e3 * t:.0f} ms"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--sizes", default="1.3,12")
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--no-memory", action="store_true", help="skip the fresh processes")
    args = parser.parse_args()
    threads = set_threads(args.threads)
    np.show_runtime()
    kept = keep_freed_memory()
    print(f"\nnumba threads: {threads}; cores: {os.cpu_count()}; freed memory kept for the "
          f"next arrays: {'yes' if kept else 'no (not glibc)'}")
    for key in args.sizes.split(","):
        size = SIZES[key]
        mpix = size[0] * size[1] / 1e6
        print(f"\ncaptures {size[1]}x{size[0]} ({mpix:.1f} MP), 8 bit, median of "
              f"{args.runs} runs")
        print(f"{'codec':<30} {'decode':>9} {'MP/s':>6} {'arctan2':>9} {'ratio':>6} "
              f"{'B/px':>6} {'first call':>11} {'compile':>9}")
        for label, params, options in CASES:
            spec = spec_of(params)
            frames = captures(spec, size)
            bistair.decode(frames, spec, **options)  # warm up (compiled kernels)
            runs = args.runs if mpix < 5 else max(2, args.runs // 2)
            t_dec = timed(lambda f=frames, s=spec, o=options: bistair.decode(f, s, **o), runs)
            t_atan = timed(lambda f=frames: bare_arctan2(f), runs)
            mem = first = compile_s = ""
            if not args.no_memory:
                warm_cache = fresh_process(frames, spec, options, None)
                mem = f"{1024 * warm_cache['peak_kb'] / (size[0] * size[1]):6.1f}"
                first = f"{1e3 * warm_cache['first']:9.0f}ms"
                with tempfile.TemporaryDirectory() as cache:
                    cold = fresh_process(frames, spec, options, cache)
                compile_s = f"{cold['first'] - cold['warm']:7.1f}s"
            print(f"{label:<30} {1e3 * t_dec:7.0f}ms {mpix / t_dec:6.1f} "
                  f"{1e3 * t_atan:7.1f}ms {t_atan / t_dec:6.3f} {mem:>6} {first:>11} "
                  f"{compile_s:>9}", flush=True)
            if not options and params["method"] == "bidirectional" and kept:
                keep_freed_memory(False)
                t_sys = timed(lambda f=frames, s=spec: bistair.decode(f, s), runs)
                t_atan = timed(lambda f=frames: bare_arctan2(f), runs)
                keep_freed_memory(True)
                print(f"{'  the same, system malloc':<30} {1e3 * t_sys:7.0f}ms "
                      f"{mpix / t_sys:6.1f} {1e3 * t_atan:7.1f}ms {t_atan / t_sys:6.3f}",
                      flush=True)
        print(fringes_three_frequency(size, args.runs))


if __name__ == "__main__":
    main()
