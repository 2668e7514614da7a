"""Fanuc macro B control flow: GOTO, IF ... GOTO, IF ... THEN, WHILE ... DO ... END, G65 macro
calls, vacant variables, #3000 / #3006.

The rules are Fanuc's (the Fanuc operator's manuals, Series 16i/18i B-63684EN and 0i, "Custom
macro": "Branch and repetition", "Macro call", "Variables"); the oracle for the motion is
LinuxCNC's rs274 running the same program written with o-words (`o100 while`, `o100 if`, `o100 sub` with #1..): each
Fanuc program here has its LinuxCNC twin, and ncpp's moves of the one are rs274's of the other.
"""

from __future__ import annotations

import io
import random
import subprocess
import sys

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion import interpret
from ncpp.motion.canon import canon_call
from ncpp.motion.segments import FLOW, Line, Pass
from ncpp.pipeline import dialect_tools
from ncpp.program.parser import parse_stream
from tests.conftest import READING, ROOT, SHARED
from tests.motion.test_oracle import ours, read_canon, rs274, rs274_error, same_calls, write_program

HEAD = "G21 G90 G17\nG0 X0 Y0 Z5 F300\n"
PATHCHECK = SHARED / "tools" / "pathcheck"

# name: (Fanuc program, the same program for LinuxCNC)
TWINS = {
    # the manual's example: the sum of 1 to 10 with IF ... GOTO, each partial sum a move
    "sum with IF GOTO back": (
        "O0001\n" + HEAD + "#1=0\n#2=1\nN1 IF [#2 GT 10] GOTO 2\n#1=#1+#2\nG1 X#1\n#2=#2+1\nGOTO 1\n"
        "N2 G0 Y#1\nM30\n",
        HEAD + "#1=0\n#2=1\no1 while [#2 LE 10]\n#1=[#1+#2]\nG1 X#1\n#2=[#2+1]\no1 endwhile\nG0 Y#1\nM2\n",
    ),
    # the manual's example again, with WHILE
    "sum with WHILE": (
        "O0002\n" + HEAD + "#1=0\n#2=1\nWHILE [#2 LE 10] DO1\n#1=#1+#2\nG1 X#1 Y#2\n#2=#2+1\nEND1\nM30\n",
        HEAD + "#1=0\n#2=1\no1 while [#2 LE 10]\n#1=[#1+#2]\nG1 X#1 Y#2\n#2=[#2+1]\no1 endwhile\nM2\n",
    ),
    # WH for WHILE, the two characters a macro word may be cut to (Fanuc Series 0i-D operator's
    # manual B-64304EN, "Custom macro", "Abbreviations of custom macro words"), as a real
    # Fanuc 0i-MD macro writes it: `WH[[#1GE#2]OR[#1EQ#2]]DO1`
    "WH for WHILE": (
        HEAD + "#1=3\nWH[[#1GE1]OR[#1EQ0]]DO1\n#1=#1-1\nG1X#1\nEND1\nM30\n",
        HEAD + "#1=3\no1 while [[#1 GE 1] OR [#1 EQ 0]]\n#1=[#1-1]\nG1 X#1\no1 endwhile\nM2\n",
    ),
    # nested loops (DO1 around DO2), a grid of plunges
    "nested WHILE": (
        HEAD + "#10=0\nWHILE [#10 LT 3] DO1\n#11=0\nWHILE [#11 LT 2] DO2\nG0 X[#10*10] Y[#11*5]\n"
        "G1 Z-1\nG0 Z5\n#11=#11+1\nEND2\n#10=#10+1\nEND1\nM30\n",
        HEAD + "#10=0\no1 while [#10 LT 3]\n#11=0\no2 while [#11 LT 2]\nG0 X[#10*10] Y[#11*5]\n"
        "G1 Z-1\nG0 Z5\n#11=[#11+1]\no2 endwhile\n#10=[#10+1]\no1 endwhile\nM2\n",
    ),
    # a loop that runs no time, then a loop of the same number again (ids may be reused)
    "WHILE false, DO1 reused": (
        HEAD + "#1=5\nWHILE [#1 LT 3] DO1\nG1 X99\nEND1\nWHILE [#1 GT 3] DO1\nG1 X#1\n#1=#1-1\nEND1\nM30\n",
        HEAD + "#1=5\no1 while [#1 LT 3]\nG1 X99\no1 endwhile\no2 while [#1 GT 3]\nG1 X#1\n#1=[#1-1]\n"
        "o2 endwhile\nM2\n",
    ),
    # forward jumps: IF ... GOTO over moves, a computed GOTO#10, GOTO out of a loop
    "forward and computed GOTO": (
        HEAD + "#10=30\nIF [#10 EQ 30] GOTO 20\nG1 X99\nN20 G1 X1\nGOTO#10\nN25 G1 X98\nN30 G1 Y2\n"
        "#1=0\nWHILE [1 EQ 1] DO1\n#1=#1+1\nG1 Z-#1\nIF [#1 GE 3] GOTO 40\nEND1\nN40 G0 Z5\nM30\n",
        HEAD + "#10=30\nG1 X1\nG1 Y2\n#1=0\no1 while [1 EQ 1]\n#1=[#1+1]\nG1 Z-#1\no2 if [#1 GE 3]\n"
        "o1 break\no2 endif\no1 endwhile\nG0 Z5\nM2\n",
    ),
    # IF ... THEN: one assignment, when the condition holds
    "IF THEN": (
        HEAD + "#1=2\n#2=0\nIF [#1 EQ 2] THEN #2=7\nIF [#1 NE 2] THEN #2=9\nG1 X#2\n"
        "IF [[#1 GT 1] AND [#2 LT 8]] THEN #3=#1+#2\nG1 Y#3\nM30\n",
        HEAD + "#1=2\n#2=7\nG1 X#2\n#3=[#1+#2]\nG1 Y#3\nM2\n",
    ),
    # a bolt-hole circle macro called with G65 and arguments (X Y: centre, R: radius,
    # A: first angle, B: angle step, H: holes, Z: depth), its locals its own (#1 of the
    # caller comes back); the LinuxCNC twin passes them in the order #1.. of its sub
    "G65 bolt-hole circle": (
        HEAD + "#1=77\nG65 P9100 X50. Y20. R15. A0 B60. H6 Z-3.\nG65 P9100 X-10. Y0 R5. A45. B90. H4 Z-1.\n"
        "G0 X#1\nM30\n"
        "O9100 (BOLT HOLE CIRCLE)\n#30=0\nWHILE [#30 LT #11] DO1\n#31=#1+#30*#2\n"
        "G0 X[#24+#18*COS[#31]] Y[#25+#18*SIN[#31]]\nG1 Z#26\nG0 Z5\n#30=#30+1\nEND1\nM99\n",
        HEAD + "#1=77\no100 sub\n#30=0\no101 while [#30 LT #6]\n#31=[#4+#30*#5]\n"
        "G0 X[#1+#3*COS[#31]] Y[#2+#3*SIN[#31]]\nG1 Z#7\nG0 Z5\n#30=[#30+1]\no101 endwhile\no100 endsub\n"
        "o100 call [50] [20] [15] [0] [60] [6] [-3]\no100 call [-10] [0] [5] [45] [90] [4] [-1]\n"
        "G0 X#1\nM2\n",
    ),
    # G65 ... L3: the macro runs three times, with the locals it left (the arguments set once)
    "G65 L repeats": (
        HEAD + "G65 P200 L3 X1 Z-2\nM30\nO200\nG1 X#24 Z#26\n#24=#24+1\nM99\n",
        HEAD + "G1 X1 Z-2\nG1 X2 Z-2\nG1 X3 Z-2\nM2\n",
    ),
    # vacant arguments: IF [#i EQ #0] tells a left-out argument from one given as 0, and an
    # address whose value is vacant is no address (`X#24` with no X moves no X)
    "vacant arguments": (
        HEAD + "G65 P300 X0 Y4\nG65 P300 Y6\nM30\n"
        "O300\nIF [#24 EQ #0] GOTO 1\nG1 X#24\nGOTO 2\nN1 G1 X9\nN2 G1 X#24 Y#25\nM99\n",
        HEAD + "G1 X0\nG1 X0 Y4\nG1 X9\nG1 Y6\nM2\n",
    ),
    # G66: the macro is called after each block that moves, with the G66 block's arguments,
    # until G67; the G66 block, a block that does not move and the macro's own moves call nothing
    "G66 modal call": (
        HEAD + "G67\nG66 P9200 Z-2 R1 F50\nG0 X10 Y10\nM8\nX20\nG67\nG0 X30\nM30\n"
        "O9200\nG0 Z#18\nG1 Z#26 F#9\nG0 Z5\nM99\n",
        HEAD + "G0 X10 Y10\nG0 Z1\nG1 Z-2 F50\nG0 Z5\nM8\nG0 X20\nG0 Z1\nG1 Z-2\nG0 Z5\nG0 X30\nM2\n",
    ),
    # G66 in a loop: the blocks of its second pass that do not move call nothing
    "G66 in a loop": (
        HEAD + "G66 P9 Z-1.\n#1=0\nWHILE [#1 LT 2] DO1\nG0 X#1\n#1=#1+1\nEND1\nG67\nM30\n"
        "O9\nG1 Z#26\nG0 Z5\nM99\n",
        HEAD + "G0 X0\nG1 Z-1\nG0 Z5\nG0 X1\nG1 Z-1\nG0 Z5\nM2\n",
    ),
    # argument specification II: A, then four sets of I J K (#4-#6, #7-#9, #10-#12, #13-#15), the
    # points of a polyline the macro visits with #[4 + 3 n]; G66 passes them alike
    "G65 argument specification II": (
        HEAD + "G65 P600 A4. I10. J5. K-1. I20. J15. K-2. I30. J0 K-1.5 I5. J-5. K-0.5\n"
        "G66 P600 A2. I1. J1. K-1. I2. J-1. K-2.\nG0 X40 Y40\nG67\nM30\n"
        "O600\n#30=0\nWHILE [#30 LT #1] DO1\nG1 X#[4+3*#30] Y#[5+3*#30] Z#[6+3*#30] F200\n#30=#30+1\nEND1\n"
        "G0 Z5\nM99\n",
        HEAD + "o600 sub\n#30=0\no601 while [#30 LT #1]\nG1 X#[4+3*#30] Y#[5+3*#30] Z#[6+3*#30] F200\n"
        "#30=[#30+1]\no601 endwhile\nG0 Z5\no600 endsub\n"
        "o600 call [4] [0] [0] [10] [5] [-1] [20] [15] [-2] [30] [0] [-1.5] [5] [-5] [-0.5]\n"
        "G0 X40 Y40\no600 call [2] [0] [0] [1] [1] [-1] [2] [-1] [-2]\nM2\n",
    ),
    # M98 inside a G65 macro shares the macro's locals
    "M98 in a G65 macro": (
        HEAD + "G65 P400 A3\nM30\nO400\nM98 P401\nG1 X#1\nM99\nO401\n#1=#1*2\nG1 Y#1\nM99\n",
        HEAD + "G1 Y6\nG1 X6\nM2\n",
    ),
}


