"""`--expand` on Sinumerik: loops (FOR, WHILE, REPEAT), jumps back (IF ... GOTOB), program section
repetitions (REPEAT label, REPEATB) and subprogram calls (`L100`, `L100 P2`, a PROC by name) written
out as straight code, each run's moves compensated.

The judges: closed form, as for Klartext (`test_klartext_expand`): the test computes where each
run of a body puts the tool (a FOR loop of 3 squares at Z-1, Z-2, Z-3), reads the numbers of the
written program with a reader of its own (`points`) and maps them through the formula of a
machine whose errors are linear in position (`AFFINE`, `machine`): each programmed corner must be
reached within 0.5 µm, where the program compensated without --expand misses them by microns.
And the CEAD interpreter's recorded positions (`test_sinumerik_oracle`): the corpus programs with
loops and jumps, written out on a machine without errors, reach the oracle's positions with no
control line left.  ncpp's own interpreter, reading the original with --expand and the written
program without, is a consistency check only."""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np
import pytest

import ncpp.motion.expand as expand_module
from ncpp.cli import main
from ncpp.guard import without_guard
from ncpp.motion.segments import Arc, Line
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests.compensation.test_dialect_cutter_comp import compensated, machine
from tests.conftest import CORPUS, SHARED
from tests.dialect_motion.test_sinumerik_flow import SECTION_ENDS, SECTIONS
from tests.writeback.closed_form import end_points, landed, squares
from tests.writeback.conftest import linear_errors, machine_file

# 3 squares 40 x 40, each 1 mm deeper, by a FOR loop; the line after it reads the loop's variable
FOR_SQUARES = """DEF INT I
DEF REAL DEPTH=0
G17 G90 G71
G0 X-5 Y-5 Z5
FOR I=1 TO 3
  DEPTH=-I
  G1 X0 Y0 Z=DEPTH F300
  X40
  Y40
  X0
  Y0
ENDFOR
G0 Z=5-DEPTH
M30
"""
# WHILE and REPEAT, each 3 runs with an R parameter counter; the lines after them read it
WHILE_REPEAT = """G17 G90 G71
G0 X-5 Y-5 Z5
R1=0
WHILE R1<3
  R1=R1+1
  G1 X=10*R1 Y0 Z-1 F200
  Y=5*R1
ENDWHILE
G1 X=R1 Y-10
REPEAT
  R1=R1-1
  G1 X=R1*20 Y=-20-R1
UNTIL R1<=0
G1 X50 Y=R1
M30
"""
WHILE_REPEATED = [(10, 0, -1), (10, 5, -1), (20, 0, -1), (20, 10, -1), (30, 0, -1), (30, 15, -1),
                  (3, -10, -1), (40, -22, -1), (20, -21, -1), (0, -20, -1), (50, 0, -1)]  # fmt: skip
# a loop of IF ... GOTOB (X 10 ... 50), a line after it that reads the counter, and a forward jump
# over a line that must not run
JUMPS = """G17 G90 G71
G0 X-5 Y-5 Z5
R1=0
START:
R1=R1+10
G1 X=R1 Y0 Z-1 F200
IF R1<50 GOTOB START
G1 X=R1 Y10
IF R1==50 GOTOF SKIPPED
G1 X999 Y999
SKIPPED:
G0 Z50
M30
"""
JUMPED = [(10, 0, -1), (20, 0, -1), (30, 0, -1), (40, 0, -1), (50, 0, -1), (50, 10, -1)]
# a subprogram called at X 100 and (P2) twice from X 200, which moves its R2 on by 1 each run,
# and a PROC called by its name with a value parameter
CALLS = """G17 G90 G71
G0 X-5 Y-5 Z5
R2=100
L100
R2=200
L100 P2
HOLE(30)
G0 X=R2 Z50
M30
"""
L100 = """G1 X=R2 Y20 Z-2 F300
G2 X=R2 Y60 I0 J20
G1 Y80
R2=R2+1
G0 Z5
M17
"""
HOLE = """PROC HOLE(REAL XP)
DEF REAL DOWN=-3
G1 X=XP Y=XP/2 Z=DOWN F100
G0 Z5
RET
"""
CALLED_AT = [(x, y, -2) for x in (100, 200, 201) for y in (20, 60, 80)] + [(30, 15, -3), (202, 15, 50)]
# a PROC whose parameters are the caller's variables by reference (Job Planning, "Subprograms with
# parameter transfer": VAR), called by its name and by PCALL with a path; the caller's moves after
# each call read what it assigned: LEN 20 -> 40 -> 80, WID 10 -> 15 -> 20, R1 = 600, R2 = 1600
VAR_CALLS = """G17 G90 G71
DEF REAL LEN=20, WID=10
G0 X-5 Y-5 Z5
RECT(LEN, WID, R1)
G1 X=LEN Y=WID+R1/100 Z-1 F200
PCALL/_N_WKS_DIR/_N_PART_WPD/RECT(LEN, WID, R2)
G1 X=LEN+R2/1000 Y=WID Z-1
M30
"""
RECT = """PROC RECT(VAR REAL _LG, VAR REAL _WD, VAR REAL _AREA) DISPLOF
_LG=_LG*2
_WD=_WD+5
G1 X=_LG Y=_WD Z-2 F300
_AREA=_LG*_WD
RET
"""
BY_REFERENCE = [(40, 15, -2), (40, 21, -1), (80, 20, -2), (81.6, 20, -1)]
_WORD = re.compile(r"(?<![A-Z\d_])([XYZ])=?(-?\d+(?:\.\d*)?)")


