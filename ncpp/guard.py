"""The placement guard: a compensated program stops at its start unless the control's
work offset is the one it was compensated for.

Compensation corrects the errors of the places the program's points take on the
machine, which the work offset decides (`--work-offset`, `--var-file`).  Run under
another offset, the program carries the corrections of other places.  The guard
reads the control's active coordinate system and its zero (X Y Z) and stops the
program, with a message, when the system differs or an axis's zero is more than
`GUARD_MM` from the one told.  It is written only where ncpp was told the offset, at
the start of the program the control runs as the main one, after its program number: in a
Fanuc or Haas file whose subprograms stand before the main program (Fanuc Series 0i-MC
operator's manual, B-64124EN, "Subprogram (M98, M99)": a subprogram ends with M99), after
the O line of the program the interpreter runs as the main one (`flow.MainProgram`), never
in a stored subprogram, which runs only where it is called.

Per control (the ISO dialect: LinuxCNC's syntax, or Fanuc's for a program that
starts with an O number):

* LinuxCNC (G-code manual, "G Code Overview": numbered parameters #5220, the active
  system 1-9, and #5221-#5223, ..., G54's X Y Z, #5230 its rotation about Z (G10 L2 R,
  degrees), with 20 per system; its comments section: `(abort, text)` ends the program with
  the text, `(MSG, text)` shows it): the zeros stand in the machine's units (the INI's
  [TRAJ]LINEAR_UNITS), whatever G20/G21, as rs274 reads them.  The rotation must be the one
  told within `GUARD_DEG`: a system turned other than told puts every point elsewhere.
* Fanuc and Haas (Custom Macro B: #4014 holds group 14's G code, 54-59; #5221-#5223
  G54's X Y Z, 20 per system; `#3000=n (text)` raises macro alarm n with the text and
  stops; `IF [cond] THEN` one assignment): G54-G59.  An additional work offset
  (G54.1 Pn, G154 Pn) in effect at the start gets no guard: #4014 reads 54 for it too.
  One the program selects is checked at its zero's variables (Fanuc's #7001 on, Haas's
  #14001 on, `motion/offsets.py`).

An ISO program (LinuxCNC, Fanuc, Haas) that selects a told system checks its zero before the
block that selects it (`PlacementChecks`; rs274ngc and Fanuc select the system before the
block's move), once per system, where the zero is still the one told (not after the program's
own G10 L2/L20 of it) and the block runs once (not in a loop, nor in a subroutine or subprogram
that runs more than once; in one that runs once, a stored Fanuc subprogram among them, the check
stands in its text before the block, and runs where the call runs the block).  The check at the
start (with the system number) is written only where the program may rely on the system in
effect before it selects one: not where its first lines, of settings alone (modal G codes,
T M S F H D words, G28/G30, G53, G10 L2 P1-P9), select one (`_iso_selects_first`).

A LinuxCNC program's G92 that sets the offset of an axis the program has not positioned yet sets it
from where the operator left the tool (`G92 X0 Y0 Z0` at the top of a hobby program), which ncpp
takes to be the program's zero: the writer hands the axes to the check after the block
(`PlacementChecks.after`), which stops the program when #5211-#5213, the G92 offset X Y Z (G-code
manual, "Numbered Parameters": #5210 1 while a G52/G92 offset is applied, #5211-#5219 its axes, in
the machine's units, set by the G92 as rs274 runs it), is not the one ncpp compensated for within
`GUARD_MM` on those axes (`offset_lines`).  The offset does not depend on the one in effect before:
rs274ngc makes the block's point the tool's, whatever the old offset.  A G92.3 (G-code manual,
"G92.3 Restore G92 Offsets": the offset of #5211-#5219) gets the check of X Y Z: the saved offset
comes from the parameter file (`WorkOffsets.g92_saved`) or the program's last G92, and a control
may hold another.  G92.1 and G92.2 set no offset from the control's state (zero), G52 the values
it names: no check.  A LinuxCNC G10 L20 Pn of such axes (G-code manual, "G10 L20 Set Coordinate
System": system n's zero such that the current point reads the block's coordinates; P0 the system
in effect, 1-9 G54-G59.3) gets the same check of system n's zero, #5221-#5223 + 20 (n - 1) (the
parameters of the start's check, which makes sure P0's system is the one ncpp follows); rs274ngc
sets it from the machine position less the G92 offset and tool length in effect, as the
interpreter does.  Fanuc and Haas programs keep the warning alone: no variable of the G92 shift
is cited here from their manuals (Haas Mill Operator's Manual, "Macros", offsets: #5201-#5205 G52,
#5221-#5225 G54 ..., #7001-#7005 G110 ..., no G92), and their G10 L20 gives an additional work
offset's zero in machine coordinates (`motion/fanuc.py`), not one from where the tool stands.

A LinuxCNC program that touches off first, a G92 or a G10 L20 of the system in effect that sets X Y
Z after lines of settings alone (`touch_off_ahead`, `_iso_touches_off_first`), puts its zero where
the tool stood, whatever zero the control's system held: the check after it (`touch_off_lines`)
compares where the program's zero then stands in machine coordinates, the zero of the system in
effect plus the G92 offset applied (#5220; #5221 + 20 (n - 1); #5211-#5213; #5210 1 while applied:
"Numbered Parameters"), with where ncpp placed it (`Pass.zero_placed`), and the check at the start,
or before the block that selects the system there, leaves the system's zero out and keeps its
number and rotation (`_linuxcnc_touched_off`).  The sum holds where the system is not turned
(the G92 offset turns with the system: `Interpreter._rotation`): a turned system keeps the other checks.

* Sinumerik (840D sl System Variables parameter manual: `$P_UIFRNUM`, the number of the
  active settable frame, 1-4 for G54-G57; `$P_UIFR[n, axis, TR]` and `[n, axis, FI]`, its
  coarse and fine translation; Job Planning manual: `MSG("text")` shows the text, `SETAL(n)`
  raises cycle alarm n, 65000-67999 being the user's; `M0` stops): G54-G57 only.

Heidenhain programs get no guard.  ncpp's program zero of a Klartext program is the preset it
runs under (`--work-offset`, the zero of CYCL DEF 247's first preset), so the guard would read the
active preset's row and its X Y Z with `FN 18: SYSREAD` and stop with `FN 14: ERROR`, each as the
manual of the controls Klartext programs are written for (TNC 640, TNC7) gives it.  Those rows
are cited only from the previous generation: the iTNC 530 HSCI Technical Manual (07/2013, 9.5.4
"Data transfer NC > NC program (FN18: SYSREAD)") has ID530 NR1, the active row of the preset
table, and ID502/ID503 with the row as NR and the column as IDX, a row's values with and without
conversion to the active coordinate system.  HEIDENHAIN's TNC7 User's Manual (81762x-16, -17,
"Preset table") says that the table's active row is the workpiece preset, its X Y Z a basic
transformation in the basic coordinate system B-CS; the TNC7 basic manual (81762x-19, "System
data") that FN 18 returns system data in mm whatever the program's unit; 81762x-17's list of FN
functions that an FN 14 with the NC CANCEL reaction aborts the program with an error message
unless ID13 NR2 names a label it jumps to instead; the TNC 640 DIN/ISO User's Manual (34059x-05,
1/2015, 19.3 "Technical information") that FN 14's error number is 0 to 1199.  The group that
reads the active preset is not cited here from them, nor from the FN 18 tables of the TNC 640
Conversational User's Manual (10/2017, 10 "Programming Q parameters") or the TNC 620 Klartext
User's Manual (01/2022, 15 "Tables and overviews | System data"), whose pages found list tool data
and coordinate transformations (ID210) only.  The older technical manuals do not stand in for
it: the TNC 426/430's ID220 ("Current datum shift" NR2, "Difference between reference point and
datum point" NR3, IDX 1-9 the axes) predates the preset table, and its ID500/ID501 read the
datum table.  Nor do the Klartext programs at hand show it: those that use FN 18 read the tool
in the spindle and its table length (ID20 NR1, ID50 NR1 IDX, on a TNC 640), the datum shift and
the position (ID220 NR2, ID270 NR1, on a TNC 620), the traverse range (ID230) or the REF position
(ID240), never the active preset.

The tool guard: compensation also depends on the tool lengths ncpp was told (`--tool-table`):
the length moves the Z positions where the errors are evaluated and lengthens the Abbe arm.
After each block that applies the length of the tool in the spindle from the told table
(G43, G43 H0 or G43 H of that tool, G43.2 H of it; `interpreter._tool_length` marks it,
`Pass.length_told`), a check stops the program when the control's tool in the spindle or its
length is not the one told, within `GUARD_MM` (in a subroutine's or subprogram's text only where
it runs once: the check runs where the call runs the block).  The block's own move (`G43 H1 Z5`)
runs before the check; the next does not.  A length the program set itself (LinuxCNC's G10 L1/L10/L11, Haas's
G10 L10/L11) is the one told from there on: the control holds it too (rs274 writes it into the
spindle's #5401-#5409 at the G10, Haas into #2001-#2400), so the check finds the G10 run as the
program says, and a tool table or wear that differs.

* LinuxCNC (G-code manual, "Numbered Parameters": #5400 the tool number, #5401-#5409 the tool
  offsets X..W, volatile): they hold the table's entry of the tool in the spindle, set at M6 or
  M61, not the offset G43 applies, so a G43 H of another tool is not checked.  They stand in the
  machine's units, as the table.  Each check's `if` has a label of its own (rs274ngc refuses a
  label defined twice); `(abort, ...)` says #5400 and #5403 with their values.
* LinuxCNC's other tool parameters (#5401-#5413: the offsets, #5410 the diameter, #5411 #5412
  the front and back angles, #5413 the orientation): a program that reads one after its own M6 or
  M61 carries the told table's value where ncpp wrote numbers computed from it.  Before each block
  that reads one (`Pass.tool_read`; a control line's condition too), a check stops the program
  when the control's tool in the spindle or that parameter is not the one told (`tool_read_lines`,
  `ToolGuard.before`).  The interpreter marks a read where its block runs once where it is written
  (straight code, a loop's pass or a subroutine's run written as it ran, the subroutine's check
  inside its body); a read in text that runs again is warned of (`Interpreter._unchecked`).
* Haas (Mill Operator's Manual, "Macros", the system variables table: #2001-#2200 the tool
  length offsets' geometry, #2201-#2400 their wear, by offset number; G43 Hn applies offset n's
  sum): after a G43 whose H is the tool in the spindle (whose length ncpp was told), the check
  raises macro alarm 5 (`#3000`) when #2000+n plus #2200+n is not the told length within
  `GUARD_MM`, in the control's units, as the table.  A G43 without H, or with another H, gets
  none (ncpp is not told which tool's length that register holds).
* Fanuc: no check.  Where a Fanuc control keeps a tool's length depends on its tool
  compensation memory, which the machine builder chooses: with memory C "Memory for geometry
  compensation and wear compensation is separate", and "Separate memories are prepared for
  cutter compensation (for D code) and for tool length compensation (for H code)" (Series 0i/0i
  Mate Model B Connection Manual (Function), B-63833EN-1/02, 10 "Tool functions", "Tool
  compensation memory C"), while memory A keeps one value per offset.  The system variables of
  each memory's H offsets (geometry, wear) are not cited here from a Fanuc operator's manual, nor
  is a variable of the tool in the spindle: Fanuc has no standard one, and #4120, the T code of
  the modal information, is the last T commanded (cited only from Mitsubishi's Fanuc-style M700V
  manual, 13.5 "User Macro Specifications"), not the tool an M6 put in the spindle.  Sources
  other than Fanuc's do not settle the variables: they disagree on which of #2001-#2200 and
  #2201-#2400 holds the H offsets' geometry and which their wear (the Intek M84/M86 controller's
  User Manual, 6.2.2 "System Variables": geometry #11001 (#2201), wear #10001 (#2001); the
  ZapCon1/KnowledgeBase repository's FanucSystemVariables.md: lengths #2001-, wear #2201-).
* Sinumerik (Basic Functions Function Manual, 09/2011, 6FC5397-0BP40-2BA0, W1 "Tool offset",
  18.2 "Tool": "The compensation values $TC_DP1 to $TC_DP25 of the active tool compensation can be
  read with system variable $P_AD[n]"; Job Planning, 03/2006, 6FC5398-2BP10-1BA0, 8.1 "Offset
  memory": length 1 is $TC_DP3 (geometry), $TC_DP12 (wear) and $TC_DP21 (base dimension/adapter),
  "added together to produce a value (e.g. total length 1)"): after each M6 or D that selects an
  edge of the told offsets (`_N_TO_INI`), outside a loop, the check raises cycle alarm 65001 and
  stops (the placement guard's MSG, SETAL, M0) when $P_AD[3] + $P_AD[12] + $P_AD[21] is not the
  told length 1 within `GUARD_MM`, in the control's units, as the offsets.  It reads the
  compensation the program selected, not which tool is in the spindle ($P_TOOLNO and $P_TOOL are
  not cited here from a Siemens manual), nor a sum or setup offset DL (`$TC_SCP`, `$TC_ECP`) the
  control adds, which ncpp does not model.
* Heidenhain: no check.  Klartext's active length is FN 18: SYSREAD ID200 NR2 in the iTNC 530
  HSCI's and TNC 426/430's technical manuals ("Active length (including oversizes)"); the TNC
  620 Klartext User's Manual (01/2022, "System data") has "Active length" as NR2 of its tool
  group, with IDX 1 without oversize, 2 with the table's DL, 3 with it and TOOL CALL's DL (the
  length ncpp applies), but that group's number is not cited from a TNC 640, TNC 620 or TNC7
  manual (nor the active tool's, ID20 NR1 in the iTNC 530 HSCI's, which a TNC 640 program reads).
  The current tool's L and DL (ID950 NR1, NR4) are cited only from the TNC 320 DIN/ISO User's
  Manual (340 55x-04, 8.7 "Additional functions"); the TNC 620 Conversational User's Manual
  (10/2017, 10 "Programming Q Parameters") lists that group's NR13 on, not its number.  The
  preassigned Q114 holds "the current value for the tool length" (TNC 620 DIN/ISO User's Manual,
  5/2013, 9.11 "Preassigned Q parameters"; in the program's unit, TNC7 User's Manual 81762x-17),
  but is not said to include the table's and TOOL CALL's DL, as Q108's radius is said to include
  their DR (TNC 640 DIN/ISO User's Manual, 34059x-01, 8.11 "Preassigned Q parameters").

Readers of a written program drop both guards (`without_guard`): ncpp's interpreter
does not know the control's parameters, and the guards neither move nor act.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Generator, Iterable, Iterator
from dataclasses import dataclass, replace
from functools import cache
from itertools import chain, islice

from ncpp.errors import NcppError
from ncpp.motion.flow import MainProgram, program_number
from ncpp.motion.offsets import (
    _ADDITIONAL_X,
    _ROTATION_AFTER_X,
    ADDITIONAL,
    SYSTEMS,
    WorkOffsets,
    system_name,
)
from ncpp.motion.segments import Event, Pass
from ncpp.program.blocks import AnyItem, Block, Comment, Statement, Word
from ncpp.program.parser import LEADER_LINES, LineParser

GUARD_MM = 0.1  # how far an axis's zero may be from the one told: re-touching a fixture moves it microns
GUARD_DEG = 0.001  # how far a LinuxCNC system's rotation may be from the one told: 17 µm a metre out
BEGIN = "ncpp placement guard:"
END = "ncpp placement guard end"
TOOL_BEGIN = "ncpp tool guard:"
TOOL_END = "ncpp tool guard end"
GUARD_BLOCKS = 12  # the most blocks a guard has (a first comment without its last within them is no guard)
_SETTINGS_SCANNED = 8  # the Sinumerik lines of G codes alone after the definitions the guard may follow


@cache
def _parser(dialect: str) -> LineParser:
    """The parser of a written program's lines: the dialect's grammar (a post's "linuxcnc" writes ISO)."""
    return LineParser(dialect if dialect in ("heidenhain", "sinumerik") else "iso")


def _items(dialect: str, line: str) -> tuple[AnyItem, ...] | None:
    """The items the dialect's grammar reads in a written line (None: a line it cannot read)."""
    try:
        return _parser(dialect).parse(line.rstrip("\r\n")).items
    except NcppError:
        return None


def _program_number(items: tuple[AnyItem, ...] | None) -> bool:
    """A Fanuc program number line (`O1234`, perhaps with a `( )` comment); not an o-word line
    (`o100 sub`), nor `O1 ; ...`: a `;` comment is LinuxCNC's, which reads Fanuc-style subprograms
    too (its interpreter tests, `m98m99`), and whose guard is its own."""
    if not items or type(items[0]) is not Word:
        return False
    first, rest = items[0], items[1:]
    return (first.letter == "O" and first.number.isdigit()
            and all(type(item) is Comment and item.style == "(" for item in rest))  # fmt: skip


def _comments(items: tuple[AnyItem, ...] | None) -> str:
    return " ".join(item.text.lower() for item in items or () if type(item) is Comment)


@dataclass(frozen=True)
class Placement:
    """What the guard checks: the coordinate system in effect at the start (1-9: G54-G59.3),
    its zero (machine mm), and the mm per unit the control's parameters hold them in."""

    system: int
    zero: tuple[float, float, float]
    unit_mm: float = 1.0
    dialect: str = "fanuc"  # whose names the systems take (Haas: G154 Pn; Klartext: the preset)
    rotation: float = 0.0  # degrees about Z (LinuxCNC's G10 L2 R; the other controls' guards leave it)

    @classmethod
    def of(cls, offsets: WorkOffsets, unit_mm: float = 1.0) -> Placement | None:
        """The placement `offsets` tell (None: the system in effect is not told)."""
        if not offsets.told(offsets.active):
            return None
        return cls.of_system(offsets, offsets.active, unit_mm)

    @classmethod
    def of_system(cls, offsets: WorkOffsets, system: int, unit_mm: float = 1.0) -> Placement:
        """The placement of coordinate system `system` as `offsets` tell it."""
        rotation = offsets.rotations[system - 1] if system <= len(offsets.rotations) else 0.0
        return cls(system, offsets.zero(system), unit_mm, rotation=rotation)

    @property
    def name(self) -> str:
        """The system as the dialect names it; a Klartext program's zero is the preset it runs under."""
        return "the active preset" if self.dialect == "heidenhain" else system_name(self.system, self.dialect)

    def values(self) -> list[str]:
        """X Y Z of the zero in the control's units, as the guard compares them."""
        return [_number(v / self.unit_mm) for v in self.zero]

    def said(self) -> str:
        x, y, z = self.values()
        turned = f" turned R{_number(self.rotation)}" if self.rotation else ""
        return f"{self.name} at X{x} Y{y} Z{z} {_units(self.unit_mm)}{turned}"


def _number(value: float) -> str:
    return f"{value:.4f}".rstrip("0").rstrip(".") if value != 0 else "0"


def _less(number: str, gap: str = "") -> str:
    """A number written as subtracted (`-5`, `+5` for -5; `gap` after the sign): `--5` is no
    expression the Fanuc or Siemens manuals define."""
    return f"+{gap}{number[1:]}" if number.startswith("-") else f"-{gap}{number}"


def _units(unit_mm: float) -> str:
    return "mm" if unit_mm == 1.0 else "inch" if unit_mm == 25.4 else f"x{unit_mm:g} mm"


def _sinumerik_place(head: list[str], at: int, rest: Iterator[str]) -> tuple[int, int | None]:
    """Where the guard goes in a Sinumerik program, and the settable frame (1-4: G54-G57) the
    program has selected there (None: the one in effect counts): after the definitions at its
    start, and after the lines of G codes alone that follow them up to one that selects a
    settable frame, if one does (`head` takes the lines it needs from `rest`)."""
    settings, start = 0, None  # (start: the first line after the definitions)
    while True:
        if at == len(head):
            line = next(rest, None)
            if line is None:
                return at if start is None else start, None
            head.append(line)
        items = _items("sinumerik", head[at])
        if not _sinumerik_definition(items) or start is not None:
            start = at if start is None else start
            codes = _sinumerik_settings(items)
            if settings >= _SETTINGS_SCANNED or codes is None:
                return start, None
            settings += 1
            frame = next((code for code in codes if 54 <= code <= 57), None)
            if frame is not None:
                return at + 1, frame - 53
        at += 1


def _without_block_number(items: tuple[AnyItem, ...]) -> tuple[AnyItem, ...]:
    first = items[0] if items else None
    return items[1:] if type(first) is Word and first.letter == "N" else items


def _sinumerik_definition(items: tuple[AnyItem, ...] | None) -> bool:
    """A line that defines a variable (DEF; REDEF, which the grammar reads as a call of that name),
    or one a definition section may hold between them (a comment, a blank line): the 840D wants
    definitions before the program's first statement (Job Planning, "Definition of user variables
    (DEF)")."""
    if items is None:
        return False
    rest = _without_block_number(items)
    if not rest or type(rest[0]) is Comment:
        return True
    first = rest[0]
    return type(first) is Statement and (
        first.kind == "def" or (first.kind == "call" and first.node[0].upper() == "REDEF")
    )


def _sinumerik_settings(items: tuple[AnyItem, ...] | None) -> list[int] | None:
    """The G codes of a Sinumerik line of whole G codes alone (and a block number, a comment);
    None for any other line."""
    if items is None:
        return None
    codes = []
    for item in _without_block_number(items):
        if type(item) is Word and item.letter == "G" and item.number.isdigit():
            codes.append(int(item.value))
        elif type(item) is not Comment:
            return None
    return codes


def guard_lines(
    placement: Placement,
    dialect: str,
    first_lines: Iterable[str] = (),
    selected: bool = False,
    label: int = 0,
) -> list[str]:
    """The guard's lines (without line ends) for a program of `dialect` (a post's "linuxcnc" or
    "fanuc" says its syntax, and a Haas program's is Fanuc's; for "iso", `first_lines`, the
    program's first lines, tell Fanuc's from LinuxCNC's).  [] where there is none.  `selected`:
    the program selects the system itself (only its zero is checked); `label` numbers a
    LinuxCNC check after the first (a program's labels are each defined once)."""
    if dialect == "iso":
        fanuc = any(_program_number(_items(dialect, line)) for line in first_lines)
        dialect = "fanuc" if fanuc else "linuxcnc"
    # (grbl reads no parameters and has no conditionals: it cannot test its work offset)
    if dialect == "linuxcnc":
        return _linuxcnc(placement, selected, label)
    if dialect in ("fanuc", "haas"):
        return _fanuc(replace(placement, dialect=dialect), selected)
    return _sinumerik(placement, selected) if dialect == "sinumerik" else []


def _tolerance(placement: Placement) -> str:
    return _number(GUARD_MM / placement.unit_mm)


def _linuxcnc(placement: Placement, selected: bool = False, label: int = 0, zero: bool = True) -> list[str]:
    """`zero`: the zero's X Y Z are checked too (not where the program touches off first: `with_guard`)."""
    if placement.system > 9:
        return []  # (the additional work offsets are Fanuc's and Haas's)
    if not zero:
        return _linuxcnc_touched_off(placement, selected, label)
    x = 5221 + 20 * (placement.system - 1)
    tolerance = _tolerance(placement)
    far = [
        f"[ABS[#{x + k} {_less(value, ' ')}] GT {tolerance}]" for k, value in enumerate(placement.values())
    ]
    far.append(f"[ABS[#{x + _ROTATION_AFTER_X} {_less(_number(placement.rotation), ' ')}] GT {GUARD_DEG}]")
    if not selected:
        far.insert(0, f"[#5220 NE {placement.system}]")
    name = f"o<ncpp_guard_{label}>" if label else "o<ncpp_guard>"
    differs = (
        f"the control's {placement.name} zero differs" if selected else "the control's work offset differs"
    )
    return [
        f"({BEGIN} {placement.said()} within {_number(GUARD_MM)} mm)",
        f"{name} if [{' OR '.join(far)}]",
        f"(abort, ncpp: compensated for {placement.said()}; {differs}: compensate again for it, or set the offset)",
        f"{name} endif",
        f"({END})",
    ]


def _linuxcnc_touched_off(placement: Placement, selected: bool = False, label: int = 0) -> list[str]:
    """The check of a program that touches off first, at its start or before its selection of the
    system (`selected`): the system in effect (not where the program selects it) and its rotation,
    not its zero, which the touch-off's check replaces (`touch_off_lines`)."""
    rotation = 5221 + 20 * (placement.system - 1) + _ROTATION_AFTER_X
    turned = f"turned R{_number(placement.rotation)}" if placement.rotation else "not turned"
    said = f"{placement.name} {turned}" if selected else f"{placement.name} in effect, {turned}"
    far = f"[ABS[#{rotation} {_less(_number(placement.rotation), ' ')}] GT {GUARD_DEG}]"
    if not selected:
        far = f"[#5220 NE {placement.system}] OR {far}"
    name = f"o<ncpp_guard_{label}>" if label else "o<ncpp_guard>"
    return [
        f"({BEGIN} {said}, its zero where the program touches off)",
        f"{name} if [{far}]",
        f"(abort, ncpp: compensated for {said}; the control's work offset differs: compensate again for it, "
        "or set the offset)",
        f"{name} endif",
        f"({END})",
    ]


def _fanuc_x(placement: Placement) -> int | None:
    """The variable of the X of the zero of the placement's system on a Fanuc or Haas control
    (None: it has none): G54-G59 at #5221, 20 per system (Custom Macro B); an additional work
    offset at Fanuc's #7001 or Haas's #14001, 20 per offset (`offsets.py`)."""
    if placement.system > ADDITIONAL:
        n = placement.system - ADDITIONAL
        first, last = _ADDITIONAL_X[1 if placement.dialect == "haas" else 0]
        return first + 20 * (n - 1) if n <= last else None
    return 5221 + 20 * (placement.system - 1) if placement.system <= 6 else None  # (G59.1-G59.3: LinuxCNC's)


def _fanuc(placement: Placement, selected: bool = False) -> list[str]:
    """`selected`: the program selects the system itself (only its zero is checked); an
    additional work offset only so, since #4014 reads 54 for it (the module docstring)."""
    x = _fanuc_x(placement)
    if x is None or (placement.system > ADDITIONAL and not selected):
        return []
    tolerance = _tolerance(placement)
    lines = [f"({BEGIN.upper()} {placement.said().upper()} WITHIN {_number(GUARD_MM)} MM)"]
    if not selected:
        lines.append(f"IF [#4014 NE {53 + placement.system}] THEN #3000=1 (NCPP {placement.name} NOT ACTIVE)")
    for k, (axis, value) in enumerate(zip("XYZ", placement.values(), strict=True)):
        alarm = f"#3000={2 + k} (NCPP {placement.name} {axis} MOVED)"
        lines.append(f"IF [ABS[#{x + k}{_less(value)}] GT {tolerance}] THEN {alarm}")
    return lines + [f"({END.upper()})"]


def _sinumerik(placement: Placement, selected: bool = False) -> list[str]:
    """`selected`: the program has selected the frame itself (only its translation is checked)."""
    if placement.system > 4:
        return []  # (G58, G59 are Sinumerik's programmable offsets, not a settable frame)
    n, tolerance = placement.system, _tolerance(placement)
    far = " OR ".join(
        f"(ABS($P_UIFR[{n},{axis},TR]+$P_UIFR[{n},{axis},FI]{_less(value)})>{tolerance})"
        for axis, value in zip("XYZ", placement.values(), strict=True)
    )
    return [
        f"; {BEGIN} {placement.said()} within {_number(GUARD_MM)} mm",
        f"IF {far}" if selected else f"IF ($P_UIFRNUM<>{n}) OR {far}",
        f'MSG("ncpp: compensated for {placement.said()}: the settable frame differs")',
        "SETAL(65000)",
        "M0",
        "ENDIF",
        f"; {END}",
    ]


# Why a dialect's program gets no guard, as the warning says it
UNGUARDED = {
    "grbl": "grbl cannot test its work offset (it reads no parameters)",
    "heidenhain": "ncpp cites the FN 18 reads of the active preset (ID530 NR1, ID502/ID503) only from the "
    "iTNC 530's technical manual, not from a TNC 640, TNC 620 or TNC7 manual",
}


def with_guard(
    lines: Iterable[str],
    placement: Placement,
    dialect: str,
    header: str,
    header_lines: int = 1,
    unguarded: Callable[[str], None] = lambda why: None,
    checks: bool = False,
    main: MainProgram | None = None,
) -> Iterator[str]:
    """The written program's lines with the guard after the header comment (`header_lines` lines,
    the first holding `header`) and the program number that may follow it: at the start of the
    program the control runs as the main one, which `main` tells where the interpreter ran a
    later program of the file as the main one (`flow.MainProgram`: a Fanuc or Haas file whose
    subprograms stand before it), after that program's O line and never in a stored subprogram,
    which runs only where called.  Where the dialect (or the control's system) has no guard, or
    the main program is not decided, `unguarded` is told why.  `checks`: the ISO program's
    selections of told systems are checked where it makes them (`PlacementChecks`), so no guard
    is written where it selects a system before anything relies on the one in effect."""
    # (lines are taken from `lines` no further than the guard's place: the verifier tags each
    # line with how far the writer had read when it was taken)
    it = iter(lines)
    head: list[str] = []
    for line in it:  # (a Fanuc tape leader may stand above the header)
        head.append(line)
        if header in line or len(head) >= LEADER_LINES + 12:
            break
    at = None
    if head and header in head[-1]:
        head.extend(islice(it, header_lines - 1))
        at = len(head)
        for line in it:  # a Fanuc program's number comes first
            head.append(line)
            if not _program_number(_items(dialect, line)):
                break
    guard = guard_lines(placement, dialect, head)
    # (read once the writer has written the program's first lines: the flow decided before its first block)
    stored, number = (
        (main.stored, main.number) if main is not None and at is not None and guard else (0, None)
    )
    if stored is None:
        unguarded(MAIN_UNDECIDED)
        yield from chain(head, it)
        return
    if stored and at is not None:
        head, at = yield from _before_main(head, at, it, stored, number, dialect)
        if not head:
            unguarded(f"ncpp did not find the O line of the main program, O{number}, in the written program")
            return
    if checks and at is not None and dialect in ISO_SYNTAX and _iso_selects_first(head, at, it):
        guard = []  # (the check of the system it selects stands before that line)
    elif (
        checks and at is not None and dialect in ISO_SYNTAX and guard and _iso_touches_off_first(head, at, it)
    ):
        guard = _linuxcnc(placement, zero=False)  # (the touch-off's check, after it, replaces the zero's)
    elif not guard:
        unguarded(UNGUARDED.get(dialect, f"{dialect} has no settable frame for {placement.name}"))
    if at is None or not guard:
        yield from chain(head, it)
        return
    while at < len(head) and _program_number(_items(dialect, head[at])):
        at += 1
    if dialect == "sinumerik":  # (the guard's IF is a statement: after the definitions)
        at, frame = _sinumerik_place(head, at, it)
        if frame is not None:  # the zero told is that of the frame the program selects first
            guard = _sinumerik(replace(placement, system=frame), selected=True)
    eol = "\r\n" if head[at - 1].endswith("\r\n") else "\n"
    yield from head[:at]
    yield from (line + eol for line in guard)
    yield from head[at:]
    yield from it


MAIN_UNDECIDED = (
    "the file's first program ends with M99 (a subprogram), and which later program the control runs as the "
    "main one is not ncpp's to guess"
)


def _before_main(
    head: list[str], at: int, rest: Iterator[str], stored: int, number: str | None, dialect: str
) -> Generator[str, None, tuple[list[str], int]]:
    """Yield the lines before the main program's O line: the header's and those of the `stored`
    programs before it, each from its O line (`head[at:]` and `rest` hold them), the program numbers
    read as the flow reads them (`flow.program_number`).  Return the lines from the main program's
    O line on that were read (1: the guard goes after the first), or ([], 0) where the line found
    there is not program `number` (every line yielded)."""
    yield from head[:at]
    waiting, programs = head[at:], 0  # (read, not yet yielded)
    while True:
        if not waiting:
            line = next(rest, None)
            if line is None:
                return [], 0
            waiting.append(line)
        found = _program_of(dialect, waiting[0])
        if found is not None:
            if programs == stored:
                break
            programs += 1
        yield waiting.pop(0)
    if found == number:
        return waiting, 1
    yield from waiting
    yield from rest
    return [], 0


@cache
def _own_parser(dialect: str) -> LineParser:
    return LineParser(dialect)


def _program_of(dialect: str, line: str) -> str | None:
    """The program number of a written line as the flow reads one (`flow.program_number`), else None."""
    if "O" not in line and "o" not in line:
        return None
    try:
        return program_number(_own_parser(dialect).parse(line.rstrip("\r\n")))
    except NcppError:
        return None


ISO_SYNTAX = ("iso", "linuxcnc", "fanuc", "haas")  # the dialects whose guard is LinuxCNC's or Fanuc's
# The G codes of an ISO line of settings, one that neither moves nor relies on the work offset in
# effect: modal ones, G28 G30 (returns) and G53 (a move in machine coordinates: ncpp leaves them as
# programmed, so no compensation rests on the offset), and G10 with L2 P1-P9 (it sets that system's
# zero, whichever is in effect); with M0-M9 (not M98 M99, calls), T S F H D and N words, comments
_SETTING_G = frozenset((0, 1, 2, 3, 17, 18, 19, 20, 21, 28, 30, 40, 43, 49, 53, 61, 61.1, 64, 80, 90, 91,
                        90.1, 91.1, 93, 94, 95, 96, 97, 98, 99))  # fmt: skip
_MACHINE_MOVES = frozenset((28, 30, 53))  # (whose axis words are the control's own positions)
_AXIS_LETTERS = frozenset("XYZABCUVW")
# lines of settings (not comments alone) a CAM post's head may have before it selects a system
_ISO_SETTINGS_SCANNED = 16


def _iso_lines(
    head: list[str], at: int, rest: Iterator[str], ahead: int = 0
) -> Iterator[tuple[tuple[AnyItem, ...] | None, str, int]]:
    """The items and comments of an ISO program's lines from `at` on, each with the index of the line
    after it, the tool guard's checks skipped, at most LEADER_LINES + _ISO_SETTINGS_SCANNED lines
    (comment lines too, boundedly); `head` takes the lines it needs from `rest`, and `ahead` more
    after each (they end where the program does)."""
    tool_check = False
    for _ in range(LEADER_LINES + _ISO_SETTINGS_SCANNED):
        head.extend(islice(rest, max(0, at + 1 + ahead - len(head))))
        if at + ahead >= len(head):
            return
        items, at = _items("iso", head[at]), at + 1
        said = _comments(items)
        if TOOL_BEGIN in said or tool_check:
            tool_check = TOOL_END not in said
            continue
        yield items, said, at


def _iso_selects_first(head: list[str], at: int, rest: Iterator[str]) -> bool:
    """Whether an ISO program selects a work offset before anything relies on the one in effect:
    in one of the lines of settings alone from `at` on, or in the first other line (whose
    selection, in rs274ngc's order of execution and Fanuc's, comes before its move); a placement
    check the writer put before a selection says so too (`head` takes the lines it needs from
    `rest`)."""
    settings = 0
    for items, said, _ in _iso_lines(head, at, rest):
        if BEGIN in said:
            return True
        setting = _iso_setting(items)
        if setting is None:
            return False
        if setting == "selects":
            return True
        settings += setting == "codes"
        if settings > _ISO_SETTINGS_SCANNED:
            break
    return False


def _iso_touches_off_first(head: list[str], at: int, rest: Iterator[str]) -> bool:
    """Whether an ISO program's first line from `at` on that is not one of settings alone (as
    `_iso_selects_first` reads them) is a touch-off that the writer follows with its check
    (`touch_off_lines`): the lines before it rely on no work offset, and the program's zero after
    it is where the tool stood, whatever zero the control held (`head` takes the lines it needs
    from `rest`)."""
    for items, said, after in _iso_lines(head, at, rest, ahead=1):
        if BEGIN in said:
            return False
        setting = _iso_setting(items)
        if setting is None:  # (the line after it: the touch-off's check, if it is one)
            return f"{BEGIN} {TOUCH_OFF}" in _comments(_items("iso", head[after]))
        if setting == "selects" or not _before_touch_off(setting, items or ()):
            return False
    return False


def _before_touch_off(setting: str, items: Iterable[AnyItem]) -> bool:
    """Whether a line of settings (`_iso_setting`) may come before a touch-off made first: not a G10
    (L2 sets a zero or a rotation), nor a line that names an axis (G28 Z0 passes through Z0 in the
    work offset, G53 moves)."""
    words = [item for item in items if type(item) is Word]
    return setting == "none" or not any(
        word.letter in _AXIS_LETTERS or (word.letter, word.value) == ("G", 10.0) for word in words
    )


def _iso_setting(items: tuple[AnyItem, ...] | None) -> str | None:
    """What an ISO line is to `_iso_selects_first`: "selects" a work offset (G54-G59.3, G54.1 P and
    G154 P, Fanuc's and Haas's additional ones), "codes" of settings alone (`_SETTING_G`), "none"
    (comments, a tape mark, a Fanuc program number), or None: anything else, a block delete among
    it (the control may skip the line)."""
    if items is None or any(type(item) is Statement and item.kind == "block_delete" for item in items):
        return None
    words = [item for item in items if type(item) is Word]
    if any(word.letter == "G" and (54 <= word.value < 60 or int(word.value) == 154) for word in words):
        return "selects"
    if _program_number(items) or all(type(item) is Comment or _tape_mark(item) for item in items):
        return "none"
    if len(words) + sum(type(item) is Comment for item in items) < len(items):
        return None  # (an expression, an o-word, an assignment, a call)
    codes = {word.value for word in words if word.letter == "G"}
    axes = bool(codes & _MACHINE_MOVES)
    zero_set = not axes and _zero_set(words)
    if zero_set:
        words = [word for word in words if word not in zero_set]
    if all(_setting_word(word, axes or bool(zero_set)) for word in words):
        return "codes"
    return None


def _tape_mark(item: AnyItem) -> bool:
    return type(item) is Statement and item.kind == "tape" and item.node[0].strip() == "%"


def _zero_set(words: list[Word]) -> list[Word]:
    """The G10, L2 and P1-P9 of a G10 L2 that sets the zero of system P ([] for none)."""
    firsts = [next((word for word in words if test(word)), None) for test in (
        lambda w: w.letter == "G" and w.value == 10, lambda w: w.letter == "L" and w.value == 2,
        lambda w: w.letter == "P" and w.value in range(1, 10))]  # fmt: skip
    return [word for word in firsts if word is not None] if all(firsts) else []


def _setting_word(word: Word, axes: bool) -> bool:
    """A word a line of settings may hold (`axes`: axis words too, of a machine move or a zero set)."""
    letter, value = word.letter, word.value
    if letter == "G":
        return value in _SETTING_G
    if letter in "NM":
        return value == int(value) and value >= 0 and (letter == "N" or value < 10)
    return letter in "TSFHD" and value >= 0 or axes and letter in _AXIS_LETTERS


class PlacementChecks:
    """The placement guard's check of the zero of each told system an ISO program selects, once,
    before the first block that selects it (`before`): the interpreter marks the block
    (`Pass.zero_told`) where it runs once and the zero is still the one told.  LinuxCNC's
    syntax, or Fanuc's (Haas's) in a Fanuc program (a program number at its top).  In LinuxCNC's,
    the offset a G92 or G10 L20 sets too, after the block, on the axes the program has not
    positioned, which the writer hands over (`after`), and the G92 offset after a G92.3 (the
    interpreter's `Pass.offset_told`)."""

    def __init__(
        self,
        offsets: WorkOffsets,
        dialect: str,
        unit_mm: float,
        unguarded: Callable[[str], None] = lambda why: None,
    ):
        self.offsets, self.dialect, self.unit_mm, self.unguarded = offsets, dialect, unit_mm, unguarded
        self.looked = 0  # blocks looked at for a Fanuc program number
        self.checked: set[int] = set()
        self.labels = 0  # the checks written so far (each `if` a label of its own)
        # the block of a touch-off the program makes first (`touch_off_ahead`), where a system it selects
        # before it gets its rotation checked alone (`deferred`: the zero's check, where the touch-off's is not)
        self.touch_off: Block | None = None
        self.deferred: Placement | None = None

    def before(self, events: list[Event]) -> list[str]:
        """The check of the zero of the told system the block selects, where it is the first to."""
        block = events[0].block
        if self.dialect == "iso" and self.looked < LEADER_LINES + 12:
            self.looked += 1
            if _program_number(block.items):
                self.dialect = "fanuc"
        if block is self.touch_off and self.deferred is not None:
            return self._deferred(events)
        number = next((e.zero_told for e in events if type(e) is Pass and e.zero_told is not None), None)
        if number is None or number in self.checked:
            return []
        self.checked.add(number)
        placement = Placement.of_system(self.offsets, number, self.unit_mm)
        dialect = "linuxcnc" if self.dialect == "iso" else self.dialect
        self.labels += 1
        if self.touch_off is not None and dialect == "linuxcnc" and placement.system <= 9:
            self.deferred = placement  # (its zero matters only where the touch-off gets no check of its own)
            lines = _linuxcnc(placement, selected=True, label=self.labels, zero=False)
        else:
            lines = guard_lines(placement, dialect, selected=True, label=self.labels)
        if not lines:
            self.unguarded(f"{dialect} has no variables of {placement.name}'s zero")
        eol = block.eol or "\n"
        return [line + eol for line in lines]

    def _deferred(self, events: list[Event]) -> list[str]:
        """Before the touch-off: the check of the zero of the system the program selected before it,
        where the touch-off gets no check of the program's zero (`after`)."""
        placement, self.deferred = self.deferred, None
        if placement is None or self._offset_checked(events, "XYZ") and _placed(events) is not None:
            return []
        self.labels += 1
        eol = events[0].block.eol or "\n"
        return [line + eol for line in _linuxcnc(placement, selected=True, label=self.labels)]

    def after(self, events: list[Event], unplaced: Collection[str]) -> list[str]:
        """The check of the offset after the block: after a G92 or G10 L20, of its `unplaced` axes
        (X Y Z the program had not positioned before it), and after one of the system in effect that
        sets all three there (a touch-off), of where the program's zero stands in machine
        coordinates (`touch_off_lines`); after a G92.3, of X Y Z."""
        checked = self._offset_checked(events, unplaced)
        if checked is None:
            return []
        system, offset, restored = checked
        self.labels += 1
        eol = events[0].block.eol
        placed = _placed(events)
        first = events[0].block is self.touch_off  # (X Y Z unplaced there: the program positioned nothing)
        if placed is not None and not restored and (first or _XYZ_LETTERS <= set(unplaced)):
            lines = touch_off_lines(*placed, g92=system == 0, unit_mm=self.unit_mm, label=self.labels)
        else:
            lines = offset_lines(system, offset, self.unit_mm, self.labels, restored)
        return [line + eol for line in lines]

    def checks_offset(self, events: list[Event], unplaced: Collection[str]) -> bool:
        """Whether `after` checks the offset the block sets (the writer's warning of a G92 or
        G10 L20 on `unplaced` axes says that the check stops the program where it differs)."""
        return self._offset_checked(events, unplaced) is not None

    def _offset_checked(
        self, events: list[Event], unplaced: Collection[str]
    ) -> tuple[int, list[tuple[int, float]], bool] | None:
        """(the system, the offset on each axis 0-2 in mm, whether a G92.3 restored it) that the
        check after the block compares; None where there is none (LinuxCNC's only, not after the
        last line)."""
        told = next((e.offset_told for e in events if type(e) is Pass and e.offset_told), None)
        if told is None or self.dialect != "iso" or not events[0].block.eol:
            return None
        restored = not any(type(e) is Pass and e.setting is not None for e in events)
        first = events[0].block is self.touch_off
        offset = [(axis, mm) for axis, mm in told[1] if restored or first or "XYZ"[axis] in unplaced]
        return (told[0], offset, restored) if offset else None


def _placed(events: list[Event]) -> tuple[int, tuple[float, float, float]] | None:
    """The program's zero a touch-off among the events put in machine coordinates (`Pass.zero_placed`)."""
    return next((e.zero_placed for e in events if type(e) is Pass and e.zero_placed), None)


def touch_off_ahead(blocks: Iterable[Block], offsets: WorkOffsets) -> Block | None:
    """The block of a touch-off an ISO program makes first: a G92, or a G10 L20 of the system in effect
    (P0, or its number), of X Y Z, after lines of settings alone that name no axis (`_iso_setting`:
    modal codes, T M S F H D words, comments, a selection of G54-G59.3) and before another line, the
    system in effect not turned (`offsets`: as told; the interpreter's `_zero_placed`).  Before it
    nothing relies on a system's zero, and after it the program's zero is where the tool stood
    (LinuxCNC G-code manual, "G92 Coordinate System Offset", "G10 L20 Set Coordinate System"),
    whatever zero the control held."""
    system = offsets.active
    for block in blocks:
        setting = _iso_setting(block.items)
        words = [item for item in block.items if type(item) is Word]
        codes = {(word.letter, word.value) for word in words}
        if setting is not None:
            if not _before_touch_off(setting, words):
                return None
            selected = [n for n, name in enumerate(SYSTEMS, 1) if ("G", float(name[1:])) in codes]
            if setting == "selects" and len(selected) != 1:
                return None  # (Fanuc's and Haas's additional offsets: no LinuxCNC touch-off)
            system = selected[0] if selected else system
            continue
        p = {value for letter, value in codes if letter == "P"}
        sets = ("G", 92.0) in codes and not p or {("G", 10.0), ("L", 20.0)} <= codes and p <= {0.0, system}
        plain = all(type(item) in (Word, Comment) for item in block.items)
        named = {word.letter for word in words if word.letter in _AXIS_LETTERS}
        turned = system <= len(offsets.rotations) and offsets.rotations[system - 1]
        return block if sets and plain and named == _XYZ_LETTERS and block.eol and not turned else None
    return None


def offset_lines(
    system: int, offset: Iterable[tuple[int, float]], unit_mm: float, label: int, restored: bool = False
) -> list[str]:
    """LinuxCNC's check (without line ends), after a G92 block or a G92.3 (`restored`; `system` 0) or
    a G10 L20 of coordinate system `system` (1-9), that the offset it set on each axis (0-2: X Y Z;
    mm) is the one told within GUARD_MM: #5211-#5213 hold the G92 offset, #5221-#5223 + 20 (n - 1)
    system n's zero, in the machine's units (`unit_mm` mm each); `label` numbers the check's `if`."""
    x = 5211 if system == 0 else 5221 + 20 * (system - 1)
    values = [("XYZ"[axis], x + axis, _number(mm / unit_mm)) for axis, mm in offset]
    name = "the G92 offset" if system == 0 else f"{system_name(system, 'linuxcnc')}'s zero"
    told = f"{name} {' '.join(letter + value for letter, _, value in values)} {_units(unit_mm)}"
    tolerance = _number(GUARD_MM / unit_mm)
    far = " OR ".join(f"[ABS[#{key} {_less(value, ' ')}] GT {tolerance}]" for _, key, value in values)
    found = " ".join(f"{letter}#{key}" for letter, key, _ in values)
    label_name = f"o<ncpp_guard_{label}>"
    if restored:  # (the messages stay short: rs274ngc reads lines of up to 255 characters)
        how, then = (
            "restored by G92.3",
            f"the control restored {found}: compensate again with its parameter file",
        )
    else:
        how = "set with the tool at the program's zero"
        block = "G92" if system == 0 else "G10 L20"
        then = f"this {block} set {found}: jog the tool to that zero first, or compensate again for where it stands"
    return [
        f"({BEGIN} {told} {how} within {_number(GUARD_MM)} mm)",
        f"{label_name} if [{far}]",
        f"(abort, ncpp: compensated for {told} {how}; {then})",
        f"{label_name} endif",
        f"({END})",
    ]


_XYZ_LETTERS = frozenset("XYZ")
TOUCH_OFF = "the program's zero at machine"  # (what a touch-off's check says first, lower case: `with_guard`)
# the program's zero in machine coordinates on X Y Z, as LinuxCNC reads it (G-code manual, "Numbered
# Parameters"): the zero of the system in effect (#5220: 1-9, its X at #5221 + 20 (n - 1)) plus the G92
# offset (#5211-#5213) where it is applied (#5210 1, else 0)
_PROGRAM_ZERO = tuple(f"#[{5201 + k}+20*#5220]+#5210*#{5211 + k}" for k in range(3))  # (lines of 255 at most)


def touch_off_lines(
    active: int, zero_mm: tuple[float, float, float], g92: bool, unit_mm: float, label: int
) -> list[str]:
    """LinuxCNC's check (without line ends), after a G92 (`g92`) or a G10 L20 of the system in
    effect (`active`, 1-9) that sets X Y Z before the program positions them, that the program's
    zero then stands at `zero_mm` in machine coordinates within GUARD_MM: what the compensation
    depends on, whatever zero the system held before; `label` numbers the check's `if`."""
    values = [_number(mm / unit_mm) for mm in zero_mm]
    told = f"{TOUCH_OFF} {' '.join(a + v for a, v in zip('XYZ', values, strict=True))} {_units(unit_mm)}"
    tolerance = _number(GUARD_MM / unit_mm)
    far = " OR ".join(
        f"[ABS[{read}{_less(value)}] GT {tolerance}]"
        for read, value in zip(_PROGRAM_ZERO, values, strict=True)
    )
    x = 5221 + 20 * (active - 1)
    block = "G92" if g92 else "G10 L20"
    found = f"{system_name(active, 'linuxcnc')} X#{x} Y#{x + 1} Z#{x + 2} + #5210 * G92 X#5211 Y#5212 Z#5213"
    label_name = f"o<ncpp_guard_{label}>"
    return [
        f"({BEGIN} {told} set by the tool there within {_number(GUARD_MM)} mm)",
        f"{label_name} if [{far}]",
        f"(abort, ncpp: compensated for {told}; this {block} put it at {found}: jog the tool there first, "
        "or compensate again)",
        f"{label_name} endif",
        f"({END})",
    ]


def tool_guard_lines(tool: int, length_mm: float, unit_mm: float, label: int) -> list[str]:
    """LinuxCNC's check (without line ends) that the control's tool in the spindle is `tool` and
    its Z offset `length_mm` within GUARD_MM (its parameters in the machine's units, `unit_mm` mm
    each); `label` numbers the check's `if` (a program's labels are each defined once)."""
    length, units, name = _number(length_mm / unit_mm), _units(unit_mm), f"o<ncpp_tool_guard_{label}>"
    told = f"tool {tool} at length Z{length} {units}"
    return [
        f"({TOOL_BEGIN} {told} within {_number(GUARD_MM)} mm)",
        f"{name} if [[#5400 NE {tool}] OR [ABS[#5403 {_less(length, ' ')}] GT {_number(GUARD_MM / unit_mm)}]]",
        f"(abort, ncpp: compensated for {told}; the control has tool #5400 at Z#5403: "
        "compensate again with its tool table, or set the length)",
        f"{name} endif",
        f"({TOOL_END})",
    ]


# LinuxCNC's parameters of the tool in the spindle a program may read (G-code manual, "Numbered
# Parameters"): #5401-#5409 its offsets X Y Z A B C U V W, #5410 its diameter, #5411 #5412 its front
# and back angles, #5413 its orientation; what each is, and whether it is an angle (degrees)
TOOL_PARAMETER_NAMES = {
    **{5401 + k: f"{letter} offset" for k, letter in enumerate("XYZABCUVW")},
    5410: "diameter",
    5411: "front angle",
    5412: "back angle",
    5413: "orientation",
}
_ANGLES = frozenset((5404, 5405, 5406, 5411, 5412))


_READ_CHECK = ", parameter 54"  # what the first comment of a tool parameter's check says (`tool_read_lines`)


def _read_tolerance(key: int, unit_mm: float) -> str:
    """How far the control's parameter may be from the told one: GUARD_MM for a length (in the
    table's units), GUARD_DEG for an angle (a tool turned by it puts its tip 17 µm off a metre
    out, and the told value is written to 0.0001), half a step for the orientation (a number)."""
    if key == 5413:
        return "0.5"
    return _number(GUARD_DEG if key in _ANGLES else GUARD_MM / unit_mm)


def tool_read_lines(tool: int, key: int, value: float, unit_mm: float, label: int) -> list[str]:
    """LinuxCNC's check (without line ends), before a block that reads tool parameter `key`, that
    the control's tool in the spindle is `tool` and its `key` is `value` (the told table's, in its
    units or degrees) within `_read_tolerance`; `label` numbers the check's `if`."""
    told, name = _number(value), f"o<ncpp_tool_guard_{label}>"
    unit = "deg" if key in _ANGLES else "" if key == 5413 else _units(unit_mm)
    within, unit = _read_tolerance(key, unit_mm), f" {unit}" if unit else ""
    said = (
        f"tool {tool} with {TOOL_PARAMETER_NAMES[key]}, parameter {key}, at {told}{unit}"  # (`#n` reads it)
    )
    return [
        f"({TOOL_BEGIN} {said} within {within}{unit})",
        f"{name} if [[#5400 NE {tool}] OR [ABS[#{key} {_less(told, ' ')}] GT {within}]]",
        f"(abort, ncpp: compensated for {said}; the control has tool #5400 with #{key}: "
        "compensate again with its tool table, or set the tool)",
        f"{name} endif",
        f"({TOOL_END})",
    ]


HAAS_OFFSETS = 200  # Haas's tool length offsets in #2001-#2200 (geometry), #2201-#2400 (wear)


def haas_tool_guard_lines(offset: int, length_mm: float, unit_mm: float) -> list[str]:
    """Haas's check (without line ends) that tool length offset `offset` (G43's H), geometry plus
    wear, is `length_mm` within GUARD_MM, in the control's units (`unit_mm` mm each): Haas Mill
    Operator's Manual, "Macros", the system variables table: #2001-#2200 tool length offsets
    (geometry), #2201-#2400 tool length wear, by offset number; `#3000=n (text)` raises alarm n
    and stops; `IF [cond] THEN` one statement.  [] for an offset beyond #2200's."""
    if not 1 <= offset <= HAAS_OFFSETS:
        return []
    length = _number(length_mm / unit_mm)
    told = f"H{offset} AT LENGTH Z{length} {_units(unit_mm).upper()}"
    return [
        f"({TOOL_BEGIN.upper()} {told} WITHIN {_number(GUARD_MM)} MM)",
        f"IF [ABS[#{2000 + offset}+#{2200 + offset}{_less(length)}] GT {_number(GUARD_MM / unit_mm)}] "
        f"THEN #3000=5 (NCPP H{offset} LENGTH DIFFERS)",
        f"({TOOL_END.upper()})",
    ]


# Sinumerik's lengths 1 of the active tool offset: geometry, wear and base/adapter ($TC_DP3,
# $TC_DP12, $TC_DP21 of the edge D selects, `$P_AD[n]` its $TC_DPn; the module docstring)
_SINUMERIK_LENGTH_1 = "$P_AD[3]+$P_AD[12]+$P_AD[21]"


def sinumerik_tool_guard_lines(edge: int, length_mm: float, unit_mm: float) -> list[str]:
    """Sinumerik's check (without line ends) that the active tool offset's length 1 (geometry,
    wear and adapter: `_SINUMERIK_LENGTH_1`) is `length_mm` within GUARD_MM, in the control's
    units (`unit_mm` mm each), with the placement guard's MSG, SETAL and M0 (cycle alarm 65001)."""
    length = _number(length_mm / unit_mm)
    told = f"D{edge} at length 1 = {length} {_units(unit_mm)}"
    return [
        f"; {TOOL_BEGIN} {told} within {_number(GUARD_MM)} mm",
        f"IF ABS({_SINUMERIK_LENGTH_1}{_less(length)})>{_number(GUARD_MM / unit_mm)}",
        f'MSG("ncpp: compensated for {told}: the control\'s active tool offset differs")',
        "SETAL(65001)",
        "M0",
        "ENDIF",
        f"; {TOOL_END}",
    ]


def _h_number(block: Block) -> int | None:
    """The block's H word's offset number (None: none, or one from a variable)."""
    words = [item for item in block.items if type(item) is Word and item.letter == "H"]
    return int(words[0].value) if len(words) == 1 and words[0].value == int(words[0].value) else None


# Why a dialect's program gets no tool guard, as the warning says it
TOOLS_UNGUARDED = {
    "fanuc": "a Fanuc control keeps the H offsets' lengths in system variables that depend on its tool "
    "compensation memory (A, B or C, the machine builder's choice), which ncpp cites from no Fanuc manual, "
    "and has no standard variable of the tool in the spindle (#4120 is the last T commanded)",
    "grbl": "grbl cannot test its tool length (it reads no parameters)",
    "heidenhain": "ncpp cites the FN 18 read of the active tool length (ID200 NR2) only from the iTNC 530's "
    "and TNC 426/430's technical manuals, not from a TNC 640, TNC 620 or TNC7 manual",
}


class ToolGuard:
    """The tool guard's checks, written after each block that applies a told length (the
    writer's `after`): LinuxCNC's, in an ISO program that is not a Fanuc one (a program number
    at its top), Haas's, where the block's H is the tool in the spindle, and Sinumerik's, after
    each M6 or D that selects a told edge.  Where there is none, `unguarded` is told why, once."""

    def __init__(self, dialect: str, unit_mm: float, unguarded: Callable[[str], None] = lambda why: None):
        self.unit_mm, self.unguarded, self.haas = unit_mm, unguarded, dialect == "haas"
        self.sinumerik = dialect == "sinumerik"
        guarded = dialect in ("iso", "haas", "sinumerik")
        self.why = None if guarded else TOOLS_UNGUARDED.get(dialect, f"{dialect} has no tool guard")
        self.looked = 0  # blocks looked at for a Fanuc program number
        self.checks = 0
        if self.why is not None:
            unguarded(self.why)

    def __call__(self, events: list[Event]) -> list[str]:
        block = events[0].block
        if self.looked < LEADER_LINES + 12 and self.why is None and not (self.haas or self.sinumerik):
            self.looked += 1
            if _program_number(block.items):
                self.why = TOOLS_UNGUARDED["fanuc"]
                self.unguarded(self.why)
        last = events[-1]
        told = last.length_told if type(last) is Pass else None
        if told is None or self.why is not None or not block.eol:  # (a last line: nothing runs after it)
            return []
        if self.sinumerik:
            return [line + block.eol for line in sinumerik_tool_guard_lines(*told, self.unit_mm)]
        if self.haas:
            offset = _h_number(block)  # (G43 without H, or H of another tool: not the told length's offset)
            lines = haas_tool_guard_lines(offset, told[1], self.unit_mm) if offset == told[0] else []
            return [line + block.eol for line in lines]
        self.checks += 1
        return [line + block.eol for line in tool_guard_lines(*told, self.unit_mm, self.checks)]

    def before(self, events: list[Event]) -> list[str]:
        """LinuxCNC's checks of the tool parameters the block reads (`Pass.tool_read`), one each,
        before it (the writer's `before`)."""
        reads = [read for e in events if type(e) is Pass and e.tool_read for read in e.tool_read]
        if not reads or self.why is not None or self.haas or self.sinumerik:
            return []
        eol = events[0].block.eol or "\n"
        lines: list[str] = []
        for read in reads:
            self.checks += 1
            lines.extend(line + eol for line in tool_read_lines(*read, self.unit_mm, self.checks))
        return lines


def without_guard(
    blocks: Iterable[Block], dropped: Callable[[Block, str], None] | None = None
) -> Iterator[Block]:
    """The blocks without the guards: the placement guard's and the tool guard's checks wherever
    they stand, each from its first comment to its last (within GUARD_BLOCKS: a first comment
    without its last is no guard, and its blocks stay).  `dropped` is told of each check of a tool
    parameter the program read (its first block, what it says): numbers after it may have been
    computed from that value, where no read is left to check again."""
    held: list[Block] = []  # the blocks of a guard under way
    end = ""
    for block in blocks:
        raw = block.raw
        if not held and "ncpp" not in raw and "NCPP" not in raw:  # (most blocks: no guard's text)
            yield block
            continue
        said = " ".join(item.text.lower() for item in block.items if type(item) is Comment)
        if not held:
            end = TOOL_END if TOOL_BEGIN in said else END if BEGIN in said else ""
            if not end:
                yield block
                continue
        held.append(block)
        if end in said:
            first = " ".join(item.text for item in held[0].items if type(item) is Comment)
            if dropped is not None and end == TOOL_END and _READ_CHECK in first:
                dropped(held[0], first)
            held = []
        elif len(held) >= GUARD_BLOCKS:
            yield from held
            held = []
    yield from held
