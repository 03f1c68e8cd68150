"""Calibrating two cameras from image pairs of a board (``bistair calibrate-stereo``).

The board's corners are found in each image (OpenCV ``findChessboardCornersSB``, else
``findChessboardCorners`` + ``cornerSubPix``; circle grids with ``findCirclesGrid``:
:meth:`~bistair.geometry.board.Board.detect`); a pose whose board is not found in both
images is skipped. Each camera is calibrated alone (``cv2.calibrateCamera``), then both
together (``cv2.stereoCalibrateExtended``, every parameter refined), with one standard
deviation of each (:func:`~bistair.geometry.calibrate.calibrate_points`, which calibrates
any two devices that see the same board points).

A chessboard's corners come back from OpenCV starting at either end of the board; both
images of a pose are put in the same order (the first corner the one nearer the image's
top-left), which is the same corner of the board for two cameras side by side.

Examples
--------
>>> board = Board("checkerboard", 4, 3, 10.0)
>>> pts = board.object_points()[:, :2] * 3 + 50  # an upright view
>>> bool(np.array_equal(_upright(pts[::-1]), pts))
True
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import BistairError
from .board import Board
from .calibrate import MIN_POSES, calibrate_points
from .stereo_calibration import MIN_BASELINE, StereoCalibration, on_the_left


def calibrate_stereo_images(left: Sequence[np.ndarray], right: Sequence[np.ndarray],
                            board: Board, names: Sequence[str] | None = None,
                            min_poses: int = MIN_POSES, fix_k3: bool = True
                            ) -> tuple[StereoCalibration, list[str]]:
    """Calibrate two cameras from grey images of a board, pose by pose.

    Parameters
    ----------
    left, right : sequence of numpy.ndarray
        Per pose, the left and the right camera's grey image (2-D, any dtype; every left
        image of one size, every right image of one size).
    board : Board
        The board (``columns x rows`` inner corners or circles, spacing in mm).
    names : sequence of str, optional
        The poses' names (for the per-pose errors and the skipped poses).
    min_poses : int, optional
        The fewest poses with the board found in both images (3 at least).
    fix_k3 : bool, optional
        Keep ``k3 = 0``.

    Returns
    -------
    calibration : StereoCalibration
        With the stereo RMS, the per-pose errors (``left_rms``, ``right_rms``), the board,
        the number of poses given and the uncertainty of every parameter.
    skipped : list of str
        The poses whose board was not found in both images.

    Raises
    ------
    BistairError
        Different numbers of left and right images, images of different sizes or not 2-D,
        the board found in both images of fewer than ``min_poses`` poses, OpenCV failing, the
        camera of the right images on the left of the other (images named the wrong way
        round) or the cameras under 1 mm apart (a board's square not in millimetres).

    Examples
    --------
    Blank images show no board (``tests/test_stereo_calibrate.py`` calibrates from rendered
    board pairs):

    >>> blank = [np.ones((60, 80))] * 3
    >>> calibrate_stereo_images(blank, blank, Board())
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: board found in both images of 0 of 3 poses, need at least 3
    """
    if len(left) != len(right):
        raise BistairError(f"{len(left)} left and {len(right)} right images: they go in pairs")
    if min_poses < MIN_POSES:
        raise BistairError(f"min_poses {min_poses} is too few: a stereo calibration needs at "
                           f"least {MIN_POSES} board poses")
    names = list(names) if names is not None else [f"pose-{i:02d}" for i in range(len(left))]
    sizes = {}
    for side, images in (("left", left), ("right", right)):
        for name, img in zip(names, images, strict=True):
            if np.ndim(img) != 2:
                raise BistairError(f"{name}: the {side} image must be grey (2-D), got shape "
                                   f"{np.shape(img)}")
            h, w = np.shape(img)
            first = sizes.setdefault(side, (w, h, name))
            if (w, h) != first[:2]:
                raise BistairError(f"{name}: the {side} image is {w}x{h}, the {side} image of "
                                   f"{first[2]} {first[0]}x{first[1]}")
    obj, lpts, rpts, used, skipped = [], [], [], [], []
    for name, li, ri in zip(names, left, right, strict=True):
        a, b = board.detect(li), board.detect(ri)
        if a is None or b is None:
            skipped.append(name)
            continue
        if board.type != "asymmetric-circles":  # its corners come in one order only
            a, b = _upright(a), _upright(b)
        obj.append(board.object_points())
        lpts.append(a)
        rpts.append(b)
        used.append(name)
    if len(used) < min_poses:
        raise BistairError(f"board found in both images of {len(used)} of {len(names)} poses, "
                           f"need at least {min_poses}")
    pair = calibrate_points(obj, lpts, rpts, sizes["left"][:2], sizes["right"][:2], used,
                            fix_k3=fix_k3)
    left_of = on_the_left(pair.R, pair.T)
    if left_of > 0:
        raise BistairError(f"the camera of the right images sits {left_of:.1f} mm to the left "
                           "of the other (the right camera is the one at +x of the left, to "
                           "the right in its image): are the board images named the wrong way "
                           "round? Exchange left and right")
    if pair.baseline < MIN_BASELINE:
        raise BistairError(f"the cameras come out {pair.baseline:.3g} mm apart: is the "
                           f"board's square size ({board.spacing:g}) in millimetres?")
    cal = StereoCalibration.from_pair(pair)
    return cal.replace(board=board.to_dict(), poses_total=len(names)), skipped


def _upright(points: np.ndarray) -> np.ndarray:
    """Detected board points in the order that starts at the end nearer the image's
    top-left (the list reversed otherwise: the same grid turned by 180 degrees)."""
    first, last = points[0], points[-1]
    return points[::-1].copy() if first.sum() > last.sum() else points
