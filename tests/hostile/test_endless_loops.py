"""A loop that comes back to its head with the state it had at an earlier pass never ends: it is
refused there, at once, at the line that goes back; a loop whose state changes from pass to pass
(a counter, the position a move changes, a parameter a subroutine sets) runs to its end.

The bound on lines run again is lowered here (it is the old way of refusing these loops): a loop
refused by the state test is refused long before it, with its own message."""

from __future__ import annotations

import io

import pytest

import ncpp.motion.flow as flow
from ncpp.errors import NcppError
from ncpp.motion import interpret
from ncpp.motion.fanuc import FanucInterpreter, interpreting
from ncpp.motion.segments import Line
from ncpp.program.parser import parse_stream
from tests.conftest import SHARED

BOUND = 200_000  # lines run again: a loop refused by its state is refused long before
HEAD = "G21 G90 G17\nG0 X0 Y0 Z10 F200\n"
FANUC_HEAD = "%\nO1000\nG21 G90 G17\nG0 X0 Y0 Z5\n"


@pytest.fixture(autouse=True)
def _lower_bound(monkeypatch):
    monkeypatch.setattr(flow, "MAX_RERUN", BOUND)


def _iso(text: str) -> list:
    return list(interpret(parse_stream(io.BytesIO(text.encode()), "t.ngc"), file="t.ngc"))


def _fanuc(text: str) -> list:
    run = interpreting(FanucInterpreter)
    return list(run(parse_stream(io.BytesIO(text.encode()), "t.nc", "fanuc"), file="t.nc"))


def _refused_at(read, text: str, file: str, line: int, head: int) -> None:
    """`read(text)` refuses the loop at `line`, naming the loop's head, `head`."""
    with pytest.raises(
        NcppError, match=rf"a loop that does not end: it comes back to line {head} with"
    ) as err:
        read(text)
    assert (err.value.where.file, err.value.where.line) == (file, line)


def _ends(events: list) -> list[tuple[float, ...]]:
    return [tuple(round(v, 6) for v in e.end[:3]) for e in events if type(e) is Line]


ENDLESS_ISO = {
    "while": (HEAD + "o100 while [#9 EQ 0]\nG1 X1\nG1 X0\no100 endwhile\nM2\n", 6, 3),
    "do while": (HEAD + "o1 do\nG1 X1\nG1 X0\no1 while [#9 EQ 0]\nM2\n", 6, 3),
    "a parameter set to the same value": (
        HEAD + "o1 while [#1 LT 5]\n#1 = 2\nG1 X#1\no1 endwhile\nM2\n", 6, 3,
    ),
    "a toggle: the state of two passes before": (
        HEAD + "o1 while [#9 EQ 0]\n#1 = [1 - #1]\no2 if [#1 EQ 1]\nG1 X1\no2 else\nG1 X0\no2 endif\n"
        + "o1 endwhile\nM2\n",
        10, 3,
    ),
    "a subroutine call and a counted loop inside": (
        "o<s> sub\n#2 = [#1 + 1]\nG1 X#2\no<s> endsub\n" + HEAD
        + "o1 while [#9 EQ 0]\no<s> call [5]\no2 repeat [3]\nG1 Y1\nG1 Y0\no2 endrepeat\no1 endwhile\nM2\n",
        13, 7,  # (the loop that does not end, not the counted one inside it that repeats too)
    ),
    "incremental moves that come back": (HEAD + "G91\no1 while [#9 EQ 0]\nG1 X1\nG1 X-1\no1 endwhile\nM2\n", 7, 4),
    "inside a subroutine": (
        "o<s> sub\no1 while [#9 EQ 0]\nG1 X1\nG1 X0\no1 endwhile\no<s> endsub\n" + HEAD + "o<s> call\nM2\n", 5, 2,
    ),
}  # fmt: skip


@pytest.mark.parametrize("name", ENDLESS_ISO)
def test_an_iso_loop_back_at_a_state_it_had_is_refused_at_once(name):
    text, line, head = ENDLESS_ISO[name]
    _refused_at(_iso, text, "t.ngc", line, head)


