"""Klartext subprograms, program-section repeats and FN 9-12 jumps, move by move.

TNC 640 Klartext manual, "Subprograms and program section repeats": `CALL LBL n` runs the
blocks from `LBL n` to `LBL 0` and goes on after the call; `CALL LBL n REP k` runs the section
from `LBL n` to the call k more times; "If-then decisions with Q parameters": FN 9 (EQU),
FN 10 (NE), FN 11 (GT), FN 12 (LT) jump to the label when the comparison holds."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion import heidenhain_flow
from ncpp.motion.segments import FLOW, Event, Line, Pass
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests.conftest import READING, ROOT

# The manual's subprogram example: a hole pattern's depth cycle as LBL 1, called at two places
SUBPROGRAM = """0 BEGIN PGM SUB MM
1 TOOL CALL 1 Z S1000
2 L X+0 Y+0 Z+10 R0 FMAX
3 CALL LBL 1
4 L X+50 Y+0 R0 FMAX
5 CALL LBL 1
6 L Z+100 R0 FMAX M30
7 LBL 1
8 L IZ-12 F100
9 L IX+10
10 L IZ+12 FMAX
11 LBL 0
12 END PGM SUB MM
"""


def events(text: str, warnings: Warnings | None = None) -> list[Event]:
    interpret, _ = dialect_tools("heidenhain")
    _, blocks = parse_program(io.BytesIO(text.encode()), "p.h", "heidenhain")
    return list(interpret(blocks, file="p.h", warnings=warnings or Warnings(stream=io.StringIO())))


def moves(text: str, warnings: Warnings | None = None) -> list[tuple[int, tuple, str]]:
    """(the line whose text the move is written at, its end point, why it is left as programmed)."""
    return [(e.block.line, e.end, e.fixed) for e in events(text, warnings) if type(e) is Line]


def pattern(x: float) -> list[tuple]:
    """The subprogram's three moves from (x, 0, 10): down 12, across 10, up 12."""
    return [(x, 0.0, -2.0), (x + 10, 0.0, -2.0), (x + 10, 0.0, 10.0)]


def test_a_subprogram_called_twice_runs_at_each_call_and_belongs_to_the_call_line():
    found = moves(SUBPROGRAM)
    assert [end for _, end, _ in found] == [(0.0, 0.0, 10.0), *pattern(0.0), (50.0, 0.0, 10.0),
                                            *pattern(50.0), (60.0, 0.0, 100.0)]  # fmt: skip
    assert [line for line, _, _ in found] == [3, 4, 4, 4, 5, 6, 6, 6, 7]  # (file lines: block n is line n+1)
    assert [fixed for _, _, fixed in found] == ["", FLOW, FLOW, FLOW, "", FLOW, FLOW, FLOW, ""]


def test_the_subprogram_text_after_m30_is_written_once_and_not_run_in_its_place():
    after_end = [e for e in events(SUBPROGRAM) if e.block.line >= 8]
    assert [e.block.line for e in after_end] == list(range(8, 14)) and all(type(e) is Pass for e in after_end)


def test_nested_calls_run_the_inner_subprogram_inside_the_outer():
    text = SUBPROGRAM.replace("9 L IX+10\n", "9 CALL LBL 2\n").replace(
        "12 END PGM", "12 LBL 2\n13 L IX+10\n14 LBL 0\n15 END PGM"
    )
    found = moves(text)
    assert [end for _, end, _ in found] == [(0.0, 0.0, 10.0), *pattern(0.0), (50.0, 0.0, 10.0),
                                            *pattern(50.0), (60.0, 0.0, 100.0)]  # fmt: skip
    assert [line for line, _, _ in found][1:4] == [4, 4, 4]


REPEAT = """0 BEGIN PGM REP MM
1 TOOL CALL 1 Z S1000
2 L X+0 Y+0 Z+2 R0 FMAX
3 LBL "ROW"
4 L IX+10 R0 FMAX
5 L IZ-4 F100
6 L IZ+4 FMAX
7 CALL LBL "ROW" REP 2
8 L Z+50 FMAX
9 END PGM REP MM
"""


