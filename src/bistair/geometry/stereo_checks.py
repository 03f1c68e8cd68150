"""Checks that a binocular reconstruction's inputs fit each other, beyond what the matching
itself refuses (:mod:`bistair.geometry.stereo`): the same captures given for both cameras,
two cameras whose projector rows disagree (both axes decoded), and points that no single
projector could have lit (:func:`projector_misfits`).

The projector is the third view of every scene point: the coordinate each point was lit
with is, for a pinhole projector, a ratio of two affine functions of the point,
``x_p = (a . P + a0) / (c . P + c0)``, the same seven numbers for every point. A right
reconstruction fits it to the decode's noise (plus the projector's smooth lens distortion,
fitted as a cubic of ``x_p`` and the image row); a pair whose rows do not correspond
(cameras exchanged, R, T of another pair, an image upside down) puts points where no
projector ray meets them, tens of projector pixels off. What it cannot see: a
reconstruction that is a projective distortion of the truth fits as well (a baseline or
focal length scaled, and, with one coded axis, cameras exchanged on a scene without detail
down the image: a plane, upright cylinders), so these checks judge only what a scene shows.

Examples
--------
Points lit by a pinhole projector fit it; moving a few of them along the ray makes them
misfits:

>>> rng = np.random.default_rng(0)
>>> pts = rng.uniform([-100, -80, 500], [100, 80, 700], (4000, 3))
>>> coord = 960 + 2000 * (pts[:, 0] - 100) / pts[:, 2]
>>> rows = 240 + 600 * pts[:, 1] / pts[:, 2]
>>> projector_misfits(pts, coord, rows)
0.0
>>> pts[:200, 2] *= 1.2
>>> round(projector_misfits(pts, coord, rows), 3)
0.048
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import BistairError

Coords = dict[str, tuple[np.ndarray, np.ndarray]]  # per coded axis: left and right coordinates

MIN_MATCHED = 0.10  # fewer matched left pixels than this share: the inputs do not fit
MISFIT_FLOOR = 0.002  # projector misfits over this share: other readings of the inputs tried
MISFIT_RATIO = 5.0  # ... one refused when that reading has this many times fewer misfits
MISFIT_WARN = 0.01  # ... else a warning over this share
MISFIT_PX = 5.0  # a point off the projector's fit by more than this (projector px) misfits
MISFIT_SAMPLE = 30000  # points fitted (evenly spaced through the matched ones)
MISFIT_MIN_POINTS = 1000  # fewer points: nothing judged
OTHER_AXIS_MAX = 0.10  # share of the decoded left pixels whose projector rows disagree


def same_captures(left: np.ndarray, right: np.ndarray) -> None:
    """Refuse one camera's captures given for both (two cameras never give equal images:
    their noise alone differs).

    Parameters
    ----------
    left, right : numpy.ndarray
        The two cameras' capture stacks.

    Raises
    ------
    BistairError
        ``left`` and ``right`` hold the same values.

    Examples
    --------
    >>> same_captures(np.zeros((3, 4, 4)), np.ones((3, 4, 4)))
    >>> same_captures(np.zeros((3, 4, 4)), np.zeros((3, 4, 4)))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the left and right captures are the same images: ...
    """
    if left.shape == right.shape and np.array_equal(left[0], right[0]) and \
            np.array_equal(left, right):
        raise BistairError("the left and right captures are the same images: give each "
                           "camera's own captures")


def other_axis_share(rejected: int, decoded: int) -> float:
    """The share of the decoded left pixels whose match the other projector axis refused.

    Parameters
    ----------
    rejected : int
        Left pixels whose projector rows disagree with their match's (``other_axis``).
    decoded : int
        Left pixels decoded on the matched axis.

    Returns
    -------
    float

    Examples
    --------
    >>> other_axis_share(50, 1000)
    0.05
    """
    return rejected / max(decoded, 1)


def other_readings(coords: Coords, same_size: bool) -> dict[str, Coords]:
    """The other readings of two cameras' coordinates that a mistake would call for: the
    right images upside down (flipped top to bottom) and, for cameras of one size, the two
    cameras exchanged.

    Parameters
    ----------
    coords : dict
        Both cameras' coordinates per coded axis, as given.
    same_size : bool
        Whether the two cameras' images have one size.

    Returns
    -------
    dict
        ``{"upside down": coords, "exchanged": coords}`` (the latter for one size).

    Examples
    --------
    >>> a, b = np.zeros((2, 3)), np.ones((2, 3))
    >>> sorted(other_readings({"columns": (a, b)}, True))
    ['exchanged', 'upside down']
    """
    out = {"upside down": {k: (a, b[::-1]) for k, (a, b) in coords.items()}}
    if same_size:
        out["exchanged"] = {k: (b, a) for k, (a, b) in coords.items()}
    return out


def check_matches(info: dict[str, Any], coords: Coords,
                  misfits_of: Callable[[Coords], tuple[float, float]], same_size: bool,
                  misfits: float) -> list[str]:
    """What a binocular match says against its inputs: too few matches, projector rows that
    disagree (both axes decoded, over :data:`OTHER_AXIS_MAX`), points that no projector lit
    (over :data:`MISFIT_FLOOR`, when another reading of the inputs fits
    :data:`MISFIT_RATIO` times better; else a warning over :data:`MISFIT_WARN`).

    Parameters
    ----------
    info : dict
        The reconstruction's ``info`` (``matched_fraction``, ``left_decoded``,
        ``other_axis``); gets ``other_axis_share`` (both axes), ``projector_misfits``,
        ``other_readings`` (the misfits of each reading tried) and warnings.
    coords : dict
        Both cameras' coordinates per coded axis.
    misfits_of : callable
        ``(misfits, matched share)`` of a match of other coordinates.
    same_size : bool
        Whether the two cameras' images have one size (so that they can be exchanged).
    misfits : float
        The projector misfits of the inputs as given.

    Returns
    -------
    list of str
        The refusals (empty when the inputs fit); the first is the one to raise.

    Examples
    --------
    >>> info = {"matched_fraction": 0.05, "left_decoded": 1000, "other_axis": 0}
    >>> check_matches(info, {}, None, True, 0.0)[0]  # doctest: +ELLIPSIS
    'only 5.0% of the 1000 decoded left pixels found their match in the right camera: ...'
    """
    share = info["matched_fraction"]
    if share < MIN_MATCHED:
        return [f"only {100 * share:.1f}% of the {info['left_decoded']} decoded left pixels "
                "found their match in the right camera: is the calibration for these "
                "cameras, and are LEFT and RIGHT the right way round?"]
    if len(coords) == 2:
        rows = info["other_axis_share"] = round(
            other_axis_share(info["other_axis"], info["left_decoded"]), 6)
        if rows > OTHER_AXIS_MAX:
            return [f"the projector rows disagree between the two cameras at {100 * rows:.0f}% "
                    f"of the decoded left pixels (over {100 * OTHER_AXIS_MAX:.0f}%): their "
                    "rectified rows are not the same; are LEFT and RIGHT the right way round, "
                    "is the calibration for these cameras, is one image upside down?"]
    info["projector_misfits"] = round(misfits, 6)
    if misfits <= MISFIT_FLOOR:
        return []
    tried = info["other_readings"] = {}
    for reading, alt in other_readings(coords, same_size).items():
        try:
            other, matched = misfits_of(alt)
        except BistairError:  # the matching refuses this reading outright
            continue
        tried[reading] = round(other, 6)
        if matched >= MIN_MATCHED and other * MISFIT_RATIO <= misfits:
            ask = ("are LEFT and RIGHT the right way round?" if reading == "exchanged"
                   else "is the right camera upside down (its images flipped top to bottom)?")
            return [f"{100 * misfits:.1f}% of the points lie off the projector that lit the "
                    f"others (over {MISFIT_PX:g} projector pixels), {100 * other:.2f}% with "
                    f"the {_READING[reading]}: {ask}"]
    if misfits > MISFIT_WARN:
        info["warnings"].append(
            f"{100 * misfits:.1f}% of the points lie off the projector that lit the others "
            f"(over {MISFIT_PX:g} projector pixels): wrong matches or decodes, or a "
            "calibration for other cameras")
    return []


_READING = {"exchanged": "cameras exchanged", "upside down": "right images upside down"}


def projector_misfits(points: np.ndarray, coord: np.ndarray, rows: np.ndarray) -> float:
    """The share of points farther than :data:`MISFIT_PX` (projector pixels) from the
    projector that best explains the rest.

    Fitted on up to :data:`MISFIT_SAMPLE` points evenly spaced through the list: the
    pinhole projector's coordinate ``(a . P + a0) / (c . P + c0)`` (direct linear
    transform, weighted toward the geometric error), plus a cubic in the coordinate and
    the image row for its lens distortion, refitted four times without the tenth of the
    points that fit worst.

    Parameters
    ----------
    points : numpy.ndarray
        ``(N, 3)`` points (any frame, mm).
    coord : numpy.ndarray
        ``(N,)`` the projector coordinate each point was decoded with (the matched axis).
    rows : numpy.ndarray
        ``(N,)`` each point's image row (a stand-in for the projector's other coordinate
        in the distortion).

    Returns
    -------
    float
        The share of misfits among the points fitted; 0 for fewer than
        :data:`MISFIT_MIN_POINTS` points.

    Examples
    --------
    See the module's (a pinhole projector's points, and 5% of them moved).

    >>> projector_misfits(np.zeros((10, 3)), np.zeros(10), np.zeros(10))
    0.0
    """
    n = len(coord)
    if n < MISFIT_MIN_POINTS:
        return 0.0
    pick = np.linspace(0, n - 1, min(n, MISFIT_SAMPLE)).astype(np.int64)
    pts, x, v = (np.asarray(a, float)[pick] for a in (points, coord, rows))
    centre = pts.mean(axis=0)
    scale = np.sqrt(((pts - centre) ** 2).sum(axis=1).mean() / 3) or 1.0
    pts = (pts - centre) / scale
    x_mean, x_scale = x.mean(), x.std() or 1.0
    xn = (x - x_mean) / x_scale
    vn = (v - v.mean()) / (v.std() or 1.0)
    xp, vp = [xn**i for i in range(4)], [vn**j for j in range(4)]
    cubic = np.empty((len(xn), 10))  # x^i v^j, i + j <= 3
    powers = [(i, j) for i in range(4) for j in range(4 - i)]
    for c, (i, j) in enumerate(powers):
        np.multiply(xp[i], vp[j], out=cubic[:, c])
    system = np.empty((len(xn), 8))  # a . P + a0 - x (c . P + c0), x the corrected coordinate
    system[:, :3], system[:, 3] = pts, 1.0
    bent = np.zeros_like(xn)  # the distortion's share of each coordinate
    keep = None  # every point, at first
    for _ in range(4):
        corrected = xn - bent
        system[:, 4:7], system[:, 7] = -corrected[:, None] * pts, -corrected
        if keep is None:
            p = _dlt(system, pts)
        else:
            p = _dlt(system[keep], pts[keep])
        residual = xn - (pts @ p[:3] + p[3]) / (pts @ p[4:7] + p[7])
        sub, kept = (cubic, residual) if keep is None else (cubic[keep], residual[keep])
        bent = cubic @ np.linalg.solve(sub.T @ sub, sub.T @ kept)
        off = np.abs(residual - bent)
        keep = np.flatnonzero(off <= np.partition(off, int(0.9 * (len(off) - 1)))[
            int(0.9 * (len(off) - 1))])
    return float(np.mean(off * x_scale > MISFIT_PX))


def _dlt(system: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """``(a, a0, c, c0)`` of ``x = (a . P + a0) / (c . P + c0)`` by least squares on the rows
    ``a . P + a0 - x (c . P + c0) = 0`` of ``system`` (the eigenvector of the normal
    matrix with the least eigenvalue), reweighted twice by ``1 / |c . P + c0|`` (toward
    the geometric error)."""
    weight = np.ones(len(system))
    for _ in range(3):
        rows = system * weight[:, None]
        p = np.linalg.eigh(rows.T @ rows)[1][:, 0]
        weight = 1.0 / np.maximum(np.abs(pts @ p[4:7] + p[7]), 1e-12)
        weight /= np.median(weight)
    return p
