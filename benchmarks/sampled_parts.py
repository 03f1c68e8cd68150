"""Would a 2 x 2 sample find the disagreeing parts of regions that the full-resolution
detection finds (issue 32 part C, not done in the decoder)? A measurement of a prototype,
not the decoder's code.

The prototype (:func:`sampled`) replaces ``bistair.core.resolve.split_disagreeing`` for one
decode: it takes every second row and column of the bad (a decided pixel whose stair
reading does not fit its region's order) and decided maps, seeds where more than
``--share`` of a ``--window`` x ``--window`` neighbourhood of the sample's decided pixels is
bad (``window_seeds``), and, if any, runs today's detection with only the pixels inside
the bounding box of the sampled bad components holding a seed (a margin of two full-size
windows) counted as bad. Each rendered scene (every preset with objects, 640 x 512, hard
and default optics of ``benchmarks/robustness.py``, three seeds) is decoded with today's
detection and with the prototype: the parts detached, the pixels whose order differs,
order error rate, coverage and the worst object's share decoded right
(``bistair.evaluation.metrics.score``), and the share of the image the box covers (the
full-resolution work left).

    python benchmarks/sampled_parts.py [--window 4] [--share 0.5] [--seeds 3]
    python benchmarks/sampled_parts.py --speed [--size 1.3|12]

``--speed`` times instead what the sample saves at most: the default decode's own inputs to
``pixel_orders`` and ``stair_agreement`` at full resolution and on the sample (one kernel
thread, process CPU time, the minimum of interleaved rounds, the OpenCV floor alongside).
"""

from __future__ import annotations

import argparse
import itertools
import time

import cv2
import numpy as np
from robustness import DEFAULT, HARD

import bistair
from bistair.core import resolve
from bistair.core.resolve_jit import pixel_orders, window_seeds
from bistair.evaluation.metrics import score
from bistair.sim import Imaging, expose, preset, preset_spec, trace

SCENES = ("sphere-on-plane", "paper-sim", "two-masks", "mask-prism", "two-sculptures",
          "objects-on-plane", "mugs-on-wall")
FULL = resolve.split_disagreeing


def sampled(window_s: int, share_s: float, seen: dict):
    """A ``split_disagreeing`` that seeds on the 2 x 2 sample and runs the full detection
    only inside the seeded components' box (``seen["box"]``: its share of the image)."""

    def split(labels, n, k_reg, agrees, window=7, share=0.7, min_size=30):
        k_pix = pixel_orders(labels, np.asarray(k_reg))
        decided = k_pix >= 0
        # the agreement is per pixel: the sample's is the full map's, sampled
        bad = ~np.asarray(agrees(k_pix), bool) & decided
        bad_s, decided_s = bad[::2, ::2].copy(), decided[::2, ::2].copy()
        seen["box"] = 0.0
        if min(bad_s.shape) < window_s or not bad_s.any():
            return labels, n, 0
        seeds_s, _ = window_seeds(bad_s, decided_s, window_s, share_s)
        if not seeds_s.any():
            return labels, n, 0
        _, comp = cv2.connectedComponents(bad_s.view(np.uint8), connectivity=8)
        keep = np.zeros(int(comp.max()) + 1, bool)
        keep[comp[seeds_s]] = True
        keep[0] = False
        ys, xs = np.nonzero(keep[comp])
        m = 2 * window
        box = np.zeros(labels.shape, bool)
        box[max(2 * ys.min() - m, 0):2 * ys.max() + m + 2,
            max(2 * xs.min() - m, 0):2 * xs.max() + m + 2] = True
        seen["box"] = float(box.mean())
        return FULL(labels, n, k_reg, lambda k: np.asarray(agrees(k), bool) | ~box, window,
                    share, min_size)

    return split


