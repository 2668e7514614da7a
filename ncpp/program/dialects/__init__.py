"""NC dialects: the registry, detection from content, and sniffing a stream.

Each dialect brings a grammar (`grammar/<name>.lark`) and a builder that maps
its syntax onto the common items (see `heidenhain` and `sinumerik` for their
Statement kinds and node shapes); `parser_for(name)` gives its line parser.
Writers live beside them (`iso.IsoWriter`), interpreters in `ncpp/motion/`;
`UNITS` names each dialect's parts, the one place a dialect is registered.
"""

from __future__ import annotations

import importlib
import io
import re
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from itertools import chain
from typing import BinaryIO, cast

from ncpp.errors import NcppError
from ncpp.program.parser import Dialect, LineParser, _ItemBuilder


@dataclass(frozen=True)
class DialectUnit:
    """Where one dialect's parts live, each named here once: its syntax (the parser's
    `Dialect`, "module:attribute"), its interpreter ("module:function", as `interpret` of
    `ncpp.motion.interpreter`) and its writer ("module:Class").  `family`: the dialect whose grammar and writer a
    flavour shares (grbl is ISO's, its interpreter a subclass of LinuxCNC's)."""

    name: str
    family: str
    syntax: str
    interpreter: str
    writer: str


UNITS = {
    unit.name: unit
    for unit in (
        DialectUnit(
            "iso",
            "iso",
            "ncpp.program.dialects:ISO",
            "ncpp.motion.interpreter:interpret",
            "ncpp.program.dialects.iso:IsoWriter",
        ),
        DialectUnit(
            "fanuc",
            "iso",
            "ncpp.program.dialects:FANUC",
            "ncpp.motion.fanuc:interpret",
            "ncpp.program.dialects.iso:IsoWriter",
        ),
        DialectUnit(
            "haas",
            "iso",
            "ncpp.program.dialects:HAAS",
            "ncpp.motion.fanuc:interpret_haas",
            "ncpp.program.dialects.iso:IsoWriter",
        ),
        DialectUnit(
            "grbl",
            "iso",
            "ncpp.program.dialects:GRBL",
            "ncpp.motion.grbl:interpret",
            "ncpp.program.dialects.iso:IsoWriter",
        ),
        DialectUnit(
            "heidenhain",
            "heidenhain",
            "ncpp.program.dialects.heidenhain:HEIDENHAIN",
            "ncpp.motion.heidenhain:interpret",
            "ncpp.program.dialects.heidenhain:HeidenhainWriter",
        ),
        DialectUnit(
            "sinumerik",
            "sinumerik",
            "ncpp.program.dialects.sinumerik:SINUMERIK",
            "ncpp.motion.sinumerik:interpret",
            "ncpp.program.dialects.sinumerik:SinumerikWriter",
        ),
    )  # fmt: skip
}
DIALECTS = tuple(UNITS)
FAMILY = {name: unit.family for name, unit in UNITS.items()}
SNIFF_BYTES = 4096
# The most the detection reads: the sniffed bytes and the rest of their last line, cut short
# (a line of megabytes would take the patterns minutes)
_SNIFF_MOST = 2 * SNIFF_BYTES

ISO = Dialect(
    "iso", "iso", _ItemBuilder, fast_terminals=LineParser.FAST_TERMINALS, read_where_run=True,
    bare_tape_marks=True,
)  # fmt: skip
# grbl: a line it reads as a system command (`$H`, `$100=250`) is no G code: read where it
# runs, it reaches the interpreter as a line the grammar cannot read; it reads no tape marks
# (`protocol.c`: "Program start-end percent sign NOT SUPPORTED")
GRBL = Dialect(
    "grbl", "iso", _ItemBuilder, fast_terminals=LineParser.FAST_TERMINALS, read_where_run=True, tape_marks=False,
)  # fmt: skip
FANUC = Dialect(
    "fanuc", "fanuc", _ItemBuilder, fast_terminals=LineParser.FAST_TERMINALS, read_where_run=True, leader=True,
    programs_after_end=True, eob_semicolon=True,
)  # fmt: skip
HAAS = Dialect(
    "haas", "fanuc", _ItemBuilder, fast_terminals=LineParser.FAST_TERMINALS, read_where_run=True, leader=True,
    programs_after_end=True, eob_semicolon=True,
)  # fmt: skip
# File name endings that name a dialect when the content does not tell.
SUFFIXES = {".h": "heidenhain", ".mpf": "sinumerik", ".spf": "sinumerik"}


