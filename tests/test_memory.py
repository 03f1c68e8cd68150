"""Keeping freed memory: a freed frame-sized array's pages serve the next one."""

import json
import subprocess
import sys

import pytest

# Run in a fresh process: in the test process, earlier tests that kept freed memory (the
# command line's, in-process) can leave a free block of the size in the heap, which serves
# the "given back" array too (measured: 0 faults after the whole suite, on main as well).
_MEASURE = """
import json, resource
import numpy as np
from bistair.core.memory import keep_freed_memory


def faults_of_second_array(size):
    first = np.ones(size, np.uint8)
    del first
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    second = np.ones(size, np.uint8)
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
    del second
    return faults


size = 64 << 20  # above glibc's largest default mmap threshold (32 MiB)
if not keep_freed_memory(True):
    print(json.dumps(None))
else:
    try:
        kept = faults_of_second_array(size)
    finally:
        assert keep_freed_memory(False)
    print(json.dumps([kept, faults_of_second_array(size), size]))
"""


def test_freed_memory_is_reused_and_given_back():
    """Minor page faults while a second array is filled after a first one of the same size
    was filled and freed: kept, (almost) none; given back, the array's pages."""
    out = subprocess.run([sys.executable, "-c", _MEASURE], capture_output=True, text=True,
                         check=True).stdout
    measured = json.loads(out.strip().splitlines()[-1])
    if measured is None:
        pytest.skip("the C library is not glibc")
    kept, released, size = measured
    # given back: mmapped and faulted in afresh, page by page (4 KiB, or 2 MiB where NumPy
    # asks for transparent huge pages); kept: reused, (almost) nothing is faulted in
    assert released >= size // (2 << 20) // 2
    assert kept <= released // 8

