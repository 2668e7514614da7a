"""Fanuc's and Haas's coordinate system rotation G68 in the ZX plane (G18: `G68 X_ Z_ R_`) and the YZ
plane (G19: `G68 Y_ Z_ R_`), compensated.  The control turns the program's coordinates in the selected
plane about the centre its two axis words give, by R degrees counter-clockwise (Fanuc Series 0i
connection manual (function) B-64113EN-1, 11.12 "Coordinate system rotation"; Haas Mill Operator's
Manual 96-8000, "G68 Rotation"), counter-clockwise as the plane's arcs turn there: seen from the
positive end of the axis normal to it, Z toward X in G18, Y toward Z in G19 (Haas Mill Operator's
Manual, "G17 XY / G18 XZ / G19 YZ Plane Selection": G18's circular motion seen "from the rear of the
machine toward the front control panel").  Judged without ncpp's interpreter: the test's own reading of
a program (`worked_out`: each point turned by hand as the manual says) gives where its moves end and the
same program with the rotation worked out, which LinuxCNC's rs274 (no G68 there) runs; on a machine
whose errors are linear in X, Y and Z (`closed_form`) the rewritten program must land on the programmed
points, and along its whole path on the original's, within 0.5 µm, where the program as written misses
them by more than 10 µm."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from tests import rs274
from tests.compensation.test_rotation import (
    code_words,
    fanuc_written,
    interpreted,
    refused_as_written_by,
    turned_twice,
)
from tests.compensation.tool_centre import deviation, feed_moves
from tests.writeback.conftest import linear_errors, linearly_reached, machine_file, misses

# error along the first axis from travel of the second, µm per mm (`linear_errors`)
SLOPES = {"EXX": 0.2, "EYY": -0.08, "EZZ": -0.15, "EZX": 0.25, "EXZ": -0.1, "EYZ": 0.12, "EZY": -0.2}
MACHINE = machine_file("affine-xyz", linear_errors(**SLOPES))
ZERO = (120.0, -40.0, 25.0)  # G54's, told with --work-offset


def closed_form(command: np.ndarray) -> np.ndarray:
    """Where MACHINE puts the tool for commands (n,3), machine mm: each axis off by the slopes times
    the positions of the axes that carry it."""
    return linearly_reached(command, **SLOPES)


# In G18: a contour turned about (X30, Z-5) by 25 degrees (lines, an R and an I K arc, a G91 move), then
# one about (X-10, Z10) by -40 degrees whose first move is G91 (from where the tool stands at G68)
G18_PROGRAM = (
    "%\nO1000\nG21 G90 G17 G94\nG54\nG0 X-10 Y5 Z10\nG18\nG68 X30 Z-5 R25\nG0 X0 Z0\nG1 Y-1 F300\n"
    "G1 X80 Z0\nG3 X100 Z20 R20\nG91 G1 Z40\nG90 G2 X60 Z60 I-20 K0\nG1 X0 Z0\nG0 Y5\nG69\nG0 X-10 Z10\n"
    "G68 X-10 Z10 R-40\nG91 G1 X20 Z5 F200\nG1 Y-7\nG90 G1 X40 Z-30\nG3 X60 Z-10 I0 K20\nG0 Y5\nG69\n"
    "G90 G0 X0 Z0\nG17\nM30\n%\n"
)
# The same in G19, X and Y (and I and J) swapped
G19_PROGRAM = G18_PROGRAM.translate(str.maketrans("XYIJ", "YXJI")).replace("G18", "G19")
PROGRAMS = {18: G18_PROGRAM, 19: G19_PROGRAM}
PLANES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}  # first, second and normal axis (rs274's order)


def turning(angle: float) -> np.ndarray:
    """The 2x2 matrix turning by `angle` degrees from a plane's first axis toward its second."""
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    return np.array([[c, -s], [s, c]])


class Rotation:
    """G68's turn: `matrix` about `centre` in the plane's first and second axes (`PLANES`)."""

    def __init__(self, plane: int, angle: float, centre: tuple[float, float]) -> None:
        self.axes, self.matrix, self.centre = list(PLANES[plane][:2]), turning(angle), np.array(centre)

    def point(self, p: np.ndarray, back: bool = False) -> np.ndarray:
        """Program point -> where the control puts it (work coordinates); `back`: the other way."""
        q = p.copy()
        matrix = self.matrix.T if back else self.matrix
        q[self.axes] = matrix @ (p[self.axes] - self.centre) + self.centre
        return q

    def step(self, v: np.ndarray) -> np.ndarray:
        q = v.copy()
        q[self.axes] = self.matrix @ v[self.axes]
        return q


