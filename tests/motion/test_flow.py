"""O-word control flow (subroutines, branches, loops) against LinuxCNC's rs274, and in compensation.

The corpus has LinuxCNC's own o-word programs (run by test_oracle.py); these
cover each construct, parameters local to a call, return values, a call
before the definition, nesting, the errors rs274 stops at, how the events
belong to the text (each block written once, where it stands), and what
compensation does with them.
"""

from __future__ import annotations

import io
import random
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion import interpret
from ncpp.motion.flow import _TRIM, Flow
from ncpp.motion.segments import FLOW, Arc, Line, Pass
from ncpp.program.parser import parse_stream
from tests import rs274 as oracle
from tests.conftest import ROOT, RS274
from tests.motion.compensating import compensate
from tests.motion.test_oracle import (
    assert_agrees_with_rs274,
    assert_refused_like_rs274,
    ours,
    read_canon,
    rs274,
    rs274_error,
    same_calls,
    write_program,
)

HEAD = "G21 G90 G17\nG0 X0 Y0 Z10 F200\n"
SQUARE = "o<square> sub\n  G1 X#1 Y#2\n  G1 X[#1+#3]\n  G1 Y[#2+#3]\n  G1 X#1\n  G1 Y#2\no<square> endsub\n"

AGREE = {
    "a subroutine, arguments": HEAD
    + SQUARE
    + "o<square> call [1] [2] [5]\no<square> call [10] [2] [3]\nG0 X#1\n",
    "call before definition": HEAD
    + "o200 call [3]\nG0 Y#<_value>\nM2\no200 sub\n G1 X#1\n o200 return [#1*2]\no200 endsub\n",
    "local names, global names": HEAD
    + "#<a> = 1\n#<_g> = 2\no1 sub\n #<a> = 7\n #<_g> = [#<_g> + 1]\n G0 X#<a> Y#<_g>\no1 endsub\no1 call\nG0 X#<a> Y#<_g>\n",
    "value without return": HEAD
    + "o1 sub\n o1 return [5]\no1 endsub\no2 sub\no2 endsub\no1 call\nG0 X#<_value>\no2 call\nG0 Y#<_value>\n",
    "if elseif else": HEAD
    + "#1 = 2\no10 if [#1 EQ 1]\n G0 X1\no10 elseif [#1 EQ 2]\n G0 X2\no10 elseif [#1 EQ 2]\n G0 X3\no10 else\n G0 X4\no10 endif\nG0 Y1\n",
    "if without else, false": HEAD + "o10 if [0]\n G0 X1\no10 endif\nG0 Y1\n",
    "while": HEAD + "#1 = 0\no20 while [#1 LT 4]\n G1 X#1 Y[#1*#1]\n #1 = [#1 + 1]\no20 endwhile\nG0 Z1\n",
    "while that never runs": HEAD + "o20 while [0]\n G1 X9\no20 endwhile\nG0 Z1\n",
    "break out of a while in a do loop (rs274ngc: ends the do loop too)": HEAD
    + "#1 = 3\no1 do\n #1 = [#1 - 1]\n G0 X#1\n o2 while [1]\n  G0 Y7\n  o2 break\n o2 endwhile\no1 while [#1 GT 0]\nG0 Z9\n",
    "continue in a do loop, then a break (rs274ngc: loops once more)": HEAD
    + "#1=0\no2 do\n#1=[#1+1]\nG0 X#1\no3 if [#1 LT 3]\no2 continue\no3 endif\nG0 Y#1\no2 while [#1 LT 5]\n#2=0\no4 while [#2 LT 2]\n#2=[#2+1]\no4 break\no4 endwhile\nG0 Z#2\n",
    "a while without endwhile at the end of the file": HEAD + "G0 X1\no1 while [0]\nG0 X2\n",
    "do while": HEAD + "#1 = 5\no30 do\n G1 X#1\n #1 = [#1 - 2]\no30 while [#1 GT 0]\nG0 Z1\n",
    "repeat": HEAD + "G91\no40 repeat [3]\n G1 X1 Y0.5\n G2 X1 Y0 I0.5 J0\no40 endrepeat\nG90 G0 X0\n",
    "break and continue": HEAD
    + "#1 = 0\no50 while [1]\n #1 = [#1 + 1]\n o51 if [#1 EQ 2]\n  o50 continue\n o51 endif\n G0 X#1\n o52 if [#1 GE 4]\n  o50 break\n o52 endif\no50 endwhile\nG0 Y#1\n",
    "nested loops in a subroutine": HEAD
    + "o<grid> sub\n #<i> = 0\n o1 while [#<i> LT #1]\n  #<j> = 0\n  o2 repeat [#2]\n   G0 X#<i> Y#<j>\n   #<j> = [#<j> + 1]\n  o2 endrepeat\n  #<i> = [#<i> + 1]\n o1 endwhile\no<grid> endsub\no<grid> call [3] [2]\nG0 X0 Y0\n",
    "recursion": HEAD
    + "o<f> sub\n o1 if [#1 LE 1]\n  o<f> return [1]\n o1 endif\n o<f> call [#1 - 1]\n o<f> return [#1 * #<_value>]\no<f> endsub\no<f> call [5]\nG0 X#<_value>\n",
    "a call in a loop": HEAD
    + SQUARE
    + "#<k> = 0\no5 while [#<k> LT 3]\n o<square> call [#<k>*10] [0] [4]\n #<k> = [#<k> + 1]\no5 endwhile\nG0 X0 Y0\n",
    "o[expr] call": HEAD + "o100 sub\n G0 X7\no100 endsub\n#2 = 10\no[#2 * 10] call\n",
    "a loop in the main program after a subroutine definition": HEAD
    + "o9 sub\n G0 Z#1\no9 endsub\no8 repeat [2]\n o9 call [2]\n G1 X5\no8 endrepeat\n",
    "fanuc subprogram, repeats": HEAD + "M98 P1 L3\nG0 X0\nM30\nO1\nG91 G1 X1 Y0.5\nG90\nM99\n",
    "fanuc: a program number, P expression": "O1000\n"
    + HEAD
    + "M98 P2000 L2\nM98 P[1000*2]\nG0 X9\nM30\nO2000\nG91 G1 X1 F100\nG90\nM99\n",
    "fanuc: nested, #1-#30 shared, names scoped": HEAD
    + "#1 = 3\n#<a> = 5\nM98 P10 L2\nG0 X#1 Y#<_bb>\nG0 Z#<a>\nM30\nO10\n#1 = [#1 + 1]\n#<_bb> = 7\nM98 P11\nM99\nO11\n#<a> = 1\nG0 X#1 Y#<a>\nM99\n",
    "fanuc: L0 runs nothing": HEAD + "#1 = 1\nM98 P9 L0\nG0 X#1\nM30\nO9\nG0 Y1\nM99\n",
    "fanuc: the first of two definitions": HEAD + "M98 P0002\nM30\nO0002\nG0 X1\nM99\nO2\nG0 X2\nM99\n",
    "calls nine levels deep": HEAD
    + "o<f> sub\n o1 if [#1 GT 0]\n  G0 X#1\n  o<f> call [#1 - 1]\n o1 endif\no<f> endsub\no<f> call [8]\n",
    "block-deleted control lines run (the switch is off; was: o-word lines passed through)": HEAD
    + "#1 = 1\n/o1 sub\nG1 X1\n/o1 endsub\n/o2 if [#1 EQ 1]\n/o1 call\n/o2 endif\n/M98 P9\nG1 Y2\nM30\nO9\nG1 Z3\nM99\n",
    "labels: one per frame, an untaken branch's not used, do loops reopen theirs": HEAD
    + "o100 sub\no1 if [1]\nG1 X1\no1 endif\no100 endsub\no1 if [1]\nG1 X2\no1 endif\no100 call\no100 call\no2 if [0]\no3 if [1]\no3 endif\no2 endif\no3 repeat [2]\nG1 Y1\no3 endrepeat\no4 do\no4 while [0]\no4 do\nG1 Z1\no4 while [0]\n",
    "definitions the program does not meet: after M2, in an untaken branch": HEAD
    + "o2 if [0]\no1 sub\nG1 X1\no1 endsub\no2 endif\no1 sub\nG1 X2\no1 endsub\no1 call\no3 call\nM2\no3 sub\nG1 Y1\no3 endsub\no3 sub\nG1 Y2\no3 endsub\n",
    "tape marks after a blank first line": "\n%\n" + HEAD + "G1 X1\n%\n",
    "a stray % after M2": HEAD + "G1 X1\nM2\n%\n",
    "a closing % with blanks after it is a tape mark": "%\n" + HEAD + "G1 X1\n%  \t\nG1 X9\n",
    "modes a subroutine leaves": HEAD
    + "o1 sub\n G91 G1 X1\n G18\no1 endsub\nG1 X5 Y5\no1 call\nX1 Z1\nG2 X2 Z0 I1 K0\nG90\n",
}