def _pair(tmp_path, name: str):
    fanuc, linuxcnc = TWINS[name]
    program = tmp_path / "fanuc.nc"
    program.write_text(fanuc)
    return program, write_program(tmp_path, linuxcnc, "twin.ngc")


def _events(text: str, **kwargs) -> list:
    return list(interpret(parse_stream(io.BytesIO(text.encode()), "t.nc"), file="t.nc", **kwargs))


def _warned(text: str) -> tuple[list, str]:
    stream = io.StringIO()
    events = _events(text, warnings=Warnings(stream=stream))
    return events, stream.getvalue()


@pytest.mark.parametrize("name", TWINS)
def test_fanuc_macros_move_as_rs274_runs_their_o_word_twins(tmp_path, name):
    program, twin = _pair(tmp_path, name)
    calls, messages = rs274(str(twin))
    assert rs274_error(messages) is None, messages
    reference = read_canon(calls)
    mine, error, warning = ours(program)
    assert error is None and not warning, (error, warning)
    assert len(mine) == len(reference) and same_calls(reference, mine), (reference, mine)


@pytest.mark.parametrize("name", TWINS)
def test_every_fanuc_block_is_written_once_where_it_stands(name):
    text = TWINS[name][0]
    groups, last = [], None
    events, warned = _warned(text)
    assert not warned  # (read, not passed through unread)
    for event in events:
        if event.block is not last:
            groups.append(event.block.text)
            last = event.block
    assert "".join(groups) == text


