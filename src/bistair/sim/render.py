"""Image formation: cast rays once (:func:`trace`), then expose any pattern set (:func:`expose`).

Each camera pixel is integrated over ``s x s`` sub-rays. A sub-ray's nearest surface point is
lit when it lies inside the projector image, faces the projector and nothing lies on the
segment to the projector centre. It sees the projector pixel its point maps to (pixel ``c``
covers ``[c - 0.5, c + 0.5)``) of the emitted image ``blur(quantised(pattern) ** gamma)``.
Its signal (fraction of full scale) is
``exposure * albedo * (cos(incidence) * falloff * emitted + ambient)``; the image is blurred
(camera defocus), given Poisson shot noise and Gaussian read noise, clipped at full scale and
quantised.

Gamma: ``Imaging(gamma=1)`` is a linear projector; ``Imaging(gamma=2.2)`` with a spec of
``gamma=1`` is an uncompensated one; ``Imaging(gamma=2.2)`` with patterns encoded from a spec
with ``gamma=2.2`` is a pre-compensated one.

Examples
--------
>>> import numpy as np
>>> from bistair.sim import Imaging, Rig, Scene, Plane, render
>>> rig = Rig.default(camera_size=(40, 32), projector_size=(64, 48), projector_focal=100)
>>> scene = Scene([Plane(center=(0, 0, 600))])
>>> patterns = np.full((2, 48, 64), 0.5, np.float32)
>>> images, truth = render(patterns, rig, scene, Imaging(read_noise=0, full_well=0))
>>> images.shape, images.dtype, int(truth.mask.sum()) > 0, float(truth.depth[16, 20])
((2, 32, 40), dtype('uint8'), True, 600.0)
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from ..core.captures import to_bit_depth
from ..errors import BistairError
from .rig import Rig, dot
from .shapes import Scene
from .truth import Truth

_SHADOW_EPS = 1e-6  # relative distance along a shadow ray counted as the point itself
_BLOCK = 1 << 16  # rays per block of work


@dataclass(frozen=True)
class Imaging:
    """Image formation parameters (all seeded and deterministic).

    Geometry, used by :func:`trace`:

    - ``supersample``: sub-rays per pixel side (``s x s`` per pixel, averaged).
    - ``max_incidence_deg``: steeper views from camera or projector are not ground truth.
    - ``edge_margin``: truth-mask erosion in pixels (``None``: ``ceil(2 * camera_blur)``).
    - ``inverse_square``: projector irradiance falls as ``1/d^2``, normalised at the
      working distance.

    Radiometry, used by :func:`expose`:

    - ``gamma``: the projector's, ``emitted = pattern ** gamma``.
    - ``projector_bits``: pattern quantisation before the gamma (``None``: none).
    - ``projector_blur``: defocus, Gaussian sigma in projector pixels, on the emitted images.
    - ``projector_sampling``: ``"linear"`` (default), bilinear between pixel centres: the
      smooth image a defocused projector gives (a pixel's box convolved with the blur);
      ``"nearest"``, a point sees the one projector pixel it falls in (pixel ``c`` covers
      ``[c - 0.5, c + 0.5)``: sharp pixel edges, a 0.12 px staircase in the phase).
    - ``ambient``: ambient light, fraction of full scale on albedo 1.
    - ``exposure``: response to full white at normal incidence on albedo 1.
    - ``camera_blur``: defocus, Gaussian sigma in camera pixels.
    - ``full_well``: electrons at full scale for Poisson shot noise (0: none).
    - ``read_noise``: Gaussian sigma, fraction of full scale.
    - ``bits``: 8 gives uint8 codes, 10/12/14/16 uint16 codes, ``None`` float32 without
      quantisation; ``float_output`` returns the codes divided by full scale as float32.
    - ``seed``: the noise generator's seed.

    Every field is checked when the object is made: a value outside its range (a negative
    noise, a NaN blur, a gamma of 0, unknown bits, ...) raises
    :class:`~bistair.errors.BistairError` with one line naming the field.
    """

    gamma: float = 2.2
    ambient: float = 0.05
    exposure: float = 0.8
    read_noise: float = 0.005
    full_well: float = 10000.0
    bits: int | None = 8
    float_output: bool = False
    camera_blur: float = 1.0
    projector_blur: float = 0.5
    projector_bits: int | None = 8
    projector_sampling: str = "linear"
    inverse_square: bool = True
    supersample: int = 2
    max_incidence_deg: float = 80.0
    edge_margin: int | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        """Refuse parameters that cannot form an image.

        Raises
        ------
        BistairError
            One line naming the field (a ``ValueError``).

        Examples
        --------
        >>> Imaging(read_noise=-0.01)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        bistair.errors.BistairError: read noise (read_noise) must be a finite number of at least ...
        """
        for name, low, strict in _NUMBERS:
            _check_number(name, getattr(self, name), low, strict)
        if self.max_incidence_deg > 90:
            raise BistairError(f"incidence limit (max_incidence_deg) must be at most 90 degrees, "
                               f"got {self.max_incidence_deg}")
        if self.bits is not None and _whole(self.bits) not in (8, 10, 12, 14, 16):
            raise BistairError(f"camera bits (bits) must be 8, 10, 12, 14, 16 or None, got "
                               f"{self.bits!r}")
        wholes = (("projector_bits", "projector bits", 1, 16, True),
                  ("supersample", "sub-rays per pixel side", 1, 16, False),
                  ("edge_margin", "edge margin", 0, None, True), ("seed", "seed", 0, None, False))
        for name, label, low, high, optional in wholes:
            value = getattr(self, name)
            number = _whole(value)
            if optional and value is None:
                continue
            if number is None or number < low or (high is not None and number > high):
                span = f"from {low} to {high}" if high is not None else f"of at least {low}"
                named = label if label == name else f"{label} ({name})"
                raise BistairError(f"{named} must be a whole number {span}"
                                   f"{' or None' if optional else ''}, got {value!r}")
        if self.projector_sampling not in ("nearest", "linear"):
            raise BistairError(f"projector_sampling must be 'nearest' or 'linear', got "
                               f"{self.projector_sampling!r}")
        for name in ("float_output", "inverse_square"):
            if not isinstance(getattr(self, name), bool | np.bool_):
                raise BistairError(f"{name} must be True or False, got {getattr(self, name)!r}")


# the numbers of Imaging: field, lowest value, whether it is excluded
_NUMBERS = (("gamma", 0.0, True), ("ambient", 0.0, False), ("exposure", 0.0, True),
            ("read_noise", 0.0, False), ("full_well", 0.0, False), ("camera_blur", 0.0, False),
            ("projector_blur", 0.0, False), ("max_incidence_deg", 0.0, True))
_LABELS = {"gamma": "projector gamma", "ambient": "ambient light", "exposure": "exposure",
           "read_noise": "read noise", "full_well": "full well", "camera_blur": "camera blur",
           "projector_blur": "projector blur", "max_incidence_deg": "incidence limit"}


def _check_number(name: str, value: object, low: float, strict: bool) -> None:
    """Refuse an Imaging number that is not finite or lies below ``low`` (or at it)."""
    ok = (isinstance(value, int | float | np.number) and not isinstance(value, bool)
          and math.isfinite(value) and (value > low if strict else value >= low))
    if not ok:
        bound = f"above {low:g}" if strict else f"of at least {low:g}"
        raise BistairError(f"{_LABELS[name]} ({name}) must be a finite number {bound}, got "
                           f"{value!r}")


def _whole(value: object) -> int | None:
    """``value`` as an int if it is a whole number (not a bool), else None."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer):
        return None
    return int(value)


@dataclass(frozen=True, eq=False)
class Trace:
    """What the camera sees, per sub-ray pass: cast once, exposed for any pattern set."""

    rig: Rig
    imaging: Imaging
    truth: Truth
    coords: np.ndarray  # (passes, 2, H*W) float32 projector x, y of each sub-ray (NaN: unlit)
    gain: np.ndarray  # (passes, H*W) float32 albedo * cos * falloff where lit
    albedo: np.ndarray  # (passes, H*W) float32, 0 where nothing is hit


@dataclass
class _Hits:
    """Per ray of a pass (full length; NaN, 0 or False where nothing is hit)."""

    dirs: np.ndarray
    which: np.ndarray  # object id, 0 for nothing
    depth: np.ndarray
    proj: np.ndarray  # (N, 2) projector coordinates
    lit: np.ndarray
    gain: np.ndarray  # albedo * cos(incidence) * falloff where lit
    albedo: np.ndarray
    points: np.ndarray | None = None  # (N, 3), centre pass only
    normals: np.ndarray | None = None
    facing: np.ndarray | None = None  # both incidence angles below the limit


def _cast(rig: Rig, scene: Scene, u: np.ndarray, v: np.ndarray, falloff: bool,
          cos_max: float | None = None) -> _Hits:
    """Cast camera rays through pixel coordinates and light their hits.

    With ``cos_max`` (the centre pass) points, normals and the incidence test are kept.
    """
    cam, proj = rig.camera, rig.projector
    origin = cam.center
    dirs = cam.rays(u, v)
    n = len(dirs)
    t_all, surf_all, nrm_all = scene.cast(origin, dirs)
    idx = np.flatnonzero(surf_all >= 0)
    every = idx.size == n
    if every:  # no gathers needed
        d, t, surf, nrm = dirs, t_all, surf_all, nrm_all
    else:
        d, t, surf, nrm = dirs[idx], t_all[idx], surf_all[idx], nrm_all[idx]
    pts = origin + t[:, None] * d
    nd = dot(nrm, d)
    nrm *= np.where(nd > 0, -1.0, 1.0)[:, None]  # face the camera
    to_proj = proj.center - pts
    dist2 = dot(to_proj, to_proj)
    dist = np.sqrt(dist2)
    cos_proj = dot(nrm, to_proj) / dist
    xy = proj.project(pts)
    with np.errstate(invalid="ignore"):
        lit = ((xy[:, 0] >= -0.5) & (xy[:, 0] < proj.width - 0.5) & (xy[:, 1] >= -0.5)
               & (xy[:, 1] < proj.height - 0.5) & (cos_proj > 0))
    rays = np.flatnonzero(lit)
    lit[rays[scene.blocked(proj.center, -to_proj[rays], 1.0 - _SHADOW_EPS,
                           dist2[rays])]] = False
    if len(scene.surfaces) == 1:
        albedo = scene.surfaces[0].albedo_at(pts)
    else:
        albedo = np.zeros(idx.size)
        for i, surface in enumerate(scene.surfaces):
            sel = np.flatnonzero(surf == i)
            if sel.size:
                albedo[sel] = surface.albedo_at(pts[sel])
    gain = albedo * np.where(lit, cos_proj, 0.0)
    if falloff:
        gain *= rig.projector_distance**2 / dist2
    which = np.array(scene.ids, np.int32)[surf]
    if every:
        out = _Hits(dirs=dirs, which=which, depth=t, proj=xy, lit=lit, gain=gain,
                    albedo=albedo)
    else:
        out = _Hits(dirs=dirs, which=np.zeros(n, np.int32), depth=np.full(n, np.nan),
                    proj=np.full((n, 2), np.nan), lit=np.zeros(n, bool), gain=np.zeros(n),
                    albedo=np.zeros(n))
        out.which[idx], out.depth[idx], out.proj[idx] = which, t, xy  # depth: rays have z = 1
        out.lit[idx], out.gain[idx], out.albedo[idx] = lit, gain, albedo
    if cos_max is not None:
        cos_cam = np.abs(nd) / np.sqrt(dot(d, d))
        facing = (cos_cam > cos_max) & (cos_proj > cos_max)
        if every:
            out.points, out.normals, out.facing = pts, nrm, facing
        else:
            out.points = np.full((n, 3), np.nan)
            out.normals = np.full((n, 3), np.nan)
            out.facing = np.zeros(n, bool)
            out.points[idx], out.normals[idx], out.facing[idx] = pts, nrm, facing
    return out


def trace(rig: Rig, scene: Scene, imaging: Imaging | None = None,
          workers: int | None = None) -> Trace:
    """Cast the camera's rays into the scene once; see :func:`expose` and :func:`render`.

    Pixels are traced in blocks on ``workers`` threads (default: the CPU count); the result
    does not depend on it.
    """
    imaging = imaging or Imaging()
    cam = rig.camera
    h, w = cam.height, cam.width
    n = h * w
    passes = imaging.supersample ** 2
    out = dict(coords=np.empty((passes, 2, n), np.float32), gain=np.empty((passes, n), np.float32),
               albedo=np.empty((passes, n), np.float32), good=np.empty(n, bool),
               coord=np.empty((n, 2)), depth=np.empty(n), points=np.empty((n, 3)),
               normals=np.empty((n, 3)), which=np.empty(n, np.int32), lit=np.empty(n, bool))
    blocks = [slice(i, min(i + _BLOCK, n)) for i in range(0, n, _BLOCK)]
    if (workers or os.cpu_count() or 1) > 1 and len(blocks) > 1:
        _in_threads(workers or os.cpu_count() or 1,
                    lambda b: _trace_block(rig, scene, imaging, b, out), blocks)
    else:
        for b in blocks:
            _trace_block(rig, scene, imaging, b, out)
    margin = imaging.edge_margin
    if margin is None:
        margin = int(np.ceil(2 * imaging.camera_blur))
    mask = out["good"].reshape(h, w)
    if margin > 0:
        mask = ndimage.binary_erosion(mask, iterations=margin, border_value=1)
    truth = Truth(coord_x=out["coord"][:, 0].reshape(h, w),
                  coord_y=out["coord"][:, 1].reshape(h, w), depth=out["depth"].reshape(h, w),
                  points=out["points"].reshape(h, w, 3), normals=out["normals"].reshape(h, w, 3),
                  object_id=out["which"].reshape(h, w), lit=out["lit"].reshape(h, w), mask=mask)
    return Trace(rig, imaging, truth, out["coords"], out["gain"], out["albedo"])


def _trace_block(rig: Rig, scene: Scene, imaging: Imaging, block: slice, out: dict) -> None:
    """Trace the pixels ``block`` (flat indices) into the shared outputs ``out``."""
    w = rig.camera.width
    flat = np.arange(block.start, block.stop)
    uu, vv = (flat % w).astype(float), (flat // w).astype(float)
    cos_max = float(np.cos(np.deg2rad(imaging.max_incidence_deg)))
    centre = _cast(rig, scene, uu, vv, imaging.inverse_square, cos_max)
    good = centre.lit & centre.facing
    # one surface: every sub-ray hits the centre's object, is lit, and lies on the centre
    # hit's tangent plane to within the pixel's footprint (no depth step inside the pixel)
    footprint = centre.depth / rig.camera.fx
    s = imaging.supersample
    offsets = (np.arange(s) + 0.5) / s - 0.5
    for k, (dv, du) in enumerate((dv, du) for dv in offsets for du in offsets):
        sub = centre if du == dv == 0 else _cast(rig, scene, uu + du, vv + dv,
                                                  imaging.inverse_square)
        with np.errstate(invalid="ignore", divide="ignore"):
            planar = _plane_depth(rig, centre, sub.dirs)
            good &= (sub.which == centre.which) & sub.lit & (
                np.abs(sub.depth - planar) <= footprint)
        out["coords"][k, :, block] = np.where(sub.lit, sub.proj.T, np.nan)
        out["gain"][k, block] = sub.gain
        out["albedo"][k, block] = sub.albedo
    out["good"][block] = good
    out["coord"][block] = centre.proj
    out["depth"][block] = centre.depth
    out["points"][block] = centre.points
    out["normals"][block] = centre.normals
    out["which"][block] = centre.which
    out["lit"][block] = centre.lit


def _plane_depth(rig: Rig, centre: _Hits, dirs: np.ndarray) -> np.ndarray:
    """Depth where rays ``dirs`` from the camera meet the tangent planes of the centre hits."""
    return (dot(centre.normals, centre.points - rig.camera.center)
            / dot(centre.normals, dirs))


def expose(trace: Trace, patterns: np.ndarray, imaging: Imaging | None = None,
           workers: int | None = None, first_frame: int = 0) -> np.ndarray:
    """Camera images ``(frames, H, W)`` of projector ``patterns`` on a traced scene.

    ``patterns`` are floats in [0, 1] of shape ``(frames, projector height, width)``, e.g.
    :func:`bistair.encode`. ``imaging`` overrides the radiometry of the trace's imaging
    (supersampling, incidence limit, edge margin and falloff stay those of the trace).
    Returns integer codes (uint8 for 8 bits, uint16 otherwise) or float32, see
    :class:`Imaging`. Frames are made on ``workers`` threads (default: the CPU count), each
    with its own noise stream from ``imaging.seed``, so the result does not depend on it.
    Frame ``k`` takes the noise of frame ``first_frame + k`` of a longer set, so exposing a
    set one frame at a time (``first_frame=k``) gives the images of exposing it whole.
    """
    imaging = imaging or trace.imaging
    proj = trace.rig.projector
    pats = np.asarray(patterns, float)
    if pats.ndim == 2:
        pats = pats[None]
    if pats.shape[1:] != (proj.height, proj.width):
        raise ValueError(f"patterns of {pats.shape[2]}x{pats.shape[1]} do not fit the "
                         f"{proj.width}x{proj.height} projector")
    if imaging.projector_sampling == "nearest":  # the projector pixel of every sub-ray
        where = [_nearest_pixel(x, y, proj.width, proj.height) for x, y in trace.coords]
    else:
        where = list(trace.coords)
    ambient = np.float32(imaging.ambient) * trace.albedo.sum(axis=0)
    # the children SeedSequence(seed).spawn(n) gives, from any first frame
    seeds = [np.random.SeedSequence(imaging.seed, spawn_key=(first_frame + k,))
             for k in range(len(pats))]
    jobs = [(pattern, seed) for pattern, seed in zip(pats, seeds, strict=True)]
    count = min(workers or os.cpu_count() or 1, len(jobs))
    if count > 1:
        frames = _in_threads(count, lambda job: _frame(trace, imaging, where, ambient, *job),
                             jobs)
    else:
        frames = [_frame(trace, imaging, where, ambient, *job) for job in jobs]
    return np.stack(frames)


def _in_threads(count: int, func: Callable[[Any], Any], items: list) -> list:
    """``[func(item) for item in items]`` on ``count`` threads. On an exception (Ctrl-C
    included) the items not started are cancelled, so it propagates once the running ones
    end rather than after all of them."""
    pool = ThreadPoolExecutor(count)
    try:
        futures = [pool.submit(func, item) for item in items]
        return [future.result() for future in futures]
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    finally:
        pool.shutdown(wait=True)


def _frame(trace: Trace, imaging: Imaging, where: list, ambient: np.ndarray,
           pattern: np.ndarray, seed: np.random.SeedSequence) -> np.ndarray:
    """One camera frame of one projector pattern."""
    proj, cam = trace.rig.projector, trace.rig.camera
    pat = np.clip(pattern, 0.0, 1.0)
    if imaging.projector_bits:
        top = (1 << imaging.projector_bits) - 1
        pat = np.round(pat * top) / top
    emitted = pat**imaging.gamma if imaging.gamma != 1.0 else pat
    if imaging.projector_blur > 0:
        emitted = ndimage.gaussian_filter(emitted, imaging.projector_blur, mode="nearest")
    flat = emitted.astype(np.float32).ravel()
    acc = ambient.copy()
    for pos, gain in zip(where, trace.gain, strict=True):
        if imaging.projector_sampling == "nearest":
            acc += gain * flat[pos]
        else:
            acc += gain * _bilinear(flat, pos[0], pos[1], proj.width, proj.height)
    img = (acc.astype(np.float64) * (imaging.exposure / len(trace.gain))).reshape(
        cam.height, cam.width)
    if imaging.camera_blur > 0:
        img = ndimage.gaussian_filter(img, imaging.camera_blur, mode="nearest")
    rng = np.random.default_rng(seed)
    img = np.clip(img, 0.0, 1.0)
    if imaging.full_well > 0:
        img = rng.poisson(img * imaging.full_well) / imaging.full_well
    if imaging.read_noise > 0:
        img = img + rng.normal(0.0, imaging.read_noise, img.shape)
    img = np.clip(img, 0.0, 1.0)
    if imaging.bits is None:
        return img.astype(np.float32)
    return to_bit_depth(img, imaging.bits, as_float=imaging.float_output)


def _nearest_pixel(x: np.ndarray, y: np.ndarray, width: int, height: int) -> np.ndarray:
    """Flat index of the projector pixel holding each point (pixel c covers [c-0.5, c+0.5))."""
    col = np.clip(np.floor(np.nan_to_num(x) + 0.5).astype(np.int64), 0, width - 1)
    row = np.clip(np.floor(np.nan_to_num(y) + 0.5).astype(np.int64), 0, height - 1)
    return row * width + col


def _bilinear(flat: np.ndarray, x: np.ndarray, y: np.ndarray, width: int,
              height: int) -> np.ndarray:
    """Bilinear interpolation between projector pixel centres (anything where NaN)."""
    x, y = np.nan_to_num(x), np.nan_to_num(y)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0).astype(np.float32), (y - y0).astype(np.float32)
    c0 = np.clip(x0.astype(np.int64), 0, width - 1)
    c1 = np.clip(x0.astype(np.int64) + 1, 0, width - 1)
    r0 = np.clip(y0.astype(np.int64), 0, height - 1) * width
    r1 = np.clip(y0.astype(np.int64) + 1, 0, height - 1) * width
    top = flat[r0 + c0] * (1 - fx) + flat[r0 + c1] * fx
    bottom = flat[r1 + c0] * (1 - fx) + flat[r1 + c1] * fx
    return top * (1 - fy) + bottom * fy


def render(patterns: np.ndarray, rig: Rig, scene: Scene,
           imaging: Imaging | None = None) -> tuple[np.ndarray, Truth]:
    """Images of ``patterns`` projected on ``scene`` and the ground truth.

    Equivalent to ``t = trace(rig, scene, imaging); expose(t, patterns), t.truth``.
    """
    traced = trace(rig, scene, imaging)
    return expose(traced, patterns), traced.truth