ENDLESS_FANUC = {
    "WHILE [..] DO1": (
        FANUC_HEAD + "WHILE [#1 NE 2] DO1\nG1 X1 F100\nG1 X0\n#1 = 1\nEND1\nM30\n%\n",
        9,
        5,
    ),
    "IF [..] GOTO back": (FANUC_HEAD + "N10 G1 X1 F100\nG1 X0\nIF [#1 NE 2] GOTO 10\nM30\n%\n", 7, 5),
    "IF [..] GOTO back, a parameter set to the same value": (
        FANUC_HEAD + "#1 = 0\nN20 G1 X1 F100\nG1 X[#1 * 0]\nIF [#1 EQ 0] GOTO 20\nM30\n%\n",
        8,
        6,
    ),
}


@pytest.mark.parametrize("name", ENDLESS_FANUC)
def test_a_fanuc_loop_back_at_a_state_it_had_is_refused_at_once(name):
    text, line, head = ENDLESS_FANUC[name]
    _refused_at(_fanuc, text, "t.nc", line, head)


def test_a_loop_whose_counter_counts_for_ever_is_left_to_the_bound(monkeypatch):
    monkeypatch.setattr(flow, "MAX_RERUN", 20_000)
    with pytest.raises(NcppError, match="a loop that does not end: 20,000 lines run again"):
        _iso(HEAD + "o1 while [#1 GE 0]\nG1 X1\n#1 = [#1 + 1]\no1 endwhile\nM2\n")


WITHOUT_WAY_OUT = {  # a constant condition and nothing that leaves: refused at the end of the first pass
    "while [1] and a counter": (_iso, HEAD + "o1 while [1]\nG1 X1\n#1 = [#1 + 1]\no1 endwhile\nM2\n", 6, 3),
    "do ... while [2 GT 1]": (_iso, HEAD + "o1 do\n#1 = [#1 + 1]\nG1 X#1\no1 while [2 GT 1]\nM2\n", 6, 3),
    "a call whose body has no way out": (
        _iso, "o<s> sub\nG1 X#1\no<s> endsub\n" + HEAD + "o1 while [1]\n#2 = [#2 + 1]\no<s> call [#2]\n"
        "o1 endwhile\nM2\n", 9, 6,
    ),
    "Fanuc GOTO back and a counter": (
        _fanuc, FANUC_HEAD + "#1 = 0\nN10 #1 = #1 + 1\nG1 X#1 F100\nGOTO 10\nM30\n%\n", 8, 6,
    ),
    "Fanuc WHILE [1 EQ 1] and a counter": (
        _fanuc, FANUC_HEAD + "#1 = 0\nWHILE [1 EQ 1] DO1\n#1 = #1 + 1\nG1 X#1 F100\nEND1\nM30\n%\n", 9, 6,
    ),
}  # fmt: skip


@pytest.mark.parametrize("name", WITHOUT_WAY_OUT)
def test_a_while_of_a_constant_with_no_way_out_is_refused_after_its_first_pass(name):
    read, text, line, head = WITHOUT_WAY_OUT[name]
    with pytest.raises(
        NcppError, match=rf"does not end: the loop at line {head} has no condition that can end it"
    ) as err:
        read(text)
    assert err.value.where.line == line


WAYS_OUT = {  # the same loops, each with a way out the first pass does not take
    "a break": (_iso, HEAD + "o1 while [1]\n#1 = [#1 + 1]\nG1 X#1\no2 if [#1 GT 4]\no1 break\no2 endif\n"
                "o1 endwhile\nM2\n"),
    "a program end": (_iso, HEAD + "o1 while [1]\n#1 = [#1 + 1]\nG1 X#1\no2 if [#1 GT 4]\nM2\no2 endif\n"
                      "o1 endwhile\nM2\n"),
    "a return": (_iso, "o<s> sub\no1 while [1]\n#1 = [#1 + 1]\nG1 X#1\no2 if [#1 GT 4]\no<s> return\no2 endif\n"
                 "o1 endwhile\no<s> endsub\n" + HEAD + "o<s> call\nM2\n"),
    "a Fanuc jump out": (_fanuc, FANUC_HEAD + "#1 = 0\nWHILE [1 EQ 1] DO1\n#1 = #1 + 1\nG1 X#1 F100\n"
                         "IF [#1 GT 4] GOTO 10\nEND1\nN10 M30\n%\n"),
    "a Fanuc jump out of a GOTO loop": (_fanuc, FANUC_HEAD + "#1 = 0\nN10 #1 = #1 + 1\nG1 X#1 F100\n"
                                        "IF [#1 GT 4] GOTO 20\nGOTO 10\nN20 M30\n%\n"),
    "a Fanuc subprogram that ends the program": (
        _fanuc, FANUC_HEAD + "#1 = 0\nWHILE [1 EQ 1] DO1\n#1 = #1 + 1\nM98 P2000\nEND1\nM30\n%\n"
        "O2000\nG1 X#1 F100\nIF [#1 LT 5] GOTO 5\nM30\nN5 M99\n%\n",
    ),
}  # fmt: skip


