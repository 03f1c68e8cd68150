"""Board features mapped to the projector on the virtual rig: local homography against local
quadratic fit.

The rig of ``tests/test_calib.py`` (camera 640 x 512 with distortion, projector 960 x 540),
the 9 x 6 checkerboard (20 mm) in the eight poses of ``bistair.sim.boards.POSES``, default
imaging (0.5% read noise, shot noise, 1 px defocus, gamma 2.2 pre-compensated). For each
decode, both axes at once: the corners found in the white frame and in the mean image
(error against their true camera positions), then the true camera positions mapped to the
projector by each fit (error against their true projector positions), for windows of 0.4,
0.7 and 1.0 feature spacings (``share`` 0.2, 0.35, 0.5 of the spacing as the half-width;
bistair uses 0.35). About 2 minutes a decode on 2 cores.

    python benchmarks/corner_fit.py [--methods multifreq,graycode,alone]
"""

from __future__ import annotations

import argparse
import dataclasses

import cv2
import numpy as np

import bistair
from bistair.geometry.board import Board
from bistair.geometry.calibration import Calibration
from bistair.geometry.corners import feature_spacing, local_homography, sample_local
from bistair.sim import Imaging, Rig, Scene, expose, trace
from bistair.sim.boards import POSES, board_plane
from bistair.sim.rig import euler

SHARES = (0.2, 0.35, 0.5)


def specs() -> dict[str, bistair.spec.BaseSpec]:
    common = dict(width=960, height=540, orientation="both", white=1, gamma=2.2)
    return {"multifreq": bistair.make_spec("multifreq", periods=(960, 120, 15), **common),
            "graycode": bistair.make_spec("graycode", period=30, **common),
            "alone": bistair.make_spec("graycode", steps=0, inverse=1, **common)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--methods", default="multifreq,graycode,alone")
    args = parser.parse_args()
    rig = Rig.default(camera_size=(640, 512), projector_size=(960, 540), projector_focal=1000,
                      camera_dist=(-0.08, 0.05, 0, 0, 0), projector_dist=(0.03, 0, 0, 0, 0))
    truth = Calibration.from_rig(rig)
    board = Board("checkerboard", 9, 6, 20.0)
    obj = board.object_points().astype(float)
    imaging = Imaging(seed=0)
    for name in args.methods.split(","):
        spec = specs()[name]
        patterns = bistair.encode(spec)
        errors: dict[tuple[str, str], list[np.ndarray]] = {}
        for i, pose in enumerate(POSES):
            seeded = dataclasses.replace(imaging, seed=i)
            traced = trace(rig, Scene([board_plane(board, *pose)]), seeded)
            result = bistair.decode(expose(traced, patterns, seeded), spec)
            rot = euler(*pose[:3])
            world = obj @ rot.T + (np.array(pose[3:], float) - rot @ obj.mean(axis=0))
            cam = cv2.projectPoints(world, np.zeros(3), np.zeros(3), truth.camera.K,
                                    truth.camera.dist)[0].reshape(-1, 2)
            proj = cv2.projectPoints(world @ truth.R.T + truth.T, np.zeros(3), np.zeros(3),
                                     truth.projector.K, truth.projector.dist)[0].reshape(-1, 2)
            for image_name, image in (("white frame", result.texture),
                                      ("mean image", (result.x.average + result.y.average) / 2)):
                found = board.detect(image)
                if found is None:
                    continue
                if np.linalg.norm(found[0] - cam[0]) > np.linalg.norm(found[0] - cam[-1]):
                    found = found[::-1]  # a half-turn of the labels
                errors.setdefault(("corners in the", image_name), []).append(
                    np.hypot(*(found - cam).T))
            maps = np.stack([result.coord_x, result.coord_y])
            for share in SHARES:
                radius = int(np.clip(round(share * feature_spacing(cam, board.columns)), 3, 30))
                for fit_name, fit in (("homography", local_homography),
                                      ("quadratic", sample_local)):
                    got = fit(maps, cam, radius).T
                    errors.setdefault((fit_name, f"share {share}"), []).append(
                        np.hypot(*(got - proj).T))
        for (what, how), values in errors.items():
            err = np.concatenate(values)
            ok = np.isfinite(err)
            print(f"{name:10s} {what:15s} {how:12s} mapped {ok.mean():6.1%}  RMS "
                  f"{np.sqrt(np.mean(err[ok] ** 2)):.4f} px  median {np.median(err[ok]):.4f} "
                  f"px  max {err[ok].max():.4f} px")


if __name__ == "__main__":
    main()