def _unit(name: str) -> DialectUnit:
    unit = UNITS.get(name.lower())
    if unit is None:
        raise NcppError(f"unknown dialect {name!r} (known: {', '.join(DIALECTS)})")
    return unit


def _load(where: str):
    module, attribute = where.split(":")
    return getattr(importlib.import_module(module), attribute)


def get_dialect(name: str) -> Dialect:
    """The syntax of the dialect called `name` (case-insensitive)."""
    return cast(Dialect, _load(_unit(name).syntax))


def dialect_tools(name: str) -> tuple[Callable, type]:
    """(interpret, Writer) of the dialect called `name`."""
    unit = _unit(name)
    return _load(unit.interpreter), _load(unit.writer)


def parser_for(dialect: str | Dialect) -> LineParser:
    return LineParser(dialect)


# ---- detection ------------------------------------------------------------------

_HEIDENHAIN = re.compile(r"^[ \t]*\d*[ \t]*BEGIN[ \t]+PGM\b", re.M)
_HEIDENHAIN_BLOCK = re.compile(
    r"^[ \t]*\d+[ \t]+(L[ \t]|LP[ \t]|CC[ \t]|C[ \t]|CR[ \t]|CT[ \t]|CP[ \t]|RND[ \t]|TOOL[ \t]+CALL|TOOL[ \t]+DEF"
    r"|CYCL[ \t]+DEF|CYCL[ \t]+CALL|LBL[ \t]|CALL[ \t]+LBL|FN[ \t]*\d+:|Q\d+[ \t]*=|END[ \t]+PGM)",
    re.M,
)
# Constructs no ISO / Fanuc / LinuxCNC program has, on a line without its comments.
_SINUMERIK = re.compile(
    r"^%_N_"
    r"|^[ \t]*(N\d+[ \t]+)?(DEF|PROC|REPEAT|ENDIF|ENDWHILE|ENDFOR|ENDLOOP|UNTIL"
    r"|A?TRANS|A?ROTS?|A?SCALE|A?MIRROR|CIP|ASPLINE|BSPLINE|CSPLINE)\b"
    r"|^[ \t]*(N\d+[ \t]+)?(IF|WHILE)[ \t]+[^\[\s]"
    r"|^[ \t]*(N\d+[ \t]+)?[A-NP-Za-np-z_][A-Za-z0-9_]*[ \t]*:(?!=)"  # a label (not Fanuc `O1000:`)
    r"|^[ \t]*(N\d+[ \t]+)?(?!GOTO)[A-NP-Za-np-z_][A-Za-z_]{2}[A-Za-z0-9_]*[ \t]*\("  # a call (not `OCIRCLE(`, `GOTO60(`)
    r"|\bGOTO[FBC]\b|\b(AC|IC|ACP|ACN|DC)[ \t]*\(|\bMSG[ \t]*\(|\bCR[ \t]*=|\$[A-Z]{1,3}_[A-Z]"
    r"|(?<![#\w<])[A-Za-z][A-Za-z0-9_]*[ \t]*=(?!=)",  # `X=10`, `R1=5` (LinuxCNC assigns `#1=5`)
    re.M | re.I,
)


# Constructs only LinuxCNC has (o-word control lines, named parameters): they outweigh what
# looks like Sinumerik elsewhere (a note `Tools: ...` after M2 reads like a label).
_LINUXCNC = re.compile(
    r"^[ \t]*(N\d+[ \t]+)?O(<[^>\n]*>|\d+)[ \t]*(SUB|ENDSUB|CALL|RETURN|IF|ELSEIF|ELSE|ENDIF|WHILE|ENDWHILE|DO|REPEAT|ENDREPEAT|BREAK|CONTINUE)\b"
    r"|#<[A-Za-z_]",
    re.M | re.I,
)


def _code_only(text: str) -> str:
    """The text with `;` and `(...)` comments removed, line by line."""
    lines = []
    for line in text.splitlines():
        line = line.split(";", 1)[0]
        lines.append(line if _call_like(line) else re.sub(r"\([^)]*(\)|$)", "", line))
    return "\n".join(lines)


