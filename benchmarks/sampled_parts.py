"""The sampled split of disagreeing parts: a prototype kept to measure it, switched off in
the decoders.

:func:`split_parts` finds the parts of fringe regions whose codes contradict their region's
order (``bistair.core.parts.split_disagreeing``, which every region decoder runs over the
whole image) from a 2 x 2 sample: the parts are flagged on every second row and column
(:func:`sample_boxes`), then found and detached at full resolution inside each flagged
part's box alone (:func:`split_in_boxes`). It gave the whole image's parts on 42 of 42
preset renders, every split of the real captures and 400 drawn scenes, and cut the split
8.2 -> 2.5 ms at 1.3 MP (73 -> 17 ms at 12 MP); but the sample missed a part 5 rows tall on
the README's own sphere-on-plane render (``bistair simulate --scene sphere-on-plane --camera
640x512``) and left its 38 pixels an order 7 fringes off the truth (``tests/test_parts.py``
pins that decode on the truth). So no decoder runs it: a codec's agreement would have to
judge a part of the image (:func:`windowed`), and none does.

Do the disagreeing parts found from the sample equal those the whole image gives? And what
does the sample save? Each rendered scene (every preset with objects, 640 x 512, hard and
default optics of ``benchmarks/robustness.py``, three seeds) is decoded both ways: the parts
detached, the pixels whose order differs, order error rate, coverage and the worst object's
share decoded right (``bistair.evaluation.metrics.score``), and the share of the image the
boxes cover (the full-resolution work left).

    python benchmarks/sampled_parts.py [--seeds 3]
    python benchmarks/sampled_parts.py --real
    python benchmarks/sampled_parts.py --drawn 400
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
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
from robustness import DEFAULT, HARD

import bistair
from bistair.core import resolve
from bistair.core.parts import split_disagreeing
from bistair.core.parts_jit import dense_tile, pixel_orders, window_seeds
from bistair.evaluation.metrics import score
from bistair.sim import Imaging, expose, preset, preset_spec, trace

Agreement = Callable[..., np.ndarray]
ALL = (slice(None), slice(None))  # the whole image, as ``at``
STEP = 2  # the sample: every STEP-th row and column
SAMPLE_WINDOW = 4  # the sample's neighbourhood, in sample pixels
TILE = 8  # the sample's seeds are gathered in tiles of TILE x TILE sample pixels
SAMPLE_SHARE = 0.45  # flags a part on the sample: more than this share of the decided pixels bad
Box = tuple[int, int, int, int]  # y0, y1, x0, x1 (ends excluded)


def windowed(agrees: Agreement) -> Agreement:
    """Mark ``agrees(order, at)`` as an agreement that can judge a part of the image: given
    the orders of the pixels ``image[at]`` (``at``: a tuple of two slices, :data:`ALL` for
    the whole image), it returns which of those pixels' own codes fit them. Such an agreement
    lets :func:`split_parts` work from a sample; any other is judged on the whole image.

    Parameters
    ----------
    agrees : callable
        ``agrees(order, at=ALL) -> bool array`` of ``order``'s shape (-1: undecided).

    Returns
    -------
    callable
        ``agrees`` itself, marked.

    Examples
    --------
    >>> codes = np.arange(12).reshape(3, 4)
    >>> @windowed
    ... def agrees(k, at=ALL):
    ...     return k == codes[at]
    >>> agrees(codes[::2, 1:3], (slice(None, None, 2), slice(1, 3))).all(), agrees.windowed
    (np.True_, True)
    """
    agrees.windowed = True  # type: ignore[attr-defined]
    return agrees


def split_parts(labels: np.ndarray, n: int, k_reg: np.ndarray, agrees: Agreement,
                window: int = 7, share: float = 0.7, min_size: int = 30
                ) -> tuple[np.ndarray, int, int]:
    """:func:`split_disagreeing` from a sample: the parts are flagged on every second row
    and column (:func:`sample_boxes`), then found and detached at full resolution inside
    each flagged part's box alone (:func:`split_in_boxes`), with the same labels, numbering
    and counts as :func:`split_disagreeing` gives whenever every seed of a part lies in a
    box (measured: every rendered scene of this benchmark and every real capture in
    ../shared/data; ``--drawn``: :func:`drawn`).

    An agreement not marked :func:`windowed`, an image under ``8 * window`` pixels on a
    side, a bad share within rounding of ``share`` in a box, or seeds in boxes without a
    dense tile there (where the whole image decides) go to :func:`split_disagreeing`.

    Parameters
    ----------
    labels : (H, W) int32 array
        Fringe regions, 0 outside any.
    n : int
        Number of regions.
    k_reg : (n+1,) int array
        The order per region, -1 where undecided.
    agrees : callable
        ``agrees(order, at)`` (:func:`windowed`), or ``agrees(order)`` for the whole image.
    window, share, min_size
        As :func:`split_disagreeing`.

    Returns
    -------
    labels, n, detached
        As :func:`split_disagreeing`.

    Examples
    --------
    >>> labels = np.ones((60, 100), np.int32)
    >>> truth = np.where(np.arange(100) < 70, 3, 5)[None].repeat(60, axis=0)
    >>> new, n, detached = split_parts(labels, 1, np.array([-1, 3]),
    ...                                windowed(lambda k, at=ALL: k == truth[at]))
    >>> n, detached, np.unique(new[:, 70:]).tolist()
    (2, 1, [2])
    """
    if not getattr(agrees, "windowed", False) or min(labels.shape) < 8 * window:
        return split_disagreeing(labels, n, k_reg, agrees, window, share, min_size)
    boxes = sample_boxes(labels, k_reg, agrees, window)
    if not boxes:
        return labels, n, 0
    found = split_in_boxes(labels, n, k_reg, agrees, boxes, window, share, min_size)
    if found is None:
        return split_disagreeing(labels, n, k_reg, agrees, window, share, min_size)
    return found


def _bad(labels: np.ndarray, k_reg: np.ndarray, agrees: Agreement,
         at: tuple[slice, slice]) -> tuple[np.ndarray, np.ndarray]:
    """The decided pixels of ``labels[at]`` and those whose codes disagree with their
    region's order."""
    k = pixel_orders(np.ascontiguousarray(labels[at]), np.asarray(k_reg))  # (faster so)
    decided = k >= 0
    bad = np.asarray(agrees(k, at), bool)
    bad = np.logical_not(bad, out=bad if bad.flags.writeable else None)
    bad &= decided
    return bad, decided


