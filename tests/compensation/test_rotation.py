"""Programs under LinuxCNC's G10 L2 R (the rotation of a coordinate system about Z: LinuxCNC G-code
manual, G10 L2), compensated.  The control turns the program's X Y (plus G92) about Z by the system's
R and then adds its zero (rs274ngc's canon), so a compensated point must be written back turned the
other way.  Judged without ncpp's interpreter: the test's own reading of the written program's end
points, turned and placed by hand (`placed`) and run on a machine whose errors are linear in
position (`closed_form`), must land on the programmed points within 0.5 µm, where the program as
written misses them by more than 10 µm; rs274 (LinuxCNC's interpreter) reads the whole path of both
programs (`tool_centre.feed_moves`, SET_XY_ROTATION applied by hand) and pathcheck accepts the
rewritten one.  What ncpp does not follow under a rotation stays out of scope, at its word."""

from __future__ import annotations

import dataclasses
import io
import math
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import ncpp.program.dialects.iso
from ncpp.cli import main
from ncpp.errors import Warnings
from ncpp.motion.canon import canon_call, read_canon
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests import rs274
from tests.compensation.test_cutter_comp_accuracy import AFFINE, closed_form
from tests.compensation.tool_centre import deviation, feed_moves
from tests.conftest import ROOT
from tests.writeback.conftest import misses

# system (G code) -> its zero (machine mm) and rotation (degrees), as the program's G10 L2 sets them
SYSTEMS = {54: ((150.0, -60.0, 0.0), 30.0), 55: ((-80.0, 120.0, 0.0), -52.5)}
SETUP = "".join(
    f"G10 L2 P{code - 53} X{x:g} Y{y:g} Z{z:g} R{angle:g}\n" for code, ((x, y, z), angle) in SYSTEMS.items()
)
# lines, arcs (R and I J, both turns), G91 increments, a G53 retract, two systems turned either way
PROGRAM = (
    "G21 G90 G17 G94 G64\n"
    + SETUP
    + (
        "G54\nG0 X-10 Y-10 Z5\nG1 Z-1 F300\nG1 X100 Y0\nG3 X120 Y20 R20\nG1 Y80\nG3 X80 Y120 I-40 J0\n"
        "G91 G1 X-50 Y-20\nG1 Y-40\nG90 G1 X0 Y0\nG0 Z5\n"
        "G55\nG0 X0 Y0\nG1 Z-2 F300\nG1 X60 Y30\nG2 X60 Y-30 R35\nG1 X0 Y0\nG0 Z5\nG53 G0 Z0\nG54\nM2\n"
    )
)
_WORD = re.compile(r"([XYZ])\s*(-?[\d.]+)")
_MOTION = re.compile(r"G0*[0-3](?!\d)")


def placed(point: list[float], system: int) -> list[float]:
    """Where the control puts a program point of `system` (no G92, no tool length): X Y turned about
    Z by the system's rotation, then its zero added."""
    (zx, zy, zz), angle = SYSTEMS[system]
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    x, y, z = point
    return [zx + c * x - s * y, zy + s * x + c * y, zz + z]


def end_points(text: str) -> np.ndarray:
    """The machine point (mm) each move of a program in this test's words ends at: its own reading
    of G90/G91, G54/G55 and the X Y Z words of G0-G3 blocks (G10 and G53 blocks are no such move)."""
    here, system, absolute, moving = [0.0, 0.0, 0.0], 54, True, False
    ends = []
    for line in text.splitlines():
        code = line.split("(")[0].upper()
        if not code.strip() or "G10" in code or "G53" in code:
            continue
        for number in re.findall(r"G(\d+)", code):
            system = int(number) if int(number) in SYSTEMS else system
            absolute = {90: True, 91: False}.get(int(number), absolute)
        moving = moving or bool(_MOTION.search(code))
        words = _WORD.findall(code)
        if not (moving and words):
            continue
        for axis, value in words:
            k = "XYZ".index(axis)
            here[k] = float(value) if absolute else here[k] + float(value)
        ends.append(placed(here, system))
    return np.array(ends)


def written(tmp_path: Path, text: str = PROGRAM) -> tuple[Path, Path, subprocess.CompletedProcess]:
    """The program and ncpp's compensation of it for AFFINE's machine (verified as it is written)."""
    (tmp_path / "affine.toml").write_text(AFFINE)
    program, out = tmp_path / "turned.ngc", tmp_path / "turned.out.ngc"
    program.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "affine.toml"),
                           "--tolerance", "0.0001", str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300, stdin=subprocess.DEVNULL)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "scope" not in proc.stderr, proc.stderr
    return program, out, proc


