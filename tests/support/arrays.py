"""Array comparisons and random arrays for the tests of compiled twins."""

from __future__ import annotations

import numpy as np


def same(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal dtype, shape and bits (NaN equal to NaN, -0.0 not equal to 0.0)."""
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype != b.dtype or a.shape != b.shape:
        return False
    if a.dtype.kind == "f":
        a, b = (np.where(np.isnan(x), np.inf, x).view(f"i{x.itemsize}") for x in (a, b))
    return bool(np.array_equal(a, b))


def floats(rng: np.random.Generator, shape: tuple[int, ...], dtype=np.float32) -> np.ndarray:
    """Normal values at four scales (1, 1e-3, 1e-7, 10), where roundings bite."""
    scale = rng.choice([1.0, 1e-3, 1e-7, 10.0], shape)
    return (rng.standard_normal(shape) * scale).astype(dtype)


def arctan2_rounded(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The correctly rounded float32 arctangent: float64 ``arctan2`` rounded once."""
    return np.arctan2(y.astype(np.float64), x.astype(np.float64)).astype(np.float32)


def octant_np(y: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``bistair.core.phase_jit._octant`` written out in NumPy float32, operation by
    operation in its order (NumPy rounds each one: no fused multiply-add)."""
    from bistair.core import phase_jit as pj

    f = np.float32
    y, x = np.asarray(y, f), np.asarray(x, f)
    ax, ay = np.abs(x), np.abs(y)
    steep = ay > ax
    hi, lo = np.where(steep, ay, ax), np.where(steep, ax, ay)
    big = lo > pj._TAN_PI8 * hi
    num, den = np.where(big, lo - hi, lo), np.where(big, lo + hi, hi)
    den = np.where(den > f(0), den, f(1))
    u = num / den
    s = u * u
    t = u + u * (s * (((pj._P3 * s + pj._P2) * s + pj._P1) * s + pj._P0))
    m = np.where(big, f(1), f(0))
    m, t = np.where(steep, f(2) - m, m), np.where(steep, -t, t)
    left = x < f(0)
    m, t = np.where(left, f(4) - m, m), np.where(left, -t, t)
    return m, t


def angle_np(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``bistair.core.phase_jit.angle32`` in NumPy float32 (see :func:`octant_np`)."""
    from bistair.core import phase_jit as pj

    m, t = octant_np(y, x)
    below = np.asarray(y, np.float32) < 0
    m, t = np.where(below, -m, m), np.where(below, -t, t)
    return m * pj._PI4_HI + (m * pj._PI4_LO + t)


def phase_np(y: np.ndarray, x: np.ndarray, offset: float = 0.0) -> np.ndarray:
    """``bistair.core.phase_jit.phase32`` in NumPy float32 (see :func:`octant_np`)."""
    from bistair.core import phase_jit as pj

    f = np.float32
    hi, lo = pj.offset_parts(offset)
    m, t = octant_np(y, x)
    below = np.asarray(y, f) < 0
    m, t = np.where(below, f(8) - m, m), np.where(below, -t, t)
    a = m * pj._PI4_HI - hi
    b = (m * pj._PI4_LO - lo) + t
    r = a + b
    low, high = r < f(0), r >= pj.TWO_PI32
    a = np.where(high, a - pj._TWO_PI_HI, np.where(low, a + pj._TWO_PI_HI, a))
    b = np.where(high, b - pj._TWO_PI_LO, np.where(low, b + pj._TWO_PI_LO, b))
    r = a + b
    return np.where((r >= f(0)) & (r < pj.TWO_PI32), r, f(0))
