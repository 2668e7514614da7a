"""Errors and warnings that point at a place in an input file.

Every user-facing problem is an `NcppError` carrying file, line and column so
that the CLI can print `file:line:col: message` and exit non-zero without a
traceback.
"""

from __future__ import annotations

import heapq
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from _typeshed import SupportsWrite

    from ncpp.program.blocks import Block


_CONTROL = {c: f"\\x{c:02x}" for c in [*range(0x20), *range(0x7F, 0xA0)]}


def printable(text: str) -> str:
    """`text` with its control characters escaped (`\\x1b`): a message quoting a name from a
    file sends a terminal no escape sequence."""
    return text.translate(_CONTROL)


def quoted(text: str, width: int = 40) -> str:
    """A file's text for a message: quoted, cut short, its control characters escaped (a
    damaged or wrong file can hold a line of megabytes, or another file's secrets)."""
    shown = repr(text if len(text) <= width else text[: width - 3] + "...")
    return printable(shown)


@dataclass(frozen=True, slots=True)
class Location:
    file: str = "<stdin>"
    line: int | None = None
    col: int | None = None
    # A pass's fault, whose numeric work knows the line but not its text: the letter of the word it
    # is at (None: the block), until the pass finds the column (`NcppError.locate`)
    word: str | None = None

    def __str__(self) -> str:
        parts = [self.file]
        if self.line is not None:  # a line's problem whose column nobody found is at its start
            parts += [str(self.line), str(self.col or 1)]
        return printable(":".join(parts))


class NcppError(Exception):
    """A problem with the user's input; printed as `file:line:col: message`."""

    def __init__(self, message: str, where: Location | None = None):
        super().__init__(message)
        self.message = message
        self.where = where or Location()

    def locate(self, blocks: Iterable[Block]) -> None:
        """Give an error that names its line but no column (a pass's, a path's) the column of
        its word in the block of that line among `blocks`: that of the word its location
        names, else 1 (the block)."""
        from ncpp.program.blocks import Word

        where = self.where
        if where.col is not None or where.line is None:
            return
        block = next((b for b in blocks if b.line == where.line), None)
        if block is None:
            return
        word = next((item for item in block.items if type(item) is Word and item.letter == where.word), None)
        self.where = replace(where, col=1 if word is None else word.start + 1, word=None)

    def __str__(self) -> str:
        return f"{self.where}: {printable(self.message)}"

    def __reduce__(self):  # pickled with its location (it may come from another process: `compensate --jobs`)
        return (type(self), (self.message, self.where))


# Warnings of one text printed before the rest are only counted: a drilling program warns
# at each of its cycle series, hundreds of times, which buries the other warnings on a
# terminal and fills the pipe a LinuxCNC screen reads a line at a time (QtVCP: one a tick).
SHOWN_PER_TEXT = 5
_TEXTS_COUNTED = 1000  # texts whose repeats are counted (memory stays flat in program length)
# warnings held to be printed in line order (`Warnings.in_line_order`) at most: past it the first goes
_HELD_MOST = 1000


class Warnings:
    """Collects and prints warnings; in strict mode a warning is an error.

    The same text is printed SHOWN_PER_TEXT times, the last saying that more are
    counted; `finish` tells how many were not printed and where the last was.
    Subclasses that keep warnings instead override `say`."""

    def __init__(self, strict: bool = False, stream: SupportsWrite[str] | None = None):
        self.strict = strict
        self.stream = stream if stream is not None else sys.stderr
        self.count = 0
        self._times: dict[str, int] = {}  # how often each text was warned
        self._hidden: dict[
            str, tuple[Location, Location]
        ] = {}  # where each text was first and last not printed
        # told every warning (`summary.Summary.heard`)
        self.listeners: list[Callable[[str, Location], None]] = []
        self._held: list[tuple[int, int, str]] | None = None  # (line, order, text): `in_line_order`

    def warn(self, message: str, where: Location) -> None:
        if self.strict:
            raise NcppError(f"{message} (refused in strict mode)", where)
        self.count += 1
        for listener in self.listeners:
            listener(message, where)
        self.say(message, where)

    def say(self, message: str, where: Location) -> None:
        """Print a warning (or count it): what a collector that keeps them replaces."""
        times = self._times.get(message, 0) + 1
        if times > 1 or len(self._times) < _TEXTS_COUNTED:
            self._times[message] = times
        message = printable(message)
        if times < SHOWN_PER_TEXT:
            self._print(f"{where}: warning: {message}", where)
        elif times == SHOWN_PER_TEXT:
            self._print(
                f"{where}: warning: {message} (warned {times} times: more of these are counted, not printed)",
                where,
            )
        else:
            self._hidden[message] = (self._hidden.get(message, (where,))[0], where)

    def _print(self, text: str, where: Location) -> None:
        if self._held is None:
            print(text, file=self.stream)
            return
        heapq.heappush(self._held, (where.line or 0, self.count, text))
        if len(self._held) > _HELD_MOST:  # (memory stays flat: the earliest line goes now)
            print(heapq.heappop(self._held)[2], file=self.stream)

    @contextmanager
    def in_line_order(self) -> Iterator[Callable[[int | None], None]]:
        """Hold the warnings printed meanwhile and print them in the order of their lines: the
        stages of a run warn as they meet a line, and an early one (the interpreter, which reads
        ahead) meets a later line before a late one (the passes, the writer) is done with an earlier
        line.  The function yielded prints those up to a line the run is past (None: all); the
        rest go at the end, and past _HELD_MOST held the earliest goes at once.  A line a stage
        warns of after the run is past it (a subroutine's, run from a later call) comes out late."""
        self._held = []
        try:
            yield self._release
        finally:
            self._release(None)
            self._held = None

    def _release(self, line: int | None) -> None:
        held = self._held
        while held and (line is None or held[0][0] <= line):
            print(heapq.heappop(held)[2], file=self.stream)

    def finish(self) -> None:
        """At the end of a run: how many warnings of each text were not printed, and where."""
        for message, (first, last) in self._hidden.items():
            hidden = self._times[message] - SHOWN_PER_TEXT
            print(
                f"{last}: warning: {message} ({hidden} not printed, from line {first.line} to this one)",
                file=self.stream,
            )
        self._hidden.clear()


def resolve_warnings(warnings: Warnings | None, strict: bool) -> Warnings:
    """The warnings to report through: strict when asked, whatever was passed."""
    if warnings is None:
        return Warnings(strict=strict)
    if strict and not warnings.strict:
        return Warnings(strict=True, stream=warnings.stream)
    return warnings
