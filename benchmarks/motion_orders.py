"""Fringe-order errors of every codec under motion (issue 34).

Each method's comparable set (``method_specs``: period 30, four steps; the bidirectional
set's stair frames, the Gray code's bits and the multifreq reference's 36 frames included)
rendered on sphere-on-plane with the sphere moving sideways (along the coded axis) at 0,
0.5, 1, 2 and 4 camera pixels per frame, every frame at its own pose
(:func:`bistair.sim.motion.trace_frames`, one trace per frame shared by the methods), and
decoded as a still set. A moving surface has no one true order: each decode is scored
against the truth at the time of its own phase frames (the frames its wrapped phase comes
from, e.g. 1.5 for shifts 0-3 first in the set, 29.5 for the reference's 30-px set last:
the truth of the two frames around it averaged, on pixels that see one object at both),
so that an order counts as wrong where the absolute phase is off by more than half a
fringe there (:func:`bistair.evaluation.metrics.score`), and motion that only shifts the
phase does not. Coverage is against those pixels; a refused decode is shown as refused.

    python benchmarks/motion_orders.py [--camera 320x256] [--seeds 1] [--markdown PAGE]
"""

from __future__ import annotations

import argparse
import re
import time
from pathlib import Path

import numpy as np
from markdown_page import markdown_page

from bistair import decode, encode
from bistair.errors import BistairError
from bistair.evaluation.benchmark import method_specs
from bistair.evaluation.metrics import score
from bistair.sim import Imaging, expose, preset
from bistair.sim.motion import parse_motion, trace_frames
from bistair.spec import format_period

SPEEDS = (0.0, 0.5, 1.0, 2.0, 4.0)
OPTICS = dict(gamma=2.2, read_noise=0.01, camera_blur=1.0, projector_blur=0.5, ambient=0.05)
TITLE = "Motion: fringe orders of every codec"
ABOUT = ("Every method's comparable set on sphere-on-plane with the sphere moving sideways "
         "0 to 4 camera pixels per frame (each frame rendered at its own pose, default "
         "optics), decoded as a still set; order errors against the truth at the time of "
         "each set's phase frames.")


def phase_frames(spec) -> list[int]:
    """The indices of the frames a decode's wrapped phase comes from: ``shift-n`` (of the
    shortest period for multifreq)."""
    own = f"T{format_period(spec.period)}-" if spec.method == "multifreq" else ""
    return [i for i, name in enumerate(spec.frames)
            if re.fullmatch(re.escape(own) + r"shift-\d+", name)]


def truth_at(truths, frames: list[int], spec):
    """The truth coordinate at the middle of ``frames`` (two frames averaged, or one) and
    where it holds: lit at both and one object at both."""
    mid = (frames[0] + frames[-1]) / 2
    pair = [truths[int(np.floor(mid))], truths[int(np.ceil(mid))]]
    coord = (pair[0].coord(spec) + pair[1].coord(spec)) / 2
    mask = pair[0].mask & pair[1].mask & (pair[0].object_id == pair[1].object_id)
    return coord, mask, mid


def measure(camera: tuple[int, int], seeds: int, speeds=SPEEDS) -> dict:
    """label -> speed -> (order error rate, coverage) median of the seeds, or None where
    any seed's decode was refused."""
    rig, scene = preset("sphere-on-plane", camera_size=camera)
    specs = method_specs(rig.projector.size, period=30, gamma=2.2)
    count = max(s.frame_count for s, _ in specs.values())
    table: dict = {label: {} for label in specs}
    refusals: dict = {}
    for speed in speeds:
        start = time.process_time()
        runs: dict = {label: [] for label in specs}
        for seed in range(seeds):
            imaging = Imaging(**OPTICS, seed=seed)
            motion = parse_motion(f"{speed:g}px")
            traces = trace_frames(rig, scene, motion, range(count), imaging)
            truths = [t.truth for t in traces]
            for label, (spec, options) in specs.items():
                pats = encode(spec)
                images = np.stack([expose(traces[k], pats[k:k + 1], imaging, first_frame=k)[0]
                                   for k in range(len(pats))])
                coord, mask, _ = truth_at(truths, phase_frames(spec), spec)
                try:
                    result = decode(images, spec, **options)
                except BistairError as exc:
                    runs[label].append(None)
                    refusals.setdefault((label, speed), str(exc))
                    continue
                s = score(result, coord, mask)
                runs[label].append((s["order_error_rate"], s["coverage"]))
        for label, got in runs.items():
            table[label][speed] = (None if any(g is None for g in got) else
                                   tuple(float(np.median([g[i] for g in got])) for i in (0, 1)))
        print(f"# {speed:g} px/frame: {seeds} seed(s), {count} poses, "
              f"{time.process_time() - start:.0f} s CPU")
    for (label, speed), why in refusals.items():
        print(f"# refused: {label} at {speed:g} px/frame: {why}")
    return table


def print_table(table: dict, speeds=SPEEDS) -> None:
    """Order errors (coverage) per method and speed."""
    print()
    print("| method | frames | phase frames' time | "
          + " | ".join(f"{s:g} px/frame" for s in speeds) + " |")
    print("| --- | ---: | ---: | " + " | ".join("---:" for _ in speeds) + " |")
    rig, _ = preset("sphere-on-plane", camera_size=(64, 48))
    specs = method_specs(rig.projector.size, period=30, gamma=2.2)
    for label, row in table.items():
        spec = specs[label][0]
        frames = phase_frames(spec)
        cells = ["refused" if row[s] is None else
                 f"{100 * row[s][0]:.3f}% ({100 * row[s][1]:.1f}%)" for s in speeds]
        print(f"| {label} | {spec.frame_count} | {(frames[0] + frames[-1]) / 2:g} | "
              + " | ".join(cells) + " |")
    print()
    print("Each cell: order errors, % of the decoded pixels (coverage, % of the pixels with "
          "a truth).")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="320x256")
    parser.add_argument("--seeds", type=int, default=1)
    parser.add_argument("--speeds", default=",".join(f"{s:g}" for s in SPEEDS))
    parser.add_argument("--markdown", type=Path, default=None,
                        help="also write what is printed as a Markdown page")
    args = parser.parse_args(argv)
    camera = tuple(int(v) for v in args.camera.lower().split("x"))
    speeds = tuple(float(s) for s in args.speeds.split(","))
    with markdown_page(args.markdown, TITLE, ABOUT):
        print_table(measure(camera, args.seeds, speeds), speeds)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
