"""Tool lengths place a program on the machine too: G43 adds the tool's offset from the
control's tool table (--tool-table) to every machine position, and the longer tool
lengthens the Abbe arm through which the axes' angular errors move the tip."""

import io
import re
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.tools import ToolTable
from ncpp.pipeline import ErrorSource, process
from ncpp.simulate import contour_error, sample_events
from tests.compensation.conftest import compensate, events_of, repeatable_machine

ROOT = Path(__file__).resolve().parents[2]
MACHINE = ROOT / "samples/machines/hr5b.toml"
G54 = (400.0, 350.0, 300.0)
TABLE = "T1 P1 Z+150.000 D10.000 ;long 10 mm end mill\nT2 P2 Z40 D3 ; short drill\n\n; spare pockets\nT7 P3 X0.5 Z4.25\n"


def _tools(tmp_path: Path, text: str = TABLE, unit_mm: float = 1.0) -> ToolTable:
    path = tmp_path / "tool.tbl"
    path.write_text(text)
    return ToolTable.from_file(path, unit_mm)


def test_linuxcnc_tool_table(tmp_path):
    tools = _tools(tmp_path)
    assert tools.offset(1) == (0, 0, 150.0, 0, 0, 0, 0, 0, 0)
    assert tools.offset(7)[:3] == (0.5, 0.0, 4.25)
    assert tools.offset(0) == (0.0,) * 9 and tools.offset(3) is None  # tool 0: none in the spindle
    assert _tools(tmp_path, unit_mm=25.4).offset(2)[2] == pytest.approx(40 * 25.4)
    for text, message in (
        ("T1 Z1\nT1 Z2\n", r"tool.tbl:2:1: tool 1 is listed twice"),
        ("T1 Z1\nP2 Z3\n", r"tool.tbl:2:1: tool table line without a T word"),
        ("T1 Zabc\n", r"tool.tbl:1:4: expected a number, got 'abc'"),
        ("T1 K3\n", r"tool.tbl:1:4: unknown tool table word 'K3'"),
        ("T1.5 Z1\n", r"tool.tbl:1:1: a tool number is a whole number"),
    ):
        with pytest.raises(NcppError, match=message):
            _tools(tmp_path, text)
    with pytest.raises(NcppError, match=r"nowhere.tbl: cannot read the tool table"):
        ToolTable.from_file(tmp_path / "nowhere.tbl")


def _lengths(program: bytes, offsets: WorkOffsets) -> list[tuple[float, float, float]]:
    return [
        e.context.tool for e in events_of(program, offsets=offsets) if type(e).__name__ in ("Line", "Arc")
    ]


def test_g43_applies_the_tool_in_the_spindle_or_h_and_g49_none(tmp_path):
    told = replace(WorkOffsets.at(G54), tools=_tools(tmp_path))
    program = b"G21 G90\nT1 M6\nG43\nG0 Z10\nG43 H2\nG0 Z10\nT7\nG43\nG0 Z10\nM6 G43\nG0 Z10\nG43.2 H2\nG0 Z10\nG49\nG0 Z10\nM61 Q2\nG43 H0\nG0 Z10\nM2\n"
    # T selects, M6 loads, G43 (H0 too) applies the loaded tool, G43.2 adds one, G49 cancels; M61 sets the loaded tool
    want = [
        (0, 0, 150.0),
        (0, 0, 40.0),
        (0, 0, 150.0),
        (0.5, 0, 4.25),
        (0.5, 0, 44.25),
        (0, 0, 0),
        (0, 0, 40.0),
    ]
    assert _lengths(program, told) == want
    z10 = [e for e in events_of(program, offsets=told) if type(e).__name__ == "Line"][0]
    assert z10.context.to_machine(z10.end)[2] == pytest.approx(
        300.0 + 150.0 + 10.0
    )  # the gauge line is 150 mm above the tip
    inch = b"G20 G90\nT1 M6 G43\nG0 Z1\nM2\n"  # the table's mm lengths in program inches, as the control applies them
    assert _lengths(inch, told) == [pytest.approx((0, 0, 150.0 / 25.4))]


def test_a_tool_the_table_lacks_is_a_located_error(tmp_path):
    told = replace(WorkOffsets.at(G54), tools=_tools(tmp_path))
    with pytest.raises(NcppError, match=r"<test>:2:5: Requested tool 9 not found in the tool table"):
        events_of(b"G21\nG43 H9\nM2\n", offsets=told)
    with pytest.raises(NcppError, match=r"<test>:2:1: Requested tool 3 not found in the tool table"):
        events_of(b"G21\nT3 M6\nM2\n", offsets=told)


def _warnings(program: bytes, offsets: WorkOffsets, strict: bool = False, source: bool = True) -> str:
    said = io.StringIO()
    src = ErrorSource.from_machine_file(str(MACHINE)) if source else None
    process(
        io.BytesIO(program),
        io.BytesIO(),
        file="t.ngc",
        source=src,
        warnings=Warnings(strict, said),
        offsets=offsets,
    )
    return said.getvalue()


G43_PROGRAM = b"G21 G90\nT1 M6\nG43 H1\nG0 X10 Y10 Z5\nG43 H2\nG1 X20 F100\nM2\n"


