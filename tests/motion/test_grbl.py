"""grbl 1.1's reading of G code where it differs from LinuxCNC's (`ncpp/motion/grbl.py`).

The rules are grbl's own source, `grbl/gcode.c` (`gc_execute_line`) and `protocol.c`."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import Arc, Line, Pass
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import detect, parse_program
from tests.conftest import READING, ROOT

ARC_WITH_K = b"G21 G90 G17\nG0 X0 Y0 Z1\nG2 X10 Y0 Z1 I5 J0 K0.000 F300\nM2\n"


def events(program: bytes, dialect: str, warnings: Warnings | None = None) -> list:
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(program), "p.nc", dialect)
    return list(interpret(blocks, file="p.nc", warnings=warnings or Warnings(stream=io.StringIO())))


def test_an_arc_in_offset_mode_takes_k_in_g17_as_grbl_does():
    """gcode.c, "Arc Center Format Offset Mode": `bit_false(value_words, I|J|K)`, all three used;
    LinuxCNC refuses the K (rs274ngc: "K word given for arc in xy plane")."""
    arc = events(ARC_WITH_K, "grbl")[2]
    assert type(arc) is Arc and arc.end == (10.0, 0.0, 1.0) and arc.center[:2] == (5.0, 0.0)
    with pytest.raises(NcppError, match="K word given for arc in xy plane"):
        events(ARC_WITH_K, "iso")


def test_an_arc_in_radius_mode_with_k_is_refused():
    """In radius mode the I J K words are not used: grbl's "unused words" error (20)."""
    with pytest.raises(NcppError, match="Mixed radius ijk format"):
        events(b"G0 X0 Y0\nG2 X10 Y0 R5 K0 F300\n", "grbl")


def test_realtime_commands_pass_through():
    """serial.c picks `?` `~` `!` out of the stream as they arrive: the parser never sees them."""
    found = events(b"?  ; status\nG0 X1\n~\nG1 X2 F100\n", "grbl")
    assert [type(event) for event in found] == [Pass, Line, Pass, Line]


def test_system_commands_pass_through_and_homing_ends_what_ncpp_follows():
    """protocol.c hands a line that starts with `$` to `system_execute_line`, never to the
    G-code parser; `$H` and `$J=` move the machine, so the state after them is unknown."""
    said = io.StringIO()
    program = b"$100=250.000\n$X\nG0 X1 Y1\n$H\nG0 X5\nM2\n"
    found = events(program, "grbl", Warnings(stream=said))
    kinds = [type(event) for event in found]
    assert kinds == [Pass, Pass, Line, Pass, Pass, Pass]
    assert "p.nc:4:1: warning: grbl homing ($H), a move ncpp cannot follow" in said.getvalue()
    jog = events(b"G0 X1\n$J=G91 X10 F500\nG1 X2 F100\n", "grbl", Warnings(stream=said))
    assert [type(event) for event in jog] == [Line, Pass, Pass]


@pytest.mark.parametrize(
    "head, dialect",
    [
        (b"$H\nG21 G90\nG0 X1\n", "grbl"),
        (b"G21\n$J=G91 X10 F500\n", "grbl"),  # (not Sinumerik's `J=` assignment)
        (b"$110=500\nG0 X1\n", "grbl"),
        (b"$I  ; View build info\n$$\nG90\n", "grbl"),
        (b"(Exported by FreeCAD)\n(Post Processor: grbl_post)\nG17 G90\n", "grbl"),
        (b"G21 G90\nG0 X1 Y2\n", "iso"),
        (b"$P_UIFR[1]=CTRANS(X,10)\nG0 X1\n", "sinumerik"),
        (b"G0 X1\nG1 X2 $1 F100\n", "iso"),  # LinuxCNC's spindle word
    ],
)
def test_grbl_is_told_by_its_system_commands_and_freecads_comment(head, dialect):
    assert detect(head) == dialect


def test_a_grbl_program_is_compensated_without_a_guard_and_the_user_is_told(tmp_path):
    """grbl has no parameters and no conditionals: no placement guard can be written."""
    program = tmp_path / "p.nc"
    program.write_bytes(b"$H\n" + ARC_WITH_K.replace(b"M2\n", b"") + b"G0 X0\nM2\n")
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "--machine", str(READING), "--work-offset", "10,20,30", str(program)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stderr
    assert "o<ncpp_guard>" not in proc.stdout and "#5220" not in proc.stdout
    assert "grbl cannot test its work offset" in proc.stderr
    assert "make sure the control has G54 at X10 Y20 Z30 mm" in proc.stderr


def test_grbl_programs_are_compensated_and_read_back_as_grbl(tmp_path):
    """The verifier reads the written program as grbl too: the K words of the arcs are no fault."""
    program = tmp_path / "p.nc"
    program.write_bytes(ARC_WITH_K)
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "--dialect", "grbl", "--machine", str(READING), str(program)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stderr
    assert "compensated 2 moves" in proc.stderr and "left as programmed: nothing" in proc.stderr
    assert "\nG2 X9.9999 Y0.0000 Z1.0000 I5.0000 J0.0001 F300\n" in proc.stdout


def test_axis_words_before_any_motion_code_are_a_rapid_as_grbl_starts_in_g0(tmp_path):
    """`G91` then `Z2` (svenhb/GRBL-Plotter, GRBL-Plotter/data/examples/gcode_relative.nc): grbl's parser starts
    in G0 (`gcode.h`: MOTION_MODE_SEEK 0, "Default: Must be zero"), so Z2 is `G0 Z2`; rs274 runs the twin that
    says so, and refuses the program as written, as ncpp's LinuxCNC reading does."""
    from ncpp.motion.canon import canon_call, read_canon
    from tests.conftest import RS274
    from tests.motion.test_oracle import rs274, same_calls

    program = b"( Test relative moves)\nG91\nZ2\nG0 X-10 Y-10\nG1 Z-5 F300\nY20\nX20\nM30\n"
    with pytest.raises(NcppError, match="Cannot use axis values without a g code that uses them"):
        events(program, "iso")
    mine = [c for c in (canon_call(e) for e in events(program, "grbl")) if c is not None]
    assert mine[0].name == "STRAIGHT_TRAVERSE" and mine[0].end[:3] == (0.0, 0.0, 2.0) and len(mine) == 5
    if not RS274.exists():
        pytest.skip("rs274 not available")
    twin = tmp_path / "twin.ngc"
    twin.write_bytes(program.replace(b"\nZ2\n", b"\nG0 Z2\n"))
    reference = read_canon(rs274(str(twin))[0])
    assert same_calls(reference, mine), (reference, mine)


def test_grbl_reads_on_after_m30_with_its_modes_reset(tmp_path):
    """Two jobs one after another, each ending in M30 (an excerpt of thawkins/gcodekit4,
    assets/gcode/generated.gcode): grbl resets the modes at M30 and runs the lines the sender
    streams after it (gcode.c, "[21. Program flow]": G1 G17 G90 G94 G40 G54 M5 M9, then
    `program_flow = PROGRAM_FLOW_RUNNING`).  rs274 runs the twin whose first M30 is those resets;
    LinuxCNC's reading stops at the M30."""
    from ncpp.motion.canon import canon_call, read_canon
    from tests.conftest import RS274
    from tests.motion.test_oracle import rs274, same_calls

    job = (
        "G90\nG21\nG17\nM3\nN10 G00 X{0} Y108.711 Z10.000\nN20 G01 Z-5.000 F100\nN30 G01 X{1} Y108.711 F100\n"
    )
    second = job.format(243.688, 537.441).replace("G90\n", "")  # (M30's G90 ends the first job's G91)
    program = (job.format(93.465, 207.699) + "G91 G00 Z10\nM30\n" + second + "M30\n").encode()
    mine = [c for c in (canon_call(e) for e in events(program, "grbl")) if c is not None]
    assert len(mine) == 7 and mine[-1].end[:3] == (537.441, 108.711, -5.0)
    linuxcnc = [c for c in (canon_call(e) for e in events(program, "iso")) if c is not None]
    assert len(linuxcnc) == 4
    if not RS274.exists():
        pytest.skip("rs274 not available")
    twin = tmp_path / "twin.ngc"
    twin.write_bytes(program.replace(b"M30\n", b"G17 G90 G94 G40 G54 M5 M9\n", 1))
    reference = read_canon(rs274(str(twin))[0])
    assert same_calls(reference, mine), (reference, mine)


def test_a_percent_line_grbl_does_not_read_passes_through():
    """`M30` then `%` with no `%` at the start (CAMotics examples/cameo/cameo.nc ends so): grbl
    reads no tape marks (protocol.c, "Program start-end percent sign NOT SUPPORTED"; the parser
    answers error 1 and changes nothing), and as grbl reads on after M30 the line is reached;
    LinuxCNC refuses it as a stray `%`."""
    program = b"G21 G90\nG0 X1\nG1 X2 F100\nM30\n%\n"
    found = events(program, "grbl")
    assert [type(event) for event in found] == [Pass, Line, Line, Pass, Pass]
    with pytest.raises(NcppError, match="Bad character '%' used"):
        events(program.replace(b"M30\n", b""), "iso")


def test_grbl_runs_the_lines_after_a_second_percent_line(tmp_path):
    """grbl reads no tape marks: the `% vfd enable` a Fusion MPCNC post writes into its start
    G-code (an excerpt of richcreations/Ghettotator, models/wiggler-8-back0125drill.gcode) closes
    no program, and the moves after it run; rs274 runs the twin without the `%` lines."""
    from ncpp.motion.canon import canon_call, read_canon
    from tests.conftest import RS274
    from tests.motion.test_oracle import rs274, same_calls

    program = b"%\n% vfd enable\nM6 T0\n%( *** START end ***)\nM3 S5000\nG0 Z3 F300\nX77.688 Y49.688\nG1 Z-3 F1000\n%\n"
    mine = [c for c in (canon_call(e) for e in events(program, "grbl")) if c is not None]
    assert len(mine) == 3 and mine[-1].end[:3] == (77.688, 49.688, -3.0)
    if not RS274.exists():
        pytest.skip("rs274 not available")
    twin = tmp_path / "twin.ngc"
    twin.write_bytes(
        b"".join(line for line in program.splitlines(keepends=True) if not line.startswith(b"%"))
    )
    reference = read_canon(rs274(str(twin))[0])
    assert same_calls(reference, mine), (reference, mine)