REFUSED = {
    "a subroutine's name is not the caller's": (
        HEAD + "#<m> = 7\no1 sub\n G0 X#<m>\no1 endsub\no1 call\n",
        5,
    ),
    "break out of a repeat": (HEAD + "o1 repeat [2]\n G0 X1\n o1 break\no1 endrepeat\n", 5),
    "continue in an if": (HEAD + "o1 if [1]\n o1 continue\no1 endif\n", 4),
    "an o-word subroutine ended by M99": (HEAD + "o1 sub\nG0 X1\nM99\no1 endsub\no1 call\n", 5),
    "M98 L0 (rs274ngc stays a call level deeper): the caller's names": (
        HEAD + "#<a> = 1\nM98 P9 L0\nG0 X#<a>\nM30\nO9\nG0 Y1\nM99\n",
        5,
    ),
    "M98 L0: the caller's loops": (
        HEAD + "#1 = 0\no1 while [#1 LT 2]\n#1 = [#1 + 1]\nM98 P9 L0\no1 endwhile\nM30\nO9\nG0 Y1\nM99\n",
        7,
    ),
    "endwhile outside a loop": (HEAD + "G0 X1\no1 endwhile\n", 4),
    "a move after an o-word (was: the if ran, the move was dropped)": (
        HEAD + "o1 if [1] G1 X1\no1 endif\n",
        3,
    ),
    "calls ten levels deep": (
        HEAD
        + "o<f> sub\n o1 if [#1 GT 0]\n  G0 X#1\n  o<f> call [#1 - 1]\n o1 endif\no<f> endsub\no<f> call [9]\n",
        6,
    ),
    "a subroutine that calls itself for ever (was: memory without end)": (
        HEAD + "o100 sub\nG1 X1 F100\no100 call\no100 endsub\no100 call\n",
        5,
    ),
    "a label used by a second if (was: both ran)": (
        HEAD + "o1 if [1]\nG1 X1\no1 endif\no1 if [1]\nG1 X2\no1 endif\n",
        6,
    ),
    "an if's label reused by a while": (HEAD + "o1 if [1]\no1 endif\no1 while [0]\no1 endwhile\n", 5),
    "a repeat's label reused by a repeat": (
        HEAD + "o1 repeat [1]\nG1 X1\no1 endrepeat\no1 repeat [1]\no1 endrepeat\n",
        6,
    ),
    "an if's label closing a do loop": (HEAD + "o1 if [1]\no1 endif\no1 do\nG1 X1\no1 while [0]\n", 7),
    "a subroutine defined twice (was: the first ran)": (
        HEAD + "o1 sub\nG1 X1\no1 endsub\no1 call\no1 sub\nG1 X2\no1 endsub\no1 call\n",
        7,
    ),
    "a definition met after a call ahead of it": (HEAD + "o1 call\no1 sub\nG1 X1\no1 endsub\n", 4),
    "a definition in a loop": (
        HEAD + "#1 = 0\no9 while [#1 LT 2]\n#1 = [#1 + 1]\no1 sub\nG1 X1\no1 endsub\no9 endwhile\n",
        6,
    ),
    "a definition in a definition": (HEAD + "o1 sub\no2 sub\no2 endsub\no1 endsub\n", 4),
    "a % line in a program that does not start with one (was: read as a tape mark)": (
        "(setup)\n%\n" + HEAD + "G1 X1\n%\n",
        2,
    ),
    # Excerpt of Ghettotator models/wiggler-8-back0125drill.gcode (richcreations/Ghettotator, Fusion
    # CAM's MPCNC21 post): its start G-code writes `% vfd enable` between the program's moves
    "a % with text after it is no tape mark (was: read as the closing one, the moves after it dropped)": (
        "%\n" + HEAD + "% vfd enable\nM6 T0\n% LED ON\nG1 X1 Z-3\n%\n",
        4,
    ),
    "a % with a comment after it": ("%\n" + HEAD + "G1 X1\n%( *** START end ***)\nG1 X2\n", 5),
    "a first line of % and text": ("% program start\n" + HEAD + "G1 X1\n%\n", 1),
    "a Fanuc subprogram that calls itself": (HEAD + "M98 P1\nM30\nO1\nG1 X1 F100\nM98 P1\nM99\n", 7),
}