def test_moves_that_run_again_are_left_as_programmed():
    """A loop's moves, a backward GOTO's from their first pass, a macro's: FIXED; the rest not."""
    for name in ("sum with IF GOTO back", "sum with WHILE", "G65 bolt-hole circle", "G66 modal call"):
        moves = [e for e in _events(TWINS[name][0]) if type(e) is not Pass]
        looped = [m for m in moves if m.fixed == FLOW]
        assert looped and all(not m.fixed for m in moves if m not in looped)
    moves = [e for e in _events(TWINS["sum with IF GOTO back"][0]) if type(e) is Line]
    assert [m.fixed == FLOW for m in moves] == [False] + [True] * 10 + [False]  # (G0 at the top, G0 Y after)


def test_the_manual_sum_ends_with_55():
    events = _events(
        "O0001\n#1=0\n#2=1\nN1 IF [#2 GT 10] GOTO 2\n#1=#1+#2\n#2=#2+1\nGOTO 1\nN2 G0 X#1\nM30\n"
    )
    (move,) = [e for e in events if type(e) is Line]
    assert move.end[0] == 55.0


@pytest.mark.parametrize(
    "text, line, message",
    [
        (HEAD + "END1\n", 3, "END1 without WHILE ... DO1"),
        (HEAD + "WHILE [1 EQ 1] DO4\nEND4\n", 3, "a loop's number is 1, 2 or 3"),
        (HEAD + "GOTO 0\n", 3, "a sequence number is 1 to 99999"),
        (HEAD + "GOTO 7\nN8 G0 X1\n", 3, "the program has no block N7"),
        (HEAD + "GOTO 5\nWHILE [1 EQ 1] DO1\nN5 G0 X1\nEND1\n", 3, "jumps into the loop WHILE ... DO1"),
        (
            HEAD + "WHILE [1 EQ 1] DO1\nWHILE [1 EQ 1] DO2\nEND1\nEND2\n",
            5,
            "END1 closes DO1 across the loop DO2",
        ),
        (
            HEAD + "WHILE [1 EQ 1] DO1\nWHILE [1 EQ 1] DO1\nEND1\nEND1\n",
            4,
            "nested loops take different numbers",
        ),
        (HEAD + "G65 P9 L0\nM30\nO9\nM99\n", 3, "G65 L0: a macro runs 1 to 9999 times"),
        (
            HEAD + "G65 P9\nM30\nO9\nIF [#24 EQ #0] THEN #3000=1 (X MISSING)\nM99\n",
            6,
            "macro alarm 3001: X MISSING",
        ),
    ],
)
def test_refused_as_the_control_alarms(text, line, message):
    with pytest.raises(NcppError) as err:
        _events(text)
    assert err.value.where.line == line and message in err.value.message, err.value


def test_a_stop_with_a_message_is_no_error():
    """#3006 = 1 (MESSAGE) stops the control as M0 does; the program goes on."""
    events, warned = _warned("O1\n" + HEAD + "IF [1 EQ 1] GOTO 5\nN5 #3006=1 (TURN THE PART)\nG1 X4\nM30\n")
    assert not warned and [e.end[0] for e in events if type(e) is Line][-1] == 4.0


def test_3000_is_an_alarm_in_a_fanuc_program_a_parameter_in_a_linuxcnc_one():
    with pytest.raises(NcppError) as err:
        _events("O1\n" + HEAD + "GOTO 2\nN2 #3000=4 (NO TOOL)\nG1 X#3000\nM30\n")
    assert err.value.where.line == 5 and err.value.message == "macro alarm 3004: NO TOOL"
    events = _events(HEAD + "#3000=4 (NO TOOL)\nG1 X#3000\nM2\n")
    assert [e.end[0] for e in events if type(e) is Line][-1] == 4.0


def test_a_fanuc_programs_system_variables_are_out_of_scope():
    """#5021 is where the machine stands, which the operator may have jogged it to; #2001 a tool
    offset: read as a plain parameter (0) they would be a guess.  #1 set from #5021 is as unknown:
    the IF that reads it is where interpretation ends."""
    _, warned = _warned("O1\n" + HEAD + "#1=#5021\nIF [#1 GT 0] GOTO 3\nN3 G1 X#1\nM30\n")
    assert (
        "t.nc:5:1: warning: #1, which line 4 set from the control's system variable #5021 is outside"
        in warned
    )
    _, warned = _warned("O1\n" + HEAD + "#2001=0.1\nWHILE [0 EQ 1] DO1\nEND1\nM30\n")
    assert "t.nc:4:1: warning: a write to the control's system variable #2001" in warned


