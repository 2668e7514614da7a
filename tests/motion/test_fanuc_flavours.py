"""Fanuc and Haas settings that move no axis (`ncpp/motion/fanuc.py`), where LinuxCNC reads
the same codes otherwise (G5.1 a spline, G8 lathe radius mode) or not at all.

Fanuc 0i-MF operator's manual: "AI contour control (G05.1 Q1)", "Advanced preview control (G08
P1)"; Haas Mill Operator's Manual: "G187 Accuracy Control", "G103 Limit Block Buffering",
"G154 Select Work Coordinates P1-P99", "M97 Local Sub-Program Call"."""

from __future__ import annotations

import io
import re
import subprocess
import sys
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import Arc, Line, Pass
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import detect, parse_program
from tests import rs274 as oracle
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
     ("M97 P1000 X1.", "M97 with other words in its block", "haas"), ("G54.1 P1", "G54.1 (Fanuc's additional work offset", "haas"),
     # (a Haas program read as Fanuc's: rs274ngc's "P word with no ..." said nothing of the call)
     ("M97 P1000", "M97 (Haas's local subprogram call, which a Fanuc control has not: for a Haas program give --dialect haas)", "fanuc"),
     ("G54.1 P1", "G54.1 P1 (an additional work offset ncpp is not told: give --work-offset G54.1P1=", "fanuc"),
     ("G54.1 P49", "G54.1 P49 (an additional work offset ncpp is not told)", "fanuc"),
     ("G154 P3 G0 X1", "G154 with other words in its block", "haas"), ("G54.1", "G54.1 without one P", "fanuc"),
     ("G10 L20 P1 X0 Y0", "G10 L20 P1 of some axes of an additional work offset ncpp is not told", "fanuc"),
     ("G10 L20 P2 X#1 Y0 Z0", "G10 L20 with a value from a variable", "haas"),
     ("G10 L2 P0 X5", "G10 L2 P0 (it sets the external work offset", "fanuc"),
     ("G10 L2 P[#1] X5", "G10 L2 P0 (it sets the external work offset", "haas"),
     ("G13 Z-0.3 I0.1875 K0.2 Q0.1875 D02 F10.", "G13 (Haas circular pocket milling", "haas"),
     ("G12 I1.5 F10. Z-1.2 D01", "G12 (Haas circular pocket milling", "haas"),
     # Haas's text engraving (CadeKiely/Hass-CNC-Programs, "CNC MILL/4x3 block - o78244.nc"), which the
     # Haas dialect refused as an unknown G code
     ("G47 P0 (CADE KIELY) X.01 Y-2.95 I0. J0.1 R0.05 Z-0.005 F15. E10.", "G47 (Haas text engraving", "haas"),
     ("G00 G45 H03 Z2.0", "G45 (tool position offset", "fanuc"), ("G46 X10. D15", "G46 (tool position", "fanuc"),
     ("G91 G47 G01 X10. D1", "G47 (tool position offset", "fanuc"), ("G48 Z-2. D2", "G48 (tool position", "fanuc"),
     ("N20 G53 G00 H0 Z -110 M05;", "an H word without G43 (Fanuc's", "fanuc"), ("H2", "an H word without G43", "fanuc"),
     ("G49 H0", "an H word without G43", "fanuc"), ("G0 H#1 Z5", "an H word without G43", "fanuc"),
     # a Haas macro program's rotations under G0 (their R is G68's angle, not a G0 word), which ncpp does
     # not follow (tests/compensation/test_rotation.py: those it follows)
     ("/ G68 X0. R0. ", "2:3: warning: G68 without X and Y", "haas"),
     ("G68 X0. Y0. R#0", "2:1: warning: G68 without R", "haas"),  # (#0 vacant: no R word)
     ("G68 X0. Y0. R#21 F#1", "2:1: warning: G68 with a value from a variable", "haas"),
     ("G68 X0. Y0.", "2:1: warning: G68 without R", "fanuc")],
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
        (b"%\nO1000\nM97 P100 L2\nM30\nN100\nG0 X1\nM99\n", "haas"),  # Haas's local call
        (b"G21\nM97P100\nM30\n", "haas"),
        # Haas's circular pocket milling (a Haas mill program without G187, G103, G154 or M97)
        (b"%\nO1001\nG0 G54 X1.7 Y1.6\nG13 Z-0.3 I0.1875 K0.2 Q0.1875 D02 F10.0\n", "haas"),
        (b"G21\nG12 I5. D1 F100\n", "iso"),  # (no Q: an older Fanuc's circle cutting reads so too)
        (b"G21\nG12.1\nG1 X10. C0 Q1\n", "iso"),
        (b"o100 sub\nM97 P100\no100 endsub\n", "iso"),
        (b"G21\nM97\n(M97 P100)\n", "iso"),  # (no P: not the call; a comment's text is none)
        (b"G21 G90\nG0 X1 Y2 (G187 in a comment)\n", "iso"),
        # axis words after a G80 that gave no motion code: Fanuc's G00 before the cycle moves them, rs274 refuses
        (b"G0 X0. Y14.249\nG98 G73 X0. Y14.249 Z-1. R5. Q0.25 F250.\nG80\nZ5.533\n", "fanuc"),
        (b"G81 X1 Y1 Z-1 R1 F100\nG80\n(next)\n\nN20 X1. Y2.\n", "fanuc"),
        (b"G81 X1 Y1 Z-1 R1 F100\nG80 G0 Z5\nX1\n", "iso"),  # (the G80 line gives G0)
        (b"G81 X1 Y1 Z-1 R1 F100\nG80\nG0 X1\n", "iso"),
        # G00 in a G28 block (a textbook program, `(O2201);` its number in a comment): the G28 takes the
        # axis words on a Fanuc control, rs274 refuses "two g codes that both use axis values"
        (b"(O2201);\nN002 G00 G17 G40 G49 G80 G90;\nN003 G00 G91 G28 Z0.0;\n", "fanuc"),
        (b"G21\nG0 G30 Z5.\n", "fanuc"),
        (b"G21\nG1 G28 Z5.\n", "iso"),  # (G1 there the Fanuc interpreter refuses too)
        (b"G21\nG91 G28 Z0\nG90 G0 X1\n", "iso"),  # (G28 with G91 alone: LinuxCNC's too)
        (b"G21\nG0 G28.1 Z0\nG0 X1 (G28 G0)\n", "iso"),
        (b"o100 sub\nG0 G28 Z0\no100 endsub\n", "iso"),
        # macro statements: LinuxCNC's loops and conditions are o-word lines, Sinumerik's take no brackets
        (b"#1=0\nWHILE [#1 LT 3] DO1\nG0 X#1\n#1=#1+1\nEND1\n", "fanuc"),
        (b"#1=0\nWH[#1LT3]DO1\nG0X#1\n#1=#1+1\nEND1\n", "fanuc"),  # WH: WHILE cut to two characters
        (b"N10 IF [#1 GT 2] GOTO 30\n", "fanuc"),
        (b"WHILE R1<3\nG0 X=R1\nENDWHILE\n", "sinumerik"),
        (b"o1 while [#1 LT 3]\nG0 X#1\no1 endwhile\n", "iso"),
    ],
)
def test_fanuc_and_haas_are_told_by_what_only_they_write(head, dialect):
    assert detect(head) == dialect


def test_a_fusion_drilling_program_with_axis_words_after_g80_is_compensated_as_fanuc(tmp_path):
    """A Fusion 360 post's drilling (no program number: `G80` then `Z5.533` alone, which the G00 before
    the cycle moves on a Fanuc control) is read as Fanuc without `--dialect`: compensated as with it."""
    program = tmp_path / "drill.tap"
    program.write_text(
        "G90 G94 G17 G40 G49\nG21\nT1 M6\nS10000 M3\nG54\nG0 X0. Y14.249\nG43 Z10. H1\nZ5.\n"
        "G98 G73 X0. Y14.249 Z-1. R5. Q0.25 F250.\nG80\nZ5.533\nG73 X-4.369 Y7.315 Z-1. R5.533 Q0.25 F250.\n"
        "X4.369\nG80\nX0. Y-14.249 Z5.533\nZ10.\nM30\n"
    )
    outputs = []
    for told in ((), ("--dialect", "fanuc")):
        run = subprocess.run([sys.executable, "-m", "ncpp", "compensate", *told, "--no-guard", "--machine",
                              str(ROOT / "samples/machines/hr5b.toml"), "--work-offset", "400,350,300", str(program)],
                             capture_output=True, text=True, cwd=tmp_path)  # fmt: skip
        assert run.returncode == 0, run.stderr
        outputs.append(run.stdout)
    assert outputs[0] == outputs[1]


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


# A class exercise's program with a closing `%` and none above it (IIIVENDETTAIII/CNC-Programming,
# SSCNC "One Flor.txt", shortened): its only `%` is the start a Fanuc control reads the file from
UNSTARTED = "O0008\nG17 G21 G40 G49 G90\nG00 X-86 Y0 Z5\nG01 Z-2 F500\nG01 X-46 Y0 F800\nM30\n%\n"


@pytest.mark.parametrize("start", ["", "%\n"])
def test_a_program_above_the_files_only_percent_is_said_to_be_the_leader_not_compensated(tmp_path, start):
    """Its lines are the tape's leader the control skips: they pass through as they are with a warning at
    the first of them (before, the run said it left nothing as programmed); with a `%` above, compensated."""
    program = tmp_path / "p.nc"
    program.write_text(start + UNSTARTED)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(READING), str(program)],
                          capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    told = "p.nc:1:1: warning: this line stands above the file's first `%`" in proc.stderr
    moves = [line for line in proc.stdout.splitlines() if line.startswith("G0")]
    assert told == (start == "")
    assert (moves == [line for line in UNSTARTED.splitlines() if line.startswith("G0")]) == (start == "")


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


def compensated_by_cli(tmp_path: Path, text: str, dialect: str, *options: str) -> tuple[str, str, Path]:
    """`text` compensated by `ncpp compensate` on READING's machine as `dialect` (the test fails on a
    non-zero exit): the written program, the messages, and the program's file."""
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(text)
    command = [
        "compensate",
        "--machine",
        str(READING),
        "--dialect",
        dialect,
        *options,
        str(program),
        "-o",
        str(out),
    ]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    return out.read_text(), proc.stderr, program


def test_g0_in_a_return_block_is_the_modal_motion_after_it(tmp_path):
    """The return is left as programmed and the moves after it are compensated: the X Y Z block after
    `G0 G28` is a rapid.  Judged by LinuxCNC's rs274 on the twins of input and output (pathcheck: same
    actions, rapids where the original rapids, within 0.05 mm); ncpp refused the block before."""
    if not (RS274.exists() and PATHCHECK.exists()):
        pytest.skip("rs274 or pathcheck not available")
    written, messages, _ = compensated_by_cli(tmp_path, RETURN_WITH_G0, "fanuc")
    assert "\nG0 G28 G91 Z0.\n" in written and "\nG00 G91 G28 Z0.\n" in written
    assert "compensated 4 moves" in messages
    twin_in, twin_out = tmp_path / "in.ngc", tmp_path / "out.ngc"
    twin_in.write_text(rs274_twin(RETURN_WITH_G0))
    twin_out.write_text(rs274_twin(written))
    check = subprocess.run([sys.executable, str(PATHCHECK), str(twin_in), str(twin_out), "--tol-mm", "0.05"],
                           capture_output=True, text=True, timeout=600)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


def test_a_program_with_g0_in_a_return_block_and_no_number_is_read_as_fanuc(tmp_path):
    """Without its `O0025` line (a textbook program gives its number in a comment) the `G0 G28` block alone
    tells a Fanuc program: compensated as with `--dialect fanuc`, where it was read as LinuxCNC's and refused."""
    text = RETURN_WITH_G0.replace("%\nO0025\n", "(O0025);\n")
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(READING), str(program),
                           "-o", str(out)], capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert out.read_text() == compensated_by_cli(tmp_path, text, "fanuc")[0]


def test_g1_in_a_return_block_is_still_refused():
    """Only the G0 that posts write is read so: G1 with G28 stays LinuxCNC's refusal."""
    with pytest.raises(NcppError, match="two g codes that both use axis values"):
        events("G21 G90\nG1 G28 G91 Z0. F100\nM30\n", "fanuc")


# Haas G73/G83 with P: from (0, 0, 5), G98, holes at X10 and X20, R2, bottom -10, pecks of 4 mm; between
# pecks G83 goes out to R and G73 up by rs274ngc's 0.254 mm, both back in to 0.254 mm above the last peck
PECK_DWELL = "%\nO1\nG21 G90 G54\nG0 X0 Y0 Z5\nG{g} G98 X10 Y0 Z-10 R2 Q4 P500 F100\nX20\nG80\nM30\n%\n"


def peck_hole(x: float, g: int) -> list[tuple[str, tuple[float, float, float]]]:
    moves = [("STRAIGHT_TRAVERSE", (x, 0, 5)), ("STRAIGHT_TRAVERSE", (x, 0, 2))]
    for depth in (-2, -6):
        moves.append(("STRAIGHT_FEED", (x, 0, depth)))
        moves += [("STRAIGHT_TRAVERSE", (x, 0, 2))] if g == 83 else []
        moves.append(("STRAIGHT_TRAVERSE", (x, 0, round(depth + 0.254, 9))))
    return moves + [("STRAIGHT_FEED", (x, 0, -10)), ("STRAIGHT_TRAVERSE", (x, 0, 5))]


@pytest.mark.parametrize("g", [73, 83])
def test_haas_g73_g83_take_a_dwell_p_and_drill_the_same_holes(g):
    """Haas Mill Operator's Manual 96-8000, "G73 High-Speed Peck Drilling Canned Cycle" and "G83 Normal
    Peck Drilling Canned Cycle": P, the pause at the bottom of each hole after its last peck.  The
    holes' moves, computed by hand, are those without it; Fanuc's formats take no P, which is kept and
    moves nothing (`FanucInterpreter.any_cycle_p`); rs274 refuses it."""
    from ncpp.motion.canon import canon_call

    for dialect in ("haas", "fanuc"):
        calls = [canon_call(e) for e in events(PECK_DWELL.format(g=g), dialect)]
        found = [(c.name, tuple(round(v, 9) for v in c.args[:3])) for c in calls if c is not None]
        assert found == [("STRAIGHT_TRAVERSE", (0, 0, 5)), *peck_hole(10, g), *peck_hole(20, g)]
    with pytest.raises(NcppError, match="P word with no G2 G3 G4"):
        events(PECK_DWELL.format(g=g), "iso")


@pytest.mark.parametrize("g", [73, 83])
def test_a_haas_peck_cycle_with_p_is_compensated_with_its_p_and_verified(tmp_path, g):
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(PECK_DWELL.format(g=g))
    command = ["compensate", "--machine", str(READING), "--dialect", "haas", str(program), "-o", str(out)]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True, cwd=ROOT)
    moves = 1 + len(peck_hole(10, g)) * 2
    assert proc.returncode == 0 and f"compensated {moves} moves" in proc.stderr, proc.stderr
    cycle = next(line for line in out.read_text().splitlines() if line.startswith(f"G{g} "))
    assert cycle.endswith(" Q4 P500 F100") and cycle != f"G{g} G98 X10 Y0 Z-10 R2 Q4 P500 F100"
    # written as G0/G1 moves the pause is a G4 after each hole's last peck, with the P as given where a
    # Haas G04 reads it in seconds too (a decimal point); P500, which a G04 reads in milliseconds, is refused
    expand = [sys.executable, "-m", "ncpp", *command, "--expand-cycles"]
    expanded = subprocess.run(expand, capture_output=True, text=True, cwd=ROOT)
    assert (
        expanded.returncode != 0
        and "p.nc:5:" in expanded.stderr
        and "P500 cannot be written as a G04" in expanded.stderr
    )
    program.write_text(PECK_DWELL.format(g=g).replace("P500", "P0.5"))
    assert _dwells(expand, out) == [-10.0, -10.0]
    # a G82's dwell holds in the G83 after it, until G80 cancels it (the manual: "The same dwell time
    # applies to all subsequent blocks that do not specify a dwell time")
    for between, holes in (("", 2), ("G80\n", 1)):
        program.write_text(f"%\nO1\nG21 G90\nG0 X0 Y0 Z5\nG82 X10 Y0 Z-10 R2 P1. F100\n{between}"
                           f"G{g} X20 Y0 Z-10 R2 Q4\nG80\nM30\n%\n")  # fmt: skip
        assert _dwells(expand, out, "P1.") == [-10.0] * holes


# G81 with a P its format has not (Fanuc Series 0i and 16i: `G81 X_ Y_ Z_ R_ F_ K_`), from (0, 0, 5), G98
DRILL_P = "%\nO1\nG21 G90 G54\nG0 X0 Y0 Z5\nG81 G98 X10 Y0 Z-10 R2 P500 F100\nX20\nG80\nM30\n%\n"


def drill_hole(x: float) -> list[tuple[str, tuple[float, float, float]]]:
    return [("STRAIGHT_TRAVERSE", (x, 0, 5)), ("STRAIGHT_TRAVERSE", (x, 0, 2)), ("STRAIGHT_FEED", (x, 0, -10)),
            ("STRAIGHT_TRAVERSE", (x, 0, 5))]  # fmt: skip


def test_a_p_on_g81_is_kept_and_the_holes_are_g81s(tmp_path):
    """G81's sequence has no dwell: the P moves nothing whatever the control makes of it, the block is
    compensated with its P as written (rs274 refuses it); --expand-cycles, which would drop it, refuses."""
    from ncpp.motion.canon import canon_call

    for dialect in ("fanuc", "haas"):
        calls = [canon_call(e) for e in events(DRILL_P, dialect)]
        found = [(c.name, tuple(round(v, 9) for v in c.args[:3])) for c in calls if c is not None]
        assert found == [("STRAIGHT_TRAVERSE", (0, 0, 5)), *drill_hole(10), *drill_hole(20)]
    with pytest.raises(NcppError, match="P word with no G2 G3 G4"):
        events(DRILL_P, "iso")


@pytest.mark.parametrize("before", ["G81 X10 Y10 Z-5 R2", "G76 X10 Y10 Z-5 R2 I0.2 J0.1"])
def test_a_back_bore_after_another_cycle_without_both_i_and_j_ends_interpretation(before):
    """I J are modal in a Fanuc canned cycle (15i-MA, "Back boring cycle (G87)": "I, J, and K are modal in a
    canned cycle"): a G87 that follows another cycle of the series and leaves one out may shift by that
    cycle's, which ncpp does not guess; with both it is compensated, a hole."""
    head = "G21 G90 G17\nG0 X0 Y0 Z25 S500 M3\nG98 " + before + " F100\n"
    said = io.StringIO()
    found = events(head + "G87 X1 Y1 Z-1 R-3 I1\nG80\nM30\n", "fanuc", Warnings(stream=said))
    assert (
        "p.nc:4:1: warning: Fanuc's back boring G87 after another cycle without both I and J"
        in said.getvalue()
    )
    assert not any(type(e) is Line and e.block.line >= 4 for e in found)
    found = events(head + "G87 X1 Y1 Z-1 R-3 I1 J0\nG80\nM30\n", "fanuc")
    assert [e.hole.fanuc_back for e in found if type(e) is Line and e.block.line == 4] == [True] * 8


def test_a_g81_with_p_is_compensated_with_its_p_and_expand_cycles_refuses_it(tmp_path):
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(DRILL_P)
    command = ["compensate", "--machine", str(READING), "--dialect", "fanuc", str(program), "-o", str(out)]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0 and "compensated 9 moves" in proc.stderr, proc.stderr
    cycle = next(line for line in out.read_text().splitlines() if line.startswith("G81 "))
    assert cycle.endswith(" P500 F100") and cycle != "G81 G98 X10 Y0 Z-10 R2 P500 F100"
    expand = subprocess.run([sys.executable, "-m", "ncpp", *command, "--expand-cycles"], capture_output=True,
                            text=True, cwd=ROOT)  # fmt: skip
    assert expand.returncode != 0, expand.stderr
    assert "p.nc:5:24: --expand-cycles: the P of G81" in expand.stderr


def _dwells(command: list[str], out: Path, p: str = "P0.5") -> list[float]:
    """The Z (to 0.01 mm) of the move before each `G4 {p}` of the program `command` writes to `out`."""
    proc = subprocess.run(command, capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    lines = out.read_text().splitlines()
    assert not any(line.startswith("G4") and line != f"G4 {p}" for line in lines)
    return [round(float(re.findall(r"Z(-?[\d.]+)", lines[k - 1])[0]), 2) for k, line in enumerate(lines)
            if line == f"G4 {p}"]  # fmt: skip


@pytest.mark.parametrize("g", [73, 83])
def test_haas_peck_holes_are_rs274s_of_the_cycle_without_p(tmp_path, g):
    from ncpp.motion.canon import canon_call, read_canon
    from tests.motion.test_oracle import rs274, same_calls

    if not RS274.exists():
        pytest.skip("rs274 not available")
    twin = tmp_path / "twin.ngc"
    twin.write_text(PECK_DWELL.format(g=g).replace(" P500", ""))
    reference = read_canon(rs274(str(twin))[0])
    mine = [c for c in (canon_call(e) for e in events(PECK_DWELL.format(g=g), "haas")) if c is not None]
    assert len(mine) == len(reference) and same_calls(reference, mine), (reference, mine)


def test_a_d_word_in_a_tool_length_block_is_read():
    """`G43H1D1Z150.` (dennisselyaev/gcode, 3.nc, a Fanuc 0i-MD program): a Fanuc control keeps the D for
    the G41/G42 to come; LinuxCNC refuses a D without G41/G42."""
    program = "G90G54G0X0.Y0.;\nG43H1D1Z150.;\nG0X10.\nM30\n"
    for dialect in ("fanuc", "haas"):
        assert [type(e) for e in events(program, dialect)] == [Line, Line, Line, Pass]
    with pytest.raises(NcppError, match="D word with no G41"):
        events(program, "iso")


@pytest.mark.parametrize(
    "body, refused",
    [("T1 M6\nD2\nG41\nG1 X38.09\n", 7), ("T1 M6\nD2\nG41\nG1 X38.11\nG40\nG1 X0\n", None),
     ("T2 M6\nD1\nG41\nG1 X126.99\n", 7), ("T2 M6\nD1\nG41\nG1 X127.01\nG40\nG1 X0\n", None)],
)  # fmt: skip
def test_g41_without_d_takes_the_radius_of_the_d_in_effect(tmp_path, body, refused):
    """Fanuc's D is modal: `D2` then `G41` offsets by tool 2's radius (1.5 in), as LinuxCNC's `G41 D2`, which
    rs274 judges here (its refusal of a move shorter than the radius, a line earlier there)."""
    from dataclasses import replace

    from ncpp.motion.offsets import WorkOffsets
    from ncpp.motion.tools import ToolTable
    from tests.motion.test_oracle import rs274_error, write_program

    if not RS274.exists():
        pytest.skip("rs274 not available")
    table = tmp_path / "tool.tbl"
    table.write_text("T1 P1 D10 Z0\nT2 P2 D3 Z0\n")
    head = "G21 G90 G17 G94\nG0 X0 Y0 Z5\nG1 Z-1 F100\n"
    twin = write_program(tmp_path, head + body.replace("D2\nG41", "G41 D2").replace("D1\nG41", "G41 D1"))
    theirs = rs274_error(oracle.run(twin, tool_table=table, timeout=60).stderr)
    offsets = replace(WorkOffsets.at((0.0, 0.0, 0.0)), tools=ToolTable.from_file(table, unit_mm=25.4))
    interpret, _ = dialect_tools("fanuc")
    _, blocks = parse_program(io.BytesIO((head + body + "M30\n").encode()), "p.nc", "fanuc")
    try:
        list(interpret(blocks, file="p.nc", offsets=offsets, warnings=Warnings(stream=io.StringIO())))
        error = None
    except NcppError as err:
        error = err
    assert (theirs is None) is (refused is None) and (error is None) is (refused is None), (theirs, error)
    assert refused is None or (error.where.line == refused and error.message == theirs[0]), (theirs, error)


def test_a_d_word_under_compensation_ends_interpretation():
    said = io.StringIO()
    found = events("G21 G90\nG0 X0 Y0\nG41 D1 G1 X10 F100\nD2\nG1 X20\nG40 G1 X30\nM30\n", "fanuc",
                   Warnings(stream=said))  # fmt: skip
    assert "a D word under cutter compensation" in said.getvalue() and "p.nc:4:1" in said.getvalue()
    assert [type(e) for e in found][3:] == [Pass, Pass, Pass, Pass]


def test_a_fanuc_dwell_in_x_is_read_past():
    """`G04 X2.0 (wait 2.0s)` (mojimould/mould_moji, Created_NC_Programs/sub_programs/O410000.nc): Fanuc's
    dwell in seconds ("Dwell (G04)": `G04 X_ ;` or `G04 P_ ;`), no axis word; LinuxCNC and Haas read P only."""
    program = "G21 G90\nG0 X0 Y0 Z5\nG04 X2.0 (wait 2.0s)\nG1 X10 F100\nM30\n"
    assert [type(e) for e in events(program, "fanuc")] == [Pass, Line, Pass, Line, Pass]
    for dialect in ("haas", "iso"):
        with pytest.raises(NcppError, match="Dwell time missing with G4"):
            events(program, dialect)
    said = io.StringIO()
    found = events(program.replace("X2.0 (wait", "X2.0 Y1 (wait"), "fanuc", Warnings(stream=said))
    assert [type(e) for e in found] == [Pass, Line, Pass, Pass, Pass] and "G04 X (a dwell) with other" in (
        said.getvalue()
    )


# A drilling cycle interrupts the G0 or G1 of the line before it; after G80 a block of axis words alone
CYCLE_THEN_G80 = "G21 G90 G17 G94\nG0 X0 Y0 Z5\n{mode} Z1 F100\nG98 G81 X10 Y0 Z-2 R1 F50\nG80\nX20 Y5\n"


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
@pytest.mark.parametrize("mode", ["G0", "G1"])
def test_g80_leaves_the_motion_mode_the_cycle_interrupted(tmp_path, mode, dialect):
    """`G0 Z.1`, `G81 ...`, `G80`, `G91 A[360.0 / #2]` (z64/cncbook stdbc.nc, a Haas bolt circle): cycles are
    group 09 and G80 leaves group 01's mode in effect (fanuc.py).  Judged by rs274 on the twin that writes
    the mode again after G80; LinuxCNC, where G80 leaves no motion mode, refuses the block."""
    from ncpp.motion.canon import canon_call, read_canon
    from tests.motion.test_oracle import rs274_error, run_rs274, write_program

    if not RS274.exists():
        pytest.skip("rs274 not available")
    program = CYCLE_THEN_G80.format(mode=mode) + "M30\n"
    mine = [call for call in map(canon_call, events(program, dialect)) if call is not None]
    twin = write_program(tmp_path, program.replace("G80\nX20", f"G80\n{mode} X20"))
    calls, messages = run_rs274(twin)
    assert rs274_error(messages) is None, messages
    theirs = read_canon(calls)
    last = theirs[-1]
    assert last.name == ("STRAIGHT_TRAVERSE" if mode == "G0" else "STRAIGHT_FEED")
    assert last.args[:3] == (20, 5, 1)
    assert [c.name for c in mine] == [c.name for c in theirs]
    assert all(abs(a - b) <= 1e-6 for want, got in zip(theirs, mine) for a, b in zip(want.args, got.args))
    with pytest.raises(NcppError, match="Cannot use axis values without a g code that uses them"):
        events(program, "iso")


def test_g80_on_a_line_of_its_own_keeps_the_g0_in_effect():
    """A safety line's G80 with no cycle running changes nothing in group 01: the X after it is a rapid."""
    found = events("G21 G90 G54\nG0 X0 Y0 Z5\nG17 G40 G80\nX10\nM30\n", "fanuc")
    assert [type(e) for e in found] == [Pass, Line, Pass, Line, Pass]
    assert found[3].rapid and found[3].end[0] == 10


def test_a_return_under_cutter_compensation_ends_interpretation():
    """`G41 D01 ...` never cancelled, then `G28 Z0` (MechatronicsCherepanovMA/CNCLearn O0005.nc): Fanuc drops
    the offset at the intermediate point and restores it after (fanuc.py); ncpp does not follow that and
    passes the rest through, located, where LinuxCNC refuses the block."""
    program = "G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-2 F100\nG41 D1 Y-5\nG1 X10\nG28 Z0\nG28 X0 Y0\nM30\n"
    said = io.StringIO()
    found = events(program, "fanuc", Warnings(stream=said))
    assert "p.nc:6:1: warning: G28 under cutter compensation" in said.getvalue()
    assert [type(e) for e in found][5:] == [Pass, Pass, Pass]
    with pytest.raises(NcppError, match="Cannot use g28 or g30 with cutter radius comp"):
        events(program, "iso")


# Haas's cycle log (aaronrzt/SistemasTecnologias4.0 DPRNTer/2003.nc writes such lines above its O number)
EXTERNAL_OUTPUT = (
    "%\nO1\nG21 G90 G54\nPOPEN\nDPRNT[FECHA (AAMMDD): #3011]\nG0 X10 Y10 Z5\n"
    "DPRNT[X#5021[44]*Y#5022[44]]\nBPRNT[C*/X#110[3]]\npclos\nG1 X20 F100\nM30\n%\n"
)


def test_external_output_is_read_whole_and_moves_nothing():
    """`DPRNT[ a #b [ c d ] ... ]` (NCT 2000M manual, "Custom Macro"), `BPRNT[..]`, `POPEN`, `PCLOS`: one
    statement each, to the line's end, the `(` and the format brackets in it unread; the moves around
    them are followed.  LinuxCNC refuses the line as rs274 does ("Unknown word where unary ...")."""
    _, blocks = parse_program(io.BytesIO(EXTERNAL_OUTPUT.encode()), "p.nc", "fanuc")
    outputs = [b for b in blocks if b.items and getattr(b.items[0], "kind", None) == "external_output"]
    assert [len(b.items) for b in outputs] == [1, 1, 1, 1, 1]
    assert [b.items[0].end - b.items[0].start for b in outputs] == [len(b.raw) for b in outputs]
    for dialect in ("fanuc", "haas"):
        said = io.StringIO()
        found = events(EXTERNAL_OUTPUT, dialect, Warnings(stream=said))
        assert [type(e) for e in found].count(Line) == 2 and not said.getvalue()
        assert [e.end for e in found if type(e) is Line] == [(10, 10, 5), (20, 10, 5)]
    with pytest.raises(NcppError, match=r"p.nc:4:1: Unknown word where unary operation could be"):
        events(EXTERNAL_OUTPUT, "iso")


def test_external_output_passes_through_the_compensated_program(tmp_path):
    written, messages, _ = compensated_by_cli(tmp_path, EXTERNAL_OUTPUT, "haas")
    for line in EXTERNAL_OUTPUT.splitlines()[3:5] + EXTERNAL_OUTPUT.splitlines()[6:9]:
        assert f"\n{line}\n" in written
    assert "compensated 2 moves" in messages


SUBPROGRAM_IN_P = (
    "%\nO1000\nG21 G90 G17\nG0 X0 Y0 Z5 F200\nM98 P31002\nG1 Y1\nM30\nO{n}\nG91 G1 X1\nG90\nM99\n%\n"
)


def test_fanuc_m98_p_gives_the_runs_before_the_program_number():
    """Fanuc Series 0i-MC operator's manual (B-64124EN), "Subprogram (M98, M99)": `M98 P51002` calls
    subprogram 1002 five times; a program numbered with all of P (eight-digit numbers) is called once."""
    ends = [e.end[:2] for e in events(SUBPROGRAM_IN_P.format(n=1002), "fanuc") if type(e) is Line]
    assert [round(x, 6) for x, _ in ends] == [0.0, 1.0, 2.0, 3.0, 3.0] and ends[-1][1] == 1.0
    ends = [e.end[:2] for e in events(SUBPROGRAM_IN_P.format(n=31002), "fanuc") if type(e) is Line]
    assert [round(x, 6) for x, _ in ends] == [0.0, 1.0, 1.0]


@pytest.mark.parametrize("dialect", ["haas", "iso"])
def test_haas_and_linuxcnc_m98_p_is_the_program_number(dialect):
    """Haas Mill Operator's Manual, "M98 Sub Program Call": "M98 Pnnnn (Pnnnn is the number of the
    program being called)"; rs274ngc alike: `M98 P31002` with only O1002 in the program is not followed."""
    said = io.StringIO()
    ends = [
        e for e in events(SUBPROGRAM_IN_P.format(n=1002), dialect, Warnings(stream=said)) if type(e) is Line
    ]
    assert (
        len(ends) == 1
        and "p.nc:5:1: warning: M98 P31002: a subprogram the program does not define" in said.getvalue()
    )


# A Haas student program's circular pocket (enier290188/cnc src/mill_hp_4/mill_hp_4_ok_v2.nc), shortened
CIRCULAR_POCKET = (
    "G17 G20 G40 G49 G80\nT02 M06\nG00 G90 G54 X1.7 Y1.6\nS10000 M03\nG43 H02 Z0.1\nG01 Z-0.05 F10.\n"
    "X1.9 Y1.8\nG13 Z-0.3 I0.1875 K0.2 Q0.1875 D02 F10.0\nG01 X1.7125 Y1.6 F650.0\nY0.9\nG00 Z0.1\nM30\n"
)


def test_a_haas_circular_pocket_passes_through_and_the_moves_before_it_are_compensated(tmp_path):
    """G12/G13 spiral a pocket out from where the tool stands (Haas VF-series manual 96-8000, "Circular
    Pocket Milling"): ncpp leaves the rest of the program as it is, located, where it refused the line
    with LinuxCNC's "Unknown g code used"; rs274 judges the compensated moves before it."""
    tools = tmp_path / "tools.tbl"
    tools.write_text("T2 P2 Z1.5 D0.375 ; 3/8 end mill\n")
    written, messages, program = compensated_by_cli(
        tmp_path, CIRCULAR_POCKET, "haas", "--no-guard", "--tool-table", str(tools), "--var-units", "inch"
    )
    assert f"{program}:8:1: warning: G13 (Haas circular pocket milling" in messages
    tail = "".join(CIRCULAR_POCKET.splitlines(keepends=True)[7:])
    assert written.endswith(tail) and "compensated 4 moves" in messages
    if not RS274.exists():
        pytest.skip("rs274 not available")
    head = written[: -len(tail)]
    before, after = tmp_path / "before.ngc", tmp_path / "after.ngc"
    before.write_text(CIRCULAR_POCKET[: -len(tail)] + "M30\n")
    after.write_text(head + "M30\n")
    check = subprocess.run([sys.executable, str(PATHCHECK), str(before), str(after), "--tol-mm", "0.02",
                            "--tool-table", str(tools)], capture_output=True, text=True)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


# A Mazak EIA program's tool position offset (obirimelvin/machinist 2002.nc, "Machine Mazak v7.5": its line 14),
# after moves of its own
POSITION_OFFSET = (
    "%\nO2002\nG00 G20 G17 G40 G49 G54 G80 G90\nG00 G90 X0.5 Y0.5 Z1.\nG01 X1.5 Y1.0 F20.\nG00 G45 H03 Z2.0\n"
    "G00 Z.1\nG01 X0.5 F20.\nM30\n%\n"
)


def test_a_fanuc_tool_position_offset_passes_through_and_the_moves_before_it_are_compensated(tmp_path):
    """G45-G48 lengthen or shorten the block's move by an offset value (Mitsubishi M700V/M70V programming
    manual, "Tool Position Offset; G45 to G48"): ncpp leaves the rest of the program as it is, located,
    where it refused the line with LinuxCNC's "Unknown g code used"; rs274 judges the moves before it."""
    written, messages, program = compensated_by_cli(tmp_path, POSITION_OFFSET, "fanuc", "--no-guard")
    assert f"{program}:6:5: warning: G45 (tool position offset" in messages
    tail = "".join(POSITION_OFFSET.splitlines(keepends=True)[5:])
    assert written.endswith(tail) and "compensated 3 moves" in messages
    with pytest.raises(NcppError, match="p.nc:6:5: Unknown g code used"):
        events(POSITION_OFFSET, "iso")
    _heads_take_one_path(tmp_path, POSITION_OFFSET, written, tail)


def _heads_take_one_path(tmp_path: Path, program: str, written: str, tail: str) -> None:
    """The program and the written one up to the `tail` they share (where interpretation ended),
    each closed by M30: rs274 runs them along one path (pathcheck)."""
    before, after = tmp_path / "before.ngc", tmp_path / "after.ngc"
    before.write_text(program[: -len(tail)] + "M30\n")
    after.write_text(written[: -len(tail)] + "M30\n")
    oracle.pathcheck(before, after, "--tol-mm", "0.02")


# A Fanuc course program's retract to the machine's Z zero with H0 and no G43 (rodolforavellli23/Projects
# GCode/new_college_project.nc, its line 7), after moves of the program's own
INDEPENDENT_H = (
    "%\nO0001\nN10 G17 G21 G90 G94;\nN12 G00 G54 X10 Y10 Z20;\nN14 G01 X40 Y25 F500;\n"
    "N20 G53 G00 H0 Z -110 M05; (This is the Z 0 position for the machine targeted by this program)\n"
    "N30 T13;\nN40 M06;\nM30;\n%\n"
)


def test_a_fanuc_h_word_without_g43_passes_through_and_the_moves_before_it_are_compensated(tmp_path):
    """Fanuc takes an H on its own (0i-MB operator's manual: "independent specification of the H command"):
    ncpp leaves the rest of the program as it is, located, where it refused the line with LinuxCNC's "H word
    with no G43 or G76 to use it" (as it still does for LinuxCNC and Haas); rs274 judges the moves before."""
    written, messages, program = compensated_by_cli(tmp_path, INDEPENDENT_H, "fanuc", "--no-guard")
    assert f"{program}:6:13: warning: an H word without G43" in messages
    tail = "".join(INDEPENDENT_H.splitlines(keepends=True)[5:])
    assert written.endswith(tail) and "compensated 2 moves" in messages
    for dialect in ("iso", "haas"):
        with pytest.raises(NcppError, match="p.nc:6:13: H word with no G43 or G76 to use it"):
            events(INDEPENDENT_H, dialect)
    _heads_take_one_path(tmp_path, INDEPENDENT_H, written, tail)


# A Fanuc student program's circles (IIIVENDETTAIII/CNC-Programming, SSCNC "Phase 2 ... Work Wersion Update")
STILL_ARC = "O0025\nG21 G17 G40 G49 G90\nG00 G54 X40 Y50 Z5\nG01 Z-3 F100.0\nG03 X40 Y50 R20\nG03 X80 Y50 R20\nG00 Z50\nM30\n"


def test_an_r_arc_that_ends_where_it_starts_does_not_move():
    """Fanuc 16/18/160/180-C operator's manual, "Circular interpolation": with R, an end point at the start
    point is an arc of 0 degrees, the cutter does not move (`G02 R_;` too); the next arc keeps G03.
    LinuxCNC refuses it ("Current point same as end point of arc"), ncpp too on Haas and under cutter
    compensation."""
    for program in (STILL_ARC, STILL_ARC.replace("G03 X40 Y50 R20", "G03 R20")):
        found = events(program, "fanuc")
        assert [type(e) for e in found][3:6] == [Line, Pass, Arc]
        assert found[5].start == (40, 50, -3) and found[5].end == (80, 50, -3)
    for dialect in ("iso", "haas"):
        with pytest.raises(NcppError, match="p.nc:5:1: Current point same as end point of arc"):
            events(STILL_ARC, dialect)
    with pytest.raises(NcppError, match="Current point same as end point of arc"):
        events(STILL_ARC.replace("G01 Z-3 F100.0", "G01 Z-3 F100.0\nG41 D0 X40 Y50"), "fanuc")


def test_an_r_arc_that_ends_where_it_starts_passes_through_and_rs274_judges_the_rest(tmp_path):
    """The compensated program (the 0-degree arc as written) against the original without that block, which
    is what the control runs: rs274 judges both."""
    compensated, _, _ = compensated_by_cli(tmp_path, STILL_ARC, "fanuc", "--no-guard")
    assert "\nG03 X40 Y50 R20\n" in compensated
    if not RS274.exists():
        pytest.skip("rs274 not available")
    meant = tmp_path / "meant.ngc"
    meant.write_text(STILL_ARC.replace("O0025\n", "").replace("G03 X40 Y50 R20\n", ""))
    written = tmp_path / "written.ngc"
    written.write_text(compensated.replace("O0025\n", ""))
    check = subprocess.run([sys.executable, str(PATHCHECK), str(meant), str(written), "--tol-mm", "0.02"],
                           capture_output=True, text=True)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


# R and I J in one arc block: the second arc's I J point nowhere near its centre
R_AND_IJ = "G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG2 X20 Y0 R10 I10 J0\nG2 X40 Y0 R10 I3 J7\nG0 Z5\nM30\n"


def test_r_wins_over_i_j_k_in_a_fanuc_arc_block(tmp_path):
    """Fanuc 16/18/160/180-C operator's manual, "Circular interpolation": with I, J, K and R in one block the
    arc is R's and the others are ignored.  rs274 judges the compensated program against the original
    without its I and J; LinuxCNC refuses the block ("Mixed radius ijk format for arc"), ncpp too on Haas."""
    found = [e for e in events(R_AND_IJ, "fanuc") if type(e) is Arc]
    assert [(a.center[0], a.center[1]) for a in found] == [pytest.approx((10, 0)), pytest.approx((30, 0))]
    for dialect in ("iso", "haas"):
        with pytest.raises(NcppError, match="p.nc:4:1: Mixed radius ijk format for arc"):
            events(R_AND_IJ, dialect)
    compensated, _, _ = compensated_by_cli(tmp_path, R_AND_IJ, "fanuc", "--no-guard")
    assert " R10" not in compensated
    if not RS274.exists():
        pytest.skip("rs274 not available")
    meant = tmp_path / "meant.ngc"
    meant.write_text(R_AND_IJ.replace(" I10 J0", "").replace(" I3 J7", ""))
    written = tmp_path / "written.ngc"
    written.write_text(compensated)
    check = subprocess.run([sys.executable, str(PATHCHECK), str(meant), str(written), "--tol-mm", "0.02"],
                           capture_output=True, text=True)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_a_program_number_written_with_a_colon_is_the_o_number(tmp_path, dialect):
    """`:100` is O100, the program number in ISO code's address (Fanuc 16i/18i-MB B-63684EN, "Program
    number": in ISO code a colon may stand for the O): M98 P100 runs it; rs274 judges the LinuxCNC
    twin, and the lines are written back as they stand."""
    from ncpp.motion.canon import canon_call, read_canon
    from tests.motion.test_oracle import rs274, same_calls, write_program

    if not RS274.exists():
        pytest.skip("rs274 not available")
    head = "G21 G90 G17\nG0 X0 Y0 Z5 F300\n"
    program = ":0001 (MAIN)\n" + head + "M98 P100\nG1 X5\nM98 P100 L2\nM30\n:100\nG91 G1 X1 Y1\nG90\nM99\n"
    twin = head + "o100 sub\nG91 G1 X1 Y1\nG90\no100 endsub\no100 call\nG1 X5\no100 call\no100 call\nM2\n"
    reference = read_canon(rs274(str(write_program(tmp_path, twin)))[0])
    mine = [call for call in map(canon_call, events(program, dialect)) if call is not None]
    assert len(mine) == len(reference) and same_calls(reference, mine), (reference, mine)
    _, blocks = parse_program(io.BytesIO(program.encode()), "p.nc", dialect)
    assert "".join(block.text for block in blocks) == program


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
@pytest.mark.parametrize("line", [":", " : (PART)"])
def test_a_colon_without_a_number_is_refused_where_it_runs(dialect, line):
    """The program number address with no number after it (B-63684EN, "Program number": `:` or O, then
    the number) is refused where the control would run it, and read past where it does not run."""
    with pytest.raises(NcppError, match="p.nc:1:[12]: a program number address `:` without its number"):
        events(f"{line}\nG0 X1\nM30\n", dialect)
    assert len([e for e in events(f"G0 X1\nM30\n{line}\n", dialect) if type(e) is Line]) == 1


def test_a_colon_is_no_program_number_for_linuxcnc():
    """rs274ngc refuses the `:` ("Bad character ':' used"), and so does ncpp in a LinuxCNC program."""
    with pytest.raises(NcppError, match="':1000'"):
        events(":1000\nG0 X1\nM2\n", "iso")


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
@pytest.mark.parametrize("variable", [100, 199, 500, 999])
def test_a_common_variable_reads_only_what_the_program_set(dialect, variable):
    """#100-#199 and #500-#999 are common variables (Fanuc 16i/18i-MB B-63684EN, "Custom macro", "Types of
    variables": #500 on kept at power off): read before the program sets one, it holds what an earlier
    program, a probe cycle or the operator left there, so the move it gives is out of scope (it was
    read as 0, and `G1 X#500` rewritten as a move to X0); set first, it is followed."""
    said = io.StringIO()
    found = events(f"G0 X1\nG1 X#{variable} F100\nG0 X2\nM30\n", dialect, Warnings(stream=said))
    assert [type(e) for e in found] == [Line, Pass, Pass, Pass], said.getvalue()
    assert (
        f"2:4: warning: #{variable}, a variable the control keeps from before the program" in said.getvalue()
    )
    found = events(f"#{variable}=5.\nG0 X1\nG1 X#{variable} F100\nM30\n", dialect)
    assert [e.end[0] for e in found if type(e) is Line] == [1.0, 5.0]


def test_a_linuxcnc_programs_parameter_500_reads_as_rs274_reads_it():
    """In a LinuxCNC program #500 is a parameter rs274ngc reads as 0 until set (its parameter file aside)."""
    found = events("G0 X1\nG1 X#500 F100\nM2\n", "iso")
    assert [e.end[0] for e in found if type(e) is Line] == [1.0, 0.0]


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_g41_again_while_compensation_is_on_ends_interpretation(dialect):
    """A second G41 in the offset mode (a finish pass's, Haas turner's cube `O3001`) is the control's to
    take, its offset vector built anew (module docstring of ncpp/motion/fanuc.py): out of scope at its
    word, where rs274ngc's "Cannot turn cutter radius comp on when on" refused the program."""
    said = io.StringIO()
    text = "G0 X-10 Y0 Z1\nG1 Z0 F100\nG41 X0 Y0\nX10\nG41 X20 Y1\nG40 X30\nM30\n"
    found = events(text, dialect, Warnings(stream=said))
    assert [type(e) for e in found][4:] == [Pass, Pass, Pass], said.getvalue()
    assert "5:1: warning: G41 while cutter compensation is on" in said.getvalue(), said.getvalue()


def test_g41_again_is_refused_in_a_linuxcnc_program():
    with pytest.raises(NcppError, match="Cannot turn cutter radius comp on when on"):
        events("G0 X-10 Y0 Z1\nG1 Z0 F100\nG41 X0 Y0\nX10\nG41 X20 Y1\nG40 X30\nM2\n", "iso")


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_a_local_variable_the_program_has_not_set_is_vacant(dialect):
    """A Fanuc or Haas program's local variables start vacant (B-63684EN, "Custom macro", "Variables"), and
    an address whose value is a vacant variable is left out: `G1 X#21 Y5` with #21 unset moves Y alone,
    where it was read as X0 in a program without a macro statement."""
    found = events("G0 X1 Y1\nG1 X#21 Y5 F100\nM30\n", dialect)
    assert [tuple(e.end) for e in found if type(e) is Line] == [(1.0, 1.0, 0.0), (1.0, 5.0, 0.0)]


def test_expand_keeps_a_g68_of_variables_out_of_scope(tmp_path):
    """Written out, a loop's assignments go and the G68 block's text stays: `R#21` would read what the
    written program no longer sets, so --expand leaves the scope at it, where without --expand the loop
    is left as programmed and the rotation followed."""
    program = tmp_path / "p.nc"
    program.write_text("%\nO1\nG21 G90 G54\nG0 X0 Y0 Z5\n#21=0\n#1=0\nWHILE [#1 LT 2] DO1\nG68 X0 Y0 R#21\n"
                       "G0 X10 Y0\nG1 Z-1 F100\nG0 Z5\nG69\n#21=#21+90\n#1=#1+1\nEND1\nM30\n%\n")  # fmt: skip
    machine = SHARED / "machines" / "wide.toml"
    run = [sys.executable, "-m", "ncpp", "compensate", "--machine", str(machine), "--no-guard", str(program)]
    for expand, said in (
        ([], "left as programmed: 6 moves in loops"),
        (["--expand"], "--expand: G68 with a value"),
    ):
        proc = subprocess.run([*run, "-o", str(tmp_path / "out.nc"), *expand], capture_output=True, text=True,
                              cwd=ROOT, timeout=300)  # fmt: skip
        assert said in proc.stderr, proc.stderr


# Axis words before any of G00-G03 (`G90 Z50` as `G43 H01 Z50` is in a Fanuc program's start), a cycle
# (group 09, which names none), more after its G80, in G91 too, then the program's first G00
HELD_START = ("G21 G90 G17 G94 G54 G40 G49 G80\nG90 Z50\nX-18 Y-18\nG98 G81 X0 Y0 Z-2 R1 F50\nG80\nZ40\n"
              "G91 X5\nG90\nG00 X-18 Y-18\nZ2\nG01 Z-1 F200\nX40\n")  # fmt: skip


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_axis_words_before_any_motion_code_move_in_the_mode_the_control_holds(tmp_path, dialect):
    """Fanuc's group 01 at power-on or reset is G00 (G01 by parameter 3402#0), Haas's G00 (fanuc.py): the
    blocks before the first G00-G03 move straight to their points, left as programmed, with one warning at
    the first; LinuxCNC refuses the program."""
    from ncpp.motion.segments import CYCLE, HELD, HOLE

    said = io.StringIO()
    found = events(HELD_START + "M30\n", dialect, Warnings(stream=said))
    moves = [e for e in found if type(e) is Line]
    held = [m for m in moves if m.fixed == HELD]
    assert [m.block.line for m in held] == [2, 3, 6, 7] and all(m.rapid for m in held)
    assert all(m.fixed in (CYCLE, HOLE) for m in moves if m.block.line == 4)
    assert not any(m.fixed for m in moves if m.block.line > 8)
    assert (
        said.getvalue().count("before the program names G00") == 1 and "p.nc:2:5: warning" in said.getvalue()
    )
    with pytest.raises(NcppError, match="Cannot use axis values without a g code that uses them"):
        events(HELD_START, "iso")


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_the_moves_before_any_motion_code_are_rs274s_of_the_twin_that_writes_g0_in_them(tmp_path, dialect):
    """Judged by LinuxCNC's rs274: the moves are those of the twin with G0 in the blocks before the first G00."""
    from ncpp.motion.canon import canon_call, read_canon
    from tests.motion.test_oracle import rs274_error, run_rs274, write_program

    if not RS274.exists():
        pytest.skip("rs274 not available")
    found = events(HELD_START + "M30\n", dialect)
    twin = (
        HELD_START.replace("\nG90 Z50", "\nG0 G90 Z50")
        .replace("\nX-18", "\nG0 X-18")
        .replace("\nZ40\nG91 X5", "\nG0 Z40\nG0 G91 X5")
    )
    calls, messages = run_rs274(write_program(tmp_path, twin))
    assert rs274_error(messages) is None, messages
    theirs = read_canon(calls)
    mine = [call for call in map(canon_call, found) if call is not None]
    assert [c.name for c in mine] == [c.name for c in theirs]
    assert all(abs(a - b) <= 1e-6 for want, got in zip(theirs, mine) for a, b in zip(want.args, got.args))


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_the_moves_before_any_motion_code_are_written_as_programmed_and_the_rest_compensated(
    tmp_path, dialect
):
    """`G43 H01 Z50` first (the issue's program): every line before the first G00 is written as the input has
    it but the cycle's, whose hole is compensated, and none gets a G word (a G00 or G01 ncpp wrote there would
    set the mode the control holds for the lines after it); the moves from the G00 on are compensated.
    Judged by rs274 on the twins of input and output that write G0 in the held blocks (pathcheck: same
    actions, rapids where the original rapids, within 0.05 mm)."""
    text = (
        "%\nO0200 (PLYTKA)\n"
        + HELD_START.replace("G90 Z50", "G43 H01 Z50").replace("G91 X5\nG90\n", "")
        + "M30\n%\n"
    )
    written, messages, _ = compensated_by_cli(tmp_path, text, dialect, "--no-guard")
    assert "before the program names G00" in messages and "compensated" in messages
    program = [line for line in written.splitlines() if not line.startswith("(ncpp")]
    first = text.splitlines().index("G00 X-18 Y-18")
    before = list(zip(program[:first], text.splitlines()[:first]))
    assert all(re.findall(r"G\d+", out) == re.findall(r"G\d+", given) for out, given in before)
    assert all(out == given for out, given in before if "G81" not in given)  # (the hole is compensated)
    assert program[first] != "G00 X-18 Y-18"  # (compensated)
    if not (RS274.exists() and PATHCHECK.exists()):
        pytest.skip("rs274 or pathcheck not available")
    twins = []
    for name, source in (("in.ngc", text), ("out.ngc", "\n".join(program) + "\n")):
        twin = (
            source.replace("%\n", "").replace("O0200 (PLYTKA)\n", "").replace("G43 H01 Z50", "G43 H01 G0 Z50")
        )
        twin = twin.replace("\nX-18 Y-18", "\nG0 X-18 Y-18").replace("\nZ40\n", "\nG0 Z40\n")
        (tmp_path / name).write_text(twin)
        twins.append(str(tmp_path / name))
    check = subprocess.run([sys.executable, str(PATHCHECK), *twins, "--tol-mm", "0.05"], capture_output=True,
                           text=True, timeout=600)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


@pytest.mark.parametrize(
    "block, reason",
    [("X10 ,C1", "a corner (,C ,R) on a move before the program names G00-G03"),
     ("G41 D1 X10", "a move under cutter compensation before the program names G00-G03")],
)  # fmt: skip
def test_a_move_before_any_motion_code_that_ncpp_cannot_place_ends_interpretation(block, reason):
    said = io.StringIO()
    found = events(f"G21 G90 G54\n{block}\nG0 X1\nM30\n", "fanuc", Warnings(stream=said))
    assert [type(e) for e in found] == [Pass, Pass, Pass, Pass] and reason in said.getvalue()


def test_expanded_cycles_before_a_move_in_the_mode_the_control_holds_are_refused():
    """--expand-cycles writes a cycle as G0/G1 blocks, which would leave the control in G0 or G1 for the
    axis words after its G80: refused, where without the option the cycle's block is kept."""
    interpret, _ = dialect_tools("fanuc")
    program = "G21 G90 G54\nG98 G81 X0 Y0 Z-2 R1 F50\nG80\nZ40\nM30\n"
    _, blocks = parse_program(io.BytesIO(program.encode()), "p.nc", "fanuc")
    with pytest.raises(NcppError, match="--expand-cycles: a canned cycle before the program names G00-G03"):
        list(interpret(blocks, file="p.nc", warnings=Warnings(stream=io.StringIO()), expand_cycles=True))
    assert [type(e) for e in events(program, "fanuc")][-2:] == [Line, Pass]


def test_a_g91_move_before_any_motion_code_right_after_a_cycle_passes_the_rest_on(tmp_path):
    """A G91 move right after a canned cycle in G90 starts where the cycle's G98 retract left the tool, which
    ncpp does not follow (`pipeline.INCREMENTAL_CYCLE`): in the control's start mode too, the rest passes
    through uncompensated with the warning."""
    text = "G21 G90 G54\nG0 X0 Y0 Z5\nG98 G81 X10 Y0 Z-2 R1 F50\nG80\nG91 X5\nG90 G0 X30 Y10\nM30\n"
    held = text.replace("G0 X0 Y0 Z5\n", "X0 Y0 Z5\n")
    written, messages, _ = compensated_by_cli(tmp_path, held, "fanuc")
    assert "a G91 move right after a canned cycle in G90" in messages
    assert written.endswith("G91 X5\nG90 G0 X30 Y10\nM30\n")


@pytest.mark.parametrize(
    "assignment, value",
    [("#3=[#1 OR #2]", 3.0), ("#3=[#1 AND #2]", 0.0), ("#3=[#1 XOR #2]", 3.0), ("#3=[5.0 AND 3.0]", 1.0),
     ("#3=[5.7 XOR 3.2]", 6.0), ("#3=[[#1 LT #2] AND [#2 GT 0]]", 1.0)],
)  # fmt: skip
def test_haas_logical_operators_work_on_the_bits_of_the_integer_parts(assignment, value):
    """Haas Mill Operator's Manual 96-8000, "Macros", "Logical Operators": they "work on binary bit values
    ... only the integer portion of the floating point number is used"; its example `#1=1.0; #2=2.0;
    #3=#1 OR #2;` leaves 3.0 in #3, where rs274ngc's OR (a truth value) gave 1.0 and the move went to X1.
    (ncpp reads an assignment's unbracketed right-hand side as arithmetic only: `#3=[#1 OR #2]`.)"""
    found = events(f"#1=1.0\n#2=2.0\n{assignment}\nG0 X0\nG1 X#3 F100\nM30\n", "haas")
    assert [e.end[0] for e in found if type(e) is Line] == [0.0, value]


def test_a_haas_g_code_of_an_or_is_its_bits():
    """`G[20 OR ABS[20]]` (a program's first block, the shop's own way of writing G20) is G20 on a Haas,
    where the truth value 1 made it a G1 move and the program was read in millimetres."""
    found = events("G[20 OR ABS[20]]\nG0 X1.\nG1 X2. F10.\nM30\n", "haas")
    assert [(type(e), e.end[0]) for e in found if type(e) is Line] == [(Line, 1.0), (Line, 2.0)]
    assert [type(e) for e in found][0] is Pass


def test_a_fanuc_logical_operation_on_other_values_than_0_and_1_ends_interpretation():
    """No Fanuc manual in ncpp's reference set says what OR gives of values other than 0 and 1 (Haas's are
    bitwise): such a block is out of scope, where `G[20 OR 20]` was read as G1 and the block rewritten as a
    move; of comparisons (0 or 1) the result is the same either way, and followed."""
    said = io.StringIO()
    found = events("G0 X1.\nG[20 OR 20]\nG1 X2. F10.\nM30\n", "fanuc", Warnings(stream=said))
    assert [type(e) for e in found] == [Line, Pass, Pass, Pass], said.getvalue()
    assert "2:1: warning: 20 OR 20 (a logical operation on values other than 0 and 1" in said.getvalue()
    found = events("#1=2.\n#2=3.\nIF [[#1 GT 0] AND [#2 GT 2]] GOTO 10\nG0 X9.\nN10 G0 X1.\nM30\n", "fanuc")
    assert [e.end[0] for e in found if type(e) is Line] == [1.0]


def test_a_linuxcnc_or_is_a_truth_value_as_rs274_reads_it(tmp_path):
    """rs274ngc's OR is 1.0 when either value is not 0: `G1 X[20 OR 20]` moves to X1 (rs274 says so)."""
    program = "G21 G90\nG0 X0 Y0 Z0\nG1 X[20 OR 20] F100\nM2\n"
    assert [e.end[0] for e in events(program, "iso") if type(e) is Line] == [0.0, 1.0]
    if RS274.exists():
        path = tmp_path / "p.ngc"
        path.write_text(program)
        calls = subprocess.run([str(RS274), str(path)], capture_output=True, text=True).stdout
        assert "STRAIGHT_FEED(1.0000, 0.0000, 0.0000" in calls