def _program(tmp_path, text: str, name: str = "flow.ngc"):
    return write_program(tmp_path, text, name)


def _events(text: str, **kwargs) -> list:
    return list(interpret(parse_stream(io.BytesIO(text.encode()), "t.ngc"), file="t.ngc", **kwargs))


@pytest.mark.parametrize("name", AGREE)
def test_flow_moves_as_rs274_does(tmp_path, name):
    assert assert_agrees_with_rs274(_program(tmp_path, AGREE[name]))


@pytest.mark.parametrize("name", REFUSED)
def test_flow_refused_where_rs274_refuses(tmp_path, name):
    text, line = REFUSED[name]
    assert_refused_like_rs274(_program(tmp_path, text), line)


@pytest.mark.parametrize("name", AGREE)
def test_every_block_is_written_once_where_it_stands(name):
    """The events, block by block, are the program's text in order: passthrough is byte for byte."""
    text = AGREE[name]
    assert _text_of(_events(text)) == text


def _text_of(events) -> str:
    """The text of each run of events of one block: what passthrough writes."""
    groups, last = [], None
    for event in events:
        if event.block is not last:
            groups.append(event.block.text)
            last = event.block
    return "".join(groups)


def test_what_runs_out_of_order_belongs_to_the_line_that_runs_it():
    events = _events(HEAD + SQUARE + "o<square> call [1] [2] [5]\nG0 X0\n")
    call = next(e for e in events if e.block.line == 10)
    assert type(call) is Pass and not call.skipped
    moves = [e for e in events if type(e) is Line and e.block.line == 10]
    assert len(moves) == 5 and all(e.fixed == FLOW for e in moves)  # the subroutine's, as programmed
    assert all(e.skipped for e in events if 3 <= e.block.line <= 9)  # its definition: text that does not run
    last = events[-1]
    assert type(last) is Line and not last.fixed and last.block.line == 11


