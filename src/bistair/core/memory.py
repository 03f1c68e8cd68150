"""Keeping freed memory in the process for the next array (glibc's allocator settings).

A decode allocates and frees dozens of frame-sized arrays. glibc's ``malloc`` hands every
block above its mmap threshold (which grows with the blocks freed, but never past 32 MiB:
a float32 frame of 8 MP or more) back to the kernel when it is freed, so each new array of
that size has its pages faulted in and zeroed again: at 12 MP some 1.5 GB of page faults
and over a third of a decode's time. :func:`keep_freed_memory` raises the mmap and trim
thresholds so that freed blocks stay in the process's heap and the next arrays reuse them.
The process then holds on to its peak memory between decodes, which is what a scanner
decoding capture after capture wants; :func:`keep_freed_memory` with ``False`` gives the
freed memory back and restores glibc's defaults.

The command line turns this on for its decodes (``bistair decode``, ``batch``, ``bench``);
``bistair.decode`` from Python leaves the allocator alone unless asked. Other C libraries
(musl, macOS, Windows) are left alone: the functions return ``False`` there.

Examples
--------
>>> keep_freed_memory() in (True, False)  # False where the C library is not glibc
True
>>> keep_freed_memory(False) in (True, False)
True
"""

from __future__ import annotations

import ctypes
import ctypes.util
from functools import cache

M_TRIM_THRESHOLD = -1  # glibc's mallopt parameters (malloc.h)
M_MMAP_THRESHOLD = -3
KEEP_BYTES = 1 << 30  # blocks up to 1 GiB come from the heap and go back to it
DEFAULT_BYTES = 128 * 1024  # glibc's initial thresholds


@cache
def _glibc() -> ctypes.CDLL | None:
    """The process's C library if it is glibc (it has ``mallopt`` and ``malloc_trim``)."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.gnu_get_libc_version  # noqa: B018 - only glibc has it
        libc.mallopt, libc.malloc_trim  # noqa: B018
    except (OSError, AttributeError):
        return None
    return libc


def keep_freed_memory(keep: bool = True) -> bool:
    """Keep freed blocks (up to 1 GiB each) in the heap for the next arrays, or, with
    ``keep=False``, give freed memory back to the system and restore the default
    thresholds (128 KiB; glibc's growing mmap threshold stays off).

    Parameters
    ----------
    keep : bool
        Keep freed memory (``True``) or release it (``False``).

    Returns
    -------
    bool
        Whether the allocator was changed (``False`` where the C library is not glibc).

    Examples
    --------
    >>> changed = keep_freed_memory()
    >>> keep_freed_memory(False) == changed
    True
    """
    libc = _glibc()
    if libc is None:
        return False
    size = KEEP_BYTES if keep else DEFAULT_BYTES
    done = bool(libc.mallopt(M_MMAP_THRESHOLD, size)) and bool(
        libc.mallopt(M_TRIM_THRESHOLD, size))
    if not keep:
        libc.malloc_trim(0)
    return done


def row_bands(height: int) -> range:
    """First rows of the bands of an image worked a band at a time: an eighth of the image
    (at least 64 rows), so that a band's temporaries take an eighth of a whole image's, in
    few kernel calls (the stair phase's cosine and sine here, for example: a byte per pixel
    rather than eight).

    Parameters
    ----------
    height : int
        Rows of the image.

    Returns
    -------
    range
        The bands' first rows; its ``step`` is the band height.

    Examples
    --------
    >>> list(row_bands(1000)), list(row_bands(100))
    ([0, 125, 250, 375, 500, 625, 750, 875], [0, 64])
    """
    return range(0, height, max(64, -(-height // 8)))
