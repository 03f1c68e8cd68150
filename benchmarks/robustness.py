"""Robustness of every method on the same rendered scenes of the virtual rig.

Sweeps, one factor at a time from the baseline (paper-sim geometry, camera 640 x 512,
1% read noise, 1 px camera defocus, 0.5 px projector defocus, gamma 2.2 pre-compensated,
ambient 0.05):

- read noise, camera defocus, uncompensated projector gamma, ambient light (exposure scaled
  so the brightest pixel stays below full scale);
- object width in fringes, 0.5 to 6 (a scene of isolated ellipsoids, 1.7 groups tall);
- the number of fringes of the coded methods, 36 / 64 / 100 / 144 by P x S = 6x6 .. 12x12
  (period 30, 17, 11, 8 px on the 1080-px projector; fringes = ceil(1080 / period)).

Prints a table per factor (order error rate and coverage; for widths the share of each
object decoded right) and writes plots and ``robustness.json`` into ``--out``.

    python benchmarks/robustness.py [--out bench-out] [--camera 640x512] [--quick]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bistair.codecs.bidirectional import stairs_for  # noqa: E402
from bistair.evaluation.benchmark import method_specs, run  # noqa: E402
from bistair.sim import Ellipsoid, Imaging, Rig, Scene, preset, trace  # noqa: E402

PROJECTOR = (1080, 1080)
BASE = dict(gamma=2.2, read_noise=0.01, camera_blur=1.0, projector_blur=0.5, ambient=0.05,
            exposure=0.8, seed=0)
METHODS = ["bidirectional", "bidirectional (paper decoder)", "lv", "phase-coding", "graycode",
           "multifreq"]


def widths_scene() -> tuple[Scene, list[float]]:
    """Isolated ellipsoids 0.5 to 6 fringes wide (9 mm per fringe of 30 px at 600 mm)."""
    widths = [0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0]
    fringe_mm = 30 * 600 / 2000  # period x distance / projector focal
    objects, x = [], -150.0
    for i, w in enumerate(widths):
        rx = w * fringe_mm / 2
        x += rx + 12
        y = -45 if i % 2 else 45
        objects.append(Ellipsoid(center=(x, y, 600), radii=(rx, 15, 8), albedo=0.7))
        x += rx + 12
    return Scene(objects), widths


def sweep(traced, factor: str, values, make_imaging, make_specs=None, progress=None):
    rows = []
    for value in values:
        specs = (make_specs or (lambda _: method_specs(PROJECTOR, gamma=2.2)))(value)
        comp = run(traced, specs, imaging=make_imaging(value))
        for row in comp.rows:
            rows.append({"factor": factor, "value": value, "method": row.label,
                         "frames": row.frames, "coverage": row.scores["coverage"],
                         "order_error_rate": row.scores["order_error_rate"],
                         "phase_rmse": row.scores["phase_rmse"],
                         "objects": {str(i): row.scores.get("objects", {}).get(i, 0.0)
                                     for i in comp.objects}})
        if progress:
            progress(f"{factor}={value}")
    return rows


def imaging_with(**changes) -> Imaging:
    return Imaging(**{**BASE, **changes})


def fringes_specs(period: int):
    parts, stairs = stairs_for(math.ceil(PROJECTOR[0] / period))
    specs = method_specs(PROJECTOR, period=period, gamma=2.2)
    bid = specs["bidirectional"][0].replace(partitions=parts, stairs=stairs)
    specs["bidirectional"] = (bid, {})
    specs["bidirectional (paper decoder)"] = (bid, {"strategy": "paper"})
    return specs


def print_table(rows, factor: str, key: str) -> None:
    values = sorted({r["value"] for r in rows if r["factor"] == factor})
    print(f"\n{factor}: {key}")
    print(f"{'method':<30}" + "".join(f"{v:>10}" for v in values))
    for method in METHODS:
        cells = []
        for v in values:
            r = next(r for r in rows if r["factor"] == factor and r["value"] == v
                     and r["method"] == method)
            cells.append(f"{100 * r[key]:9.3f}%")
        print(f"{method:<30}" + "".join(f"{c:>10}" for c in cells))


def plot(rows, factor: str, key: str, out: Path, label: str) -> None:
    fig, ax = plt.subplots(figsize=(6.4, 4))
    for method in METHODS:
        pts = sorted((r["value"], r[key]) for r in rows
                     if r["factor"] == factor and r["method"] == method)
        ax.plot([p[0] for p in pts], [100 * p[1] for p in pts], marker="o", label=method)
    ax.set_xlabel(factor)
    ax.set_ylabel(label)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / f"{factor}-{key}.png", dpi=90)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("bench-out"))
    parser.add_argument("--camera", default="640x512")
    parser.add_argument("--quick", action="store_true", help="fewer values per factor")
    args = parser.parse_args()
    camera = tuple(int(v) for v in args.camera.split("x"))
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()

    def progress(msg: str) -> None:
        print(f"[{time.perf_counter() - t0:6.1f}s] {msg}", flush=True)

    rig, scene = preset("paper-sim", camera_size=camera)
    traced = trace(rig, scene, imaging_with())
    q = args.quick
    rows = []
    rows += sweep(traced, "read noise", [0.005, 0.02, 0.08] if q else
                  [0.005, 0.01, 0.02, 0.04, 0.08],
                  lambda v: imaging_with(read_noise=v), progress=progress)
    rows += sweep(traced, "camera defocus (px)", [0.5, 2.0, 4.0] if q else
                  [0.5, 1.0, 2.0, 3.0, 4.0],
                  lambda v: imaging_with(camera_blur=v), progress=progress)
    rows += sweep(traced, "uncompensated gamma", [1.0, 2.2] if q else [1.0, 1.5, 2.2, 2.8],
                  lambda v: imaging_with(gamma=v),
                  lambda v: method_specs(PROJECTOR, gamma=1.0), progress=progress)
    rows += sweep(traced, "ambient light", [0.0, 0.5] if q else [0.0, 0.1, 0.3, 0.6, 1.0],
                  lambda v: imaging_with(ambient=v, exposure=0.8 / (1 + v)),
                  progress=progress)
    rows += sweep(traced, "fringes (period px)", [30, 11] if q else [30, 17, 11, 8],
                  lambda v: imaging_with(), fringes_specs, progress=progress)
    small_rig = Rig.default(camera_size=camera, projector_size=PROJECTOR)
    wscene, widths = widths_scene()
    wtraced = trace(small_rig, wscene, imaging_with())
    wrows = sweep(wtraced, "object width", [0], lambda v: imaging_with(), progress=progress)
    for r in wrows:  # one row per (object, method): its width in fringes
        for i, w in enumerate(widths, start=1):
            rows.append({"factor": "object width (fringes)", "value": w,
                         "method": r["method"], "frames": r["frames"],
                         "coverage": r["objects"].get(str(i), 0.0),
                         "order_error_rate": 0.0, "phase_rmse": float("nan"), "objects": {}})
    (args.out / "robustness.json").write_text(json.dumps(rows, indent=1) + "\n")
    for factor in ("read noise", "camera defocus (px)", "uncompensated gamma", "ambient light",
                   "fringes (period px)"):
        print_table(rows, factor, "order_error_rate")
        print_table(rows, factor, "coverage")
        plot(rows, factor, "order_error_rate", args.out, "order error rate (%)")
        plot(rows, factor, "coverage", args.out, "coverage (%)")
    print_table(rows, "object width (fringes)", "coverage")
    print("(object width: share of each object's truth pixels decoded right)")
    plot(rows, "object width (fringes)", "coverage", args.out, "object decoded right (%)")
    progress(f"plots and robustness.json in {args.out}/")


if __name__ == "__main__":
    main()
