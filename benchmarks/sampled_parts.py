"""Do the disagreeing parts found from a 2 x 2 sample (``bistair.core.parts.split_parts``:
flagged on the sample, split at full resolution inside each flagged part's box) equal those
the whole image gives (``split_disagreeing``)? And what does the sample save?

Each rendered scene (every preset with objects, 640 x 512, hard and default optics of
``benchmarks/robustness.py``, three seeds) is decoded both ways: the parts detached, the
pixels whose order differs, order error rate, coverage and the worst object's share decoded
right (``bistair.evaluation.metrics.score``), and the share of the image the boxes cover
(the full-resolution work left).

    python benchmarks/sampled_parts.py [--seeds 3]
    python benchmarks/sampled_parts.py --real
    python benchmarks/sampled_parts.py --speed [--size 1.3|12]

``--real`` decodes every real capture in ../shared/data part by part
(``tests/support/real_parts.py``) and, at each split of a region decoder (whatever its
agreement: one that judges the whole image alone is judged through :func:`as_windowed`),
compares the split from the sample with the whole image's.

``--speed`` times both on the default decode's own inputs (one kernel thread, process CPU
time, the minimum of interleaved rounds, the OpenCV floor alongside).
"""

from __future__ import annotations

import argparse
import itertools
import sys
import time
from pathlib import Path

import cv2
import numpy as np
from robustness import DEFAULT, HARD

import bistair
from bistair.core import parts, resolve
from bistair.evaluation.metrics import score
from bistair.sim import Imaging, expose, preset, preset_spec, trace

SCENES = ("sphere-on-plane", "paper-sim", "two-masks", "mask-prism", "two-sculptures",
          "objects-on-plane", "mugs-on-wall")
MODES = {"full": parts.split_disagreeing, "sampled": parts.split_parts}


def watched_boxes(seen: dict):
    """``parts.sample_boxes`` that keeps the share of the image its boxes cover."""
    kept = parts.sample_boxes

    def boxes(labels, *args):
        found = kept(labels, *args)
        seen["box"] = sum((y1 - y0) * (x1 - x0) for y0, y1, x0, x1 in found) / labels.size
        return found

    return boxes


def as_windowed(agrees):
    """Any agreement as a :func:`~bistair.core.parts.windowed` one: the orders of
    ``image[at]`` placed in a whole image of -1 and judged there (as slow as the whole
    image; for comparisons)."""

    @parts.windowed
    def windowed(k, at=parts.ALL):
        full = np.full(shape, -1, k.dtype)
        full[at] = k
        return np.asarray(agrees(full), bool)[at]

    shape = None

    def bind(labels_shape):
        nonlocal shape
        shape = labels_shape
        return windowed

    return bind


def same_split(labels, n, k_reg, agrees) -> tuple[bool, int]:
    """Whether ``split_parts`` (through :func:`as_windowed` unless ``agrees`` is windowed)
    gives what ``split_disagreeing`` gives; and the parts detached."""
    full = parts.split_disagreeing(labels, n, k_reg, agrees)
    if not getattr(agrees, "windowed", False):
        agrees = as_windowed(agrees)(labels.shape)
    sampled = parts.split_parts(labels, n, k_reg, agrees)
    same = (np.array_equal(full[0], sampled[0]) and full[1:] == sampled[1:])
    return same, full[2]


