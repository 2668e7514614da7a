"""`;` on Fanuc and Haas: their manuals and screens show the end of block as `;`, and hand-written
programs carry it (`G43; H01 (USE TOOL OFFSET #1)`, a Haas mill program on GitHub).  Whether the
control reads words after it as a block of their own or skips them is not known, so such a line
is refused where it runs (`ncpp/program/parser.py`, `_words_after_eob`); a `;` with nothing but a
comment after it reads as before, and LinuxCNC and grbl keep `;` a comment to the line's end."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import Line
from ncpp.pipeline import ErrorSource, dialect_tools, process
from ncpp.program.blocks import Comment, Word
from ncpp.program.dialects import parse_program
from tests.conftest import SHARED

WIDE = SHARED / "machines" / "wide.toml"

# A Haas mill program's head as hand-written with `;` ends (GitHub, cline/smiley.nc's lines)
PROGRAM = (
    "%\nO00001\n(SMILEY)\nM06 T1; \t\t(Select tool)\nM03 S5000;\nG54; \t\t\t(Use Work Offset G54)\n"
    "G90 G17;\nG00 X0. Y0. Z0.; \t(Position at 0)\nG43; H01 \t\t(Use Tool Offset #1)\nG91;\nZ0.15;\nM30\n%\n"
)


def events(program: str, dialect: str) -> list:
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(program.encode()), "p.nc", dialect)
    return list(interpret(blocks, file="p.nc", warnings=Warnings(stream=io.StringIO())))


@pytest.mark.parametrize("dialect, name", [("haas", "Haas"), ("fanuc", "Fanuc")])
def test_words_after_a_semicolon_are_refused_where_they_run(dialect, name):
    with pytest.raises(NcppError) as caught:
        events(PROGRAM, dialect)
    assert str(caught.value.where) == "p.nc:9:6"
    assert caught.value.message.startswith(f"words follow `;` on the line (`H01`): a {name} control shows")


@pytest.mark.parametrize("dialect", ["haas", "fanuc"])
def test_a_semicolon_with_only_a_comment_after_it_ends_the_block(dialect):
    _, blocks = parse_program(io.BytesIO(b"M06 T1; \t\t(Select tool)\nG0 X1.;\n"), "p.nc", dialect)
    first, second = blocks
    assert [(w.letter, w.value) for w in first.words()] == [("M", 6.0), ("T", 1.0)]
    assert [type(i) for i in first.items] == [Word, Word, Comment] and second.words()[-1].value == 1.0
    moves = events("G21 G90\nG0 X1.; (A)\nG1 X2. F100.;\nM30\n", dialect)
    assert [e.end[0] for e in moves if type(e) is Line] == [1.0, 2.0]


def test_a_semicolon_is_a_comment_to_the_end_of_the_line_in_linuxcnc():
    """rs274 reads `G43; H01` as G43 alone (the tool's own length), H01 a comment."""
    _, (block,) = parse_program(io.BytesIO(b"G43; H01\n"), "p.nc", "iso")
    assert [w.letter for w in block.words()] == ["G"] and block.items[-1].text == " H01"


@pytest.mark.skipif(not WIDE.exists(), reason="no shared machine file")
def test_compensating_refuses_the_line_with_nothing_written():
    out = io.BytesIO()
    with pytest.raises(NcppError, match="words follow `;`") as caught:
        source = ErrorSource.from_machine_file(str(WIDE))
        process(io.BytesIO(PROGRAM.encode()), out, file="p.nc", source=source, dialect="haas",
                warnings=Warnings(stream=io.StringIO()))  # fmt: skip
    assert caught.value.where.line == 9 and out.getvalue() == b""