def test_a_top_level_branch_is_compensated_a_loop_is_not():
    events = _events(
        HEAD + "o1 if [1]\n G1 X1\no1 else\n G1 X2\no1 endif\no2 repeat [2]\n G2 X3 Y0 I1 J0\no2 endrepeat\n"
    )
    taken = next(e for e in events if type(e) is Line and e.block.line == 4)
    assert not taken.fixed
    untaken = next(e for e in events if e.block.line == 6)
    assert type(untaken) is Pass and untaken.skipped
    arcs = [e for e in events if type(e) is Arc]
    assert len(arcs) == 2 and all(a.fixed == FLOW for a in arcs)
    assert [a.block.line for a in arcs] == [9, 10]  # the second iteration's, the endrepeat's


def test_a_call_of_a_subroutine_the_program_does_not_define_passes_the_rest():
    warned = io.StringIO()
    events = _events(HEAD + "G0 X1\no<probe> call [2]\nG0 X2\n", warnings=Warnings(stream=warned))
    assert [type(e) for e in events[-2:]] == [Pass, Pass]
    assert "t.ngc:4:1: warning: a call of o<probe>, which the program does not define" in warned.getvalue()


def test_out_of_scope_inside_a_subroutine_names_the_call():
    warned = io.StringIO()
    events = _events(
        HEAD + "o1 sub\n G38.2 X1 F10\no1 endsub\nG0 X5\no1 call\nG0 X6\n", warnings=Warnings(stream=warned)
    )
    assert "t.ngc:4:" in warned.getvalue() and "from line 7, which runs it," in warned.getvalue()
    assert [e.block.line for e in events if type(e) is Line] == [2, 6]
    assert (
        "".join(e.block.text for e in events if type(e) is Pass and e.setting is None).count("o1 call") == 1
    )
    # where interpretation ends in the call, a step back to the programmed point before it (`entries.py`)
    assert [(e.block.line, e.setting.position) for e in events if type(e) is Pass and e.setting] == [
        (7, (5.0, 0.0, 10.0))
    ]


def test_a_loop_that_does_not_end_is_refused_at_its_line(monkeypatch):
    """LinuxCNC would run it for ever; a pass over the program must end, at a stated bound (here
    its counter changes the state at each pass: no pass comes back to a state it had)."""
    import ncpp.motion.flow as flow

    monkeypatch.setattr(flow, "MAX_RERUN", 1000)
    with pytest.raises(NcppError, match=r"a loop that does not end: 1,000 lines run again") as err:
        _events(HEAD + "o1 while [#1 GE 0]\n G0 X1\n #1 = [#1 + 1]\no1 endwhile\nG0 Y5\n")
    assert (err.value.where.file, err.value.where.line) == ("t.ngc", 6)


def test_memory_stays_flat_around_loops_and_calls():
    """A long program calling a subroutine defined at its top: blocks are kept only while a loop may go back."""
    body = "".join(f"G1 X{i % 50} Y{i % 7}\no<s> call [{i % 3}]\n" for i in range(20_000))
    seen = []
    flow = Flow("t", lambda e, b, i: 0.0, _Params(), lambda: False, None)
    blocks = parse_stream(io.BytesIO((HEAD + "o<s> sub\n G0 Z#1\no<s> endsub\n" + body).encode()), "t.ngc")
    for n, _ in enumerate(flow.steps(blocks)):
        if n % 1000 == 0:
            seen.append(len(flow.buffer))
    assert max(seen) <= 3 * _TRIM


