"""What motion does to the phase of a stream, against the virtual rig's truth.

:func:`stream_errors` renders a stream whose shift advances one step per frame on a scene
whose objects move (:mod:`bistair.sim.motion`), takes the phase of the first window
(plain N-step) and the binomial self-compensation of orders 1..K
(:mod:`bistair.core.motion`), and scores each against the truth traced at the time it
describes (``(N+K-1)/2``): the RMS of the phase error and the amplitude of its ripple at
twice the fringe frequency (:func:`ripple`), in radians and in depth along the camera rays
(:func:`depth_per_pixel`), over the pixels of the moving objects that
the truth keeps at every frame used.

Examples
--------
>>> import numpy as np
>>> phase = np.tile(np.linspace(0, 8 * np.pi, 64, endpoint=False), (32, 1))
>>> error = 0.05 * np.sin(2 * phase + 1.0)
>>> round(ripple(error, phase, np.ones(phase.shape, bool), sigma=8.0), 3)
0.05
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..core.motion import compensate, window_phases
from ..core.phase import TWO_PI, wrap
from ..sim.motion import Motion, moving, render_moving, trace_frames
from ..sim.render import Imaging
from ..sim.rig import Rig
from ..sim.shapes import Scene


def ripple(error: np.ndarray, phase: np.ndarray, mask: np.ndarray, sigma: float) -> float:
    """Mean amplitude (radians) of the error's component at twice the fringe frequency.

    A lock-in: ``error * exp(-2i * phase)`` averaged over a Gaussian window of ``sigma``
    camera pixels (about a fringe, so that the phase turns within it) among the ``mask``
    pixels gives the local complex amplitude; its modulus times 2, averaged over the mask.

    Parameters
    ----------
    error : (H, W) array
        Phase error in radians (any value where not ``mask``).
    phase : (H, W) array
        The true phase (radians, wrapped or not).
    mask : (H, W) bool
        The pixels to measure.
    sigma : float
        Window in camera pixels.
    """
    m = np.asarray(mask, bool)
    e = np.where(m, error, 0.0).astype(np.float64)
    two = 2.0 * np.where(m, phase, 0.0)
    weight = ndimage.gaussian_filter(m.astype(np.float64), sigma, mode="constant")
    c = ndimage.gaussian_filter(e * np.cos(two), sigma, mode="constant")
    s = ndimage.gaussian_filter(e * np.sin(two), sigma, mode="constant")
    keep = m & (weight > 0.2)
    if not keep.any():
        return float("nan")
    return float(np.mean(2.0 * np.hypot(c[keep], s[keep]) / weight[keep]))


def depth_per_pixel(rig: Rig, points: np.ndarray, orientation: str = "columns",
                    step: float = 0.5) -> np.ndarray:
    """How far (mm, along z) a point moves along its camera ray per projector pixel of the
    coded axis: the depth a phase error of ``2*pi/T`` rad costs (NaN where unknown).

    ``points`` are ``(H, W, 3)`` world points of the camera frame (the truth's); the ray
    through the camera centre (the origin) is followed ``step`` mm deeper.

    Examples
    --------
    >>> rig = Rig.default(camera_size=(64, 48))
    >>> mm = depth_per_pixel(rig, np.array([[[0.0, 0.0, 600.0]]]))
    >>> # 2000 px focal length, 632 mm away, the rays 18.4 degrees apart: 2000 sin / 632
    >>> round(float(mm[0, 0]), 2)
    1.0
    """
    p = np.asarray(points, float)
    deeper = p * ((p[..., 2:] + step) / p[..., 2:])
    axis = 0 if orientation == "columns" else 1
    with np.errstate(invalid="ignore", divide="ignore"):
        moved = rig.projector.project(deeper)[..., axis] - rig.projector.project(p)[..., axis]
        return np.abs(step / moved)


@dataclass
class StreamErrors:
    """Per compensation order (0: plain N-step): phase error RMS and 2x ripple (radians),
    the ripple in depth (mm, along the camera rays), the pixels scored, and the fringe
    period in camera pixels."""

    rms: dict[int, float]
    ripple: dict[int, float]
    ripple_mm: dict[int, float]
    pixels: dict[int, int]
    period_px: float


def stream_errors(rig: Rig, scene: Scene, motion: Motion, period: float, steps: int = 4,
                  orders: Sequence[int] = (0, 1, 2, 3, 4), imaging: Imaging | None = None,
                  orientation: str = "columns") -> StreamErrors:
    """Render ``steps + max(orders)`` frames of a stream (frame ``i`` shows shift ``i mod
    steps`` of one ``period``) with the scene moving, and score plain N-step (order 0) and
    each compensation order against the truth at the time the result describes.

    Examples
    --------
    >>> from bistair.sim import preset
    >>> from bistair.sim.motion import parse_motion
    >>> rig, scene = preset("sphere-on-plane", camera_size=(96, 80))
    >>> im = Imaging(read_noise=0, full_well=0)
    >>> moved = stream_errors(rig, scene, parse_motion("1px"), 60, orders=(0, 2), imaging=im)
    >>> round(moved.period_px), moved.ripple[0] > 5 * moved.ripple[2]
    (6, True)
    """
    imaging = imaging or Imaging()
    top = max(orders)
    proj = rig.projector
    axis = np.arange(proj.width if orientation == "columns" else proj.height, dtype=float)
    shifts = TWO_PI * np.arange(steps + top) / steps
    wave = 0.5 + 0.5 * np.cos(TWO_PI * axis[None, :] / period + shifts[:, None])
    if imaging.gamma != 1.0:
        wave = wave ** (1.0 / imaging.gamma)  # patterns pre-compensate the gamma
    if orientation == "columns":
        patterns = np.repeat(wave[:, None, :], proj.height, axis=1)
    else:
        patterns = np.repeat(wave[:, :, None], proj.width, axis=2)
    frames, truths = render_moving(patterns, rig, scene, motion, imaging)
    phases, _ = window_phases(frames.astype(np.float32), steps)
    times = sorted({(steps + k - 1) / 2 for k in orders})
    at = dict(zip(times, trace_frames(rig, scene, motion, times, imaging), strict=True))
    ids = [scene.ids[i] for i in moving(scene, motion.whole)]
    rms, rip, rip_mm, count = {}, {}, {}, {}
    period_px = float("nan")
    for k in orders:
        truth = at[(steps + k - 1) / 2].truth
        coord = truth.coord(orientation)
        used = truths[:steps + k]
        mask = truth.mask & np.isin(truth.object_id, ids) & np.isfinite(coord)
        for t in used:
            mask &= t.mask & (t.object_id == truth.object_id)
        true_phase = TWO_PI * np.where(mask, coord, 0.0) / period
        estimate = compensate(phases[:k + 1], k)[0] if k else phases[0]
        error = np.asarray(wrap(estimate - true_phase), np.float64)
        if np.isnan(period_px):
            grad = np.abs(np.gradient(np.where(mask, coord, np.nan),
                                      axis=1 if orientation == "columns" else 0))
            period_px = float(period / np.nanmedian(grad[mask])) if mask.any() else 8.0
        rms[k] = float(np.sqrt(np.mean(error[mask] ** 2))) if mask.any() else float("nan")
        rip[k] = ripple(error, true_phase, mask, period_px)
        mm = error * (period / TWO_PI) * depth_per_pixel(rig, truth.points, orientation)
        rip_mm[k] = ripple(np.where(mask, mm, 0.0), true_phase, mask & np.isfinite(mm),
                           period_px)
        count[k] = int(mask.sum())
    return StreamErrors(rms, rip, rip_mm, count, period_px)
