"""The old name of :mod:`.scan_series` (``scan --scans``): an alias for one release."""

from .scan_series import (
    MAX_BACKLOG,
    MAX_SCANS,
    NOT_ASKED,
    OUTPUT_BACKLOG,
    SERIES_FILE,
    WRITE_BACKLOG,
    SeriesReport,
    scan_series,
    summary_lines,
)

__all__ = ["MAX_BACKLOG", "MAX_SCANS", "NOT_ASKED", "OUTPUT_BACKLOG", "SERIES_FILE",
           "WRITE_BACKLOG", "SeriesReport", "scan_series", "summary_lines"]