def quality(window_s: int, share_s: float, seeds: int) -> None:
    seen: dict = {}
    same = 0
    rows = list(itertools.product(SCENES, (("hard", HARD), ("default", DEFAULT)),
                                  range(1, seeds + 1)))
    for name, (optics, params), seed in rows:
        rig, sc = preset(name, camera_size=(640, 512))
        spec = preset_spec(name, "bidirectional")
        imaging = Imaging(**params, seed=seed)
        traced = trace(rig, sc, imaging)
        images = expose(traced, bistair.encode(spec), imaging)
        out = {}
        for mode in ("full", "sampled"):
            resolve.split_disagreeing = FULL if mode == "full" else sampled(window_s, share_s,
                                                                            seen)
            try:
                result = bistair.decode(images, spec, force=True)
            finally:
                resolve.split_disagreeing = FULL
            out[mode] = result, score(result, traced.truth.coord(spec), traced.truth.mask,
                                      traced.truth.object_id)
        (full, sf), (samp, ss) = out["full"], out["sampled"]
        differ = int((full.order != samp.order).sum())
        same += differ == 0

        def worst(s):
            return min(s["objects"].values()) if s.get("objects") else float("nan")

        print(f"{name:17s} {optics:7s} seed {seed}: detached {full.info['regions_detached']}"
              f" -> {samp.info['regions_detached']}, {differ:5d} px differ, box "
              f"{seen.get('box', 0.0):.3f}; order errors {sf['order_error_rate']:.5f} -> "
              f"{ss['order_error_rate']:.5f}, coverage {sf['coverage']:.4f} -> "
              f"{ss['coverage']:.4f}, worst object {worst(sf):.4f} -> {worst(ss):.4f}",
              flush=True)
    print(f"window {window_s}, share {share_s}: orders the same in {same} of {len(rows)}")


def speed(size: str, count: int) -> None:
    from labelspace_speed import rounds, scene

    from bistair.codecs import bidirectional
    from bistair.core.jit import set_threads
    from bistair.core.memory import keep_freed_memory
    from bistair.evaluation.speed import opencv_floor

    keep_freed_memory()
    set_threads(1)
    cv2.setNumThreads(1)
    frames, spec = scene(size)
    seen: dict = {}
    kept = resolve.pixel_orders, bidirectional.stair_agreement

    def watch(name, func):
        def watched(*args):
            seen.setdefault(name, args)
            return func(*args)
        return watched

    resolve.pixel_orders = watch("orders", kept[0])
    bidirectional.stair_agreement = watch("agreement", kept[1])
    try:
        bistair.decode(frames, spec)
    finally:
        resolve.pixel_orders, bidirectional.stair_agreement = kept
    labels, k_reg = seen["orders"]
    ks, theta, k, stairs, partitions = seen["agreement"]

    def half(a):
        return np.ascontiguousarray(a[::2, ::2])

    labels2, ks2, theta2, k2 = half(labels), half(ks), half(theta), half(k)
    jobs = {"floor": lambda: opencv_floor(frames),
            "pixel_orders full": lambda: kept[0](labels, k_reg),
            "pixel_orders 2x2": lambda: kept[0](labels2, k_reg),
            "stair_agreement full": lambda: kept[1](ks, theta, k, stairs, partitions),
            "stair_agreement 2x2": lambda: kept[1](ks2, theta2, k2, stairs, partitions)}
    for job in jobs.values():
        job()
    best = rounds(jobs, count, time.process_time)
    print(f"{size} MP {labels.shape}, one thread, CPU time, min of {count} rounds")
    for key, t in best.items():
        print(f"  {key:24s} {1e3 * t:8.2f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--window", type=int, default=4, help="window on the sample")
    parser.add_argument("--share", type=float, default=0.5, help="bad share on the sample")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--speed", action="store_true")
    parser.add_argument("--size", default="1.3", choices=("1.3", "12"))
    parser.add_argument("--rounds", type=int, default=10)
    args = parser.parse_args()
    if args.speed:
        speed(args.size, args.rounds)
    else:
        quality(args.window, args.share, args.seeds)


if __name__ == "__main__":
    main()
