"""The fringe-region labellings of a default decode, old passes against new, with the
OpenCV floor of a 4-step decode in the same rounds.

The inputs are the decode's own: one default (bidirectional) decode of
``decode_speed.py``'s scene is run with ``coherent_pixels`` and the codec's
``fringe_regions`` watched, and their arguments kept. Then, in interleaved rounds, each
pass is timed: the passes of bistair 02b6580 (``tests/support/regions_before.py``, compiled
with the same numba options) and their replacements in ``bistair.core.regions_jit`` and
``regions_labels_jit``, the two labellings whole (``fringe_regions``, ``coherent_pixels``)
before and after, and the floor (``cv2.subtract`` x2, ``cv2.phase``, ``cv2.magnitude``).
One kernel thread and process CPU time by default (``time.process_time``, ``set_threads(1)``,
``cv2.setNumThreads(1)``: what a loaded machine still measures well), or ``--wall`` on
every core; the minimum over the rounds is printed, in ms and ns a pixel.

    python benchmarks/regions_speed.py [--size 1.3|12] [--rounds 8] [--wall] [--decode]

``--decode`` times whole default decodes instead (``bistair.decode``, interleaved with the
floor): run it with each checkout on ``PYTHONPATH`` for a before / after pair.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bistair.evaluation.speed import CASES, opencv_floor, speed_captures  # noqa: E402

SIZES = {"1.3": (1024, 1280), "12": (3000, 4000)}

import bistair  # noqa: E402
from bistair.core import measure, regions  # noqa: E402
from bistair.core.jit import set_threads  # noqa: E402
from bistair.core.measure_jit import keep_coherent  # noqa: E402
from bistair.core.memory import keep_freed_memory  # noqa: E402


def scene(size: str) -> tuple[np.ndarray, bistair.spec.BaseSpec]:
    """``decode_speed.py``'s default scene, kept in /tmp between runs."""
    spec = CASES[0].spec()
    path = Path(f"/tmp/bistair_regions_speed_{size}.npy")
    if path.exists():
        return np.load(path), spec
    frames = speed_captures(spec, SIZES[size])
    np.save(path, frames)
    return frames, spec


def decode_inputs(frames: np.ndarray, spec) -> tuple[tuple, tuple]:
    """The arguments of the decode's coherent_pixels and of its codec's fringe_regions."""
    from bistair.codecs import bidirectional

    seen: dict[str, tuple] = {}
    coherent, fringes = measure.coherent_pixels, bidirectional.fringe_regions

    def watch_coherent(*args, **kw):
        seen.setdefault("coherent", (args, kw))
        return coherent(*args, **kw)

    def watch_fringes(*args, **kw):
        seen.setdefault("fringes", (args, kw))
        return fringes(*args, **kw)

    measure.coherent_pixels = watch_coherent
    bidirectional.fringe_regions = watch_fringes
    try:
        bistair.decode(frames, spec)
    finally:
        measure.coherent_pixels = coherent
        bidirectional.fringe_regions = fringes
    return seen["coherent"], seen["fringes"]


