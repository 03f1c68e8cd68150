"""How close right and wrong two-camera inputs come to each stereo check's limit: the
margins of ``bistair.geometry.stereo_checks`` (docs/guide/stereo.md's table of refusals).

Every scene is rendered on the two-camera virtual rig (the projector between the cameras,
both aimed at the scene: vergence 2 x atan(B / 2 / 600 mm)), each camera decoded once, and
matched in four readings: ``right`` (as rendered, the rig's exact calibration), ``exchanged``
(LEFT and RIGHT swapped), ``upside down`` (the right images flipped top to bottom) and
``other rig`` (the calibration of a pair 0.6 times the baseline apart). Printed per case:
the matched share, the share of decoded left pixels whose projector rows disagree (both
axes), the projector misfits as given and in the other readings (share of points over 5
projector pixels off the projector that lit the others), what ``bistair stereo`` does with
it (ok, warned, or which check refuses) and the share of its points off by more than 1%.
Optics: ``default`` (:class:`bistair.sim.Imaging`) or ``hard`` (gamma 2.2, 3% read noise,
camera blur 1.2 px, projector blur 1.0 px, 15% ambient, and the projector's lens distortion
of the real procam-calibration rig: k1 -0.12, k2 0.164, p1 0.005, p2 -0.0007).

    python benchmarks/stereo_margins.py [--scenes all] [--methods graycode] [--optics
        default,hard] [--camera 320x256] [--baselines 200] [--seeds 4] [--axes columns]

A calibration whose right camera sits on the left (R, T inverted), a baseline of zero or
under 1 mm and the same captures twice are refused before any matching (no threshold).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import bistair
from bistair.errors import BistairError
from bistair.evaluation.benchmark import method_specs
from bistair.evaluation.stereo import depth_errors
from bistair.geometry.calibration import StereoCalibration
from bistair.geometry.stereo import readings, reconstruct_stereo
from bistair.geometry.stereo_checks import (
    MIN_MATCHED,
    MISFIT_FLOOR,
    MISFIT_RATIO,
    MISFIT_WARN,
    OTHER_AXIS_MAX,
)
from bistair.sim import Imaging, preset, scene_names
from bistair.sim.stereo import StereoRig, render_stereo

HARD = dict(gamma=2.2, read_noise=0.03, camera_blur=1.2, projector_blur=1.0, ambient=0.15)
PROJECTOR_DIST = (-0.12, 0.164, 0.005, -0.0007, 0.0)  # bistair calibrate on procam-calibration


def spec_for(method: str, axes: str) -> bistair.spec.BaseSpec:
    if method == "graycode":
        spec = bistair.make_spec("graycode", width=1920, height=1080, period=30,
                                 complementary=1, gamma=2.2)
    else:
        spec = method_specs((1920, 1080), gamma=2.2, methods=[method])[method][0]
    return spec.replace(orientation=axes)


def verdict(left, right, cal, spec) -> tuple[str, dict, object]:
    """What bistair stereo does with the decodes: ok, warned or the refusal; the figures
    (from a forced run when refused)."""
    try:
        res = reconstruct_stereo(left, right, cal, spec.orientation, offset=spec.offset)
        said = "warned" if res.info["warnings"] else "ok"
    except BistairError as exc:
        text = str(exc)
        said = ("refused: rows disagree" if "projector rows disagree" in text else
                "refused: exchanged" if "right way round?" in text and "lie off" in text else
                "refused: upside down" if "upside down" in text else
                "refused: few matches" if "found their match" in text else f"refused: {text}")
        try:
            res = reconstruct_stereo(left, right, cal, spec.orientation, offset=spec.offset,
                                     force=True)
        except BistairError:
            return said, {}, None
    return said, res.info, res


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default="all")
    parser.add_argument("--methods", default="graycode")
    parser.add_argument("--optics", default="default,hard")
    parser.add_argument("--camera", default="320x256")
    parser.add_argument("--baselines", default="200")
    parser.add_argument("--seeds", default="4")
    parser.add_argument("--axes", default="columns", help="columns, both, or columns,both")
    args = parser.parse_args()
    scenes = scene_names() if args.scenes == "all" else args.scenes.split(",")
    size = tuple(int(v) for v in args.camera.split("x"))
    rows, right_said, caught = [], [], {}
    for scene in scenes:
        for method in args.methods.split(","):
            for axes in args.axes.split(","):
                for optics in args.optics.split(","):
                    for baseline in map(float, args.baselines.split(",")):
                        for seed in map(int, args.seeds.split(",")):
                            start = time.perf_counter()
                            label = (f"{scene} {method} {axes} {optics} B{baseline:g} "
                                     f"s{seed}")
                            for row in config(scene, method, axes, optics, baseline, seed,
                                              size):
                                rows.append((label, *row))
                                if row[0] == "right":
                                    right_said.append((label, row[-2]))
                                else:
                                    caught.setdefault(row[0], []).append(row[-2])
                                print("  ".join(map(str, rows[-1])), flush=True)
                            print(f"  ({time.perf_counter() - start:.0f} s)", flush=True)
    print(f"\nlimits: matched >= {100 * MIN_MATCHED:g}%, other axis <= "
          f"{100 * OTHER_AXIS_MAX:g}%, misfits over {100 * MISFIT_FLOOR:g}% tried against "
          f"the other readings (refused at {MISFIT_RATIO:g} times fewer), warned over "
          f"{100 * MISFIT_WARN:g}%")
    refused = [label for label, said in right_said if said.startswith("refused")]
    warned = [label for label, said in right_said if said == "warned"]
    print(f"right inputs: {len(right_said)}, refused {len(refused)} {refused}, warned "
          f"{len(warned)} {warned}")
    for case, said in caught.items():
        n = sum(s.startswith("refused") for s in said)
        print(f"{case}: {len(said)}, refused {n}, warned {said.count('warned')}")


def config(scene: str, method: str, axes: str, optics: str, baseline: float, seed: int,
           size: tuple[int, int]) -> list[tuple]:
    hard = optics == "hard"
    rig = StereoRig.default(camera_size=size, baseline=baseline,
                            projector_dist=PROJECTOR_DIST if hard else (0.0,) * 5)
    spec = spec_for(method, axes)
    left, right, truth, _ = render_stereo(bistair.encode(spec), rig, preset(scene)[1],
                                          Imaging(seed=seed, **(HARD if hard else {})))
    try:
        dl, dr, flipped = (bistair.decode(images, spec) for images in
                           (left, right, right[:, ::-1]))
    except BistairError as exc:  # the decoder's own checks refuse these captures
        return [("right", "-", "-", "-", "-", f"decode refused: {str(exc)[:60]}", "-")]
    cal = StereoCalibration.from_rig(rig)
    other = StereoCalibration.from_rig(StereoRig.default(camera_size=size,
                                                         baseline=0.6 * baseline))
    out = []
    for case, a, b, c in (("right", dl, dr, cal), ("exchanged", dr, dl, cal),
                          ("upside down", dl, flipped, cal), ("other rig", dl, dr, other)):
        said, info, res = verdict(a, b, c, spec)
        tried = readings(a, b, c, spec.orientation) if case == "right" else {}
        wrong = (depth_errors(res.depth, truth.depth, truth.mask).get("wrong_share", 0.0)
                 if res is not None else float("nan"))
        alts = info.get("other_readings") or {k: v[0] for k, v in tried.items()
                                              if k != "as given"}
        out.append((case, _pct(info.get("matched_fraction")),
                    _pct(info.get("other_axis_share")), _pct(info.get("projector_misfits"), 3),
                    "; ".join(f"{k} {_pct(v, 3)}" for k, v in alts.items()) or "-",
                    said, _pct(wrong)))
    return out


def _pct(value: float | None, digits: int = 1) -> str:
    if value is None or not np.isfinite(value):
        return "-"
    return f"{100 * value:.{digits}f}%"


if __name__ == "__main__":
    main()
