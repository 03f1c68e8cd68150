"""The two-camera OpenCV import's old module, kept for one release:
:func:`read_opencv_stereo` lives in :mod:`bistair.geometry.opencv` now."""

from .opencv import DEFAULT_STEREO_KEYS, STEREO_ROLES, read_opencv_stereo  # noqa: F401