def cases(frames: np.ndarray, spec) -> dict:
    from support import regions_before as old  # the oracle, in tests/support

    from bistair.core import regions_jit as new
    from bistair.core import regions_labels_jit as labels

    (c_args, c_kw), (f_args, f_kw) = decode_inputs(frames, spec)
    phi, weak, strong, sigma = c_args
    fphi, fvalid = f_args
    noise = np.ascontiguousarray(f_kw["phase_noise"], np.float32)
    edges = f_kw["boundaries"]
    sign = f_kw["sign"]
    cut = float(np.float32(regions.default_cut(fphi, fvalid)))
    jv, jh = old.period_jump_links(fphi, fvalid, noise, 3, 0.3)
    jv |= edges[0]
    jh |= edges[1]
    vert, horiz, keep = old.fringe_links(fphi, fvalid, cut, sign, noise, jv, jh)
    n_cc, lab_cc = cv2.connectedComponents(keep.view(np.uint8), connectivity=4,
                                           ltype=cv2.CV_32S)
    labels_old, n_old = old.regions_before(fphi, fvalid, cut, 20, noise, edges, sign)
    bits = new.link_bits(fphi, fvalid, noise, cut, sign, 0.3, edges[0], edges[1], True)
    lab, roots, n, size, lit = labels.label_kept(bits, new.NO_CUTS, False, new.TILE, 3)
    remap = np.arange(n + 1, dtype=np.int32)
    c_lab, c_n = old.regions_before(phi, weak, None, 1, sigma)
    coh = regions.label_fringes(phi, weak, phase_noise=sigma, strong=strong)
    h, w = fphi.shape
    print(f"{h}x{w}: valid {fvalid.mean():.2f}, kept {keep.mean():.2f}, "
          f"{n_cc - 1} components, {n_old} regions; coherent labelling: weak "
          f"{weak.mean():.2f}, {c_n} regions")
    return {
        "floor": lambda: opencv_floor(frames),
        "old period_jump_links": lambda: old.period_jump_links(fphi, fvalid, noise, 3, 0.3),
        "old fringe_links": lambda: old.fringe_links(fphi, fvalid, cut, sign, noise, jv, jh),
        "new link_bits (both)": lambda: new.link_bits(fphi, fvalid, noise, cut, sign, 0.3,
                                                      edges[0], edges[1], True),
        "old cv2.connectedComponents": lambda: cv2.connectedComponents(
            keep.view(np.uint8), connectivity=4, ltype=cv2.CV_32S),
        "old reattach": lambda: old.reattach(lab_cc.copy(), fvalid, keep, vert, horiz, 3),
        "new label_kept (+ reattach)": lambda: labels.label_kept(bits, new.NO_CUTS, False,
                                                              new.TILE, 3),
        "old drop_small": lambda: old.drop_small(labels_old.copy(), n_old, 20),
        "copy of the labels": lambda: lab.copy(),
        "new relabel (+ the copy)": lambda: labels.relabel(lab.copy(), roots, remap),
        "old keep_coherent": lambda: old.keep_coherent(c_lab, weak, strong, c_n, 10, 100, 20),
        "new keep_coherent": lambda: keep_coherent(coh.labels, coh.roots, coh.size,
                                                   coh.strong, strong, 10, 100, 20),
        "old fringe_regions": lambda: old.regions_before(fphi, fvalid, None, 20, noise, edges,
                                                         sign),
        "new fringe_regions": lambda: regions.fringe_regions(fphi, fvalid, None, 20, noise,
                                                             edges, sign),
        "old coherent_pixels": lambda: old.coherent_before(phi, weak, strong, sigma),
        "new coherent_pixels": lambda: measure.coherent_pixels(phi, weak, strong, sigma),
    }


def rounds(jobs: dict, count: int, clock) -> dict[str, float]:
    best = {k: np.inf for k in jobs}
    for _ in range(count):
        for key, job in jobs.items():
            t0 = clock()
            job()
            best[key] = min(best[key], clock() - t0)
    return best


def report(best: dict[str, float], frames: np.ndarray, size: str, threads: int, count: int,
           wall: bool) -> None:
    """Print each job's least time: ms, ns a pixel and the ratio to the ``floor`` job."""
    px = frames.shape[1] * frames.shape[2]
    print(f"bistair {Path(bistair.__file__).parents[1]}, {size} MP, {threads} thread(s), "
          f"{'wall' if wall else 'CPU'} time, min of {count} rounds")
    for key, t in best.items():
        print(f"  {key:32s} {1e3 * t:8.2f} ms {1e9 * t / px:7.2f} ns/px "
              f"{t / best['floor']:7.2f} x floor")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="1.3", choices=sorted(SIZES))
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--wall", action="store_true",
                        help="every core, wall time (else one thread, CPU time)")
    parser.add_argument("--decode", action="store_true", help="time whole default decodes")
    args = parser.parse_args()
    keep_freed_memory()
    threads = set_threads(None if args.wall else 1)
    cv2.setNumThreads(threads)
    clock = time.perf_counter if args.wall else time.process_time
    frames, spec = scene(args.size)
    if args.decode:
        jobs = {"floor": lambda: opencv_floor(frames),
                "default decode": lambda: bistair.decode(frames, spec)}
        bistair.decode(frames, spec)
    else:
        jobs = cases(frames, spec)
    for job in jobs.values():  # compiled and warm
        job()
    report(rounds(jobs, args.rounds, clock), frames, args.size, threads, args.rounds, args.wall)


if __name__ == "__main__":
    main()