def test_a_programs_own_number_holds_no_memory():
    """`O1000` at the top of a long program starts no subprogram for ever: kept up to MAX_SUBPROGRAM blocks."""
    from ncpp.motion.flow import MAX_SUBPROGRAM

    body = "".join(f"G1 X{i % 50} Y{i % 7}\n" for i in range(MAX_SUBPROGRAM + 5000))
    flow = Flow("t", lambda e, b, i: 0.0, _Params(), lambda: False, None)
    steps = flow.steps(parse_stream(io.BytesIO(("O1000\n" + HEAD + body).encode()), "t.ngc"))
    for n, _ in enumerate(steps):
        if n == MAX_SUBPROGRAM + 100:
            break
    assert flow._defining is None and len(flow.buffer) <= 3 * _TRIM and not flow.subprograms


class _Params:
    fanuc = False  # (a LinuxCNC program's parameters)

    def enter(self, arguments):
        pass

    def leave(self, value):
        pass

    def start_fanuc(self):
        pass


def _random_program(rng: random.Random) -> str:
    """Nested branches, loops and calls with random conditions, numbered and named parameters."""
    lines = ["G21 G90 G17", "G0 X0 Y0 Z5 F100", "#<_n> = 0"]
    subs = []
    for s in range(rng.randint(0, 2)):
        subs.append(f"o<s{s}>")
        lines += [f"o<s{s}> sub", f" G1 X[#1 + {rng.randint(0, 9)}] Y#2", f" o{900 + s} if [#1 GT {rng.randint(0, 5)}]", f"  o<s{s}> return [#1 * 2]",
                  f" o{900 + s} endif", " #<loc> = [#1 + #2]", " G0 Z#<loc>", f"o<s{s}> endsub"]  # fmt: skip
    label = iter(range(100, 200))

    def statements(depth: int) -> list[str]:
        out = []
        for _ in range(rng.randint(1, 3)):
            kind = rng.choice(
                ["move", "move", "assign", "if", "while", "repeat", "do", "call"]
                if depth < 3
                else ["move", "assign"]
            )
            if kind == "move":
                out.append(
                    rng.choice(["G1", "G0", ""])
                    + f" X[#<_n> + {rng.uniform(-3, 3):.3f}] Y{rng.uniform(-3, 3):.3f}"
                )
            elif kind == "assign":
                out.append(f"#<_n> = [#<_n> + {rng.randint(1, 3)}]")
            elif kind == "call" and subs:
                out.append(f"{rng.choice(subs)} call [{rng.randint(0, 6)}] [#<_n>]")
                out.append("G0 Y#<_value>")
            elif kind == "if":
                n = next(label)
                out += [f"o{n} if [[#<_n> MOD 3] EQ {rng.randint(0, 2)}]", *statements(depth + 1)]
                if rng.random() < 0.5:
                    out += [f"o{n} elseif [#<_n> GT {rng.randint(0, 8)}]", *statements(depth + 1)]
                if rng.random() < 0.5:
                    out += [f"o{n} else", *statements(depth + 1)]
                out.append(f"o{n} endif")
            elif kind == "while":
                n, count = next(label), f"#<w{depth}>"
                out += [
                    f"{count} = 0",
                    f"o{n} while [{count} LT {rng.randint(0, 3)}]",
                    f"{count} = [{count} + 1]",
                    *statements(depth + 1),
                ]
                if rng.random() < 0.3:
                    out += [f"o{n + 50} if [{count} EQ 2]", f"o{n} break", f"o{n + 50} endif"]
                out.append(f"o{n} endwhile")
            elif kind == "repeat":
                n = next(label)
                out += [f"o{n} repeat [{rng.randint(0, 3)}]", *statements(depth + 1), f"o{n} endrepeat"]
            elif kind == "do":
                n, count = next(label), f"#<d{depth}>"
                out += [
                    f"{count} = {rng.randint(1, 3)}",
                    f"o{n} do",
                    f"{count} = [{count} - 1]",
                    *statements(depth + 1),
                    f"o{n} while [{count} GT 0]",
                ]
        return out

    return "\n".join(lines + statements(0) + ["M2"]) + "\n"


