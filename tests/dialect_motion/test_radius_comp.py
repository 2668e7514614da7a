"""Tool radius compensation in the three dialects (G41/G42 ... G40, RL/RR ... R0): the moves the
tool makes off the programmed contour are marked; they are compensated where the tool centre stands
(tests/compensation/test_cutter_comp_accuracy.py for ISO, tests/compensation/test_dialect_cutter_comp.py
for Klartext and Sinumerik), in G17 and in the other planes, and the same part compensates to the same
moves after them in every dialect."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import Warnings
from ncpp.motion.segments import COMP, Arc, Line
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests.motion.compensating import compensate

ISO = """G21 G90 G17
G0 X-20 Y-20 Z5
G1 Z-5 F500
G41 D1 G1 X0 Y0 F200
G1 X40
G3 X50 Y10 I0 J10
G1 Y40
G40 G1 X55 Y45
G1 X70
G2 X80 Y55 I0 J10
G0 Z50
M30
"""
HEIDENHAIN = """0 BEGIN PGM COMP MM
1 L X-20 Y-20 Z+5 R0 FMAX
2 L Z-5 R0 F500
3 L X+0 Y+0 RL F200
4 L X+40
5 CC X+40 Y+10
6 C X+50 Y+10 DR+
7 L Y+40
8 L X+55 Y+45 R0
9 L X+70
10 CC X+70 Y+55
11 C X+80 Y+55 DR-
12 L Z+50 R0 FMAX M30
13 END PGM COMP MM
"""
SINUMERIK = ISO.replace("G21 G90 G17", "G90 G17 G71").replace("G41 D1", "G41")  # (D is a tool edge there)
# dialect: (program, file name, the line compensation starts on, the lines to the exit move's)
PROGRAMS = {
    "iso": (ISO, "part.ngc", 4, 5),
    "heidenhain": (HEIDENHAIN, "part.h", 4, 6),
    "sinumerik": (SINUMERIK, "part.mpf", 4, 5),
}


def moves(text: str, name: str) -> list:
    dialect, blocks = parse_program(io.BytesIO(text.encode()), name, None)
    interpret, _ = dialect_tools(dialect)
    return [
        e
        for e in interpret(blocks, file=name, warnings=Warnings(stream=io.StringIO()))
        if type(e) is Line or type(e) is Arc
    ]


@pytest.mark.parametrize("dialect", PROGRAMS)
def test_the_moves_from_the_first_with_compensation_to_the_first_after_it_are_marked(dialect):
    text, name, _, _ = PROGRAMS[dialect]
    marked = [e.fixed == COMP or e.centre_shift is not None for e in moves(text, name)]
    assert marked == [False, False, True, True, True, True, True, False, False, False]


# the same part with the tool along Y (Klartext: the ZX plane, as G18), which compensation follows too
IN_G18 = HEIDENHAIN.replace(
    "0 BEGIN PGM COMP MM\n", "0 BEGIN PGM COMP MM\n0 TOOL DEF 1 L+0 R+2\n0 TOOL CALL 1 Y\n"
)


def test_outside_g17_they_are_compensated_too():
    """(How close: tests/compensation/test_dialect_cutter_comp.py.)"""
    _, name, first, count = PROGRAMS["heidenhain"]
    first += 2  # (the TOOL DEF and TOOL CALL lines)
    out, warned = compensate(IN_G18, name)
    source, lines = (
        [line.split(" ", 1)[1] for line in IN_G18.splitlines()],
        [line.split(" ", 1)[1] for line in out.splitlines()[1:]],
    )  # (Klartext renumbers)
    contour = [line for line in source[first - 1 : first - 1 + count] if not line.startswith("CC")]
    assert len(contour) == count - 1 and not set(contour) & set(lines), out  # every one rewritten
    assert "cutter compensation" not in warned, warned


@pytest.mark.parametrize("dialect", PROGRAMS)
def test_in_g17_they_are_compensated(dialect):
    """(Where the tool centre stands is not known without the tool table: the warning says so.)"""
    text, name, first, count = PROGRAMS[dialect]
    out, warned = compensate(text, name)
    unnumbered = (lambda line: line.split(" ", 1)[1]) if dialect == "heidenhain" else (lambda line: line)
    source, lines = (
        [unnumbered(line) for line in text.splitlines()],
        [unnumbered(line) for line in out.splitlines()],
    )
    entry = source[first - 1]
    start = next(k for k, line in enumerate(lines) if line.startswith(entry[: entry.index("X") + 1]))
    assert all(
        lines[start + k] != source[first - 1 + k] for k in range(count) if "CC" not in source[first - 1 + k]
    )
    assert (
        warned.count("warning") == 1
        and f"{name}:{first}:1: warning: cutter compensation with the tool radius not known" in warned
    )


def test_the_same_part_compensates_alike_after_compensation_in_every_dialect():
    after = {}
    for dialect, (text, name, _, _) in PROGRAMS.items():
        if dialect == "iso":  # (compensated under compensation too)
            continue
        out, _ = compensate(text, name)
        compensated = [e for e in moves(out, name) if e.fixed != COMP]
        after[dialect] = [
            e.end for e in compensated[-4:]
        ]  # from the exit move's end: connecting step, line, arc, rapid
        programmed = [e.end for e in moves(text, name)[-3:]]
        assert len(after[dialect]) == 4 and all(
            max(abs(a - b) for a, b in zip(p, q)) > 0.001 for p, q in zip(after[dialect][1:], programmed)
        )
    assert all(
        max(abs(a - b) for a, b in zip(p, q)) < 2e-4 for p, q in zip(after["heidenhain"], after["sinumerik"])
    ), after
