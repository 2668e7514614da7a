"""Cutter compensation under a rotation of the coordinate system: LinuxCNC's G10 L2 R and Fanuc's and
Haas's G68, with G41/G42 (G41.1/G42.1) in the XY plane.  A rotation is an isometry: the tool-centre path of
a turned contour is the turned tool-centre path of the contour, and the controls offset after they turn
(Fanuc Series 16/18-MC operator's manual B-62764EN/01, "Coordinate system rotation": "Tool offset, such as
cutter compensation, tool length offset, or tool offset, is performed after the coordinate system is
rotated for the command program"; Fanuc Series 15i-MA B-63324EN/03, "Tool compensation": likewise).  The
order followed is the one the Haas training manual gives ("Advanced Haas Mill Programming Techniques",
G68: "the G41 or G42 commands should be turned on after the G68 rotation is called up and turned off
with G40 before the G68 is cancelled with a G69"); a rotation turned on or off while compensation is on
stays out of scope.

Judged by what is not ncpp: rs274 (which turns and offsets itself) and pathcheck at a tolerance of twice
the largest correction plus 0.01 mm for LinuxCNC; for Fanuc and Haas, the test's own offset of the turned
contour (`offset`: lines square to their direction, arcs' radii grown or shrunk, inside corners cut where
the offset lines cross) run on the closed-form machine read from the machine file without ncpp
(`ClosedMachine`)."""

from __future__ import annotations

import io
import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest

import ncpp.program.dialects.iso
from ncpp.cli import main
from ncpp.errors import Warnings
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests import rs274
from tests.compensation.closed_machine import ClosedMachine
from tests.compensation.test_cutter_comp_accuracy import AFFINE, closed_form
from tests.compensation.test_dialect_cutter_comp import OUTLINE, _centre, compensated, machine, offset
from tests.compensation.test_rotation import as_linuxcnc, fanuc_written, turned_twice
from tests.compensation.tool_centre import deviation, feed_moves
from tests.conftest import ROOT

# ---- LinuxCNC: G10 L2 R, judged by rs274 and pathcheck ---------------------------------------------

# G54 turned by 30 degrees, an outside contour on the left (G41.1 D10: lines, a convex and an I J arc, a
# chamfer corner), then G55 turned by -52.5 degrees, a pocket on the right with tool 3's radius (G42)
LINUXCNC = (
    "G21 G90 G17 G94 G64\nG10 L2 P1 X150 Y-60 Z0 R30\nG10 L2 P2 X-80 Y120 Z0 R-52.5\n"
    "G54\nG0 X-20 Y-20 Z5\nG1 Z-1 F300\nG41.1 D10\nG1 X0 Y0\nG1 X80 Y0\nG3 X100 Y20 R20\nG1 X100 Y60\n"
    "G3 X80 Y80 I-20 J0\nG1 X30 Y80\nG1 X0 Y50\nG1 X0 Y0\nG40\nG1 X-20 Y-20\nG0 Z5\n"
    "G55\nT3 M6\nG0 X50 Y40\nG1 Z-2 F200\nG42 D3\nG1 X50 Y10\nG1 X90 Y10\nG3 X110 Y30 I0 J20\n"
    "G1 X110 Y70\nG3 X90 Y90 I-20 J0\nG1 X30 Y90\nG3 X10 Y70 R20\nG1 X10 Y30\nG3 X30 Y10 I20 J0\n"
    "G1 X50 Y10\nG40\nG1 X50 Y40\nG0 Z5\nM2\n"
)
TOOLS = "T3 P3 Z0 D0.3 ;tool 3: 7.62 mm\n"  # (inches: the stand-alone rs274 reads its table so)