@pytest.mark.skipif(not RS274.exists(), reason="no rs274")
def test_random_flow_programs_agree_with_rs274(tmp_path):
    """40 random programs move as rs274 does, call by call, and pass through byte for byte."""
    rng, moves = random.Random(20261122), 0
    for n in range(40):
        text = _random_program(rng)
        path = tmp_path / f"random{n}.ngc"
        path.write_text(text)
        calls, messages = rs274(str(path))
        reference = read_canon(calls)
        assert rs274_error(messages) is None, (text, messages)
        mine, error, warning = ours(path)
        assert (
            error is None and not warning and len(mine) == len(reference) and same_calls(reference, mine)
        ), (text, error, warning)
        assert _text_of(_events(text)) == text
        moves += len(mine)
    assert moves > 200


# -- subroutine files ----------------------------------------------------------------------------
def _library(tmp_path):
    folder = tmp_path / "subs"
    folder.mkdir()
    (folder / "square.ngc").write_text(
        "(a square)\n" + SQUARE.replace("o<square> endsub", "o<mark> call [#1]\no<square> endsub") + "M2\n"
    )
    (folder / "mark.ngc").write_text("o<mark> sub\n G0 Z[#1 / 10]\n G0 Z10\no<mark> endsub\n")
    (folder / "bad.ngc").write_text("o<bad> sub\n G1 X#<nope>\no<bad> endsub\n")
    ini = tmp_path / "machine.ini"
    ini.write_text("[RS274NGC]\nSUBROUTINE_PATH = subs\n")
    return folder, ini


@pytest.mark.skipif(not RS274.exists(), reason="no rs274")
def test_subroutine_files_move_as_rs274_does(tmp_path):

    from ncpp.motion.offsets import WorkOffsets

    folder, ini = _library(tmp_path)
    path = _program(tmp_path, HEAD + "o<square> call [1] [2] [5]\nG0 X0 Y0\no<square> call [10] [10] [2]\n")
    proc = oracle.run(path, ini=ini, cwd=tmp_path)
    reference = read_canon(proc.stdout)
    assert rs274_error(proc.stderr) is None and len(reference) == 16, proc.stderr
    events = interpret(
        parse_stream(open(path, "rb"), str(path)),
        file=str(path),
        offsets=WorkOffsets.given({}, subroutine_path=[folder]),
    )
    from ncpp.motion.canon import canon_call

    mine = [c for c in map(canon_call, events) if c is not None]
    assert len(mine) == len(reference) and same_calls(reference, mine)


def test_a_relative_subroutine_folder_counts_from_the_working_directory(tmp_path, monkeypatch):
    from ncpp.motion.offsets import WorkOffsets

    (tmp_path / "step.ngc").write_text("o<step> sub\nG1 X[#1] F100\no<step> endsub\n")
    monkeypatch.chdir(tmp_path)
    found = _events(HEAD + "o<step> call [7]\n", offsets=WorkOffsets.given({}, subroutine_path=[Path(".")]))
    assert [e.end[0] for e in found if type(e) is Line][-1] == 7.0


def test_an_error_in_a_subroutine_file_names_that_file(tmp_path):
    from ncpp.motion.offsets import WorkOffsets

    folder, _ = _library(tmp_path)
    with pytest.raises(NcppError) as err:
        _events(HEAD + "o<bad> call\n", offsets=WorkOffsets.given({}, subroutine_path=[folder]))
    assert (
        str(err.value)
        == f"{folder / 'bad.ngc'}:2:5: Named parameter #<nope> not defined (in the subroutine line 3 calls)"
    )


def test_a_construct_out_of_scope_in_a_subroutine_file_is_warned_at_the_program_s_calling_line(tmp_path):
    """`o<pocket_circ> call [0][0] [0.75] ...` of a subroutine file that reads the tool's diameter #5410
    (Thaddeus-Maximus/lagun-linuxcnc, `nc_files/spr_hub_mill.ngc` and `nc_files/pocket_circ.ngc`): the
    program passes through from its calling line, where the warning stands, naming the place in the file
    (it stood at the file's line, which the summary counted as the program's: "from line 40 on (-7 lines)")."""
    import io as _io

    from ncpp.motion.offsets import WorkOffsets
    from ncpp.pipeline import ErrorSource, process
    from tests.conftest import SHARED

    (tmp_path / "pocket_circ.ngc").write_text("o<pocket_circ> sub\nG1 X#1 F100\n#<td> = #5410\nG1 X#<td>\n"
                                              "o<pocket_circ> endsub\n")  # fmt: skip
    program = HEAD + "o<pocket_circ> call [1]\nG1 X2\nM2\n"
    said = _io.StringIO()
    source = ErrorSource.from_machine_file(str(SHARED / "machines" / "wide.toml"))
    stats = process(_io.BytesIO(program.encode()), _io.BytesIO(), file="p.ngc", source=source,
                    warnings=Warnings(stream=said), offsets=WorkOffsets.given({}, subroutine_path=[tmp_path]))  # fmt: skip
    where = f"(at {tmp_path / 'pocket_circ.ngc'}:4:4)"
    assert (
        f"p.ngc:3:1: warning: #<td>, which line 3 set from machine-state parameter #5410 of the tool in the "
        f"spindle, without the tool table (--tool-table) {where}" in said.getvalue()
    )
    assert "from line 3, which runs it, on the program passes through" in said.getvalue()
    assert "everything from line 3 on (3 lines)" in stats.summary.line()