def test_a_backward_goto_past_the_read_ahead_over_moves_run_once_is_out_of_scope(monkeypatch):
    """Beyond the blocks read ahead at the start, a backward GOTO would run again a move passed
    on as run once (its text may be rewritten for that one run): ncpp stops following."""
    import ncpp.motion.flow as flow

    monkeypatch.setattr(flow, "_TRIM", 4)
    body = "#1=0\nG0 X1\nG0 X2\nN10 G1 X#1\n#1=#1+1\nIF [#1 LT 3] GOTO 10\nG0 Y5\nM30\n"
    text = "O1\nIF [#1 EQ 1] GOTO 99\n" + HEAD + body  # (a macro statement read ahead: a Fanuc program)
    events, warned = _warned(text)
    assert "t.nc:10:1: warning: GOTO 10 back over moves that ran once in their place" in warned
    assert type(events[-2]) is Pass and events[-2].block.text == "G0 Y5\n"
    # a program whose first macro statement comes past the blocks read ahead: no moves were noted
    _, warned = _warned("O1\n" + HEAD + body)
    assert "t.nc:9:1: warning: GOTO 10 back, the program's first macro statement past the 4 blocks" in warned
    monkeypatch.setattr(flow, "_TRIM", 4096)  # read ahead: the loop is seen, its moves FIXED
    events, warned = _warned(text)
    assert not warned and [e.end[0] for e in events if type(e) is Line and e.fixed == FLOW] == [0, 1, 2]


def test_a_goto_whose_target_is_no_longer_held_is_out_of_scope():
    body = "".join(f"G1 X{i % 50} Y{i % 7}\n" for i in range(3 * 4096))
    _, warned = _warned("O1\n" + HEAD + "N5 G0 Z5\n" + body + "#1=1\nIF [#1 EQ 1] GOTO 5\nM30\n")
    assert "GOTO 5: N5 is further back than the blocks ncpp holds" in warned


def test_memory_stays_flat_with_fanuc_loops():
    """A long program of WHILE loops and forward GOTOs: blocks are held only for a loop, and a
    window back for a GOTO."""
    from ncpp.motion.flow import _TRIM
    from ncpp.motion.interpreter import Interpreter, run

    piece = "#1=0\nWHILE [#1 LT 2] DO1\nG1 X#1\n#1=#1+1\nEND1\nIF [#1 EQ 2] GOTO {n}\nG1 X99\nN{n} G0 Z1\n"
    body = "".join(piece.format(n=n + 1) for n in range(6000))
    interpreter = Interpreter("t.nc")
    seen = []
    events = run(interpreter, parse_stream(io.BytesIO(("O1\n" + body).encode()), "t.nc"), None, True)
    for n, _ in enumerate(events):
        if n % 1000 == 0:
            seen.append(len(interpreter.flow.buffer))  # type: ignore[union-attr]
    assert n > 6000 * 5 and max(seen) <= 3 * _TRIM


def test_the_block_end_position_is_read_where_a_move_placed_the_axis():
    """#5001-#5003: the end point of the last block, work coordinates (Fanuc's position
    information); known once a move has put the axis at a programmed position, and not at the
    start or after a program stop, where the operator may move the machine."""
    top = "O1\nIF [#1 NE #0] GOTO 9\n"  # (a macro statement: a Fanuc program)
    body = "G21 G90 G0 X10 Y20\nG1 X12 F100\n#1=#5001\n#2=#5002\nG1 X[#1+1] Y[#2+1]\nN9 M30\n"
    events, warned = _warned(top + body)
    assert not warned and [e.end[:2] for e in events if type(e) is Line][-1] == (13.0, 21.0)
    for text, line in (  # (#1, set from what ncpp does not know, stops where a move reads it)
        (top + "G0 X1\n#1=#5003\nG0 Z#1\nN9 M30\n", 4),
        (top + "G0 X1 Z2\nM0\n#1=#5001\nG0 Z#1\nN9 M30\n", 5),
        (top + "G0 X1\nG92 X0\n#1=#5001\nG0 Z#1\nN9 M30\n", 5),
        (top + "#2=#0\nG0 X1 Y#2\n#1=#5002\nG0 Z#1\nN9 M30\n", 5),
    ):
        _, warned = _warned(text)
        whence = f"#1, which line {line} set from the control's system variable #500"
        assert f"t.nc:{line + 1}:4: warning: {whence}" in warned
    # a program that may be LinuxCNC's (no macro statement): #5001 is a parameter as rs274 reads it
    events = _events("O1\nG0 X1\n#5001=3\nG0 Y#5001\nM30\n")
    assert [e.end[1] for e in events if type(e) is Line] == [0.0, 3.0]


def test_a_vacant_variable_copies_as_vacant():
    """`#2 = #1` with #1 vacant leaves #2 vacant; `#2 = #1 + 0` makes it 0 (Fanuc's table)."""
    text = (
        "O1\n"
        + HEAD
        + "#2=#1\n#3=#1+0\nIF [#2 EQ #0] GOTO 8\nG1 X99\nN8 IF [#3 EQ #0] GOTO 9\nG1 Y7\nN9 M30\n"
    )
    events = _events(text)
    assert [(e.end[0], e.end[1]) for e in events if type(e) is Line][-1] == (0.0, 7.0)


def test_compensation_leaves_the_loops_and_the_macro_and_corrects_the_moves_that_run_once():
    from tests.motion.compensating import compensate

    text = TWINS["sum with IF GOTO back"][0]
    out, warned = compensate(text, "t.nc")
    body = text.splitlines()[3:10]  # #1=0 ... GOTO 1: the loop and its set-up, as programmed
    assert "\n".join(body) in out and "t.nc:8:1: warning: loop or subroutine" in warned
    last = out.splitlines()[-2]
    assert last.startswith("N2 G0 Y55.0") and "#" not in last  # the move after the loop: corrected
    out, _ = compensate(TWINS["G65 bolt-hole circle"][0], "t.nc")
    assert TWINS["G65 bolt-hole circle"][0].split("M30\n")[1] in out  # the macro's text as it was
    assert "G0 X77.0" in out  # `G0 X#1` after the calls: the caller's #1 again, corrected


