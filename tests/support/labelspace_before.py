"""Bidirectional's label-space stages as bistair computed them at the branch point of issue
32 part C (main at 5d200cd), in NumPy: the tests' oracles for the compiled passes that
replace them (tests/test_labelspace.py)."""

from __future__ import annotations

import numpy as np

from bistair.codecs.bidirectional.profiles import stair_values
from bistair.core.regions import core_weight


def relabel_then_stair_sums(labels: np.ndarray, roots: np.ndarray, remap: np.ndarray,
                            phi: np.ndarray, theta: np.ndarray, stair_mod: np.ndarray,
                            mod: np.ndarray) -> tuple[np.ndarray, ...]:
    """The final labels ``remap[roots[labels]]`` and, in a scan of its own, the five stair
    values per (label, row) summed by ``np.bincount`` (float64, raster order): ``(final
    labels, keys = label * H + row, counts, sums (5, K))``."""
    final = remap[roots[labels]].astype(np.int32)
    h = final.shape[0]
    ratio = np.clip(stair_mod / np.maximum(mod, np.float32(1e-6)), 0.0, 2.0)
    values = stair_values(theta, core_weight(phi) * np.minimum(ratio, 1.0), ratio)
    inside = final > 0
    key = (final.astype(np.int64) * h + np.arange(h)[:, None])[inside]
    keys, inv = np.unique(key, return_inverse=True)
    counts = np.bincount(inv, minlength=keys.size).astype(np.int64)
    sums = np.stack([np.bincount(inv, v[inside].astype(np.float64), keys.size)
                     for v in values])
    return final, keys, counts, sums