def test_g41_under_g10_l2_r_passes_pathcheck_at_twice_the_largest_correction(tmp_path):
    """rs274 turns and offsets both programs itself: the rewritten program's tool-centre path stays
    within twice the largest correction (plus 0.01 mm) of the original's, every move under
    compensation compensated (nothing left as programmed)."""
    (tmp_path / "affine.toml").write_text(AFFINE)
    tools, program, out, report = (tmp_path / name for name in ("t.tbl", "turned.ngc", "out.ngc", "r.json"))
    tools.write_text(TOOLS)
    program.write_text(LINUXCNC)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "affine.toml"),
                           "--tolerance", "0.0001", "--tool-table", str(tools), "--var-units", "inch",
                           "--report", str(report), str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300, stdin=subprocess.DEVNULL)  # fmt: skip
    assert proc.returncode == 0 and "warning" not in proc.stderr, proc.stderr
    assert "left as programmed: nothing" in proc.stderr, proc.stderr
    largest = json.loads(report.read_text())["largest_correction_um"] / 1000.0
    before, after = (feed_moves(p, tools, home=tmp_path) for p in (program, out))
    assert sum(m.comp > 0 for m in before) >= 20
    assert deviation(before, before, closed_form).max() > 0.010
    missed = deviation(before, after, closed_form)  # (per rewritten move)
    exits = _exit_corners(after)
    assert len(exits) == 4 and np.delete(missed, exits).max() <= 0.0005
    assert missed[exits].max() <= 0.001
    rs274.pathcheck(program, out, "--tool-table", str(tools), "--tol-mm", f"{2 * largest + 0.01:.4f}")


@pytest.mark.parametrize("wrong", [lambda segment: segment, turned_twice], ids=["unturned", "turned-twice"])
def test_the_verifier_refuses_a_writer_that_gets_the_rotation_wrong_under_compensation(
    tmp_path, monkeypatch, capsys, wrong
):
    """A writer that writes the turned frame's points under compensation (and only there) as the
    program's words, or turns them the wrong way, is caught by the verifier: nothing is written."""
    right = ncpp.program.dialects.iso.as_written
    monkeypatch.setattr(ncpp.program.dialects.iso, "as_written",
                        lambda segment: (right if segment.centre_shift is None else wrong)(segment))  # fmt: skip
    (tmp_path / "affine.toml").write_text(AFFINE)
    program, out = tmp_path / "turned.ngc", tmp_path / "turned.out.ngc"
    program.write_text(LINUXCNC.split("G55\n")[0] + "M2\n")
    assert main(["compensate", "--machine", str(tmp_path / "affine.toml"), str(program), "-o", str(out)]) != 0
    err = capsys.readouterr().err
    assert "turned.ngc:" in err and "verification" in err, err
    assert not out.exists()


def _exit_corners(moves: list) -> list[int]:
    """The exit move of each compensated section (the last move of its number) and the move before it.
    Where the two meet the control offsets the rewritten line square to its own direction, which the
    machine's errors have turned (here by up to 0.15 mrad: 0.75 µm at a radius of 5 mm); ncpp puts the
    corners between two lines under compensation where their corrected contours cross, not this one,
    with or without a rotation."""
    last = [k for k, m in enumerate(moves) if m.comp and (k + 1 == len(moves) or moves[k + 1].comp != m.comp)]
    return sorted({j for k in last for j in (k - 1, k)})


# ---- Fanuc and Haas: G68, judged by the test's own offset on the closed-form machine ----------------

CENTRE, ANGLE, RADIUS = (30.0, 20.0), 25.0, 5.0
# a rounded rectangle with a chamfered corner, the tool on the left (outside it): R and I J arcs, a G91
# edge; the radius set by G10 L12 (Fanuc: D1's geometry, a radius), G68 before G41 and G69 after G40
FANUC = """%
O1000
G21 G90 G17 G94
G10 L12 P1 R5.
G54
G0 X-20. Y-20. Z5.
G68 X30. Y20. R25.
G0 X-20. Y0
G1 Z-1. F300.
G41 D1 G1 X0 Y0
G1 X80.
G3 X100. Y20. R20.
G91 G1 Y40.
G90 G3 X80. Y80. I-20. J0
G1 X30.
G1 X0 Y50.
G1 Y0
G40 G1 X0 Y-30.
G0 Z5.
G69
G0 X-20. Y-20.
M30
%
"""
# the contour as drawn (program coordinates, before G68 turns it): (end, arc centre or None, turn)
# (the outline of the dialects' cutter compensation tests, leaving along its last edge)
CONTOUR = [*OUTLINE[:-1], ((0, -30), None, 0)]
_WORD = re.compile(r"([XYZIJR])\s*(-?\d*\.?\d*)")


