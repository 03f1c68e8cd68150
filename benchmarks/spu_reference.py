"""bistair's stereo phase unwrapping against a NumPy transcription of the published
pipeline (Zhang et al.'s BSC MATLAB code, as its reference re-implementation is described),
both from the same captures of a rectified virtual rig, bistair through its commands.

The rig: two parallel cameras (already rectified, as the published data's
``1_Rectified/``, ``2_Rectified/``), a projector between them, one four-step set of
28.5 fringes over a 1280-px projector (``T = 1280 / 28.5``) in the BSC convention
``I_n = a + b*cos(2*pi*x/T - 2*pi*n/4)`` (bistair's ``shift_sign -1``). The frames are
written as ``%04d.bmp``, the three 3x4 matrices as MATLAB ``.mat`` files with 1-based
camera pixels (``mCamera1Rectified.mat``, ``mCamera2Rectified.mat``, ``mProjector.mat``),
then the user's path runs: ``bistair patterns multifreq --periods T --steps 4
--shift-sign -1``, ``bistair import-calibration --projection-matrices ...`` (pixel origin
1 by default for ``.mat``) and ``bistair stereo ... --depth-range``.

The reference (:func:`reference`), per window: wrapped phase ``mod(atan2(I1 - I3, I0 -
I2), 2*pi)``, modulation ``0.5*hypot(.)`` under 5 grey levels dropped; for each left pixel
the right pixel of least circular phase difference within the depth range's disparities
(sub-pixel by a parabola), triangulated by the two cameras and projected into the
projector for the order ``round((x_p*2*pi/T - phi)/(2*pi))``; the point from the left
camera and the projector column of the absolute phase (1-based pixel grid); regions of
continuous phase: large ones kept, small ones shifted by whole orders to agree with their
neighbours; points more than 2 mm from a 9x9 median of z removed.

Reported: bistair's points against the reference's, the median nearest-point distance
(mm) and the share over 2 mm (scipy cKDTree), and both against the truth (the nearest
truth point; ``ours_same_pixel_truth``: bistair's share within 2 mm of the truth's depth at
the same pixel, ``ours_same_pixel_over_5mm`` over 5 mm off it or where it has none), and
the decided pixels bistair left undecided as mixed (``mixed``:
:func:`bistair.geometry.unwrap.mixed_pixels`).

    python benchmarks/spu_reference.py [--camera 320x240] [--scenes two-masks,plane]
        [--projector-at 0.5,0.3] [--motion 0,1]

Done when (issue 34): bistair's points at least 90% of the reference's, median distance
0.3 mm, at most 1% over 2 mm.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import tempfile
import warnings
from pathlib import Path

import cv2
import numpy as np
import scipy.io
from click.testing import CliRunner
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from bistair.app.cli import cli
from bistair.codecs import encode, make_spec
from bistair.io.atomic import write_image
from bistair.sim import preset, trace
from bistair.sim.motion import Motion, render_moving
from bistair.sim.render import Imaging, expose
from bistair.sim.rig import Camera, Projector, look_rotation
from bistair.sim.stereo import StereoRig

PROJECTOR = (1280, 800)
FRINGES = 28.5
MIN_MODULATION = 5.0  # grey levels
#: a region of continuous phase is reliable from this share of the valid pixels
LARGE = 0.02
MEDIAN, MEDIAN_OFF = 9, 2.0  # pixels, mm
#: 0-based camera pixels to 1-based: (u + 1, v + 1)
ONE_BASED = np.array([[1.0, 0, 1], [0, 1, 1], [0, 0, 1]])


def rectified_rig(camera: tuple[int, int], baseline: float = 100.0,
                  projector_at: float = 0.5, distance: float = 600.0) -> StereoRig:
    """Two parallel cameras ``baseline`` mm apart (rectified: same rows), the projector
    on the line between them aimed at ``(0, 0, distance)``."""
    w, h = camera
    f = 1.5 * w
    left = Camera(w, h, f, f, (w - 1) / 2, (h - 1) / 2)
    right = Camera(w, h, f, f, (w - 1) / 2, (h - 1) / 2, R=np.eye(3),
                   t=np.array([-baseline, 0.0, 0.0]))
    x = projector_at * baseline
    rot = look_rotation(float(np.rad2deg(np.arctan2(x, distance))))
    pw, ph = PROJECTOR
    proj = Projector(pw, ph, 2000.0, 2000.0, (pw - 1) / 2, (ph - 1) / 2, R=rot,
                     t=-rot @ np.array([x, 0.0, 0.0]))
    return StereoRig(left, right, proj, distance)


def matrices(srig: StereoRig) -> list[np.ndarray]:
    """The three 3x4 matrices of the left camera's frame, the cameras' 1-based (MATLAB's),
    the projector's column as the pattern's."""
    out = []
    for dev, one in ((srig.left, True), (srig.right, True), (srig.projector, False)):
        K = np.array([[dev.fx, 0, dev.cx], [0, dev.fy, dev.cy], [0, 0, 1]])
        P = K @ np.hstack([dev.R, np.asarray(dev.t, float)[:, None]])
        out.append(ONE_BASED @ P if one else P)
    return out


def _wrapped(frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    i0, i1, i2, i3 = (f.astype(np.float64) for f in frames[:4])
    phi = np.mod(np.arctan2(i1 - i3, i0 - i2), 2 * np.pi)
    mod = 0.5 * np.hypot(i1 - i3, i0 - i2)
    return np.where(mod >= MIN_MODULATION, phi, np.nan), mod


def _null_points(rows: list[np.ndarray]) -> np.ndarray:
    """Points ``(N, 3)`` from the rows ``(N, 4)`` of their linear equations (3 or 4)."""
    A = np.stack(rows, axis=1)
    if A.shape[1] == 3:
        return np.linalg.solve(A[:, :, :3], -A[:, :, 3:])[..., 0]
    _, _, vt = np.linalg.svd(A)
    X = vt[:, -1]
    return X[:, :3] / X[:, 3:]


def _disparities(P1: np.ndarray, P2: np.ndarray, depth: tuple[float, float],
                 size: tuple[int, int]) -> tuple[int, int]:
    """The disparity range (whole pixels) of the depth range at the image centre."""
    c = np.array([(size[0] - 1) / 2 + 1, (size[1] - 1) / 2 + 1, 1.0])
    M, p4 = P1[:, :3], P1[:, 3]
    ray = np.linalg.solve(M, c)
    centre = -np.linalg.solve(M, p4)
    out = []
    for z in depth:
        X = centre + ray * (z - centre[2]) / ray[2]
        u1 = P1 @ np.append(X, 1)
        u2 = P2 @ np.append(X, 1)
        out.append(u1[0] / u1[2] - u2[0] / u2[2])
    return int(math.floor(min(out))) - 1, int(math.ceil(max(out))) + 1


def reference(left: np.ndarray, right: np.ndarray, P1: np.ndarray, P2: np.ndarray,
              Pp: np.ndarray, period: float, depth: tuple[float, float],
              start: int = 0, pixels: bool = False) -> np.ndarray | tuple[np.ndarray, ...]:
    """The published pipeline's points ``(N, 3)`` (the matrices' world frame, mm) of one
    window of four frames starting at frame ``start`` of each camera (with ``pixels``, also
    their left rows and columns)."""
    phl, _ = _wrapped(left)
    phr, _ = _wrapped(right)
    phl = np.mod(phl + np.pi / 2 * start, 2 * np.pi)
    phr = np.mod(phr + np.pi / 2 * start, 2 * np.pi)
    h, w = phl.shape
    dmin, dmax = _disparities(P1, P2, depth, (w, h))
    ds = np.arange(dmin, dmax + 1)
    cost = np.full((len(ds), h, w), np.inf)
    for i, d in enumerate(ds):
        if d >= w or d <= -w:
            continue
        diff = np.full((h, w), np.nan)
        if d >= 0:
            diff[:, d:] = phl[:, d:] - phr[:, :w - d]
        else:
            diff[:, :d] = phl[:, :d] - phr[:, -d:]
        cost[i] = np.abs(np.angle(np.exp(1j * diff)))
    cost[np.isnan(cost)] = np.inf
    best = np.argmin(cost, axis=0)
    ok = np.isfinite(phl) & np.isfinite(np.take_along_axis(cost, best[None], 0)[0])
    ok &= (best > 0) & (best < len(ds) - 1)
    v, u = np.nonzero(ok)
    b = best[v, u]
    a, c0, c = cost[b - 1, v, u], cost[b, v, u], cost[b + 1, v, u]
    curv = a - 2 * c0 + c
    with np.errstate(invalid="ignore", divide="ignore"):
        off = np.where(np.isfinite(curv) & (curv > 0), 0.5 * (a - c) / curv, 0.0)
    disparity = ds[b] + np.clip(off, -0.5, 0.5)
    x1, y1 = u + 1.0, v + 1.0  # MATLAB's grid
    x2 = x1 - disparity
    X = _null_points([x1[:, None] * P1[2] - P1[0], y1[:, None] * P1[2] - P1[1],
                      x2[:, None] * P2[2] - P2[0], y1[:, None] * P2[2] - P2[1]])
    q = np.column_stack([X, np.ones(len(X))]) @ Pp.T
    xp = q[:, 0] / q[:, 2]
    phi = phl[v, u]
    order = np.rint((xp * 2 * np.pi / period - phi) / (2 * np.pi))
    Phi = np.full((h, w), np.nan)
    Phi[v, u] = phi + 2 * np.pi * order
    Phi = _clean_regions(Phi)
    v, u = np.nonzero(np.isfinite(Phi))
    column = Phi[v, u] / (2 * np.pi) * period
    x1, y1 = u + 1.0, v + 1.0
    X = _null_points([x1[:, None] * P1[2] - P1[0], y1[:, None] * P1[2] - P1[1],
                      column[:, None] * Pp[2] - Pp[0]])
    z = np.full((h, w), np.nan)
    z[v, u] = X[:, 2]
    keep = np.abs(z - _nan_median(z, MEDIAN)) <= MEDIAN_OFF
    if pixels:
        return X[keep[v, u]], v[keep[v, u]], u[keep[v, u]]
    return X[keep[v, u]]


def _clean_regions(Phi: np.ndarray) -> np.ndarray:
    """Regions of continuous absolute phase (4-neighbours within pi): those of at least
    :data:`LARGE` of the valid pixels kept, smaller ones shifted by the whole orders their
    reliable neighbours say (dropped without any)."""
    h, w = Phi.shape
    idx = np.arange(h * w).reshape(h, w)
    valid = np.isfinite(Phi)
    edges = []
    for a, b in ((Phi[:, :-1], Phi[:, 1:]), (Phi[:-1], Phi[1:])):
        same = np.abs(a - b) < np.pi
        ia = idx[:, :-1] if a.shape[1] == w - 1 else idx[:-1]
        ib = idx[:, 1:] if a.shape[1] == w - 1 else idx[1:]
        edges.append((ia[same], ib[same]))
    i = np.concatenate([e[0] for e in edges])
    j = np.concatenate([e[1] for e in edges])
    graph = coo_matrix((np.ones(len(i)), (i, j)), shape=(h * w, h * w))
    _, labels = connected_components(graph, directed=False)
    labels = labels.reshape(h, w)
    sizes = np.bincount(labels[valid], minlength=labels.max() + 1)
    large = valid & (sizes[labels] >= LARGE * valid.sum())
    out = np.where(large, Phi, np.nan)
    small = valid & ~large
    # the whole orders each small region needs: the median over its borders with large ones
    shifts: dict[int, list[float]] = {}
    for a, b, la, lb in ((Phi[:, :-1], Phi[:, 1:], large[:, :-1], large[:, 1:]),
                         (Phi[:-1], Phi[1:], large[:-1], large[1:])):
        sa = small[:, :-1] if a.shape[1] == w - 1 else small[:-1]
        sb = small[:, 1:] if a.shape[1] == w - 1 else small[1:]
        lab_a = labels[:, :-1] if a.shape[1] == w - 1 else labels[:-1]
        lab_b = labels[:, 1:] if a.shape[1] == w - 1 else labels[1:]
        for s_mask, lab, mine, theirs in ((sa & lb, lab_a, a, b), (sb & la, lab_b, b, a)):
            for lb_, d in zip(lab[s_mask], (theirs - mine)[s_mask], strict=True):
                shifts.setdefault(int(lb_), []).append(float(d))
    for lab, diffs in shifts.items():
        k = np.rint(np.median(diffs) / (2 * np.pi))
        region = small & (labels == lab)
        out[region] = Phi[region] + 2 * np.pi * k
    return out


def _nan_median(z: np.ndarray, size: int) -> np.ndarray:
    """The median of the finite values in a ``size`` x ``size`` window about each pixel."""
    r = size // 2
    padded = np.pad(z, r, constant_values=np.nan)
    win = np.lib.stride_tricks.sliding_window_view(padded, (size, size))
    out = np.full(z.shape, np.nan)
    rows = np.nonzero(np.isfinite(z).any(axis=1))[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN windows: NaN
        for y in rows:
            out[y] = np.nanmedian(win[y].reshape(z.shape[1], -1), axis=1)
    return out


def read_ply(path: Path) -> np.ndarray:
    """The points ``(N, 3)`` of a bistair PLY (binary little-endian, x y z float32, r g b
    uchar)."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    rec = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("r", "u1"), ("g", "u1"),
                    ("b", "u1")])
    arr = np.frombuffer(data[end:], rec)
    return np.column_stack([arr["x"], arr["y"], arr["z"]]).astype(np.float64)