def points(text: str) -> np.ndarray:
    """Where each block of a Sinumerik program that names X, Y or Z ends (not the placement guard's
    check and message): the test's own reading of the numbers."""
    return end_points(
        text, _WORD, lambda code: _WORD.search(code) is not None and not ('"' in code or "$" in code)
    )


def _with_subprograms(tmp_path: Path) -> tuple[str, ...]:
    (tmp_path / "L100.SPF").write_text(L100)
    (tmp_path / "HOLE.SPF").write_text(HOLE)
    (tmp_path / "RECT.SPF").write_text(RECT)
    return ("--subroutine-path", str(tmp_path))


CASES = [(FOR_SQUARES, "for.mpf", squares(3)), (WHILE_REPEAT, "while.mpf", WHILE_REPEATED),
         (JUMPS, "jumps.mpf", JUMPED), (CALLS, "calls.mpf", CALLED_AT),
         (SECTIONS, "sections.mpf", SECTION_ENDS[1:]), (VAR_CALLS, "var.mpf", BY_REFERENCE)]  # fmt: skip
IDS = ["for", "while-repeat", "gotob", "calls", "section repetition", "by reference"]


@pytest.mark.parametrize("text, name, wanted", CASES, ids=IDS)
def test_every_run_of_a_body_lands_on_its_programmed_points_within_half_a_micron(
    tmp_path, text, name, wanted
):
    """Each corner of each run, the written numbers mapped through the machine's formula, within
    0.5 µm of the point the test computes; the program as written misses them by microns."""
    options = _with_subprograms(tmp_path)
    written, _ = compensated(tmp_path, name, text, "--expand", *options)
    assert landed(points(written), wanted).max() < 0.5e-3
    plain, _ = compensated(tmp_path, "plain-" + name, text, *options)
    assert landed(points(plain), wanted).max() > 5e-3  # (the bodies left as programmed: the measure can fail)


def test_a_for_loop_is_written_as_three_squares_its_variables_set_after_it(tmp_path):
    """FOR I=1 TO 3 (840D sl Job Planning, "Control structures": the variable counts up by 1 while
    not above the end value): three squares at Z-1 ... Z-3, no FOR, ENDFOR or assignment in the
    body; the DEF lines stay at the program's start, and before the line after the loop, which
    reads DEPTH, the variables the loop changed are set (I ends at 4)."""
    written = _expanded(tmp_path, FOR_SQUARES)
    lines = [line.strip() for line in written.splitlines() if not line.startswith(";")]
    first = lines.index("DEF INT I")
    assert lines[first + 1] == "DEF REAL DEPTH=0" and lines[first + 2].startswith(
        "IF ($P_UIFRNUM"
    )  # (the guard)
    assert lines[lines.index("ENDIF") + 1] == "G17 G90 G71"
    assert not re.search(r"FOR|DEPTH=-I|Z=DEPTH", written)
    assert sorted({round(z, 3) for z in points(written)[:, 2]} - {5.0, 8.0}) == [-3.0, -2.0, -1.0]
    end = lines.index("DEPTH=-3")
    assert lines[end + 1] == "I=4" and lines[end + 2].startswith("G0 Z")


