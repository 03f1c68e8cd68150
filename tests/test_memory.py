"""Keeping freed memory: a freed frame-sized array's pages serve the next one."""

import resource

import numpy as np
import pytest

from bistair.core.memory import keep_freed_memory


def _faults_of_second_array(size: int) -> int:
    """Minor page faults while a second array of ``size`` bytes is filled after a first
    one of the same size was filled and freed."""
    first = np.ones(size, np.uint8)
    del first
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    second = np.ones(size, np.uint8)
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
    del second
    return faults


def test_freed_memory_is_reused_and_given_back():
    size = 64 << 20  # above glibc's largest default mmap threshold (32 MiB)
    if not keep_freed_memory(True):
        pytest.skip("the C library is not glibc")
    try:
        kept = _faults_of_second_array(size)
    finally:
        assert keep_freed_memory(False)
    released = _faults_of_second_array(size)
    # given back: mmapped and faulted in afresh, page by page (4 KiB, or 2 MiB where NumPy
    # asks for transparent huge pages); kept: reused, (almost) nothing is faulted in
    assert released >= size // (2 << 20) // 2
    assert kept <= released // 8
