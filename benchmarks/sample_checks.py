"""The figures the checks moved onto pass 0's sample judge, before and after (issue 32):
shift order, axis and stair misfit, on every real capture in ../shared/data (part by part)
and on tests/test_spec_mismatch.py's rendered cases.

Before: each check as it judged at the branch point, on samples found by scanning the full
maps (the formulas are kept here, only here, to compare); after: the same check on pass 0's
sample (``FringeSet.sample``, its strong pixels). Beside them, what the decode says now
(``force=True``: the checks that would refuse). Figures and limits:

- shift order: the median fit residual over the modulation of the N-step set (a swap is
  looked for above 0.3, and named when an exchange fits 3 times better: ``x3.2``);
- axis: how many times faster the phase changes down the columns than along the rows
  (refused above 1; before: per 4 rows against per 2 columns, after: per pixel both);
- stair misfit: the median distance from the nearest stair level in half gaps (refused
  above 0.7).

Run: ``python benchmarks/sample_checks.py [--real] [--mismatch]``; ``--speed 1.3|12``
times each check before and after instead, on ``decode_speed.py``'s default scene (one
kernel thread, process CPU time, the minimum over interleaved rounds, the OpenCV floor of
a 4-step decode in the same rounds).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import bistair  # noqa: E402
from bistair.codecs import REGISTRY  # noqa: E402
from bistair.codecs.bidirectional.bands import union_levels  # noqa: E402
from bistair.core.checks import (  # noqa: E402
    axis_rates,
    fit_residual,
    stair_misfit,
    stair_sample,
    swapped_frames,
)
from bistair.core.phase import wrap  # noqa: E402
from bistair.core.stair import stair_level_phase  # noqa: E402
from bistair.errors import BistairError  # noqa: E402


def shift_figure(values: np.ndarray, shift_sign: int) -> str:
    """The residual a shift-order check judges, and the named swap's gain if any."""
    if values.shape[0] < 4 or values.shape[1] < 500:
        return "-"
    base = fit_residual(values, shift_sign)
    pair = swapped_frames(values, shift_sign)
    return f"{base:.3f}" + ("" if pair is None else f" swap{pair}")


def shift_sets(spec) -> list[list[int]]:
    sets: dict[str, list[int]] = {}
    for i, name in enumerate(spec.method_frames()):
        if "shift-" in name:
            sets.setdefault(name.rsplit("shift-", 1)[0], []).append(i)
    return [m for m in sets.values() if len(m) >= 4]