def test_a_loops_counter_is_set_before_the_line_that_reads_it_and_a_jumped_line_is_left_out(tmp_path):
    written = _expanded(tmp_path, JUMPS)
    lines = written.splitlines()
    settle = lines.index("R1=50")
    assert "Y10" in lines[settle + 1]
    assert "GOTO" not in written and "R1+10" not in written and "999" not in written
    assert written.count("START:") == 1  # (a label stays where its text stands, once)


def test_after_a_loop_an_out_of_scope_line_of_the_main_program_passes_through_its_variables_set(tmp_path):
    """Outside any loop the rest passes through as it is (as without --expand), after the lines
    that set what the loop changed; the jump's label stays where it stands."""
    text = JUMPS.replace("G0 Z50\n", "G0 Z50 ASPLINE\nG1 X=R1 Y30\n")
    written, messages = compensated(tmp_path, "rest.mpf", text, "--expand")
    lines = written.splitlines()
    assert lines[-6] == "R1=50" and lines[-4:] == ["SKIPPED:", "G0 Z50 ASPLINE", "G1 X=R1 Y30", "M30"]
    assert "ASPLINE is outside the motion interpreter's scope" in messages and "GOTO" not in written
    assert written.count("START:") == 1


def test_calls_are_left_out_and_the_subprogram_files_untouched(tmp_path):
    options = _with_subprograms(tmp_path)
    written, _ = compensated(tmp_path, "calls.mpf", CALLS, "--expand", *options)
    assert not re.search(r"L100|HOLE|PROC|RET|M17|DOWN|XP", written)
    assert re.findall(r"R2=\d+", written) == ["R2=100", "R2=101", "R2=200", "R2=202"]
    assert (tmp_path / "L100.SPF").read_text() == L100 and (tmp_path / "HOLE.SPF").read_text() == HOLE


def test_a_call_by_reference_is_left_out_and_the_variables_it_changed_set_after_it(tmp_path):
    """With --expand the call lines (by name, PCALL) are left out, RECT's moves written with their
    numbers, and before the caller's next line the variables the call changed through its VAR
    parameters are set."""
    options = _with_subprograms(tmp_path)
    written, _ = compensated(tmp_path, "var.mpf", VAR_CALLS, "--expand", *options)
    lines = [line for line in written.splitlines() if not line.startswith(";")]
    assert not re.search(r"RECT|PCALL|_LG|_AREA", written)
    first = lines.index("R1=600")
    assert lines[first : first + 3] == ["R1=600", "LEN=40", "WID=15"]
    second = lines.index("R2=1600")
    assert lines[second : second + 3] == ["R2=1600", "LEN=80", "WID=20"]
    # without --expand the calls stay, and the caller's moves after them, read from what they
    # assigned, are compensated: within 0.5 µm of their points on the machine
    plain, _ = compensated(tmp_path, "plain-var.mpf", VAR_CALLS, *options)
    assert "RECT(LEN, WID, R1)" in plain and "PCALL/_N_WKS_DIR/_N_PART_WPD/RECT(LEN, WID, R2)" in plain
    assert landed(points(plain), BY_REFERENCE[1::2]).max() < 0.5e-3


def test_words_keep_their_form_with_this_runs_numbers():
    """`X=AC(R2)` -> `X=AC(..)`, `CR=R3` -> `CR=..`, `Z=R1` -> `Z..`, a cycle's arguments as
    numbers; words that read no variable as they are (the events' blocks, before the writer)."""
    program = """G17 G90 G71
R2=7
R3=5
G0 X0 Y0 Z5
R1=0
WHILE R1<2
  R1=R1+1
  G1 X=AC(R2*R1) Y=IC(R1) Z=-R1 F=100*R1
  G2 X=AC(R2*R1+10) CR=R3
  CYCLE81(R3, 0, 2, -R1)
ENDWHILE
M30
"""
    interpret, _ = dialect_tools("sinumerik")
    raws = [e.block.raw.strip() for e in interpret(_blocks(program), expand=True)]
    assert "G1 X=AC(7) Y=IC(1) Z-1 F100" in raws and "G1 X=AC(14) Y=IC(2) Z-2 F200" in raws
    assert "G2 X=AC(17) CR=5" in raws and "CYCLE81(5,0,2,-2)" in raws
    assert not any("WHILE" in raw or "R1+1" in raw for raw in raws) and raws[-2:] == ["R1=2", "M30"]


