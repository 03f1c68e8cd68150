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
