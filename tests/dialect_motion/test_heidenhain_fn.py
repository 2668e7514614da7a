"""Klartext FN 0-8 Q parameter arithmetic, with the TNC 640 Klartext manual's examples
("Basic arithmetic", "Angle functions")."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import Line
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program


def end_of(assignments: str, axis: str = "X") -> float:
    """Where `L {axis}+Q9` puts the tool after the FN blocks."""
    text = f"0 BEGIN PGM P MM\n{assignments}\n9 L {axis}+Q9 FMAX\n10 END PGM P MM\n"
    interpret, _ = dialect_tools("heidenhain")
    _, blocks = parse_program(io.BytesIO(text.encode()), "p.h", "heidenhain")
    moves = [
        e for e in interpret(blocks, file="p.h", warnings=Warnings(stream=io.StringIO())) if type(e) is Line
    ]
    return moves[-1].end["XYZ".index(axis)]


@pytest.mark.parametrize(
    "blocks, value",
    [
        ("1 FN 0: Q9 = +10", 10.0),
        ("1 FN 0: Q5 = +10\n2 FN 3: Q9 = +Q5 * +7", 70.0),
        ("1 FN 1: Q9 = -5 + +2,5", -2.5),
        ("1 FN 0: Q2 = +10\n2 FN 2: Q9 = +Q2 - -5", 15.0),
        ("1 FN 4: Q9 = +6 DIV +2", 3.0),
        ("1 FN 5: Q9 = SQRT +16", 4.0),
        ("1 FN 0: Q5 = +30\n2 FN 6: Q9 = SIN+Q5", 0.5),
        ("1 FN 7: Q9 = COS-60", 0.5),
        ("1 FN 8: Q9 = +5 LEN +4", 41**0.5),
        ("1 FN 13: Q9 = +25 ANG +50", 26.565051177),  # the manual's example: arctan 0.5
        ("1 FN 0: Q1 = -1\n2 FN 13: Q9 = +0 ANG +Q1", 180.0),
        ("1 FN 13: Q9 = -1 ANG +0", 270.0),  # (0 to 360 degrees)
    ],
)
def test_fn_arithmetic_as_the_manual_gives_it(blocks, value):
    assert end_of(blocks) == pytest.approx(value)


@pytest.mark.parametrize(
    "block, message",
    [("1 FN 4: Q9 = +6 DIV +0", "FN 4: division by zero"), ("1 FN 5: Q9 = SQRT -1", "square root of a negative"),
     ("1 FN 4: Q9 = +6 / +2", "FN 4: expected Q.. = a DIV b")],
)  # fmt: skip
def test_what_the_control_refuses_is_refused_with_its_line(block, message):
    with pytest.raises(NcppError, match=message) as err:
        end_of(block)
    assert err.value.where.line == 2