def sample_boxes(labels: np.ndarray, k_reg: np.ndarray, agrees: Agreement,
                 window: int = 7) -> list[Box]:
    """Boxes of the image around the parts that disagree on a sample: every
    :data:`STEP`-th row and column, where more than :data:`SAMPLE_SHARE` of a
    :data:`SAMPLE_WINDOW`-pixel neighbourhood's decided pixels disagree (a part of 30 px
    still shows about 7 pixels there; at 0.5, 5 of 400 drawn scenes of ``tests/test_parts.py``
    lost a part 3 px wide along the image's edge, none at 0.45). The flagged pixels' tiles
    of :data:`TILE` x :data:`TILE` sample pixels, each widened by one tile (at least
    ``2 * window`` full-resolution pixels), give a box per cluster of tiles (8-connected);
    boxes that overlap are merged.

    Parameters
    ----------
    labels : (H, W) int32 array
        Fringe regions, 0 outside any.
    k_reg : (n+1,) int array
        The order per region, -1 where undecided.
    agrees : callable
        A :func:`windowed` agreement.
    window : int
        The full-resolution neighbourhood (the margin must reach ``2 * window``).

    Returns
    -------
    list of (y0, y1, x0, x1)
        Full-resolution boxes (ends excluded), none overlapping; empty when no part shows.

    Examples
    --------
    >>> labels = np.ones((64, 96), np.int32)
    >>> truth = np.full(labels.shape, 3)
    >>> truth[8:20, 16:28] = truth[40:50, 70:80] = 5
    >>> sample_boxes(labels, np.array([-1, 3]), windowed(lambda k, at=ALL: k == truth[at]))
    [(0, 64, 0, 96)]
    """
    h, w = labels.shape
    bad, decided = _bad(labels, k_reg, agrees, (slice(None, None, STEP),) * 2)
    if min(bad.shape) < SAMPLE_WINDOW:
        return [(0, h, 0, w)]
    seeds, _ = window_seeds(bad, decided, SAMPLE_WINDOW, SAMPLE_SHARE)
    # the seeds' tiles of TILE x TILE sample pixels, each widened by a tile (2 * TILE full
    # pixels, at least 2 * window): each cluster of those (8-connected) gives a box; a part
    # seeded in several is made whole at full resolution (split_in_boxes)
    rows = np.flatnonzero(seeds.any(axis=1))  # (seeds are few: found row by row)
    if rows.size == 0:
        return []
    ry, rx = np.nonzero(seeds[rows])
    tiles = np.zeros((-(-seeds.shape[0] // TILE), -(-seeds.shape[1] // TILE)), np.uint8)
    tiles[rows[ry] // TILE, rx // TILE] = 1
    tiles = cv2.dilate(tiles, np.ones((3, 3), np.uint8))
    count, _, stats, _ = cv2.connectedComponentsWithStats(tiles, connectivity=8)
    full = STEP * TILE
    boxes = [(ty * full, min((ty + bh) * full, h), tx * full, min((tx + bw) * full, w))
             for tx, ty, bw, bh in (stats[c, :4].tolist() for c in range(1, count))]
    return merge_boxes(boxes)


def merge_boxes(boxes: list[Box], reach: int = 0) -> list[Box]:
    """Boxes that overlap once each is widened by ``reach`` pixels on every side, merged
    into their bounding box until none do; sorted.

    Parameters
    ----------
    boxes : list of (y0, y1, x0, x1)
        Boxes, ends excluded.
    reach : int
        How far apart two boxes may lie and still be merged (each widened by it).

    Returns
    -------
    list of (y0, y1, x0, x1)

    Examples
    --------
    >>> merge_boxes([(0, 5, 0, 5), (4, 9, 4, 9), (20, 30, 0, 3)])
    [(0, 9, 0, 9), (20, 30, 0, 3)]
    >>> merge_boxes([(0, 5, 0, 5), (8, 9, 0, 5)], reach=2)
    [(0, 9, 0, 5)]
    """
    boxes = sorted(boxes)
    merged = True
    while merged:
        merged = False
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                a, b = boxes[i], boxes[j]
                if (a[0] < b[1] + 2 * reach and b[0] < a[1] + 2 * reach
                        and a[2] < b[3] + 2 * reach and b[2] < a[3] + 2 * reach):
                    boxes[i] = (min(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]),
                                max(a[3], b[3]))
                    del boxes[j]
                    merged = True
                    break
            if merged:
                break
    return sorted(boxes)


def _outer(box: Box, window: int, h: int, w: int, tile: int = 8) -> Box:
    """``box`` widened by ``window`` pixels on every side, out to the ``tile``-pixel grid
    from the image's top left (the grid of ``dense_tile``), within the image."""
    y0, y1, x0, x1 = box
    return ((max(y0 - window, 0) // tile) * tile, min(-(-(y1 + window) // tile) * tile, h),
            (max(x0 - window, 0) // tile) * tile, min(-(-(x1 + window) // tile) * tile, w))


def split_in_boxes(labels: np.ndarray, n: int, k_reg: np.ndarray, agrees: Agreement,
                   boxes: list[Box], window: int = 7, share: float = 0.7,
                   min_size: int = 30) -> tuple[np.ndarray, int, int] | None:
    """:func:`split_disagreeing` with its seeds taken inside ``boxes`` alone: at full
    resolution, in each box widened by ``window`` (so that every window around a pixel of
    the box counts what it counts in the whole image), the seeds of the box grow over their
    disagreeing pixels; a part that reaches the widened box's edge widens the box and the
    boxes are judged again, so that every part is whole. The parts are numbered as
    :func:`split_disagreeing` numbers them (by their first pixel in raster order, then the
    region).

    Parameters
    ----------
    labels, n, k_reg, agrees, window, share, min_size
        As :func:`split_parts`.
    boxes : list of (y0, y1, x0, x1)
        Where seeds may lie (:func:`sample_boxes`).

    Returns
    -------
    (labels, n, detached) or None
        As :func:`split_disagreeing` (the input labels when no seed lies in a box), or
        ``None`` when a box cannot decide alone: a neighbourhood's bad share within
        rounding of ``share``, or seeds without an 8 x 8 tile dense enough in any box
        (the whole image's test that :func:`split_disagreeing` applies first).

    Examples
    --------
    >>> labels = np.ones((64, 96), np.int32)
    >>> truth = np.full(labels.shape, 3)
    >>> truth[8:20, 16:28] = truth[40:50, 70:80] = 5
    >>> agrees = windowed(lambda k, at=ALL: k == truth[at])
    >>> new, n, detached = split_in_boxes(labels, 1, np.array([-1, 3]), agrees,
    ...                                   [(5, 25, 15, 35)])  # the first part's box alone
    >>> n, detached, int((new == 2).sum())
    (2, 1, 144)
    """
    h, w = labels.shape
    widened = True
    while widened:  # until no part runs on past its widened box
        boxes = merge_boxes(boxes, window + 8)  # their widened boxes apart
        widened, dense = False, False
        flats, ids, firsts, judged = [], [], [], []
        for box in boxes:
            oy0, oy1, ox0, ox1 = _outer(box, window, h, w)
            at = (slice(oy0, oy1), slice(ox0, ox1))
            bad, decided = _bad(labels, k_reg, agrees, at)
            if min(bad.shape) < window:
                return None
            seeds, close = window_seeds(bad, decided, window, share)
            if close:
                return None
            inner = np.zeros(bad.shape, bool)
            inner[box[0] - oy0:box[1] - oy0, box[2] - ox0:box[3] - ox0] = True
            seeds &= inner
            judged.append(box)
            if not seeds.any():
                continue
            dense = dense or dense_tile(bad, decided, share, 8)
            _, parts = cv2.connectedComponents(bad.view(np.uint8), connectivity=4,
                                               ltype=cv2.CV_32S)
            seeded = np.zeros(int(parts.max()) + 1, bool)
            seeded[parts[seeds]] = True
            seeded[0] = False
            grown = seeded[parts]
            ys, xs = np.nonzero(grown)
            if ((oy0 > 0 and grown[0].any()) or (oy1 < h and grown[-1].any())
                    or (ox0 > 0 and grown[:, 0].any()) or (ox1 < w and grown[:, -1].any())):
                # a part runs on past the widened box: the box takes it in, judged again
                judged[-1] = (min(box[0], oy0 + int(ys.min())),
                              max(box[1], oy0 + int(ys.max()) + 1),
                              min(box[2], ox0 + int(xs.min())),
                              max(box[3], ox0 + int(xs.max()) + 1))
                widened = True
                continue
            part = parts[ys, xs]
            uniq, first = np.unique(part, return_index=True)
            flat = (ys + oy0).astype(np.int64) * w + (xs + ox0)
            ids.append(np.searchsorted(uniq, part) + sum(f.size for f in firsts))
            flats.append(flat)
            firsts.append(flat[first])
        boxes = judged
    if not flats:
        return labels, n, 0
    if not dense:
        return None
    flat, part = np.concatenate(flats), np.concatenate(ids)
    rank = np.argsort(np.argsort(np.concatenate(firsts)))  # parts in raster order
    key = rank[part].astype(np.int64) * (n + 1) + labels.ravel()[flat]
    uniq, inv, size = np.unique(key, return_inverse=True, return_counts=True)
    new = np.where(size >= min_size, n + 1 + np.cumsum(size >= min_size) - 1, 0)
    labels = labels.copy()
    labels.ravel()[flat] = new[inv]
    return labels, n + int((size >= min_size).sum()), int((size >= min_size).sum())


SCENES = ("sphere-on-plane", "paper-sim", "two-masks", "mask-prism", "two-sculptures",
          "objects-on-plane", "mugs-on-wall")
MODES = {"full": split_disagreeing, "sampled": split_parts}


def watched_boxes(seen: dict):
    """:func:`sample_boxes` that keeps the share of the image its boxes cover."""
    kept = sample_boxes

    def boxes(labels, *args):
        found = kept(labels, *args)
        seen["box"] = sum((y1 - y0) * (x1 - x0) for y0, y1, x0, x1 in found) / labels.size
        return found

    return boxes


def as_windowed(agrees):
    """Any agreement as a :func:`windowed` one: the orders of
    ``image[at]`` placed in a whole image of -1 and judged there (as slow as the whole
    image; for comparisons)."""

    @windowed
    def judged(k, at=ALL):
        full = np.full(shape, -1, k.dtype)
        full[at] = k
        return np.asarray(agrees(full), bool)[at]

    shape = None

    def bind(labels_shape):
        nonlocal shape
        shape = labels_shape
        return judged

    return bind


def same_split(labels, n, k_reg, agrees) -> tuple[bool, int]:
    """Whether ``split_parts`` (through :func:`as_windowed` unless ``agrees`` is windowed)
    gives what ``split_disagreeing`` gives; and the parts detached."""
    full = split_disagreeing(labels, n, k_reg, agrees)
    if not getattr(agrees, "windowed", False):
        agrees = as_windowed(agrees)(labels.shape)
    sampled = split_parts(labels, n, k_reg, agrees)
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
            return split_disagreeing(labels, n, k_reg, agrees, *args)

        stack, spec = read_with_spec(folder, spec)
        resolve.split_disagreeing = split
        try:
            bistair.decode(stack, spec, force=True, **options)
        finally:
            resolve.split_disagreeing = split_disagreeing
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
    kept = sample_boxes
    globals()["sample_boxes"] = watched_boxes(seen)  # what split_parts calls
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
                resolve.split_disagreeing = split
                try:
                    result = bistair.decode(images, spec, force=True)
                finally:
                    resolve.split_disagreeing = split_disagreeing
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
        globals()["sample_boxes"] = kept
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
        return split_parts(*args)

    resolve.split_disagreeing = watched
    try:
        bistair.decode(frames, spec)
    finally:
        resolve.split_disagreeing = split_disagreeing
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


def _drawn_scene(rng, h=160, w=224):
    """Fringe regions (vertical bands, some cut in two), their orders, and codes that
    disagree in blobs, thin streaks and scattered noise."""
    edges = np.sort(rng.choice(np.arange(8, w - 8), 9, replace=False))
    labels = np.searchsorted(edges, np.arange(w))[None].repeat(h, 0).astype(np.int32) + 1
    cut = rng.integers(20, h - 20)
    labels[cut:] += labels.max()  # each band cut in two, one above the other
    labels[rng.random((h, w)) < 0.02] = 0  # holes
    n = int(labels.max())
    k_reg = np.r_[-1, rng.integers(0, 40, n)]
    k_reg[rng.integers(1, n + 1)] = -1  # an undecided region
    codes = k_reg[labels]
    for _ in range(rng.integers(0, 6)):  # blobs of the other surface's code
        y, x = rng.integers(0, h), rng.integers(0, w)
        dy, dx = rng.integers(3, 40, 2)
        codes[y:y + dy, x:x + dx] += rng.integers(1, 4)
    if rng.random() < 0.5:  # a thin streak far past any box
        x = rng.integers(0, w - 3)
        codes[5:h - 5, x:x + 3] += 1
    codes = np.where(rng.random((h, w)) < rng.choice([0.0, 0.05, 0.2]), codes + 1, codes)
    return labels, n, k_reg, codes


def drawn(count: int) -> int:
    """The sampled split against the whole image's on ``count`` drawn scenes (blobs of every
    size, parts that run far past their box, parts side by side, noise): how many differ
    (the same labels, numbering and counts expected); the parts found and the boxes
    widened to hold a part are printed."""
    rng = np.random.default_rng(32)
    found = widened = differ = 0
    kept = globals()["_outer"]
    calls = []

    def outer(box, *args):  # watch the boxes judged, to see one widened
        calls.append(box)
        return kept(box, *args)

    globals()["_outer"] = outer
    try:
        for _ in range(count):
            labels, n, k_reg, codes = _drawn_scene(rng)

            @windowed
            def agrees(k, at=ALL, codes=codes):
                return (k == codes[at]) | (k < 0)

            calls.clear()
            whole = split_disagreeing(labels, n, k_reg, agrees)
            sampled = split_parts(labels, n, k_reg, agrees)
            differ += not (np.array_equal(whole[0], sampled[0]) and whole[1:] == sampled[1:])
            found += whole[2]
            first = set(calls[:len(set(calls))])
            widened += any(box not in first for box in calls)
    finally:
        globals()["_outer"] = kept
    print(f"{count} drawn scenes: {differ} split otherwise than the whole image, {found} parts, "
          f"boxes widened in {widened}")
    return differ


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--speed", action="store_true")
    parser.add_argument("--real", action="store_true")
    parser.add_argument("--drawn", type=int, default=0, help="this many drawn scenes")
    parser.add_argument("--size", default="1.3", choices=("1.3", "12"))
    parser.add_argument("--rounds", type=int, default=10)
    args = parser.parse_args()
    if args.speed:
        speed(args.size, args.rounds)
    elif args.real:
        real()
    elif args.drawn:
        drawn(args.drawn)
    else:
        quality(args.seeds)


if __name__ == "__main__":
    main()