def test_a_section_repeated_with_rep_runs_k_plus_one_times_all_left_as_programmed():
    """REP 2: the section runs in its place, then twice more for the call line."""
    found = moves(REPEAT)
    holes = [end for _, end, _ in found[1:-1]]
    assert holes == [p for x in (10.0, 20.0, 30.0) for p in ((x, 0.0, 2.0), (x, 0.0, -2.0), (x, 0.0, 2.0))]
    assert [line for line, _, _ in found[1:-1]] == [5, 6, 7] + [8] * 6
    assert all(fixed == FLOW for _, _, fixed in found[1:-1])  # (its one text runs three times)
    assert found[-1] == (9, (30.0, 0.0, 50.0), "")


LOOP = """0 BEGIN PGM LOOP MM
1 TOOL CALL 1 Z S1000
2 L X+0 Y+0 Z+2 R0 FMAX
3 FN 0: Q1 = +0
4 LBL 2
5 L X+Q1 Y+20 R0 FMAX
6 FN 1: Q1 = +Q1 + +5
7 FN 12: IF +Q1 LT +15 GOTO LBL 2
8 FN 9: IF +0 EQU +0 GOTO LBL 3
9 L X+999 FMAX
10 LBL 3
11 L Z+50 FMAX
12 END PGM LOOP MM
"""


def test_an_fn_12_loop_counts_q1_and_an_fn_9_jump_skips_forward():
    found = moves(LOOP)
    assert [end for _, end, _ in found] == [(0.0, 0.0, 2.0), (0.0, 20.0, 2.0), (5.0, 20.0, 2.0),
                                            (10.0, 20.0, 2.0), (10.0, 20.0, 50.0)]  # fmt: skip
    assert [(line, fixed) for line, _, fixed in found] == [(3, ""), (6, FLOW), (8, FLOW), (8, FLOW), (12, "")]
    skipped = [e.block.line for e in events(LOOP) if type(e) is Pass and e.skipped]
    assert skipped == [10]  # `L X+999` is written, not run


@pytest.mark.parametrize(
    ("number", "condition", "passes"),
    [(9, "+Q1 EQU +5", 2), (10, "+Q1 NE +15", 3), (11, "+15 GT +Q1", 3), (12, "+Q1 LT +10", 2)],
)
def test_each_comparison_jumps_back_while_it_holds(number, condition, passes):
    """Q1 is 5, 10, 15 after the first, second, third pass."""
    found = moves(LOOP.replace("7 FN 12: IF +Q1 LT +15", f"7 FN {number}: IF {condition}"))
    assert [end[0] for _, end, _ in found if end[1:] == (20.0, 2.0)] == [0.0, 5.0, 10.0][:passes]


def test_a_loop_that_never_ends_is_refused(monkeypatch):
    monkeypatch.setattr(heidenhain_flow, "MAX_RERUN", 1000)
    with pytest.raises(NcppError, match="never ends"):
        moves(LOOP.replace("FN 12: IF +Q1 LT +15", "FN 12: IF -1 LT +Q1"))


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        (("9 L IX+10", "9 CALL LBL 1"), "a subprogram that calls itself"),
        (("3 CALL LBL 1", "3 CALL LBL 7"), "LBL 7 (not in the program)"),
        (("11 LBL 0\n", ""), "END PGM in a subprogram (no LBL 0 before it)"),
        (("5 CALL LBL 1", "5 CALL LBL 1 REP 2"), "CALL LBL ... REP with the label after the call"),
        (("12 END PGM", "12 LBL 1\n12 END PGM"), "LBL 1 (defined more than once)"),
        (("11 LBL 0\n12 END PGM SUB MM\n", ""), "a subprogram without LBL 0 before the end of the program"),
    ],
)
def test_what_cannot_be_followed_ends_interpretation_with_a_warning(change, reason):
    stream = io.StringIO()
    moves(SUBPROGRAM.replace(*change), Warnings(stream=stream))
    assert reason in stream.getvalue() and "scope" in stream.getvalue()


