"""Stereo phase unwrapping of a stream: a depth map for every window of two cameras'
frames whose shift advances one step per frame.

:class:`StereoStream` takes one frame of each camera at a time. Each camera's frames go
through a :class:`~bistair.core.motion.PhaseStream` (running sums: a new frame costs two
multiply-adds a pixel; order ``K`` compensates motion). For each window:

1. The wrapped phases (NaN below the modulation threshold measured on the first ``N``
   frames) are resampled onto the rectified grids in one compiled pass a camera, on every
   core (:func:`~bistair.geometry.stereo_jit.resample_wrapped`: the threshold and the
   resampler of :func:`~bistair.geometry.unwrap.rectified_phase`, so the first window and
   the later ones read the same numbers; no trigonometry).
2. The first window is unwrapped by :func:`~bistair.geometry.unwrap.unwrap_stereo`, as the
   one-set ``stereo`` command does, its depth range checked. Each later window searches
   each pixel of both rectified grids only within :data:`MARGIN` pixels of its single
   candidate in the previous window (:func:`~.unwrap_stream_jit.track_rows`); a pixel
   without one, or whose narrow search finds no candidate or two, is searched over the
   whole range; a right pixel whose narrow search fails is searched in full only where a
   left pixel's single candidate lands (:func:`~.unwrap_stream_jit.match_targets`: the
   only right pixels the confirmation reads). The decisions are confirmed as the full
   search's are (:func:`~.unwrap_stream_jit.confirm`): by the right grid's own candidate
   at the match, by a row above or below, and dropped beside an occlusion; then grown as
   the full search grows them (:func:`~.unwrap_jit.grow`).
3. The depth: the left camera's ray cut by the projector's plane of the column of the
   absolute phase (the pixel's own wrapped phase and the order its rectified neighbours
   decided; :func:`~.unwrap_stream_jit.plane_depth`). NaN where undecided, and where
   :func:`~.unwrap.mixed_pixels` finds a ramp across a depth step or a spike (every
   window, the first too; ``info["mixed"]`` counts them).

Everything that does not change between frames (the rectification, the rays in the
projector's frame, the disparity bounds) is computed once.

The margin: a window one frame after the last sees the scene one frame later; a pixel's
disparity moves by ``f * B * dz / z**2`` for a surface ``dz`` mm nearer (0.67 px a mm at
600 mm with ``f`` = 1200 px and ``B`` = 200 mm, the virtual rig at 640 x 480) and along a
slope by the slope times the lateral motion. Measured there on two-masks moving 5 mm
nearer a frame (0.45 m/s at 90 frames a second): disparity steps of 3.5 px (median), 7 px
(99th percentile). :data:`MARGIN` (6 px) searches 53% of the valid pixels near (3 px: 28%,
the rest in full, 30% more time); a pixel that moved more is searched in full. The ghosts of
stereo phase unwrapping lie two right-camera fringes apart (58 px of disparity for 48-px
fringes there, 19 px for 16-px fringes), outside a search 12 px wide.

Examples
--------
>>> from bistair.codecs import make_spec
>>> from bistair.geometry.calibration import StereoCalibration
>>> from bistair.sim import preset, trace
>>> from bistair.sim.stereo import StereoRig
>>> rig, scene = preset("plane", camera_size=(80, 60))  # a plane at 600 mm
>>> srig = StereoRig.default(camera_size=(80, 60), projector_size=rig.projector.size,
...                          projector_at=0.3)
>>> cal = StereoCalibration.from_rig(srig)
>>> spec = make_spec("multifreq", width=rig.projector.size[0],
...                  height=rig.projector.size[1], periods=(48,))
>>> x = [trace(srig.rig(side), scene).truth.coord_x for side in ("left", "right")]
>>> def frame(c, i):  # frame i shows shift i mod 4
...     return np.float32(0.5 + 0.4 * np.cos(2 * np.pi * c / 48 + np.pi * i / 2))
>>> stream = StereoStream(cal, spec, 500.0, 700.0)
>>> out = [stream.push(frame(x[0], i), frame(x[1], i)) for i in range(6)]
>>> [o is None for o in out]
[True, True, True, False, False, False]
>>> out[-1].start, out[-1].info["decided"] > 2000
(2, True)
>>> round(float(np.nanmedian(out[-1].depth)), 1)  # mm
600.0
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.captures import prepare
from ..core.measure import measure
from ..core.motion import PhaseStream
from ..errors import BistairError
from .calibration import StereoCalibration
from .projection_matrices import with_pixel_origin
from .stereo import Rectification, rectify, resample_wrapped
from .unwrap import (
    EDGE,
    GROW_SUPPORT,
    MIN_TOLERANCE,
    REACH,
    SUPPORT,
    TOLERANCE_SIGMAS,
    grow,
    is_single_period,
    mixed_pixels,
    mixed_terms,
    unwrap_stereo,
)
from .unwrap_stream_jit import (
    confirm,
    match_targets,
    plane_depth,
    projector_pixels,
    track_rows,
    window_counts,
)

#: Half the width (rectified pixels) of a later window's search about the previous
#: window's disparity (module docstring).
MARGIN = 6.0


@dataclass
class StreamDepth:
    """One window's result: ``depth`` (float32 ``z`` in mm on the left camera's own grid,
    NaN where undecided), ``order`` (int32 fringe order, -1 there), ``phase`` (float32
    absolute phase, NaN there), ``mask`` (where depth
    is known), ``disparity`` (float32 on the rectified left grid), ``grey`` (uint8: the
    left camera's modulation, for the cloud) and ``info`` (counts and settings)."""

    start: int
    depth: np.ndarray
    order: np.ndarray
    phase: np.ndarray
    mask: np.ndarray
    disparity: np.ndarray
    grey: np.ndarray
    info: dict[str, Any] = field(default_factory=dict)


class StereoStream:
    """Depth maps of a two-camera stream, one a window (module docstring).

    Parameters
    ----------
    calibration : StereoCalibration
        The two cameras and the projector (its ``projector`` entry).
    spec : MultiFreqSpec
        One N-step set of one period coding the projector columns; its conventions
        describe the stream's first frame.
    min_depth, max_depth : float
        The depth range (left camera frame, mm).
    order : int, optional
        ``K``: motion compensation of order ``K`` (windows of ``N + K`` frames).
    min_modulation : float, optional
        The modulation a valid pixel needs (fraction of full scale); by default from the
        noise measured on the first ``N`` frames.
    margin : float, optional
        :data:`MARGIN`; 0 searches every window in full (:func:`~.unwrap.unwrap_stereo`,
        its range checked on the first window alone).
    force : bool, optional
        Keep the first window when its depth range check would refuse it (a warning).
    tolerance : float, optional
        The phase tolerance (radians); by default as :func:`~.unwrap.unwrap_stereo`'s.
    pixel_origin : int, optional
        The cameras' pixel origin the calibration records (``import-calibration
        --projection-matrices``): the first window checks it as
        :func:`~.unwrap.unwrap_stereo` does, and every window uses the origin it settles on.

    Examples
    --------
    See the module docstring.
    """

    def __init__(self, calibration: StereoCalibration, spec: Any, min_depth: float,
                 max_depth: float, order: int = 0, min_modulation: float | None = None,
                 margin: float = MARGIN, force: bool = False,
                 tolerance: float | None = None, pixel_origin: int | None = None) -> None:
        if not is_single_period(spec) or spec.orientation != "columns":
            raise BistairError("stereo phase unwrapping needs one N-step set of one period "
                               "coding the projector columns (bistair patterns multifreq "
                               "--periods T)")
        if calibration.projector is None:
            raise BistairError("stereo phase unwrapping needs the projector in the "
                               "calibration (bistair simulate --cameras 2 writes it, "
                               "import-calibration --projection-matrices makes one)")
        if not (0 < min_depth < max_depth and math.isfinite(max_depth)):
            raise BistairError(f"stereo phase unwrapping needs a finite depth range above 0 "
                               f"mm (--depth-range ZMIN:ZMAX), got {min_depth:g}:{max_depth:g}")
        if not margin >= 0:
            raise BistairError(f"the search margin must be 0 or more, got {margin}")
        self.calibration, self.spec = calibration, spec
        self.period = float(spec.periods[0])
        self.range = (float(min_depth), float(max_depth))
        self.order, self.margin, self.force = order, float(margin), force
        self.min_modulation, self.tolerance = min_modulation, tolerance
        self.pixel_origin = pixel_origin
        self.streams = [PhaseStream(spec.steps, order, spec.shift_sign, spec.phase_offset)
                        for _ in range(2)]
        self.count = 0
        self.first: list[list[np.ndarray]] = [[], []]  # the first N frames: the noise
        self.thresholds: tuple[float, float] | None = None
        self.noise: tuple[float, float] = (0.0, 0.0)
        self.check: dict[str, Any] | None = None
        self.previous: np.ndarray | None = None  # the single candidates of each grid
        self.previous_right: np.ndarray | None = None
        self._setup()

    def _setup(self) -> None:
        """What does not change between frames."""
        cal, rect = self.calibration, rectify(self.calibration)
        self.rect: Rectification = rect
        proj = cal.projector
        lo, hi = rect.disparities(*self.range)
        self.bounds = (lo, min(hi, 4.0 * rect.size_right[0]))
        self.geometry = (rect.shift, rect.f, rect.cx_left, rect.cy, rect.tx, rect.R1.T,
                         proj.device.K, proj.device.dist, proj.R, proj.T)
        rx, ry = rect.rays
        rp = np.asarray(proj.R, np.float64)
        self.ax = (rp[0, 0] * rx + rp[0, 1] * ry + rp[0, 2]).astype(np.float32)
        self.az = (rp[2, 0] * rx + rp[2, 1] * ry + rp[2, 2]).astype(np.float32)
        self.mixed_terms = mixed_terms(cal, rect.rays)  # (mixed_pixels' per pixel)
        # plane_depth reads the projector rows only through distortion or skew
        self.rows = bool(np.any(proj.device.dist) or proj.device.K[0, 1] != 0.0)
        self.buffers: list[dict] = [{}, {}]  # resample_wrapped's

    @property
    def lag(self) -> float:
        """Frames between a window's newest frame and the time it describes."""
        return (self.spec.steps + self.order - 1) / 2

    def push(self, left: np.ndarray, right: np.ndarray) -> StreamDepth | None:
        """Add the next frame of each camera; the newest window's depth once ``N + K``
        frames are in, else None.

        Parameters
        ----------
        left, right : numpy.ndarray
            ``(H, W)`` the cameras' next frames (any numeric type; the sizes of the
            calibration).

        Returns
        -------
        StreamDepth or None

        Raises
        ------
        BistairError
            Frames of another size than the calibration's, or (first window) what
            :func:`~.unwrap.unwrap_stereo` refuses.
        """
        clock = time.process_time()
        cal, n = self.calibration, self.spec.steps
        for name, frame, dev in (("left", left, cal.left), ("right", right, cal.right)):
            if np.shape(frame) != (dev.height, dev.width):
                raise BistairError(f"the calibration is for {dev.width}x{dev.height} {name} "
                                   f"images, frame {self.count} is {np.shape(frame)[1::-1]}")
        if self.count < n:
            for kept, frame in zip(self.first, (left, right), strict=True):
                kept.append(np.array(frame))
            if self.count == n - 1:
                self._measure()
        ready = [s.update(f) for s, f in zip(self.streams, (left, right), strict=True)]
        self.count += 1
        if not (ready[0] and ready[1]):
            return None
        assert self.thresholds is not None
        states = [s.state for s in self.streams]
        rectified = [resample_wrapped(st.phase, table, st.mod, t, buffers)
                     for st, t, table, buffers in zip(
                         states, self.thresholds, (self.rect.maps_left, self.rect.maps_right),
                         self.buffers, strict=True)]
        start = self.count - n - self.order
        result = self._window(rectified[0], rectified[1], start)
        grey = states[0].mod * np.float32(255 / max(self.scale, 1e-12))
        result.grey = np.clip(grey, 0, 255, out=grey).astype(np.uint8)
        result.info["cpu_seconds"] = round(time.process_time() - clock, 6)
        return result

    def _measure(self) -> None:
        """The thresholds and phase noise of each camera from the first ``N`` frames (as
        a one-set decode measures them)."""
        thresholds, noise = [], []
        for frames in self.first:
            prepared = prepare(np.stack(frames), self.spec.steps, self.spec.method)
            fs = measure(prepared, 0, self.spec.steps, self.min_modulation, check=False,
                         shift_sign=self.spec.shift_sign, phase_offset=self.spec.phase_offset)
            self.scale = float(prepared.full_scale)
            thresholds.append(float(fs.threshold) * self.scale)
            noise.append(float(np.median(fs.phase_noise[fs.valid])) if fs.valid.any()
                         else 0.0)
        self.thresholds = (thresholds[0], thresholds[1])
        self.noise = (noise[0], noise[1])
        self.first = [[], []]
        if self.tolerance is None:
            self.tolerance = max(MIN_TOLERANCE, TOLERANCE_SIGMAS * math.hypot(*self.noise))

    def _window(self, left: tuple[np.ndarray, np.ndarray, int],
                right: tuple[np.ndarray, np.ndarray, int], start: int) -> StreamDepth:
        """One window's depth from the two wrapped phases (each camera's, NaN where not
        modulated, on its own grid and on its rectified grid, and its count of valid
        pixels: :func:`~bistair.geometry.stereo_jit.resample_wrapped`)."""
        rect = self.rect
        (lphase, lrect, valid), (rphase, rrect, _) = left, right
        info: dict[str, Any]
        tracked = not (self.previous is None or self.margin == 0)
        if not tracked:
            first = self.previous is None
            found = unwrap_stereo(lphase, rphase, self.calibration, self.period,
                                  *self.range, self.noise, self.tolerance,
                                  rectification=rect, force=self.force, check=first,
                                  pixel_origin=self.pixel_origin if first else None)
            disparity = found.disparity
            if first:
                self.check = found.info["range_check"]
                self._settle_origin(found.info.get("pixel_origin", self.pixel_origin))
                rect = self.rect
            info = {k: found.info[k] for k in ("no_candidate", "undecided", "grown",
                                                "not_confirmed", "unsupported", "warnings")}
            info.update(searched_near=0, searched_full=int(np.isfinite(disparity).sum()))
        else:
            disparity, info = self._track(lrect, rrect)
        cols, rows = projector_pixels(disparity, *self.geometry, rows=self.rows)
        proj = self.calibration.projector
        u, v = rect.positions
        depth, order, column = plane_depth(cols, rows, u, v, lphase, self.ax, self.az,
                                           self.period, self.period / 2, proj.device.K,
                                           proj.device.dist, proj.T, *self.range)
        if not tracked:  # (a tracked window keeps its single candidates: _track)
            self.previous, self.previous_right = disparity, None
        mask = np.isfinite(depth)
        mixed = mixed_pixels(depth, mask, self.calibration, self.period, self.noise[0],
                             rect.rays, terms=self.mixed_terms)  # (as unwrap_stereo)
        if mixed.any():
            depth[mixed], order[mixed], column[mixed], mask[mixed] = np.nan, -1, np.nan, False
        decided = int(mask.sum())
        info = {"start": start, "decided": decided,
                "decided_fraction": round(decided / max(valid, 1), 6), "left_decoded": valid,
                **info, "mixed": int(mixed.sum()),
                "tolerance_rad": round(float(self.tolerance or 0.0), 6),
                "noise_rad": [round(v, 6) for v in self.noise]}
        phase = np.multiply(column, np.float32(2 * np.pi / self.period), out=column)
        return StreamDepth(start, depth, order, phase, mask, disparity,
                           np.zeros(depth.shape, np.uint8), info)

    def _settle_origin(self, used: int | None) -> None:
        """The first window found the cameras' pixels fit the other origin
        (:func:`~.unwrap.unwrap_stereo` unwrapped it so, with a warning): every later window
        uses that calibration and its rectified grids."""
        if self.pixel_origin is None or used is None or used == self.pixel_origin:
            return
        self.calibration = with_pixel_origin(self.calibration, used - self.pixel_origin)
        self.pixel_origin = used
        self._setup()

    def _track(self, lrect: np.ndarray, rrect: np.ndarray
               ) -> tuple[np.ndarray, dict[str, Any]]:
        """A later window: each grid searched near its previous single candidates,
        confirmed as the full search confirms."""
        assert self.previous is not None
        lo, hi = self.bounds
        args = (*self.geometry, self.period, self.tolerance, *self.range,
                self.calibration.projector.device.width)
        right_before = (self.previous_right if self.previous_right is not None
                        else _on_right(self.previous, self.rect.shift, rrect.shape[1]))
        n_in, disparity, near, candidates = track_rows(
            lrect, rrect, self.previous, self.margin, lo, hi, *args)
        needed = match_targets(disparity, self.rect.shift, rrect.shape[1])
        _, from_right, _, _ = track_rows(rrect, lrect, right_before, self.margin, lo, hi,
                                         *args, from_right=True, keep=0, needed=needed)
        valid = np.isfinite(lrect)
        alone, blocked, not_confirmed, unsupported = confirm(
            disparity, n_in, valid, from_right, self.rect.shift, SUPPORT, EDGE)
        kept = grow(alone, n_in, candidates, blocked, REACH, GROW_SUPPORT)
        self.previous, self.previous_right = disparity, from_right
        counts = window_counts(lrect, n_in, near, alone, kept)
        info = {"no_candidate": counts[0], "undecided": counts[1], "grown": counts[2],
                "not_confirmed": not_confirmed, "unsupported": unsupported,
                "searched_near": counts[3], "searched_full": counts[4], "warnings": []}
        return kept, info


def _on_right(disparity: np.ndarray, shift: float, width: int) -> np.ndarray:
    """The left grid's disparities put on the right grid's pixels they match (the right
    grid's previous disparities; NaN where none)."""
    rows, cols = np.nonzero(np.isfinite(disparity))
    d = disparity[rows, cols]
    xr = np.rint(cols - shift - d).astype(np.int64)
    inside = (xr >= 0) & (xr < width)
    out = np.full((disparity.shape[0], width), np.nan, np.float32)
    out[rows[inside], xr[inside]] = d[inside]
    return out
