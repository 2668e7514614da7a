"""A tool length applied in the block that changes the tool, as LinuxCNC's rs274 applies it.

`G43 H..` alone keeps the machine where it is (the program position moves the other way);
`T4 M6 G43` keeps the program position, so the next move that does not name Z takes the
machine by the difference.  Judged by rs274 itself, with tools of different lengths."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from ncpp.errors import Warnings
from ncpp.motion import interpret
from ncpp.motion.canon import canon_call, read_canon
from ncpp.motion.offsets import UNIT_MM, WorkOffsets
from ncpp.program.parser import parse_stream
from tests import rs274

pytestmark = pytest.mark.oracle

PROGRAM = """G20 G90
G0 X0 Y0 Z1
T1 M6 G43
G0 X1
G0 Z1
T4 M6 G43
G0 X2
G53 G0 Z0
T3 M6 G43
G1 X3 F10
G43 H4
G0 X4
T2 M6
G43
G0 X5
T1 M6 G43 H3
G2 X6 Y1 I0.5 J0.5
M2
"""
TOOLS = "".join(f"T{n} P{n} Z{0.4 + 0.02 * n:.2f} D0.01\n" for n in range(1, 10))


def test_tool_lengths_applied_with_a_tool_change_follow_rs274(tmp_path: Path):
    program, table = tmp_path / "lengths.ngc", tmp_path / "tools.tbl"
    program.write_text(PROGRAM)
    table.write_text(TOOLS)
    proc = rs274.run(program, tool_table=table, home=tmp_path, timeout=60)
    if not rs274.ran(proc):
        pytest.skip(f"rs274 oracle did not run: {proc.stderr.strip()[:200]}")
    theirs = read_canon(proc.stdout)
    offsets = WorkOffsets.given(
        {}, None, UNIT_MM["inch"], str(table)
    )  # the stand-alone rs274 reads its table in inches
    events = interpret(parse_stream(io.BytesIO(PROGRAM.encode()), "lengths.ngc"), file="lengths.ngc",
                       warnings=Warnings(stream=io.StringIO()), offsets=offsets)  # fmt: skip
    mine = [call for call in map(canon_call, events) if call is not None]
    assert [c.name for c in mine] == [c.name for c in theirs]
    for a, b in zip(mine, theirs):
        assert a.args == pytest.approx(b.args, abs=1e-4), (a, b)
