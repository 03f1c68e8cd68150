"""Row profiles of fringe regions: the stair values averaged along each row of a region
(across the fringe), the 1-D signal the band analysis (:mod:`.bands`) reads.

The sums run in compiled passes (:mod:`.profiles_jit`), the stair values computed as they
are summed when the maps are float32; :func:`row_profiles` of :func:`stair_values` is the
NumPy reference.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .profiles_jit import label_row_sums, label_stair_sums, relabel_stair_sums
from .profiles_jit import profile_centroids as centroids_of


@dataclass
class RowProfiles:
    """Per (region, row) sums of the stair phasor over a region's pixels in that row."""

    region: np.ndarray
    row: np.ndarray
    cos: np.ndarray  # sum of weight * cos(theta)
    sin: np.ndarray
    weight: np.ndarray
    level: np.ndarray  # mean stair-pair modulation over the fringe modulation
    count: np.ndarray
    col_sum: np.ndarray  # sum of the pixels' column indices


def stair_values(theta: np.ndarray, weight: np.ndarray, ratio: np.ndarray) -> np.ndarray:
    """The per-pixel values :func:`row_profiles` sums: ``weight*cos(theta)``,
    ``weight*sin(theta)``, ``weight``, ``ratio`` and the column index, (5, H, W) float32.

    Parameters
    ----------
    theta : numpy.ndarray
        (H, W) stair phase in radians.
    weight : numpy.ndarray
        (H, W) weight of each pixel's stair phase.
    ratio : numpy.ndarray
        (H, W) stair-pair modulation over the fringe modulation.

    Returns
    -------
    numpy.ndarray
        (5, H, W) float32.

    Examples
    --------
    >>> theta = np.zeros((4, 3), np.float32)
    >>> values = stair_values(theta, np.full((4, 3), 0.5), np.ones((4, 3)))
    >>> values.shape, values.dtype, values[:, 0, 2].tolist()
    ((5, 4, 3), dtype('float32'), [0.5, 0.0, 0.5, 1.0, 2.0])
    """
    h, w = theta.shape
    out = np.empty((5, h, w), np.float32)
    np.multiply(weight, np.cos(theta), out=out[0])
    np.multiply(weight, np.sin(theta), out=out[1])
    out[2] = weight
    out[3] = ratio
    out[4] = np.arange(w, dtype=np.float32)
    return out


def row_profiles(labels: np.ndarray, values: np.ndarray) -> RowProfiles:
    """Sum each region's pixels row by row (sorted by region, then row); ``values`` from
    :func:`stair_values`.

    Parameters
    ----------
    labels : numpy.ndarray
        (H, W) int fringe region labels, 0 for no region.
    values : numpy.ndarray
        (5, H, W) float32 from :func:`stair_values`.

    Returns
    -------
    RowProfiles
        One entry per (region, row) a region has pixels in.

    Examples
    --------
    A 48 x 16 image of two fringe regions (orders 5 and 6, eight columns each) of a code
    with ``S = 4`` stairs and ``P = 3`` partitions, in groups of 16 rows, 10 of them local:

    >>> from bistair.core.stair import stair_level_phase
    >>> y = np.arange(48)[:, None]
    >>> k = np.where(np.arange(16) < 8, 5, 6)
    >>> theta = np.where(y % 16 < 10, stair_level_phase(k % 4, 4),
    ...                  stair_level_phase(k // 4, 3)).astype(np.float32)
    >>> labels = np.tile(np.where(np.arange(16) < 8, 1, 2), (48, 1)).astype(np.int32)
    >>> ones = np.ones(theta.shape, np.float32)
    >>> prof = row_profiles(labels, stair_values(theta, ones, ones))
    >>> prof.region.size, prof.region[:2].tolist(), prof.row[:2].tolist(), prof.count[:2].tolist()
    (96, [1, 1], [0, 1], [8, 8])
    """
    return _profiles(labels.shape[0], *label_row_sums(labels, values, int(labels.max())))


def stair_row_profiles(labels: np.ndarray, phi: np.ndarray, theta: np.ndarray,
                       stair_mod: np.ndarray, mod: np.ndarray) -> RowProfiles:
    """:func:`row_profiles` of the values :func:`stair_values` would make from float32 maps
    (weight ``core_weight(phi) * min(ratio, 1)``, ``ratio = clip(stair_mod / max(mod,
    1e-6), 0, 2)``), summed as they are computed
    (:func:`~bistair.codecs.bidirectional.profiles_jit.label_stair_sums`).

    Parameters
    ----------
    labels : numpy.ndarray
        (H, W) int32 fringe region labels, 0 for no region.
    phi, theta, stair_mod, mod : numpy.ndarray
        (H, W) float32 wrapped phase, stair phase, modulation of the stair pair and of the
        fringes.

    Returns
    -------
    RowProfiles
        The same as :func:`row_profiles` of the stored values.

    Examples
    --------
    >>> from dataclasses import astuple
    >>> from bistair.core.regions import core_weight
    >>> rng = np.random.default_rng(0)
    >>> phi, theta, stair_mod, mod = (rng.uniform(0.1, 1, (6, 5)).astype(np.float32)
    ...                               for _ in range(4))
    >>> labels = rng.integers(0, 3, (6, 5)).astype(np.int32)
    >>> a = stair_row_profiles(labels, phi, theta, stair_mod, mod)
    >>> ratio = np.clip(stair_mod / np.maximum(mod, 1e-6), 0.0, 2.0)
    >>> values = stair_values(theta, core_weight(phi) * np.minimum(ratio, 1.0), ratio)
    >>> b = row_profiles(labels, values)
    >>> all(np.array_equal(u, v) for u, v in zip(astuple(a), astuple(b)))
    True
    """
    return _profiles(labels.shape[0], *label_stair_sums(labels, phi, theta, stair_mod, mod,
                                                        int(labels.max())))


