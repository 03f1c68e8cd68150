"""A Gray code alone (``steps = 0``): each pixel's projector cell from the code's bits, with
no phase shifts (OpenCV's ``GrayCodePattern``, projector-camera calibration rigs).

Frames ``gray-0 .. gray-(B-1)``, most significant bit first, each followed by its inverse
``gray-i-inv`` when the spec has ``inverse``, then ``white`` and ``black`` with ``white``
(OpenCV's order; any order through ``frames``). The cell of projector column ``x`` is
``floor(x / period)``: ``period`` is the cell width (1 by default: one projector pixel, as
OpenCV's code). The stages take the spec's numbers (bits, inverse, cell width, cells),
not the spec: :mod:`.graycode`, the codec, calls them.

A bit is read against its inverse where the spec has them (robust to albedo and ambient
light, as OpenCV), else against the mid-level of the white and black frames. A bit is
clear when the two differ by at least three times the noise of their difference, the noise
measured on the capture itself: from how the sums ``pattern + inverse``, which every bit
shares, vary from bit to bit (with inverses), or from the frames' second differences along
the stripes (without). A pixel is decoded when its contrast (``|pattern - inverse|`` or
``white - black``) reaches the modulation threshold (four times the noise, at least 1% of
full scale) and every bit of its code is clear: a pixel that straddles an edge of the finest
stripes is left out, never guessed.

The decoded coordinate is the cell's centre, ``cell * period + (period - 1) / 2`` in
projector pixels (pixel ``x``'s centre is at ``x``): the projector column itself for
one-pixel cells. Its phase is ``2*pi*coordinate/period`` and its order the cell, as every
codec reports them. Sub-cell refinement is not offered: the code says nothing inside a
cell.

Examples
--------
>>> import numpy as np
>>> from bistair import decode, encode, make_spec
>>> spec = make_spec("graycode", width=64, height=16, steps=0, inverse=1)
>>> spec.period, spec.frames[:3]
(1.0, ('gray-0', 'gray-0-inv', 'gray-1'))
>>> res = decode(encode(spec), spec)
>>> res.coord[0, :5].tolist(), res.order[0, 60:].tolist()
([0.0, 1.0, 2.0, 3.0, 4.0], [60, 61, 62, 63])
"""

from __future__ import annotations

import math

import numpy as np

from ..core.captures import Prepared, check_decodable, modulation_threshold
from ..core.checks import EdgeCheck
from ..core.jit import kernel_frames
from ..core.measure import FringeSet, along_fringe_noise
from .base import CodeMap
from .graycode_jit import alone_cells, alone_levels

CLEAR = 3.0  # a bit is clear at this many noise sigmas of its difference
MIN_CLEAR = 0.005  # and by at least this fraction of full scale (noiseless captures)


def cell_phase(period: float) -> float:
    """The wrapped phase of a cell's centre, ``2*pi*((period - 1) / 2) / period``.

    Parameters
    ----------
    period : float
        The cell width in projector pixels.

    Returns
    -------
    float
        Radians in ``[0, pi)``: 0 for one-pixel cells.

    Examples
    --------
    >>> cell_phase(1.0), round(cell_phase(100.0), 4)
    (0.0, 3.1102)
    """
    return 2.0 * math.pi * ((period - 1.0) / 2.0) / period


def alone_noise(prepared: Prepared, bits: int, inverse: bool) -> float:
    """Camera noise sigma (fraction of full scale) of a Gray code capture.

    With inverses, every bit's ``pattern + inverse`` is the same scene lit by the whole
    projector (linear optics: blur and interreflections move light between the two, not
    out of their sum), so the differences of consecutive bits' sums hold noise alone:
    ``sigma = median|s_i - s_(i+1)| / (0.6745 * 2)`` on every fourth row and column. Without
    inverses, the frames' second differences along the stripes (down the columns of the
    column layout) give it (:func:`bistair.core.measure.along_fringe_noise`).

    Parameters
    ----------
    prepared : Prepared
        The code frames in method order (each bit then its inverse when ``inverse``),
        column layout.
    bits : int
        Code bits.
    inverse : bool
        The frames hold each bit's inverse after it.

    Returns
    -------
    float
        The noise sigma.

    Examples
    --------
    >>> from bistair.core.captures import prepare
    >>> rng = np.random.default_rng(0)
    >>> bit = np.tile(np.arange(64) % 16 < 8, (32, 1)).astype(float)
    >>> frames = np.stack([bit, 1 - bit, bit[:, ::-1], 1 - bit[:, ::-1]]) * 0.6 + 0.2
    >>> frames += rng.normal(0, 0.01, frames.shape)
    >>> round(alone_noise(prepare(frames, 4, "demo"), 2, True), 2)
    0.01
    """
    frames = prepared.frames
    if not inverse or bits < 2:
        return along_fringe_noise(frames[...])
    sub = (slice(None, None, 4), slice(None, None, 4))
    sums = [frames[2 * i][sub] + frames[2 * i + 1][sub] for i in range(bits)]
    diffs = np.concatenate([np.abs(a - b).ravel()
                            for a, b in zip(sums[:-1], sums[1:], strict=True)])
    return float(np.median(diffs) / (0.6745 * 2.0))


