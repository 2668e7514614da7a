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
