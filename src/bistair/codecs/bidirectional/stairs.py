"""The stair code against the decoded orders: where the code says two surfaces meet inside a
fringe (:func:`stair_edges`), and the share of decoded pixels whose stair phase contradicts
their order (:func:`stair_fit`, the check that refuses a spec that does not fit).

Their compiled passes are in :mod:`.stairs_jit`; the codec's stages take two of them
through this module, their door: ``stair_noise`` (the stair phase's noise per pixel) and
``stair_agreement`` (the share of pixels whose stair level agrees with their order).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import cv2
import numpy as np

from ...core.measure import FringeSet
from ...core.memory import row_bands
from ...core.phase import TWO_PI, wrap
from ...core.stair import stair_level_phase
from .bands import nearest_level, observed_levels, union_levels
from .stairs_jit import stair_agreement as stair_agreement  # (the stages' door to it)
from .stairs_jit import stair_noise as stair_noise  # (the stages' door to it)
from .stairs_jit import stair_turns

if TYPE_CHECKING:
    from . import BidirectionalSpec


def stair_fit(fs: FringeSet, theta: np.ndarray, stair_mod: np.ndarray, order: np.ndarray,
              spec: BidirectionalSpec, samples: int = 20000,
              readings: np.ndarray | None = None) -> float:
    """Share of decoded pixels whose stair phase contradicts their fringe order.

    A pixel of order ``k`` shows the local level ``k % S`` or the partition level ``k // S``
    (its projector row decides which). Among pixels whose stair phase is sharp (noise under
    0.1 rad) and away from the fringe edges, those nearer another level of either stair
    (by twice their noise and at least 0.05 rad; levels where this capture shows them, as
    an uncompensated gamma moves them) contradict their order. A right decode has almost
    none; a spec with other partitions or stairs than the captures' has many.

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout (phase, validity and camera noise).
    theta : numpy.ndarray
        (H, W) stair phase in radians (``maps["stair_phase"]``).
    stair_mod : numpy.ndarray
        (H, W) modulation of the stair pair, fraction of full scale.
    order : numpy.ndarray
        (H, W) int decoded fringe order, -1 where invalid.
    spec : BidirectionalSpec
        The spec of one coded axis.
    samples : int, default 20000
        At most how many decoded pixels to judge (:func:`grid_sample`).
    readings : numpy.ndarray, optional
        (L,) where the union levels read in ``theta`` when a response moves them
        (:func:`~bistair.core.stair.level_readings`): each level's observed phase is then
        taken around its reading, not its nominal phase.

    Returns
    -------
    float
        The share in [0, 1]; 0.0 when fewer than 500 pixels can be judged.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.codecs.bidirectional import code_columns, order_columns
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("bidirectional", width=240, height=64, period=20, partitions=3,
    ...                  stairs=4, group_rows=16, local_rows=10)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> theta, stair_mod = code.maps["stair_phase"], code.maps["stair_modulation"]
    >>> order = order_columns(fs, code, spec).order
    >>> stair_fit(fs, theta, stair_mod, order, spec)
    0.0
    >>> round(stair_fit(fs, theta, stair_mod, np.where(order >= 0, order + 1, -1), spec), 3)
    0.583
    """
    idx = grid_sample(fs.valid, order, samples)
    th, k = theta.ravel()[idx].astype(np.float64), order.ravel()[idx].astype(np.int64)
    sigma = fs.noise * math.sqrt(2.0) / np.maximum(stair_mod.ravel()[idx], 1e-6)
    phi = fs.phi.ravel()[idx]
    sharp = (sigma < 0.1) & (phi > 0.5) & (phi < TWO_PI - 0.5)
    th, k, sigma = th[sharp], k[sharp], sigma[sharp]
    if th.size < 500:
        return 0.0
    levels = union_levels(spec.partitions, spec.stairs)
    seen = observed_levels(th, np.ones(th.size), levels if readings is None else readings)
    near = np.abs(wrap(th - seen[nearest_level(th, seen)]))  # the least distance to a level
    local = nearest_level(stair_level_phase(np.arange(spec.stairs), spec.stairs), levels)
    part = nearest_level(stair_level_phase(np.arange(spec.partitions), spec.partitions), levels)
    inside = k // spec.stairs < spec.partitions
    kk = np.where(inside, k, 0)
    own = np.minimum(np.abs(wrap(th - seen[local[kk % spec.stairs]])),
                     np.abs(wrap(th - seen[part[kk // spec.stairs]])))
    return float(np.mean(~inside | (own > near + np.maximum(0.05, 2.0 * sigma))))


def grid_sample(valid: np.ndarray, order: np.ndarray, samples: int) -> np.ndarray:
    """Flat indices of at most ``samples`` decoded pixels (valid, order >= 0) on a fixed
    grid, never a scan of the image to find them: every ``m``-th pixel in raster order
    (``m`` prime to the width, so that the grid walks across the columns from row to row
    and no band of rows or columns is left out; about three times ``samples`` pixels),
    then every ``j``-th decoded pixel of those.

    Parameters
    ----------
    valid : (H, W) bool array
        Valid pixels.
    order : (H, W) int array
        Fringe orders, -1 where not decoded.
    samples : int
        At most how many pixels to pick (at least 1).

    Returns
    -------
    int64 array
        The flat indices, ascending.

    Examples
    --------
    >>> order = np.zeros((40, 6), np.int32)
    >>> order[0, 3] = -1
    >>> grid_sample(np.ones((40, 6), bool), order, 20).tolist()  # every 3rd of every 5th
    [2, 17, 32, 47, 62, 77, 92, 107, 122, 137, 152, 167, 182, 197, 212, 227]
    >>> grid_sample(np.ones((40, 6), bool), order, 1000).size  # all, one not decoded
    239
    """
    h, w = valid.shape
    m = max(1, h * w // (3 * max(1, int(samples))))
    while m > 1 and math.gcd(m, w) > 1:
        m += 1
    grid = np.arange(m // 2, h * w, m, dtype=np.int64)
    idx = grid[valid.ravel()[grid] & (order.ravel()[grid] >= 0)]
    return idx[:: max(1, -(-idx.size // samples))]


def stair_edges(phi: np.ndarray, theta: np.ndarray, valid: np.ndarray, noise: np.ndarray,
                stairs: int, reach: int) -> tuple[np.ndarray, np.ndarray]:
    """Where the stair code changes along a row inside a fringe: the edge of one surface
    against another whose fringe the wrapped phase runs on into (vertical links (H-1, W),
    horizontal links (H, W-1) to cut).

    Along a row the code only changes where the phase jumps, so a change of at least three
    quarters of a local stair step (and four times its noise, ``noise``: per-pixel stair
    phase noise) between the pairs of pixels either side of a link, away from the phase
    jumps, in four or more rows on end, is an edge. Neighbouring fringes often share their
    partition level, so the edge found in the local bands is carried ``reach`` rows up and
    down across the partition bands between them.

    Parameters
    ----------
    phi : numpy.ndarray
        (H, W) wrapped phase in [0, 2*pi), column layout.
    theta : numpy.ndarray
        (H, W) stair phase in radians.
    valid : numpy.ndarray
        (H, W) bool, the pixels to use.
    noise : numpy.ndarray
        (H, W) stair phase noise per pixel, radians.
    stairs : int
        Local stair levels ``S`` (the step is ``2*pi/S``).
    reach : int
        Rows an edge is carried up and down (0: not carried).

    Returns
    -------
    vertical : numpy.ndarray
        (H-1, W) bool, links between rows to cut (none: all False).
    horizontal : numpy.ndarray
        (H, W-1) bool, links between columns to cut.

    Examples
    --------
    Two surfaces side by side: right of column 110 the patterns are two fringes further
    on, so the phase runs on and the stair code jumps (on the local rows only: fringes 5
    and 7 share their partition level).

    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.codecs.bidirectional import code_columns, order_columns
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("bidirectional", width=240, height=64, period=20, partitions=3,
    ...                  stairs=4, group_rows=16, local_rows=10)
    >>> images = encode(spec)
    >>> images[:, :, 110:] = np.roll(images, -40, axis=2)[:, :, 110:]
    >>> cols = prepare(images, spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> theta = code_columns(cols, spec, fs).maps["stair_phase"]
    >>> noise = np.full(theta.shape, 0.01, np.float32)
    >>> vertical, edge = stair_edges(fs.phi, theta, fs.valid, noise, spec.stairs, 0)
    >>> vertical.shape, edge.shape, bool(vertical.any()), int(edge[:, 109].sum())
    ((63, 240), (64, 239), False, 40)
    >>> _, edge = stair_edges(fs.phi, theta, fs.valid, noise, spec.stairs, 12)
    >>> int(edge[:, 109].sum()), np.unique(np.nonzero(edge)[1]).tolist()
    (64, [108, 109, 110])
    """
    h, w = phi.shape
    noise = np.ascontiguousarray(noise, dtype=np.float32)
    edge = np.empty((h, w - 1), bool)
    bands = row_bands(h)
    for y0 in bands:  # the cosine and sine for a band of rows at a time
        rows = slice(y0, y0 + bands.step)
        edge[rows] = stair_turns(phi[rows], np.cos(theta[rows]), np.sin(theta[rows]),
                                 valid[rows], noise[rows], TWO_PI / stairs)
    ys, xs = np.flatnonzero(edge.any(axis=1)), np.flatnonzero(edge.any(axis=0))
    if ys.size == 0:
        return np.zeros((h - 1, w), bool), edge
    # morphology on the edges' bounding box (with margins the structures cannot reach past)
    y0, y1 = max(ys[0] - reach - 8, 0), min(ys[-1] + reach + 9, h)
    x0, x1 = max(xs[0] - 4, 0), min(xs[-1] + 5, w - 1)
    edge[y0:y1, x0:x1] = edge_runs(edge[y0:y1, x0:x1], reach)
    return np.zeros((h - 1, w), bool), edge


def edge_runs(edge: np.ndarray, reach: int) -> np.ndarray:
    """The links of ``edge`` that lie in runs of four or more rows on end (allowing a
    column's shift either way), carried ``reach`` rows up and down: the morphology of
    :func:`stair_edges`, as scipy.ndimage's binary dilation (1 x 3), opening (4 x 1) and
    dilation (``2 reach + 1`` x 1) with the image's outside empty give it, done by OpenCV.

    Parameters
    ----------
    edge : numpy.ndarray
        (H, W) bool, the links where the stair phase turns.
    reach : int
        Rows an edge is carried up and down (0: not carried).

    Returns
    -------
    numpy.ndarray
        (H, W) bool, the links kept and carried.

    Examples
    --------
    >>> edge = np.zeros((12, 5), bool)
    >>> edge[2:6, 1] = True  # four rows on end, one column
    >>> edge[3:6, 2] = edge[9, 3] = True  # three rows beside them; a lone link
    >>> kept = edge_runs(edge, 0)
    >>> np.argwhere(kept).tolist() == np.argwhere(edge[:, :3]).tolist()
    True
    >>> edge_runs(edge, 2)[:, 1].nonzero()[0].tolist()
    [0, 1, 2, 3, 4, 5, 6, 7]
    """
    box = np.ascontiguousarray(edge, dtype=bool).view(np.uint8)
    empty = dict(borderType=cv2.BORDER_CONSTANT, borderValue=0)
    wide = cv2.dilate(box, np.ones((1, 3), np.uint8), **empty)
    # opening with a 4-row element: scipy erodes over rows y-2 .. y+1 and dilates over
    # y-1 .. y+2 (its reflected element); OpenCV does not reflect, hence the anchors
    column = np.ones((4, 1), np.uint8)
    opened = cv2.dilate(cv2.erode(wide, column, anchor=(0, 2), **empty), column,
                        anchor=(0, 1), **empty)
    box = box & opened
    if reach > 0 and box.any():
        box = cv2.dilate(box, np.ones((2 * reach + 1, 1), np.uint8), **empty)
    return box.view(bool)
