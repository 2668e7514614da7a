"""CPU instructions counted by the kernel (Linux `perf_event_open`), for figures the
machine's load does not move: on this shared machine a run's time swings by a third
from one minute to the next, and its cycles with it; its instructions repeat to 0.1%.

`Instructions()` counts this process's user-space instructions from its creation on;
with `children=True` also those of the processes it starts afterwards (added when they
exit).  Where the kernel refuses (another OS, `perf_event_paranoid` 3), `counters()`
gives None and the benchmark reports time alone."""

from __future__ import annotations

import ctypes
import os
import struct
import sys

_PERF_EVENT_OPEN = {"x86_64": 298, "aarch64": 241}  # the syscall's number
_HARDWARE, _INSTRUCTIONS = 0, 1
_INHERIT, _EXCLUDE_KERNEL, _EXCLUDE_HV = 1 << 1, 1 << 5, 1 << 6


class _Attr(
    ctypes.Structure
):  # struct perf_event_attr, as far as it is used (PERF_ATTR_SIZE_VER0 = 64 bytes)
    _fields_ = [("type", ctypes.c_uint32), ("size", ctypes.c_uint32), ("config", ctypes.c_uint64), ("sample_period", ctypes.c_uint64),
                ("sample_type", ctypes.c_uint64), ("read_format", ctypes.c_uint64), ("flags", ctypes.c_uint64),
                ("wakeup_events", ctypes.c_uint32), ("bp_type", ctypes.c_uint32), ("config1", ctypes.c_uint64)]  # fmt: skip


class Instructions:
    def __init__(self, children: bool = False):
        number = _PERF_EVENT_OPEN.get(os.uname().machine) if sys.platform == "linux" else None
        if number is None:
            raise OSError("perf_event_open: not on this platform")
        attr = _Attr(type=_HARDWARE, size=ctypes.sizeof(_Attr), config=_INSTRUCTIONS,
                     flags=_EXCLUDE_KERNEL | _EXCLUDE_HV | (_INHERIT if children else 0))  # fmt: skip
        libc = ctypes.CDLL(None, use_errno=True)
        fd = libc.syscall(
            number, ctypes.byref(attr), 0, -1, -1, 0
        )  # this process, any CPU, no group, no flags
        if fd < 0:
            raise OSError(ctypes.get_errno(), "perf_event_open")
        self.fd = fd

    def read(self) -> int:
        return struct.unpack("q", os.read(self.fd, 8))[0]

    def close(self) -> None:
        os.close(self.fd)


def counters() -> tuple[Instructions, Instructions] | None:
    """(this process's instructions, with the processes it starts from now on), or None."""
    try:
        return Instructions(), Instructions(children=True)
    except OSError:
        return None
