"""A binocular capture set as another tool might ship it, rendered on the two-camera virtual
rig: 12-step sinusoid (sine convention, ``phase_offset = -pi/2``) plus complementary Gray
code with inverse patterns, white and black frames first, BMP files ``0001.bmp`` ... in
``L/`` and ``R/``, a hand-written ``spec.json``, the projector's gamma 2.2 not
pre-compensated, and the calibration as OpenCV FileStorage YAML under the tool's own key
names (``cameraMatrixL``, ``distCoeffsL``, ... with 14 distortion numbers, ``imageSize``).

Used by ``tests/test_stereo_sample.py`` (640 x 512) and ``benchmarks/stereo_sample.py``
(1280 x 1024).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np

import bistair
from bistair.geometry.calibration import Calibration, save_calibration
from bistair.io.atomic import write_image
from bistair.sim import Imaging, preset
from bistair.sim.stereo import StereoRig, render_stereo

KEYS = ("left=cameraMatrixL,left_dist=distCoeffsL,right=cameraMatrixR,"
        "right_dist=distCoeffsR,R=rotationLR,T=translationLR")
FRAMES = ("white", "black", *(f"shift-{i}" for i in range(12)),
          *(name for i in range(7) for name in (f"gray-{i}", f"gray-{i}-inv")))


def rig(size: tuple[int, int]) -> StereoRig:
    """A pair 160 mm apart, not quite level, both lenses distorted, aimed at 650 mm."""
    return StereoRig.default(camera_size=size, baseline=160.0, working_distance=650.0,
                             camera_dist=(-0.09, 0.12, 0.0008, -0.0006, 0.0),
                             right_dist=(-0.07, 0.08, -0.0005, 0.0009, 0.0),
                             right_height=3.0, right_roll_deg=0.7)


def write_sample(out: Path, size: tuple[int, int], seed: int = 5) -> dict:
    """Write the sample into ``out`` (``L/``, ``R/``, ``spec.json``, ``calib/stereo.yml``)
    and, for the checks, ``truth/`` (each camera's depth and mask) and ``mono.json`` (the
    left camera and projector: an independent reconstruction). Returns the paths."""
    pair = rig(size)
    spec = bistair.make_spec("graycode", width=1920, height=1080, period=30, steps=12,
                             complementary=1, inverse=1, white=1,
                             phase_offset=-math.pi / 2).replace(frame_order=FRAMES)
    left, right, lt, rt = render_stereo(bistair.encode(spec), pair, preset("mugs-on-wall")[1],
                                        Imaging(gamma=2.2, seed=seed))
    for name, images in (("L", left), ("R", right)):
        (out / name).mkdir(parents=True)
        for i, img in enumerate(images, 1):
            write_image(out / name / f"{i:04d}.bmp", img)
    fields = json.loads(spec.to_json())
    for intensity in ("bits", "offset", "amplitude", "gamma"):
        fields.pop(intensity)
    fields["phase_offset"] = "-pi/2"
    (out / "spec.json").write_text(json.dumps(fields, indent=1))
    (out / "calib").mkdir()
    fs = cv2.FileStorage(str(out / "calib" / "stereo.yml"), cv2.FILE_STORAGE_WRITE)
    for key, dev in (("L", pair.left), ("R", pair.right)):
        fs.write(f"cameraMatrix{key}", dev.K)
        fs.write(f"distCoeffs{key}", np.append(dev.dist_coeffs, np.zeros(9))[None, :])
    fs.write("rotationLR", cv2.Rodrigues(pair.right.R)[0])  # a rotation vector
    fs.write("translationLR", pair.right.t.reshape(3, 1))
    fs.startWriteStruct("imageSize", cv2.FileNode_SEQ | cv2.FileNode_FLOW)
    for v in size:
        fs.write("", int(v))
    fs.endWriteStruct()
    fs.release()
    for name, truth in (("L", lt), ("R", rt)):
        (out / "truth" / name).mkdir(parents=True)
        np.save(out / "truth" / name / "depth.npy", truth.depth)
        np.save(out / "truth" / name / "mask.npy", truth.mask)
    save_calibration(Calibration.from_rig(pair.rig("left")), out / "mono.json")
    return {"L": out / "L", "R": out / "R", "spec": out / "spec.json",
            "yml": out / "calib" / "stereo.yml", "mono": out / "mono.json",
            "truth": out / "truth" / "L"}
