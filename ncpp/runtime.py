"""Process-wide settings for compensation's runs: the C heap and BLAS's threads.

Nothing here imports numpy: `one_blas_thread` must act before numpy is loaded.

The heap (glibc).  Compensation makes numpy arrays of 0.1-2 MB many times a
second (a chunk's samples and rows, and their temporaries).  By default glibc
serves arrays over its mmap threshold with fresh pages from the kernel, and hands
memory at the top of the heap back to the kernel once more than its trim
threshold is free; either way such an array costs page faults and the zeroing of
its pages again and again.  Higher thresholds keep freed memory in the heap for
the next chunk, at the same peak size.  The setting is process-wide and stays
(glibc has no way back to its adjusting thresholds): what it costs a host process
(FreeCAD running the post) is freed memory kept for reuse; the peak, which is what
the host sees, stays flat in program length.

BLAS.  numpy's OpenBLAS starts a thread per core that spins after the import,
taking CPU from the other processes of `compensate --jobs`; ncpp's arrays are too
small to share out among threads.
"""

from __future__ import annotations

import ctypes
import os
import sys
from collections.abc import MutableMapping
from typing import TypeVar

MMAP_THRESHOLD = 16 << 20  # bytes: arrays up to this size come from the heap
TRIM_THRESHOLD = 64 << 20  # bytes: free memory at the heap's top kept for reuse
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # mallopt's parameters (malloc.h)

_kept: bool | None = None  # the outcome, once asked


def keep_freed_memory() -> bool:
    """Raise glibc's mmap and trim thresholds (once per process); False where the C
    library is not glibc or refuses, and nothing changes."""
    global _kept
    if _kept is None:
        _kept = _raise_thresholds()
    return _kept


def _raise_thresholds() -> bool:
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None)
    except OSError:
        return False
    if not hasattr(libc, "gnu_get_libc_version") or not hasattr(
        libc, "mallopt"
    ):  # not glibc (musl's mallopt does nothing)
        return False
    mallopt = libc.mallopt
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    # both: setting either ends glibc's adjusting of both, and one alone is worse than
    # none (the mmap threshold alone: twice the faults, trimming at 128 kB)
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and bool(
        mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD)
    )


Environ = TypeVar("Environ", bound=MutableMapping[str, str])


def one_blas_thread(environ: Environ = os.environ) -> Environ:  # type: ignore[assignment]
    """`environ` set for one OpenBLAS thread, unless it names a count already (the
    user's choice); numpy reads it when it is imported.  Returns `environ`."""
    environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    return environ


class Terminated(BaseException):
    """A SIGTERM, raised where the process is, so that every `with` cleans up as on Ctrl-C:
    temporary files beside the output and spooled input are removed."""

    EXIT_STATUS = 128 + 15  # (a shell's status for a process SIGTERM ended)


def terminate_as_interrupt() -> None:
    """Have SIGTERM raise `Terminated` (once: a second one during the clean-up is ignored);
    only a process's main thread can (`main` called from another leaves the handler as it is)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return

    def raise_terminated(signum, frame) -> None:
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        raise Terminated()

    signal.signal(signal.SIGTERM, raise_terminated)


_PR_SET_PDEATHSIG = 1  # prctl's option (linux/prctl.h)


def die_with_parent(parent: int) -> None:
    """End this process (SIGKILL) when process `parent`, which started it, ends: a worker of
    `compensate --jobs` must not go on writing programs for a run that was killed.  Linux only;
    elsewhere nothing changes."""
    import signal

    if not sys.platform.startswith("linux"):
        return
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return
    prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    if os.getppid() != parent:  # (it ended before the request was made)
        os.kill(os.getpid(), signal.SIGKILL)