def test_the_linuxcnc_ini_names_the_subroutine_folders(tmp_path):
    from ncpp.integrations.config import Settings, with_linuxcnc_ini

    folder, ini = _library(tmp_path)
    settings = with_linuxcnc_ini(Settings(), ini)
    assert settings.offsets().subroutine_path == (folder.resolve(),)
    # searched in LinuxCNC's order: the program folder, SUBROUTINE_PATH (":"-separated), the wizard root
    ini.write_text(
        "[DISPLAY]\nPROGRAM_PREFIX = nc_files\n[RS274NGC]\nSUBROUTINE_PATH = subs:more\n[WIZARD]\nWIZARD_ROOT = wizard\n"
    )
    found = with_linuxcnc_ini(Settings(), ini).offsets().subroutine_path
    assert found == tuple((tmp_path / f).resolve() for f in ("nc_files", "subs", "more", "wizard"))


def test_compensate_with_a_subroutine_path(tmp_path):
    import subprocess
    import sys

    folder, _ = _library(tmp_path)
    path = tmp_path / "part.ngc"
    path.write_text(HEAD + "G1 Z-1\nG1 X40 Y12\no<square> call [1] [2] [5]\nG1 X50 Y50\nM2\n")
    command = [
        sys.executable,
        "-m",
        "ncpp",
        "compensate",
        "--machine",
        str(ROOT / "samples/machines/hr5b.toml"),
        "--work-offset",
        "400,350,350",
        str(path),
    ]
    without = subprocess.run(command, capture_output=True, text=True)
    assert "give its folder with --subroutine-path" in without.stderr and without.stdout.endswith(
        "o<square> call [1] [2] [5]\nG1 X50 Y50\nM2\n"
    )
    found = subprocess.run(command + ["--subroutine-path", str(folder)], capture_output=True, text=True)
    assert found.returncode == 0 and "part.ngc:5:1: warning: loop or subroutine" in found.stderr, found.stderr
    assert "\nG1 X50 Y50\n" not in found.stdout and "X50.0" in found.stdout  # compensated after the call


# -- compensation ---------------------------------------------------------------------------------
def _compensate(text: str, strict: bool = False) -> tuple[str, str]:
    return compensate(text, "flow.ngc", strict)


POCKET = (
    HEAD
    + SQUARE
    + "G1 Z-1\nG1 X40 Y12\no<square> call [1] [2] [5]\n#1 = 0\no7 while [#1 LT 2]\n G1 X[20+#1] Y20\n #1 = [#1 + 1]\no7 endwhile\nG1 X50 Y50\nG3 X70 Y40 R15\nG0 Z10\n"
)


def test_subroutines_and_loops_pass_through_and_compensation_resumes():
    out, warned = _compensate(POCKET)
    original, lines = POCKET.splitlines(), out.splitlines()
    start = lines.index("o<square> sub")
    assert lines[start : start + 7] == original[2:9]  # the definition verbatim
    call = lines.index("o<square> call [1] [2] [5]")
    assert lines[call - 1].startswith("X40.0")  # compensated before it
    loop = lines.index("o7 while [#1 LT 2]")
    assert lines[loop : loop + 4] == original[13:17]  # the loop verbatim
    after = lines[loop + 4 :]
    assert (
        after[0].startswith("G1 X21.0") and "Z" in after[0]
    )  # from the loop's end to where compensation resumes
    assert after[1].startswith("X50.0") and "Z" in after[1]  # compensated, every axis said after the loop
    assert any(line.startswith("G3 ") and "I" in line for line in after)
    # one warning: the subroutine's moves and the loop's make one series
    assert warned.count("warning") == 1 and "flow.ngc:12:1: warning: loop or subroutine" in warned


def test_strict_refuses_subroutine_moves():
    with pytest.raises(NcppError, match="flow.ngc:12:1: loop or subroutine"):
        _compensate(POCKET, strict=True)