def _call_like(line: str) -> bool:
    """Parentheses that call (`AC(`, `CYCLE81(`), not an ISO comment."""
    return bool(
        re.search(r"\b(AC|IC|DC)[ \t]*\(|\b(?!GOTO)[A-NP-Za-np-z_][A-Za-z_]{2}[A-Za-z0-9_]*[ \t]*\(", line)
    )


# grbl's system commands (grbl 1.1, "Grbl v1.1 Commands"): homing, jogging, unlock, settings
# `$100=250`, startup blocks `$N0=`, `$$ $# $G $I $C`; and the comment FreeCAD's grbl posts write
_GRBL = re.compile(
    r"^[ \t]*\$(H|X|\$|#|G|I|C|SLP)[ \t]*(;.*|\(.*)?\r?$|^[ \t]*\$(J|RST|N\d?|\d+)[ \t]*="
    r"|^\(Post Processor: grbl",
    re.M | re.I,
)


# Haas's own settings (G187 smoothness, G103 look-ahead, G154 work offsets); Fanuc's program
# number line (`O1000`, `O1000 (NAME)`, `:1000`), macro call, alarm, AI contour and preview control,
# and its macro statements (LinuxCNC's loops and conditions are o-word lines; Sinumerik's take no brackets)
_HAAS = re.compile(r"(?<![\w#.])G0*(187|103|154)(?![\d.])", re.I)
# Haas's local subprogram call `M97 P1000` (Haas Mill Operator's Manual, "M97 Local Sub-Program Call"):
# neither Fanuc's code lists nor LinuxCNC's M codes have an M97 (rs274 refuses it; ncpp there refuses its P)
_HAAS_CALL = re.compile(r"(?<![\w#.])M0*97[ \t]*P[ \t]*\d", re.I)
# Haas's circular pocket milling `G12`/`G13 ... Q..` (Mill Operator's Manual, "G12 Circular Pocket Milling
# CW / G13 Circular Pocket Milling CCW": Q the radius increment, used with K): LinuxCNC has no G12/G13,
# Fanuc's are G12.1/G13.1 (polar coordinate interpolation), and the circle cutting of older Fanuc
# controls' G12/G13 takes I D F, no Q
_HAAS_POCKET = re.compile(r"(?<![\w#.])G0*1[23](?![\d.])[^\n;(]*Q", re.I)
_FANUC = re.compile(
    r"^[ \t]*[O:]\d+[ \t]*(\(.*\))?[ \t]*\r?$|(?<![\w#.])G0*65[ \t]*P|#3000[ \t]*=|(?<![\w#.])G0*5\.1[ \t]*Q"
    r"|(?<![\w#.])G0*8[ \t]*P"
    r"|^[ \t]*(N\d+[ \t]*)?(WH(?:ILE)?[ \t]*\[.*\][ \t]*DO[ \t]*\d|IF[ \t]*\[.*\][ \t]*(GOTO|THEN))",
    re.M | re.I,
)


_G80 = re.compile(r"(?<![\w#.])G0*80(?![\d.])", re.I)
# G00 in the block of a G28 or G30 (`G00 G91 G28 Z0`, as posts write it): the Fanuc interpreter reads it
# (`FanucInterpreter`), rs274ngc refuses the block ("Cannot use two g codes that both use axis values")
_RETURN_WITH_G0 = re.compile(
    r"^(?=[^\n]*(?<![\w#.])G0*0(?![\d.]))[^\n]*(?<![\w#.])G0*(28|30)(?![\d.])", re.M | re.I
)
_MOTION_CODE = re.compile(r"(?<![\w#.])G0*([0-3]|7[346]|8[1-9])(?![\d.])", re.I)
_AXIS_FIRST = re.compile(r"^[ \t]*(N\d+[ \t]*)?[XYZ][ \t]*[-+.\d]", re.I)


def _axes_after_g80(code: str) -> bool:
    """Whether a line of axis words with no motion code follows a G80 that gave none: Fanuc's G80
    cancels the canned cycle alone (group 09), and the G00 or G01 before it moves them (Fanuc Series
    0i-MD operator's manual, G code list); LinuxCNC's G80 cancels the motion mode (group 1) and
    rs274ngc refuses them ("Cannot use axis values without a g code that uses them")."""
    after_g80 = False
    for line in code.splitlines():
        if not line.strip() or line.strip() in ("%",):
            continue
        if after_g80 and _AXIS_FIRST.match(line) and not _MOTION_CODE.search(line):
            return True
        after_g80 = bool(_G80.search(line)) and not _MOTION_CODE.search(line)
    return False