def run(scene: str, camera: tuple[int, int], projector_at: float, folder: Path,
        seed: int = 1, motion: float = 0.0, continue_unseen: bool = False) -> dict[str, float]:
    """Render (the objects moving ``motion`` mm per frame along x, when given), run the
    reference and bistair's commands, compare; the figures (the truth of frame 0)."""
    period = PROJECTOR[0] / FRINGES
    rig, geometry = preset(scene, camera_size=camera)
    srig = rectified_rig(camera, projector_at=projector_at)
    spec = make_spec("multifreq", width=PROJECTOR[0], height=PROJECTOR[1],
                     periods=(period,), steps=4, shift_sign=-1)
    im = dataclasses.replace(Imaging(), seed=seed, gamma=1.0)
    patterns = encode(spec)
    frames, truth = {}, None
    for i, (side, name) in enumerate((("left", "1_Rectified"), ("right", "2_Rectified"))):
        cam = dataclasses.replace(im, seed=im.seed + i)
        traced = trace(srig.rig(side), geometry, cam)
        if motion:
            imgs, _ = render_moving(patterns, srig.rig(side), geometry,
                                    Motion(translation=(motion, 0.0, 0.0)), cam)
        else:
            imgs = expose(traced, patterns, cam)
        (folder / name).mkdir(parents=True, exist_ok=True)
        for k, img in enumerate(imgs):
            write_image(folder / name / f"{k:04d}.bmp", img)
        frames[side] = np.stack([cv2.imread(str(folder / name / f"{k:04d}.bmp"),
                                            cv2.IMREAD_GRAYSCALE) for k in range(len(imgs))])
        truth = traced.truth if side == "left" else truth
    P = matrices(srig)
    names = ("mCamera1Rectified.mat", "mCamera2Rectified.mat", "mProjector.mat")
    for name, M in zip(names, P, strict=True):
        scipy.io.savemat(folder / name, {name.split(".")[0]: M})
    z = truth.depth[np.isfinite(truth.depth)]
    depth = (math.floor(z.min() - 10), math.ceil(z.max() + 10))
    ref, rv, ru = reference(frames["left"], frames["right"], *P, period, depth, pixels=True)
    invoke = CliRunner().invoke
    steps = [["patterns", "multifreq", "--periods", f"{period!r}", "--steps", "4",
              "--shift-sign", "-1", "--width", str(PROJECTOR[0]), "--height",
              str(PROJECTOR[1]), "--out", str(folder / "patterns")],
             ["import-calibration", "--projection-matrices",
              ",".join(str(folder / n) for n in names), "--camera-size",
              f"{camera[0]}x{camera[1]}", "--projector-size",
              f"{PROJECTOR[0]}x{PROJECTOR[1]}", "--out", str(folder / "rig.json")],
             ["stereo", str(folder / "1_Rectified"), str(folder / "2_Rectified"), "--spec",
              str(folder / "patterns" / "spec.json"), "--calibration",
              str(folder / "rig.json"), "--depth-range", f"{depth[0]}:{depth[1]}", "--out",
              str(folder / "out")] + (["--continue-unseen"] if continue_unseen else [])]
    for args in steps:
        res = invoke(cli, args)
        if res.exit_code != 0:
            raise SystemExit(f"bistair {' '.join(args[:2])}: {res.output}")
    ours = read_ply(folder / "out" / "cloud.ply")
    depth = np.load(folder / "out" / "depth.npy")
    decided = np.isfinite(depth)
    info = json.loads((folder / "out" / "info.json").read_text())
    mixed = info["mixed"]
    truth_points = truth.points[truth.mask]
    near = cKDTree(ref).query(ours)[0]
    out = {"reference": len(ref), "bistair": len(ours), "ratio": len(ours) / max(len(ref), 1),
           "median_mm": float(np.median(near)), "over_2mm": float(np.mean(near > 2.0))}
    if len(truth_points):
        tree = cKDTree(truth_points)
        to_truth = tree.query(ours)[0]
        ref_to_truth = tree.query(ref)[0]
        out["ref_truth_mm"] = float(np.median(ref_to_truth))
        out["ours_truth_mm"] = float(np.median(to_truth))
        # bistair's points over 2 mm from the reference: on the truth (over 2 mm from it)?
        out["ours_far_off_truth"] = float(np.mean(to_truth[near > 2.0] > 2.0)) if np.any(
            near > 2.0) else 0.0
        out["ref_off_truth"] = float(np.mean(ref_to_truth > 2.0))
        out["ours_off_truth"] = float(np.mean(to_truth > 2.0))
        # at the same pixel (the truth's depth is on the left camera's grid), and the
        # decided pixels left undecided as mixed (geometry.unwrap.mixed_pixels)
        with np.errstate(invalid="ignore"):
            same = np.abs(depth[decided] - truth.depth[decided]) <= 2.0
            over = ~(np.abs(depth[decided] - truth.depth[decided]) <= 5.0)
        out["ours_same_pixel_truth"] = float(np.mean(same)) if same.size else 0.0
        out["ours_same_pixel_over_5mm"] = float(np.mean(over)) if over.size else 0.0
        out["mixed"] = mixed
        # the reference's right pixels (its point within 2 mm of the truth's depth at the
        # pixel) that bistair leaves undecided
        with np.errstate(invalid="ignore"):
            right = np.abs(ref[:, 2] - truth.depth[rv, ru]) < 2.0
        out["ref_right"] = int(right.sum())
        out["ref_right_left"] = int(np.sum(right & ~decided[rv, ru]))
    out["continued"] = info.get("continued", 0)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="320x240")
    parser.add_argument("--scenes", default="two-masks,sphere-on-plane,plane")
    parser.add_argument("--projector-at", default="0.5,0.3")
    parser.add_argument("--motion", default="0", help="mm per frame along x, e.g. 0,1")
    parser.add_argument("--continue-unseen", action="store_true",
                        help="bistair stereo --continue-unseen (unwrap_fill's step)")
    args = parser.parse_args()
    camera = tuple(int(v) for v in args.camera.split("x"))
    for scene in args.scenes.split(","):
        for at, moving in ((float(a), float(m)) for a in args.projector_at.split(",")
                           for m in args.motion.split(",")):
            with tempfile.TemporaryDirectory() as tmp:
                r = run(scene, camera, at, Path(tmp), motion=moving,
                        continue_unseen=args.continue_unseen)
            extra = "".join(f", {k} {v:.3f}" for k, v in r.items() if "truth" in k)
            extra += (f", mixed {r.get('mixed', 0)}, continued {r['continued']}, reference's "
                      f"right pixels left {r.get('ref_right_left', 0)} of "
                      f"{r.get('ref_right', 0)}")
            print(f"{scene:16s} at {at} moving {moving:g} mm/frame: reference "
                  f"{r['reference']} points, bistair {r['bistair']} "
                  f"({100 * r['ratio']:.1f}%), median distance "
                  f"{r['median_mm']:.3f} mm, over 2 mm {100 * r['over_2mm']:.2f}%{extra}",
                  flush=True)


if __name__ == "__main__":
    main()
