"""Klartext and Sinumerik interpreters follow the rotary axes A B C as the ISO reading does: a
word that names where the axis stands is a plain move, a turn on a line is compensated piece by
piece (each piece its share, its words absolute) where the machine file says the programmed X Y Z
are the linear axes' positions, else refused; what ncpp does not follow (the control's own way,
an arc that turns) ends interpretation with a warning.  The written numbers are judged by closed-form
arithmetic on the programmed line, and read back with ncpp's reader."""

from __future__ import annotations

import io
import math
import re
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import Line
from ncpp.pipeline import ErrorSource, Stats, dialect_tools, process
from ncpp.program.dialects import parse_program

ROOT = Path(__file__).resolve().parents[2]
PLACED = WorkOffsets.at((400.0, 350.0, 300.0))
NUMBER = r"([-+]?\d+(?:\.\d*)?)"

# DangaRPT/CNC_Prog test.mpf (an NX-style Sinumerik program), its first twelve lines as written:
# `A0.0` on the first move, where the rotary axis stands (0 before a word names it, as rs274ngc)
DANGA = """N000001 G40 G17 G90
N000002 T01 M06
N000003 T00
N000004 S1061 M03
N000005 G01 X-26.313 Y23.749 A0.0 F3000
N000006 Z13. F3000
N000007 Z3. F3000
N000008 Z0.0 F250.
N000009 G03 X-22.313 Y19.749 CR=4. F250.
N000010 G01 X22.313 F250.
N000011 X27.999 Y14.063 F250.
N000012 Y11.383 F250.
M30
"""
INDEXED = """0 BEGIN PGM P MM
1 TOOL CALL 1 Z S1000
2 L X+0 Y+0 Z+10 A+0 C+0 R0 FMAX
3 L Z+0 F500
4 L X+300 Y+200
5 L X+10 A+0
6 END PGM P MM
"""
# A 3+2 program: A and C positioned, then milling in X Y Z
THREE_PLUS_TWO = {
    "p.mpf": "G0 X0 Y0 Z50\nG0 A30 C45\nG1 Z0 F500\nG1 X300 Y200\nG1 X10\nG0 Z50\nM30\n",
    "p.h": "0 BEGIN PGM P MM\n1 L X+0 Y+0 Z+50 R0 FMAX\n2 L A+30 C+45 FMAX\n3 L Z+0 F500\n4 L X+300 Y+200\n"
    "5 L X+10\n6 L Z+50 FMAX\n7 END PGM P MM\n",
}
# A line from X0 Y0 to X300 Y200 that turns A from 0 to 90 (line 2 / block 2, the A word at column 14 / 17)
TURNING = {
    "c.mpf": "G0 X0 Y0 Z0\nG1 X300 Y200 A90 F500\nG1 X10\nM30\n",
    "r.h": "0 BEGIN PGM R MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n2 L X+300 Y+200 A+90 F500\n3 L X+10\n4 END PGM R MM\n",
}


def _machine(tmp_path: Path, turns: bool) -> ErrorSource:
    """HR5B; with `turns`, its programmed X Y Z said to be the linear axes' positions."""
    text = (ROOT / "samples/machines/hr5b.toml").read_text()
    if turns:
        text = text.replace("max_correction_mm", "rotary_xyz_are_axis_positions = true\nmax_correction_mm", 1)
    path = tmp_path / "m.toml"
    path.write_text(text)
    return ErrorSource.from_machine_file(str(path))


def _compensated(program: str, name: str, source: ErrorSource) -> tuple[str, Stats, str]:
    said, out = io.StringIO(), io.BytesIO()
    stats = process(io.BytesIO(program.encode()), out, file=name, source=source, warnings=Warnings(stream=said),
                    offsets=PLACED, guard=None)  # fmt: skip
    return out.getvalue().decode(), stats, said.getvalue()


def _moves(text: str, name: str) -> list[Line]:
    """The lines ncpp's own reader makes of a program (no placement: program coordinates)."""
    dialect = "heidenhain" if name.endswith(".h") else "sinumerik"
    interpret, _ = dialect_tools(dialect)
    blocks = parse_program(io.BytesIO(text.encode()), name, dialect)[1]
    return [
        e for e in interpret(blocks, file=name, warnings=Warnings(stream=io.StringIO())) if type(e) is Line
    ]


