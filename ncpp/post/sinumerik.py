"""SINUMERIK 840D: `;` comments, G2/G3 with incremental I J K (a helix adds
the third axis), `T1 M6` + `D1`, ends with M30."""

from __future__ import annotations

from typing import Iterator

from ncpp.post.iso import IsoGenerator


class SinumerikGenerator(IsoGenerator):
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
