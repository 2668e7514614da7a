"""Fanuc and Haas settings that move no axis (`ncpp/motion/fanuc.py`), where LinuxCNC reads
the same codes otherwise (G5.1 a spline, G8 lathe radius mode) or not at all.

Fanuc 0i-MF operator's manual: "AI contour control (G05.1 Q1)", "Advanced preview control (G08
P1)"; Haas Mill Operator's Manual: "G187 Accuracy Control", "G103 Limit Block Buffering",
"G154 Select Work Coordinates P1-P99", "M97 Local Sub-Program Call"."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import Line, Pass
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import detect, parse_program
from tests.conftest import READING, ROOT, RS274, SHARED

PATHCHECK = SHARED / "tools" / "pathcheck"


def events(program: str, dialect: str, warnings: Warnings | None = None) -> list:
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(program.encode()), "p.nc", dialect)
    return list(interpret(blocks, file="p.nc", warnings=warnings or Warnings(stream=io.StringIO())))


@pytest.mark.parametrize(
    "setting, dialects",
    [("G05.1 Q1", ("fanuc", "haas")), ("G08 P1", ("fanuc", "haas")), ("G187 P1 E0.01", ("haas",)),
     ("G103 P1", ("haas",))],
)  # fmt: skip
def test_a_setting_on_its_own_line_is_read_past(setting, dialects):
    program = f"G21 G90 G54\n{setting}\nG0 X10 Y10\nG1 X20 F100\n{setting.split()[0]} {setting.split()[1][0]}0\nM30\n"
    for dialect in dialects:
        found = events(program, dialect)
        assert [type(e) for e in found] == [Pass, Pass, Line, Line, Pass, Pass]
    with pytest.raises(NcppError):  # LinuxCNC's reading: an unknown code, a spline, or a P word for nothing
        events(program, "iso")


def test_a_setting_with_motion_in_its_block_ends_interpretation():
    said = io.StringIO()
    found = events("G0 X1\nG05.1 Q1 X10\nG0 X2\n", "fanuc", Warnings(stream=said))
    assert [type(e) for e in found] == [Line, Pass, Pass] and "G05.1 with other words" in said.getvalue()


@pytest.mark.parametrize(
    "block, reason, dialect",
    [("G154 P1", "G154 P1 (an additional work offset ncpp is not told: give --work-offset G154P1=X,Y,Z", "haas"),
     ("M97 P1000", "M97 (a local", "haas"), ("G54.1 P1", "G54.1 (Fanuc's additional work offset", "haas"),
     ("G54.1 P1", "G54.1 P1 (an additional work offset ncpp is not told: give --work-offset G54.1P1=", "fanuc"),
     ("G54.1 P49", "G54.1 P49 (an additional work offset ncpp is not told)", "fanuc"),
     ("G154 P3 G0 X1", "G154 with other words in its block", "haas"), ("G54.1", "G54.1 without one P", "fanuc"),
     ("G10 L20 P1 X0 Y0 Z0", "G10 L20 (it sets an additional work offset here)", "fanuc"),
     ("G10 L2 P0 X5", "G10 L2 P0 (it sets the external work offset", "fanuc"),
     ("G10 L2 P[#1] X5", "G10 L2 P0 (it sets the external work offset", "haas")],
)  # fmt: skip
def test_what_fanuc_and_haas_programs_need_ncpp_is_not_told_ends_interpretation(block, reason, dialect):
    said = io.StringIO()
    found = events(f"G0 X1\n{block}\nG0 X2\nM30\n", dialect, Warnings(stream=said))
    assert [type(e) for e in found] == [Line, Pass, Pass, Pass] and reason in said.getvalue()


@pytest.mark.parametrize(
    "head, dialect",
    [
        (b"%\nO1000 (PART)\nG21 G90\n", "fanuc"),
        (b"%\nO1000\nG187 P1 E0.01\n", "haas"),
        (b"G21\nG154 P3\nG0 X1\n", "haas"),
        (b"G21\nG05.1 Q1\n", "fanuc"),
        (b"G65 P9810 X1. Y2.\n", "fanuc"),
        (b"o100 sub\nG0 X1\no100 endsub\nO1000\n", "iso"),  # LinuxCNC's o-words win
        (b"G21 G90\nG0 X1 Y2 (G187 in a comment)\n", "iso"),
    ],
)
def test_fanuc_and_haas_are_told_by_what_only_they_write(head, dialect):
    assert detect(head) == dialect


def test_a_haas_program_gets_the_fanuc_guard(tmp_path):
    program = tmp_path / "p.nc"
    program.write_text("%\nO1000\nG187 P1 E0.01\nG21 G90 G54\nG0 X10 Y10 Z5\nG1 Z-1 F100\nM30\n%\n")
    proc = subprocess.run([sys.executable, "-m", "ncpp", "--machine", str(READING), "--work-offset", "10,20,30",
                           str(program)], capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "IF [#4014 NE 54] THEN #3000=1" in proc.stdout and "\nG187 P1 E0.01\n" in proc.stdout


# A simulator's example file: its own directives stand above the program's start `%`
LEADER = """($Message("Load the machine settings file first.") )
($SetPartSize(4, 4, 1, 1) )

 %
 O123 ( SAMPLE )
 G21 G40 G54 G80 G90
 G0 X10 Y10 Z5
 G1 Z-1 F100
 X50
 M30