def test_a_label_further_ahead_than_ncpp_reads_ends_interpretation(monkeypatch):
    monkeypatch.setattr(heidenhain_flow, "MAX_AHEAD", 3)
    monkeypatch.setattr(heidenhain_flow, "LOOKAHEAD", 1)
    stream = io.StringIO()
    assert len(moves(SUBPROGRAM, Warnings(stream=stream))) == 1
    assert "LBL 1 (not within 3 blocks ahead)" in stream.getvalue()


def test_a_jump_back_over_moves_run_in_their_place_ends_interpretation(monkeypatch):
    """Read ahead less than the loop's length, its first pass ran compensable: no second one."""
    monkeypatch.setattr(heidenhain_flow, "LOOKAHEAD", 1)
    stream = io.StringIO()
    found = moves(LOOP, Warnings(stream=stream))
    assert "a jump back to LBL 2 over moves that ran in their place" in stream.getvalue()
    assert len(found) == 2


def test_a_compensated_program_writes_each_text_once_and_leaves_the_called_moves_as_programmed(tmp_path):
    program = tmp_path / "p.h"
    program.write_text(SUBPROGRAM)
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "--machine", str(READING), "--no-guard", str(program)],
        capture_output=True, text=True, cwd=ROOT,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    written = [line.split(" ", 1)[1] for line in proc.stdout.splitlines()]
    for text in ("CALL LBL 1", "L IZ-12 F100", "L IX+10", "L IZ+12 FMAX", "LBL 1", "LBL 0"):
        assert written.count(text) == (2 if text == "CALL LBL 1" else 1)
    assert "left as programmed: 6 moves in loops or subroutines" in proc.stderr
    assert "compensated 3 moves" in proc.stderr
    across = next(line for line in written if line.startswith("L X+49"))  # `L X+50 Y+0`, compensated
    assert across != "L X+50 Y+0 R0 FMAX"


# A contour subprogram with a fillet and its own incremental pole, called after compensated arcs
CONTOUR = """0 BEGIN PGM C MM
1 TOOL CALL 1 Z S1000
2 L X+0 Y+0 Z+2 R0 FMAX
3 CALL LBL 5
4 L X+100 Y+0 R0 FMAX
5 CC X+110 Y+0
6 C X+120 Y+0 DR- F200
7 CALL LBL 5
8 L X+135 Y+20 R0 FMAX
9 C X+135 Y+0 DR-
10 L Z+50 R0 FMAX M30
11 LBL 5
12 L IX+10 F100
13 RND R2
14 L IY+10
15 CC IX+5 IY+0
16 C IX+10 IY+0 DR+
17 LBL 0
18 END PGM C MM
"""


def test_a_subprogram_with_a_fillet_and_its_own_pole_runs_about_it_at_each_call():
    arcs = [e for e in events(CONTOUR) if type(e).__name__ == "Arc"]
    fillet, half, _, second_fillet, second_half, after = arcs
    assert fillet.center[:2] == pytest.approx((8.0, 2.0)) and second_fillet.center[:2] == pytest.approx(
        (128.0, 2.0)
    )
    assert half.center[:2] == (15.0, 10.0) and second_half.center[:2] == (135.0, 10.0)
    assert after.center[:2] == (135.0, 10.0)  # (the pole the subprogram left, as the control keeps it)
    assert {fillet.fixed, half.fixed, second_fillet.fixed, second_half.fixed} == {FLOW}
    assert second_half.block.line == 8 and not after.fixed


def test_a_compensated_contour_subprogram_keeps_its_text_and_gets_the_program_pole_at_the_call(tmp_path):
    program = tmp_path / "p.h"
    program.write_text(CONTOUR)
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "--machine", str(READING), "--no-guard", str(program)],
        capture_output=True, text=True, cwd=ROOT,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr  # (and the written program reads back the same)
    written = [line.split(" ", 1)[1] for line in proc.stdout.splitlines()]
    assert written[written.index("LBL 5") :] == [line.split(" ", 1)[1] for line in CONTOUR.splitlines()[11:]]
    before_call = written[written.index("CALL LBL 5", written.index("CALL LBL 5") + 1) - 1]
    assert before_call == "CC X+110.000000 Y+0.000000"  # the arc before moved the output's pole


