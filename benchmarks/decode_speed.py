"""Decoding speed of every codec against the OpenCV floor of a 4-step decode, in the same run.

For 1.3 MP (1280 x 1024) and 12 MP (4000 x 3000) captures, 8-bit, each codec's decode time
(median of several runs) is printed next to the least work any 4-step decode must do on the
same frames: two frame differences, their phase and magnitude (``cv2.subtract`` into
float32, ``cv2.phase``, ``cv2.magnitude``), timed between the decodes (the machine is shared
and noisy: the ratio decode / floor, the median of the runs' own ratios, is the figure;
targets: at most 25 at 1.3 MP, 15 at 12 MP). Also printed: megapixels and scans (one capture
set) per second, each codec's ratio against the default decoder's, the peak memory of a
decode in a fresh process per camera pixel beyond the input stack, and two cold starts in
fresh processes with an empty numba cache (``NUMBA_CACHE_DIR``): the first call with the
kernels compiled at install time (``bistair/_kernels``, see ``setup.py``; ``-`` if this
checkout has none: ``python -m bistair.app.kernels src/bistair/_kernels`` makes them) and
the compile of a first call without them (``BISTAIR_KERNELS=none``: first call less a warm
one). ``numpy.show_runtime()`` says which vector units NumPy uses. If comimag's
``fringes`` package is installed, its three-frequency decode is timed too.

The decodes are timed as the command line runs them, with freed memory kept for the next
arrays (:func:`bistair.core.memory.keep_freed_memory`); the default decoder is also timed
with glibc's default allocator settings (``system malloc``), which is what
``bistair.decode`` from Python gets unless asked. The memory figure is always measured
with the default settings.

    python benchmarks/decode_speed.py [--runs 5] [--sizes 1.3,12] [--threads N] [--no-memory]
                                      [--codecs 0,2]
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

import cv2
import numpy as np

import bistair
from bistair.core.jit import set_threads
from bistair.core.memory import keep_freed_memory
from bistair.sim.warp import Blob, WarpScene, render_warp

try:
    from bistair.core.jit import prebuilt_folder
except ImportError:  # a build from before the kernels were compiled at install time
    def prebuilt_folder() -> None:
        return None

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


def opencv_floor(frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The least work a 4-step decode does: two frame differences (float32), their phase and
    magnitude, in OpenCV."""
    b = cv2.subtract(frames[3], frames[1], dtype=cv2.CV_32F)
    a = cv2.subtract(frames[0], frames[2], dtype=cv2.CV_32F)
    return cv2.phase(a, b), cv2.magnitude(a, b)


def interleaved(decode, frames: np.ndarray, runs: int) -> tuple[float, float, list[float]]:
    """Median decode time, median floor time and each run's ratio: every decode is followed
    by the floor (the best of five: a pass of a few ms that one busy moment would spoil)."""
    dec, flo, ratios = [], [], []
    for _ in range(runs):
        t0 = time.perf_counter()
        decode()
        t1 = time.perf_counter()
        floor = min(timed(lambda: opencv_floor(frames), 1) for _ in range(5))
        dec.append(t1 - t0)
        flo.append(floor)
        ratios.append((t1 - t0) / floor)
    return statistics.median(dec), statistics.median(flo), ratios


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


def fresh_process(frames: np.ndarray, spec, options: dict, cache: str | None,
                  prebuilt: bool = True) -> dict:
    """First-call time, warm time and peak resident memory growth of one decode in a new
    process (``cache``: a numba cache folder, empty for a cold start; ``prebuilt``: the
    kernels compiled at install time are read)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "frames.npy"
        np.save(path, frames)
        # a fixed mmap threshold: freed arrays leave the resident set, so the warm decode's
        # peak is its own and not hidden in memory glibc kept from the first
        env = {**os.environ, "MALLOC_MMAP_THRESHOLD_": "131072",
               "MALLOC_TRIM_THRESHOLD_": "131072"}
        if cache is not None:
            env["NUMBA_CACHE_DIR"] = cache
        if not prebuilt:
            env["BISTAIR_KERNELS"] = "none"
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
    parser.add_argument("--codecs", default=None,
                        help="comma-separated indices of the codecs to time (default: all)")
    args = parser.parse_args()
    threads = set_threads(args.threads)
    np.show_runtime()
    kept = keep_freed_memory()
    folder = prebuilt_folder()
    have = folder is not None and any(folder.glob("*.nbi"))
    print(f"\nnumba threads: {threads}; OpenCV threads: {cv2.getNumThreads()}; cores: "
          f"{os.cpu_count()}; freed memory kept for the next arrays: "
          f"{'yes' if kept else 'no (not glibc)'}; kernels compiled at install time: "
          f"{folder if have else 'none'}; load average {os.getloadavg()[0]:.1f}")
    picked = (range(len(CASES)) if args.codecs is None
              else [int(i) for i in args.codecs.split(",")])
    for key in args.sizes.split(","):
        size = SIZES[key]
        mpix = size[0] * size[1] / 1e6
        runs = args.runs if mpix < 5 else max(2, args.runs // 2)
        print(f"\ncaptures {size[1]}x{size[0]} ({mpix:.1f} MP), 8 bit, median of {runs} runs; "
              "floor: OpenCV's 4-step pass on the same frames, timed between the decodes")
        print(f"{'codec':<28} {'decode':>8} {'floor':>7} {'ratio':>6} {'(range)':>8} "
              f"{'MP/s':>5} {'scans/s':>7} {'/default':>8} {'B/px':>5} {'first':>7} "
              f"{'compile':>7}")
        default = None
        for i in picked:
            label, params, options = CASES[i]
            spec = spec_of(params)
            frames = captures(spec, size)
            bistair.decode(frames, spec, **options)  # warm up (compiled kernels)
            t_dec, t_floor, ratios = interleaved(
                lambda f=frames, s=spec, o=options: bistair.decode(f, s, **o), frames, runs)
            ratio = statistics.median(ratios)
            if i == 0:
                default = ratio
            mem = first = compile_s = ""
            if not args.no_memory:
                with tempfile.TemporaryDirectory() as cache:
                    cold = fresh_process(frames, spec, options, cache)
                mem = f"{1024 * cold['peak_kb'] / (size[0] * size[1]):5.1f}"
                first = f"{cold['first']:6.2f}s" if have else "-"
                with tempfile.TemporaryDirectory() as cache:
                    jit = fresh_process(frames, spec, options, cache, prebuilt=False)
                compile_s = f"{jit['first'] - jit['warm']:6.1f}s"
            against = f"{ratio / default:8.2f}" if default else f"{'':8s}"
            print(f"{label:<28} {1e3 * t_dec:6.0f}ms {1e3 * t_floor:5.1f}ms {ratio:6.1f} "
                  f"{f'{min(ratios):.0f}-{max(ratios):.0f}':>8} {mpix / t_dec:5.1f} "
                  f"{1 / t_dec:7.1f} {against} {mem:>5} {first:>7} {compile_s:>7}",
                  flush=True)
            if i == 0 and kept:
                keep_freed_memory(False)
                t_sys, _, r_sys = interleaved(
                    lambda f=frames, s=spec: bistair.decode(f, s), frames, runs)
                keep_freed_memory(True)
                print(f"{'  the same, system malloc':<28} {1e3 * t_sys:6.0f}ms {'':7s} "
                      f"{statistics.median(r_sys):6.1f}", flush=True)
        print(fringes_three_frequency(size, args.runs))


if __name__ == "__main__":
    main()