%
"""


def test_a_tape_leader_above_the_start_is_not_read():
    """Fanuc 16i/18i operator's manual (B-63524EN), memory card file format: a file is read from
    its first `%`; text above it is a leader the control skips."""
    found = events(LEADER, "fanuc")
    assert [type(e) for e in found if type(e) is Line] == [Line] * 3
    assert detect(LEADER.encode()) == "fanuc"


def test_the_header_and_guard_go_below_the_start_not_into_the_leader(tmp_path):
    program = tmp_path / "p.nc"
    program.write_text(LEADER)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "--machine", str(READING), "--work-offset", "10,20,30",
                           str(program)], capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    leader, program_part = proc.stdout.split(" %\n", 1)
    assert leader == LEADER.split(" %\n")[0]  # the leader as it was
    assert (
        program_part.startswith("(ncpp compensated for")
        and "IF [ABS[#5221-10] GT 0.1] THEN #3000=2" in program_part
    )  # (the program selects G54 itself: its zero is checked, not #4014)


def test_g10_l2_of_a_numbered_system_is_followed():
    """P1-P6: G54-G59 (the Fanuc manual's G10 L2), as LinuxCNC reads them."""
    said = io.StringIO()
    found = events("G10 L2 P1 X5\nG0 X1\nM30\n", "fanuc", Warnings(stream=said))
    assert type(found[1]) is Line and said.getvalue() == ""


# A Mastercam-style Fanuc/Haas tool change: `G0 G28 G91 Z0.` sends Z home and leaves G0 modal, so
# the next block's axis words are a rapid (free-cnc-simulator-wine's `Mill/MM/Fanuc/G81 ABS.nc`
# writes `G00 G28 G91 Z1`; Mastercam's Fanuc posts `G0 G28 G91 Z0.`)
RETURN_WITH_G0 = """%
O0025
G21 G54 G90 G17
G0 G28 G91 Z0.
G90
X10. Y20. Z5. S800 M3
G1 Z-1. F100.
X30. Y25.
G00 G91 G28 Z0.
G90 X40.
M30
%
"""


def rs274_twin(text: str) -> str:
    """The same program as LinuxCNC must be told it: the return, then the modal G0 on a line of its own."""
    return text.replace("G0 G28 G91 Z0.\n", "G28 G91 Z0.\nG0\n").replace(
        "G00 G91 G28 Z0.\n", "G91 G28 Z0.\nG0\n"
    )


def test_g0_in_a_return_block_is_the_modal_motion_after_it(tmp_path):
    """The return is left as programmed and the moves after it are compensated: the X Y Z block after
    `G0 G28` is a rapid.  Judged by LinuxCNC's rs274 on the twins of input and output (pathcheck: same
    actions, rapids where the original rapids, within 0.05 mm); ncpp refused the block before."""
    if not (RS274.exists() and PATHCHECK.exists()):
        pytest.skip("rs274 or pathcheck not available")
    program = tmp_path / "p.nc"
    program.write_text(RETURN_WITH_G0)
    out = tmp_path / "out.nc"
    command = ["compensate", "--machine", str(READING), "--dialect", "fanuc", str(program), "-o", str(out)]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    written = out.read_text()
    assert "\nG0 G28 G91 Z0.\n" in written and "\nG00 G91 G28 Z0.\n" in written
    assert "compensated 4 moves" in proc.stderr
    twin_in, twin_out = tmp_path / "in.ngc", tmp_path / "out.ngc"
    twin_in.write_text(rs274_twin(RETURN_WITH_G0))
    twin_out.write_text(rs274_twin(written))
    check = subprocess.run([sys.executable, str(PATHCHECK), str(twin_in), str(twin_out), "--tol-mm", "0.05"],
                           capture_output=True, text=True, timeout=600)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


def test_g1_in_a_return_block_is_still_refused():
    """Only the G0 that posts write is read so: G1 with G28 stays LinuxCNC's refusal."""
    with pytest.raises(NcppError, match="two g codes that both use axis values"):
        events("G21 G90\nG1 G28 G91 Z0. F100\nM30\n", "fanuc")
