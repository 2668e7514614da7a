"""Sinumerik control flow (`ncpp/motion/sinumerik_flow.py`): the positions the loops and
jumps reach, worked out by hand from the 840D sl manual's rules; what a compensated program
with a loop writes; what leaves the scope."""

from __future__ import annotations

import io

import pytest

import ncpp.motion.sinumerik_flow as sinumerik_flow
from ncpp.errors import NcppError, Warnings
from ncpp.motion.flow import RUN, SKIP, TEXT
from ncpp.motion.segments import FLOW, Arc, Line, Pass
from ncpp.motion.sinumerik import SinumerikInterpreter, interpret
from ncpp.program.dialects import parse_program
from tests.writeback.conftest import SQUARE, compensate_file


def _run(text: str) -> tuple[list, str]:
    """(the events, the warnings) of a Sinumerik program's text."""
    warned = io.StringIO()
    _, blocks = parse_program(io.BytesIO(text.encode()), "flow.mpf", "sinumerik")
    events = list(interpret(blocks, file="flow.mpf", warnings=Warnings(stream=warned)))
    return events, warned.getvalue()


def _xs(events: list) -> list[float]:
    return [round(e.end[0], 6) for e in events if type(e) is Line or type(e) is Arc]


def test_for_loop_counts_to_its_end_inclusive():
    events, warned = _run("DEF INT I\nG1 F100\nFOR I=1 TO 3\nX=I*10\nENDFOR\nX=I\nM30\n")
    assert warned == ""
    assert _xs(events) == [10.0, 20.0, 30.0, 4.0]  # the variable leaves the loop one past its end


def test_repeat_runs_once_before_its_test_while_may_run_no_time():
    text = "R1=5\nG1 F100\nREPEAT\nX=R1\nR1=R1+1\nUNTIL R1>2\nWHILE R1<0\nX99\nENDWHILE\nY1\nM30\n"
    events, warned = _run(text)
    assert warned == "" and _xs(events) == [5.0, 5.0]
    assert [e.block.line for e in events if type(e) is Pass and e.skipped] == [
        8,
        9,
    ]  # the body that did not run, its end


def test_loop_left_by_a_forward_jump_is_refused_not_guessed():
    events, warned = _run("G1 F100\nLOOP\nX1\nGOTOF OUT\nENDLOOP\nOUT: X2\nM30\n")
    assert "flow.mpf:4:1: warning: GOTOF inside LOOP" in warned
    assert len(events) == 7  # every block written once


def test_nested_if_else_takes_one_branch():
    text = "R1=1\nG1 F100\nIF R1==1\nIF R1>5\nX9\nELSE\nX2\nENDIF\nELSE\nX8\nENDIF\nY3\nM30\n"
    events, warned = _run(text)
    assert warned == "" and _xs(events) == [2.0, 2.0]


def test_jumps_to_labels_and_block_numbers():
    text = (
        "R1=0\nG1 F100\nGOTOF N40\nX99\nN40 BACK: X=R1\nR1=R1+1\nIF R1<3 GOTOB BACK\nGOTOC NOWHERE\n"
        "CASE(R1) OF 2 GOTOF TWO 3 GOTOF THREE DEFAULT GOTOF TWO\nTWO: X77\nTHREE: Y5\nM30\n"
    )
    events, warned = _run(text)
    assert warned == "" and _xs(events) == [0.0, 1.0, 2.0, 2.0]
    # a backward jump among the first blocks: the blocks it runs again are left as programmed
    assert [e.fixed for e in events if type(e) is Line] == [FLOW, FLOW, FLOW, ""]


@pytest.mark.parametrize("jump", ["GOTOF NOWHERE", "GOTOB NOWHERE", "GOTO NOWHERE"])
def test_a_jump_to_a_label_not_found_ends_interpretation(jump):
    events, warned = _run(f"G1 X1 F100\n{jump}\nX2\nM30\n")
    assert "flow.mpf:2:1: warning: " in warned and "a jump destination not found" in warned
    assert _xs(events) == [1.0] and len(events) == 4


def test_a_backward_jump_past_the_read_ahead_over_compensated_moves_is_refused(monkeypatch):
    monkeypatch.setattr(sinumerik_flow, "_TRIM", 2)
    events, warned = _run("R1=0\nG1 F100\nBACK: X=R1\nR1=R1+1\nIF R1<3 GOTOB BACK\nM30\n")
    assert "flow.mpf:5:9: warning: GOTOB BACK, a backward jump over moves compensated" in warned
    assert _xs(events) == [0.0] and len(events) == 6


def test_a_loop_that_does_not_end_is_refused(monkeypatch):
    monkeypatch.setattr(sinumerik_flow, "MAX_RERUN", 100)
    with pytest.raises(NcppError, match="flow.mpf:4:1: a loop that does not end"):
        _run("G1 F100\nLOOP\nX1\nENDLOOP\nM30\n")


def test_memory_stays_bounded_on_a_long_program_with_a_loop(monkeypatch):
    monkeypatch.setattr(sinumerik_flow, "_TRIM", 10)
    loop = "R1=0\nWHILE R1<3\nX=R1\nR1=R1+1\nENDWHILE\n"
    text = "G1 F100\n" + "X1\nX2\n" * 200 + loop + "IF R1==3\n" + "Y1\nY2\n" * 200 + "ELSE\nX9\nENDIF\n"
    _, blocks = parse_program(io.BytesIO(text.encode()), "flow.mpf", "sinumerik")
    interpreter = SinumerikInterpreter("flow.mpf")
    flow = sinumerik_flow.SinumerikFlow("flow.mpf", interpreter.value, interpreter.assign,
                                        lambda: interpreter.done, None)  # fmt: skip
    held = 0
    kinds = []
    for block, kind, _owner in flow.steps(blocks):
        held = max(held, len(flow.buffer))
        kinds.append(kind)
        if kind in (RUN, sinumerik_flow.FIXED):
            interpreter.block(block)
    assert held <= 2 * 10 + 2  # (not the 800 blocks of the program)
    assert kinds.count(TEXT) == 4 and kinds.count(SKIP) == 2  # WHILE, ENDWHILE, IF, ELSE; X9, ENDIF
    assert interpreter.pos == [2.0, 2.0, 0.0]


def test_a_compensated_loop_is_written_once_as_programmed_and_the_moves_around_it_compensated(tmp_path):
    """The machine's X is off by -50 µm/m · Y: at Y200 a compensated X gains 0.0100."""
    loop = ["WHILE R1<2", "G1 X=20+R1 Y200", "", "; the next row", "R1=R1+1", "ENDWHILE"]
    program = tmp_path / "loop.mpf"
    program.write_text(
        "\n".join(["R1=0", "G90 G71", "G0 X10 Y200 Z5", *loop, "G1 X30 Y200 F500", "M30"]) + "\n"
    )
    warned = io.StringIO()
    output = compensate_file(program, SQUARE, tmp_path, dialect="sinumerik", warnings=Warnings(stream=warned))
    lines = output.read_text().splitlines()
    assert "loop.mpf:5:1: warning: loop or subroutine" in warned.getvalue()  # the user is told
    start = lines.index("WHILE R1<2")
    assert lines[start : start + 6] == loop and lines.count("WHILE R1<2") == 1  # its text once, as programmed
    assert "X10.0100" in " ".join(lines[:start])  # compensated before the loop
    assert lines[start + 6].startswith("G1 X30.0100")  # and after it (the blank line not written again)


def test_a_control_statement_with_more_in_its_block_ends_interpretation():
    events, warned = _run("G1 X1 F100\nR1=0\nWHILE R1<2\nR1=R1+1\nENDWHILE G1 X5\nX7\nM30\n")
    assert "flow.mpf:5:10: warning: ENDWHILE with more in its block" in warned
    assert _xs(events) == [1.0] and len(events) == 7  # every block written once


# Program section repetition (840D sl Job Planning, "Program section repetition (REPEAT, REPEATB,
# ENDLABEL, P)"): REPEAT ROW runs ROW's line to the line before it twice more, REPEATB one line
# twice more, REPEAT FIRST LAST the lines between the two labels once more; each then goes on
# after its REPEAT line.
SECTIONS = """G17 G90 G71
G0 X-5 Y-5 Z5
R1=0
ROW: R1=R1+10
G1 X=R1 Y0 Z-1 F200
Y=R1
REPEAT ROW P=2
G1 X50 Y=R1
STEP: G1 X=R1+100 Y-10
REPEATB STEP P=2
FIRST: R1=R1+1
G1 X=200+R1 Y-30
LAST: Y-40
G0 Z5
REPEAT FIRST LAST P=1
G1 X0 Y=R1
M30
"""
SECTION_ENDS = [(-5, -5, 5), (10, 0, -1), (10, 10, -1), (20, 0, -1), (20, 20, -1), (30, 0, -1), (30, 30, -1),
                (50, 30, -1), (130, -10, -1), (130, -10, -1), (130, -10, -1), (231, -30, -1), (231, -40, -1),
                (231, -40, 5), (232, -30, 5), (232, -40, 5), (0, 32, 5)]  # fmt: skip


def test_program_section_repetition_runs_each_section_its_p_times_more_then_goes_on():
    events, warned = _run(SECTIONS)
    ends = [tuple(round(v, 6) for v in e.end) for e in events if type(e) is Line]
    assert warned == "" and ends == SECTION_ENDS
    moves = [e for e in events if type(e) is Line]
    # the sections' runs are left as programmed, their second and later runs the REPEAT line's
    assert [m.block.line for m in moves if m.fixed == FLOW] == [5, 6, 7, 7, 7, 7, 9, 10, 10, 12, 13, 15, 15]
    assert not moves[7].fixed and not moves[-1].fixed and not moves[13].fixed  # (lines 8, 16, 14)


def test_a_section_ahead_of_its_repeat_runs_there_then_in_its_place():
    text = "G90 G1 F100\nX1\nREPEAT AHEAD BEYOND\nX2\nAHEAD: X3\nBEYOND: X4\nX5\nM30\n"
    events, warned = _run(text)
    assert warned == "" and _xs(events) == [1.0, 3.0, 4.0, 2.0, 3.0, 4.0, 5.0]


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("A: X1\nREPEAT A P=2 X5\n", "REPEAT with more in its block"),
        ("A: X1\nX2\nENDLABEL: X3\nREPEAT A P=2\n", "a section with ENDLABEL"),
        ("A: X1\nIF R1==0 GOTOF B\nB: X2\nREPEAT A P=2\n", "IF in a section a REPEAT runs"),
        ("REPEAT NOWHERE P=2\n", "REPEAT NOWHERE: the label is not found"),
        ("A: X1\nWHILE R1<1\nR1=R1+1\nREPEATB A\nENDWHILE\n", "REPEATB inside WHILE"),
        ("A: X1\nREPEAT A P=0.5\n", "REPEAT with P=0.5"),
    ],
)
def test_a_repetition_ncpp_does_not_follow_ends_interpretation(text, said):
    events, warned = _run("R1=0\nG90 G1 F100\n" + text + "X9\nM30\n")
    assert said in warned and 9.0 not in _xs(events)


def test_a_repetition_of_more_blocks_than_ncpp_follows_is_refused_before_it_runs():
    with pytest.raises(NcppError, match=r"flow.mpf:4:1: REPEAT P=1000000000: 2,000,000,000 blocks run again"):
        _run("G90 G1 F100\nA: X1\nX2\nREPEAT A P=1000000000\nM30\n")
