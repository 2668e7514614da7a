"""Sinumerik blocks in machine coordinates (G53, G153, SUPA) and the settable frame in effect.

840D sl Programming Manual, Fundamentals, "Frame suppression (G53, G153, SUPA)": the block's
coordinates are the machine's (ncpp assumes no basic frame and no external offsets), the tool
offset still applies unless the block says D0; "Settable zero offset (G54 to G57, G505 to G599,
G500)": G500 turns the settable frame off."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import MACHINE, Line
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program

ZERO = (100.0, 200.0, 300.0)


def lines(text: str, warnings: Warnings | None = None) -> list[Line]:
    interpret, _ = dialect_tools("sinumerik")
    _, blocks = parse_program(io.BytesIO(text.encode()), "p.mpf", "sinumerik")
    found = interpret(blocks, file="p.mpf", warnings=warnings or Warnings(stream=io.StringIO()),
                      offsets=WorkOffsets.at(ZERO))  # fmt: skip
    return [event for event in found if type(event) is Line]


@pytest.mark.parametrize("block", ["G0 SUPA Z0 D0", "G0 G53 Z0 D0", "G0 G153 Z0 D0"])
def test_a_move_in_machine_coordinates_is_left_as_programmed_and_followed(block):
    moves = lines(f"G54 G90\nG0 X10 Y20 Z5\n{block}\nG0 X30\nM30\n")
    retract = moves[1]
    assert retract.fixed == MACHINE and retract.placed == (False, False, True)
    assert retract.end == (10.0, 20.0, -ZERO[2]) and retract.context.to_machine(retract.end)[2] == 0.0
    assert not moves[2].fixed and moves[2].start == retract.end


def test_a_move_under_another_settable_frame_than_the_first_ends_interpretation():
    said = io.StringIO()
    moves = lines("G500 G90\nG54\nG0 X10 Y20 Z5\nG55\nG0 X30\nM30\n", Warnings(stream=said))
    assert len(moves) == 1 and "a move under G55 (ncpp is told the zero of G54)" in said.getvalue()
    said = io.StringIO()
    assert lines("G500\nG0 X1\nG54\nG0 X2\n", Warnings(stream=said)) == []
    assert "a move under G500" in said.getvalue()
    assert len(lines("G54\nG0 X1\nG500\nG54\nG0 X2\n")) == 2  # (G500 with no move under it)


def test_cycle800_and_cycle832_that_move_nothing_are_read_past():
    text = "CYCLE800()\nCYCLE832(0.01,_ROUGH,1)\nG54\nG0 X1 Y2 Z3\nCYCLE832()\nG1 X4 F100\nM30\n"
    said = io.StringIO()
    assert len(lines(text, Warnings(stream=said))) == 2 and "scope" not in said.getvalue()
    lines('CYCLE800(1,"TABLE",200000,57,0,0,0,0,0,0,0,0,0,-1,100,1)\nG0 X1\n', Warnings(stream=said))
    assert "call CYCLE800" in said.getvalue()


@pytest.mark.parametrize("block", ["COMPCAD", "STOPRE", "TRAFOOF", "ORIWKS", "FGROUP()", "DIAMOF",
                                   'WORKPIECE(,"",,"BOX",0,0,-50,-80,0,0,100,100)'])  # fmt: skip
def test_what_cam_posts_write_that_moves_no_axis_is_read_past(block):
    said = io.StringIO()
    assert len(lines(f"G54\n{block}\nG0 X1 Y2 Z3\nM30\n", Warnings(stream=said))) == 1
    assert "scope" not in said.getvalue()


def test_program_block_markers_of_the_operate_editor_are_read_past():
    """`GROUP_BEGIN(0,"NAGLOWEK",0,0)` ... `GROUP_END(0,0)` frame each step of a program written in
    SINUMERIK Operate's editor (a hand program, index id 9982440370: every line after its first
    GROUP_BEGIN passed through uncompensated).  They are the editor's program blocks, which group
    lines for display and move no axis (SINUMERIK Operate Milling operating manual, "Creating program
    blocks"): the moves are those of the program without them, and nothing is warned."""
    body = "G0 X10 Y20 Z5\nG1 Z-1 F200\nX40 Y25\n"
    said = io.StringIO()
    grouped = lines(f'G54\nGROUP_BEGIN(0,"FACE TOP",0,0)\n{body}GROUP_END(0,0)\nM30\n', Warnings(stream=said))
    assert said.getvalue() == ""
    assert [m.end for m in grouped] == [m.end for m in lines(f"G54\n{body}M30\n")]
    assert len(grouped) == 3


@pytest.mark.parametrize("word", ["FNORM", "FLIN", "FCUB"])
def test_a_feedrate_profile_is_read_past(word):
    """`N60 G17 G710 G94 G90 FNORM` heads a CAM program for an 840D sl
    (121philip/SINUMERIK-840D-sl-CAS-Package, `Approach A/CAM TEST.MPF`).  FNORM, FLIN and FCUB shape
    the feedrate along a block, not its path (840D sl Programming Manual, Fundamentals, "Feedrate
    characteristic (FNORM, FLIN, FCUB)"): the moves are those of the program without the word, and
    nothing is warned (before, the word ended interpretation)."""
    said = io.StringIO()
    body = "G0 X10 Y20 Z5\nG1 Z-1 F200\nX40 Y25\nM30\n"
    with_word = lines(f"G54 G17 G710 G94 G90 {word}\n{body}", Warnings(stream=said))
    assert said.getvalue() == ""
    assert [m.end for m in with_word] == [m.end for m in lines(f"G54 G17 G710 G94 G90\n{body}")]
    assert len(with_word) == 3