def _word(line: str, letter: str) -> float | None:
    match = re.search(rf"(?<![A-Z]){letter}{NUMBER}", line)
    return None if match is None else float(match.group(1))


@pytest.mark.parametrize("program, name, moves", [(DANGA, "test.mpf", 8), (INDEXED, "i.h", 4)])
def test_a_rotary_word_where_the_axis_stands_is_a_plain_move(tmp_path, program, name, moves):
    """Compensated on a machine file that allows no turn: no move turns."""
    written, stats, said = _compensated(program, name, _machine(tmp_path, turns=False))
    assert "outside the motion interpreter's scope" not in said
    assert stats.summary is not None and stats.summary.moves == moves
    first = next(line for line in written.splitlines() if "A0.0" in line or "A+0 C+0" in line)
    programmed = next(line for line in program.splitlines() if "A0.0" in line or "A+0 C+0" in line)
    assert first != programmed  # (its X Y corrected, the rotary words kept)
    for letter in "XY":
        assert 0 < abs(_word(first, letter) - _word(programmed, letter)) < 0.1


@pytest.mark.parametrize("name", sorted(THREE_PLUS_TWO))
def test_a_3_plus_2_program_is_compensated_in_x_y_z(tmp_path, name):
    program = THREE_PLUS_TWO[name]
    written, stats, said = _compensated(program, name, _machine(tmp_path, turns=True))
    assert "outside the motion interpreter's scope" not in said
    summary = stats.summary
    assert summary is not None and summary.moves == 6  # (the positioning of A and C among them)
    assert summary.feed_mm == pytest.approx(50 + math.hypot(300, 200) + 290, abs=0.05)
    positioning = [line for line in written.splitlines() if re.search(r"A\+?30 C\+?45", line)]
    assert len(positioning) == 1 and positioning[0].split(" ", 1)[-1] in program  # (as written)


@pytest.mark.parametrize("name", sorted(TURNING))
def test_each_piece_of_a_turning_line_turns_its_share(tmp_path, name):
    written, stats, said = _compensated(TURNING[name], name, _machine(tmp_path, turns=True))
    assert "outside the motion interpreter's scope" not in said
    lines = written.splitlines()
    start = next(n for n, line in enumerate(lines) if "F500" in line)
    end = next(n for n, line in enumerate(lines) if re.search(r"X\+?10\.0", line))
    turning = lines[start:end]
    shares = [a for a in (_word(line, "A") for line in turning) if a is not None]
    n = len(shares)
    assert n > 1  # (the line is split: hr5b's errors bow along it)
    # the k-th piece ends at 90 k / n degrees, where the programmed line is at k / n of its way
    assert shares == pytest.approx([90.0 * k / n for k in range(1, n + 1)], abs=1e-9)
    x = y = 0.0
    for line in turning:
        x, y = _word(line, "X") or x, _word(line, "Y") or y
        a = _word(line, "A")
        if a is not None:
            assert x == pytest.approx(300.0 * a / 90.0, abs=0.1)
            assert y == pytest.approx(200.0 * a / 90.0, abs=0.1)
    # read back: every move of the block turns A in proportion to its way along the line
    for move in (m for m in _moves(written, name) if m.extra and m.extra_start != m.extra):
        assert move.extra[0] == pytest.approx(90.0 * move.end[0] / 300.0, abs=0.05)
        assert move.extra[0] - move.extra_start[0] == pytest.approx(90.0 / n, abs=1e-9)


@pytest.mark.parametrize("name, where", [("c.mpf", "c.mpf:2:14:"), ("r.h", "r.h:3:17:")])
def test_a_turn_is_refused_where_the_machine_file_does_not_allow_it(tmp_path, name, where):
    with pytest.raises(NcppError) as refused:
        _compensated(TURNING[name], name, _machine(tmp_path, turns=False))
    assert str(refused.value).startswith(where) and "this move turns A" in str(refused.value)