def test_a_word_has_the_value_where_it_stands_in_its_block():
    """A block's items run in order: a word before an assignment in its block reads the value
    before it, a word after it the value after (`X=R1*10 R1=R1+1 Y=R1`)."""
    program = """G17 G90 G71
G0 X0 Y0 Z5
R1=0
WHILE R1<2
  G1 X=R1*10 R1=R1+1 Y=R1
ENDWHILE
M30
"""
    interpret, _ = dialect_tools("sinumerik")
    raws = [e.block.raw.strip() for e in interpret(_blocks(program), expand=True)]
    assert raws[3:5] == ["G1 X0 Y1", "G1 X10 Y2"]


@pytest.mark.parametrize("text, name, _", CASES, ids=IDS)
def test_ncpps_interpreter_reads_the_same_moves_from_both_texts(tmp_path, text, name, _):
    """Consistency: the moves ncpp's interpreter reads from the original with --expand are the
    ones it reads from the written program, mapped through the machine (every end point of the
    first within 0.5 µm of one of the second's, none of which is left as programmed)."""
    options = _with_subprograms(tmp_path)
    interpret, _ = dialect_tools("sinumerik")
    from ncpp.motion.offsets import WorkOffsets

    offsets = WorkOffsets(subroutine_path=(tmp_path,))
    original = _ends(interpret(_blocks(text), expand=True, offsets=offsets))
    written = _ends(interpret(_blocks(compensated(tmp_path, name, text, "--expand", *options)[0])))
    assert len(original) and not any(fixed for _, fixed in written) and not any(f for _, f in original)
    ends = machine(np.array([end for end, _ in written]))
    assert all(np.min(np.linalg.norm(ends - end, axis=1)) < 0.5e-3 for end, _ in original)


@pytest.mark.parametrize(
    "text, message",
    [
        (
            FOR_SQUARES.replace("  X40\n", "  X40 A5\n"),
            # (followed as outside a loop: a machine file that does not allow turning moves refuses it)
            r"prog\.mpf:8:7: this move turns A, and ncpp models the linear axes only",
        ),
        (FOR_SQUARES.replace("  X40\n", "  DEF REAL W\n"), r"prog\.mpf:8:3: --expand: DEF inside a loop"),
        (
            FOR_SQUARES.replace("  X40\n", '  MSG("AT "<<I)\n'),
            r"prog\.mpf:8:3: --expand: MSG with a string made of variables",
        ),
        (
            FOR_SQUARES.replace("  X40\n", "  GOTOF OUT\n"),
            r"prog\.mpf:8:3: --expand: GOTOF inside FOR .* is outside the motion interpreter's scope",
        ),
        (
            FOR_SQUARES.replace("  X40\n", "  CYCLE81(5, 0, 2, -I) R7=I\n"),
            r"prog\.mpf:8:3: --expand: CYCLE81 with an assignment in its block",
        ),
        (
            CALLS.replace("HOLE(30)\n", "L200\n"),
            r"L200\.SPF:1:1: --expand: the subprogram L200 ending without M17 or RET",
        ),
    ],
    ids=["rotary-axis", "def", "message", "jump-out", "cycle-with-assignment", "no-return"],
)
def test_what_cannot_be_written_out_is_refused_with_its_line(tmp_path, capsys, text, message):
    (tmp_path / "L200.SPF").write_text("G1 X1 Y1 Z1 F100\n")
    options = _with_subprograms(tmp_path)
    program = tmp_path / "prog.mpf"
    program.write_text(text)
    code = main(["compensate", "--machine", str(_wide()), "--expand", *options, str(program),
                 "-o", str(tmp_path / "out.mpf")])  # fmt: skip
    assert code != 0 and re.search(message, capsys.readouterr().err)
    assert main(["compensate", "--machine", str(_wide()), *options, str(program), "-o",
                 str(tmp_path / "o.mpf")]) == 0  # fmt: skip