def test_g43_without_a_tool_table_is_warned_once_where_it_applies_one(tmp_path):
    lines = _warnings(G43_PROGRAM, WorkOffsets.at(G54)).splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        "t.ngc:3:5: warning: G43 applies a tool length from the control's tool table"
    )
    assert "--tool-table" in lines[0]
    assert _warnings(G43_PROGRAM, replace(WorkOffsets.at(G54), tools=_tools(tmp_path))) == ""
    assert _warnings(G43_PROGRAM, WorkOffsets.at(G54), source=False) == ""  # passthrough places nothing
    with pytest.raises(NcppError, match=r"t.ngc:3:5: G43 applies a tool length"):
        _warnings(G43_PROGRAM, WorkOffsets.at(G54), strict=True)


def test_a_longer_tool_is_a_longer_abbe_arm():
    """The tool point is the machine file's `tool` (the gauge point) minus the tool length offset."""
    machine = repeatable_machine(MACHINE)
    P = np.array([[400.0, 350.0, 450.0], [100.0, 600.0, 200.0]])
    length = np.array([0.0, 0.0, 150.0])
    lengthened = machine.replace(tool=tuple(np.asarray(machine.tool) - length))
    assert np.array_equal(machine.deviation(P, None, np.tile(length, (2, 1))), lengthened.deviation(P))
    arm = machine.deviation(P, None, np.tile(length, (2, 1))) - machine.deviation(P)
    assert np.abs(arm).max() > 0.001  # µm-size: the pitch and yaw of the axes times 150 mm


POCKET = [
    line
    for line in (ROOT / "samples/programs/pocket.ngc").read_bytes().splitlines()
    if line.strip() not in (b"%", b"M2")
]
TWO_TOOLS = b"\n".join(
    [b"T1 M6", b"G43 H1", *POCKET, b"T2 M6", b"G43 H2", *POCKET[2:], b"M2", b""]
)  # the pocket with each tool


def _contour_um(machine, program: bytes, offsets: WorkOffsets) -> float:
    run, nominal = (
        sample_events(events_of(program, offsets=offsets)),
        sample_events(events_of(TWO_TOOLS, offsets=offsets)),
    )
    return contour_error(machine, run, nominal, feed_effects=False).max_um


def test_each_tool_is_compensated_at_its_length(tmp_path):
    """The pocket cut with a 150 mm and a 40 mm tool: compensated with the tool table, the
    simulated contour error is within the tolerance + 0.5 µm; compensated as if G43 applied
    length 0 (no table), it is several times the tolerance on the real machine."""
    machine = repeatable_machine(MACHINE)
    told = replace(WorkOffsets.at(G54), tools=_tools(tmp_path))
    before = _contour_um(machine, TWO_TOOLS, told)
    after = _contour_um(machine, compensate(TWO_TOOLS, machine, told), told)
    at_length_0 = _contour_um(machine, compensate(TWO_TOOLS, machine, WorkOffsets.at(G54)), told)
    assert before > 20.0 and after <= 1.5 and at_length_0 > 4.0, (before, after, at_length_0)


ORACLE_PROGRAM = b"""G21 G90
G0 X1 Y1 Z10
T1 M6
G43
G1 Z5 F100
G43 H2
G1 Z5
T7 M6
G43
G1 Z5
G43.2 H1
G1 Z5
G49
G1 Z5
G43 H7
G1 Z5
G43 H0
G1 Z5
G20
G43 H1
G1 Z1
M2
"""
ORACLE_TABLE = (
    "T1 P1 D6.0 Z2.0 ;a\nT2 P2 D3 Z-1.5 X0.1\nT7 P3 Z4\n"  # inches: the stand-alone rs274 reads them so
)


def test_tool_lengths_agree_with_linuxcnc_started_from_the_same_tool_table(tmp_path):
    from tests.rs274 import calls_from, end_points

    var, program = tmp_path / "sim.var", tmp_path / "p.ngc"
    var.write_text("5220 1.0\n")
    program.write_bytes(ORACLE_PROGRAM)
    canon = calls_from(var, program, ORACLE_TABLE)
    told = replace(WorkOffsets.at((0.0, 0.0, 0.0)), tools=_tools(tmp_path, ORACLE_TABLE, 25.4))
    events = [e for e in events_of(ORACLE_PROGRAM, offsets=told) if type(e).__name__ == "Line"]
    want = end_points(canon)
    assert len(events) == len(want) == 9
    for event, point in zip(events, want):
        assert event.end == pytest.approx(point, abs=1e-4)
    # the offset rs274 applies before each move is the one the move is placed with
    applied = [
        [float(v) for v in call.replace(",", " ").split()[:3]]
        for call in re.findall(r"USE_TOOL_LENGTH_OFFSET\((.*)\)", canon)
    ]
    assert len(applied) == 8
    np.testing.assert_allclose([e.context.tool for e in events], [[0.0, 0.0, 0.0], *applied], atol=1e-4)


def test_command_line_tool_table(tmp_path):
    table, program = tmp_path / "tool.tbl", tmp_path / "two.ngc"
    table.write_text(TABLE)
    program.write_bytes(TWO_TOOLS)

    def run(*placement: str) -> subprocess.CompletedProcess:
        command = [
            sys.executable,
            "-m",
            "ncpp",
            "compensate",
            "--machine",
            str(MACHINE),
            "--work-offset",
            "400,350,300",
            str(program),
            *placement,
        ]
        return subprocess.run(command, capture_output=True, cwd=ROOT)

    told, untold = run("--tool-table", str(table)), run()
    assert told.returncode == 0 and b"warning" not in told.stderr, told.stderr
    assert untold.returncode == 0 and b"G43 applies a tool length" in untold.stderr
    assert told.stdout != untold.stdout
    missing = run("--tool-table", str(tmp_path / "nowhere.tbl"))
    assert missing.returncode != 0 and b"nowhere.tbl: cannot read the tool table" in missing.stderr