def test_a_macros_backward_goto_leaves_the_main_programs_moves_to_compensation():
    """A macro after M30 numbers its blocks as it likes: its backward GOTO to N1 is its own N1,
    not the main program's, whose moves run once and are corrected."""
    text = HEAD + "N1 G1 X1\nG65 P500 A2\nG1 X3\nM30\nO500\nN1 G1 Y#1\n#1=#1-1\nIF [#1 GT 0] GOTO 1\nM99\n"
    moves = [e for e in _events(text) if type(e) is Line]
    assert [(m.end[0], m.end[1], m.fixed == FLOW) for m in moves] == [
        (0.0, 0.0, False),
        (1.0, 0.0, False),
        (1.0, 2.0, True),
        (1.0, 1.0, True),
        (3.0, 1.0, False),
    ]


def test_a_move_in_a_subprogram_under_g66_is_out_of_scope():
    """Whether the control calls the modal macro after a move of a subprogram the G66 frame
    calls is not ncpp's to guess."""
    text = HEAD + "G66 P9 Z-1\nM98 P8\nM30\nO8\nG0 X1\nM99\nO9\nG1 Z#26\nM99\n"
    events, warned = _warned(text)
    assert "t.nc:7:1: warning: a move in a subprogram or macro called while G66 is in effect" in warned
    _, warned = _warned(HEAD + "G66 P9 Z-1\nG66 P9 Z-2\nM30\nO9\nM99\n")
    assert "t.nc:4:1: warning: G66 while a G66 modal call is in effect" in warned


def test_a_macro_goes_on_past_its_first_m99_to_the_next_program():
    """A Fanuc program is all its blocks to the next program number or %: a GOTO finds the
    alarm after the macro's first M99 (as Haas's O0300 example does)."""
    macro = "O9300\nIF [#1 EQ #0] GOTO 10\nG1 X#1\nM99\nN10 #3000=1 (A MISSING)\nM99\n"
    events = _events(HEAD + "G65 P9300 A1.\nM30\n" + macro + "%\n")
    assert [e.end[0] for e in events if type(e) is Line][-1] == 1.0
    with pytest.raises(NcppError) as err:
        _events(HEAD + "G65 P9300 A1.\nG65 P9300\nM30\n" + macro + "O9301\nM99\n")
    assert err.value.where.line == 10 and err.value.message == "macro alarm 3001: A MISSING"
    # what follows may be the main program's (it ends with M30): not the macro's
    _, warned = _warned(HEAD + "G65 P9300\n" + macro + "G0 X5\nM30\n")
    assert "t.nc:5:1: warning: GOTO 10: no N10 in the subprogram" in warned


def _random_twins(rng: random.Random) -> tuple[str, str]:
    """A random Fanuc macro program of nested WHILE loops, IF ... THEN, IF ... GOTO over blocks
    and IF ... GOTO back loops, with moves, and the same program in o-words for rs274."""
    numbers, labels, counters = iter(range(10, 9000, 10)), iter(range(100, 900)), iter(range(110, 199))
    fanuc, twin = (
        ["O0100", "G21 G90 G17", "G0 X0 Y0 Z5 F100", "#101=0"],
        ["G21 G90 G17", "G0 X0 Y0 Z5 F100", "#101=0"],
    )

    def both(*lines: str) -> None:
        fanuc.extend(lines)
        twin.extend(lines)

    def statements(depth: int) -> None:
        for _ in range(rng.randint(1, 3)):
            kind = rng.choice(
                ["move", "move", "assign", "then", "while", "skip", "back"]
                if depth < 3
                else ["move", "assign", "then"]
            )
            if kind == "move":
                both(
                    f"{rng.choice(['G1', 'G0', ''])} X[#101*2+{rng.randint(-3, 3)}] Y{rng.uniform(-3, 3):.3f}"
                )
            elif kind == "assign":
                k = rng.randint(1, 3)
                fanuc.append(f"#101=#101+{k}")
                twin.append(f"#101=[#101+{k}]")
            elif kind == "then":
                k, j, label = rng.randint(0, 6), rng.randint(1, 3), next(labels)
                fanuc.append(f"IF [#101 GT {k}] THEN #101=#101-{j}")
                twin.extend([f"o{label} if [#101 GT {k}]", f"#101=[#101-{j}]", f"o{label} endif"])
            elif kind == "while":
                c, k, label, m = next(counters), rng.randint(0, 3), next(labels), depth + 1
                both(f"#{c}=0")
                fanuc.append(f"WHILE [#{c} LT {k}] DO{m}")
                twin.append(f"o{label} while [#{c} LT {k}]")
                statements(depth + 1)
                fanuc.extend([f"#{c}=#{c}+1", f"END{m}"])
                twin.extend([f"#{c}=[#{c}+1]", f"o{label} endwhile"])
            elif kind == "skip":
                k, n, label, z = rng.randint(0, 6), next(numbers), next(labels), rng.randint(1, 9)
                fanuc.append(f"IF [#101 LT {k}] GOTO {n}")
                twin.extend([f"o{label} if [#101 LT {k}]", f"o{label} else"])
                statements(depth + 1)
                fanuc.append(f"N{n} G0 Z{z}")
                twin.extend([f"o{label} endif", f"G0 Z{z}"])
            else:  # a loop back with IF ... GOTO: a do-while in o-words
                c, k, n, label, z = (
                    next(counters),
                    rng.randint(1, 3),
                    next(numbers),
                    next(labels),
                    rng.randint(1, 9),
                )
                both(f"#{c}=0")
                fanuc.append(f"N{n} G1 Z{z}")
                twin.extend([f"o{label} do", f"G1 Z{z}"])
                statements(depth + 1)
                fanuc.extend([f"#{c}=#{c}+1", f"IF [#{c} LT {k}] GOTO {n}"])
                twin.extend([f"#{c}=[#{c}+1]", f"o{label} while [#{c} LT {k}]"])

    statements(0)
    return "\n".join(fanuc + ["M30"]) + "\n", "\n".join(twin + ["M2"]) + "\n"


