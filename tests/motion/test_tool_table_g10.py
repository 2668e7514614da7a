"""G10 L1 sets a tool's entry in the tool table, which a later G43 (or G41/G42) applies (LinuxCNC
G-code manual, "G10 L1 Set Tool Table").  The program opens as a real one does (Thaddeus-Maximus/
lagun-linuxcnc, nc_files/HEMA/HEMA-P005.ngc: `G10 L1 P1 Z0.0 R5.0 ; set tool`, then `T1`, `M06`);
judged by rs274 itself, with and without the tool table told to ncpp."""

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

PROGRAM = """G21  ; mm
G10 L1 P1 Z0.0 R5.0 ; set tool
T1   ; set tool to T1
M06  ; manual toolchange
G54  ; absolute coordinates
F1000
G0 X50 Y-10 Z2
G1 Z-10
G10 L1 P1 Z5
G0 Z2
G43
G0 X70
G20
G10 L1 P1 Z0.5
G43
G1 Z0.2
G10 L1 P1 X0.1
G43 H1
G0 Y1
G10 L1 P2 Z0.3
T2 M6 G43
G0 X3
M2
"""
TOOLS = "".join(f"T{n} P{n} Z0 D0.01\n" for n in range(1, 10))


def calls(told: bool, tmp_path: Path) -> tuple[list, str]:
    table = tmp_path / "tools.tbl"
    offsets = WorkOffsets.given({}, None, UNIT_MM["inch"], str(table) if told else None)
    said = io.StringIO()
    events = interpret(parse_stream(io.BytesIO(PROGRAM.encode()), "g10.ngc"), file="g10.ngc",
                       warnings=Warnings(stream=said), offsets=offsets)  # fmt: skip
    return [call for call in map(canon_call, events) if call is not None], said.getvalue()


@pytest.mark.parametrize("told", [True, False], ids=["table told", "table not told"])
def test_tool_entries_the_program_sets_follow_rs274(tmp_path: Path, told: bool):
    program, table = tmp_path / "g10.ngc", tmp_path / "tools.tbl"
    program.write_text(PROGRAM)
    table.write_text(TOOLS)
    proc = rs274.run(program, tool_table=table, home=tmp_path, timeout=60)
    if not rs274.ran(proc):
        pytest.skip(f"rs274 oracle did not run: {proc.stderr.strip()[:200]}")
    assert not rs274.messages(proc), proc.stderr
    theirs = [call for call in read_canon(proc.stdout) if call.name != "SET_TOOL_TABLE_ENTRY"]
    mine, said = calls(told, tmp_path)
    assert [c.name for c in mine] == [c.name for c in theirs]
    for a, b in zip(mine, theirs):
        assert a.args == pytest.approx(b.args, abs=1e-4), (a, b)
    assert "out of scope" not in said and "not told" not in said, said  # (every G43 reads a set entry)


def test_a_tool_the_told_table_lacks_is_refused_as_rs274_refuses_it(tmp_path: Path):
    table = tmp_path / "tools.tbl"
    table.write_text(TOOLS)
    offsets = WorkOffsets.given({}, None, UNIT_MM["inch"], str(table))
    program = "G21\nG10 L1 P77 Z5\nM2\n"
    with pytest.raises(Exception, match="Requested tool 77 not found in the tool table"):
        list(interpret(parse_stream(io.BytesIO(program.encode()), "t.ngc"), file="t.ngc",
                       warnings=Warnings(stream=io.StringIO()), offsets=offsets))  # fmt: skip
