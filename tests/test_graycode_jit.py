"""The Gray code's compiled passes (bistair.codecs.graycode_jit: code bits, orders, the
Gray code alone's levels and cells) give, bit for bit, what NumPy gives (written out here:
the first bit the most significant, as OpenCV's GrayCodePattern), on random data and on the
values where roundings and thresholds bite; and the evidence each order needs, pixel by
pixel."""

from __future__ import annotations

import numpy as np
from support.arrays import same

from bistair.codecs.graycode import gray_to_binary
from bistair.codecs.graycode_jit import alone_cells, alone_levels, code_bits, read_orders
from bistair.core.captures import ScaledStack
from bistair.core.phase import TWO_PI

RNG = np.random.default_rng(7)


def test_code_bits_are_numpys():
    raw = RNG.integers(0, 256, (9, 20, 30)).astype(np.uint8)
    frames = ScaledStack(raw, 1 / 255)
    avg = RNG.uniform(0, 1, (20, 30)).astype(np.float32)
    avg.flat[:3] = frames[2].flat[:3]  # a frame equal to its threshold reads 0
    for inverse in (False, True):
        ref = frames[5:8] if inverse else avg[None].repeat(3, axis=0)
        gray = np.zeros(avg.shape, np.int32)
        for frame, against in zip(frames[2:5], ref, strict=True):
            gray <<= 1
            gray |= frame > against
        assert same(code_bits(raw, 2, 3, np.float32(1 / 255), avg, inverse), gray)



def _frames(gray: np.ndarray, bits: int, contrast=0.4) -> np.ndarray:
    """Code frames and their inverses (float32, fractions of full scale) of ``gray``."""
    bright = np.stack([(gray >> b) & 1 for b in range(bits - 1, -1, -1)])
    code = 0.5 + contrast * (2 * bright - 1)
    return np.concatenate([code, 1 - code]).astype(np.float32)


def test_read_orders_are_numpys():
    """The orders and edges as read are the NumPy expressions of the three rules."""
    gray = RNG.integers(0, 2**8, (30, 40)).astype(np.int32)
    phi = RNG.uniform(0, TWO_PI, gray.shape).astype(np.float32)
    phi.flat[:4] = [np.nan, np.float32(np.pi / 2), np.float32(1.5 * np.pi), np.float32(np.pi)]
    valid = RNG.random(gray.shape) < 0.9
    raw = _frames(gray, 8)
    mod = np.full(gray.shape, 0.3, np.float32)
    for mode, fringes in ((0, 200), (1, 100), (2, 200)):
        if mode == 1:
            k1 = gray_to_binary(gray >> 1)
            k2 = (gray_to_binary(gray) + 1) // 2
            k = np.where(phi < np.pi / 2, k2, np.where(phi >= 1.5 * np.pi, k2 - 1, k1))
            edges = k1
        elif mode == 2:
            edges = gray_to_binary(gray)
            k = np.where(phi < np.pi, edges, edges - 1)
        else:
            k = edges = gray_to_binary(gray)
        ok = valid & (k >= 0) & (k < fringes)
        code, got_edges, carried, beyond = read_orders(
            raw, 0, 8, 1.0, mod, True, phi, mod, valid, mode, fringes, 0.01, 0.01, 3.0, 0.5,
            0.5)
        assert same(code, np.where(ok, k, -1).astype(np.int32))
        assert same(got_edges, np.where(valid, edges, -1).astype(np.int32))
        assert beyond == int(np.count_nonzero(valid & (k >= fringes)))
        assert not (carried & ~ok).any()


def _carried(d, phi, mode=0, inverse=True, noise_d=0.01, mod=0.3):
    """Whether the evidence carries the order of one pixel whose bit margins (MSB first)
    are ``d``."""
    d = np.asarray(d, np.float32)
    bits = len(d)
    if inverse:
        raw = np.concatenate([0.5 + d / 2, 0.5 - d / 2])[:, None, None]
    else:
        raw = (0.5 + d)[:, None, None]
    one = np.ones((1, 1), np.float32)
    out = read_orders(raw.astype(np.float32), 0, bits, 1.0, 0.5 * one, inverse,
                      np.float32(phi) * one, np.float32(mod) * one, one > 0, mode, 2**bits,
                      noise_d, 0.01, 3.0, 0.5, 0.5)
    assert out[0][0, 0] >= 0
    return bool(out[2][0, 0])


