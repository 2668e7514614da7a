"""ncpp.runtime: numpy's temporaries reuse the heap instead of fresh pages (glibc)."""

import os
import subprocess
import sys

import pytest

from ncpp.runtime import keep_freed_memory

# Arrays of growing sizes, each freed before the next (a chunk's temporaries): by
# default glibc serves each from fresh pages, each page a fault.
FAULTS = """
import resource, sys
import numpy as np
from ncpp.runtime import keep_freed_memory
kept = keep_freed_memory() if sys.argv[1] == "kept" else None
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for k in range(40):
    np.ones((1 << 20) // 8 + k * 8192)  # 1 MB and growing, every page written
print(kept, resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def _faults(mode: str) -> tuple[str, int]:
    out = subprocess.run(
        [sys.executable, "-c", FAULTS, mode], capture_output=True, text=True, check=True
    ).stdout.split()
    return out[0], int(out[1])


@pytest.mark.skipif(not keep_freed_memory(), reason="the C library is not glibc")
def test_freed_memory_is_reused_not_faulted_in_again():
    kept, with_kept = _faults("kept")
    _, default = _faults("default")
    assert kept == "True"
    assert default > 40 * 200  # each array's 256+ pages faulted in
    assert with_kept < default / 4


def test_one_blas_thread_unless_the_user_chose():
    from ncpp.runtime import one_blas_thread

    assert one_blas_thread({})["OPENBLAS_NUM_THREADS"] == "1"
    assert one_blas_thread({"OPENBLAS_NUM_THREADS": "4"})["OPENBLAS_NUM_THREADS"] == "4"


CLI_THREADS = """
import os
from ncpp.cli import main
try:
    main(["--help"])  # builds the parser: the commands import numpy
except SystemExit:
    pass
import numpy
print(len(os.listdir("/proc/self/task")))
"""


@pytest.mark.skipif(
    not os.path.isdir("/proc/self/task") or (os.cpu_count() or 1) < 2, reason="threads are not counted here"
)
def test_the_cli_starts_numpy_with_one_blas_thread():
    """`ncpp` sets the count before its commands import numpy: OpenBLAS starts no pool."""
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    out = subprocess.run(
        [sys.executable, "-c", CLI_THREADS], capture_output=True, text=True, check=True, env=env
    ).stdout
    assert out.split()[-1] == "1"
