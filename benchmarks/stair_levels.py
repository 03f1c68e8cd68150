"""Stair levels that cannot be read (issue 31): the bidirectional default decoder on every
preset scene, codeword count, optics and seed, scored against the rendered truth.

For each case the table gives the response exponent the decoder fitted to the stair levels
(``-``: read as they are), how far the band rows read from their levels (``level_offset``,
the median share of half a gap) and from the worst level (``worst_level_offset``, against
the limit ``LEVEL_DOUBT`` = 0.35), the levels past that limit (a region reading one is
faint: its neighbours decide), the stair check's share of contradicting pixels
(``stair_misfit``, refused over 0.1), the share of the decoded pixels more than half a
period off the truth, the share of the truth's pixels decoded, and what a check refused
(each case is decoded with ``force=True``). A case is *silently wrong* when over 1% of its
decoded pixels are wrong and no check refused it, a *false refusal* when a check refused a
decode at most 1% wrong.

Codes: 6 x 6 at a period of 54 px, 8 x 8 at 30, 10 x 10 at 20, 11 x 11 at 16 and 12 x 12 at
14 (the 1920-px projector's widths; paper-sim's 1080-px projector shows fewer partitions).
Optics: ``default`` (1% read noise, camera blur 1 px, 5% ambient) and ``hard`` (3% noise,
camera blur 1.2 px, projector blur 1 px, 15% ambient), each with the projector's gamma of
2.2 compensated by the patterns (``c``) and not (``u``).

    python benchmarks/stair_levels.py [--camera 640x512] [--seeds 0,1,2] [--scenes all]
                                      [--codes 6,8,10,11,12] [--cache DIR]

``--cache DIR`` keeps the rendered captures (``DIR/<case>.npy`` and ``.json``) and truths
for the next run. Every preset, five codes, four optics and three seeds at 640 x 512: 480
decodes; rendering them took about an hour on two busy cores, decoding them from the cache
about four minutes.
"""

from __future__ import annotations

import argparse
import itertools
import time
from pathlib import Path

import numpy as np

import bistair
from bistair.sim import Imaging, expose, preset, scene_names, trace

OPTICS = {"default": dict(read_noise=0.01, camera_blur=1.0, gamma=2.2, ambient=0.05),
          "hard": dict(gamma=2.2, read_noise=0.03, camera_blur=1.2, projector_blur=1.0,
                       ambient=0.15)}
PERIODS = {6: 54, 8: 30, 10: 20, 11: 16, 12: 14}


def cases(scene: str, camera: tuple[int, int], codes: list[int], seeds: list[int],
          cache: Path | None):
    """``(name, stack, spec, truth coord, truth mask)`` of every case of one scene."""
    rig, geometry = preset(scene, camera_size=camera)
    width, height = rig.projector.size
    for optics, params in OPTICS.items():
        stem = f"{scene}-{camera[0]}-{optics}"
        truth_file = cache / f"truth-{stem}.npz" if cache else None
        traced = None
        if truth_file is None or not truth_file.exists():
            traced = trace(rig, geometry, Imaging(**params))
            coord, mask = traced.truth.coord_x, traced.truth.mask
            if truth_file is not None:
                np.savez_compressed(truth_file, coord=coord, mask=mask)
        else:
            with np.load(truth_file) as truth:
                coord, mask = truth["coord"], truth["mask"]
        for code, seed, compensated in itertools.product(codes, seeds, (True, False)):
            name = f"{stem}-{code}-{seed}-{'c' if compensated else 'u'}"
            imaging = Imaging(**params, seed=seed)
            spec = bistair.make_spec("bidirectional", width=width, height=height,
                                     period=PERIODS[code], partitions=code, stairs=code,
                                     gamma=imaging.gamma if compensated else 1.0)
            stored = cache / f"{name}.npy" if cache else None
            if stored is not None and stored.exists():
                stack = np.load(stored)
            else:
                if traced is None:
                    traced = trace(rig, geometry, Imaging(**params))
                stack = expose(traced, bistair.encode(spec), imaging)
                if stored is not None:
                    np.save(stored, stack)
                    stored.with_suffix(".json").write_text(spec.to_json())
            yield name, stack, spec, coord, mask


def score(stack: np.ndarray, spec, coord: np.ndarray, mask: np.ndarray) -> dict:
    """One forced decode against the truth."""
    start = time.perf_counter()
    res = bistair.decode(stack, spec, force=True)
    both = res.mask & mask
    wrong = float(np.mean(np.abs(res.coord - coord)[both] > spec.period / 2)) if both.any() \
        else 0.0
    info = res.info
    return dict(wrong=wrong, coverage=float(both.sum() / max(int(mask.sum()), 1)),
                response=info.get("stair_response"), offset=info.get("level_offset", 0.0),
                worst=info.get("worst_level_offset", 0.0), misfit=info.get("stair_misfit", 0.0),
                doubtful=info.get("doubtful_levels", 0), forced=info.get("forced", []),
                seconds=time.perf_counter() - start)


def verdict(row: dict) -> str:
    if row["forced"]:
        return "false refusal" if row["wrong"] <= 0.01 else "refused"
    return "silently wrong" if row["wrong"] > 0.01 else "right"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="640x512")
    parser.add_argument("--seeds", default="0,1,2")
    parser.add_argument("--scenes", default="all")
    parser.add_argument("--codes", default="6,8,10,11,12")
    parser.add_argument("--cache", type=Path, default=None)
    args = parser.parse_args()
    camera = tuple(int(v) for v in args.camera.split("x"))
    scenes = scene_names() if args.scenes == "all" else args.scenes.split(",")
    codes = [int(c) for c in args.codes.split(",")]
    seeds = [int(s) for s in args.seeds.split(",")]
    if args.cache:
        args.cache.mkdir(parents=True, exist_ok=True)
    head = ("case", "response", "level offset", "worst level", "doubtful", "stair misfit",
            "wrong", "coverage", "refused", "verdict")
    print("  ".join(head))
    counts: dict[str, int] = {}
    for scene in scenes:
        for name, stack, spec, coord, mask in cases(scene, camera, codes, seeds, args.cache):
            row = score(stack, spec, coord, mask)
            v = verdict(row)
            counts[v] = counts.get(v, 0) + 1
            print(f"{name}  {row['response'] or '-'}  {row['offset']:.3f}  {row['worst']:.3f}  "
                  f"{row['doubtful']}  {row['misfit']:.3f}  "
                  f"{100 * row['wrong']:.2f}%  {100 * row['coverage']:.1f}%  "
                  f"{'; '.join(f[:50] for f in row['forced']) or '-'}  {v}", flush=True)
    print(f"\n{sum(counts.values())} decodes: " + ", ".join(f"{n} {v}" for v, n in
                                                         sorted(counts.items())))


if __name__ == "__main__":
    main()
