"""ISO 6983 G code: the generic form, LinuxCNC and FANUC.

Arcs are G2/G3 with incremental I J K centre words (every control's
default), both plane axes always written, full turns split off.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from ncpp.cldata.cycles import Hole
from ncpp.motion.segments import PLANE_AXES, Arc, Line
from ncpp.post.generator import Generator, number

CENTRE = "IJK"


class IsoGenerator(Generator):
    """Generic ISO: `%` tape marks, `( )` comments, ends with M30."""

    tape_marks = True
    program_end = 30
    keep_point = True  # "X12." — a FANUC reads "X12" as 12 µm
    dwell_ms = False  # G4 P and a canned cycle's P in seconds (RS274/NGC); FANUC: milliseconds

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.motion: int | None = None
        self.plane: int | None = None

    def coordinate(self, value: float) -> str:
        return number(value, self.decimals, self.keep_point)

    def emit_header(self) -> Iterator[str]:
        if self.tape_marks:
            yield "%"
        yield from self.emit_program_number()
        if self.job.header:
            yield from self.emit_comment(self.job.header)
        yield from self.emit_comment(self.job.name)
        yield f"{'G20' if self.job.inch else 'G21'} G17 G40 G49 G80 G90 G94"
        self.plane = 17

    def emit_program_number(self) -> Iterator[str]:
        return iter(())

    def emit_footer(self) -> Iterator[str]:
        yield f"M{self.program_end}"
        if self.tape_marks:
            yield "%"

    def emit_comment(self, text: str) -> Iterator[str]:
        # A comment cannot hold parentheses; they would end it early.
        yield "(" + text.replace("(", "[").replace(")", "]") + ")"

    def emit_tool(self, tool: int) -> Iterator[str]:
        yield f"T{tool} M6"
        yield f"G43 H{tool}"

    def emit_spindle(self, rpm: float, clockwise: bool) -> Iterator[str]:
        yield f"S{number(rpm, 0)} M{3 if clockwise else 4}"

    def emit_m(self, code: int) -> Iterator[str]:
        yield f"M{code}"

    def emit_hole(self, hole: Hole) -> Iterator[str]:
        """`G99 G81 X Y Z R F` (G98: back to the start level; Q the peck, P the dwell); the
        cycle's words written for every hole."""
        cycle = hole.cycle
        words = []
        if self.plane != 17:
            words.append("G17")
            self.plane = 17
        if not self.canned:
            words += ["G98" if cycle.to_start else "G99", f"G{cycle.code}"]
            self.motion = cycle.code
        where = (hole.x, hole.y, hole.bottom, hole.r)
        words += [f"{axis}{self.coordinate(value)}" for axis, value in zip("XYZR", where)]
        if cycle.step:
            words.append(f"Q{self.coordinate(cycle.step)}")
        if cycle.dwell:
            words.append(f"P{self.dwell(cycle.dwell)}")
        if hole.feed != self.feed:
            self.feed = hole.feed
            words.append(f"F{number(hole.feed, 3, self.keep_point)}")
        yield " ".join(words)

    def emit_cycle_off(self) -> Iterator[str]:
        self.motion = None
        yield "G80"

    def dwell(self, seconds: float) -> str:
        return str(round(seconds * 1000)) if self.dwell_ms else number(seconds, 3)

    def emit_dwell(self, seconds: float) -> Iterator[str]:
        yield f"G4 P{self.dwell(seconds)}"

    def emit_cutcom(self, side: str) -> Iterator[str]:
        yield {"LEFT": "G41", "RIGHT": "G42", "": "G40"}[side]

    def _motion_word(self, code: int) -> list[str]:
        if code == self.motion:
            return []
        self.motion = code
        return [f"G{code}"]

    def _feed_word(self, segment: Line | Arc) -> list[str]:
        feed = self.feed_of(segment)
        if feed == self.feed:
            return []
        self.feed = feed
        return [f"F{number(feed, 3, self.keep_point)}"]

    def emit_line(self, line: Line) -> Iterator[str]:
        axes = self.moved_axes(line.end)
        if not axes:
            return
        code = 0 if line.rapid else 1
        words = self._motion_word(code) + [letter + text for letter, text in axes]
        if not line.rapid:
            words += self._feed_word(line)
        yield " ".join(words)

    def emit_arc(self, arc: Arc) -> Iterator[str]:
        plane = arc.context.plane
        i, j, _ = PLANE_AXES[plane]
        words = []
        if plane != self.plane:
            words.append(f"G{plane}")
            self.plane = plane
        words += self._motion_word(3 if arc.turn > 0 else 2)
        words += [letter + text for letter, text in self.moved_axes(arc.end, always="XYZ"[i] + "XYZ"[j])]
        words += [CENTRE[k] + self.coordinate(arc.center[k] - arc.start[k]) for k in sorted((i, j))]
        words += self._feed_word(arc)
        yield " ".join(words)


class LinuxCncGenerator(IsoGenerator):
    """LinuxCNC: no tape marks, ends with M2."""

    tape_marks = False
    program_end = 2


class FanucGenerator(IsoGenerator):
    """FANUC: `%`, an O number, decimal points on every coordinate; the tool
    length offset (G43 H) goes with the first Z move after a tool change."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.length_offset: int | None = None

    dwell_ms = True  # G04 P1000: one second

    def emit_program_number(self) -> Iterator[str]:
        yield "O0001"

    def emit_tool(self, tool: int) -> Iterator[str]:
        yield f"T{tool} M6"
        self.length_offset = tool

    def emit_hole(self, hole: Hole) -> Iterator[str]:
        if self.length_offset is not None:  # on its own: a canned cycle's block takes no G43
            yield f"G43 H{self.length_offset}"
            self.length_offset = None
        yield from super().emit_hole(hole)

    def emit_line(self, line: Line) -> Iterator[str]:
        for text in super().emit_line(line):
            if self.length_offset is not None and " Z" in f" {text}":
                text = f"G43 H{self.length_offset} {text}"
                self.length_offset = None
            yield text
