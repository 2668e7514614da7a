"""ncpp.heap: numpy's temporaries reuse the heap instead of fresh pages (glibc)."""

import subprocess
import sys

import pytest

from ncpp.heap import keep_freed_memory

# Arrays of growing sizes, each freed before the next (a chunk's temporaries): by
# default glibc serves each from fresh pages, each page a fault.
FAULTS = """
import resource, sys
import numpy as np
from ncpp.heap import keep_freed_memory
kept = keep_freed_memory() if sys.argv[1] == "kept" else None
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for k in range(40):
    np.ones((1 << 20) // 8 + k * 8192)  # 1 MB and growing, every page written
print(kept, resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def _faults(mode: str) -> tuple[str, int]:
    out = subprocess.run([sys.executable, "-c", FAULTS, mode], capture_output=True, text=True, check=True).stdout.split()
    return out[0], int(out[1])


@pytest.mark.skipif(not keep_freed_memory(), reason="the C library is not glibc")
def test_freed_memory_is_reused_not_faulted_in_again():
    kept, with_kept = _faults("kept")
    _, default = _faults("default")
    assert kept == "True"
    assert default > 40 * 200  # each array's 256+ pages faulted in
    assert with_kept < default / 4


def test_asking_again_changes_nothing():
    assert keep_freed_memory() == keep_freed_memory()