def real(names: str = "") -> int:
    """Every real part's splits compared; returns how many differ."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from support.real_parts import parts as real_parts

    from bistair.io.read import read_with_spec

    differ = 0
    for name, folder, spec, options in real_parts():
        if names and names not in name:
            continue
        seen = []

        def split(labels, n, k_reg, agrees, *args, seen=seen):
            seen.append(same_split(labels, n, k_reg, agrees))
            return parts.split_disagreeing(labels, n, k_reg, agrees, *args)

        stack, spec = read_with_spec(folder, spec)
        resolve.split_parts = split
        try:
            bistair.decode(stack, spec, force=True, **options)
        finally:
            resolve.split_parts = parts.split_parts
        differ += sum(not same for same, _ in seen)
        print(f"{name:40s} splits {len(seen)}: the same {sum(s for s, _ in seen)}, parts "
              f"detached {[d for _, d in seen]}", flush=True)
    print(f"splits that differ: {differ}")
    return differ


def quality(seeds: int) -> None:
    seen: dict = {}
    same = 0
    rows = list(itertools.product(SCENES, (("hard", HARD), ("default", DEFAULT)),
                                  range(1, seeds + 1)))
    kept = parts.sample_boxes
    parts.sample_boxes = watched_boxes(seen)
    try:
        for name, (optics, params), seed in rows:
            rig, sc = preset(name, camera_size=(640, 512))
            spec = preset_spec(name, "bidirectional")
            imaging = Imaging(**params, seed=seed)
            traced = trace(rig, sc, imaging)
            images = expose(traced, bistair.encode(spec), imaging)
            out = {}
            for mode, split in MODES.items():
                seen["box"] = 0.0
                resolve.split_parts = split
                try:
                    result = bistair.decode(images, spec, force=True)
                finally:
                    resolve.split_parts = parts.split_parts
                out[mode] = result, score(result, traced.truth.coord(spec),
                                          traced.truth.mask, traced.truth.object_id)
            (full, sf), (samp, ss) = out["full"], out["sampled"]
            differ = int((full.order != samp.order).sum())
            same += differ == 0 and np.array_equal(full.phase, samp.phase, equal_nan=True)

            def worst(s):
                return min(s["objects"].values()) if s.get("objects") else float("nan")

            print(f"{name:17s} {optics:7s} seed {seed}: detached "
                  f"{full.info['regions_detached']} -> {samp.info['regions_detached']}, "
                  f"{differ:5d} px differ, boxes {seen['box']:.3f}; order errors "
                  f"{sf['order_error_rate']:.5f} -> {ss['order_error_rate']:.5f}, coverage "
                  f"{sf['coverage']:.4f} -> {ss['coverage']:.4f}, worst object "
                  f"{worst(sf):.4f} -> {worst(ss):.4f}", flush=True)
    finally:
        parts.sample_boxes = kept
    print(f"orders and phases the same in {same} of {len(rows)}")


def speed(size: str, count: int) -> None:
    from labelspace_speed import rounds, scene

    from bistair.core.jit import set_threads
    from bistair.core.memory import keep_freed_memory
    from bistair.evaluation.speed import opencv_floor

    keep_freed_memory()
    set_threads(1)
    cv2.setNumThreads(1)
    frames, spec = scene(size)
    seen: dict = {}

    def watched(*args):
        seen.setdefault("args", args)
        return parts.split_parts(*args)

    resolve.split_parts = watched
    try:
        bistair.decode(frames, spec)
    finally:
        resolve.split_parts = parts.split_parts
    args = seen["args"]
    jobs = {"floor": lambda: opencv_floor(frames)}
    jobs.update({mode: (lambda split=split: split(*args)) for mode, split in MODES.items()})
    found = {mode: job() for mode, job in jobs.items() if mode != "floor"}
    same = all(np.array_equal(a, b) for a, b in zip(found["full"], found["sampled"],
                                                     strict=True))
    best = rounds(jobs, count, time.process_time)
    print(f"{size} MP {args[0].shape}, one thread, CPU time, min of {count} rounds; parts "
          f"detached {found['full'][2]}, the same both ways: {same}")
    for key, t in best.items():
        print(f"  {key:10s} {1e3 * t:8.2f} ms  {t / best['floor']:6.2f} x floor")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--speed", action="store_true")
    parser.add_argument("--real", action="store_true")
    parser.add_argument("--size", default="1.3", choices=("1.3", "12"))
    parser.add_argument("--rounds", type=int, default=10)
    args = parser.parse_args()
    if args.speed:
        speed(args.size, args.rounds)
    elif args.real:
        real()
    else:
        quality(args.seeds)


if __name__ == "__main__":
    main()
