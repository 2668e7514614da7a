"""HEIDENHAIN Klartext (conversational): `BEGIN PGM` ... `END PGM`, numbered blocks.

Lines are `L X+.. Y+.. Z+.. R0 F..|FMAX`; arcs are a centre `CC` followed by
`C X.. Y.. DR+|DR-` (DR+ counter-clockwise, as G3); a helix is
`CP IPA±angle IZ±rise DR±` about the same `CC`.  The tool is called with
its speed (`TOOL CALL 1 Z S9000`), so a tool change waits for the spindle
record or the first move.  A hole is a `CYCL DEF` (200 drilling, 203 universal
drilling, 205 universal pecking, 207 rigid tapping, 201 reaming) with its Q
parameters, then `L X.. Y.. R0 FMAX M99` over the hole, which calls it there.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from typing import Any

from ncpp.cldata.cycles import Hole
from ncpp.motion.segments import PLANE_AXES, Arc, Event, Line
from ncpp.post.generator import Generator, SetupLookup, number

AXES = "XYZ"
# CL cycle kind -> (Klartext cycle, its name)
CYCLES = {"DRILL": (200, "DRILLING"), "FACE": (200, "DRILLING"), "DEEP": (203, "UNIVERSAL DRILLING"),
          "BRKCHP": (205, "UNIVERSAL PECKING"), "TAP": (207, "RIGID TAPPING NEW"), "BORE": (201, "REAMING"),
          "REAM": (201, "REAMING")}  # fmt: skip
BREAK = 0.2  # Q256 (and the advanced stop distances of 205): the retraction to break a chip, mm


def signed(value: float, decimals: int) -> str:
    text = number(value, decimals)
    return text if text.startswith("-") else "+" + text


class HeidenhainGenerator(Generator):
    grammar = "heidenhain"

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.pending_tool: int | None = None
        self.radius_comp = "R0"  # RL / RR under CUTCOM/LEFT / RIGHT
        self.defined: str | None = None  # the CYCL DEF in force (M99 calls it at each hole)

    def write(self, events: Iterable[Event], setup: SetupLookup) -> Iterator[str]:
        for n, text in enumerate(super().write(events, setup)):
            yield f"{n} {text}"

    def coordinate(self, value: float) -> str:
        return signed(value, self.decimals)

    @property
    def units(self) -> str:
        return "INCH" if self.job.inch else "MM"

    def emit_header(self) -> Iterator[str]:
        yield f"BEGIN PGM {self.job.name} {self.units}"
        if self.job.header:
            yield from self.emit_comment(self.job.header)

    def emit_footer(self) -> Iterator[str]:
        yield from self._tool_call()
        yield "L M30"
        yield f"END PGM {self.job.name} {self.units}"

    def emit_comment(self, text: str) -> Iterator[str]:
        yield "; " + text

    def emit_tool(self, tool: int) -> Iterator[str]:
        yield from self._tool_call()
        self.pending_tool = tool

    def _tool_call(self, speed: str = "") -> Iterator[str]:
        if self.pending_tool is not None:
            yield f"TOOL CALL {self.pending_tool} Z{speed}"
            self.pending_tool = None

    def emit_spindle(self, rpm: float, clockwise: bool) -> Iterator[str]:
        speed = f" S{number(rpm, 3)}"
        if self.pending_tool is not None:
            yield from self._tool_call(speed)
        else:
            yield f"TOOL CALL Z{speed}"
        yield f"L M{3 if clockwise else 4}"

    def emit_m(self, code: int) -> Iterator[str]:
        yield from self._tool_call()
        yield "STOP" if code == 0 else f"L M{code}"

    def _feed(self, segment: Line | Arc) -> str:
        feed = self.feed_of(segment)
        if feed == self.feed:
            return ""
        self.feed = feed
        return f" F{number(feed, 3)}"

    def emit_line(self, line: Line) -> Iterator[str]:
        yield from self._tool_call()
        axes = self.moved_axes(line.end)
        if not axes:
            return
        words = " ".join(letter + text for letter, text in axes)
        yield f"L {words} {self.radius_comp}" + (" FMAX" if line.rapid else self._feed(line))

    def emit_arc(self, arc: Arc) -> Iterator[str]:
        yield from self._tool_call()
        i, j, n = PLANE_AXES[arc.context.plane]
        first, second = sorted((i, j))
        centre = f"CC {AXES[first]}{self.coordinate(arc.center[first])} {AXES[second]}{self.coordinate(arc.center[second])}"
        direction = "DR+" if arc.turn > 0 else "DR-"
        rise = arc.end[n] - arc.start[n]
        if abs(rise) < 0.5 * 10.0**-self.decimals:
            yield centre
            axes = self.moved_axes(arc.end, always=AXES[first] + AXES[second])
            words = " ".join(letter + text for letter, text in axes)
            yield f"C {words} {direction}" + self._feed(arc)
            return
        # A helix: polar angle and rise about the pole; CP ends where the control computes.
        self.moved_axes(arc.end)
        angle = signed(math.degrees(arc.sweep()), 4)
        yield centre
        yield f"CP IPA{angle} I{AXES[n]}{signed(rise, self.decimals)} {direction}" + self._feed(arc)

    def emit_cutcom(self, side: str) -> Iterator[str]:
        """RL / RR / R0 go on the next L blocks (radius compensation is part of the straight line)."""
        self.radius_comp = {"LEFT": "RL", "RIGHT": "RR", "": "R0"}[side]
        return iter(())

    def emit_dwell(self, seconds: float) -> Iterator[str]:
        self.defined = None  # the next hole defines its cycle again
        yield "CYCL DEF 9.0 DWELL TIME"
        yield f"CYCL DEF 9.1 DWELL {number(seconds, 3)}"

    def emit_cycle_off(self) -> Iterator[str]:
        return iter(())  # each hole calls its cycle (M99): nothing stays active

    def emit_hole(self, hole: Hole) -> Iterator[str]:
        """`CYCL DEF` with the hole's Q parameters (depths from the surface Q203), then M99 over it."""
        yield from self._tool_call()
        cycle = hole.cycle
        code, name = CYCLES[cycle.kind]
        q = self._q_parameters(hole, code)
        parameters = (f"\n  Q{k}={signed(v, self.decimals)} ;{label}" for k, v, label in q)
        definition = f"CYCL DEF {code} {name}" + "".join(parameters)
        if definition != self.defined:
            self.defined = definition
            yield definition
        if self.position[2] != self.coordinate(hole.level):  # where an ISO canned cycle crosses over
            yield f"L Z{self.coordinate(hole.level)} R0 FMAX"
        yield f"L X{self.coordinate(hole.x)} Y{self.coordinate(hole.y)} R0 FMAX M99"

    def _q_parameters(self, hole: Hole, cycle_number: int) -> list[tuple[int, float, str]]:
        cycle = hole.cycle
        clearance, depth, second = hole.r - hole.top, hole.bottom - hole.top, hole.clear - hole.top
        head = [(200, clearance, "SET-UP CLEARANCE"), (201, depth, "DEPTH")]
        tail = [(203, hole.top, "SURFACE COORDINATE"), (204, second, "2ND SET-UP CLEARANCE")]
        if cycle_number == 207:
            return head + [(239, self.pitch(hole), "THREAD PITCH")] + tail
        feed = [(206, hole.feed, "FEED RATE FOR PLNGNG")]
        if cycle_number == 201:
            return head + feed + [(211, cycle.dwell, "DWELL TIME AT DEPTH"),
                                  (208, hole.feed, "RETRACTION FEED RATE"), *tail]  # fmt: skip
        if cycle_number == 200:
            return head + feed + [(202, -depth, "PLUNGING DEPTH"), (210, 0.0, "DWELL TIME AT TOP")] + tail + [
                (211, cycle.dwell, "DWELL TIME AT DEPTH")]  # fmt: skip
        if cycle_number == 203:  # a full retraction after every peck (Q213 = 0 chip breaks before it)
            return head + feed + [(202, cycle.step, "PLUNGING DEPTH"), (210, 0.0, "DWELL TIME AT TOP"), *tail,
                (212, 0.0, "DECREMENT"), (213, 0.0, "NR OF BREAKS"), (205, cycle.step, "MIN. PLUNGING DEPTH"),
                (211, 0.0, "DWELL TIME AT DEPTH"), (208, 0.0, "RETRACTION FEED RATE"),
                (256, BREAK, "DIST FOR CHIP BRKNG")]  # fmt: skip
        # 205: chip breaking every STEP, no full retraction before the bottom (Q202 the whole depth)
        return head + feed + [(202, -depth, "PLUNGING DEPTH")] + tail + [
            (212, 0.0, "DECREMENT"), (205, cycle.step, "MIN. PLUNGING DEPTH"),
            (258, BREAK, "UPPER ADV STOP DIST"), (259, BREAK, "LOWER ADV STOP DIST"),
            (257, cycle.step, "DEPTH FOR CHIP BRKNG"), (256, BREAK, "DIST FOR CHIP BRKNG"), (211, 0.0, "DWELL TIME AT DEPTH")]  # fmt: skip
