"""What motion does to the phase, and what binomial self-compensation leaves of it.

A stream whose shift advances one step per frame (frame i shows shift i mod 4 of one
4-step set) on sphere-on-plane, the sphere moving sideways (along the coded axis) at 0,
0.5, 1, 2 and 4 camera pixels per frame, rendered on the virtual rig with each frame at its
own pose. Plain four-step (the first window) and binomial self-compensation of orders 1-4
(windows 0..K, Zhang et al., ECCV 2024) are scored against the truth traced at the time
each describes ((N+K-1)/2 frames): the RMS of the phase error and the amplitude of its
ripple at twice the fringe frequency (a lock-in over about a fringe,
:func:`bistair.evaluation.motion.ripple`), in radians (and the ripple in depth along the
camera rays, mm, for plain and order 4), over the sphere's pixels that the
truth keeps at every frame used. Median of the seeds; default optics (1% read noise, 1 px
camera blur, gamma 2.2 compensated) and, with --clean, no noise (the ripple alone).

    python benchmarks/motion.py [--camera 320x256] [--period 60] [--seeds 3] [--clean]

Done when (issue 34): at 1 px/frame the order-4 ripple is at most 1/10 of plain four-step's.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

from bistair.evaluation.motion import stream_errors
from bistair.sim import Imaging, preset
from bistair.sim.motion import parse_motion

SPEEDS = (0.0, 0.5, 1.0, 2.0, 4.0)
ORDERS = (0, 1, 2, 3, 4)
DEFAULT = dict(gamma=2.2, read_noise=0.01, camera_blur=1.0, projector_blur=0.5, ambient=0.05)
CLEAN = dict(DEFAULT, read_noise=0.0, full_well=0.0)


def table(camera: tuple[int, int], period: float, seeds: int, clean: bool,
          speeds=SPEEDS, orders=ORDERS) -> dict[float, dict[str, dict[int, float]]]:
    """speed -> {"rms": {order: rad}, "ripple": {order: rad}, "ripple_mm": {order: mm}},
    median of the seeds."""
    rig, scene = preset("sphere-on-plane", camera_size=camera)
    optics = CLEAN if clean else DEFAULT
    out = {}
    for speed in speeds:
        runs = [stream_errors(rig, scene, parse_motion(f"{speed:g}px"), period,
                              orders=orders, imaging=Imaging(**optics, seed=seed))
                for seed in range(seeds)]
        out[speed] = {key: {k: statistics.median(getattr(r, key)[k] for r in runs)
                            for k in orders} for key in ("rms", "ripple", "ripple_mm")}
        out[speed]["pixels"] = runs[0].pixels[max(orders)]
        out[speed]["period_px"] = runs[0].period_px
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="320x256")
    parser.add_argument("--period", type=float, default=60.0)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--clean", action="store_true", help="no camera noise")
    args = parser.parse_args(argv)
    try:
        width, height = (int(v) for v in args.camera.lower().split("x"))
    except ValueError:
        print(f"--camera must be WIDTHxHEIGHT, got {args.camera!r}", file=sys.stderr)
        return 2
    start = time.perf_counter()
    rows = table((width, height), args.period, args.seeds, args.clean)
    first = rows[SPEEDS[0]]
    print(f"sphere-on-plane {width}x{height}, period {args.period:g} projector px "
          f"({first['period_px']:.1f} camera px), 4 steps, "
          f"{'no noise' if args.clean else 'default optics'}, median of {args.seeds} seeds; "
          f"radians; {first['pixels']} sphere pixels at rest")
    head = " | ".join(f"{'plain' if k == 0 else f'K={k}'}" for k in ORDERS)
    print(f"| px/frame | RMS: {head} | ripple: {head} | ripple mm: plain | K=4 |")
    print("|---:|" + "---:|" * (2 * len(ORDERS) + 2))
    for speed, row in rows.items():
        rms = " | ".join(f"{row['rms'][k]:.4f}" for k in ORDERS)
        rip = " | ".join(f"{row['ripple'][k]:.4f}" for k in ORDERS)
        mm = " | ".join(f"{row['ripple_mm'][k]:.4f}" for k in (0, max(ORDERS)))
        print(f"| {speed:g} | {rms} | {rip} | {mm} |")
    one = rows[1.0]["ripple"]
    print(f"at 1 px/frame the order-4 ripple is {one[4] / one[0]:.3f} of plain four-step's "
          f"(done when at most 0.1); {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
