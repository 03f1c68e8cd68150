"""The decode's per-pixel front end against the OpenCV floor, in the same rounds: pass 0
(the camera noise and the checks' sample from a sparse grid), pass 1 (every pixel of the
N-step set and its stair pair in one pass over row tiles) and the stair code's
quantisation, on ``decode_speed.py``'s scene (bidirectional 8x8, uint8) at 1.3 and 12 MP;
and, with ``--before SRC`` (the ``src`` folder of an earlier checkout, loaded beside this
one as the package ``bistair_before``), the stages that computed the same maps there
(prepare's clipped mask, ``nstep_sums``, ``phase_of_sums``, ``noise_level``,
``pixel_validity``, ``phase_noise``, ``pair_phase``, ``quantize32``) and the whole default
decode of both.

One kernel thread and one OpenCV thread, process CPU time (``time.process_time``: not
inflated by time spent descheduled on a loaded machine), the minimum over interleaved
rounds, each figure also as a ratio to the floor's minimum of the same run (``cv2.subtract``
x2 into float32, ``cv2.phase``, ``cv2.magnitude``).

    python benchmarks/front_end_speed.py [--sizes 1.3,12] [--rounds 7] [--before SRC]
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import sys
import time
from pathlib import Path

import cv2
import numpy as np

import bistair
from bistair.codecs import get_codec
from bistair.core.jit import set_threads
from bistair.core.measure import measure
from bistair.core.memory import keep_freed_memory
from bistair.core.sample import set_noise, take_sample
from bistair.core.stair_jit import quantize32

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bistair.evaluation.speed import CASES, opencv_floor, speed_captures  # noqa: E402

SIZES = {"1.3": (1024, 1280), "12": (3000, 4000)}


def load_before(src: str):
    """The package ``bistair`` of another checkout, imported as ``bistair_before``."""
    init = Path(src) / "bistair" / "__init__.py"
    spec = importlib.util.spec_from_file_location("bistair_before", init,
                                                  submodule_search_locations=[str(init.parent)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["bistair_before"] = module
    spec.loader.exec_module(module)
    return module


def before_stages(old, frames: np.ndarray, spec) -> dict:
    """The earlier checkout's front-end stages, each a function of no argument."""
    captures = _import("bistair_before.core.captures")
    phase = _import("bistair_before.core.phase")
    phase_jit = _import("bistair_before.core.phase_jit")
    measure_mod = _import("bistair_before.core.measure")
    measure_jit = _import("bistair_before.core.measure_jit")
    stair_jit = _import("bistair_before.core.stair_jit")
    codec = old.codecs.get_codec(spec.method)
    _, cols = codec._columns(frames, spec_before(old, spec))
    shifts = phase.shifts_of(4, 1)
    sin_w, cos_w = np.sin(shifts).astype(np.float32), np.cos(shifts).astype(np.float32)
    scale = float(cols.scale)
    num, den, avg = phase_jit.nstep_sums(cols.raw, 0, 4, scale, sin_w, cos_w)
    phi, mod = phase.phase_of_sums(num, den, 4)
    valid = measure_jit.pixel_validity(mod, avg, cols.clipped, 0.02, 0.04)[0]
    theta = stair_jit.pair_phase(cols.raw, 4, cols.scale, avg)[0]
    stack = captures.ScaledStack(cols.raw[:4], scale)
    used = cols.raw
    return {
        "before: prepare's clipped": lambda: used.max(axis=0) >= 255.0,
        "before: nstep_sums": lambda: phase_jit.nstep_sums(cols.raw, 0, 4, scale, sin_w, cos_w),
        "before: phase_of_sums": lambda: phase.phase_of_sums(num, den, 4),
        "before: noise_level": lambda: measure_mod.noise_level(stack, phi, avg, mod),
        "before: pixel_validity": lambda: measure_jit.pixel_validity(mod, avg, cols.clipped,
                                                                     0.02, 0.04),
        "before: phase_noise": lambda: measure_jit.phase_noise(mod, 0.01, 4),
        "before: pair_phase": lambda: stair_jit.pair_phase(cols.raw, 4, cols.scale, avg),
        "before: quantize32": lambda: stair_jit.quantize32(theta, 8, valid),
    }