FANUC = (
    "O1000\n"
    + HEAD
    + "G1 Z-1\nG1 X40 Y12\nM98 P2000 L3\nG1 X50 Y50\nG0 Z10\nM30\nO2000\nG1 X[#<_x> + 2] Y[#<_y> + 1]\nM99\n"
)


def test_fanuc_subprograms_pass_through_and_compensation_resumes():
    out, warned = _compensate(FANUC)
    lines = out.splitlines()
    call = lines.index("M98 P2000 L3")
    assert lines[call - 1].startswith("X40.0") and lines[call + 1].startswith("G1 X")  # compensated around it
    assert lines[-4:] == FANUC.splitlines()[-4:]  # after M30: the subprogram, verbatim
    assert "flow.ngc:6:1: warning: loop or subroutine" in warned


def test_a_subroutine_in_g91_runs_from_where_the_control_is_and_compensation_goes_on():
    """Its increments run from the compensated point before the call (`apply_error_map._carry`;
    test_exact_model measures the moves after it on the machine)."""
    text = HEAD + "o1 sub\n G91 G1 X1\n G1 Y1\no1 endsub\nG1 X40 Y12\no1 call\nG1 X3\nG90 G1 X50\n"
    out, warned = _compensate(text)
    lines = out.splitlines()
    call = lines.index("o1 call")
    assert "in G91" not in warned and "flow.ngc:8:1: warning: loop or subroutine" in warned
    assert lines[call + 1].startswith("G1 X3.0") and lines[-1].startswith(
        "G90 G1 X50.0"
    )  # compensated after it


@pytest.mark.skipif(not RS274.exists(), reason="no rs274")
def test_rs274_runs_the_compensated_program_with_the_same_subroutine_moves(tmp_path):
    out, _ = _compensate(POCKET)
    path = tmp_path / "out.ngc"
    path.write_text(out)
    calls, messages = rs274(str(path))
    assert rs274_error(messages) is None, messages
    original = read_canon(rs274(str(_program(tmp_path, POCKET, "in.ngc")))[0])
    compensated = read_canon(calls)
    fixed = [
        canon for canon, e in zip(original, [e for e in _events(POCKET) if type(e) is not Pass]) if e.fixed
    ]
    # the subroutine's and the loop's, as programmed (Z, which they do not say, is where the compensated line left it)
    xy = {(c.name, c.args[:2]) for c in compensated}
    assert len(fixed) == 7 and all((c.name, c.args[:2]) in xy for c in fixed)


def test_the_output_is_in_the_programs_motion_mode_at_a_control_line():
    """An arc block the output ends with a line: before a call (whose subroutine may rely on the
    modal G2) the writer says G2 again; after it the next block says its mode."""
    from ncpp.program.dialects.iso import IsoWriter

    text = HEAD + "o1 sub\n X4 Y0 I1 J0\no1 endsub\nG2 X2 Y0 I1 J0\no1 call\nX6 Y0 I1 J0\n"
    events = _events(text)
    arc = next(i for i, e in enumerate(events) if type(e) is Arc and e.block.line == 6)
    a = events[arc]
    events[arc : arc + 1] = [Arc(a.start, (1.0, 1.0, 10.0), a.center, a.turn, a.feed, a.block, a.context, changed=True),
                             Line((1.0, 1.0, 10.0), a.end, False, a.feed, a.block, a.context, changed=True)]  # fmt: skip
    b = events[-1]
    events[-1] = Arc(b.start, b.end, b.center, b.turn, b.feed, b.block, b.context, changed=True)
    lines = list(IsoWriter().write(events))
    call = lines.index("o1 call\n")
    assert lines[call - 1] == "G2\n" and lines[call - 2].startswith("G1 ")
    assert (
        lines[-1].startswith("G2 X6.0000 Y0.0000") and "Z10.0000" in lines[-1]
    )  # its mode said, and every axis


def test_simulating_a_file_of_subroutines_only_names_the_file(tmp_path):
    """An ngcgui subroutine file makes no motion by itself: `ncpp simulate` says so, naming the file."""
    import subprocess
    import sys

    folder, _ = _library(tmp_path)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "simulate", "--machine", str(ROOT / "samples/machines/hr5b.toml"), str(folder / "mark.ngc")],
                          capture_output=True, text=True)  # fmt: skip
    assert proc.returncode != 0 and proc.stderr.startswith(
        f"{folder / 'mark.ngc'}: the program makes no motion"
    ), proc.stderr
    assert "Traceback" not in proc.stderr
