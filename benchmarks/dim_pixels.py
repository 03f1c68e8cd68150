"""Pixels whose own evidence cannot carry their order (issue 31): what leaving them out
costs and gains, per pixel, against the orders as the code reads them.

On the rendered presets (Gray code with phase shifts, plain, with inverses, shifted,
complementary; three read noises): the share of the truth pixels decoded and the share of
the decoded ones more than half a fringe off the truth, as read and as decoded. On kamino's
object (``../shared/data/kamino-object1``, if present), one period (its second ignored) and
two, each axis: the share of the image decoded, the share more than half a period off its
5 x 5 median, and the share of the pixels the rig's own decoder also decodes that differ from
it by over half a period; the rig's own figures beside them. On a dim warped object:
multi-frequency unwrapping's pixels in the dim object, decoded and wrong, with the
quarter-fringe limit alone and with the noise of the misses judged too.

    python benchmarks/dim_pixels.py [--scenes objects-on-plane,...] [--noise 0.005,0.02]
                                    [--camera 480x384] [--no-renders] [--no-kamino]
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from support.kamino_reference import decode_kamino  # noqa: E402
from support.real_parts import EXAMPLES, SHARED  # noqa: E402

import bistair  # noqa: E402
from bistair.codecs import get_codec  # noqa: E402
from bistair.io.read import read_with_spec  # noqa: E402
from bistair.sim import Imaging, expose, preset, trace  # noqa: E402
from bistair.sim.warp import Blob, WarpScene, render_warp  # noqa: E402

VARIANTS = {"plain": {}, "inverse": {"inverse": 1}, "shifted": {"gray_offset": 0.5},
            "complementary": {"complementary": 1},
            "inverse shifted": {"inverse": 1, "gray_offset": 0.5}}
SCENES = "objects-on-plane,sphere-on-plane,two-masks,mugs-on-wall,paper-sim"


def table(head: tuple[str, ...], rows: list[tuple]) -> None:
    """Print a Markdown table."""
    print("| " + " | ".join(head) + " |")
    print("| " + " | ".join("---" for _ in head) + " |")
    for row in rows:
        print("| " + " | ".join(str(v) for v in row) + " |")
    print()


def read_phase(res) -> np.ndarray:
    """The absolute phase of the orders as the code read them (NaN where none)."""
    return np.where(res.code >= 0, res.wrapped + 2 * np.pi * res.code, np.nan)


def renders(scenes: list[str], noises: list[float], camera: tuple[int, int]) -> None:
    totals: dict[tuple[str, float], np.ndarray] = {}
    for scene in scenes:
        rig, geometry = preset(scene, camera_size=camera)
        traced = trace(rig, geometry, Imaging())
        width, height = rig.projector.size
        for noise in noises:
            for name, params in VARIANTS.items():
                spec = bistair.make_spec("graycode", width=width, height=height, period=30,
                                         gamma=Imaging().gamma, **params)
                images = expose(traced, bistair.encode(spec), Imaging(read_noise=noise, seed=1))
                res = bistair.decode(images, spec, force=True)
                truth = traced.truth.coord(spec)
                mask = traced.truth.mask & np.isfinite(truth)
                true_phase = 2 * np.pi * truth / spec.period
                before = np.isfinite(read_phase(res)) & mask
                wrong_before = before & (np.abs(read_phase(res) - true_phase) > np.pi)
                after = res.mask & mask
                wrong_after = after & (np.abs(res.phase - true_phase) > np.pi)
                t = totals.setdefault((name, noise), np.zeros(5))
                t += [mask.sum(), before.sum(), wrong_before.sum(), after.sum(),
                      wrong_after.sum()]
    rows = []
    for (name, noise), t in totals.items():
        rows.append((name, f"{noise:g}", f"{100 * t[1] / t[0]:.1f}% -> {100 * t[3] / t[0]:.1f}%",
                     f"{100 * t[2] / t[1]:.3f}% -> {100 * t[4] / t[3]:.4f}%",
                     f"{100 * (t[1] - t[2] - t[3] + t[4]) / (t[1] - t[2]):.2f}%"))
    print(f"Rendered presets ({', '.join(scenes)}; camera {camera[0]}x{camera[1]}, 4 steps, "
          "period 30, the projector's gamma compensated), per pixel, as read -> decoded:\n")
    table(("code", "read noise", "truth pixels decoded", "of them wrong", "right ones lost"),
          rows)


def outliers(coord: np.ndarray, reach: float) -> float:
    """The share of the decoded pixels more than ``reach`` from their 5 x 5 median."""
    window = sliding_window_view(np.pad(coord, 2, constant_values=np.nan), (5, 5))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN windows
        median = np.nanmedian(window.reshape(*coord.shape, 25), axis=-1)
    valid = np.isfinite(coord)
    return float((np.abs(coord - median)[valid] > reach).mean())


def kamino() -> None:
    folder = SHARED / "kamino-object1"
    if not folder.is_dir():
        print("kamino-object1 not present\n")
        return
    full = json.loads((EXAMPLES / "kamino-object1.json").read_text())
    plain = {**full, "second_period": 0,
             "frames": ["ignore" if "second" in f else f for f in full["frames"]]}
    theirs = dict(zip("xy", decode_kamino(folder), strict=True))
    rows = []
    for label, data in (("one period", plain), ("two periods", full)):
        stack, spec = read_with_spec(folder, bistair.spec_from_dict(data))
        result = bistair.decode(stack, spec, force=True)
        for axis in "xy":
            res = getattr(result, axis)
            period = res.period
            cells = []
            for coord in (read_phase(res) * period / (2 * np.pi), res.coord):
                both = np.isfinite(coord) & np.isfinite(theirs[axis])
                off = (np.abs(coord - theirs[axis])[both] > period / 2).mean()
                cells.append((f"{100 * np.isfinite(coord).mean():.1f}%",
                              f"{100 * outliers(coord, period / 2):.4f}%", f"{100 * off:.4f}%"))
            rows.append((label, axis, *(" -> ".join(c) for c in zip(*cells, strict=True))))
    for axis in "xy":
        decoded = np.isfinite(theirs[axis]).mean()
        rows.append(("the rig's own decoder", axis, f"{100 * decoded:.1f}%",
                     f"{100 * outliers(theirs[axis], 50.0):.4f}%", "-"))
    print("kamino-object1, per pixel, as read -> decoded:\n")
    table(("set", "axis", "image decoded", "off their 5x5 median", "off the rig's decode"), rows)


def multifreq() -> None:
    scene = WarpScene(size=(240, 320), stretch=1.3, offset=40.0, blur=1.5, noise=0.01, seed=5,
                      blobs=(Blob(90, 120, 80, 100, dome=20, albedo=0.8),
                             Blob(240, 120, 70, 100, shift=37, dome=10, albedo=0.1)))
    codec = get_codec("multifreq")
    rows = []
    for periods, unwrap in (((42, 45, 48), "heterodyne"), ((640, 80, 20), "hierarchical")):
        spec = bistair.make_spec("multifreq", width=640, height=480, periods=periods,
                                 unwrap=unwrap)
        images, truth = render_warp(spec, scene)
        res = bistair.decode(images, spec, force=True)
        _, cols = codec._columns(images, spec)
        fs = codec.measure_columns(cols, spec)
        code = codec.code_columns(cols, spec, fs)
        coord = (fs.phi / (2 * np.pi) + code.code) * spec.period
        agreed = (code.maps["valid"] & (code.code >= 0) & (code.maps["worst"] < 0.25)
                  & (coord >= 0) & (coord < spec.coded_length))
        true_phase = 2 * np.pi * truth.coord(spec) / spec.period
        for oid, name in ((2, "dim (albedo 0.1)"), (1, "bright (albedo 0.8)")):
            on = truth.mask & (truth.object_id == oid)
            before = agreed & on
            wrong_before = before & (np.abs(fs.phi + 2 * np.pi * code.code - true_phase)
                                     > np.pi)
            after = res.mask & on
            wrong_after = after & (np.abs(res.phase - true_phase) > np.pi)
            rows.append((f"{unwrap} {'/'.join(map(str, periods))}", name,
                         f"{100 * before.sum() / on.sum():.1f}% -> "
                         f"{100 * after.sum() / on.sum():.1f}%",
                         f"{int(wrong_before.sum())} -> {int(wrong_after.sum())}"))
    print("Multi-frequency, a dim and a bright object (1% noise, 1.5 px blur), the quarter-"
          "fringe limit alone -> with the misses' noise:\n")
    table(("periods", "object", "decoded", "wrong pixels"), rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default=SCENES)
    parser.add_argument("--noise", default="0.005,0.02,0.05")
    parser.add_argument("--camera", default="480x384")
    parser.add_argument("--no-renders", action="store_true")
    parser.add_argument("--no-kamino", action="store_true")
    args = parser.parse_args()
    if not args.no_renders:
        camera = tuple(int(v) for v in args.camera.split("x"))
        renders(args.scenes.split(","), [float(v) for v in args.noise.split(",")], camera)
    if not args.no_kamino:
        kamino()
    multifreq()


if __name__ == "__main__":
    main()