def _import(name: str):
    return importlib.import_module(name)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1.3,12")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--before", default=None, help="src folder of an earlier checkout")
    args = parser.parse_args()
    keep_freed_memory()
    set_threads(1)
    cv2.setNumThreads(1)
    old = load_before(args.before) if args.before else None
    for key in args.sizes.split(","):
        run(key, args.rounds, old)


def run(key: str, rounds: int, old) -> None:
    """Time the stages at one size and print the table."""
    spec = CASES[0].spec()
    frames = speed_captures(spec, SIZES[key])
    _, cols = get_codec(spec.method)._columns(frames, spec)
    fs = measure(cols, 0, spec.steps, pair=spec.steps)
    noise, threshold = fs.noise, fs.threshold
    lowest = max(0.005, 2.0 * noise)
    stages = {
        "floor (OpenCV 4-step pass)": lambda: opencv_floor(frames),
        "pass 0: noise (set_noise)": lambda: set_noise(cols, 0, spec.steps),
        "pass 0: the sample (take_sample)": lambda: take_sample(
            cols, 0, spec.steps, spec.steps, lowest, threshold),
        "pass 1 (front_end)": _front_end_call(cols, spec, lowest, threshold, noise),
        "quantize32": lambda: quantize32(fs.stair[0], spec.stairs, fs.valid),
        "decode (default)": lambda: bistair.decode(frames, spec),
    }
    if old is not None:
        stages.update(before_stages(old, frames, spec))
        old_spec = spec_before(old, spec)
        stages["before: decode (default)"] = lambda: old.decode(frames, old_spec)
    for fn in stages.values():
        fn()
    best = {name: np.inf for name in stages}
    for _ in range(rounds):
        for name, fn in stages.items():
            t0 = time.process_time()
            fn()
            best[name] = min(best[name], time.process_time() - t0)
    floor = best["floor (OpenCV 4-step pass)"]
    h, w = frames.shape[1:]
    print(f"\n{w}x{h} ({h * w / 1e6:.1f} MP), one thread, process CPU time, min of "
          f"{rounds} interleaved rounds")
    print(f"{'stage':<40} {'ms':>8} {'/ floor':>8}")
    for name, t in best.items():
        print(f"{name:<40} {1e3 * t:8.2f} {t / floor:8.2f}")
    new = sum(best[n] for n in best if n.startswith(("pass", "quantize")))
    print(f"{'front end now (sum)':<40} {1e3 * new:8.2f} {new / floor:8.2f}")
    if old is not None:
        was = sum(t for n, t in best.items() if n.startswith("before:") and "decode" not in n)
        print(f"{'front end before (sum)':<40} {1e3 * was:8.2f} {was / floor:8.2f}")


def _front_end_call(cols, spec, lowest: float, threshold: float, noise: float):
    """Pass 1 alone, as measure calls it."""
    from bistair.core.measure_jit import front_end
    from bistair.core.phase_jit import offset_parts, shift_weights
    from bistair.core.sample import clip_level, kernel_view

    raw, first, pair = kernel_view(cols, 0, spec.steps, spec.steps)
    none = np.zeros((1, 1), np.float32)
    args = (raw, first, spec.steps, pair, float(cols.scale),
            *shift_weights(spec.steps, spec.shift_sign), *offset_parts(spec.phase_offset),
            clip_level(cols), float(lowest), float(threshold),
            np.float32(noise / np.sqrt(spec.steps / 2.0)), none, none, False)
    return lambda: front_end(*args)


def spec_before(old, spec):
    return old.spec_from_dict(spec.to_dict())


if __name__ == "__main__":
    main()
