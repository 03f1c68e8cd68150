"""The two-camera calibration's old module, kept for one release:
:func:`calibrate_stereo_images` lives in :mod:`bistair.geometry.calibrate` now."""

from .calibrate import calibrate_stereo_images  # noqa: F401
