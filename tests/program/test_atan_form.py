"""The arc tangent is read in its two-argument form, ATAN[y]/[x], the one form Fanuc macro B, Haas
and LinuxCNC give; an ATAN without the `/[x]` (one argument, or Fanuc 30i's comma form) is refused
at the ATAN with what is read, where the grammar's error was an "unexpected end of block" past it."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import Line
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program


def events(program: str, dialect: str) -> list:
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(program.encode()), "p.nc", dialect)
    return list(interpret(blocks, file="p.nc", warnings=Warnings(stream=io.StringIO())))


@pytest.mark.parametrize("dialect", ["fanuc", "haas", "iso"])
@pytest.mark.parametrize(
    "line, col",
    [("#2=ATAN[#1]", 4), ("#2=[ATAN [#1]]", 5), ("#3=ATAN[#1]/[2.]+ATAN[3.]", 18), ("#3=ATAN[1,2]", 4)],
)
def test_an_atan_without_its_second_argument_is_refused_at_the_atan(dialect, line, col):
    with pytest.raises(NcppError) as caught:
        events(f"#1=1.\n{line}\nG0 X1.\nM30\n", dialect)
    assert caught.value.message.startswith(
        "ATAN without `/[x]` after its bracket: ncpp reads the arc tangent"
    )
    assert str(caught.value.where) == f"p.nc:2:{col}"


@pytest.mark.parametrize("dialect", ["fanuc", "haas", "iso"])
def test_the_two_argument_atan_is_read_in_degrees(dialect):
    moves = events("#1=1.\n#2=ATAN[#1]/[-1.]\nG0 X#2\nM30\n", dialect)
    assert [e.end[0] for e in moves if type(e) is Line] == [pytest.approx(135.0)]
