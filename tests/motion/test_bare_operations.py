"""A binary operation outside brackets (`#1 = #2 * 2`, `G0 X#2+1`) is refused in a LinuxCNC program
where rs274 refuses it ("Bad character '*' used": rs274ngc reads a value as a number, a parameter, a
function or a bracketed expression, each after unary signs), and read in a Fanuc one (macro B takes
it bare); bracketed, signed and function values stay read, and move as rs274 moves them."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests.rs274 import error, ran, run

BARE = [
    ("#2=3\n#1 = #2 * 2\nG0 X#1\nM2\n", 2),
    ("#2=3\nG0 X#2+1\nM2\n", 2),
    ("#2=3\nG0 X[#2]+1\nM2\n", 2),
    ("#2=3\nG0 X-[#2]*2\nM2\n", 2),
    ("#<a>=3\n#<b> = #<a> MOD 2\nM2\n", 2),
]
READ = "#2=3\n#1 = [#2 * 2]\nG0 X[#2+1] Y-[#1]\n#3 = -[#1+1]\n#4 = ATAN[1]/[2]\nG0 X#4 Z#3\n#5 = -#2\nG0 X-#5\nM2\n"


def moves(text: str, dialect: str) -> list[tuple[float, ...]]:
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(text.encode()), "p.ngc", dialect)
    return [
        e.end
        for e in interpret(blocks, file="p.ngc", warnings=Warnings(stream=io.StringIO()))
        if hasattr(e, "end")
    ]


@pytest.mark.parametrize(("text", "line"), BARE)
def test_a_bare_binary_operation_is_refused_where_rs274_refuses_it(text, line):
    done = run(text)
    if not ran(done):
        pytest.skip("rs274 did not run")
    message, source = error(done.stderr)
    assert source == text.splitlines()[line - 1] and ("Bad character" in message or "unary" in message)
    with pytest.raises(NcppError) as refused:
        moves(text, "iso")
    assert refused.value.where.line == line and message in str(refused.value), str(refused.value)


@pytest.mark.parametrize(("text", "line"), BARE[:2])
def test_fanuc_reads_a_bare_binary_operation(text, line):
    assert moves(text.replace("M2", "M30"), "fanuc")


def test_bracketed_signed_and_function_values_move_where_rs274_moves():
    done = run(READ)
    if not ran(done):
        pytest.skip("rs274 did not run")
    theirs = [tuple(float(v) for v in line.split("(")[1].split(",")[:3])
              for line in done.stdout.splitlines() if "STRAIGHT_TRAVERSE" in line]  # fmt: skip
    assert theirs and [tuple(round(v, 4) for v in m[:3]) for m in moves(READ, "iso")] == theirs