def test_the_evidence_of_one_pixel():
    """Cell 5 (Gray 111) of a 3-bit plain code: its lower edge is its last bit's (to cell
    4, Gray 110), its upper edge its middle bit's (to cell 6, Gray 101)."""
    at = TWO_PI  # the phase, as a share of the fringe
    assert _carried([0.8, 0.8, 0.8], 0.5 * at)  # every bit clear
    # the last bit unclear: carried where the phase puts the pixel beside that bit's edge,
    # at the start of cell 5 (and beyond the phase's noise), not at its end
    assert _carried([0.8, 0.8, 0.02], 0.2 * at)
    assert not _carried([0.8, 0.8, 0.02], 0.8 * at)
    assert not _carried([0.8, 0.8, 0.2], 0.8 * at)  # a faint bit away from its edge
    assert _carried([0.8, 0.8, 0.5], 0.8 * at)  # over half the contrast
    # within three sigma of the phase's wrap (sigma = 0.01 / 0.3 rad): the weaker edge bit
    # must be at the phase's end of the cell
    assert _carried([0.8, 0.7, 0.8], 0.995 * at)  # the upper edge's bit is the weaker
    assert not _carried([0.8, 0.8, 0.7], 0.995 * at)
    assert _carried([0.8, 0.8, 0.7], 0.005 * at)
    assert not _carried([0.8, 0.7, 0.8], 0.005 * at)
    # four unclear bits are more than the evidence can sort out when they are faint
    assert not _carried([0.8, 0.01, 0.01, 0.01, 0.01], 0.5 * at)
    # without inverses the dark bits read against the fringes' average may be weaker than
    # the bright ones: each sign is judged against its own kind
    assert _carried([0.4, 0.4, -0.15], 0.5 * at, inverse=False)
    assert not _carried([0.4, 0.4, -0.15, -0.02], 0.5 * at, inverse=False)
    # the first bit of cell 10 of 32 (Gray 01111; its edge 6 cells away) under three sigma:
    # where the pixel's contrast and the bit together clear them, noise could not have
    # flipped it; where they do not, it could have
    assert _carried([-0.03, 0.05, 0.05, 0.05, 0.05], 0.5 * at, noise_d=0.012)
    assert not _carried([-0.01, 0.02, 0.02, 0.02, 0.02], 0.5 * at, noise_d=0.012)


def alone_levels_numpy(raw: np.ndarray, bits: int, inverse: bool, scale: float,
                       white: np.ndarray, black: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The twin of ``alone_levels``: with inverses (frames ``2i``, ``2i + 1``) the mid-level
    is the float32 sum over the bits, in bit order, of ``pattern + inverse`` times 0.5 over
    the bits, the contrast the median of ``|pattern - inverse| * 0.5``; without, half the
    sum and half the difference of white and black."""
    half = np.float32(0.5)
    if not inverse:
        return (white + black) * half, (white - black) * half
    frames = raw[:2 * bits].astype(np.float32) * np.float32(scale)
    total = np.zeros(raw.shape[1:], np.float32)
    for i in range(bits):
        total += frames[2 * i] + frames[2 * i + 1]
    diff = np.abs(frames[0::2] - frames[1::2]) * half
    return total * half / np.float32(bits), np.median(diff, axis=0).astype(np.float32)


def alone_cells_numpy(raw: np.ndarray, bits: int, inverse: bool, scale: float,
                      mid: np.ndarray, valid: np.ndarray, clear: float) -> np.ndarray:
    """The twin of ``alone_cells``: bit ``i`` (frame ``2i`` against ``2i + 1``, or frame
    ``i`` against ``mid``) is 1 where the difference is positive and clear where it is at
    least ``clear``; the first bit is the most significant of the Gray code word; -1 where
    not ``valid`` or a bit is not clear."""
    frames = raw.astype(np.float32) * np.float32(scale)
    word = np.zeros(raw.shape[1:], np.int32)
    ok = valid.copy()
    for i in range(bits):
        diff = frames[2 * i] - frames[2 * i + 1] if inverse else frames[i] - mid
        ok &= np.abs(diff) >= np.float32(clear)
        word = (word << 1) | (diff > 0)
    return np.where(ok, gray_to_binary(word), -1).astype(np.int32)


def gray_frames(bits: int, inverse: bool, shape: tuple[int, int]) -> np.ndarray:
    """uint8 captures of random cells (each bit and, with ``inverse``, its inverse; contrast
    and noise random), a few differences exactly zero and exactly at the clear limit."""
    cells = RNG.integers(0, 2**bits, shape)
    gray = cells ^ (cells >> 1)
    lit = [(gray >> (bits - 1 - i)) & 1 for i in range(bits)]
    low = RNG.integers(0, 80, shape)
    high = low + RNG.integers(0, 170, shape)
    frames = []
    for bit in lit:
        pattern = np.where(bit, high, low) + RNG.integers(-6, 7, shape)
        frames += [pattern, np.where(bit, low, high) + RNG.integers(-6, 7, shape)] if inverse \
            else [pattern]
    raw = np.clip(frames, 0, 255).astype(np.uint8)
    if inverse:
        raw[1, 0, :5] = raw[0, 0, :5]  # no difference: not clear
        raw[0, 1, :5], raw[1, 1, :5] = 100, 105  # exactly the limit (5 / 255)
    return raw


def test_alone_levels_are_numpys():
    for inverse in (True, False):
        raw = gray_frames(7, inverse, (30, 40))
        white = RNG.uniform(0.3, 1, (30, 40)).astype(np.float32)
        black = (white * RNG.uniform(-0.1, 0.6, (30, 40))).astype(np.float32)
        args = (raw, 7, inverse, 1 / 255, white, black)
        for got, want in zip(alone_levels(*args), alone_levels_numpy(*args), strict=True):
            assert same(got, want)


def test_alone_cells_are_numpys():
    for bits, inverse in ((7, True), (6, False), (1, True)):
        raw = gray_frames(bits, inverse, (30, 40))
        mid = RNG.uniform(0.1, 0.6, (30, 40)).astype(np.float32)
        mid.flat[:3] = raw[0].flat[:3] / np.float32(255)  # a bit equal to the mid-level
        valid = RNG.random((30, 40)) < 0.9
        for clear in (np.float32(5 / 255), 0.02, 0.0):
            args = (raw, bits, inverse, 1 / 255, mid, valid, float(clear))
            got, want = alone_cells(*args), alone_cells_numpy(*args)
            assert same(got, want), (bits, inverse, clear)
            assert (got >= 0).mean() > (0.2 if clear else 0.8)  # cells decoded, not all -1
