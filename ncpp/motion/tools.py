"""The control's tool table: where each tool's tip is, as G43 applies it.

A program that says `G43 H1` (or `T1 M6` and `G43`) moves with the tool tip
as its controlled point: the control adds the tool's offset from its tool
table to every machine position.  The program does not say that offset, so
ncpp must be told it to know where the machine really is (and so which
errors it has there).

LinuxCNC's tool table, one tool per line (`tool.tbl`):

    T1 P1 Z+50.000 D6.000 ;6 mm end mill
    T2 P2 X0.100 Z-1.500 D3.000

T is the tool number, P its pocket, X Y Z A B C U V W its offsets, D I J Q
lathe and cutter data (not used here); a `;` starts the comment.  Values are
in the machine's units ([TRAJ]LINEAR_UNITS).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

from ncpp.errors import Location, NcppError

OFFSET_LETTERS = "XYZABCUVW"  # a tool's offsets, in the interpreter's axis order
_LINEAR = frozenset("XYZUVW")  # the offsets in length units (A B C are degrees)
_OTHER_LETTERS = frozenset("PDIJQ")  # pocket, diameter, lathe angles and orientation
_WORD = re.compile(r"\S+")


@dataclass(frozen=True)
class ToolTable:
    """Per tool number, its offsets X Y Z A B C U V W (mm and degrees)."""

    offsets: Mapping[int, tuple[float, ...]] = field(default_factory=dict, hash=False)
    source: str = "<tool table>"

    @classmethod
    def from_file(cls, path: str | Path, unit_mm: float = 1.0) -> "ToolTable":
        """LinuxCNC's tool table, its lengths in the machine's units (`unit_mm` mm each)."""
        try:
            text = Path(path).read_text(encoding="latin-1")
        except OSError as err:
            raise NcppError(f"cannot read the tool table: {err.strerror}", Location(str(path))) from None
        return cls(read_tool_lines(text.splitlines(), str(path), unit_mm), str(path))

    def offset(self, number: int) -> tuple[float, ...] | None:
        """Tool `number`'s offsets (tool 0, no tool: all zero), None when the table has no such tool."""
        if number == 0:
            return (0.0,) * len(OFFSET_LETTERS)
        return self.offsets.get(number)


def read_tool_lines(lines: list[str], file: str, unit_mm: float) -> dict[int, tuple[float, ...]]:
    tools: dict[int, tuple[float, ...]] = {}
    for n, line in enumerate(lines, 1):
        data = line.split(";", 1)[0]
        offsets = [0.0] * len(OFFSET_LETTERS)
        number = None
        for word in _WORD.finditer(data):
            letter, value = word.group()[0].upper(), word.group()[1:]
            where = Location(file, n, word.start() + 1)
            if letter == "T":
                number = _integer(value, where)
            elif letter in OFFSET_LETTERS:
                scale = unit_mm if letter in _LINEAR else 1.0
                offsets[OFFSET_LETTERS.index(letter)] = _number(value, where) * scale
            elif letter in _OTHER_LETTERS:
                _number(value, where)
            else:
                raise NcppError(f"unknown tool table word {word.group()!r}", where)
        if number is None:
            if data.strip():
                raise NcppError("tool table line without a T word", Location(file, n, 1))
            continue
        if number in tools:
            raise NcppError(f"tool {number} is listed twice", Location(file, n, 1))
        tools[number] = tuple(offsets)
    return tools


def _number(text: str, where: Location) -> float:
    try:
        return float(text)
    except ValueError:
        raise NcppError(f"expected a number, got {text!r}", where) from None


def _integer(text: str, where: Location) -> int:
    value = _number(text, where)
    if value != int(value) or value < 0:
        raise NcppError(f"a tool number is a whole number, got {text!r}", where)
    return int(value)