@pytest.mark.parametrize("name", WAYS_OUT)
def test_a_while_of_a_constant_with_a_way_out_runs_to_its_end(name):
    read, text = WAYS_OUT[name]
    assert max(x for x, y, z in _ends(read(text))) == 5.0


def test_a_loop_with_a_counter_runs_to_its_end():
    events = _iso(HEAD + "#1 = 0\no1 while [#1 LT 3]\nG1 X1\nG1 X0\n#1 = [#1 + 1]\no1 endwhile\nG1 Y1\nM2\n")
    assert _ends(events)[-1] == (0.0, 1.0, 10.0) and len(_ends(events)) == 1 + 6 + 1


def test_a_loop_ended_by_the_position_its_moves_change_runs_to_its_end():
    """The condition reads the position (#<_x>) and nothing else changes: the position is state."""
    events = _iso(HEAD + "G91\no1 while [#<_x> LT 2.5]\nG1 X0.5\no1 endwhile\nG90 G1 Y1\nM2\n")
    assert [x for x, _, _ in _ends(events)] == [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 2.5]


def test_a_loop_ended_by_a_mode_it_changes_runs_to_its_end():
    events = _iso(HEAD + "o1 while [#<_feed> LT 203]\nF[#<_feed> + 1]\nG1 X1\no1 endwhile\nG1 Y1\nM2\n")
    assert len(_ends(events)) == 1 + 3 + 1


def test_a_loop_ended_by_a_global_a_subroutine_sets_runs_to_its_end():
    """The subroutine's own parameters come and go with each call; its global one counts."""
    text = ("o<s> sub\n#<_n> = [#<_n> + 1]\n#<local> = 1\n#1 = 7\no<s> endsub\n" + HEAD
            + "#<_n> = 0\no1 while [#<_n> LT 4]\no<s> call [3]\nG1 X1\nG1 X0\no1 endwhile\n"
            + "G1 Y1\nM2\n")  # fmt: skip
    assert len(_ends(_iso(text))) == 1 + 8 + 1


def test_a_toggle_that_a_counter_ends_runs_to_its_end():
    text = HEAD + ("o1 while [#2 LT 5]\n#1 = [1 - #1]\no2 if [#1 EQ 1]\nG1 X1\no2 else\nG1 X0\no2 endif\n"
                   "#2 = [#2 + 1]\no1 endwhile\nG1 Y1\nM2\n")  # fmt: skip
    assert [x for x, _, _ in _ends(_iso(text))] == [0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 1.0]


def test_a_fanuc_loop_ended_by_the_position_it_reads_runs_to_its_end():
    """#5001, the X of the last block's end point: the position is state."""
    text = FANUC_HEAD + "G1 X0 F100\nWHILE [#5001 LT 3] DO1\nG1 X[#5001 + 1]\nEND1\nG1 Y1\nM30\n%\n"
    assert [x for x, _, _ in _ends(_fanuc(text))] == [0.0, 0.0, 1.0, 2.0, 3.0, 3.0]


def test_a_fanuc_goto_loop_with_a_counter_runs_to_its_end():
    text = FANUC_HEAD + "#1 = 0\nN10 G1 X1 F100\nG1 X0\n#1 = [#1 + 1]\nIF [#1 LT 3] GOTO 10\nG1 Y1\nM30\n%\n"
    assert len(_ends(_fanuc(text))) == 1 + 6 + 1


