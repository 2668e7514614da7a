"""Errors and warnings that point at a place in an input file.

Every user-facing problem is an `NcppError` carrying file, line and column so
that the CLI can print `file:line:col: message` and exit non-zero without a
traceback.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import TextIO


@dataclass(frozen=True, slots=True)
class Location:
    file: str = "<stdin>"
    line: int | None = None
    col: int | None = None

    def __str__(self) -> str:
        parts = [self.file]
        if self.line is not None:
            parts.append(str(self.line))
            if self.col is not None:
                parts.append(str(self.col))
        return ":".join(parts)


class NcppError(Exception):
    """A problem with the user's input; printed as `file:line:col: message`."""

    def __init__(self, message: str, where: Location | None = None):
        super().__init__(message)
        self.message = message
        self.where = where or Location()

    def __str__(self) -> str:
        return f"{self.where}: {self.message}"

    def __reduce__(self):  # pickled with its location (it may come from a worker process)
        return (type(self), (self.message, self.where))


class Warnings:
    """Collects and prints warnings; in strict mode a warning is an error."""

    def __init__(self, strict: bool = False, stream: TextIO | None = None):
        self.strict = strict
        self.stream = stream if stream is not None else sys.stderr
        self.count = 0

    def warn(self, message: str, where: Location) -> None:
        if self.strict:
            raise NcppError(f"{message} (refused in strict mode)", where)
        self.count += 1
        print(f"{where}: warning: {message}", file=self.stream)