def test_the_programmed_points_are_reached_under_g10_l2_r_within_half_a_micron(tmp_path):
    """Every programmed end point, turned and placed as the control does, is reached within 0.5 µm
    by the rewritten program on the machine; the program as written misses them by more than 10 µm."""
    program, out, _ = written(tmp_path)
    wanted = end_points(PROGRAM)
    assert len(wanted) == 16
    assert misses(closed_form(wanted), wanted.tolist()).max() > 0.010
    assert misses(closed_form(end_points(out.read_text())), wanted.tolist()).max() < 0.0005


def test_the_whole_path_under_g10_l2_r_lands_on_the_original_in_rs274(tmp_path):
    """rs274 reads both programs (its SET_XY_ROTATION applied by hand): along every feed move, arcs
    included, the rewritten program's path run on the machine is within 0.5 µm of the original's;
    pathcheck accepts it."""
    program, out, _ = written(tmp_path)
    before, after = (feed_moves(p, home=tmp_path) for p in (program, out))
    assert sum(m.centre is not None for m in before) == 3
    assert deviation(before, before, closed_form).max() > 0.010
    assert deviation(before, after, closed_form).max() < 0.0005
    rs274.pathcheck(program, out)


# Offsets changed under a rotation (the system in effect set again, another selected, G52, G92.1),
# G91 after them, G53 moves, a G28 of Z, inch units: rs274 keeps the machine where it is
FRAMES = (
    "G21 G90 G17\nG10 L2 P1 X10 Y20 Z0 R30\nG54 G0 X0 Y0 Z5\nG1 X10 Y0 F100\nG2 X20 Y10 I5 J5\n"
    "G91 G1 X5 Y-3\nG90 G53 G0 X0 Y0\nG10 L2 P1 X5 R90\nG91 G0 X1\nG90 G0 X3 Y4\nG52 X1 Y2\nG0 X3 Y4\n"
    "G53 G1 X7\nG91 G1 X1 Y1\nG90 G28 Z0\nG92.1\nG10 L2 P2 X0 Y0 R-45\nG55 G0 X1 Y1\n"
    "G20 G91 G1 X0.5 Y0.25\nG21 G90\nG54 G0 X1 Y1\nG10 L2 P1 R0\nG91 G0 X0 Y0\nM2\n"
)


def interpreted(text: str, dialect: str = "iso") -> tuple[list, str]:
    """The events of a program as the dialect's interpreter reads it, and its warnings' text."""
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(text.encode()), "t.ngc", dialect)
    said = io.StringIO()
    return list(interpret(blocks, file="t.ngc", warnings=Warnings(stream=said))), said.getvalue()


def test_the_interpreter_follows_rs274_through_offsets_changed_under_a_rotation():
    """ncpp's moves (in the program's own coordinates, as rs274 prints them) agree with rs274's call
    by call within 1e-6 through every offset change under a rotation."""
    events, said = interpreted(FRAMES)
    mine = [call for call in map(canon_call, events) if call is not None]
    theirs = read_canon(rs274.canon(FRAMES, digits=7))
    assert not said, said
    assert [c.name for c in mine] == [c.name for c in theirs]
    for a, b in zip(mine, theirs):
        assert np.allclose(a.args, b.args, atol=1e-6), (a, b)


def test_a_parameter_files_rotation_is_followed_as_rs274_follows_it(tmp_path):
    """LinuxCNC's parameter file holds each system's rotation (#5230 for G54's, 20 on for the next): the
    program starts turned, and ncpp's moves agree with rs274's started from the same file (the
    stand-alone rs274 reads it in inches)."""
    var = tmp_path / "turned.var"
    var.write_text("5220 2.0\n5221 1.0\n5222 2.0\n5223 0.0\n5241 4.0\n5242 -2.0\n5243 0.0\n5250 -35.0\n")
    text = "G21 G90 G17\nG0 X10 Y0 Z5\nG1 X20 Y5 F100\nG2 X30 Y-5 R12\nG53 G0 X0 Y0\nG54 G0 X5 Y5\nM2\n"
    interpret, _ = dialect_tools("iso")
    _, blocks = parse_program(io.BytesIO(text.encode()), "t.ngc", "iso")
    offsets = WorkOffsets.from_var_file(var, unit_mm=25.4)
    events = interpret(blocks, file="t.ngc", warnings=Warnings(stream=io.StringIO()), offsets=offsets)
    mine = [call for call in map(canon_call, events) if call is not None]
    theirs = read_canon(rs274.canon(text, var_file=var, digits=7))
    assert [c.name for c in mine] == [c.name for c in theirs]
    for a, b in zip(mine, theirs):
        assert np.allclose(a.args, b.args, atol=1e-6), (a, b)


def test_a_parameter_files_rotation_is_compensated_and_said_in_the_header(tmp_path):
    """A program run in a system the parameter file turns (no G10 in it) reaches its turned points within
    0.5 µm on the machine, and the header says the rotation it was compensated for."""
    (tmp_path / "affine.toml").write_text(AFFINE)
    var, program, out = tmp_path / "turned.var", tmp_path / "plain.ngc", tmp_path / "plain.out.ngc"
    var.write_text("5220 1.0\n5221 100.0\n5222 50.0\n5223 0.0\n5230 30.0\n")
    points = [
        (10.0, 0.0, 5.0),
        (20.0, 5.0, -1.0),
        (160.0, 5.0, -1.0),
        (160.0, 90.0, -1.0),
        (-20.0, 90.0, -1.0),
    ]
    program.write_text(
        "G21 G90 G17\n" + "".join(f"G1 X{x:g} Y{y:g} Z{z:g} F300\n" for x, y, z in points) + "M2\n"
    )
    assert main(["compensate", "--machine", str(tmp_path / "affine.toml"), "--var-file", str(var),
                 "--var-units", "mm", "--tolerance", "0.0001", str(program), "-o", str(out)]) == 0  # fmt: skip
    text = out.read_text()
    assert "turned about Z, degrees, from the parameter file: G54 R30" in text
    place = lambda p: [*(turning(30.0) @ np.array(p[:2]) + [100.0, 50.0]), p[2]]  # noqa: E731
    wanted = np.array([place(p) for p in points])
    written = [tuple(float(v) for v in re.findall(r"[XYZ](-?[\d.]+)", line)) for line in text.splitlines()
               if line.startswith("G1 ")]  # fmt: skip
    reached = closed_form(np.array([place(p) for p in written]))
    assert misses(closed_form(wanted), wanted.tolist()).max() > 0.010
    assert misses(reached, wanted.tolist()).max() < 0.0005


def turned_twice(segment):
    """A wrong writer's segment: turned again the way the control turns it, where it should be turned back."""
    turn = segment.context.turned
    moved = {"start": turn(segment.start), "end": turn(segment.end)}
    if hasattr(segment, "center"):
        moved["center"] = turn(segment.center)
    return dataclasses.replace(segment, **moved)


@pytest.mark.parametrize("dialect", ["iso", "fanuc"])
@pytest.mark.parametrize("wrong", [lambda segment: segment, turned_twice], ids=["unturned", "turned-twice"])
def test_the_verifier_refuses_a_writer_that_gets_the_rotation_wrong(
    tmp_path, monkeypatch, capsys, wrong, dialect
):
    """A writer that writes the turned frame's points as the program's words, or turns them the wrong
    way, is caught by the verifier: nothing is written."""
    monkeypatch.setattr(ncpp.program.dialects.iso, "as_written", wrong)
    (tmp_path / "affine.toml").write_text(AFFINE)
    program, out = tmp_path / "turned.nc", tmp_path / "turned.out.nc"
    program.write_text(PROGRAM if dialect == "iso" else FANUC)
    zero = ",".join(f"{v:g}" for v in ZERO)
    assert main(["compensate", "--dialect", dialect, "--machine", str(tmp_path / "affine.toml"), "--work-offset",
                 zero, str(program), "-o", str(out)]) != 0  # fmt: skip
    err = capsys.readouterr().err
    assert "turned.nc:" in err and "verification" in err, err
    assert not out.exists()


@pytest.mark.parametrize(
    "before, line, word, construct",
    [
        ("F100", "G18 G2 X10 Z-5 I5 K0", "G2", "an arc in G18 under a coordinate system rotation"),
        ("F100", "G81 X10 Y10 Z-3 R2", "G81", "canned cycle G81 under a coordinate system rotation"),
        ("F100", "G92 X0 Y0", "G92", "G92 under a coordinate system rotation"),
        ("F100", "G28 X0 Y0", "G28", "G28 with X or Y under a coordinate system rotation"),
        ("G52 X1", "G55", "G55", "G55 under a coordinate system rotation and a G92 offset"),
        ("G52 Y1", "G10 L2 P0 X3", "G10", "G10 L2 of the system in effect under a rotation and a G92 offset"),
    ],
)
def test_what_is_not_followed_under_a_rotation_stays_out_of_scope_at_its_word(before, line, word, construct):
    """Such a block ends interpretation with one warning at its word (the program passes through
    from there, as written)."""
    text = f"G21 G90 G17\nG10 L2 P1 X10 Y20 Z0 R30\nG0 X1 Y1 Z5\n{before}\n{line}\nG0 X5\nM2\n"
    events, warning = interpreted(text)
    assert warning.count("warning") == 1, warning
    assert f"t.ngc:5:{line.index(word) + 1}: " in warning and construct in warning, warning
    assert [type(e).__name__ for e in events[4:]] == ["Pass", "Pass", "Pass"]


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_a_g10_r_of_fanuc_and_haas_stays_out_of_scope(dialect):
    """Their G10 L2 takes no rotation: an R there is not followed."""
    text = "G21 G90 G17\nG10 L2 P1 X10 Y20 Z0 R30\nG0 X1 Y1 Z5\nM30\n"
    _, warning = interpreted(text, dialect)
    assert "t.ngc:2:22: " in warning and "coordinate system rotation G10 R" in warning, warning


# ---- Fanuc's and Haas's G68 X_ Y_ R_ / G69 ---------------------------------------------------------

ZERO = (120.0, -40.0, 0.0)  # G54's, told with --work-offset
# a contour turned about (30, 20) by 25 degrees (lines, R and I J arcs, a G91 move), then one about
# (-10, -10) by -40 degrees whose first moves are G91 (they run from where the tool stands at G68)
FANUC = (
    "%\nO1000\nG21 G90 G17 G94\nG54\nG0 X-10 Y-10 Z5\nG68 X30 Y20 R25\nG0 X0 Y0\nG1 Z-1 F300\nG1 X80 Y0\n"
    "G3 X100 Y20 R20\nG91 G1 Y40\nG90 G2 X60 Y60 I-20 J0\nG1 X0 Y0\nG0 Z5\nG69\nG0 X-10 Y-10\n"
    "G68 X-10 Y-10 R-40\nG91 G1 X20 Y5 F200\nG1 Z-7\nG90 G1 X40 Y-30\nG0 Z5\nG69\nG90 G0 X0 Y0\nM30\n%\n"
)
_G68 = re.compile(r"G68\s*X\s*(-?[\d.]+)\s*Y\s*(-?[\d.]+)\s*R\s*(-?[\d.]+)")


def turning(angle: float) -> np.ndarray:
    """The 2x2 matrix turning by `angle` degrees counter-clockwise."""
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    return np.array([[c, -s], [s, c]])


def fanuc_end_points(text: str) -> np.ndarray:
    """The machine point (mm) each move of a Fanuc program in this test's words ends at, read as the
    manual says (Fanuc Series 16/18-MC operator's manual, "Coordinate system rotation"): under G68 an
    absolute point is turned about the centre by R, an increment (G91) is turned and added to where the
    tool stands; G69 ends it."""
    zero, here = np.array(ZERO), np.array(ZERO)
    turn: tuple[np.ndarray, np.ndarray] | None = None  # (rotation matrix, centre)
    absolute, ends = True, []
    for line in text.splitlines():
        code = line.split("(")[0].upper().strip()
        if not code or code[0] in "%OI":  # (the tape marks, the program number, the guard's IF lines)
            continue
        found = _G68.search(code)
        if found:
            x, y, angle = map(float, found.groups())
            turn = (turning(angle), np.array([x, y]))
            continue
        if "G69" in code:
            turn = None
            continue
        for number in re.findall(r"G(\d+)", code):
            absolute = {90: True, 91: False}.get(int(number), absolute)
        words = {axis: float(value) for axis, value in _WORD.findall(code)}
        if not words:
            continue
        rotation, centre = turn if turn is not None else (np.eye(2), np.zeros(2))
        if absolute:
            point = here - zero  # the program's point of where the tool stands
            point[:2] = rotation.T @ (point[:2] - centre) + centre
            for axis, value in words.items():
                point["XYZ".index(axis)] = value
            here = zero + np.array([*(rotation @ (point[:2] - centre) + centre), point[2]])
        else:
            step = np.array([words.get(axis, 0.0) for axis in "XYZ"])
            here = here + np.array([*(rotation @ step[:2]), step[2]])
        ends.append(here.copy())
    return np.array(ends)


def fanuc_written(
    tmp_path: Path,
    dialect: str = "fanuc",
    text: str = FANUC,
    machine: str = AFFINE,
    zero: tuple = ZERO,
    quiet: bool = False,
    extra: tuple[str, ...] = (),
) -> tuple[Path, Path]:
    """The Fanuc program and ncpp's compensation of it for `machine` (AFFINE's), G54 at `zero`
    (`quiet`: with no warning but the tool guard's; `extra`: more arguments, a tool table's)."""
    (tmp_path / "affine.toml").write_text(machine)
    program, out = tmp_path / "turned.nc", tmp_path / "turned.out.nc"
    program.write_text(text)
    told = ",".join(f"{v:g}" for v in zero)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--dialect", dialect, "--machine",
                           str(tmp_path / "affine.toml"), "--work-offset", told, "--tolerance", "0.0001",
                           *extra, str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300, stdin=subprocess.DEVNULL)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    said = "\n".join(line for line in proc.stderr.splitlines() if "no tool guard" not in line)
    assert "scope" not in said and not (quiet and "warning" in said), proc.stderr
    return program, out


_ANY_WORD = re.compile(r"([A-Z])\s*(-?[\d.]+)")


def code_words(text: str) -> Iterator[tuple[list[float], dict[str, float]]]:
    """The G codes and the other words (N aside) of each line of a Fanuc program in the tests' words, as
    a hand reading takes them: comments, tape marks, the program number and the guard's IF lines aside."""
    for line in text.splitlines():
        code = line.split("(")[0].upper().strip()
        if not code or code[0] in "%OI":
            continue
        words = [(letter, float(value)) for letter, value in _ANY_WORD.findall(code)]
        yield (
            [value for letter, value in words if letter == "G"],
            {letter: value for letter, value in words if letter not in "GN"},
        )


def refused_as_written_by(
    wrong, tmp_path: Path, monkeypatch, capsys, text: str, machine: str, zero: tuple
) -> None:
    """A Fanuc program compensated by a writer that turns its points back `wrong` (for `as_written`) is
    refused by the verifier, its file named, and nothing is written."""
    monkeypatch.setattr(ncpp.program.dialects.iso, "as_written", wrong)
    (tmp_path / "machine.toml").write_text(machine)
    program, out = tmp_path / "framed.nc", tmp_path / "framed.out.nc"
    program.write_text(text)
    told = ",".join(f"{v:g}" for v in zero)
    assert main(["compensate", "--dialect", "fanuc", "--machine", str(tmp_path / "machine.toml"), "--work-offset",
                 told, str(program), "-o", str(out)]) != 0  # fmt: skip
    err = capsys.readouterr().err
    assert "framed.nc:" in err and "verification" in err, err
    assert not out.exists()


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_the_programmed_points_are_reached_under_g68_within_half_a_micron(tmp_path, dialect):
    """Every programmed end point, turned about G68's centre as the manual says, is reached within 0.5 µm
    by the rewritten program on the machine; the program as written misses them by more than 10 µm."""
    _, out = fanuc_written(tmp_path, dialect)
    wanted = fanuc_end_points(FANUC)
    assert len(wanted) == 15
    assert misses(closed_form(wanted), wanted.tolist()).max() > 0.010
    assert misses(closed_form(fanuc_end_points(out.read_text())), wanted.tolist()).max() < 0.0005


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_a_g68_of_variables_turns_as_their_values_do(tmp_path, dialect):
    """`G68 X#1 Y[#2] R#3` turns as `G68 X30 Y20 R25` (a word takes a macro variable's value: Fanuc
    16/18-MC operator's manual, "Custom macro", "Referencing variables"): with the values written in
    for the judge, every programmed point is reached within 0.5 µm."""
    turned = FANUC.replace("G68 X30 Y20 R25", "#1=30.\n#2=20.\n#3=25.\nG68 X#1 Y[#2] R#3")
    _, out = fanuc_written(tmp_path, dialect, turned)
    written = out.read_text()
    assert "G68 X#1 Y[#2] R#3" in written
    wanted = fanuc_end_points(FANUC)
    got = fanuc_end_points(written.replace("G68 X#1 Y[#2] R#3", "G68 X30 Y20 R25"))
    assert misses(closed_form(got), wanted.tolist()).max() < 0.0005


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_a_g69_among_modes_of_other_groups_is_followed(tmp_path, dialect):
    """`G69 G94 G80` and `G90 G69 G49` (G69 with modes of other groups that move nothing: Fanuc Series
    30i-MB G code list) cancel the rotation as a G69 alone does: every programmed point is reached
    within 0.5 µm, the program compensated to its end."""
    turned = FANUC.replace("G69\nG0 X-10", "G69 G94 G80\nG0 X-10").replace("G69\nG90 G0", "G90 G69 G49\nG0")
    assert turned.count("G69 ") == 2
    _, out = fanuc_written(tmp_path, dialect, turned)
    written = out.read_text()
    assert "G69 G94 G80\n" in written and "G90 G69 G49\n" in written
    wanted = fanuc_end_points(FANUC)
    assert misses(closed_form(fanuc_end_points(written)), wanted.tolist()).max() < 0.0005


def as_linuxcnc(text: str) -> str:
    """A Fanuc program in this test's words as LinuxCNC runs it: G54's zero set by G10 L2, each `G68 X Y R`
    a G55 whose zero is G54's plus c - R c and whose rotation is R (R (p - c) + c + zero = R p + zero'),
    each G69 G54 again (LinuxCNC keeps the machine where it is at both, as Fanuc does)."""
    lines = [f"G10 L2 P1 X{ZERO[0]:g} Y{ZERO[1]:g} Z{ZERO[2]:g}"]
    for line in text.splitlines():
        code = line.strip()
        found = _G68.search(code.upper())
        if code.upper().startswith(("O", "IF", "%")):  # (the tape marks, the number, the guard)
            continue
        if found:
            x, y, angle = map(float, found.groups())
            centre = np.array([x, y])
            zx, zy = centre - turning(angle) @ centre + np.array(ZERO[:2])
            lines += [f"G10 L2 P2 X{zx:.9f} Y{zy:.9f} Z{ZERO[2]:g} R{angle:g}", "G55"]
        else:
            lines.append("G54" if code.upper() == "G69" else code)
    return "\n".join(lines) + "\n"


def test_the_whole_path_under_g68_lands_on_the_original_in_rs274(tmp_path):
    """rs274 runs both programs turned into LinuxCNC's G10 L2 R (`as_linuxcnc`): along every feed move,
    arcs included, the rewritten program's path run on the machine is within 0.5 µm of the original's;
    pathcheck accepts it."""
    program, out = fanuc_written(tmp_path)
    linuxcnc = [tmp_path / "turned.ngc", tmp_path / "turned.out.ngc"]
    for fanuc, ngc in zip((program, out), linuxcnc):
        ngc.write_text(as_linuxcnc(fanuc.read_text()))
    before, after = (feed_moves(p, home=tmp_path) for p in linuxcnc)
    # (the manual's reading and rs274's of the program turned into LinuxCNC's agree on where it goes)
    assert misses(fanuc_end_points(FANUC), [tuple(m.end) for m in before]).max() < 1e-6
    assert deviation(before, before, closed_form).max() > 0.010
    assert deviation(before, after, closed_form).max() < 0.0005
    rs274.pathcheck(*linuxcnc)


def test_the_returns_posts_write_after_g69_are_followed():
    """`G91 G28 Z0.` and `G28 X0. Y0.` after G69 (a Fanuc post's ending) move from where the tool stands
    and home the axes: no warning, and the absolute move after them is read."""
    text = "G21 G90 G17\nG0 X1 Y1 Z5\nG68 X0 Y0 R30\nG1 X5 Y5 F100\nG69\nG91 G28 Z0.\nG28 X0. Y0.\nG90 G0 X7\nM30\n"
    events, warning = interpreted(text, "fanuc")
    assert not warning, warning
    assert [e.block.line for e in events if type(e).__name__ == "Line"][-1] == 8


@pytest.mark.parametrize(
    "body, at, construct",
    [
        ("G18\nG68 X0 Y0 R30", "G68", "G68 with other words in its block than G18, Z, X and R"),
        ("G68 G19 X0 Y0 R30", "G68", "G68 with other words in its block than G19, Y, Z and R"),
        ("G18\nG68 X0 R30", "G68", "G68 without Z and X"),
        ("G19\nG68 Y0 Z0 R30\nG17", "G17", "G17 under coordinate system rotation G68"),
        ("G18\nG68 X0 Z0 R30\nG1 X5 F100", "X5", "an absolute move of Z or X alone after G68"),
        (
            "G19\nG68 Y0 Z0 R30\nG1 Y5 Z5 F100\nG69\nG91 G1 Z1",
            "Z1",
            "an incremental move of Y or Z after G69",
        ),
        ("G18\nG68 X0 Z0 R30\nG28 Z0", "G28", "G28 with Z or X under a coordinate system rotation"),
        (
            "G18\nG68 X0 Z0 R30\nG42 D1 G1 X5 Z5 F100",
            "G42",
            "cutter compensation G42 in G18 under a coordinate",
        ),
        ("G42 D1 G1 X5 Y5 F100\nG68 X0 Y0 R30", "G68", "G68 under cutter compensation"),
        ("G68 X0 Y0 R30\nG51 X0 Y0 P2", "G51", "scaling G51"),
        ("G68 X0 Y0", "G68", "G68 without R"),
        ("G91\nG68 X0 Y0 R30", "G68", "G68 in G91"),
        ("G68 R30", "G68", "G68 without X and Y"),
        ("G68 X0 Y0 Z0 I0 J0 K1 R30", "G68", "G68 with other words in its block"),
        ("G68 X0 Y0 R30\nG18", "G18", "G18 under coordinate system rotation G68"),
        ("G68 X0 Y0 R30\nG55", "G55", "G55 under coordinate system rotation G68"),
        ("G68 X0 Y0 R30\nG1 X5 F100", "X5", "an absolute move of X or Y alone after G68"),
        (
            "G68 X0 Y0 R30\nG1 X5 Y5 F100\nG69\nG91 G1 X1",
            "X1",
            "an incremental move of X or Y after G69",
        ),
        (
            "G68 X0 Y0 R30\nG81 X1 Y1 Z-1 R1 F100",
            "G81",
            "canned cycle G81 under a coordinate system rotation",
        ),
        ("G68.2 X0 Y0 Z0 I0 J30 K0", "G68.2", "tilted working plane G68.2"),
        ("G51 X0 Y0 P2", "G51", "scaling G51"),
    ],
)
def test_what_fanuc_g68_needs_and_ncpp_does_not_follow_stays_out_of_scope_at_its_word(body, at, construct):
    """Each ends interpretation with one warning at its word (the Fanuc manual's rules for G68, and what
    else ncpp does not follow under it)."""
    text = f"G21 G90 G17\nG0 X1 Y1 Z5\n{body}\nG0 X5 Y5\nM30\n"
    _, warning = interpreted(text, "fanuc")
    lines = text.splitlines()
    line = min(n for n, code in enumerate(lines, 1) if n > 2 and at in code.split())
    assert warning.count("warning") == 1, warning
    assert f"t.ngc:{line}:{lines[line - 1].index(at) + 1}: " in warning and construct in warning, warning


SAFETY = {  # a post's safety line, and the cancels in it the control has (G code lists of their manuals)
    "fanuc": ("G90 G17 G40 G49 G80 G15 G50 G50.1 G69", ("G15", "G50", "G50.1", "G69")),
    "haas": ("G90 G17 G40 G49 G80 G50 G69", ("G50", "G69")),
}


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_a_safety_lines_cancels_of_modes_not_in_effect_change_nothing(tmp_path, dialect):
    """`G15`, `G50`, `G50.1` and `G69` where no polar coordinates, scaling, mirror image or rotation is in
    effect cancel nothing: the program is compensated to its end, and its written text is that of the
    same program without them, but for the cancels, kept where they stand."""
    line, cancels = SAFETY[dialect]
    program = "%\nO1000\n" + line + "\nG21 G54\nG0 X10. Y10. Z5.\nG1 Z-1. F300.\nX60. Y40.\nG0 Z5.\nM30\n%\n"
    plain = program.replace(line, " ".join(w for w in line.split() if w not in cancels))
    outputs = []
    for name, text in (("with.nc", program), ("without.nc", plain)):
        source = tmp_path / name
        source.write_text(text)
        run = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--dialect", dialect, "--no-guard",
                              "--machine", str(ROOT / "samples/machines/hr5b.toml"), "--work-offset", "400,350,300",
                              str(source)], capture_output=True, text=True, cwd=tmp_path)  # fmt: skip
        assert run.returncode == 0 and "warning" not in run.stderr, run.stderr
        outputs.append(run.stdout)
    assert outputs[0].replace(line, " ".join(w for w in line.split() if w not in cancels)) == outputs[1]


@pytest.mark.parametrize(
    "dialect, body, at, construct",
    [
        ("fanuc", "G68 X0 Y0 R30\nG1 X5 Y5 F100\nG69 G17", "G69", "G69 with G17 in its block"),
        ("haas", "G68 X0 Y0 R30\nG1 X5 Y5 F100\nG69 X1", "G69", "G69 with X1 in its block"),
        ("fanuc", "G50 S2000", "G50", "G50 with S"),
        ("haas", "G15 G40", "G15", "polar coordinates G15"),
    ],
)
def test_a_cancel_that_cancels_something_or_means_something_else_stays_out_of_scope(
    dialect, body, at, construct
):
    """A G69 while G68 is in effect among other words, a G50 with S (a lathe's spindle speed clamp), and a
    G15 on Haas (whose manual lists no polar coordinates) each end interpretation at their word."""
    text = f"G21 G90 G17\nG0 X1 Y1 Z5\n{body}\nG0 X5 Y5\nM30\n"
    _, warning = interpreted(text, dialect)
    lines = text.splitlines()
    line = min(n for n, code in enumerate(lines, 1) if n > 2 and at in code.split())
    assert warning.count("warning") == 1, warning
    assert f"t.ngc:{line}:{lines[line - 1].index(at) + 1}: " in warning and construct in warning, warning


_SETS = re.compile(r"(SET_G92_OFFSET|SET_G5X_OFFSET|SET_TOOL_TABLE_ENTRY)\((.*)\)")
_MOVES = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED)\(([^)]*)\)")


@pytest.mark.oracle
@pytest.mark.parametrize(
    "setting",
    ["G92 X0 Y0", "G10 L20 P0 X2 Y3", "G10 L10 P1 X0 Y0 Z0", "G10 L10 P2 X0 Y0", "G10 L20 P2 X2 Y3",
     "G10 L2 P3 R45\nG10 L20 P3 X2", "G10 L11 P2 X0 Y0"],
)  # fmt: skip
@pytest.mark.parametrize("mode", ["G0", "G1 F300"])
def test_an_offset_set_from_a_compensated_point_where_interpretation_ends_is_the_programs(
    tmp_path, setting, mode
):
    """A block that sets an offset from where the control stands (LinuxCNC G-code manual: G92, G10
    L20, G10 L10) ends interpretation under a rotation; the move before it was compensated, so ncpp
    writes a step back to the programmed point first, in the program's mode: rs274 then sets the
    offsets the original sets, and every move after it (uninterpreted, as programmed) ends where the
    original's does, however many setting blocks follow.  So too for a block that reads the point in
    another frame (G10 L20 of another system, rotated or not; G10 L11, in G59.3's)."""
    text = (
        f"G20 G90 G17\nT1 M6\nG43\nG10 L2 P1 X1 Y2 Z0 R30\n{mode}\nX4 Y3 Z0.5\n"
        f"{setting}\nG10 L10 P1 X0.5\nX1 Y0\nG91 X0.5\nM2\n"
    )
    (tmp_path / "t.tbl").write_text("T1 P1 Z0 D0.25\nT2 P2 Z0 D0.5\n")
    program, out, proc = _written_out(tmp_path, text)
    runs = _same_settings_and_last_moves(tmp_path, program, out, 3)
    moves = [[m.group(1) for m in _MOVES.finditer(run)] for run in runs]
    assert moves[1] == moves[0][:1] + [moves[0][0]] + moves[0][1:]  # the step, in the program's mode
    assert "(its modal state is unknown)" in proc.stderr


def _same_settings_and_last_moves(tmp_path: Path, program: Path, out: Path, last: int) -> list[str]:
    """rs274's runs of the original and the written program (tool table t.tbl): asserts that they set
    the same offsets and end their `last` moves at the same points (to 1e-7); returns the runs."""
    runs = [
        rs274.run(p, tool_table=tmp_path / "t.tbl", digits=7, home=tmp_path).stdout for p in (program, out)
    ]
    before, after = ([m.groups() for m in _SETS.finditer(run)] for run in runs)
    assert before and after == before, (before, after)
    ends = [
        [tuple(float(v) for v in m.group(2).split(",")[:3]) for m in _MOVES.finditer(run)][-last:]
        for run in runs
    ]
    assert np.allclose(ends[0], ends[1], atol=1e-7), ends
    return runs


@pytest.mark.oracle
def test_a_zero_set_from_the_current_point_in_a_rotated_system_is_the_programs(tmp_path):
    """G10 L20 of another system that G10 L2 R rotates, the system in effect not rotated: rs274 sets
    that system's zero from the current point turned into its frame (an axis the block does not name
    kept where the point is there, and both turned back), which ncpp does not follow: interpretation
    ends there, after a step back to the programmed point, and rs274 sets the zero the original sets
    and runs the moves in that system (as programmed) where the original's run."""
    text = (
        "G20 G90 G17\nG10 L2 P2 X0 Y0 Z0 R45\nG54\nG0 X1 Y0.5 Z0.5\nG1 X4 Y2 F300\nG10 L20 P2 X0.1 Z0\n"
        "G55\nG1 X1 Y1\nX0 Y3\nM2\n"
    )
    (tmp_path / "t.tbl").write_text("T1 P1 Z0 D0.25\n")
    program, out, proc = _written_out(tmp_path, text)
    _same_settings_and_last_moves(tmp_path, program, out, 2)
    assert "G10 L20 of a rotated coordinate system" in proc.stderr


def _written_out(tmp_path: Path, text: str) -> tuple[Path, Path, subprocess.CompletedProcess]:
    """`written`, for a program that leaves the scope (its warning expected)."""
    (tmp_path / "affine.toml").write_text(AFFINE)
    program, out = tmp_path / "turned.ngc", tmp_path / "turned.out.ngc"
    program.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "affine.toml"),
                           "--tool-table", str(tmp_path / "t.tbl"), "--var-units", "inch",
                           str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300, stdin=subprocess.DEVNULL)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return program, out, proc
