"""Captured stacks: checks, scaling to float32 full scale, bit depths, saturation and
validity masks.

Every codec calls :func:`prepare` first, so frame count, sizes, dark and saturated captures
are refused the same way whatever the method.

Examples
--------
>>> import numpy as np
>>> stack = np.full((4, 8, 8), 200, np.uint8)
>>> prepared = prepare(stack, frame_count=4, method="test")
>>> prepared.full_scale, prepared.frames.dtype, bool(prepared.clipped.any())
(255.0, dtype('float32'), False)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import BistairError


@dataclass(frozen=True)
class Prepared:
    """A capture stack scaled so that full scale is 1.0."""

    frames: np.ndarray  # (F, H, W) float32 in [0, 1]
    clipped: np.ndarray  # (H, W) bool: some frame at full scale
    full_scale: float  # the input value that maps to 1.0


def full_scale_of(stack: np.ndarray) -> float:
    """Full-scale value of a stack: its dtype's range, or the smallest common range above it."""
    if stack.dtype == np.uint8:
        return 255.0
    top = float(np.nanmax(stack)) if stack.size else 0.0
    if np.issubdtype(stack.dtype, np.integer) or top > 1.0:
        for scale in (255.0, 1023.0, 4095.0, 16383.0, 65535.0):
            if top <= scale:
                return scale
        return top
    return 1.0


def prepare(images: np.ndarray, frame_count: int, method: str) -> Prepared:
    """Check a capture stack against a spec's frame count and scale it to float32."""
    stack = np.asarray(images)
    if stack.ndim == 2:
        stack = stack[None]
    if stack.ndim != 3:
        raise BistairError(
            f"captures must be a (frames, height, width) stack, got shape {stack.shape}"
        )
    if stack.shape[0] != frame_count:
        raise BistairError(
            f"the {method} spec needs {frame_count} frames, the captures have {stack.shape[0]}"
        )
    if stack.shape[1] < 8 or stack.shape[2] < 8:
        raise BistairError(f"captures of {stack.shape[2]}x{stack.shape[1]} pixels are too small")
    if not (np.issubdtype(stack.dtype, np.number) and not np.iscomplexobj(stack)):
        raise BistairError(f"captures must be numeric images, got dtype {stack.dtype}")
    scale = full_scale_of(stack)
    if np.issubdtype(stack.dtype, np.integer):
        clipped = (stack >= scale).any(axis=0)
    else:
        if not np.isfinite(stack).all():
            raise BistairError("captures contain NaN or infinite values")
        clipped = (stack >= scale * (1.0 - 1e-6)).any(axis=0)
    frames = np.multiply(stack, np.float32(1.0 / scale), dtype=np.float32)
    return Prepared(frames, clipped, scale)


def saturation(clipped: np.ndarray, avg: np.ndarray, mod: np.ndarray) -> np.ndarray:
    """Pixels clipped by the camera: a frame at full scale where the fitted sinusoid's peak
    ``A + B`` exceeds it. An exact capture of a full-range pattern touches full scale with a
    peak of exactly 1 and is not saturated."""
    return clipped & (avg + mod > 1.02)


def validity(mod: np.ndarray, saturated: np.ndarray, noise: float,
             min_modulation: float | None = None) -> np.ndarray:
    """Pixels with enough modulation and no saturation.

    ``min_modulation`` (fraction of full scale) defaults to ``max(0.01, 4 * noise)``: pure
    noise exceeds four sigma in about one pixel in ten million.
    """
    threshold = max(0.01, 4.0 * noise) if min_modulation is None else min_modulation
    return (mod >= threshold) & ~saturated


def check_decodable(valid: np.ndarray, clipped: np.ndarray) -> None:
    """Refuse captures with (almost) nothing to decode, saying whether they are dark or blown
    (``clipped``: pixels with a frame at full scale)."""
    min_pixels = max(50, valid.size // 10000)
    if int(valid.sum()) >= min_pixels:
        return
    share = float(clipped.mean())
    if share > 0.25:
        raise BistairError(
            f"captures are saturated: {100 * share:.0f}% of pixels reach full scale"
        )
    raise BistairError("captures are dark: no pixel has enough fringe modulation to decode")


def to_bit_depth(values: np.ndarray, bits: int, as_float: bool = False) -> np.ndarray:
    """Values in [0, 1] (clipped) as the integer codes of a ``bits``-deep image: uint8 for 8
    bits, uint16 above; with ``as_float`` the codes divided by full scale, as float32.

    >>> to_bit_depth(np.array([0.0, 0.5, 1.2]), 8).tolist()
    [0, 128, 255]
    >>> to_bit_depth(np.array([0.5]), 2, as_float=True).tolist()
    [0.6666666865348816]
    """
    top = (1 << bits) - 1
    codes = np.round(np.clip(values, 0.0, 1.0) * top)
    if as_float:
        return (codes / top).astype(np.float32)
    return codes.astype(np.uint8 if bits <= 8 else np.uint16)
