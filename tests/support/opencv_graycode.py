"""OpenCV's own ``structured_light.GrayCodePattern`` images, kept as a small array file
(``tests/data/opencv_graycode.npz``) that ``tests/test_graycode_alone.py`` compares bistair's
Gray code alone with, bit for bit, without opencv-contrib installed.

How the file was made (opencv-contrib must not go into the project's environment: it would
replace its ``cv2``)::

    python -m venv /tmp/ocv
    /tmp/ocv/bin/pip install opencv-contrib-python-headless numpy
    /tmp/ocv/bin/python tests/support/opencv_graycode.py tests/data/opencv_graycode.npz

(opencv-contrib-python-headless 5.0.0.93, numpy 2.4.6). For each projector size of
:data:`SIZES` it stores ``GrayCodePattern.create(width, height).generate()`` (the column bits
then the row bits, most significant first, each pattern followed by its inverse, 0 or 255)
and ``getImagesForShadowMasks`` (white, black), each image as one bit a pixel
(``np.packbits`` of ``image > 0``), under ``"{width}x{height}"``. :func:`load` gives them
back as uint8 images.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

SIZES = ((64, 48), (100, 30), (37, 19))  # (width, height): a power of two, wide, odd
FILE = Path(__file__).resolve().parents[1] / "data" / "opencv_graycode.npz"


def load(width: int, height: int, path: Path = FILE) -> np.ndarray:
    """OpenCV's Gray code images for a ``width`` x ``height`` projector: the patterns
    (column bits then row bits, each followed by its inverse), then white and black;
    ``(frames, height, width)`` uint8, 0 or 255."""
    with np.load(path) as data:
        packed = data[f"{width}x{height}"]
    frames = len(packed)
    bits = np.unpackbits(packed, axis=1, count=height * width)
    return (bits.reshape(frames, height, width) * 255).astype(np.uint8)


def generate(width: int, height: int) -> np.ndarray:
    """OpenCV's images for one projector size (needs opencv-contrib)."""
    import cv2  # noqa: PLC0415 - opencv-contrib, in a separate environment only

    pattern = cv2.structured_light.GrayCodePattern.create(width, height)
    ok, images = pattern.generate()
    assert ok
    black, white = pattern.getImagesForShadowMasks(None, None)
    stack = np.stack([*images, white, black])
    assert set(np.unique(stack)) <= {0, 255} and stack.shape == (len(images) + 2, height, width)
    return stack


def main(out: str) -> None:
    import cv2  # noqa: PLC0415 - opencv-contrib, in a separate environment only

    arrays = {f"{w}x{h}": np.packbits((generate(w, h) > 0).reshape(-1, w * h), axis=1)
              for w, h in SIZES}
    np.savez_compressed(out, **arrays)
    for w, h in SIZES:
        assert np.array_equal(load(w, h, Path(out)), generate(w, h))
    print(f"wrote {out}: OpenCV {cv2.__version__}, sizes "
          + ", ".join(f"{w}x{h}" for w, h in SIZES))


if __name__ == "__main__":
    main(sys.argv[1])
