"""The old home of the decode, pattern and calibration jobs: an alias for one release.

Issue 35 split it by command: :mod:`bistair.app.patterns` (``save_patterns``,
``save_ramp``, ``measure_gamma``, ``read_gamma``), :mod:`bistair.app.decode`
(``decode_folder``, ``require_valid``, ``height_folder``, ``reconstruct_folder``,
``parse_depth_range``) and :mod:`bistair.app.calibrate` (``import_calibration``,
``import_projection_matrices``, ``parse_size``, ``parse_keys``). Import them from there.
"""

from .calibrate import import_calibration, import_projection_matrices, parse_keys, parse_size
from .decode import (
    decode_folder,
    height_folder,
    parse_depth_range,
    reconstruct_folder,
    require_valid,
)
from .patterns import measure_gamma, read_gamma, save_patterns, save_ramp

__all__ = ["decode_folder", "height_folder", "import_calibration", "import_projection_matrices",
           "measure_gamma", "parse_depth_range", "parse_keys", "parse_size", "read_gamma",
           "reconstruct_folder", "require_valid", "save_patterns", "save_ramp"]