def test_a_vacant_variable_is_not_the_zero_it_reads_as():
    """Fanuc: `#1 = #0` leaves #1 vacant, which EQ tells from 0: a loop that sets #1 to 0 and to
    vacant in turn changes its state."""
    text = FANUC_HEAD + ("#2 = 0\nWHILE [#2 LT 2] DO1\nIF [#1 EQ #0] THEN #2 = [#2 + 1]\n#1 = 0\nG1 X1 F100\n"
                         "END1\nG1 Y1\nM30\n%\n")  # fmt: skip
    with pytest.raises(NcppError, match="a loop that does not end: it comes back"):
        _fanuc(text)  # (#1 is 0 from the second pass on, #2 stays 1: it never ends)
    ended = text.replace("#1 = 0\n", "#1 = #0\n")
    assert len(_ends(_fanuc(ended))) == 1 + 2 + 1


def test_zero_and_minus_zero_are_different_states():
    from ncpp.motion.endless import exact

    assert exact(0.0) != exact(-0.0) and exact([1.0, -0.0]) != exact([1.0, 0.0])
    assert exact(float("nan")) != exact(float("nan"))


def _sinumerik(text: str) -> list:
    from ncpp.motion.sinumerik import interpret as run
    from ncpp.program.dialects import parse_program

    _, blocks = parse_program(io.BytesIO(text.encode()), "t.mpf", "sinumerik")
    return list(run(blocks, file="t.mpf"))


def _klartext(text: str) -> list:
    from ncpp.pipeline import dialect_tools
    from ncpp.program.dialects import parse_program

    run, _ = dialect_tools("heidenhain")
    _, blocks = parse_program(io.BytesIO(text.encode()), "t.h", "heidenhain")
    return list(run(blocks, file="t.h"))


SINUMERIK_HEAD = "G17 G90 G71 F200\nG0 X0 Y0 Z5\n"
ENDLESS_SINUMERIK = {
    # (the R parameters the loops read set first: one read before the program sets it is out of scope)
    "LOOP ... ENDLOOP": ("R9=0\nLOOP\nG1 X10 Y10\nIF R9>0\nM30\nENDIF\nG1 X0 Y0\nENDLOOP\nM30\n", 10, 5),
    "WHILE 1": ("R1=0 R2=0\nWHILE R1<5\nG1 X10\nR2=R2*0\nENDWHILE\nM30\n", 7, 4),
    "REPEAT ... UNTIL 0": ("R1=0\nREPEAT\nG1 X10\nG1 X0\nUNTIL R1>0\nM30\n", 7, 5),
    "GOTOB": ("R1=0\nBACK:\nR1=1-R1\nG1 X=R1*10\nGOTOB BACK\nM30\n", 7, 4),
}


@pytest.mark.parametrize("name", ENDLESS_SINUMERIK)
def test_a_sinumerik_loop_back_at_a_state_it_had_is_refused_at_once(monkeypatch, name):
    import ncpp.motion.sinumerik_flow as sinumerik_flow

    monkeypatch.setattr(sinumerik_flow, "MAX_RERUN", BOUND)
    text, line, head = ENDLESS_SINUMERIK[name]
    _refused_at(_sinumerik, SINUMERIK_HEAD + text, "t.mpf", line, head)


SINUMERIK_WITHOUT_WAY_OUT = {  # (the ISO and Fanuc ones: `WITHOUT_WAY_OUT`)
    "LOOP and a counter": ("R1=0\nLOOP\nR1=R1+1\nG1 X=R1\nENDLOOP\nM30\n", 7, 4),
    "WHILE TRUE and a counter": ("R1=0\nWHILE TRUE\nR1=R1+1\nG1 X=R1\nENDWHILE\nM30\n", 7, 4),
    "a message and a frame": ('R1=0\nLOOP\nMSG("X")\nTRANS X=R1\nR1=R1+1\nG1 X1\nENDLOOP\nM30\n', 9, 4),
}


@pytest.mark.parametrize("name", SINUMERIK_WITHOUT_WAY_OUT)
def test_a_sinumerik_loop_with_no_way_out_is_refused_after_its_first_pass(name):
    text, line, head = SINUMERIK_WITHOUT_WAY_OUT[name]
    with pytest.raises(NcppError, match=rf"does not end: the loop at line {head} has no condition") as err:
        _sinumerik(SINUMERIK_HEAD + text)
    assert err.value.where.line == line


