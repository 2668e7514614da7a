"""A progress line on stderr for long programs, only when stderr is a terminal
(a pipeline's log stays clean).  No total is known while streaming, so it
shows lines read and the rate."""

from __future__ import annotations

import sys
import time
from typing import TextIO


class ProgressLine:
    def __init__(self, label: str, stream: TextIO):
        self.label = label
        self.stream = stream
        self.start = time.monotonic()
        self.shown = False

    def __call__(self, lines: int) -> None:
        elapsed = max(time.monotonic() - self.start, 1e-9)
        self.stream.write(f"\rncpp {self.label}: {lines:,} lines, {lines / elapsed:,.0f} lines/s ")
        self.stream.flush()
        self.shown = True

    def done(self) -> None:
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()


def progress_printer(label: str, stream: TextIO | None = None) -> ProgressLine | None:
    """A progress callback when `stream` (stderr) is a terminal, else None."""
    stream = stream if stream is not None else sys.stderr
    return ProgressLine(label, stream) if stream.isatty() else None