def test_more_blocks_written_out_than_the_bound_are_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(expand_module, "MAX_EXPANDED", 10)
    program = tmp_path / "for.mpf"
    program.write_text(FOR_SQUARES)
    code = main(["compensate", "--machine", str(_wide()), "--expand", str(program),
                 "-o", str(tmp_path / "out.mpf")])  # fmt: skip
    assert code != 0
    assert re.search(r"for\.mpf:\d+:1: --expand: the loops and subroutines make more than 10 ",
                     capsys.readouterr().err)  # fmt: skip


def test_the_command_line_writes_out_and_verifies_on_the_wide_machine(tmp_path):
    """`ncpp compensate --machine wide.toml --expand prog.mpf -o out.mpf`: the verifier reads the
    written program back and accepts it."""
    options = _with_subprograms(tmp_path)
    for _, name, _ in CASES:
        text = next(t for t, n, _ in CASES if n == name)
        program, out = tmp_path / name, tmp_path / f"out-{name}"
        program.write_text(text)
        argv = ["compensate", "--machine", str(_wide()), "--expand", *options, str(program), "-o", str(out)]
        assert main(argv) == 0
        assert not re.search(r"GOTO|WHILE|FOR |UNTIL|L100", out.read_text())


CEAD = CORPUS / "sinumerik" / "CEAD_nc-gcode-interpreter"
# the corpus programs with loops, jumps, CASE or IF that stay in ncpp's scope
LOOPED = ["loop.mpf", "goto.mpf", "case.mpf", "arrays.mpf", "if_statement.mpf", "logic_operators.mpf"]
NO_ERRORS = machine_file("no-errors", linear_errors(EXX=0.0), 5000.0)


@pytest.mark.parametrize("name", LOOPED)
def test_the_corpus_loops_written_out_reach_the_cead_interpreters_positions(tmp_path, name):
    """The CEAD interpreter's recorded positions (`test_sinumerik_oracle`) for the program, reached
    by the program written out on a machine without errors: no loop, jump or CASE line left."""
    if not CEAD.is_dir():
        pytest.skip(f"corpus not found at {CEAD}")
    from tests.dialect_motion.test_sinumerik_oracle import TOLERANCE, _ncpp, _oracle

    machine_file, out = tmp_path / "none.toml", tmp_path / name
    machine_file.write_text(NO_ERRORS)
    assert (
        main(["compensate", "--machine", str(machine_file), "--expand", str(CEAD / name), "-o", str(out)])
        == 0
    )
    assert not re.search(r"^\s*(N\d+\s+)?(WHILE|ENDWHILE|FOR|ENDFOR|CASE|IF|ENDIF|LOOP|ENDLOOP)\b|GOTO",
                         re.sub(";.*", "", out.read_text()), re.MULTILINE | re.IGNORECASE)  # fmt: skip
    positions, stopped = _ncpp(out)
    expected = _oracle(CEAD / name)
    assert stopped is None and len(positions) == len(expected)
    for mine, row in zip(positions, expected):
        assert all(abs(mine["XYZ".index(axis)] - value) < TOLERANCE for axis, value in row.items())


# ---- helpers ---------------------------------------------------------------------------------


def _wide() -> Path:
    wide = SHARED / "machines" / "wide.toml"
    if not wide.is_file():
        pytest.skip(f"{wide} not found")
    return wide


def _blocks(text: str):
    """The program's blocks, without the placement guard the written program has (as the verifier)."""
    _, parsed = parse_program(io.BytesIO(text.encode("latin-1")), "prog.mpf", "sinumerik")
    return without_guard(parsed)


def _ends(events) -> list[tuple[np.ndarray, object]]:
    return [(np.array(e.end), e.fixed) for e in events if type(e) is Line or type(e) is Arc]


def _expanded(tmp_path: Path, text: str, name: str = "prog.mpf") -> str:
    """The program ncpp writes with --expand for AFFINE's machine (`compensated`)."""
    return compensated(tmp_path, name, text, "--expand")[0]
