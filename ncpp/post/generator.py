"""The part every dialect's generator shares: walking the events, keeping the
modal state, and turning CL set-up records into machine functions.

A generator writes complete programs from scratch (no source blocks to keep):
`Generator.write(events, setup)` yields NC lines; `setup(event)` returns the
CL `Record` behind a non-motion event (tool, spindle, coolant, comments) or
None.  Subclasses say how each thing is spelled in their dialect.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass

from ncpp.cldata.cycles import Hole, HoleBlock
from ncpp.cldata.motion import MAX_WORD, cutter_side, units_inch
from ncpp.cldata.reader import Record
from ncpp.errors import Location, NcppError, Warnings
from ncpp.motion.segments import PLANE_AXES, Arc, Event, Line, Pass, Point, replace
from ncpp.program.blocks import UNREADABLE, Block, Statement
from ncpp.program.parser import LineParser

SetupLookup = Callable[[Event], "Record | None"]
# Records that only set the interpretation of later motion: nothing to write.
SILENT = frozenset("FROM RAPID FEDRAT CIRCLE MULTAX TLAXIS INDIRV MACHIN UNITS PARTNO GOHOME GOTO".split())
COOLANT = {"ON": 8, "FLOOD": 8, "MIST": 7, "OFF": 9}


@dataclass
class Job:
    """What the program header needs, gathered from the records before the first motion."""

    name: str = "NCPP"
    inch: bool = False
    header: str | None = None  # the ncpp compensation header, when compensated


def number(value: float, decimals: int, keep_point: bool = False) -> str:
    """`value` with at most `decimals` places, trailing zeros dropped ("12.5", "12" or "12.")."""
    text = f"{value:.{decimals}f}"
    if decimals > 0:  # zeros after the point only: "1000" stays 1000
        text = text.rstrip("0")
    if text in ("-.", "-0.", "."):
        text = "0."
    text = text.removeprefix("-") if float(text) == 0 else text
    return text if keep_point else text.rstrip(".")


def single_turns(arc: Arc) -> Iterator[Arc]:
    """The arc as pieces that turn at most once (Fanuc, Heidenhain and Sinumerik
    have no turn count word); a helix keeps its pitch."""
    turns = abs(arc.turn)
    if turns <= 1:
        yield arc
        return
    i, j, n = PLANE_AXES[arc.context.plane]
    sweep = abs(arc.sweep())
    rise = arc.end[n] - arc.start[n]
    start = arc.start
    for k in range(1, turns):
        end = list(start)
        end[n] = arc.start[n] + rise * (2 * math.pi * k) / sweep
        piece_end: Point = (end[0], end[1], end[2])
        centre = list(arc.center)
        centre[n] = start[n]
        yield replace(
            arc,
            start=start,
            end=piece_end,
            center=(centre[0], centre[1], centre[2]),
            turn=1 if arc.turn > 0 else -1,
        )
        start = piece_end
    centre = list(arc.center)
    centre[n] = start[n]
    yield replace(arc, start=start, center=(centre[0], centre[1], centre[2]), turn=1 if arc.turn > 0 else -1)


def program_name(text: str, default: str = "NCPP") -> str:
    """A program name every control accepts: letters, digits, `_`, at most 24 characters."""
    name = re.sub(r"[^A-Za-z0-9_]+", "_", text.strip()).strip("_")[:24]
    return name or default


class Generator:
    """Base generator; a dialect overrides the `emit_*` spellings."""

    decimals_mm = 4
    decimals_inch = 5
    grammar = "iso"  # the NC grammar (ncpp.program.parser) that reads what the generator writes

    def __init__(
        self, warnings: Warnings | None = None, header: str | None = None, file: str = "<stdin>"
    ) -> None:
        self.warnings = warnings or Warnings()
        self.file = file
        self.job = Job(header=header)
        self.canned = False  # a canned cycle is modal (written, not ended yet)
        self.hole_block: Block | None = None  # the block of the hole last written
        self.rpm: float | None = None  # the spindle speed last written
        self.position: list[str | None] = [None, None, None]  # coordinate text last written per axis
        self.feed: float | None = None
        self.tool: int | None = None
        self.line_parser: LineParser | None = None  # made for the first INSERT/

    # -- the stream -------------------------------------------------------------
    def write(self, events: Iterable[Event], setup: SetupLookup) -> Iterator[str]:
        it = iter(events)
        prelude: list[tuple[Event, Record | None]] = []
        first_motion: Event | None = None
        for event in it:
            record = setup(event)
            if type(event) is Pass and (
                record is None or record.major in ("PARTNO", "UNITS", "MACHIN", "$$")
            ):
                self._absorb(record)
                prelude.append((event, record))
                continue
            first_motion = event
            first_record = record
            break
        yield from self.emit_header()
        for event, record in prelude:
            yield from self._event(event, record)
        if first_motion is not None:
            yield from self._event(first_motion, first_record)
            for event in it:
                yield from self._event(event, setup(event))
        yield from self.emit_footer()

    def _absorb(self, record: Record | None) -> None:
        if record is None:
            return
        if record.major == "PARTNO" and record.args:
            self.job.name = program_name(str(record.args[0]), self.job.name)
        elif record.major == "UNITS":
            self.job.inch = units_inch(record)

    def _event(self, event: Event, record: Record | None) -> Iterator[str]:
        if type(event) is Line and type(event.block) is HoleBlock:
            yield from self._hole(event)
            return
        if self.canned and type(event) in (Line, Arc):  # a move that is no hole ends the cycle
            yield from self._cycle_off()
        if type(event) is Line:
            yield from self.emit_line(event)
        elif type(event) is Arc:
            for piece in single_turns(event):
                yield from self.emit_arc(piece)
        elif record is not None:
            yield from self._setup(record)

    def _setup(self, rec: Record) -> Iterator[str]:
        major = rec.major
        if major == "UNITS" and units_inch(rec) != self.job.inch:  # the header has set the program's unit
            raise NcppError(f"UNITS/{rec.words[0]} after the first motion: a posted program has one unit "
                            f"(the CL data's first, {'INCHES' if self.job.inch else 'MM'})", rec.where)  # fmt: skip
        if major in SILENT:
            if major == "PARTNO" and rec.args:
                yield from self.emit_comment(f"PARTNO {rec.args[0]}")
            return
        if major == "$$":
            text = str(rec.args[0]) if rec.args else ""
            if text:
                yield from self.emit_comment(text)
        elif major in ("LOADTL", "LOAD"):
            self.tool = _tool_number(rec)
            yield from self.emit_tool(self.tool)
        elif major == "SPINDL":
            yield from self._spindle(rec)
        elif major == "COOLNT":
            mode = rec.words[0] if rec.words else "ON"
            if mode in COOLANT:
                yield from self.emit_m(COOLANT[mode])
            else:
                self.warnings.warn(
                    f"COOLNT/{mode} has no machine function; passed through as a comment", rec.where
                )
                yield from self.emit_comment(_one_line(rec.text))
        elif major == "CUTTER":
            yield from self.emit_comment("CUTTER " + ", ".join(f"{v:g}" for v in rec.numbers))
        elif major in ("PPRINT", "REMARK", "TITLE", "OPERATOR"):
            yield from self.emit_comment(" ".join(str(a) for a in rec.args))
        elif major == "INSERT":
            yield from self._insert(rec)
        elif major == "STOP":
            yield from self.emit_m(0)
        elif major == "OPSTOP":
            yield from self.emit_m(1)
        elif major in ("FINI", "END"):
            return  # the footer ends the program
        elif major == "CYCLE":  # the holes write the cycle (ncpp.cldata.cycles); OFF ends it
            if "OFF" in rec.words:
                yield from self._cycle_off()
        elif major == "DELAY":
            yield from self.emit_dwell(_dwell_time(rec))
        elif major == "CUTCOM":
            yield from self.emit_cutcom(cutter_side(rec))
        else:  # vendor words: ncpp.cldata.motion has warned already
            yield from self.emit_comment(_one_line(rec.text))

    def _insert(self, rec: Record) -> Iterator[str]:
        """APT INSERT/: literal NC text for the control, when the control reads it as a block;
        SolidWorks CAM writes tool and stock descriptions there, which become comments."""
        text = " ".join(str(a) for a in rec.args)
        if not self._reads(text, rec):
            self.warnings.warn(
                "INSERT/ text is no block of the control; passed through as a comment", rec.where
            )
            yield from self.emit_comment(text)
            return
        yield text

    def _reads(self, text: str, rec: Record) -> bool:
        """Does the control read `text` as a block?  (The ISO parser marks what it cannot read,
        the Heidenhain one refuses it.)"""
        if self.line_parser is None:
            self.line_parser = LineParser(self.grammar)
        try:
            block = self.line_parser.parse(text, line=rec.line, file=self.file)
        except NcppError:
            return False
        return not any(isinstance(item, Statement) and item.kind == UNREADABLE for item in block.items)

    def _hole(self, line: Line) -> Iterator[str]:
        """A hole's moves: the first writes the hole's canned cycle, each sets where it leaves the tool."""
        block = line.block
        assert isinstance(block, HoleBlock) and block.hole is not None
        if block is not self.hole_block:
            self.hole_block = block
            if block.hole.series and self.canned:
                yield from self._cycle_off()
            yield from self.emit_hole(block.hole)
            self.canned = True
        self.moved_axes(line.end)

    def pitch(self, hole: Hole) -> float:
        """A tapped hole's thread pitch: its feed per revolution (per minute over the spindle speed)."""
        cycle = hole.cycle
        if cycle.per_rev and cycle.feed is not None:
            return cycle.feed
        if not self.rpm:
            raise NcppError("CYCLE/TAP: the thread pitch needs the spindle speed (SPINDL) before it",
                            cycle.record.where)  # fmt: skip
        return hole.feed / self.rpm

    def _cycle_off(self) -> Iterator[str]:
        if self.canned:
            self.canned = False
            yield from self.emit_cycle_off()

    def _spindle(self, rec: Record) -> Iterator[str]:
        words = rec.words
        if "OFF" in words:
            yield from self.emit_m(5)
            return
        numbers = rec.numbers
        if not numbers:
            if "ON" in words:
                yield from self.emit_m(3)
            return
        self.rpm = _spindle_speed(rec)
        yield from self.emit_spindle(self.rpm, "CCLW" not in words)

    # -- helpers for dialects ----------------------------------------------------
    @property
    def decimals(self) -> int:
        return self.decimals_inch if self.job.inch else self.decimals_mm

    def moved_axes(self, end: Point, always: str = "") -> list[tuple[str, str]]:
        """(letter, text) of the axes whose written coordinate changes (and `always`)."""
        words = []
        for k, letter in enumerate("XYZ"):
            text = self.coordinate(end[k])
            if text != self.position[k] or letter in always:
                words.append((letter, text))
                self.position[k] = text
        return words

    def coordinate(self, value: float) -> str:
        return number(value, self.decimals)

    def feed_of(self, segment: Line | Arc) -> float:
        """The segment's feed (the CL data's FEDRAT)."""
        if segment.feed > 0:
            return segment.feed
        raise NcppError(
            "a feed move before any FEDRAT: the CL data gives no feed rate",
            Location(self.file, segment.block.line, 1),
        )

    # -- what dialects spell -------------------------------------------------------
    def emit_header(self) -> Iterator[str]:
        raise NotImplementedError

    def emit_footer(self) -> Iterator[str]:
        raise NotImplementedError

    def emit_comment(self, text: str) -> Iterator[str]:
        raise NotImplementedError

    def emit_line(self, line: Line) -> Iterator[str]:
        raise NotImplementedError

    def emit_arc(self, arc: Arc) -> Iterator[str]:
        raise NotImplementedError

    def emit_tool(self, tool: int) -> Iterator[str]:
        raise NotImplementedError

    def emit_spindle(self, rpm: float, clockwise: bool) -> Iterator[str]:
        raise NotImplementedError

    def emit_m(self, code: int) -> Iterator[str]:
        raise NotImplementedError

    def emit_hole(self, hole: Hole) -> Iterator[str]:
        """A hole drilled by the dialect's canned cycle, from where the tool is (above the hole's R plane)."""
        raise NotImplementedError

    def emit_cycle_off(self) -> Iterator[str]:
        raise NotImplementedError

    def emit_dwell(self, seconds: float) -> Iterator[str]:
        raise NotImplementedError

    def emit_cutcom(self, side: str) -> Iterator[str]:
        """Cutter radius compensation to the LEFT or RIGHT of the path, or off ("")."""
        raise NotImplementedError


MAX_TOOL = int(MAX_WORD)  # tool numbers a control takes


def _tool_number(rec: Record) -> int:
    """LOADTL/n: n a whole number a control takes (not LOADTL/1.5, not LOADTL/abc)."""
    numbers = rec.numbers
    if not numbers or numbers[0] != int(numbers[0]) or not 0 <= numbers[0] <= MAX_TOOL:
        raise NcppError(f"{rec.major}: expected a tool number from 0 to {MAX_TOOL:,}", rec.where)
    return int(numbers[0])


def _spindle_speed(rec: Record) -> float:
    """SPINDL/n: a speed from 0 on (the direction is CLW or CCLW, not a sign)."""
    n = rec.numbers[0]
    if not 0 <= n <= MAX_WORD:
        raise NcppError(
            f"{rec.major}: expected a spindle speed from 0 to {MAX_WORD:,.0f} (turning CLW or CCLW), got {n:g}",
            rec.where,
        )
    return n


def _dwell_time(rec: Record) -> float:
    """DELAY/t: t seconds (from 0); DELAY/REV,n (revolutions) and other forms are refused."""
    if rec.words or len(rec.numbers) != 1 or not 0 <= rec.numbers[0] <= MAX_WORD:
        raise NcppError("DELAY: expected a dwell time in seconds (DELAY/t)", rec.where)
    return rec.numbers[0]


def _one_line(text: str) -> str:
    return " ".join(part.strip().rstrip("$").strip() for part in text.splitlines())