def test_random_fanuc_macros_move_as_rs274_runs_their_o_word_twins(tmp_path):
    """40 random programs: ncpp's moves of the Fanuc one are rs274's of the o-word one, call by
    call, and every block is written once where it stands."""
    rng, moves = random.Random(20261127), 0
    for n in range(40):
        fanuc, twin = _random_twins(rng)
        program, reference_program = tmp_path / f"random{n}.nc", tmp_path / f"random{n}.ngc"
        program.write_text(fanuc)
        reference_program.write_text(twin)
        calls, messages = rs274(str(reference_program))
        assert rs274_error(messages) is None, (twin, messages)
        reference = read_canon(calls)
        mine, error, warning = ours(program)
        assert error is None and not warning, (fanuc, error, warning)
        assert len(mine) == len(reference) and same_calls(reference, mine), (fanuc, twin)
        assert "".join(block.text for block in _written(fanuc)) == fanuc
        moves += len(mine)
    assert moves > 200


def _written(text: str) -> list:
    """The blocks of the events, each run of one block's events once: what passthrough writes."""
    blocks, last = [], None
    for event in _events(text):
        if event.block is not last:
            blocks.append(event.block)
            last = event.block
    return blocks


def test_m98_runs_a_program_kept_in_a_file_of_the_subroutine_path(tmp_path):
    """A Fanuc control keeps each program under its number; on a PC a file `O9010.nc` holds
    it.  The twin defines the same lines as an o-word subroutine in its own file."""
    from ncpp.motion.offsets import WorkOffsets

    folder = tmp_path / "programs"
    folder.mkdir()
    (folder / "O9010.nc").write_text("%\nO9010 (PIERCE)\nG0 Z1\nG1 Z-0.5 F50\nG0 Z1\nM99\n%\n")
    program = write_program(tmp_path, "O1000\n" + HEAD + "G0 X10 Y10\nM98 P9010\nG1 X50\nM98 P9010 L2\nG0 X0\nM30\n",
                            "main.nc")  # fmt: skip
    twin = write_program(tmp_path, "o9010 sub\nG0 Z1\nG1 Z-0.5 F50\nG0 Z1\no9010 endsub\n" + HEAD
                         + "G0 X10 Y10\no9010 call\nG1 X50\no9010 call\no9010 call\nG0 X0\nM2\n", "twin.ngc")  # fmt: skip
    reference = read_canon(rs274(str(twin))[0])
    mine, error, warning = ours(program, offsets=WorkOffsets.given({}, subroutine_path=[folder]))
    assert error is None and not warning, (error, warning)
    assert len(mine) == len(reference) and same_calls(reference, mine), (reference, mine)
    # without the path, or without the file there, the call is out of scope and said so
    _, error, warning = ours(program, offsets=WorkOffsets.given({}, subroutine_path=[tmp_path]))
    assert (
        f"M98 P9010: a subprogram the program does not define (O9010 to M99), nor is it in {tmp_path}"
        in warning
    )
    # G65's says where it looked too (`G65P3003...` of dennisselyaev/gcode 3.nc, its file not on the path)
    macro = write_program(tmp_path, "O1000\n" + HEAD + "G65 P9010 X1.\nM30\n", "macro.nc")
    _, error, warning = ours(macro, offsets=WorkOffsets.given({}, subroutine_path=[tmp_path]))
    assert (
        f"G65 P9010: a macro the program does not define (O9010 to M99), nor is it in {tmp_path}" in warning
    )


def test_a_program_file_without_its_number_is_an_error_at_the_file(tmp_path):
    from ncpp.motion.offsets import WorkOffsets

    (tmp_path / "O0012.nc").write_text("%\nO0013\nG0 Z1\nM99\n%\n")
    program = write_program(tmp_path, "O1000\n" + HEAD + "M98 P12\nM30\n", "main.nc")
    _, error, _ = ours(program, offsets=WorkOffsets.given({}, subroutine_path=[tmp_path]))
    assert (
        error is not None and "O12 ... M99 is not in the file" in str(error) and "O0012.nc:1:1" in str(error)
    )


@pytest.mark.parametrize(
    "text, why",
    [
        (
            "%\nG91 G1 Z-1 F100\nM99\n%\n",
            "the file has no O line, and ncpp runs a file for a call of O1002 only",
        ),
        ("%\nO1003\nG91 G1 Z-1 F100\nM99\n%\n", "its program is O1003, not O1002"),
        ("%\nO1002\nG91 G1 Z-1 F100\nM30\n%\n", "O1002 has no M99 after it"),
    ],
)
def test_a_program_file_named_for_a_number_it_does_not_give_says_what_it_holds(tmp_path, text, why):
    """`O1002.nc` on the subroutine path with no `O1002` line (no Fanuc or Haas manual says a control
    takes the number from the file's name), or another program's, or O1002 without M99: an error at
    the file that says which."""
    from ncpp.motion.offsets import WorkOffsets

    (tmp_path / "O1002.nc").write_text(text)
    program = write_program(tmp_path, "O1000\n" + HEAD + "M98 P1002\nM30\n", "main.nc")
    _, error, _ = ours(program, offsets=WorkOffsets.given({}, subroutine_path=[tmp_path]))
    assert error is not None and "O1002.nc:1:1" in str(error), error
    assert f"O1002 ... M99 is not in the file: {why}" in str(error), error


