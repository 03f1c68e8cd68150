"""Captured stacks: checks, scaling to float32 full scale, bit depths, the modulation
threshold and the decodable check (the validity mask itself comes from the measure's pass,
:func:`bistair.core.measure_jit.front_end`).

Every codec calls :func:`prepare` first, so frame count, sizes, dark and saturated captures
are refused the same way whatever the method.

Examples
--------
>>> import numpy as np
>>> stack = np.full((4, 8, 8), 200, np.uint8)
>>> prepared = prepare(stack, frame_count=4, method="test")
>>> prepared.full_scale, prepared.frames[0].dtype, bool(prepared.clipped.any())
(255.0, dtype('float32'), False)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from ..errors import BistairError


class ScaledStack:
    """A capture stack read as fractions of full scale: indexing returns float32 arrays
    (``raw[key] * scale``), so only the frames a step asks for are converted.

    >>> s = ScaledStack(np.full((2, 3, 4), 51, np.uint8), 1 / 255)
    >>> s.shape, s[1].dtype, round(float(s[0, 0, 0]), 6)
    ((2, 3, 4), dtype('float32'), 0.2)
    """

    def __init__(self, raw: np.ndarray, scale: float) -> None:
        self.raw = raw
        self.scale = np.float32(scale)

    @property
    def shape(self) -> tuple[int, ...]:
        return self.raw.shape

    def __len__(self) -> int:
        return self.raw.shape[0]

    def __getitem__(self, key: Any) -> np.ndarray:
        return np.multiply(self.raw[key], self.scale, dtype=np.float32)

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        out = self[...]
        return out if dtype is None else out.astype(dtype)


@dataclass(frozen=True)
class Prepared:
    """A capture stack ready for decoding: the method's frames in its order (``raw``, the
    capture's own dtype), read as fractions of full scale through ``frames``."""

    raw: np.ndarray  # (F, H, W) the method's frames, any dtype
    full_scale: float  # the input value that maps to 1.0
    white: np.ndarray | None = None  # (H, W) the fully lit frame, if the capture has one
    black: np.ndarray | None = None  # (H, W) the dark frame, if the capture has one

    @property
    def scale(self) -> np.float32:
        """Multiply a raw value by this for its fraction of full scale."""
        return np.float32(1.0 / self.full_scale)

    @property
    def frames(self) -> ScaledStack:
        """The frames as float32 fractions of full scale (converted when indexed)."""
        return ScaledStack(self.raw, 1.0 / self.full_scale)

    @cached_property
    def clipped(self) -> np.ndarray:
        """(H, W) bool: pixels where some frame reaches full scale (a millionth below it for
        float captures), computed on first use. A decode does not use it: each N-step set
        judges saturation on its own frames in its pass
        (:func:`bistair.core.measure_jit.front_end`)."""
        if np.issubdtype(self.raw.dtype, np.integer):
            return self.raw.max(axis=0) >= self.full_scale
        return self.raw.max(axis=0) >= self.full_scale * (1.0 - 1e-6)

    def transposed(self) -> Prepared:
        """The same captures with image axes swapped (for the rows orientation)."""
        return Prepared(np.ascontiguousarray(self.raw.transpose(0, 2, 1)), self.full_scale,
                        *(None if a is None else np.ascontiguousarray(a.T)
                          for a in (self.white, self.black)))


def full_scale_of(stack: np.ndarray) -> float:
    """Full-scale value of a stack: its dtype's range, or the smallest common range above it.

    A 10-, 12- or 14-bit camera's data stored MSB-aligned in 16-bit containers (values that
    are all multiples of ``2**z``, the top above 16383) saturates at ``65536 - 2**z``, not at
    65535: its full scale is detected from the bits that are never set.

    Parameters
    ----------
    stack : numeric array of any shape.

    Returns
    -------
    float
        255 for ``uint8``; for other integers and for floats above 1 the smallest of
        255, 1023, 4095, 16383 and 65535 at or above the maximum (or the MSB-aligned full
        scale above), the maximum itself beyond that; 1 for floats within [0, 1].

    Examples
    --------
    >>> full_scale_of(np.array([0, 4095], np.uint16)), full_scale_of(np.array([0.2, 0.9]))
    (4095.0, 1.0)
    >>> full_scale_of(np.array([0, 16, 65520], np.uint16))  # 12 bits, MSB-aligned
    65520.0
    """
    if stack.dtype == np.uint8:
        return 255.0
    top = float(np.nanmax(stack)) if stack.size else 0.0
    if stack.dtype == np.uint16 and top > 16383:
        used_bits = int(np.bitwise_or.reduce(stack, axis=None))
        zeros = (used_bits & -used_bits).bit_length() - 1
        return 65536.0 - 2**zeros if 2 <= zeros <= 8 else 65535.0
    if np.issubdtype(stack.dtype, np.integer) or top > 1.0:
        for scale in (255.0, 1023.0, 4095.0, 16383.0, 65535.0):
            if top <= scale:
                return scale
        return top
    return 1.0


def prepare(images: np.ndarray, frame_count: int, method: str,
            select: Sequence[int] | None = None, white: int | None = None,
            black: int | None = None) -> Prepared:
    """Check a capture stack against a spec's frame count and scale it to float32.

    Parameters
    ----------
    images : (frames, height, width) stack, any real numeric dtype (a 2-D image is one
        frame; float16 is read as float32, extended precision as float64).
    frame_count : the frames the spec describes.
    method : the method's name, for messages.
    select : the indices of the frames to decode, in the order to keep (default: all);
        clipping is judged on these, full scale on these and the white and black frames.
    white, black : indices of a fully lit and of a dark frame, if the capture has them.

    Returns
    -------
    Prepared
        The selected frames as fractions of full scale and the white and black frames (the
        clipped pixels computed when asked for).

    Raises
    ------
    BistairError
        Wrong shape or frame count, too small, not numeric, NaN or infinite values.

    Examples
    --------
    >>> stack = np.zeros((3, 8, 8), np.uint8)
    >>> stack[0] = 255
    >>> p = prepare(stack, 3, "demo", select=[2, 1], white=0)
    >>> p.frames.shape, float(p.white.max()), bool(p.clipped.any())
    ((2, 8, 8), 1.0, False)
    """
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
    if stack.dtype.kind == "f" and stack.dtype not in (np.float32, np.float64):
        # half and extended precision: the compiled passes read float32 and float64
        stack = stack.astype(np.float32 if stack.dtype.itemsize < 4 else np.float64)
    if select is None or list(select) == list(range(len(select))):
        used = stack[:frame_count if select is None else len(select)]
    else:
        used = stack[list(select)]
    if stack.dtype.kind == "f" and not np.isfinite(stack).all():  # (before NumPy warns)
        raise BistairError("captures contain NaN or infinite values")
    lit = [stack[i][None] for i in (white, black) if i is not None]
    scale = max(full_scale_of(a) for a in (used, *lit))
    factor = np.float32(1.0 / scale)
    extra = [None if i is None else np.multiply(stack[i], factor, dtype=np.float32)
             for i in (white, black)]
    return Prepared(used, scale, *extra)


def modulation_threshold(noise: float, min_modulation: float | None = None) -> float:
    """The modulation a valid pixel needs (fraction of full scale): ``min_modulation`` if
    given (checked by :func:`check_min_modulation`), else ``max(0.01, 4 * noise)`` (pure
    noise exceeds four sigma in about one pixel in ten million).

    Parameters
    ----------
    noise : float
        Camera noise sigma, fraction of full scale.
    min_modulation : float, optional
        A threshold asked for, strictly between 0 and 1.

    Returns
    -------
    float
        The threshold, fraction of full scale.

    Raises
    ------
    BistairError
        If ``min_modulation`` is given and not strictly between 0 and 1
        (:func:`check_min_modulation`).

    Examples
    --------
    >>> modulation_threshold(0.005), modulation_threshold(0.001), modulation_threshold(0.0, 0.2)
    (0.02, 0.01, 0.2)
    """
    if min_modulation is None:
        return max(0.01, 4.0 * noise)
    check_min_modulation(min_modulation)
    return float(min_modulation)


def check_min_modulation(min_modulation: float | None) -> None:
    """Refuse a modulation threshold outside ``(0, 1)`` (a fraction of full scale; ``None``
    asks for the default from the noise).

    Parameters
    ----------
    min_modulation : float or None
        The threshold asked for, or ``None`` for the default.

    Raises
    ------
    BistairError
        If ``min_modulation`` is not a number strictly between 0 and 1 (0 would take pure
        noise for fringes; a sinusoid within full scale has a modulation below 1).

    Examples
    --------
    >>> check_min_modulation(0.05)
    >>> check_min_modulation(float("nan"))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the minimum modulation must lie between 0 and 1 ..., got nan
    """
    if min_modulation is None:
        return
    ok = isinstance(min_modulation, int | float | np.number) and not isinstance(
        min_modulation, bool)
    if not (ok and 0.0 < min_modulation < 1.0):
        raise BistairError(f"the minimum modulation must lie between 0 and 1 (a fraction of full "
                           f"scale), got {min_modulation}")


def check_decodable(valid: np.ndarray, clipped: np.ndarray | Callable[[], np.ndarray],
                    min_modulation: float | None = None, mod: np.ndarray | None = None
                    ) -> None:
    """Refuse captures with (almost) nothing to decode, saying whether they are dark or blown
    (``clipped``: pixels with a frame at full scale) or, when a ``min_modulation`` was asked
    for, how much modulation the captures have (``mod``).

    Captures pass when at least ``max(50, pixels / 10000)`` pixels are valid.

    Parameters
    ----------
    valid : (H, W) bool array
        The valid pixels.
    clipped : (H, W) bool array, or a function of no argument that returns it
        Pixels where some frame reaches full scale (called only to refuse).
    min_modulation : float, optional
        The modulation threshold asked for, if any.
    mod : (H, W) array, optional
        Modulation ``B`` (fraction of full scale), reported with ``min_modulation``.

    Raises
    ------
    BistairError
        If too few pixels are valid: the message names the modulation asked for and the
        most there is, or calls the captures saturated (over 25% of pixels clipped) or dark.

    Examples
    --------
    >>> check_decodable(np.ones((20, 20), bool), np.zeros((20, 20), bool))
    >>> check_decodable(np.zeros((20, 20), bool), np.zeros((20, 20), bool), 0.6,
    ...                 np.full((20, 20), 0.3))
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: no pixel has the minimum modulation 0.6 asked for (the most is 0.3)
    """
    min_pixels = max(50, valid.size // 10000)
    if int(np.count_nonzero(valid)) >= min_pixels:
        return
    if min_modulation is not None and mod is not None:
        top = float(np.nanmax(mod)) if mod.size else 0.0
        raise BistairError(f"no pixel has the minimum modulation {min_modulation:g} asked for "
                           f"(the most is {top:.3g})")
    share = float((clipped() if callable(clipped) else clipped).mean())
    if share > 0.25:
        raise BistairError(
            f"captures are saturated: {100 * share:.0f}% of pixels reach full scale"
        )
    raise BistairError("captures are dark: no pixel has enough fringe modulation to decode")


def to_bit_depth(values: np.ndarray, bits: int, as_float: bool = False) -> np.ndarray:
    """Values in [0, 1] (clipped) as the integer codes of a ``bits``-deep image: uint8 for 8
    bits, uint16 above; with ``as_float`` the codes divided by full scale, as float32.

    Parameters
    ----------
    values : ndarray
        Intensities as fractions of full scale; values outside [0, 1] are clipped.
    bits : int
        Bit depth of the image (at most 16).
    as_float : bool
        Return the quantised values as float32 fractions of full scale instead of codes.

    Returns
    -------
    ndarray
        Codes ``round(values * (2**bits - 1))`` (uint8 up to 8 bits, else uint16), or those
        codes over ``2**bits - 1`` as float32; same shape as ``values``.

    Examples
    --------
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
