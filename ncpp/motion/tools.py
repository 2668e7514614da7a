"""The control's tool table: where each tool's tip is, as G43 (Heidenhain's TOOL CALL, Sinumerik's D) applies it.

A program that says `G43 H1` (or `T1 M6` and `G43`) moves with the tool tip
as its controlled point: the control adds the tool's offset from its tool
table to every machine position.  The program does not say that offset, so
ncpp must be told it to know where the machine really is (and so which
errors it has there).

LinuxCNC's tool table, one tool per line (`tool.tbl`):

    T1 P1 Z+50.000 D6.000 ;6 mm end mill
    T2 P2 X0.100 Z-1.500 D3.000

T is the tool number, P its pocket, X Y Z A B C U V W its offsets, D its
diameter (cutter compensation G41/G42 checks moves against its radius), Q a
lathe tool's orientation (G41/G42 in G18 with one of 1-8 is left as programmed),
I J a lathe tool's front and back angles (degrees; a program reads them as
#5411 #5412); a `;` starts the comment.  Values are in the machine's units
([TRAJ]LINEAR_UNITS).

Heidenhain's tool table (`TOOL.T`), fixed columns under a header line, its
units in the first line:

    BEGIN TOOL    .T       MM
    T    NAME             L          R          DL      DR      TL RT
    1    D10_ENDMILL      +150,000   +5,000     -0,020  +0,000
    [END]

A tool's length is L + DL along the tool axis (the axis TOOL CALL names): its
one cutting edge's length 1, as Sinumerik's below; its radius is R + DR (radius
compensation RL/RR offsets by it); numbers may have a decimal comma.

Sinumerik's tool offsets, as the control saves them (`_N_TO_INI`), per tool T
and cutting edge D:

    $TC_TP2[1]="D10_ENDMILL"
    $TC_DP1[1,1]=120
    $TC_DP3[1,1]=150.0   ; length 1 (geometry), + $TC_DP12 (wear) + $TC_DP21 (adapter)
    $TC_DP4[1,1]=0.0     ; length 2, + $TC_DP13 + $TC_DP22
    $TC_DP5[1,1]=0.0     ; length 3, + $TC_DP14 + $TC_DP23
    $TC_DP6[1,1]=5.0     ; radius (G41/G42 offset by it), + $TC_DP15 (wear)

Its lengths are in the machine's units; which axis each acts along depends on
the plane (G17: length 1 along Z, 2 along Y, 3 along X), so they are kept per
edge, not as axis offsets.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ncpp.errors import Location, NcppError, Warnings, quoted
from ncpp.fileio import read_small

OFFSET_LETTERS = "XYZABCUVW"  # a tool's offsets, in the interpreter's axis order
_LINEAR = frozenset("XYZUVW")  # the offsets in length units (A B C are degrees)
_OTHER_LETTERS = frozenset("P")  # the pocket
_ANGLE_LETTERS = "IJ"  # a lathe tool's front and back angles
_WORD = re.compile(r"\S+")


@dataclass(frozen=True)
class ToolTable:
    """A control's tool data: LinuxCNC's per tool number offsets X Y Z A B C U V W along the
    machine's axes (mm and degrees, as G43 adds them), or Heidenhain's and Sinumerik's per
    tool and cutting edge lengths 1-3 relative to the tool axis (length 1 along it, mm: the
    control turns them onto the machine's axes), and the tools' names."""

    offsets: Mapping[int, tuple[float, ...]] = field(default_factory=dict, hash=False)
    source: str = "<tool table>"
    names: Mapping[str, float] = field(
        default_factory=dict, hash=False
    )  # name -> tool number (the first listed)
    edges: Mapping[tuple[float, int], tuple[float, float, float]] = field(
        default_factory=dict, hash=False
    )  # (T, D) -> lengths 1-3
    diameters: Mapping[int, float] = field(
        default_factory=dict, hash=False
    )  # LinuxCNC's D per tool number, mm
    orientations: Mapping[int, int] = field(
        default_factory=dict, hash=False
    )  # LinuxCNC's Q per tool number: a lathe tool's orientation (1-9)
    radii: Mapping[tuple[float, int], float] = field(
        default_factory=dict, hash=False
    )  # (T, D) -> Heidenhain's R + DR, Sinumerik's radius + wear radius, mm (where the table gives one)
    angles: Mapping[int, tuple[float, float]] = field(
        default_factory=dict, hash=False
    )  # LinuxCNC's I J per tool number: a lathe tool's front and back angles, degrees

    @classmethod
    def from_file(cls, path: str | Path, unit_mm: float = 1.0) -> ToolTable:
        """LinuxCNC's tool table or Sinumerik's tool offsets, their lengths in the machine's
        units (`unit_mm` mm each), or Heidenhain's TOOL.T (its units in its first line)."""
        try:
            text = read_small(path, "a tool table").decode("latin-1")
        except OSError as err:
            raise NcppError(f"cannot read the tool table: {err.strerror}", Location(str(path))) from None
        lines = text.splitlines()
        if "$TC_DP" in text.upper():
            edges, names, radii = read_to_ini(lines, str(path), unit_mm)
            return cls({}, str(path), names, edges, radii=radii)
        if lines and lines[0].lstrip().upper().startswith("BEGIN"):
            edges, names, radii = read_tool_t(lines, str(path))
            return cls({}, str(path), names, edges, radii=radii)
        offsets, diameters, orientations, angles = read_tool_lines(lines, str(path), unit_mm)
        return cls(offsets, str(path), diameters=diameters, orientations=orientations, angles=angles)

    def offset(self, number: int) -> tuple[float, ...] | None:
        """Tool `number`'s offsets (tool 0, no tool: all zero), None when the table has no such tool."""
        if number == 0:
            return (0.0,) * len(OFFSET_LETTERS)
        return self.offsets.get(number)

    def diameter(self, number: int) -> float:
        """Tool `number`'s diameter in mm (0: no tool, or none in the table)."""
        return self.diameters.get(number, 0.0)

    def orientation(self, number: int) -> int:
        """Tool `number`'s lathe tool orientation (0: none, or no such tool)."""
        return self.orientations.get(number, 0)

    def angle(self, number: int, letter: str) -> float:
        """Tool `number`'s front (I) or back (J) angle in degrees (0: none, or no such tool)."""
        return self.angles.get(number, (0.0, 0.0))[_ANGLE_LETTERS.index(letter)]


class UntoldLengths:
    """The one warning of a program run placed without a tool table (`armed`), where the
    program first applies a tool length: ncpp compensates it at length 0."""

    def __init__(self, armed: bool = False, warnings: Warnings | None = None):
        self.armed, self.warnings = armed, warnings

    def __call__(self, what: str, table: str, where: Location) -> None:
        """`what` (G43, TOOL CALL ...) applies a length from `table`, which ncpp is not told."""
        if self.armed and self.warnings is not None:
            self.armed = False
            self.warnings.warn(
                f"{what} applies a tool length from the control's tool table, which ncpp is not told: "
                f"compensated with tool length 0 (give --tool-table {table})",
                where,
            )


def read_tool_lines(
    lines: list[str], file: str, unit_mm: float
) -> tuple[dict[int, tuple[float, ...]], dict[int, float], dict[int, int], dict[int, tuple[float, float]]]:
    """Per tool number its offsets (mm and degrees), and the diameters (mm), lathe tool
    orientations (Q) and front and back angles (I J, degrees) the table gives."""
    tools: dict[int, tuple[float, ...]] = {}
    diameters: dict[int, float] = {}
    orientations: dict[int, int] = {}
    angles: dict[int, tuple[float, float]] = {}
    for n, line in enumerate(lines, 1):
        data = line.split(";", 1)[0]
        offsets = [0.0] * len(OFFSET_LETTERS)
        number, diameter, orientation = None, 0.0, 0
        angle = [0.0, 0.0]
        for word in _WORD.finditer(data):
            letter, value = word.group()[0].upper(), word.group()[1:]
            where = Location(file, n, word.start() + 1)
            if letter == "T":
                number = _integer(value, where)
            elif letter in OFFSET_LETTERS:
                scale = unit_mm if letter in _LINEAR else 1.0
                offsets[OFFSET_LETTERS.index(letter)] = _number(value, where) * scale
            elif letter == "D":
                diameter = _number(value, where) * unit_mm
            elif letter == "Q":
                orientation = round(_number(value, where))
            elif letter in _ANGLE_LETTERS:
                angle[_ANGLE_LETTERS.index(letter)] = _number(value, where)
            elif letter in _OTHER_LETTERS:
                _number(value, where)
            else:
                raise NcppError(_unknown_word(word.group()), where)
        if number is None:
            if data.strip():
                raise NcppError("tool table line without a T word", Location(file, n, 1))
            continue
        if number in tools:
            raise NcppError(f"tool {number} is listed twice", Location(file, n, 1))
        tools[number] = tuple(offsets)
        if diameter:
            diameters[number] = diameter
        if orientation:
            orientations[number] = orientation
        if any(angle):
            angles[number] = (angle[0], angle[1])
    return tools, diameters, orientations, angles


def _number(text: str, where: Location) -> float:
    try:
        value = float(text)
    except ValueError:
        raise NcppError(f"expected a number, got {quoted(text, _QUOTED)}", where) from None
    if not math.isfinite(value):
        raise NcppError(f"expected a finite number, got {quoted(text, _QUOTED)}", where)
    return value


def _integer(text: str, where: Location) -> int:
    value = _number(text, where)
    if value != int(value) or value < 0:
        raise NcppError(f"a tool number is a whole number, got {quoted(text, _QUOTED)}", where)
    return int(value)


def read_tool_t(
    lines: list[str], file: str
) -> tuple[
    dict[tuple[float, int], tuple[float, float, float]], dict[str, float], dict[tuple[float, int], float]
]:
    """Heidenhain's TOOL.T: per (tool, its one edge) its lengths (L + DL, 0, 0) in mm, the names,
    and per (tool, edge) its radius R + DR in mm (a table without an R column gives none)."""
    unit_mm = 25.4 if "INCH" in lines[0].upper().split() else 1.0
    if len(lines) < 2:
        raise NcppError("TOOL.T without its column header", Location(file, 1, 1))
    columns = _columns(lines[1], file)
    tools: dict[tuple[float, int], tuple[float, float, float]] = {}
    names: dict[str, float] = {}
    radii: dict[tuple[float, int], float] = {}
    for n, line in enumerate(lines[2:], 3):
        if line.strip().upper().startswith("[END]"):
            break
        if not line.strip():
            continue
        decimal = lambda name: _decimal(*_field(line, columns, name), Location(file, n))  # noqa: E731, B023  a column's number, read in this iteration
        text, col = _field(line, columns, "T")
        number = decimal("T")
        if number < 0:
            raise NcppError(
                f"a tool number is not negative, got {quoted(text, _QUOTED)}", Location(file, n, col)
            )
        if (number, 1) in tools:
            raise NcppError(f"tool {text} is listed twice", Location(file, n, col))
        tools[number, 1] = ((decimal("L") + decimal("DL")) * unit_mm, 0.0, 0.0)
        if "R" in columns:
            radii[number, 1] = (decimal("R") + decimal("DR")) * unit_mm
        name = _field(line, columns, "NAME")[0]
        if name:
            names.setdefault(name, number)
    return tools, names, radii


def _columns(header: str, file: str) -> dict[str, tuple[int, int | None]]:
    """Each column's (start, end) in the lines: from its name to the next column's name
    (None: the last column runs to the end of the line)."""
    found = list(_WORD.finditer(header))
    columns = {
        m.group().upper(): (m.start(), found[k + 1].start() if k + 1 < len(found) else None)
        for k, m in enumerate(found)
    }
    for needed in ("T", "L"):
        if needed not in columns:
            raise NcppError(f"TOOL.T header without a {needed} column", Location(file, 2, 1))
    return columns


def _decimal(text: str, col: int, line: Location) -> float:
    """A TOOL.T number (a decimal comma or point; an empty field is 0) at column `col` of `line`."""
    return _number(text.replace(",", ".") or "0", Location(line.file, line.line, col))


def _field(line: str, columns: dict[str, tuple[int, int | None]], name: str) -> tuple[str, int]:
    """The stripped text of a column in a line ('' where the table has no such column), and its 1-based column."""
    if name not in columns:
        return "", 1
    start, end = columns[name]
    return line[start:end].strip(), start + 1


_TC_DP = re.compile(r"\$TC_DP(\d+)\[\s*(\d+)\s*,\s*(\d+)\s*\]\s*=\s*(\S*)", re.IGNORECASE)
_TC_TP2 = re.compile(r"\$TC_TP2\[\s*(\d+)\s*\]\s*=\s*\"([^\"]*)\"", re.IGNORECASE)
# lengths 1-3 of an edge: geometry, wear and adapter parameters, added
_LENGTH_PARAMETERS = {3: 0, 12: 0, 21: 0, 4: 1, 13: 1, 22: 1, 5: 2, 14: 2, 23: 2}
# an edge's radius: geometry and wear, added (840D sl Programming Manual Job Planning, "Tool
# parameters": "$TC_DP6 + $TC_DP15 for the radius")
_RADIUS_PARAMETERS = frozenset((6, 15))


def read_to_ini(
    lines: list[str], file: str, unit_mm: float
) -> tuple[
    dict[tuple[float, int], tuple[float, float, float]], dict[str, float], dict[tuple[float, int], float]
]:
    """Sinumerik's tool offsets: per (T, D) its lengths 1-3 in mm, the tools' names, and per
    (T, D) its radius in mm (where the offsets give $TC_DP6 or $TC_DP15)."""
    lengths: dict[tuple[float, int], list[float]] = {}
    names: dict[str, float] = {}
    radii: dict[tuple[float, int], float] = {}
    for n, line in enumerate(lines, 1):
        data = line.split(";", 1)[0]
        if (named := _TC_TP2.search(data)) is not None:
            names.setdefault(named.group(2), float(named.group(1)))
            continue
        found = _TC_DP.search(data)
        if found is None:
            continue
        parameter, tool, edge = (int(found.group(k)) for k in (1, 2, 3))
        value = _number(found.group(4), Location(file, n, found.start(4) + 1))
        edge_lengths = lengths.setdefault((float(tool), edge), [0.0, 0.0, 0.0])
        if parameter in _LENGTH_PARAMETERS:
            edge_lengths[_LENGTH_PARAMETERS[parameter]] += value * unit_mm
        elif parameter in _RADIUS_PARAMETERS:
            radii[float(tool), edge] = radii.get((float(tool), edge), 0.0) + value * unit_mm
    return {key: (a, b, c) for key, (a, b, c) in lengths.items()}, names, radii


_QUOTED = 16  # the longest text of a table a message quotes
_WORD_SHAPED = re.compile(r"[A-Za-z][-+0-9.,]{0,15}")


def _unknown_word(text: str) -> str:
    """The message for a word a tool table does not have, quoting it only when it is shaped
    as a tool-table word (a letter and a number): another file's text is never echoed."""
    if _WORD_SHAPED.fullmatch(text):
        return f"unknown tool table word {text!r}"
    return "not a tool table word (a letter and a number, as `T1 Z+10`): is this a tool table?"