def old_shift(cols, valid, spec, samples: int = 20000) -> str:
    """The branch point's shift-order sample: every k-th valid pixel of the full map."""
    idx = np.flatnonzero(valid)
    idx = idx[:: max(1, idx.size // samples)]
    r, c = np.unravel_index(idx, valid.shape)
    return " ".join(shift_figure(np.stack([np.asarray(cols.frames.raw[m][r, c], np.float64)
                                           for m in members]), spec.shift_sign)
                    for members in shift_sets(spec)) or "-"


def new_shift(sample, spec, samples: int = 20000) -> str:
    r, c = np.nonzero(sample.strong)
    step = max(1, -(-r.size // samples))
    r, c = r[::step], c[::step]
    return " ".join(shift_figure(sample.values[members][:, r, c].astype(np.float64),
                                 spec.shift_sign) for members in shift_sets(spec)) or "-"


def old_axis(phi, valid) -> str:
    """The branch point's axis figure: every 4th row and 2nd column of the full maps."""
    sub = (slice(None, None, 4), slice(None, None, 2))
    p, v = phi[sub], valid[sub]
    along = np.abs(wrap(np.diff(p, axis=1)))[v[:, 1:] & v[:, :-1]]
    across = np.abs(wrap(np.diff(p, axis=0)))[v[1:] & v[:-1]]
    if min(along.size, across.size) < 500:
        return "-"
    return f"{np.median(across) / np.median(along):.3f}"


def new_axis(sample) -> str:
    rates = axis_rates(sample)
    return "-" if rates is None else f"{rates[1] / rates[0]:.3f}"


def levels_of(spec):
    if spec.method == "bidirectional":
        return union_levels(spec.partitions, spec.stairs)
    if spec.method == "lv":
        return stair_level_phase(np.arange(spec.levels), spec.levels)
    return None


def figures(images: np.ndarray, spec) -> list[str]:
    """Before and after of each moved check, and what the decode says now."""
    codec = REGISTRY[spec.method]
    try:
        _, cols = codec._columns(images, spec)
        fs = codec.measure_columns(cols, spec, None)
    except BistairError as exc:
        return ["-"] * 6 + [f"error: {str(exc)[:60]}"]
    out = ["-"] * 6
    if fs.sample is not None:
        out[0], out[1] = old_shift(cols, fs.valid, spec), new_shift(fs.sample, spec)
        out[2], out[3] = old_axis(fs.phi, fs.valid), new_axis(fs.sample)
    levels = levels_of(spec)
    if levels is not None and fs.stair is not None:
        theta = fs.stair[0]
        old = theta[::4, ::4][fs.valid[::4, ::4]][:20000].astype(np.float64)
        if old.size:
            out[4] = f"{stair_misfit(old, np.ones(old.size, bool), levels):.3f}"
        out[5] = f"{stair_misfit(*stair_sample(fs.sample, theta, fs.valid), levels):.3f}"
    del fs, cols
    try:
        res = bistair.decode(images, spec, force=True)
        forced = res.info.get("forced", [])
        out.append("; ".join(f[:70] for f in forced) or "decoded")
    except BistairError as exc:
        out.append(f"error: {str(exc)[:70]}")
    return out


def real_rows() -> list[tuple[str, ...]]:
    from support.real_parts import parts

    from bistair.io.read import read_with_spec

    rows, seen = [], set()
    for name, folder, spec, _ in parts():
        key = (str(folder), spec.to_json())
        if key in seen or spec.orientation == "both":  # (each axis alone is a part)
            continue
        seen.add(key)
        stack, spec = read_with_spec(folder, spec)
        rows.append((name.replace(" pixel", ""), *figures(stack, spec)))
        print(*rows[-1], sep=" | ", file=sys.stderr)
    return rows


def mismatch_rows() -> list[tuple[str, ...]]:
    import test_spec_mismatch as t

    from bistair.sim import Imaging, expose, preset, trace

    rig, geometry = preset("objects-on-plane", camera_size=(480, 384))
    imaging = Imaging(read_noise=0.01, camera_blur=1.0, seed=1)
    traced = trace(rig, geometry, imaging)
    rows = []
    for method in sorted(REGISTRY):
        spec = t._spec(method, rig, imaging)
        images = expose(traced, bistair.encode(spec), imaging)
        code = [i for i, name in enumerate(spec.frames) if "shift" not in name]
        cases = [("right spec", images, spec)]
        for case in t.COMMON + t.OWN.get(method, []):
            if case == "another method":
                others = [t._spec(m, rig, imaging) for m in sorted(REGISTRY) if m != method]
                wrong = [s for s in others if s.frame_count == spec.frame_count] or [
                    s for s in (t._same_frames(m, spec) for m in sorted(REGISTRY)
                                if m != method) if s is not None][:1]
                cases += [(f"another method ({s.method})", images, s) for s in wrong]
            elif case == "swapped code frames":
                frames = code if len(code) >= 2 else list(range(spec.steps, spec.steps * 2))
                for i in range(0, len(frames) - 1, 2):
                    swapped = images.copy()
                    swapped[[frames[i], frames[i + 1]]] = swapped[[frames[i + 1], frames[i]]]
                    cases.append((f"code frames {frames[i]},{frames[i + 1]} swapped",
                                  swapped, spec))
            elif case == "shift and code frames swapped":
                frames = code or list(range(spec.steps, spec.frame_count))
                for other in sorted({frames[0], frames[-1]}):
                    swapped = images.copy()
                    swapped[[0, other]] = swapped[[other, 0]]
                    cases.append((f"shift-0 and frame {other} swapped", swapped, spec))
            elif case == "swapped shift frames":
                swapped = images.copy()
                swapped[[0, 1]] = swapped[[1, 0]]
                cases.append((case, swapped, spec))
            else:
                cases.append((case, images, spec.replace(**t._changes(spec, case))))
        for label, imgs, sp in cases:
            rows.append((f"{method}: {label}", *figures(imgs, sp)))
            print(*rows[-1], sep=" | ", file=sys.stderr)
    return rows


def speed(size: str, count: int) -> None:
    """Each moved check timed before and after, with the floor, in interleaved rounds."""
    import time

    import cv2

    from bistair.codecs.base import shift_order_problem
    from bistair.core.checks import axis_problem
    from bistair.core.jit import set_threads
    from bistair.core.memory import keep_freed_memory
    from bistair.evaluation.speed import CASES, opencv_floor, speed_captures

    keep_freed_memory()
    cv2.setNumThreads(set_threads(1))
    spec = CASES[0].spec()  # the default decode's
    frames = speed_captures(spec, {"1.3": (1024, 1280), "12": (3000, 4000)}[size])
    codec = REGISTRY[spec.method]
    _, cols = codec._columns(frames, spec)
    fs = codec.measure_columns(cols, spec, None)
    theta, levels = fs.stair[0], levels_of(spec)

    def old_shift() -> None:  # the branch point's shift_order_problem
        idx = np.flatnonzero(fs.valid)
        idx = idx[:: max(1, idx.size // 20000)]
        r, c = np.unravel_index(idx, fs.valid.shape)
        for members in shift_sets(spec):
            swapped_frames(np.stack([np.asarray(cols.frames.raw[m][r, c], np.float64)
                                     for m in members]), spec.shift_sign)

    def old_misfit() -> float:  # the branch point's stair_misfit
        t = theta[::4, ::4][fs.valid[::4, ::4]][:20000]
        return stair_misfit(t, np.ones(t.size, bool), levels)

    from bistair.codecs import bidirectional
    from bistair.codecs.bidirectional import stairs
    from bistair.codecs.bidirectional.stairs_jit import decoded_sample

    fit_args: list = []
    fit = bidirectional.stair_fit

    def watch_fit(*args, **kwargs):
        fit_args.append((args, kwargs))
        return fit(*args, **kwargs)

    bidirectional.stair_fit = watch_fit
    try:
        bistair.decode(frames, spec)
    finally:
        bidirectional.stair_fit = fit
    (f_args, f_kw), grid = fit_args[0], stairs.grid_sample

    def old_fit() -> float:  # the branch point's sample: a scan of the decoded pixels
        stairs.grid_sample = decoded_sample
        try:
            return fit(*f_args, **f_kw)
        finally:
            stairs.grid_sample = grid

    jobs = {"floor": lambda: opencv_floor(frames),
            "stair fit before": old_fit,
            "stair fit after": lambda: fit(*f_args, **f_kw),
            "shift order before": old_shift,
            "shift order after": lambda: shift_order_problem(fs.sample, spec),
            "axis before": lambda: old_axis(fs.phi, fs.valid),
            "axis after": lambda: axis_problem(fs.sample, "columns"),
            "stair misfit before": old_misfit,
            "stair misfit after": lambda: stair_misfit(*stair_sample(fs.sample, theta,
                                                                     fs.valid), levels)}
    best = {k: np.inf for k in jobs}
    for _ in range(count):
        for key, job in jobs.items():
            t0 = time.process_time()
            job()
            best[key] = min(best[key], time.process_time() - t0)
    h, w = fs.phi.shape
    print(f"{h}x{w}, one thread, process CPU time, min of {count} rounds")
    for key, value in best.items():
        print(f"{key:22s} {1e3 * value:8.2f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--real", action="store_true", help="the real captures only")
    parser.add_argument("--mismatch", action="store_true", help="the rendered cases only")
    parser.add_argument("--speed", choices=("1.3", "12"), help="time the checks instead")
    parser.add_argument("--rounds", type=int, default=8)
    args = parser.parse_args()
    if args.speed:
        speed(args.speed, args.rounds)
        return
    both = not (args.real or args.mismatch)
    head = ("case", "shift order before", "after", "axis before", "after",
            "stair misfit before", "after", "decode now (force=True)")
    rows = (real_rows() if args.real or both else []) + (
        mismatch_rows() if args.mismatch or both else [])
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for row in rows:
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
