"""The two-camera calibration's old module, kept for one release: :class:`StereoCalibration`
and its functions live in :mod:`bistair.geometry.calibration` now (one calibration file,
either kind: ``load_calibration``, ``save_calibration``)."""

from .calibration import (  # noqa: F401
    KIND,
    MIN_BASELINE,
    WARN_BASELINE,
    ProjectorPose,
    StereoCalibration,
    check_pair,
    is_stereo_file,
    load_stereo_calibration,
    on_the_left,
    right_centre,
    save_stereo_calibration,
    short_baseline,
)
