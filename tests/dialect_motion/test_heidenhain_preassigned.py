"""Klartext's preassigned Q parameter Q108, the active tool radius, which the control sets at each
TOOL CALL to R (tool table or TOOL DEF) + DR (tool table) + DR (TOOL CALL) (TNC 320 User's Manual,
"Preassigned Q parameters").  Cycles written as programs read it (the face-milling program
`jstjst_Heidenhain-Cycles/Plan.h` of the corpus steps over by `Q1812 * Q108 * 2`)."""

import io
from dataclasses import replace
from pathlib import Path

import pytest

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import Line
from ncpp.motion.tools import ToolTable
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests.compensation.test_dialect_cutter_comp import TOOL_T  # tool 3: R 4.9 + DR 0.05

PROGRAM = """0 BEGIN PGM STEP MM
1 TOOL CALL 3 Z S1000 DR+0.05
2 Q1 = Q108 * 2
3 L X+Q1 Y+0 Z+5 R0 FMAX
4 Q108 = 7
5 L X+Q108 R0 FMAX
6 TOOL CALL 3 Z S1000
7 L X+Q108 R0 FMAX
8 END PGM STEP MM
"""


def ends_x(text: str, offsets: WorkOffsets, said: io.StringIO | None = None) -> list[float]:
    name, blocks = parse_program(io.BytesIO(text.encode()), "p.h", "heidenhain")
    interpret = dialect_tools(name)[0]
    warnings = Warnings(stream=said or io.StringIO())
    events = interpret(blocks, file="p.h", warnings=warnings, offsets=offsets)
    return [e.end[0] for e in events if isinstance(e, Line)]


def test_q108_is_the_called_tools_radius_until_the_program_sets_it(tmp_path: Path):
    (tmp_path / "TOOL.T").write_text(TOOL_T, encoding="latin-1")
    told = replace(WorkOffsets.at((0.0, 0.0, 0.0)), tools=ToolTable.from_file(tmp_path / "TOOL.T"))
    # (4.9 + 0.05 table) + 0.05 call, doubled; the program's own 7; the next TOOL CALL sets it anew
    assert ends_x(PROGRAM, told) == pytest.approx([10.0, 7.0, 4.95])


def test_without_the_tool_table_q108_is_not_guessed():
    said = io.StringIO()
    assert ends_x(PROGRAM, WorkOffsets.at((0.0, 0.0, 0.0)), said) == []
    assert (
        "p.h:3:3: warning: the parameter Q108 (the active tool radius, which ncpp is not told"
        in said.getvalue()
    )
