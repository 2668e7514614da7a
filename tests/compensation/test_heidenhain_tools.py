"""Heidenhain tool lengths: TOOL CALL applies L + DL from the TNC's tool table (TOOL.T,
--tool-table) or from the program's own TOOL DEF, plus the call's DL, along the tool axis;
a longer tool is a longer Abbe arm, as with LinuxCNC's G43."""

import io
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.tools import ToolTable
from ncpp.pipeline import ErrorSource, dialect_tools, process
from ncpp.program.dialects import parse_program
from ncpp.simulate import contour_error, sample_events
from tests.compensation.conftest import QUIET, compensate, repeatable_machine

ROOT = Path(__file__).resolve().parents[2]
MACHINE = ROOT / "samples/machines/hr5b.toml"
ZERO = (400.0, 350.0, 300.0)
# TOOL.T as the TNC writes it: fixed columns under the header, a decimal comma, names, [END]
TOOL_T = """BEGIN TOOL    .T       MM
T    NAME             L          R          DL      DR      TL RT  TIME1 TIME2 CUR.TIME DOC
0                     +0,000     +0,000     +0,000  +0,000         0     0     0
1    D10_ENDMILL      +150,020   +5,000     -0,020  +0,000         0     0     0
2    DRILL_6          +40,5      +3,000     +0,000  +0,000         0     0     0
3    D10_ENDMILL      +90,000    +5,000     +0,000  +0,000         0     0     0
[END]
"""


def _table(tmp_path: Path, text: str = TOOL_T) -> ToolTable:
    path = tmp_path / "TOOL.T"
    path.write_text(text, encoding="latin-1")
    return ToolTable.from_file(path, unit_mm=25.4)  # the file's own units win over the machine's


def test_tool_t_lengths_are_l_plus_dl_in_its_units(tmp_path):
    tools = _table(tmp_path)
    assert tools.offset(1)[2] == pytest.approx(150.0) and tools.offset(2)[2] == pytest.approx(40.5)
    assert tools.offset(1)[:2] == (0.0, 0.0) and tools.offset(4) is None
    assert tools.names == {"D10_ENDMILL": 1.0, "DRILL_6": 2.0}  # a name listed twice: its first tool
    inch = _table(tmp_path, TOOL_T.replace("MM\n", "INCH\n", 1).replace("+40,5 ", "+2,0  "))
    assert inch.offset(2)[2] == pytest.approx(50.8)
    header = TOOL_T.splitlines()[:2]
    for lines, message in (
        ([*header, "1                     +1,0", "1                     +2,0"], r"TOOL.T:4:1: tool 1 is listed twice"),
        ([*header, "5                     +1,x"], r"TOOL.T:3:23: expected a number, got '\+1.x'"),
        ([header[0], "T    NAME             R"], r"TOOL.T:2:1: TOOL.T header without a L column"),
    ):
        with pytest.raises(NcppError, match=message):
            _table(tmp_path, "\n".join(lines) + "\n")


PROGRAM = b"""0 BEGIN PGM P MM
1 TOOL CALL 1 Z S800
2 L X+10 Y+10 Z+5 R0 FMAX
3 TOOL CALL "DRILL_6" Z DL+0.5
4 L Z+5 FMAX
5 TOOL DEF 7 L+55 R+2
6 TOOL CALL 7 Z
7 L Z+5
8 TOOL CALL Z S100
9 L Z+6
10 TOOL CALL 2 X
11 L X+20
12 TOOL CALL 0 Z
13 L Z+7
14 END PGM P MM
"""


def _events(program: bytes, offsets: WorkOffsets, warnings: Warnings = QUIET) -> list:
    interpret, _ = dialect_tools("heidenhain")
    _, blocks = parse_program(io.BytesIO(program), "p.h", "heidenhain")
    return [e for e in interpret(blocks, file="p.h", warnings=warnings, offsets=offsets) if type(e).__name__ in ("Line", "Arc")]


def test_tool_call_applies_the_tools_length_along_the_tool_axis(tmp_path):
    """By number, by name (plus the call's DL), defined by TOOL DEF, kept by a call without a
    tool, along X for a TOOL CALL .. X, none for tool 0."""
    events = _events(PROGRAM, replace(WorkOffsets.at(ZERO), tools=_table(tmp_path)))
    assert [e.context.tool for e in events] == [
        pytest.approx(t) for t in ((0, 0, 150.0), (0, 0, 41.0), (0, 0, 55.0), (0, 0, 55.0), (40.5, 0, 0), (0, 0, 0))
    ]
    first = events[0]
    assert first.context.to_machine(first.end) == pytest.approx((410.0, 360.0, 300.0 + 5.0 + 150.0))  # the gauge line above the tip


def test_a_tool_the_table_lacks_is_a_located_error(tmp_path):
    told = replace(WorkOffsets.at(ZERO), tools=_table(tmp_path))
    with pytest.raises(NcppError, match=r"p.h:2:3: tool 9 is not defined: neither in .*TOOL.T nor by TOOL DEF"):
        _events(b"0 BEGIN PGM P MM\n1 TOOL CALL 9 Z\n2 END PGM P MM\n", told)
    with pytest.raises(NcppError, match=r'p.h:2:3: tool "FLY" is not in .*TOOL.T'):
        _events(b'0 BEGIN PGM P MM\n1 TOOL CALL "FLY" Z\n2 END PGM P MM\n', told)


def _warnings(program: bytes, offsets: WorkOffsets, strict: bool = False) -> str:
    said = io.StringIO()
    process(io.BytesIO(program), io.BytesIO(), file="t", source=ErrorSource.from_machine_file(str(MACHINE)),
            warnings=Warnings(strict, said), dialect="heidenhain", offsets=offsets)  # fmt: skip
    return said.getvalue()


UNTOLD = b"0 BEGIN PGM P MM\n1 TOOL CALL 1 Z S800\n2 L X+10 Y+10 FMAX\n3 TOOL CALL 2 Z\n4 END PGM P MM\n"


def test_without_a_tool_table_tool_call_is_warned_once(tmp_path):
    lines = _warnings(UNTOLD, WorkOffsets.at(ZERO)).splitlines()
    assert len(lines) == 1 and lines[0].startswith("t:2:3: warning: TOOL CALL applies the tool's length") and "tool length 0" in lines[0]
    assert _warnings(UNTOLD, replace(WorkOffsets.at(ZERO), tools=_table(tmp_path))) == ""
    defined = UNTOLD.replace(b"1 TOOL CALL", b"1 TOOL DEF 1 L+100 R+5\n1 TOOL DEF 2 L+50 R+3\n1 TOOL CALL")
    assert _warnings(defined, WorkOffsets.at(ZERO)) == ""  # the program says its tools' lengths
    with pytest.raises(NcppError, match=r"t:2:3: TOOL CALL applies the tool's length"):
        _warnings(UNTOLD, WorkOffsets.at(ZERO), strict=True)


# The sample pocket in Klartext, cut with a 150 mm and a 40.5 mm tool
POCKET = [
    "L Z+5 R0 FMAX", "L X-20 Y-10 FMAX", "L Z-2 F200", "L X+20 F600", "CC X+20 Y+0", "C X+30 Y+0 DR+", "L Y+10",
    "CC X+20 Y+10", "C X+20 Y+20 DR+", "L X-20", "CC X-20 Y+10", "C X-30 Y+10 DR+", "L Y+0", "CC X-20 Y+0",
    "C X-20 Y-10 DR+", "L Z+5 FMAX", "L X+75 Y+0 FMAX", "L Z-2 F200", "CC X+0 Y+0", "C X+75 Y+0 DR- F600", "L Z+5 FMAX",
]
TWO_TOOLS = ["BEGIN PGM POCKET MM", "TOOL CALL 1 Z S3000", *POCKET, "TOOL CALL 2 Z S3000", *POCKET, "END PGM POCKET MM"]
TWO_TOOLS_PROGRAM = "".join(f"{n} {line}\n" for n, line in enumerate(TWO_TOOLS)).encode()


def _contour_um(machine, program: bytes, offsets: WorkOffsets) -> float:
    run, nominal = sample_events(_events(program, offsets)), sample_events(_events(TWO_TOOLS_PROGRAM, offsets))
    return contour_error(machine, run, nominal, feed_effects=False).max_um


def test_each_tool_is_compensated_at_its_length(tmp_path):
    """Compensated with TOOL.T the simulated contour error is within the tolerance + 0.5 µm;
    compensated at length 0 (no table) it is several times the tolerance on the real machine."""
    machine = repeatable_machine(MACHINE)
    told = replace(WorkOffsets.at(ZERO), tools=_table(tmp_path))
    before = _contour_um(machine, TWO_TOOLS_PROGRAM, told)
    after = _contour_um(machine, compensate(TWO_TOOLS_PROGRAM, machine, told), told)
    at_length_0 = _contour_um(machine, compensate(TWO_TOOLS_PROGRAM, machine, WorkOffsets.at(ZERO)), told)
    assert before > 20.0 and after <= 1.5 and at_length_0 > 4.0, (before, after, at_length_0)


def test_command_line_tool_t(tmp_path):
    table, program = tmp_path / "TOOL.T", tmp_path / "pocket.h"
    table.write_text(TOOL_T)
    program.write_bytes(TWO_TOOLS_PROGRAM)

    def run(*placement: str) -> subprocess.CompletedProcess:
        command = [sys.executable, "-m", "ncpp", "compensate", "--machine", str(MACHINE), "--work-offset", "400,350,300", str(program), *placement]
        return subprocess.run(command, capture_output=True, cwd=ROOT)

    told, untold = run("--tool-table", str(table)), run()
    assert told.returncode == 0 and told.stderr == b"", told.stderr
    assert untold.returncode == 0 and b"TOOL CALL applies the tool's length" in untold.stderr
    assert told.stdout != untold.stdout
