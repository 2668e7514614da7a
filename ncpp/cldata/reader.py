"""APT CL data records, streamed: `read_cldata(stream, file) -> Iterator[Record]`.

A physical line ending in a single `$` continues on the next line (Creo
continues even `$$` comments that way); `$$` starts a comment to the end of
the record.  Each joined record is parsed by grammar/apt.lark.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import TextIO

import lark
from lark import Transformer, v_args

from ncpp.errors import Location, NcppError, quoted
from ncpp.program.parser import lalr_parser

# Majors that the motion module understands or that carry set-up data a
# postprocessor maps to NC words; anything else is a vendor word.
KNOWN = frozenset(
    """PARTNO UNITS MULTAX FROM GOTO RAPID FEDRAT SPINDL LOADTL LOAD CUTTER COOLNT CIRCLE
    INDIRV TLAXIS GOHOME FINI MACHIN PPRINT INSERT REMARK TITLE OPERATOR END STOP OPSTOP
    CYCLE DELAY CUTCOM""".split()
) | {"TOOL PATH"}  # NX CLSF's operation header: a comment

Value = float | str
# Other spellings of a major word, read as the one ncpp knows (SolidWorks CAM writes UNIT/MM)
ALIASES = {"UNIT": "UNITS"}


@dataclass(frozen=True, slots=True)
class Record:
    """One CL record: `major` word (upper case), its arguments, the text it came from.

    `args` holds numbers as float and minor words upper-cased as str;
    `comment` records (`$$ ...`) have major "$$" and the comment text in `text`.
    """

    major: str
    args: tuple[Value, ...]
    text: str  # the record as written, continuation lines joined with "\n"
    line: int  # first physical line, 1-based
    file: str = "<stdin>"

    @property
    def where(self) -> Location:
        return Location(self.file, self.line, 1)

    @property
    def numbers(self) -> tuple[float, ...]:
        return tuple(a for a in self.args if isinstance(a, float))

    @property
    def words(self) -> tuple[str, ...]:
        return tuple(a for a in self.args if isinstance(a, str))

    @property
    def comment(self) -> bool:
        return self.major == "$$"

    @property
    def vendor(self) -> bool:
        """A major word this reader does not model (CYCLE/, CALLSUB/, ...)."""
        return not self.comment and self.major not in KNOWN


@v_args(inline=True)
class _ToRecord(Transformer):
    def start(self, item):
        return item

    def text_record(self, major, text=None):
        name = " ".join(major.upper().split())  # "TOOL  PATH" is TOOL PATH
        return name, (str(text).strip().removeprefix("/").strip(),) if text is not None else ()

    def record(self, name, args=()):
        major = name.upper()
        return ALIASES.get(major, major), tuple(args)

    def args(self, *items):
        return [i for i in items if i is not None]

    def number(self, tok):
        return float(tok)

    def word(self, tok):
        return tok.upper()

    def string(self, tok):
        return str(tok)[1:-1]

    def assignment(self, name, value):
        return f"{name.upper()}={value}"


def _physical_records(lines: Iterable[str]) -> Iterator[tuple[int, list[str]]]:
    """(first line number, [physical lines]) per record, joining `$` continuations."""
    pending: list[str] = []
    first = 0
    for number, raw in enumerate(lines, start=1):
        line = raw.rstrip("\r\n")
        if not pending:
            first = number
        pending.append(line)
        stripped = line.rstrip()
        continued = stripped.endswith("$") and not (stripped.lstrip() == "$$" or stripped.endswith("$$"))
        if not continued:
            yield first, pending
            pending = []
    if pending:
        yield first, pending


def _logical(parts: list[str]) -> str:
    """The record's text with continuation marks removed (comments are kept)."""
    out = []
    for i, part in enumerate(parts):
        s = part.rstrip()
        if i < len(parts) - 1:
            s = s[:-1]
        out.append(s.strip() if i else s)
    return " ".join(out)


def read_cldata(stream: TextIO | Iterable[str], file: str = "<stdin>") -> Iterator[Record]:
    """Typed records of a CL file, one per statement, streamed."""
    parser = lalr_parser("apt")
    to_record = _ToRecord()
    for line, parts in _physical_records(stream):
        joined = _logical(parts)
        text = "\n".join(parts)
        statement, marker, remark = joined.partition("$$")
        if not statement.strip():
            if marker:
                yield Record("$$", (remark.strip(),), text, line, file)
            continue
        try:
            major, args = to_record.transform(parser.parse(statement.strip()))
        except lark.exceptions.UnexpectedInput as err:
            col = getattr(err, "column", 1) or 1
            record = quoted(statement.strip(), 60)
            raise NcppError(f"cannot read this CL record: {record}", Location(file, line, col)) from None
        if any(type(a) is float and not math.isfinite(a) for a in args):  # more digits than a float holds
            record = quoted(statement.strip(), 60)
            where = Location(file, line, _long_number_col(text))
            raise NcppError(f"number out of range in this CL record: {record}", where)
        yield Record(major, args, text, line, file)


_DIGITS = re.compile(r"\d{300,}")  # (a float holds 308 digits: a number past them reads as infinity)


def _long_number_col(text: str) -> int:
    """The column of the record's first number too long for a float, else 1."""
    found = _DIGITS.search(text)
    return found.start() + 1 if found else 1