# Plan.h's inputs (a face 100 x 60 from Z0 to Z-2, 1 mm infeeds, tool radius Q108 = 10): it
# is a cycle a calling program gives them to
PLAN_INPUTS = {"Q1800": 0, "Q1801": 100, "Q1802": 0, "Q1803": 60, "Q1804": 0, "Q1805": -2, "Q1810": 1,
               "Q1812": 0.7, "Q1813": 0.1, "Q1820": 1000, "Q1822": 500, "Q1830": 2, "Q1831": 5,
               "Q1832": 2, "Q1840": 1, "Q108": 10}  # fmt: skip


def test_the_corpus_face_milling_cycle_is_followed_through_its_fn_jumps_to_its_end(corpus):
    """Plan.h (jstjst/Heidenhain-Cycles) checks its inputs with FN 9-12, then mills a spiral per
    infeed, jumping back to its infeed label: (-2 - 0) / 1 gives two infeeds, at Z-1 and Z-2."""
    path = corpus / "heidenhain" / "jstjst_Heidenhain-Cycles" / "Plan.h"
    lines = path.read_text(encoding="latin-1").split("\n")
    text = "\n".join([lines[0], *(f"0 {q} = {value:+g}" for q, value in PLAN_INPUTS.items()), *lines[1:]])
    stream = io.StringIO()
    found = [e for e in events(text, Warnings(stream=stream)) if type(e) is Line and not e.rapid]
    assert "scope" not in stream.getvalue()
    depths = sorted({round(move.end[2], 9) for move in found})
    assert depths == [-2.0, -1.0] and all(move.fixed == FLOW for move in found)
    second = [move for move in found if move.end[2] == -2.0]
    assert len({move.block.line for move in second}) == 1  # the jump back runs the second infeed


def test_blocks_are_held_only_so_far_back_and_a_call_past_them_ends_interpretation(monkeypatch):
    """A label at the top and a call 20 000 blocks on: memory stays bounded, the call is refused."""
    from ncpp.motion.heidenhain import HeidenhainInterpreter

    monkeypatch.setattr(heidenhain_flow, "LOOKAHEAD", 100)
    monkeypatch.setattr(heidenhain_flow, "MAX_BEHIND", 1000)
    body = "".join(f"{n} L X+{n % 7} F100\n" for n in range(2, 20_002))
    text = f"0 BEGIN PGM B MM\n1 LBL 1\n{body}20002 CALL LBL 1 REP 1\n20003 END PGM B MM\n"
    _, blocks = parse_program(io.BytesIO(text.encode()), "p.h", "heidenhain")
    interpreter, stream = HeidenhainInterpreter("p.h"), io.StringIO()
    held = 0
    for _ in interpreter.run(blocks, Warnings(stream=stream)):
        assert interpreter.flow is not None
        held = max(held, len(interpreter.flow.held))
    assert held <= 1000 + 100 + 4096 + 1
    assert "LBL 1 (more than 1000 blocks back)" in stream.getvalue()


def test_a_repeat_count_from_a_q_parameter_is_out_of_scope_not_read_as_a_plain_call():
    """`CALL LBL 1 REPQ9` (drunsinn/language-klartext, `testprogramme/programm-zirkularnut-fraesen.klartext`):
    the manual's REP takes a number.  Read as `CALL LBL 1` with a stray word, the section ran once
    and the next move was written where the tool is not (`L Z+100` got X+7.5 Y+4 added, the control
    having repeated the slot's passes 35 times further in Y).  It stops interpretation at its line."""
    text = """0 BEGIN PGM REPQ MM
1 TOOL CALL 1 Z S1000
2 FN 0: Q9 =+35.5
3 L X+0 Y+0 Z+10 R0 FMAX
4 LBL 1
5 L IY+2 F100
6 LBL 0
7 CALL LBL 1 REPQ9
8 L Z+100 R0 FMAX M30
9 END PGM REPQ MM
"""
    stream = io.StringIO()
    found = moves(text, Warnings(stream=stream))
    assert (
        "p.h:8:3: warning: CALL LBL ... REPQ9 (a repeat count from a Q parameter) is outside"
        in stream.getvalue()
    )
    assert [end for _, end, _ in found] == [(0.0, 0.0, 10.0), (0.0, 2.0, 10.0)]  # (nothing after the call)