def turned(point, centre=CENTRE, angle: float = ANGLE) -> tuple[float, float]:
    """A program point as G68 turns it: about the centre by the angle, counter-clockwise."""
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    dx, dy = point[0] - centre[0], point[1] - centre[1]
    return centre[0] + c * dx - s * dy, centre[1] + s * dx + c * dy


def fanuc_contour(text: str) -> tuple[list, tuple]:
    """The moves of a Fanuc program's section from its G41/G42 block to its G40 block (its exit move
    last), turned as the control turns them under G68 (an absolute point about the centre, a G91
    increment turned and added), and the point the section starts from: the test's own reading (of
    programs whose first move after G68 gives X and Y, which the control then puts where they say)."""
    at = np.zeros(3)  # the program point where the tool stands (unturned)
    rotation, contour, start, on, motion, absolute = None, [], None, False, 0, True
    for line in text.splitlines():
        code = line.split("(")[0].upper()
        found = re.search(r"G68\s*X(-?[\d.]+)\s*Y(-?[\d.]+)\s*R(-?[\d.]+)", code)
        if found:
            x, y, angle = map(float, found.groups())
            rotation = ((x, y), angle)
            continue
        codes = [float(g) for g in re.findall(r"G(\d+\.?\d*)", code)]
        if 69.0 in codes or 10.0 in codes or not code.strip() or code[0] in "%OI(":
            rotation = None if 69.0 in codes else rotation
            continue
        motion = next((int(g) for g in reversed(codes) if g in (0.0, 1.0, 2.0, 3.0)), motion)
        absolute = next((g == 90.0 for g in reversed(codes) if g in (90.0, 91.0)), absolute)
        words = {letter: float(value) for letter, value in _WORD.findall(code)}
        end = at.copy()
        for k, axis in enumerate("XYZ"):
            if axis in words:
                end[k] = words[axis] if absolute else at[k] + words[axis]
        on = on or 41.0 in codes or 42.0 in codes
        if on and (end != at).any():
            start = _under(at, rotation) if start is None else start
            if motion in (0, 1):
                contour.append((_under(end, rotation), None, 0))
            else:
                centre = (
                    _centre(at[:2], end[:2], words["R"], motion == 2) if "R" in words
                    else (at[0] + words.get("I", 0.0), at[1] + words.get("J", 0.0))
                )  # fmt: skip
                contour.append((_under(end, rotation), _under(centre, rotation), 1 if motion == 3 else -1))
        at = end
        if on and 40.0 in codes:
            break
    assert start is not None
    return contour, start


def _under(point, rotation) -> tuple[float, float]:
    """A program point's X Y as the control puts it under `rotation` ((centre, angle); None: none)."""
    return (float(point[0]), float(point[1])) if rotation is None else turned(point, *rotation)


def _drawn(contour: list) -> list:
    """The contour as G68 turns it."""
    return [(turned(end), None if centre is None else turned(centre), turn) for end, centre, turn in contour]


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_g41_under_g68_puts_the_tool_centre_on_the_turned_offset_contour_within_half_a_micron(
    tmp_path, dialect
):
    """The tool centre of the rewritten program (its contour read and offset by the test), run on the
    closed-form machine, is within 0.5 µm of the offset of the turned contour all along, where the
    original's misses it by more than 10 µm; the whole program is compensated.  (The exit leaves along
    the last edge: the corner before an exit that turns away is `_exit_corners`' limit.)  (Haas reads a D offset
    G10 L12 sets as a diameter or a radius by a setting: its radius is told in the tool table.)"""
    options, text = ("--dialect", dialect), FANUC
    if dialect == "haas":
        (tmp_path / "tools.tbl").write_text("T1 P1 Z0 D10.0\n")
        options += ("--tool-table", str(tmp_path / "tools.tbl"), "--var-units", "mm")
        text = FANUC.replace("G10 L12 P1 R5.\n", "")
    (tmp_path / "affine.toml").write_text(AFFINE)
    reached = ClosedMachine.read(tmp_path / "affine.toml").reached
    on = lambda command: machine(command, 17, reached)  # noqa: E731
    start = turned((-20.0, 0.0))
    wanted = offset(_drawn(CONTOUR), RADIUS, start, transitions=True, depth=-1.0)
    assert deviation(wanted, wanted, on).max() > 0.010
    written, messages = compensated(tmp_path, "turned.nc", text, *options)
    assert "left as programmed: nothing" in messages and "warning" not in messages, messages
    moves, begun = fanuc_contour(written)
    assert np.allclose(begun, start, atol=0.1) and len(moves) == len(CONTOUR)
    made = offset(moves, RADIUS, begun, depth=-1.0)
    assert deviation(wanted, made, on).max() <= 0.0005


