"""What a new frame of a stream costs (issue 34): ``decode --window`` at 640 x 480.

A four-step stream of period 30 (uint8 frames of a tilted fringe with 1% noise). Timed, in
process CPU time, the minimum of interleaved rounds, per frame:

- ``set``: the phase of a whole window from its N frames (``window_phases`` of N frames:
  what a decoder that forgets the sums pays for every new frame), the baseline;
- ``push``: :class:`~bistair.core.motion.PhaseStream` taking one frame, plain and with
  order 4 (the running sums: the new frame's difference to the frame N before it);
- ``job``: ``decode_stream`` (the ``decode --window`` job: reading the frames from PNG,
  the sums, writing each window's wrapped.npy, modulation.npy and info.json), per window.

    python benchmarks/stream_speed.py [--camera 640x480] [--frames 40] [--rounds 5]
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from bistair.app.decode_stream import decode_stream
from bistair.codecs import make_spec
from bistair.core.motion import PhaseStream, window_phases
from bistair.io.atomic import write_image


def frames_of(width: int, height: int, count: int, steps: int = 4) -> np.ndarray:
    """``count`` uint8 frames of a stream: frame i shows shift i mod ``steps``."""
    rng = np.random.default_rng(0)
    y, x = np.mgrid[:height, :width]
    phase = 2 * np.pi * (x + 0.2 * y) / 30 * (1920 / width)
    out = [0.5 + 0.35 * np.cos(phase + 2 * np.pi * i / steps)
           + rng.normal(0, 0.01, phase.shape) for i in range(count)]
    return np.clip(np.round(np.stack(out) * 255), 0, 255).astype(np.uint8)


def cpu(fn, repeat: int) -> float:
    """Process CPU seconds of one call, over ``repeat`` calls."""
    start = time.process_time()
    for _ in range(repeat):
        fn()
    return (time.process_time() - start) / repeat


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="640x480")
    parser.add_argument("--frames", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args(argv)
    width, height = (int(v) for v in args.camera.lower().split("x"))
    frames = frames_of(width, height, args.frames)
    scaled = frames.astype(np.float32) / 255
    tmp = Path(tempfile.mkdtemp())
    try:
        (tmp / "in").mkdir()
        for i, f in enumerate(frames):
            write_image(tmp / "in" / f"{i:04d}.png", f)
        spec = make_spec("multifreq", width=1920, height=1080, periods=(30,), steps=4)
        (tmp / "in" / "spec.json").write_text(spec.to_json())

        def pushes(order: int) -> None:
            stream = PhaseStream(4, order=order)
            for f in scaled:
                stream.push(f)

        windows = args.frames - 4 + 1
        tasks = {
            "set (baseline)": lambda: window_phases(scaled[:4], 4),
            "push, plain": lambda: pushes(0),
            "push, order 4": lambda: pushes(4),
            "job --window 4": lambda: decode_stream(tmp / "in", None, tmp / "out", "4"),
            "job --window 4+4": lambda: decode_stream(tmp / "in", None, tmp / "out4", "4+4"),
        }
        per = {"set (baseline)": 1, "push, plain": args.frames, "push, order 4": args.frames,
               "job --window 4": windows, "job --window 4+4": windows - 4}
        best = {name: float("inf") for name in tasks}
        for _ in range(args.rounds):  # interleaved: each round runs every task once
            for name, task in tasks.items():
                best[name] = min(best[name], cpu(task, 1) / per[name])
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    base = best["set (baseline)"]
    print(f"# {width}x{height}, {args.frames} frames, min of {args.rounds} interleaved rounds, "
          "process CPU time")
    print("| per frame | ms | / set |")
    print("| --- | ---: | ---: |")
    for name, seconds in best.items():
        print(f"| {name} | {1000 * seconds:.2f} | {seconds / base:.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