def relabel_stair_profiles(labels: np.ndarray, roots: np.ndarray, remap: np.ndarray,
                           phi: np.ndarray, theta: np.ndarray, stair_mod: np.ndarray,
                           mod: np.ndarray, n_labels: int) -> RowProfiles:
    """The final fringe regions written in place (``remap[roots[labels]]``, what
    :func:`~bistair.core.regions.fringe_regions` writes) and :func:`stair_row_profiles` of
    them, gathered in the same scan
    (:func:`~bistair.codecs.bidirectional.profiles_jit.relabel_stair_sums`): the same
    profiles, bit for bit, without a scan of their own.

    Parameters
    ----------
    labels : numpy.ndarray
        (H, W) int32 provisional labels (:func:`~bistair.core.regions.label_fringes`),
        changed in place to the final ones.
    roots, remap : numpy.ndarray
        The region of each provisional label and the final number of each region
        (:func:`~bistair.core.regions.kept_regions`).
    phi, theta, stair_mod, mod : numpy.ndarray
        (H, W) float32 maps, as :func:`stair_row_profiles`.
    n_labels : int
        The number of regions kept.

    Returns
    -------
    RowProfiles
        :func:`stair_row_profiles` of the final labels.

    Examples
    --------
    >>> from dataclasses import astuple
    >>> from bistair.core.regions import kept_regions, label_fringes
    >>> x = np.arange(60.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (8, 1)).astype(np.float32)
    >>> theta, ones = 0 * phi + 1, np.ones(phi.shape, np.float32)
    >>> lab = label_fringes(phi, ones > 0)
    >>> remap, n = kept_regions(lab)
    >>> got = relabel_stair_profiles(lab.labels, lab.roots, remap, phi, theta, ones, ones, n)
    >>> want = stair_row_profiles(lab.labels, phi, theta, ones, ones)
    >>> n, all(np.array_equal(u, v) for u, v in zip(astuple(got), astuple(want)))
    (2, True)
    """
    return _profiles(labels.shape[0], *relabel_stair_sums(labels, roots, remap, phi, theta,
                                                          stair_mod, mod, n_labels))


def _profiles(h: int, keys: np.ndarray, count: np.ndarray, sums: np.ndarray) -> RowProfiles:
    c, s, wsum, rsum, cols = sums
    return RowProfiles(keys // h, keys % h, c, s, wsum, rsum / np.maximum(count, 1), count,
                       cols)


def profile_centroids(prof: RowProfiles, n_regions: int) -> np.ndarray:
    """(row, column) centroid of each region 0..n_regions from its row profiles.

    Parameters
    ----------
    prof : RowProfiles
        From :func:`row_profiles`.
    n_regions : int
        The highest region label.

    Returns
    -------
    numpy.ndarray
        (n_regions + 1, 2) float64 centroids in camera pixels (0, 0 for a region without
        pixels, such as 0).

    Examples
    --------
    A 48 x 16 image of two fringe regions (orders 5 and 6, eight columns each) of a code
    with ``S = 4`` stairs and ``P = 3`` partitions, in groups of 16 rows, 10 of them local:

    >>> from bistair.core.stair import stair_level_phase
    >>> y = np.arange(48)[:, None]
    >>> k = np.where(np.arange(16) < 8, 5, 6)
    >>> theta = np.where(y % 16 < 10, stair_level_phase(k % 4, 4),
    ...                  stair_level_phase(k // 4, 3)).astype(np.float32)
    >>> labels = np.tile(np.where(np.arange(16) < 8, 1, 2), (48, 1)).astype(np.int32)
    >>> ones = np.ones(theta.shape, np.float32)
    >>> prof = row_profiles(labels, stair_values(theta, ones, ones))
    >>> profile_centroids(prof, 2).tolist()
    [[0.0, 0.0], [23.5, 3.5], [23.5, 11.5]]
    """
    # compiled, the three bincounts in one pass (tests/support keeps the NumPy)
    return centroids_of(np.asarray(prof.region), np.asarray(prof.row), np.asarray(prof.count),
                        np.asarray(prof.col_sum, np.float64), int(n_regions))