def test_g41_under_g68_lands_on_the_original_in_rs274_written_as_linuxcncs_g10_l2_r(tmp_path):
    """rs274 runs both programs turned into LinuxCNC's (`as_linuxcnc`: each G68 a G55 turned by G10 L2 R,
    G41 D1 its G41.1 of the diameter G10 L12 gives): along every feed move the rewritten program's tool
    centre, run on the machine, is within 0.5 µm of the original's; pathcheck accepts it."""
    program, out = fanuc_written(tmp_path, "fanuc", FANUC)
    linuxcnc = [tmp_path / "turned.ngc", tmp_path / "turned.out.ngc"]
    for fanuc, ngc in zip((program, out), linuxcnc):
        text = fanuc.read_text().replace("G10 L12 P1 R5.\n", "").replace("G41 D1", f"G41.1 D{2 * RADIUS:g}")
        ngc.write_text(as_linuxcnc(text))
    before, after = (feed_moves(p, home=tmp_path) for p in linuxcnc)
    assert sum(m.comp > 0 for m in before) >= 8
    assert deviation(before, before, closed_form).max() > 0.010
    assert deviation(before, after, closed_form).max() <= 0.0005
    rs274.pathcheck(*linuxcnc)


# ---- what stays out of scope -------------------------------------------------------------------------


def interpreted(text: str, dialect: str) -> tuple[list, str]:
    """The events of a program as the dialect's interpreter reads it, and its warnings' text."""
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(text.encode()), "t.ngc", dialect)
    said = io.StringIO()
    return list(interpret(blocks, file="t.ngc", warnings=Warnings(stream=said))), said.getvalue()


@pytest.mark.parametrize(
    "dialect, body, at, construct",
    [
        ("fanuc", "G42 D1 G1 X5 Y5 F100\nG68 X0 Y0 R30", "G68", "G68 under cutter compensation"),
        ("haas", "G41 D1 G1 X5 Y5 F100\nG40\nG68 X0 Y0 R30", "G68", "G68 under cutter compensation"),
        ("fanuc", "G68 X0 Y0 R30\nG41 D1 G1 X5 Y5 F100\nX9\nG69", "G69", "G69 under cutter compensation"),
        ("haas", "G68 X0 Y0 R30\nG41 D1 G1 X5 Y5 F100\nX9\nG40\nG69", "G69", "G69 under cutter compensation"),
        ("iso", "G41.1 D2 G1 X5 Y5 F100\nX9\nG40\nG10 L2 P1 R30", "G10",
         "a rotation of the coordinate system before the move that ends cutter compensation"),
        ("iso", "G10 L2 P2 R30\nG41.1 D2 G1 X5 Y5 F100\nX9\nG40\nG55", "G55",
         "a rotation of the coordinate system before the move that ends cutter compensation"),
        ("iso", "G10 L2 P1 R30\nG18\nG41.1 D2 G1 X5 Z5 F100", "G41.1", "cutter compensation G41.1 in G18 under"),
    ],
)  # fmt: skip
def test_a_rotation_changed_under_compensation_stays_out_of_scope_at_its_word(dialect, body, at, construct):
    """A G68 or G69 while compensation is on, or after a G40 before the move that ends it (the tool centre
    still off the path), and a rotation of LinuxCNC's changed there: each ends interpretation with one
    warning at its word; so does compensation in G18 under a rotation about Z."""
    text = f"G21 G90 G17\nG10 L12 P1 R2.\nG0 X1 Y1 Z5\n{body}\nG0 X5 Y5\nM30\n"
    if dialect == "iso":
        text = text.replace("G10 L12 P1 R2.\n", "")
    _, warning = interpreted(text, dialect)
    lines = text.splitlines()
    line = max(n for n, code in enumerate(lines, 1) if at in code.split())
    assert warning.count("warning") == 1, warning
    assert f"t.ngc:{line}:{lines[line - 1].index(at) + 1}: " in warning and construct in warning, warning
