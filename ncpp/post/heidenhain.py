"""HEIDENHAIN Klartext (conversational): `BEGIN PGM` ... `END PGM`, numbered blocks.

Lines are `L X+.. Y+.. Z+.. R0 F..|FMAX`; arcs are a centre `CC` followed by
`C X.. Y.. DR+|DR-` (DR+ counter-clockwise, as G3); a helix is
`CP IPA±angle IZ±rise DR±` about the same `CC`.  The tool is called with
its speed (`TOOL CALL 1 Z S9000`), so a tool change waits for the spindle
record or the first move.
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Iterator

from ncpp.motion.segments import PLANE_AXES, Arc, Event, Line
from ncpp.post.generator import Generator, SetupLookup, number

AXES = "XYZ"


def signed(value: float, decimals: int) -> str:
    text = number(value, decimals)
    return text if text.startswith("-") else "+" + text


class HeidenhainGenerator(Generator):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.pending_tool: int | None = None

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
        yield f"L {words} R0" + (" FMAX" if line.rapid else self._feed(line))

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
