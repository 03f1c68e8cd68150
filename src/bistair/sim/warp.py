"""Synthetic captures with ground truth from a 2-D warp of the projected patterns.

This is the fast test generator (no 3-D geometry): camera pixels map to projector
coordinates through a horizontal stretch and offset, a vertical scale that changes down the
image (so a group of projector rows spans a varying number of camera rows), a roll, and per-
object horizontal shifts and domes (object height moves fringes sideways). Objects are
ellipses on a dark background; the image is integrated over each pixel (supersampled),
blurred, made noisy and quantised. The physical projector-camera rig is :mod:`bistair.sim`.

Examples
--------
>>> from bistair.codecs import make_spec
>>> spec = make_spec("bidirectional", width=360, height=240, period=20, partitions=3)
>>> scene = WarpScene(size=(120, 160), blobs=(Blob(80, 60, 50, 40),), noise=0.0, blur=0.0)
>>> images, truth = render_warp(spec, scene)
>>> images.shape, truth.coord(spec).shape, bool(truth.mask[60, 80]), bool(truth.mask[5, 5])
((6, 120, 160), (120, 160), True, False)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..codecs import encode
from ..core.captures import to_bit_depth
from ..spec import BaseSpec
from .truth import Truth


@dataclass(frozen=True)
class Blob:
    """An elliptical object: centre and radii in camera pixels, with its own look."""

    cx: float
    cy: float
    rx: float
    ry: float
    shift: float = 0.0  # extra projector columns (disparity of the object's mean height)
    dome: float = 0.0  # projector columns added at the centre, falling to 0 at the rim
    albedo: float = 1.0


@dataclass(frozen=True)
class WarpScene:
    """Camera size (rows, cols) and the camera-to-projector warp and image formation."""

    size: tuple[int, int] = (480, 640)
    blobs: tuple[Blob, ...] = ()  # empty: the whole field of view is one flat object
    stretch: float = 1.0  # projector columns per camera column
    offset: float = 0.0  # projector column seen by camera column 0
    scale_top: float = 1.0  # projector rows per camera row at the top of the image
    scale_bottom: float = 1.0  # ... and at the bottom
    row_offset: float = 0.0
    roll_deg: float = 0.0
    blur: float = 0.0  # Gaussian sigma in camera pixels
    noise: float = 0.0  # Gaussian noise sigma as a fraction of full scale
    gain: float = 0.9  # camera response to the brightest projector value on albedo 1
    ambient: float = 0.02
    bits: int | None = 8  # quantise to this many bits, or keep floats
    supersample: int = 3
    seed: int = 0
    albedo_texture: float = 0.0  # relative amplitude of a smooth albedo texture


def _geometry(scene: WarpScene, u: np.ndarray, v: np.ndarray):
    h = scene.size[0]
    r = np.deg2rad(scene.roll_deg)
    uu = u * np.cos(r) - v * np.sin(r)
    vv = u * np.sin(r) + v * np.cos(r)
    x = scene.offset + scene.stretch * uu
    y = (scene.row_offset + scene.scale_top * vv
         + 0.5 * (scene.scale_bottom - scene.scale_top) * vv**2 / h)
    obj = np.zeros(u.shape, np.int32)
    if not scene.blobs:
        obj[...] = 1
    for i, b in enumerate(scene.blobs, start=1):
        rho2 = ((u - b.cx) / b.rx) ** 2 + ((v - b.cy) / b.ry) ** 2
        inside = rho2 <= 1.0
        obj[inside] = i
        x = np.where(inside, x + b.shift + b.dome * (1.0 - rho2), x)
    return x, y, obj


def render_warp(spec: BaseSpec, scene: WarpScene,
                patterns: np.ndarray | None = None) -> tuple[np.ndarray, Truth]:
    """Render the captures of ``spec``'s patterns under ``scene``; returns (images, truth).

    Images are float32 in [0, 1] (quantised to ``scene.bits`` levels when set). The truth's
    ``coord(spec)`` is the projector coordinate along the coded axis.
    """
    pats = encode(spec) if patterns is None else patterns
    if spec.orientation == "rows":
        pats = pats.transpose(0, 2, 1)
    n_frames, p_rows, p_cols = pats.shape
    h, w = scene.size
    s = scene.supersample
    sub = (np.arange(s) + 0.5) / s - 0.5
    vv, uu = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    acc = np.zeros((n_frames, h, w))
    for dv in sub:
        for du in sub:
            x, y, obj = _geometry(scene, uu + du, vv + dv)
            col, row = np.rint(x).astype(np.int64), np.rint(y).astype(np.int64)
            lit = (obj > 0) & (col >= 0) & (col < p_cols) & (row >= 0) & (row < p_rows)
            vals = pats[:, np.clip(row, 0, p_rows - 1), np.clip(col, 0, p_cols - 1)]
            albedo = _albedo(scene, obj, uu + du, vv + dv)
            acc += (np.where(lit, vals * scene.gain, 0.0) + scene.ambient) * albedo
    img = acc / (s * s)
    if scene.blur > 0:
        img = ndimage.gaussian_filter(img, sigma=(0, scene.blur, scene.blur))
    rng = np.random.default_rng(scene.seed)
    if scene.noise > 0:
        img = img + rng.normal(0.0, scene.noise, img.shape)
    img = np.clip(img, 0.0, 1.0)
    if scene.bits:
        img = to_bit_depth(img, scene.bits, as_float=True)
    x, y, obj = _geometry(scene, uu.astype(float), vv.astype(float))
    lit = (obj > 0) & (x >= -0.5) & (x < p_cols - 0.5) & (y >= -0.5) & (y < p_rows - 0.5)
    # Only pixels wholly inside one lit object (plus a blur margin) are ground truth.
    margin = 1 + int(np.ceil(2 * scene.blur))
    mask = np.zeros_like(lit)
    for i in np.unique(obj[lit]):
        mask |= ndimage.binary_erosion(lit & (obj == i), iterations=margin)
    images = img.astype(np.float32)
    object_id = np.where(mask, obj, 0)
    if spec.orientation == "rows":  # the coded axis (x here) is the projector's rows
        images = np.ascontiguousarray(images.transpose(0, 2, 1))
        return images, Truth(coord_x=y.T, coord_y=x.T, object_id=object_id.T, mask=mask.T)
    return images, Truth(coord_x=x, coord_y=y, object_id=object_id, mask=mask)


def _albedo(scene: WarpScene, obj: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    alb = np.zeros(obj.shape)
    if not scene.blobs:
        alb[obj > 0] = 1.0
    for i, b in enumerate(scene.blobs, start=1):
        alb[obj == i] = b.albedo
    if scene.albedo_texture:
        tex = 1.0 + scene.albedo_texture * np.sin(u / 23.0) * np.cos(v / 17.0)
        alb = alb * tex
    return alb