def worked_out(text: str) -> tuple[np.ndarray, str]:
    """A Fanuc program in this test's words read as the manual says: the machine point (mm) each of its
    moves ends at, and the program as LinuxCNC runs it with the rotation worked out by hand (every move
    absolute, to the turned point; an arc's end turned with its R, or its centre turned and given as I J
    K from its start).  Under G68 an absolute point is turned about the centre, an increment (G91) is
    turned and added to where the tool stands; G69 ends it; the tool stays where it is at both."""
    here, zero = np.zeros(3), np.array(ZERO)
    plane, absolute, motion, rotation = 17, True, 0, None
    ends = []
    lines = [f"G10 L2 P1 X{ZERO[0]:g} Y{ZERO[1]:g} Z{ZERO[2]:g}", "G21 G94 G54"]
    for codes, given in code_words(text):
        plane = next((int(g) for g in codes if g in (17, 18, 19)), plane)
        if 68 in codes:
            first, second = ("XYZ"[i] for i in PLANES[plane][:2])
            rotation = Rotation(plane, given["R"], (given[first], given[second]))
            continue
        if 69 in codes:
            rotation = None
            continue
        absolute = {90: True, 91: False}.get(next((int(g) for g in codes if g in (90, 91)), -1), absolute)
        motion = next((int(g) for g in codes if g in (0, 1, 2, 3)), motion)
        axes = {"XYZ".index(letter): value for letter, value in given.items() if letter in "XYZ"}
        if not axes:
            lines.append(
                f"G{plane}" if any(g in (17, 18, 19) for g in codes) else "M2" if "M" in given else ""
            )
            continue
        turn = rotation or Rotation(plane, 0.0, (0.0, 0.0))
        start = here
        if absolute:
            point = turn.point(here, back=True)
            for i, value in axes.items():
                point[i] = value
            here = turn.point(point)
        else:
            here = here + turn.step(np.array([axes.get(i, 0.0) for i in range(3)]))
        ends.append(zero + here)
        move = f"G90 G{plane} G{motion} " + " ".join(f"{'XYZ'[i]}{v:.9f}" for i, v in enumerate(here))
        if motion in (2, 3) and "R" in given:
            move += f" R{given['R']:g}"
        elif motion in (2, 3):
            centre = turn.point(turn.point(start, back=True) + [given.get(letter, 0.0) for letter in "IJK"])
            move += " " + " ".join(f"{'IJK'[i]}{centre[i] - start[i]:.9f}" for i in PLANES[plane][:2])
        lines.append(move + (f" F{given['F']:g}" if "F" in given else ""))
    return np.array(ends), "\n".join(line for line in lines if line) + "\n"


def compensated(tmp_path: Path, text: str, dialect: str = "fanuc") -> tuple[Path, Path]:
    """The program and ncpp's compensation of it for MACHINE, G54 at ZERO (verified as it is written),
    with no warning."""
    return fanuc_written(tmp_path, dialect, text, MACHINE, ZERO, quiet=True)


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
@pytest.mark.parametrize("plane", [18, 19])
def test_the_programmed_points_are_reached_under_g68_in_g18_and_g19_within_half_a_micron(
    tmp_path, plane, dialect
):
    """Every programmed end point, turned in the plane about G68's centre as the manual says, is reached
    within 0.5 µm by the rewritten program on the machine; the program as written misses them by more
    than 10 µm."""
    _, out = compensated(tmp_path, PROGRAMS[plane], dialect)
    wanted, _ = worked_out(PROGRAMS[plane])
    assert len(wanted) == 16
    assert misses(closed_form(wanted), wanted.tolist()).max() > 0.010
    reached, _ = worked_out(out.read_text())
    assert misses(closed_form(reached), wanted.tolist()).max() < 0.0005


@pytest.mark.parametrize("plane", [18, 19])
def test_the_whole_path_under_g68_in_g18_and_g19_lands_on_the_original_in_rs274(tmp_path, plane):
    """rs274 runs both programs with the rotation worked out by hand (`worked_out`): along every feed
    move, arcs included, the rewritten program's path run on the machine is within 0.5 µm of the
    original's; pathcheck accepts it."""
    program, out = compensated(tmp_path, PROGRAMS[plane])
    linuxcnc = [tmp_path / "turned.ngc", tmp_path / "turned.out.ngc"]
    for fanuc, ngc in zip((program, out), linuxcnc):
        ngc.write_text(worked_out(fanuc.read_text())[1])
    before, after = (feed_moves(p, home=tmp_path) for p in linuxcnc)
    assert sum(m.centre is not None for m in before) == 3
    # (the test's reading and rs274's of the program worked out agree on where its feed moves end)
    wanted, _ = worked_out(PROGRAMS[plane])
    assert misses(wanted, [tuple(m.end) for m in before]).max() < 1e-6
    assert deviation(before, before, closed_form).max() > 0.010
    assert deviation(before, after, closed_form).max() < 0.0005
    rs274.pathcheck(*linuxcnc)