def detect(first_bytes: bytes, name: str | None = None) -> str:
    """'iso', 'fanuc', 'haas', 'grbl', 'heidenhain' or 'sinumerik' from the start of a program.

    grbl's system commands (`$H`, `$J=`, `$100=250`) or the comment FreeCAD's grbl
    posts write first mean grbl; `BEGIN PGM` or numbered conversational blocks mean Heidenhain; a
    `%_N_` header or a construct only Sinumerik has (`DEF`, `PROC`, `X=...`,
    `CR=`, `AC(`, `MSG(`, `GOTOF`, labels, `IF` without brackets, `$AA_...`)
    means Sinumerik, unless LinuxCNC's o-word lines or `#<name>` parameters
    are there too.  When the content is plain ISO-looking G code, a file name
    ending in .h / .mpf / .spf decides; then Haas's settings (G187, G103, G154) mean Haas, and so
    do its local subprogram call `M97 P..` and circular pocket milling `G12`/`G13` with a Q
    (unless LinuxCNC's o-word lines are there),
    and a Fanuc program number line, G65, #3000, G05.1 Q, G08 P, a macro `WHILE [..] DOn` or
    `IF [..] GOTOn / THEN`, G00 in a G28 or G30 block, or axis words after a G80 with no motion code mean Fanuc (unless LinuxCNC's o-word lines are there); any other is LinuxCNC's ISO.
    """
    text = first_bytes.decode("latin-1")
    if _HEIDENHAIN.search(text) or len(_HEIDENHAIN_BLOCK.findall(text)) >= 2:
        return "heidenhain"
    if _GRBL.search(text):
        return "grbl"
    code = _code_only(text)
    if text.startswith("%_N_") or (_SINUMERIK.search(code) and not _LINUXCNC.search(code)):
        return "sinumerik"
    if name:
        for suffix, dialect in SUFFIXES.items():
            if name.lower().endswith(suffix):
                return dialect
    haas_only = _HAAS_CALL.search(code) or _HAAS_POCKET.search(code)
    if _HAAS.search(code) or (haas_only and not _LINUXCNC.search(code)):
        return "haas"
    fanuc_only = _FANUC.search(code) or _RETURN_WITH_G0.search(code) or _axes_after_g80(code)
    if fanuc_only and not _LINUXCNC.search(code):
        return "fanuc"
    return "iso"


def sniff(
    stream: Iterable[bytes], name: str | None = None, dialect: str | None = None
) -> tuple[str, Iterator[bytes]]:
    """(dialect, lines) for a binary stream: the dialect is `dialect` when given,
    else detected from the first SNIFF_BYTES; lines are the stream's lines from
    the beginning, the sniffed head re-read from a buffer (stdin keeps streaming)."""
    if dialect is not None:
        get_dialect(dialect)  # an unknown name is an error before any reading
        return dialect.lower(), iter(stream)
    read = getattr(stream, "read", None)
    if read is None:
        lines = iter(stream)
        head_lines = []
        size = 0
        for line in lines:
            head_lines.append(line)
            size += len(line)
            if size >= SNIFF_BYTES:
                break
        head = b"".join(head_lines)
        return detect(head[:_SNIFF_MOST], name), chain(head_lines, lines)
    head = read(SNIFF_BYTES)
    head_lines = list(io.BytesIO(head))
    if head_lines and not head_lines[-1].endswith(b"\n"):
        head_lines[-1] += cast(BinaryIO, stream).readline()  # (it has `read`: a file)
    sniffed = b"".join(head_lines)[:_SNIFF_MOST]
    return detect(sniffed, name), chain(head_lines, stream)  # (in C: no generator's step per line)


def parse_program(stream: BinaryIO, file: str = "<stdin>", dialect: str | None = None):
    """(dialect, blocks) of a program stream, the dialect detected unless given."""
    from ncpp.program.parser import parse_stream

    name, lines = sniff(stream, file, dialect)
    return name, parse_stream(lines, file, name)