@pytest.mark.parametrize(
    "name, program, turned",
    [
        ("f.mpf", "G0 X0 Y0 Z0 A10\nG1 X30 A=IC(80) F500\nG91 X-20 A-40\nG90 X0 A=AC(0) C=DC(360)\nM30\n",
         [10.0, 90.0, 50.0, 0.0]),
        ("f.h", "0 BEGIN PGM F MM\n1 L X+0 Y+0 Z+0 A+10 R0 FMAX\n2 L X+30 IA+80 F500\n3 L IX-20 A+50\n"
         "4 L X+0 IA-50\n5 END PGM F MM\n", [10.0, 90.0, 50.0, 0.0]),
    ],
)  # fmt: skip
def test_absolute_and_incremental_rotary_words_are_followed(name, program, turned):
    assert [move.extra[0] for move in _moves(program, name)] == turned


@pytest.mark.parametrize(
    "name, program, where, what",
    [
        ("d.mpf", "G0 X0 Y0 Z0 C=DC(0)\nG1 X10 C=DC(90) F100\nM30\n", "d.mpf:2:8:", "C=DC() turning the axis"),
        ("d.mpf", "G0 X0 Y0 Z0\nG1 X10 C=ACP(90) F100\nM30\n", "d.mpf:2:8:", "ACP()"),
        ("a.mpf", "G0 X0 Y0 Z0\nG2 X20 Y0 CR=10 A5 F100\nM30\n", "a.mpf:2:17:", "in a move other than G0 or G1"),
        ("m.h", "0 BEGIN PGM M MM\n1 L X+0 Y+0 Z+0 R0 FMAX M126\n2 L X+30 A+80 F500\n3 END PGM M MM\n",
         "m.h:3:10:", "under M126"),
        ("c.h", "0 BEGIN PGM C MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n2 CC X+0 Y+0\n3 C X+0 Y+0 A+10 DR+ F100\n"
         "4 END PGM C MM\n", "c.h:4:13:", "in a block other than a line L or LP"),
        ("n.h", "0 BEGIN PGM N MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n2 L X+30 F500\n3 RND R5\n4 L Y+30 A+10\n"
         "5 END PGM N MM\n", "n.h:4:3:", "RND/CHF next to a move that turns a rotary axis"),
    ],
)  # fmt: skip
def test_a_turn_ncpp_does_not_follow_ends_interpretation(tmp_path, name, program, where, what):
    written, _, said = _compensated(program, name, _machine(tmp_path, turns=True))
    assert where in said and what in said and "outside the motion interpreter's scope" in said
    rest = program.splitlines()[int(where.split(":")[1]) - 1 :]  # (as written from there on)
    tail = written.splitlines()[-len(rest) :]
    if name.endswith(".h"):  # (Klartext's blocks numbered again after the header)
        rest, tail = ([line.split(" ", 1)[1] for line in lines] for lines in (rest, tail))
    assert tail == rest


def test_a_loop_written_out_turns_as_each_run_does(tmp_path):
    """--expand: each run of `A=IC(5)` turns from where the run before left A (5, 10, 15), `C=DC(R1)`
    is written with its value."""
    program = ("DEF INT I\nR1=0\nG0 X-5 Y-5 Z5 C=DC(R1)\nFOR I=1 TO 3\n  G1 X0 Y0 Z=-I F300 C=DC(R1)\n"
               "  X40 A=IC(5)\n  Y40\nENDFOR\nM30\n")  # fmt: skip
    said, out = io.StringIO(), io.BytesIO()
    process(io.BytesIO(program.encode()), out, file="l.mpf", source=_machine(tmp_path, turns=True),
            warnings=Warnings(stream=said), offsets=PLACED, guard=None, expand=True)  # fmt: skip
    written = out.getvalue().decode()
    assert "FOR" not in written and "C=DC(0)" in written and "warning" not in said.getvalue()
    ends = [
        round(move.extra[0], 9) for move in _moves(written, "l.mpf") if move.extra_start[0] != move.extra[0]
    ]
    assert ends == [5.0, 10.0, 15.0]
