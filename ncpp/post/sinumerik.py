"""SINUMERIK 840D: `;` comments, G2/G3 with incremental I J K (a helix adds
the third axis), `T1 M6` + `D1`, ends with M30.  A hole is `G0 X.. Y..` over it
and the drilling cycle called there (CYCLE81 drill, CYCLE82 with a dwell, CYCLE83
deep or chip-breaking, CYCLE84 rigid tapping, CYCLE85 boring), with the retract
plane RTP, the reference plane RFP (the hole's top), the safety distance SDIS and
the final depth DP, absolute; a dwell is `G4 F` seconds."""

from __future__ import annotations

from collections.abc import Iterator

from ncpp.cldata.cycles import Hole
from ncpp.post.generator import number
from ncpp.post.iso import IsoGenerator


class SinumerikGenerator(IsoGenerator):
    grammar = "sinumerik"
    tape_marks = False
    keep_point = False

    def emit_header(self) -> Iterator[str]:
        if self.job.header:
            yield from self.emit_comment(self.job.header)
        yield from self.emit_comment(self.job.name)
        yield f"G17 G40 G90 G94 {'G70' if self.job.inch else 'G71'}"
        self.plane = 17

    def emit_comment(self, text: str) -> Iterator[str]:
        yield "; " + text

    def emit_tool(self, tool: int) -> Iterator[str]:
        yield f"T{tool} M6"
        yield "D1"

    def emit_dwell(self, seconds: float) -> Iterator[str]:
        yield f"G4 F{number(seconds, 3)}"

    def emit_cycle_off(self) -> Iterator[str]:
        self.motion = None
        return iter(())  # each hole calls its cycle: none stays active (no MCALL)

    def emit_hole(self, hole: Hole) -> Iterator[str]:
        if self.position[2] != self.coordinate(hole.level):  # where an ISO canned cycle crosses over
            yield f"G0 Z{self.coordinate(hole.level)}"
        words = ["G0", f"X{self.coordinate(hole.x)}", f"Y{self.coordinate(hole.y)}"]
        if hole.feed != self.feed:
            self.feed = hole.feed
            words.append(f"F{number(hole.feed, 3)}")
        self.motion = 0
        yield " ".join(words)
        yield self._call(hole)

    def _call(self, hole: Hole) -> str:
        cycle = hole.cycle
        c = self.coordinate
        planes = [c(hole.clear), c(hole.top), c(hole.r - hole.top), c(hole.bottom), ""]  # RTP RFP SDIS DP DPR
        dwell = number(cycle.dwell, 3) if cycle.dwell else ""
        if cycle.kind in ("DEEP", "BRKCHP"):  # FDEP FDPR DAM DTB DTS FRF VARI (1: out to clear the chips)
            first = c(hole.top - cycle.step)
            vari = "1" if cycle.kind == "DEEP" else "0"
            return f"CYCLE83({', '.join(planes + [first, '', c(cycle.step), dwell, '', '1', vari])})"
        if cycle.kind == "TAP":  # DTB SDAC MPIT PIT POSS SST: M3 after, the pitch, the speed
            pitch, speed = c(self.pitch(hole)), number(self.rpm or 0, 0)
            return f"CYCLE84({', '.join(planes + [dwell, '3', '', pitch, '', speed])})"
        if cycle.kind in ("BORE", "REAM"):  # DTB FFR RFF: feed in and out
            feed = number(hole.feed, 3)
            return f"CYCLE85({', '.join(planes + [dwell, feed, feed])})"
        if dwell:
            return f"CYCLE82({', '.join(planes + [dwell])})"
        return f"CYCLE81({', '.join(planes[:4])})"