def measure_alone(prepared: Prepared, bits: int, inverse: bool, period: float,
                  min_modulation: float | None = None) -> FringeSet:
    """Stage 1 of a Gray code alone: contrast, validity and noise (no phase to measure).

    Parameters
    ----------
    prepared : Prepared
        The code frames in method order, column layout, with the white and black frames
        beside them where the spec has them.
    bits : int
        Code bits (the spec's ``code_bits``).
    inverse : bool
        The frames hold each bit's inverse after it.
    period : float
        The cell width in projector pixels.
    min_modulation : float, optional
        The contrast (half the bright-dark difference, fraction of full scale) a decoded
        pixel needs; from the noise when not given.

    Returns
    -------
    FringeSet
        ``phi`` the cell centre's wrapped phase everywhere (:func:`cell_phase`), ``avg``
        and ``mod`` the mid-level and half the bright-dark contrast (the median over the
        bits of ``|pattern - inverse| / 2`` with inverses), ``valid`` the pixels with enough
        contrast, the noise, ``steps`` 0 and the threshold.

    Raises
    ------
    BistairError
        The captures are dark or no pixel reaches ``min_modulation``.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=64, height=16, steps=0, inverse=1)
    >>> cols = prepare(encode(spec), spec.frame_count, "graycode")
    >>> fs = measure_alone(cols, spec.code_bits, True, spec.period)
    >>> bool(fs.valid.all()), float(fs.mod.max()), float(fs.phi.max()), fs.steps
    (True, 0.5, 0.0, 0)
    """
    noise = alone_noise(prepared, bits, inverse)
    threshold = modulation_threshold(noise, min_modulation)
    avg, mod = alone_levels(kernel_frames(prepared.raw)[0], bits, inverse,
                            float(prepared.scale), _frame(prepared.white),
                            _frame(prepared.black))
    valid = mod >= np.float32(threshold)
    check_decodable(valid, prepared.clipped, min_modulation, mod)
    phi = np.full(valid.shape, np.float32(cell_phase(period)), np.float32)
    return FringeSet(phi, avg, mod, valid, noise, 0, threshold)


def code_alone(prepared: Prepared, fs: FringeSet, bits: int, inverse: bool, cells: int
               ) -> CodeMap:
    """Stage 2 of a Gray code alone: each pixel's cell where every bit is clear (-1
    elsewhere).

    A bit is clear when pattern and inverse (or pattern and the mid-level of the white and
    black frames) differ by at least :data:`CLEAR` times the noise of that difference (and
    :data:`MIN_CLEAR` of full scale).

    Parameters
    ----------
    prepared : Prepared
        The code frames in method order, column layout.
    fs : FringeSet
        Stage 1 (:func:`measure_alone`): the valid pixels, the mid-level and the noise.
    bits : int
        Code bits (the spec's ``code_bits``).
    inverse : bool
        The frames hold each bit's inverse after it.
    cells : int
        The projector's cells across the coded axis (the spec's ``fringes``): a cell from
        there on is past the projector.

    Returns
    -------
    CodeMap
        ``code``: (H, W) int32 cell, -1 where not decoded or past the projector's last
        cell; ``beyond``: decoded pixels whose cell lies past the projector; a ``check``
        that says nothing of a phase convention (there is no phase).

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=40, height=8, steps=0, period=10, white=1)
    >>> cols = prepare(encode(spec), spec.frame_count, "graycode", select=range(2),
    ...                white=2, black=3)
    >>> fs = measure_alone(cols, spec.code_bits, False, spec.period)
    >>> code = code_alone(cols, fs, spec.code_bits, False, spec.fringes)
    >>> code.code[0, ::5].tolist(), code.beyond
    ([0, 0, 1, 1, 2, 2, 3, 3], 0)
    """
    # a bit's difference: pattern - inverse (noise sqrt(2) sigma) or pattern - mid-level
    # (noise sqrt(1.5) sigma)
    clear = max(CLEAR * fs.noise * (math.sqrt(2.0) if inverse else math.sqrt(1.5)),
                MIN_CLEAR)
    cell = alone_cells(kernel_frames(prepared.raw)[0], bits, inverse,
                       float(prepared.scale), fs.avg, fs.valid, float(clear))
    far = cell >= cells
    beyond = int(np.count_nonzero(far))
    cell[far] = -1
    return CodeMap(cell, {}, check=EdgeCheck(0, 0.0, 0.0, 0, 0.0), beyond=beyond)


def _frame(frame: np.ndarray | None) -> np.ndarray:
    """A white or black frame for the compiled passes (an empty one when there is none)."""
    return np.empty((0, 0), np.float32) if frame is None else frame