def test_a_program_above_its_files_first_percent_is_said_to_stand_in_the_leader(tmp_path):
    """`O1002 ... M99 %` with no `%` above it (as a PC may keep a program): the control reads the text
    before the first `%` as the tape's leader and skips it; the error said only that O1002 is not in
    the file, where it plainly stands."""
    from ncpp.motion.offsets import WorkOffsets

    (tmp_path / "O1002.nc").write_text("O1002\nG91 G1 Z-1 F100\nM99\n%\n")
    program = write_program(tmp_path, "O1000\n" + HEAD + "M98 P1002\nM30\n", "main.nc")
    _, error, _ = ours(program, offsets=WorkOffsets.given({}, subroutine_path=[tmp_path]))
    assert (
        error is not None
        and "O1002 ... M99 is not in the file: it stands above the file's first `%`" in str(error)
    )


# A macro that moves to the first local variables of each I J K set: X#4 Y#7 Z#10, X#13 Y#16 Z#19,
# X#22 Y#25 Z#28, X#31 Y#5 Z#33, vacant ones left out of the move (Fanuc: no address)
SETS_MACRO = "O700\nG1 X#4 Y#7 Z#10 F100\nG1 X#13 Y#16 Z#19\nG1 X#22 Y#25 Z#28\nG1 X#31 Y#5 Z#33\nM99\n"


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_ncpp_motion_prints_the_points_a_specification_ii_call_sets(tmp_path, capsys, dialect):
    """Ten sets I1 J1 K1 ... I10 J10 K10 (I of set n = n, J = 10 n, K = -n): set n is #(3n+1),
    #(3n+2), #(3n+3) (Fanuc B-63684EN, "Argument specification II")."""
    from ncpp.cli import main

    sets = " ".join(f"I{n}. J{10 * n}. K-{n}." for n in range(1, 11))
    program = tmp_path / "sets.nc"
    program.write_text(f"O1\nG21 G90 G17\nG0 X0 Y0 Z0\nG65 P700 A1. {sets}\nM30\n{SETS_MACRO}")
    assert main(["motion", "--dialect", dialect, str(program)]) == 0
    # #4 = I1, #7 = I2, #10 = I3; #13 = I4, #16 = I5, #19 = I6; #22 = I7, #25 = I8, #28 = I9;
    # #31 = I10, #5 = J1, #33 = K10
    want = [(0, 0, 0), (1, 2, 3), (4, 5, 6), (7, 8, 9), (10, 10, -10)]
    printed = capsys.readouterr().out.splitlines()
    assert printed == [
        f"{'STRAIGHT_TRAVERSE' if n == 0 else 'STRAIGHT_FEED'}({x:.4f}, {y:.4f}, {z:.4f}, 0.0000, 0.0000, 0.0000)"
        for n, (x, y, z) in enumerate(want)
    ]


def test_the_later_specification_sets_a_variable_both_give():
    """The manual's mixture: `G65 A1.0 B2.0 I-3.0 I4.0 D5.0 P1000` leaves #1 1, #2 2, #4 -3, #5
    and #6 vacant, #7 5.0 (D, written after the second I) (B-63684EN, "Mixture of argument
    specifications I and II"); written the other way round, the second I's 4.0."""
    macro = "O1000\nIF [#5 NE #0] GOTO 9\nIF [#6 NE #0] GOTO 9\nG1 X#1 Y#2 Z#4 F100\nG1 X#7\nN9 M99\n"
    for arguments, last in (("A1.0 B2.0 I-3.0 I4.0 D5.0", 5.0), ("A1.0 B2.0 D5.0 I-3.0 I4.0", 4.0)):
        events = _events(f"{HEAD}G65 {arguments} P1000\nM30\n{macro}")
        assert [e.end for e in events if type(e) is Line][-2:] == [(1.0, 2.0, -3.0), (last, 2.0, -3.0)]


@pytest.mark.parametrize(
    "arguments, said",
    [
        ("J1. I2.", "G65 with I J K arguments out of order (I number 1 in set 2)"),
        ("I1. J2. I3. K4.", "G65 with I J K arguments out of order (K number 1 in set 2)"),
        (" ".join(["I1. J2. K3."] * 11), "G65 with more than 10 sets of I J K arguments"),
    ],
)
def test_i_j_k_sets_that_cannot_be_told_apart_leave_the_scope(arguments, said):
    _, warned = _warned(f"{HEAD}G65 P700 {arguments}\nM30\n{SETS_MACRO}")
    assert f"t.nc:3:1: warning: {said}" in warned


def test_i_j_k_repeat_only_in_a_macro_call():
    """A move, M98 or G67 with two I words is refused as before (rs274: "Multiple i words")."""
    for block in ("G2 X1 Y0 I0.5 I0.5 J0", "M98 P700 I1 I2", "G67 I1 I2"):
        with pytest.raises(NcppError, match="Multiple i words on one line"):
            _events(f"O1\n{HEAD}{block}\nM30\n{SETS_MACRO}")


@pytest.mark.parametrize(
    "program, line",
    [  # mojimould/mould_moji, Created_NC_Programs/main_program_examples/O80000001 (a horizontal MC's Fanuc):
     # a sensor input (#1000-#1015) decides the branch
     ("%\nO80000001\nG21 G90\nG0 X0 Y0 Z5\nN0002\nIF[#1005EQ0]GOTO0003\nM00 (sensor low battery)\nN0003\n"
      "G1 X10 F100\nM30\n%\n", 6),
     ("%\nO1\nG21 G90\nG0 X0 Y0 Z5\nWHILE[#1004EQ0]DO1\nG1 X10 F100\nEND1\nM30\n%\n", 5),
     ("G21 G90\nG0 X0 Y0 Z5\no1 if [#<_hal[motion.probe-input]> EQ 0]\nG1 X10 F100\no1 endif\nM2\n", 3)],
)  # fmt: skip
def test_a_control_line_whose_value_ncpp_is_not_told_ends_interpretation_there(program, line):
    """The branch an input signal or a HAL pin decides is not followed: from that line the program
    passes through with a warning (it stopped with a traceback), the moves before it followed."""
    said = io.StringIO()
    found = list(interpret(parse_stream(io.BytesIO(program.encode()), "p.nc"), file="p.nc",
                           warnings=Warnings(stream=said)))  # fmt: skip
    assert f"p.nc:{line}:1: warning: " in said.getvalue() and "outside the motion interpreter's scope" in (
        said.getvalue()
    )
    assert [type(e) for e in found if type(e) is Line] == [Line]
    assert all(type(e) is Pass for e in found if e.block.line >= line)