@pytest.mark.parametrize(
    "plane, g68, move, lands",
    [
        (18, "G68 X0 Z0 R90", "G1 X0 Z10", (10.0, 0.0, 0.0)),  # Z turned toward X
        (18, "G68 X0 Z0 R90", "G1 X10 Z0", (0.0, 0.0, -10.0)),
        (19, "G68 Y0 Z0 R90", "G1 Y10 Z0", (0.0, 0.0, 10.0)),  # Y turned toward Z
        (19, "G68 Y5 Z0 R-90", "G1 Y5 Z10", (0.0, 15.0, 0.0)),
        (17, "G68 X0 Y0 R90", "G1 X10 Y0", (0.0, 10.0, 0.0)),  # X turned toward Y
    ],
)
def test_a_positive_r_turns_the_planes_first_axis_toward_its_second(plane, g68, move, lands):
    """G68's counter-clockwise in each plane, as its arcs' G03 turns: G17 X toward Y, G18 Z toward X,
    G19 Y toward Z (seen from the positive end of the normal axis)."""
    text = f"G21 G90 G17\nG0 X0 Y0 Z0\nG{plane}\n{g68}\n{move} F100\nM30\n"
    events, said = interpreted(text, "fanuc")
    assert not said, said
    assert np.allclose(events[4].end, lands, atol=1e-9), events[4].end


@pytest.mark.parametrize("wrong", [lambda segment: segment, turned_twice], ids=["unturned", "turned-twice"])
def test_the_verifier_refuses_a_writer_that_gets_a_g18_rotation_wrong(tmp_path, monkeypatch, capsys, wrong):
    """A writer that writes the turned frame's points as the program's words, or turns them the wrong
    way, is caught by the verifier: nothing is written."""
    refused_as_written_by(wrong, tmp_path, monkeypatch, capsys, G18_PROGRAM, MACHINE, ZERO)


def test_the_first_move_ncpp_rewrites_after_a_g18_rotation_gives_both_of_its_axes(tmp_path):
    """After G68 the control places Z and X once a move gives both absolutely (`_settle_rotation`): a move
    along Y first, whose correction moves Z and X too, is written with both, as is the move after G69."""
    text = G18_PROGRAM.replace("G68 X30 Z-5 R25\n", "G68 X30 Z-5 R25\nG0 Y2\n")
    _, out = compensated(tmp_path, text)
    lines = out.read_text().splitlines()
    after = [lines[n + 1] for n, line in enumerate(lines) if line.startswith(("G68", "G69"))]
    assert after[0].startswith("G0 Y"), after
    assert all({"X", "Z"} <= set(re.findall(r"[XYZ]", line)) for line in after), after
    reached, _ = worked_out(out.read_text())
    wanted, _ = worked_out(text)
    assert misses(closed_form(reached), wanted.tolist()).max() < 0.0005


def test_the_returns_posts_write_after_a_g18_rotation_are_followed():
    """`G91 G28 Z0.` then `G28 X0. Y0.` after G69 (a Fanuc post's ending) home Z, then X and Y, from
    where the tool stands: with both axes of the rotation's plane homed, the absolute move after them is
    read, with no warning; without them, an absolute move of X alone is not followed."""
    text = (
        "G21 G90 G17\nG0 X1 Y1 Z5\nG18\nG68 X0 Z0 R30\nG1 X5 Z5 F100\nG69\nG91 G28 Z0.\nG28 X0. Y0.\n"
        "G90 G0 X7\nM30\n"
    )
    events, warning = interpreted(text, "fanuc")
    assert not warning, warning
    assert [e.block.line for e in events if type(e).__name__ == "Line"][-1] == 9
    _, warning = interpreted(text.replace("G91 G28 Z0.\nG28 X0. Y0.\n", ""), "fanuc")
    assert "t.ngc:7:8: " in warning and "an absolute move of Z or X alone after G69" in warning, warning