def test_a_sinumerik_loop_left_by_the_program_end_runs_to_its_end():
    text = SINUMERIK_HEAD + "R1=0\nLOOP\nR1=R1+1\nG1 X=R1\nIF R1>4\nM30\nENDIF\nENDLOOP\nM30\n"
    assert max(x for x, _, _ in _ends(_sinumerik(text))) == 5.0


def test_a_sinumerik_loop_with_a_counter_or_a_toggle_it_ends_runs_to_its_end():
    text = SINUMERIK_HEAD + "R1=0\nR2=0\nWHILE R2<4\nR1=1-R1\nG1 X=R1*10\nR2=R2+1\nENDWHILE\nG1 Y5\nM30\n"
    assert [x for x, _, _ in _ends(_sinumerik(text))] == [0.0, 10.0, 0.0, 10.0, 0.0, 0.0]


KLARTEXT = """0 BEGIN PGM LOOP MM
1 TOOL CALL 1 Z S1000
2 L X+0 Y+0 Z+2 R0 FMAX
3 FN 0: Q1 = +0
4 LBL 2
5 L X+Q1 Y+20 R0 FMAX
6 FN 3: Q1 = +Q1 * +0
7 FN 9: IF +Q1 EQU +0 GOTO LBL 2
8 L Z+50 FMAX
9 END PGM LOOP MM
"""


def test_a_klartext_jump_back_at_a_state_it_had_is_refused_at_once(monkeypatch):
    from ncpp.motion import heidenhain_flow

    monkeypatch.setattr(heidenhain_flow, "MAX_RERUN", BOUND)
    _refused_at(_klartext, KLARTEXT, "t.h", 8, 5)


def test_a_klartext_jump_back_of_numbers_with_no_way_out_is_refused_at_once():
    text = KLARTEXT.replace("FN 3: Q1 = +Q1 * +0", "FN 1: Q1 = +Q1 + +5").replace("+Q1 EQU", "+0 EQU")
    with pytest.raises(NcppError, match=r"does not end: the loop at line 5 has no condition") as err:
        _klartext(text)
    assert err.value.where.line == 8


def test_a_klartext_jump_back_of_numbers_left_by_another_jump_runs_to_its_end():
    text = KLARTEXT.replace("FN 3: Q1 = +Q1 * +0", "FN 1: Q1 = +Q1 + +5\n6 FN 11: IF +Q1 GT +10 GOTO LBL 3")
    text = text.replace("+Q1 EQU", "+0 EQU").replace("8 L Z+50", "8 LBL 3\n8 L Z+50")
    assert max(x for x, y, z in _ends(_klartext(text)) if (y, z) == (20.0, 2.0)) == 10.0


def test_a_klartext_jump_back_whose_parameter_counts_runs_to_its_end():
    text = KLARTEXT.replace("FN 3: Q1 = +Q1 * +0", "FN 1: Q1 = +Q1 + +5").replace(
        "FN 9: IF +Q1 EQU +0", "FN 12: IF +Q1 LT +15"
    )
    assert [x for x, y, z in _ends(_klartext(text)) if (y, z) == (20.0, 2.0)] == [0.0, 5.0, 10.0]


MACHINE = SHARED / "machines/wide.toml"
PROGRAMS = {
    "while.ngc": (ENDLESS_ISO["while"][0], 6),
    "while.nc": (ENDLESS_FANUC["WHILE [..] DO1"][0], 9),
    "loop.mpf": (SINUMERIK_HEAD + ENDLESS_SINUMERIK["LOOP ... ENDLOOP"][0], 10),
    "jump.h": (KLARTEXT, 8),
}


@pytest.mark.skipif(not MACHINE.exists(), reason="no shared machine file")
@pytest.mark.parametrize("expand", [(), ("--expand",)], ids=["", "expand"])
@pytest.mark.parametrize("name", PROGRAMS)
def test_the_command_refuses_a_loop_back_at_a_state_it_had_in_seconds(ncpp, tmp_path, name, expand):
    """Not after the 5,000,000 lines run again of the bound (20 s to minutes a program)."""
    text, line = PROGRAMS[name]
    program = tmp_path / name
    program.write_text(text)
    out = tmp_path / f"out-{name}"
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), "-o", str(out), *expand, timeout=10)
    assert done.returncode == 2 and not out.exists()
    assert f"{program}:{line}:1: a loop that does not end: it comes back to line" in done.stderr.decode()