# A cycle of L0 (no hole: its data kept) and its holes in a subprogram (cncci.com, "Two applications for L0":
# "sets up the canned cycle but does not drill a hole"; Peter Smid's main program with a subprogram,
# `G99 G82 R2.5 Z-3.4 P200 F200.0 L0`), which rs274 refuses ("Cannot do zero repeats of cycle"); the twin
# drills the first hole in the cycle's block, and stands still where the L0 block stands (ncpp gives that
# block a move of no length, where a step to the programmed point may go before it)
STORED_CYCLE = (
    "%\nO0003\n" + HEAD + "G0 X1. Y2.\nG99 G81 R2.5 Z-3.4 F200. L0\nM98 P1002\nG0 X0 Y0\nM30\n%\n"
    "O1002\nX7. Y7.\nX39.\nY45.\nG98 X7.\nG80\nM99\n%\n",
    HEAD + "G0 X1 Y2\nG0 X1 Y2\nG99 G81 X7 Y7 R2.5 Z-3.4 F200\nX39\nY45\nG98 X7\nG80\nG0 X0 Y0\nM2\n",
)


def test_a_cycle_of_l0_stores_its_data_for_the_holes_a_subprogram_gives(tmp_path):
    program = tmp_path / "fanuc.nc"
    program.write_text(STORED_CYCLE[0])
    calls, messages = rs274(str(write_program(tmp_path, STORED_CYCLE[1], "twin.ngc")))
    assert rs274_error(messages) is None, messages
    reference = read_canon(calls)
    stream = io.StringIO()
    interpret_fanuc, _ = dialect_tools("fanuc")
    blocks = parse_stream(io.BytesIO(STORED_CYCLE[0].encode()), str(program), "fanuc")
    events = interpret_fanuc(blocks, file=str(program), warnings=Warnings(stream=stream))
    mine = [call for call in map(canon_call, events) if call is not None]
    assert not stream.getvalue()
    assert len(mine) == len(reference) and same_calls(reference, mine), (reference, mine)


@pytest.mark.parametrize(
    "block, said",
    [("G81 X5. R2.5 Z-3.4 F200. L0", "canned cycle G81 of 0 repeats with a hole position"),
     ("G98 G87 R-3. Z2. I1. L0", "Fanuc's back boring G87 of 0 repeats")],
)  # fmt: skip
def test_a_cycle_of_l0_with_a_hole_position_is_out_of_scope(block, said):
    """What a Fanuc control does with the X Y of an L0 block is not in ncpp's references: out of scope."""
    stream = io.StringIO()
    interpret_fanuc, _ = dialect_tools("fanuc")
    blocks = parse_stream(io.BytesIO(f"{HEAD}M3 S100\n{block}\nM30\n".encode()), "t.nc", "fanuc")
    events = list(interpret_fanuc(blocks, file="t.nc", warnings=Warnings(stream=stream)))
    assert said in stream.getvalue() and type(events[-1]) is Pass


def test_l0_is_refused_in_a_linuxcnc_program():
    with pytest.raises(NcppError, match="Cannot do zero repeats of cycle"):
        _events(HEAD + "G81 R2.5 Z-3.4 F200 L0\nX7 Y7\nM2\n")


def test_a_program_with_a_cycle_of_l0_is_compensated_and_steps_back_before_it(tmp_path):
    """The subprogram's holes run twice, left as programmed: the step to the programmed point before them
    comes before the L0 block, in G0, where a G0 between it and the call cancelled the cycle (the
    verifier refused the written program: "the written path leaves the original's")."""
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(STORED_CYCLE[0].replace("M98 P1002\n", "M98 P1002\nM98 P1002\n"))
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(READING), str(program),
                           "-o", str(out)], capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    written = out.read_text()
    assert "G99 G81 R2.5 Z-3.4 F200. L0\nM98 P1002\n" in written
    lines = written.splitlines()
    stored = lines.index("G99 G81 R2.5 Z-3.4 F200. L0")
    assert lines[stored - 1].startswith(("X", "Y", "Z")), written  # the step, in G0 (the mode before)


def test_holes_after_a_cycle_of_l0_in_straight_code_are_compensated(tmp_path):
    """The holes after the L0 block, in the main program, are compensated hole by hole, without a word of
    canned cycles left as programmed; judged by rs274 on twins that drill the first hole in the cycle block
    (pathcheck, 0.02 mm)."""
    text = "%\nO0004\nG21 G90 G17\nG0 X1. Y2. Z25.\nG98 G81 R2.5 Z-3.4 F200. L0\nX7. Y7.\nX39.\nY45.\nG80\nM30\n%\n"
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(READING), str(program),
                           "-o", str(out)], capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "warning" not in proc.stderr and "left as programmed: nothing" in proc.stderr, proc.stderr
    written = out.read_text()
    if not PATHCHECK.exists():
        pytest.skip("pathcheck not available")
    stored = "G98 G81 R2.5 Z-3.4 F200. L0\n"
    before = tmp_path / "before.ngc"
    before.write_text(text.replace(stored, "").replace("X7. Y7.\n", "G98 G81 X7. Y7. R2.5 Z-3.4 F200.\n"))
    head, tail = written.split(stored)
    after = tmp_path / "after.ngc"
    after.write_text(head + "G98 G81 F200. " + tail)
    check = subprocess.run([sys.executable, str(PATHCHECK), str(before), str(after), "--tol-mm", "0.02"],
                           capture_output=True, text=True, timeout=600)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr
