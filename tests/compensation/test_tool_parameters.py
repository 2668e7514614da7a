"""LinuxCNC's parameters of the tool in the spindle, read after the program's own tool change.

LinuxCNC G-code manual, "Numbered Parameters": #5400 the tool number, #5401-#5409 the tool offsets
X Y Z A B C U V W, #5410 the tool diameter, #5411 the front angle, #5412 the back angle, #5413 the
tool orientation (volatile).  rs274ngc sets them from the tool table's entry of the tool in the
spindle at M6 and M61, and again at a G10 L1/L10/L11 of that tool, in the machine's units whatever
G20/G21.  With the tool table told, ncpp follows them after the program's own M6 or M61; before it
the tool is the control's, and without the table nothing is known: such a read stays out of scope.

LinuxCNC's rs274 judges it, call by call: the stand-alone rs274 runs in inches (its tool table is
read in inches), so an inch machine is rs274 itself, and an mm machine running a G21 program is
the same numbers as rs274 running that program in G20.
"""

from __future__ import annotations

import io
import subprocess
import sys
from pathlib import Path

import pytest

from ncpp.errors import Warnings
from ncpp.motion import interpret
from ncpp.motion.canon import canon_call, read_canon
from ncpp.motion.offsets import UNIT_MM, WorkOffsets
from ncpp.motion.segments import Line, Pass
from ncpp.program.parser import parse_stream
from tests import rs274
from tests.compensation.test_cutter_comp_accuracy import PATHCHECK, needs_oracles
from tests.compensation.test_rigid_tap import TAPPING, closed_form
from tests.compensation.tool_centre import deviation, feed_moves
from tests.conftest import ROOT

# Two tools with every column a program can read; the stand-alone rs274 reads it in its inches
TABLE = (
    "T1 P1 X0.02 Y-0.01 Z2.0 A1.5 B-2 C3 U0.1 V0.2 W0.3 D0.25 I10 J20 Q3 ;end mill\nT2 P2 Z4.5 D0.5 ;drill\n"
)
# Each parameter read into a move after M6, after G10 L1 of the tool in the spindle and of another,
# after the next M6, and in a subroutine that sizes its pass by the diameter (as `pocket_circ` does)
PROGRAM = """{units} G90 G17 G54
o<pocket> sub
  #<r> = [#1 - #5410 / 2]
  G1 X[#<r>] Y0
  G3 X[#<r>] Y0 I[-#<r>] J0
o<pocket> endsub
T1 M6 G43
G0 X0 Y0 Z1
G1 X[#5400] Y[#5401 * 10] Z[#5402 * 10] F10
G1 X[#5403] Y[#5410] Z[#5413]
G1 X[#5411 / 10] Y[#5412 / 10] Z[#5404]
G1 X[#5405] Y[#5406] Z[#5407 * 10]
G1 X[#5408 * 10] Y[#5409 * 10] Z1
G10 L1 P1 Z1.5 R-0.1 I5 J7 Q2 X0.01
G1 X[#5401 * 10] Y[#5403] Z[#5410 * 10]
G1 X[#5411] Y[#5412] Z[#5413]
G10 L1 P2 Z3
G1 X[#5403] Y0
T2 M6 G43
G1 X[#5400] Y[#5403] Z[#5410]
o<pocket> call [3]
M2
"""


def _table(tmp_path: Path) -> Path:
    path = tmp_path / "tool.tbl"
    path.write_text(TABLE)
    return path


def _ncpp_calls(text: str, table: Path, unit_mm: float, said: io.StringIO | None = None) -> list:
    offsets = WorkOffsets.given({}, None, unit_mm, str(table))
    events = interpret(parse_stream(io.BytesIO(text.encode()), "p.ngc"), file="p.ngc",
                       warnings=Warnings(stream=said or io.StringIO()), offsets=offsets)  # fmt: skip
    return [call for call in map(canon_call, events) if call is not None]


def _rs274_calls(tmp_path: Path, text: str) -> list:
    program = tmp_path / "p.ngc"
    program.write_text(text)
    return read_canon(rs274.canon(program, tool_table=_table(tmp_path), home=tmp_path, timeout=60))


def _same(mine: list, theirs: list) -> None:
    assert [c.name for c in mine] == [c.name for c in theirs]
    for a, b in zip(mine, theirs):
        assert a.args == pytest.approx(b.args, abs=1e-4), (a, b)


@pytest.mark.parametrize("units", ["G20", "G21"])
def test_an_inch_machine_reads_the_spindle_tools_entry_as_rs274_does(tmp_path, units):
    """The values read stand in the table's inches in G20 and in G21 alike (G10 L1 P1 Z1.5 in G21
    makes #5403 1.5/25.4), and the moves made of them are rs274's."""
    text = PROGRAM.format(units=units)
    mine = _ncpp_calls(text, _table(tmp_path), UNIT_MM["inch"])
    theirs = _rs274_calls(tmp_path, text)
    _same(mine, theirs)
    feeds = [c.args for c in mine if c.name == "STRAIGHT_FEED"]
    assert feeds[0][:3] == pytest.approx((1.0, 0.2, -0.1))  # tool 1, its X and Y offsets
    assert feeds[1][:3] == pytest.approx((2.0, 0.25, 3.0))  # its length, diameter, orientation
    g10 = 1.0 if units == "G20" else 1 / 25.4  # (G10 L1's words are in the program's units)
    assert feeds[5][:3] == pytest.approx((0.1 * g10, 1.5 * g10, -2 * 0.1 * g10 * 10))  # (R signed)


def test_an_mm_machine_reads_the_table_in_mm_as_rs274_reads_its_inches(tmp_path):
    """An mm machine running the G21 program and rs274's inch machine running it in G20: every
    number the same."""
    mine = _ncpp_calls(PROGRAM.format(units="G21"), _table(tmp_path), UNIT_MM["mm"])
    _same(mine, _rs274_calls(tmp_path, PROGRAM.format(units="G20")))


def test_an_mm_machine_running_in_g20_reads_mm(tmp_path):
    """#5403 is the table's number in the machine's mm whatever G20 says, and G10 L1 in G20 sets
    it from inches (Z1 is 25.4 mm): rs274ngc keeps the table in the machine's units."""
    table = tmp_path / "mm.tbl"
    table.write_text("T1 P1 Z50 D6\n")
    text = (
        "G20 G90\nT1 M6\nG0 X0 Y0 Z1\nG1 X[#5410] Z[#5403] F10\nG10 L1 P1 Z1 R0.5\nG1 X[#5410] Z[#5403]\nM2\n"
    )
    calls = _ncpp_calls(text, table, UNIT_MM["mm"])
    assert [c.args[:3] for c in calls[1:]] == [
        pytest.approx((6.0, 0.0, 50.0)),
        pytest.approx((25.4, 0.0, 25.4)),
    ]


@pytest.mark.parametrize(
    "head, reason",
    [
        ("", "#5410 of the tool in the spindle before the program's first tool change (M6, M61)"),
        ("T0 M6\n", "#5410 with no tool in the spindle"),
        ("T1 M6\n#5410 = 3\n", "a write to the machine-state parameter #5410"),
    ],
)
def test_what_ncpp_does_not_know_passes_through_with_one_warning(tmp_path, head, reason):
    said = io.StringIO()
    text = f"G21 G90\nG0 X0 Y0 Z1\n{head}G1 X[#5410 / 2] F10\nG1 X5\nM2\n"
    offsets = WorkOffsets.given({}, None, UNIT_MM["inch"], str(_table(tmp_path)))
    events = list(interpret(parse_stream(io.BytesIO(text.encode()), "p.ngc"), file="p.ngc",
                            warnings=Warnings(stream=said), offsets=offsets))  # fmt: skip
    assert said.getvalue().count("warning") == 1 and reason in said.getvalue(), said.getvalue()
    assert [type(e) for e in events].count(Line) == 1 and type(events[-1]) is Pass


def test_without_a_tool_table_a_read_after_m6_stays_out_of_scope():
    said = io.StringIO()
    text = b"G21 G90\nT1 M6\nG0 X0 Y0 Z1\nG1 X[#5410 / 2] F10\nM2\n"
    events = list(interpret(parse_stream(io.BytesIO(text), "p.ngc"), file="p.ngc", warnings=Warnings(stream=said),
                            offsets=WorkOffsets.at((0.0, 0.0, 0.0))))  # fmt: skip
    assert "p.ngc:4:4: warning: machine-state parameter #5410 of the tool in the spindle, without the tool " \
           "table (--tool-table)" in said.getvalue()  # fmt: skip
    assert [type(e) for e in events].count(Line) == 1


def test_m61_loads_the_tool_whose_entry_the_parameters_then_read(tmp_path):
    """M61 Q sets the tool in the spindle without a change (LinuxCNC G-code manual, "M61 Set Current
    Tool"); rs274ngc then syncs with the control and sets #5400-#5413 from the new spindle entry, as
    at M6 (LinuxCNC's remap example of "the same thing as the builtin M61": CHANGE_TOOL_NUMBER, a
    sync, set_tool_parameters).  The stand-alone rs274's canon does not load the tool at M61 (its own
    G43 applies the old tool's offsets after it), so it is no judge here."""
    text = "G20 G90\nM61 Q2\nG0 X0 Y0 Z1\nG1 X[#5400] Y[#5403] Z[#5410] F10\nM2\n"
    calls = _ncpp_calls(text, _table(tmp_path), UNIT_MM["inch"])
    assert calls[-1].args[:3] == pytest.approx((2.0, 4.5, 0.5))


@needs_oracles
def test_written_out_the_pocket_sized_by_the_diameter_lands_on_the_original(tmp_path):
    """Compensated with `--expand`, the subroutine's pass sized by #5410 is written with the told
    diameter's numbers and compensated: run on TAPPING's machine it lands within half a micron of the
    original's path (several µm as programmed), and pathcheck passes it."""
    table = _table(tmp_path)
    text = PROGRAM.format(units="G20").replace("o<pocket> call [3]", "G0 X0 Y0\no<pocket> call [10]\n"
                                                "o<pocket> call [6]")  # fmt: skip
    program, out = tmp_path / "p.ngc", tmp_path / "p.out.ngc"
    program.write_text(text)
    (tmp_path / "machine.toml").write_text(TAPPING)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "machine.toml"),
                           "--tool-table", str(table), "--var-units", "inch", "--expand", str(program), "-o",
                           str(out)], capture_output=True, text=True, cwd=ROOT, timeout=300,
                          stdin=subprocess.DEVNULL)  # fmt: skip
    assert proc.returncode == 0 and "left as programmed: nothing" in proc.stderr, proc.stderr
    before, after = (feed_moves(p, table, home=tmp_path) for p in (program, out))
    assert deviation(before, before, closed_form).max() > 0.004
    assert deviation(before, after, closed_form).max() < 0.0005
    check = subprocess.run([sys.executable, str(PATHCHECK), str(program), str(out), "--tool-table", str(table)],
                           capture_output=True, text=True, timeout=300)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr
