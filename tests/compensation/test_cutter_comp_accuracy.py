"""Moves under cutter compensation (G41/G42, G41.1/G42.1 in G17 and G18, G90 and G91) compensated where the
tool centre stands, judged by oracles ncpp did not write: LinuxCNC's rs274 prints the tool
centre's path (under compensation its STRAIGHT_FEED and ARC_FEED calls are the tool centre's) of
the original and of the rewritten program; the rewritten one, run on a machine whose errors are
known in closed form (`closed_form`), must put the tool centre on the original's path, and
pathcheck must accept it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.compensation.tool_centre import deviation, feed_moves
from tests.conftest import CORPUS, ROOT, RS274, SHARED
from tests.writeback.conftest import linear_errors, machine_file

PATHCHECK = SHARED / "tools" / "pathcheck"
needs_oracles = pytest.mark.skipif(
    not (RS274.exists() and PATHCHECK.exists()), reason="rs274 or pathcheck not available"
)

# X runs 100 µm/m long, Y 80 µm/m short, and Y leans 100 µrad towards -X (docs/machine-file.md):
# the tool lands at (x + 1e-4·x - 1e-4·y, y - 0.8e-4·y) for the command (x, y)
AFFINE = machine_file(
    "affine", linear_errors(EXX=0.1, EYY=-0.08) + "\n[squareness]\nC0Y_urad = 100.0\n", 500.0
)


def closed_form(command: np.ndarray) -> np.ndarray:
    """Where AFFINE's machine puts the tool for commands (n,3), machine mm."""
    x, y = command[:, 0], command[:, 1]
    reached = command.copy()
    reached[:, 0] = x + 1e-4 * x - 1e-4 * y
    reached[:, 1] = y - 0.8e-4 * y
    return reached


HEAD = "G21 G90 G17 G94 G64\n"
# an outside contour, the tool on the left: lines, a convex and a concave-side arc, a chamfer corner
OUTSIDE = HEAD + (
    "G0 X-20 Y-20 Z5\nG1 Z-1 F300\nG41.1 D10\nG1 X0 Y0\nG1 X80 Y0\nG3 X100 Y20 R20\nG1 X100 Y60\n"
    "G3 X80 Y80 I-20 J0\nG1 X30 Y80\nG1 X0 Y50\nG1 X0 Y0\nG40\nG1 X-20 Y-20\nG0 Z5\nM2\n"
)
# an inside pocket, the tool on the right: arcs with the tool outside them
POCKET = HEAD + (
    "G0 X50 Y40 Z5\nG1 Z-2 F200\nG42.1 D5\nG1 X50 Y10\nG1 X90 Y10\nG3 X110 Y30 I0 J20\nG1 X110 Y70\n"
    "G3 X90 Y90 I-20 J0\nG1 X30 Y90\nG3 X10 Y70 R20\nG1 X10 Y30\nG3 X30 Y10 I20 J0\nG1 X50 Y10\nG40\n"
    "G1 X50 Y40\nG0 Z5\nM2\n"
)
# a polygon, the tool (10 mm) on the right: corners between lines only, put where the lines' corrected
# contours cross (the point corrected for the first line's tool centre would leave the second off by µm)
POLYGON = HEAD + (
    "G0 X-30 Y-30 Z5\nG1 Z-1 F300\nG42.1 D20\nG1 X0 Y0\nG1 X0 Y100\nG1 X120 Y140\nG1 X150 Y30\nG1 X60 Y-10\n"
    "G1 X0 Y0\nG40\nG1 X-30 Y-30\nG0 Z5\nM2\n"
)
# G41 with the radius of the tool table's tool 3, an entry arc, a Z move under compensation
TABLE = HEAD + (
    "T3 M6 G43\nG0 X-30 Y-10 Z5\nG1 Z-3 F250\nG41 D3\nG3 X0 Y0 R30\nG1 Y60\nG2 X20 Y80 R20\nG1 X70\n"
    "G2 X90 Y60 I0 J-20\nG1 Y20\nG2 X70 Y0 I-20 J0\nG1 X0\nG1 Z-4\nG1 X-5\nG40\nG0 X-30 Y-10 Z5\nM2\n"
)
TOOLS = "T3 P3 Z0.5 D0.3 ;tool 3: 7.62 mm\n"  # (inches: the stand-alone rs274 reads its table so)
# a line turned right back onto an arc turned three quarters round, which ends turning right back along
# the line after it; the tool inside the arc (G42): outside corners, gone round by a half turn; outside it
# (G41): inside ones, cut back to where the offsets cross, far along the arc
CUSP = HEAD + (
    "T3 M6 G43\nG0 X0 Y0 Z5\nG42 D3\nG1 X10 Y10 F300\nG1 Z-1\nG1 X200 Y10\nG2 X260 Y70 I0 J60\n"
    "G1 X260 Y200\nG3 X200 Y260 I-60 J0\nG1 X10 Y260\nG1 X10 Y10\nG0 Z5\nG40 G1 X0 Y0\nM2\n"
)


def written(
    tmp_path: Path, text: str, name: str, *options: str
) -> tuple[Path, Path, subprocess.CompletedProcess]:
    """The program as `name` and ncpp's output of it on AFFINE's machine."""
    (tmp_path / "affine.toml").write_text(AFFINE)
    program, out = tmp_path / name, tmp_path / f"{name}.out.ngc"
    program.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "affine.toml"),
                           *options, str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300, stdin=subprocess.DEVNULL)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return program, out, proc


def pathcheck(original: Path, rewritten: Path, *options: str) -> None:
    check = subprocess.run([sys.executable, str(PATHCHECK), str(original), str(rewritten), *options],
                           capture_output=True, text=True, timeout=600)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


@needs_oracles
@pytest.mark.parametrize(
    "text",
    [OUTSIDE, POCKET, POLYGON, TABLE],
    ids=["outside-g41.1", "pocket-g42.1", "polygon-g42.1", "table-g41"],
)
def test_the_tool_centre_lands_on_the_original_path_within_half_a_micron(tmp_path, text):
    """The original's tool-centre path is where the tool centre should be; the rewritten program's,
    run on the machine, is within 0.5 µm of it all along (the arcs fitted to 0.1 µm), where the
    uncompensated program misses it by several µm.  (Corners are the moves' own: the control's
    corner arcs about a corrected point keep an error of the error's gradient times the radius.)"""
    tools = tmp_path / "tools.tbl"
    tools.write_text(TOOLS)
    original, out, _ = written(tmp_path, text, "contour.ngc", "--tolerance", "0.0001", "--tool-table", str(tools),
                               "--var-units", "inch")  # fmt: skip
    before, after = (feed_moves(p, tools, home=tmp_path) for p in (original, out))
    assert sum(m.comp > 0 for m in before) >= 8
    assert deviation(before, before, closed_form).max() > 0.005
    assert deviation(before, after, closed_form).max() <= 0.0005
    pathcheck(original, out, "--tool-table", str(tools))


# X runs 200 µm/m long and Z 150 µm/m short, X moves Z by 250 µm/m of x (its straightness in Z, EZX) and
# Z moves X by -100 µm/m of z (EXZ): the tool lands at (x + 2e-4·x - 1e-4·z, y, z - 1.5e-4·z + 2.5e-4·x)
AFFINE_XZ = machine_file("affine-xz", linear_errors(EXX=0.2, EZZ=-0.15, EZX=0.25, EXZ=-0.1))


def closed_form_xz(command: np.ndarray) -> np.ndarray:
    """Where AFFINE_XZ's machine puts the tool for commands (n,3), machine mm."""
    x, z = command[:, 0], command[:, 2]
    reached = command.copy()
    reached[:, 0] = x + 2e-4 * x - 1e-4 * z
    reached[:, 2] = z - 1.5e-4 * z + 2.5e-4 * x
    return reached


# a lathe-like profile turned in the XZ plane (G18: arcs' I K, the tool right of the contour as seen from
# +Y, LinuxCNC's G41/G42), with a face, a shoulder's fillet, a convex round, a taper and a Y offset
TURNED = (
    "G21 G90 G18 G94 G64\nG0 X70 Y5 Z10\nG1 X60 F200\nG42.1 D8\nG1 X20 Z0\nG1 Z-20\nG2 X30 Z-30 R10\n"
    "G1 X40\nG3 X50 Z-40 K-10 I0\nG1 Z-60\nG1 X60 Z-70\nG3 X60 Z-90 K-10 I0\nG1 Z-110\nG40\n"
    "G1 X80 Z-120\nG0 Z10\nM2\n"
)
# a G17 contour in G91: its increments under G41.1 from the compensated points before them
INCREMENTAL = HEAD + (
    "G0 X-20 Y-20 Z5\nG1 Z-1 F300\nG91\nG41.1 D12\nG1 X20 Y20\nG1 X90\nG3 X20 Y20 R20\nG1 Y50\n"
    "G3 X-20 Y20 I-20 J0\nG1 X-60\nG1 X-30 Y-40\nG2 X0 Y-50 I10 J-25\nG40\nG1 X-20 Y-20\nG90\nG0 Z5\nM2\n"
)


@needs_oracles
@pytest.mark.parametrize(
    "text, machine, reached",
    [(TURNED, AFFINE_XZ, closed_form_xz), (INCREMENTAL, AFFINE, closed_form)],
    ids=["g18-turned-profile", "g91-g17-contour"],
)
def test_in_g18_and_in_g91_the_tool_centre_lands_on_the_original_path(tmp_path, text, machine, reached):
    """G18 (the tool centre left or right as seen from +Y, in the plane's Z X order) and G91 (each
    compensated end written as the increment from the compensated end before it): within 0.5 µm of
    the original's tool-centre path, where the program left as programmed misses it by µm."""
    (tmp_path / "machine.toml").write_text(machine)
    original, out = tmp_path / "plane.ngc", tmp_path / "plane.out.ngc"
    original.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "machine.toml"),
                           "--tolerance", "0.0001", str(original), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300, stdin=subprocess.DEVNULL)  # fmt: skip
    assert proc.returncode == 0 and "warning" not in proc.stderr, proc.stderr
    before, after = (feed_moves(p, home=tmp_path) for p in (original, out))
    under = [m for m in after if m.comp > 0]
    assert len(under) >= 9 and sum(m.centre is not None for m in under) >= 3
    assert deviation(before, [m for m in before if m.comp > 0], reached).max() > 0.005
    assert deviation(before, after, reached).max() <= 0.0005
    pathcheck(original, out)


# moves under G41.1 in a subroutine (a parameter in its words) and in a while loop
IN_BODIES = HEAD + (
    "o100 sub\nG1 X80 Y0\nG3 X100 Y20 R20\nG1 X100 Y[#1]\nG3 X80 Y[#1 + 20] I-20 J0\nG1 X30 Y[#1 + 20]\n"
    "o100 endsub\nG0 X-20 Y-20 Z5\nG1 Z-1 F300\nG41.1 D10\nG1 X0 Y0\no100 call [60]\n#2 = 0\n"
    "o200 while [#2 LT 2]\nG1 X[20 - #2 * 20] Y[80 - #2 * 15]\n#2 = [#2 + 1]\no200 endwhile\nG1 X0 Y0\nG40\n"
    "G1 X-20 Y-20\nG0 Z5\nM2\n"
)


@needs_oracles
def test_with_expand_the_moves_under_compensation_in_loops_and_subroutines_land_on_the_path(tmp_path):
    """--expand writes the bodies out as plain moves: under compensation they are compensated where
    the tool centre stands like any other (without it they are left as programmed, µm off)."""
    original, out, proc = written(tmp_path, IN_BODIES, "bodies.ngc", "--tolerance", "0.0001", "--expand")
    assert "warning" not in proc.stderr, proc.stderr
    before, after = (feed_moves(p, home=tmp_path) for p in (original, out))
    assert sum(m.comp > 0 for m in after) >= 10
    assert deviation(before, before, closed_form).max() > 0.005
    assert deviation(before, after, closed_form).max() <= 0.0005
    pathcheck(original, out)


@needs_oracles
@pytest.mark.parametrize("side, within", [("G42", 0.001), ("G41", 0.0025)])
def test_a_corner_turned_right_back_is_verified_as_the_control_makes_it(tmp_path, side, within):
    """Where the path turns right back (a line onto an arc, an arc's end along the line after it), the
    corrections tilt the corner by µrad; the control tells such a corner by the turn within 50 mrad of a
    half turn, so the written program runs round it as the original does: it is verified and written,
    within 1 µm of the original's tool centre on the machine round outside corners (the half turn about
    a corrected corner keeps the error's gradient times the tool's diameter) and 2.5 µm where the tool
    enters the arc at a crossing far along it, and pathcheck accepts it."""
    tools = tmp_path / "tools.tbl"
    tools.write_text(TOOLS)
    original, out, _ = written(tmp_path, CUSP.replace("G42", side), "cusp.ngc", "--tolerance", "0.0001",
                               "--tool-table", str(tools), "--var-units", "inch")  # fmt: skip
    before, after = (feed_moves(p, tools, home=tmp_path) for p in (original, out))
    assert deviation(before, before, closed_form).max() > 0.01
    assert deviation(before, after, closed_form).max() <= within
    pathcheck(original, out, "--tool-table", str(tools))


@needs_oracles
def test_the_entry_arc_stays_one_arc_the_control_accepts(tmp_path):
    """rs274 checks an entry arc against the tool radius: split, its first piece would be refused."""
    tools = tmp_path / "tools.tbl"
    tools.write_text(TOOLS)
    _, out, _ = written(tmp_path, TABLE, "entry.ngc", "--tolerance", "0.00005", "--tool-table", str(tools),
                        "--var-units", "inch")  # fmt: skip
    lines = out.read_text().splitlines()
    entry = lines.index("G41 D3") + 1
    assert lines[entry].startswith("G3 X0.0") and lines[entry + 1].startswith("G1 ")
    assert max(deviation(*(feed_moves(p, tools, home=tmp_path) for p in (tmp_path / "entry.ngc", out)),
                         closed_form)) <= 0.0005  # fmt: skip


def test_without_the_radius_the_points_are_corrected_where_they_are_and_the_warning_says_so(tmp_path):
    """G41 D1 with no tool table: each programmed point gets the command that lands it, in closed
    form C = (I + A)⁻¹ P for AFFINE's linear error A."""
    text = OUTSIDE.replace("G41.1 D10", "G41 D1")
    _, out, proc = written(tmp_path, text, "unknown.ngc")
    assert (
        "unknown.ngc:5:1: warning: cutter compensation with the tool radius not known (G41/G42 and no tool table"
        in proc.stderr
    )
    assert "pass through uncompensated" not in proc.stderr
    inverse = np.linalg.inv(np.array([[1 + 1e-4, -1e-4], [0.0, 1 - 0.8e-4]]))
    lines = out.read_text().splitlines()
    contour = lines[lines.index("G41 D1") + 1 : lines.index("G40")]
    programmed = [(0, 0), (80, 0), (100, 20), (100, 60), (80, 80), (30, 80), (0, 50), (0, 0)]
    for line, point in zip(contour, programmed, strict=True):
        words = dict((w[0], float(w[1:])) for w in line.split() if w[0] in "XY")
        assert np.allclose([words["X"], words["Y"]], inverse @ point, atol=0.6e-4), (line, inverse @ point)


@pytest.mark.parametrize("after", ["G1 Y40", "G3 X100 Y20 R20"], ids=["line", "arc"])
def test_a_z_move_under_compensation_keeps_the_tool_centre_where_it_stands(tmp_path, after):
    """Z alone under G41: the control keeps the tool centre's X Y; a correction of X that varies with
    Z (squareness of Z to X) must not make it a move in the plane, which the control would offset
    along its own direction.  Nor may a step join it to the move after it: a line starts where it
    stands, an arc moves onto it."""
    machine = tmp_path / "leaning.toml"
    machine.write_text(AFFINE + "B0Z_urad = 200.0\n")
    program, out = tmp_path / "z.ngc", tmp_path / "z.out.ngc"
    program.write_text(HEAD + f"G0 X-20 Y-20 Z5\nG1 Z-1 F300\nG41.1 D10\nG1 X0 Y0\nG1 X80\nG1 Z-30\n{after}\n"
                       "G1 Y60\nG40\nG1 X120 Y80\nM2\n")  # fmt: skip
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(machine), str(program),
                           "-o", str(out)], capture_output=True, text=True, cwd=ROOT, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    lines = out.read_text().splitlines()
    k = lines.index("G41.1 D10")
    along, down, then = lines[k + 2], lines[k + 3], lines[k + 4]
    assert along.startswith("G1 X79.99")  # compensated
    assert down.startswith("G1 Z-30.0") and "X" not in down and "Y" not in down  # X Y as they stand
    assert then.startswith(after[:2]) and then != after


def test_with_reversal_errors_no_step_is_put_between_the_moves(tmp_path):
    """HR5B's tables have reversal errors: outside compensation ncpp puts a step where an axis
    reverses; under compensation a step would be a move the control offsets on its own, so none is."""
    machine = ROOT / "samples/machines/hr5b.toml"
    program, out = tmp_path / "hr.ngc", tmp_path / "hr.out.ngc"
    program.write_text(OUTSIDE)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(machine),
                           "--work-offset", "400,350,300", str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    lines, source = out.read_text().splitlines(), OUTSIDE.splitlines()
    mine = lines[lines.index("G41.1 D10") : lines.index("G40") + 2]
    theirs = source[source.index("G41.1 D10") : source.index("G40") + 2]
    assert len(mine) == len(theirs) and all(a != b for a, b in zip(mine[1:], theirs[1:]) if b != "G40")


MMOUNT = CORPUS / "iso_gcode" / "linuxcnc" / "mmount.ngc"
# G55-G57 (inches) placing the three stations apart on the machine, and the tools its comments list
MMOUNT_VAR = "5220 1\n5241 4\n5242 3\n5243 -2\n5261 10\n5262 3\n5263 -2\n5281 16\n5282 3\n5283 -2\n"
MMOUNT_TOOLS = "".join(
    f"T{n} P{n} Z{z} D{d}\n"
    for n, z, d in [(1, 1.1901, 0.25), (2, 0.2875, 0.209), (3, 0.0, 0.1406), (4, 1.663, 0.25), (5, 1.5042, 0.5),
                    (15, 1.5042, 0.55), (6, 0.1833, 0.25)]
)  # fmt: skip


@needs_oracles
@pytest.mark.skipif(not MMOUNT.exists(), reason="corpus not available")
def test_mmount_contours_land_within_the_tolerance(tmp_path):
    """The motor mount's four contours under G41 (two slots with the 1/4 end mill, the outline with
    D15 and D5): their tool centre within the 1 µm tolerance of the original's on the machine, from
    30-50 µm uncompensated.  (The helical holes of its subroutine o100 run under G41 too: a
    subroutine's moves are left as programmed.)"""
    var, tools = tmp_path / "mmount.var", tmp_path / "mmount.tbl"
    var.write_text(MMOUNT_VAR)
    tools.write_text(MMOUNT_TOOLS)
    original, out, _ = written(tmp_path, MMOUNT.read_text(), "mmount.ngc", "--var-file", str(var),
                               "--tool-table", str(tools), "--var-units", "inch")  # fmt: skip
    before, after = (feed_moves(p, tools, var, home=tmp_path) for p in (original, out))
    contours = (1, 2, 15, 16)  # the G41 sections in the order rs274 runs them (3-14: in o100)
    for section in contours:
        mine = [m for m in after if m.comp == section]
        theirs = [m for m in before if m.comp == section]
        assert deviation(before, theirs, closed_form).max() > 0.03
        assert deviation(before, mine, closed_form).max() < 0.001, section
    pathcheck(original, out, "--tool-table", str(tools), "--var-file", str(var))


# X's positioning differs by travel direction by 4 µm (a reversal table) and has a screw-lead error
REVERSING = """[machine]
chain = "YXFZ"
[offsets]
tool = [0.0, 0.0, -90.0]
[errors.EXX]
kind = "table"
positions = [-300.0, -10.0, 0.0, 10.0, 300.0]
values_um = [-25.0, 1.0, 0.0, 2.0, 30.0]
values_um_minus = [-29.0, -3.0, -4.0, -2.0, 26.0]
[[effects]]
kind = "cyclic"
axis = "X"
um = 1.5
period_mm = 5.0
"""
# a helical slot under G41 (inches; arcs with Z, replaced by pieces that settle onto one another), then Z alone
HELICAL_SLOT = (
    "G17 G20 G40 G90\nG0 X-0.1806 Y-11.4324 Z0.25\nG41.1 D0.04\nG1 X-0.1806 Y-11.1824 F10\n"
    + "G3 X0.3449 Y-10.6567 I-1.7574 J2.2824 Z0.025\nG3 X0.1221 Y-10.4853 I-0.1114 J0.0857 Z0.0\n"
    + "G2 X-0.3521 Y-10.9596 I-2.0601 J1.5853 Z-0.125\nG3 X-0.1806 Y-11.1824 I0.0858 J-0.1114\n"
    + "G3 X0.3449 Y-10.6567 I-1.7574 J2.2824\nG3 X0.1221 Y-10.4853 I-0.1114 J0.0857\n"
    + "G2 X-0.3521 Y-10.9596 I-2.0601 J1.5853\nG0 Z0.25\nG40\nG0 X-0.1806 Y-11.4324\nM2\n"
)
# a loop under G41 left as programmed, then Z alone
LOOP = HEAD + (
    "G0 X-10 Y-20 Z5\nG41.1 D2\nG1 X0 Y-10 F300\nG1 Z-1\n#1 = 0\no100 while [#1 LT 2]\nG1 X50\nG1 X0\n"
    "#1 = [#1 + 1]\no100 endwhile\nG0 Z5\nG1 Y40\nG40\nG0 X-20 Y-20\nM2\n"
)


@needs_oracles
@pytest.mark.parametrize("text", [HELICAL_SLOT, LOOP], ids=["after-arc-pieces", "after-a-loop"])
def test_a_move_along_z_alone_under_compensation_makes_no_move_in_the_plane(tmp_path, text):
    """Z alone under G41 after arc pieces that settle onto their predecessor (reversal errors), and
    after a loop left as programmed: a µm of X or Y written there would be a move the control offsets
    along its own direction, swinging the tool centre round by the radius (rs274 then refuses a
    gouge at the G40, or runs the tool a radius off the path)."""
    (tmp_path / "reversing.toml").write_text(REVERSING)
    program, out = tmp_path / "z.ngc", tmp_path / "z.out.ngc"
    program.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "reversing.toml"),
                           str(program), "-o", str(out)], capture_output=True, text=True, cwd=ROOT, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    lines = out.read_text().splitlines()
    lines = lines[next(k for k, line in enumerate(lines) if line.startswith("G41.1")) :]
    z_alone = [line for line in lines if line.startswith("G0 Z")]
    assert z_alone and all("X" not in line and "Y" not in line for line in z_alone), z_alone
    pathcheck(program, out, "--tol-mm", "0.02")
