"""Independent reference decoder for the kamino-object1 captures (used by the tests).

This is a vectorised NumPy port of the decoder (``decode`` in ``phase_shifting.py``) of
kamino410/phase-shifting, https://github.com/kamino410/phase-shifting, copyright (c) 2019
kamino410, MIT licence (a copy ships as ``../shared/data/kamino-object1/LICENSE``). It exists
only so the tests can check bistair against a decoder written by someone else; it is not part
of bistair.

The original needs OpenCV contrib's ``cv2.structured_light_GrayCodePattern``, whose
``getProjPixel`` (opencv/opencv_contrib, modules/structured_light/src/graycodepattern.cpp) is
reproduced here in plain NumPy, together with the original's ``decode_pixel``. With the
default thresholds it reproduces the original's ``camera2display.csv`` (run with NumPy 2 and
opencv-contrib-python-headless 5.0) on every camera pixel: the same valid pixels and the same
float64 coordinates, bit for bit.

Capture layout (N = 32 for a 1920x1080 display and ``step`` = 200):

* 0-11: four 3-step phase-shifting sets, x at period step/3, x at period step/2, then the same
  for y. Within a set the frames follow ``cos(phi - 2pi/3)``, ``cos(phi)``, ``cos(phi + 2pi/3)``
  and the wrapped phase is ``arctan2(sqrt(3) (I1 - I3), 2 I2 - I1 - I3)``.
* 12 .. N-3: OpenCV Gray code over a grid of cells of step/2 display pixels: for each column
  bit, most significant first, the pattern (bright where the Gray-code bit is 1) then its
  inverse; then the same for the rows.
* N-2: white, N-1: black.

A camera pixel is valid when ``white - black > black_thr`` (signed, as in the original's own
test, not OpenCV's ``computeShadowMasks``), every pattern/inverse pair differs by at least
``white_thr`` (OpenCV's ``abs(val1 - val2) < whiteThreshold`` is an error) and the decoded cell
lies inside the grid (``xDec < width`` and ``yDec < height`` of the Gray-code grid).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import imageio.v3 as iio
import numpy as np

__all__ = ["decode_kamino", "gray_code_count", "read_config"]


def read_config(path: str | Path) -> tuple[int, int, int]:
    """``(disp_width, disp_height, step)`` from the original's OpenCV FileStorage XML."""
    root = ET.parse(path).getroot()
    return tuple(int(float(root.findtext(k))) for k in ("disp_width", "disp_height", "step"))


def gray_code_count(n: int) -> int:
    """Bits OpenCV's GrayCodePattern uses for ``n`` cells (``ceil(log(n) / log(2))``)."""
    return int(math.ceil(math.log(float(n)) / math.log(2.0)))


def _capture_files(folder: Path) -> list[Path]:
    """``pat*.png`` sorted by the last number in the name, as the original's glob does."""
    num = re.compile(r"(\d+)")
    return sorted(folder.glob("pat*.png"), key=lambda p: int(num.split(str(p))[-2]))


def _read_grey(path: Path) -> np.ndarray:
    img = iio.imread(path)
    if img.ndim != 2 or img.dtype != np.uint8:
        raise ValueError(f"{path}: expected an 8-bit single-channel image, got "
                         f"{img.dtype} {img.shape}")
    return img


def _wrapped(i1: np.ndarray, i2: np.ndarray, i3: np.ndarray) -> np.ndarray:
    """The original's ``decode_ps``; float64, as NumPy 2 evaluates it (``np.sqrt(3)`` is a
    float64 scalar, so the product is promoted; the float32 differences are exact)."""
    i1, i2, i3 = (a.astype(np.float32) for a in (i1, i2, i3))
    return np.arctan2(np.sqrt(3) * (i1 - i3), 2 * i2 - i1 - i3)


def _gray_to_dec(patterns: np.ndarray, inverses: np.ndarray, white_thr: int):
    """OpenCV ``getProjPixel`` for one axis: bits MSB first, 1 where pattern > inverse;
    returns the decoded cell index and a per-pixel error flag."""
    p = patterns.astype(np.float64)
    q = inverses.astype(np.float64)
    error = np.any(np.abs(p - q) < white_thr, axis=0)
    gray = (p > q).astype(np.int64)
    binary = np.bitwise_xor.accumulate(gray, axis=0)
    n = gray.shape[0]
    weights = (2 ** np.arange(n - 1, -1, -1, dtype=np.int64))[:, None, None]
    return (binary * weights).sum(axis=0), error


def _decode_axis(gc: np.ndarray, ps1: np.ndarray, ps2: np.ndarray, gc_step: int, step: int):
    """The original's ``decode_pixel``, vectorised with the same operations in the same order
    (each ``if`` updates ``p`` before the next one tests it)."""
    pi = np.pi
    d12 = ps1 - ps2
    d21 = ps2 - ps1
    dif = np.where(ps1 > ps2,
                   np.where(d12 > pi * 4 / 3, d21 + 2 * pi, d12),
                   np.where(d21 > pi * 4 / 3, d12 + 2 * pi, d21))

    even = ps1.copy()
    even = np.where((dif > pi / 6) & (even < 0), even + 2 * pi, even)
    even = np.where((dif > pi / 2) & (even < pi * 7 / 6), even + 2 * pi, even)

    odd = ps1.copy()
    odd = np.where((dif > pi * 5 / 6) & (odd > 0), odd - 2 * pi, odd)
    odd = np.where((dif < pi / 2) & (odd < pi / 6), odd + 2 * pi, odd)
    odd = odd + pi

    p = np.where(gc % 2 == 0, even, odd)
    return gc * gc_step + step * p / 3 / 2 / pi


def decode_kamino(folder: str | Path, black_thr: int = 5,
                  white_thr: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """Decode the captures in ``folder`` (``pat00.png`` ... and ``config.xml``) like the
    original ``phase_shifting.py dec`` with ``filter_size`` 0.

    Returns ``(x, y)``: float64 display coordinates per camera pixel, NaN where the original
    writes no row to ``camera2display.csv``.
    """
    folder = Path(folder)
    width, height, step = read_config(folder / "config.xml")
    gc_step = int(step / 2)
    gc_width = int((width - 1) / gc_step) + 1
    gc_height = int((height - 1) / gc_step) + 1
    n_col = gray_code_count(gc_width)
    n_row = gray_code_count(gc_height)

    files = _capture_files(folder)
    if len(files) != 2 * (n_col + n_row) + 14:
        raise ValueError(f"{folder}: {len(files)} captures, expected {2 * (n_col + n_row) + 14}")
    imgs = np.stack([_read_grey(f) for f in files])
    ps, gc_imgs, white, black = imgs[:12], imgs[12:-2], imgs[-2], imgs[-1]

    ps_x1, ps_x2, ps_y1, ps_y2 = (_wrapped(*ps[i:i + 3]) for i in range(0, 12, 3))

    cols, rows = gc_imgs[:2 * n_col], gc_imgs[2 * n_col:]
    x_dec, x_err = _gray_to_dec(cols[0::2], cols[1::2], white_thr)
    y_dec, y_err = _gray_to_dec(rows[0::2], rows[1::2], white_thr)
    valid = (white.astype(np.int64) - black.astype(np.int64) > black_thr)
    valid &= ~(x_err | y_err) & (x_dec < gc_width) & (y_dec < gc_height)

    # the original stores the cells in an int16 map; values are small, so int64 is exact
    x = _decode_axis(x_dec, ps_x1, ps_x2, gc_step, step)
    y = _decode_axis(y_dec, ps_y1, ps_y2, gc_step, step)
    return np.where(valid, x, np.nan), np.where(valid, y, np.nan)
