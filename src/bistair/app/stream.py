"""The old name of :mod:`.decode_stream` (``decode --window``): an alias for one release."""

from .decode_stream import (
    Window,
    check_stream_spec,
    decode_stream,
    parse_starts,
    parse_window,
    refuse_single_period,
)

__all__ = ["Window", "check_stream_spec", "decode_stream", "parse_starts", "parse_window",
           "refuse_single_period"]
