"""Canned cycles in G90 and G91, in G17, G18 and G19, are compensated hole by hole: the control's
tool lands on each hole's programmed bottom (X Y Z) and R plane.  Judged by LinuxCNC's rs274 running ncpp's output,
its moves mapped through a machine written here by hand (scale errors on X Y Z, squareness of
X-Y and X-Z), not by ncpp's interpreter or model."""

from __future__ import annotations

import io
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ncpp.errors import Warnings
from tests import rs274
from tests.compensation.accuracy import Machine, _moves, actual_moves, rs274_calls
from tests.conftest import SHARED
from tests.verify.test_corpus_pathcheck import rs274_environment
from tests.writeback.conftest import compensate_file, linear_errors, machine_file

MACHINE = machine_file(
    "scales and squareness",
    """
[errors.EXX]
kind = "polynomial"
coefficients_um = [0.0, 0.05]
[errors.EYY]
kind = "polynomial"
coefficients_um = [0.0, -0.04]
[errors.EZZ]
kind = "polynomial"
coefficients_um = [0.0, 0.03]
[squareness]
C0Y_urad = 30.0
B0Z_urad = 40.0
""",
)


def square(points: np.ndarray, _directions: np.ndarray) -> np.ndarray:
    """Where the tool is for commanded points, mm: X scale 50 µm/m, Y scale -40 µm/m, Z scale
    30 µm/m; Y motion carries X by -30 µm/m (C0Y), Z motion carries X by +40 µm/m (B0Z)."""
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    return points + np.column_stack([0.05 * x - 0.03 * y + 0.04 * z, -0.04 * y, 0.03 * z]) / 1000


REVERSAL = machine_file(
    "reversals of X and Z",
    """
[errors.EXX]
kind = "table"
positions = [-1000.0, 1000.0]
values_um = [-10.0, 10.0]
values_um_minus = [-13.0, 7.0]
[errors.EZZ]
kind = "table"
positions = [-1000.0, 1000.0]
values_um = [-20.0, 20.0]
values_um_minus = [-18.0, 22.0]
[errors.EZX]
kind = "polynomial"
coefficients_um = [0.0, 0.02]
[squareness]
C0Y_urad = 30.0
""",
)


def reversing(points: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """X off by 0.01 µm/mm · x, 3 µm less travelling − (it runs ahead on reversal), and -30 µm/m · y
    (C0Y); Z by 0.02 µm/mm · z and 0.02 µm/mm · x (X's straightness), 2 µm more travelling − (lost
    motion)."""
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    dx = 0.01 * x - 0.03 * y - (3.0 if directions[0] < 0 else 0.0)
    dz = 0.02 * z + 0.02 * x + (2.0 if directions[2] < 0 else 0.0)
    return points + np.column_stack([dx, 0 * x, dz]) / 1000


# (X, Y, Z bottom, R) of each hole, in the order the program drills them
HOLES = [
    (100, 120, -16, 3), (30, 40, -16, 3), (150, -50, -20, 5), (-80, 60, -20, 5),
    (200, 10, -5, 2), (210, 10, -7.5, 2.5), (220, 100, -9, 1), (230, 110, -3, 1), (240, 120, -3, 1),
    (250, 130, -4, 1.5), (-250, -130, -4, 1.5), (-200, 300, -6, 2), (-190, 300, -3, 1), (-190, -250, -3, 1),
    (300 * 0.5**0.5, 300 * 0.5**0.5, -3, 1),
]  # fmt: skip
PROGRAM = """G21 G90 G17
G0 X40 Y30 Z25
G1 X45 Y35 F300
G0 Z25
G99 G81 X100 Y120 R3 Z-16 F100
X30 Y40
G98 G83 X150 Y-50 R5 Z-20 Q4
X-80 Y60
G80
G0 X0 Y0
G99 G82 X200 Y10 R2 Z-5 P0.5
G85 X210 R2.5 Z-7.5
G73 X220 Y100 Z-9 R1 Q2.5
M3 S500
G86 X230 Y110 Z-3 R1 P1
G89 X240 Y120 Z-3 R1 P1
G84 X250 Y130 Z-4 R1.5
M4
G74 X-250 Y-130 R1.5 Z-4
G80
G1 X-190 Y290 Z4 F400
G98 G81 X-200 Y300 R2 Z-6
G99 X-190 Z-3 R1
Y-250
@300 ^45
G80
M5
M2
"""


# Cycles in G91 with repeats (L): a block per hole is written, X Y from where the control
# stands, R from the series' start level (Z25 for the G83 too: no G80 between), Z from R
# (rs274ngc's convert_cycle in G91)
HOLES_G91 = [(132, 117, -7, 3), (152, 122, -7, 3), (172, 127, -7, 3), (162, 157, 18, 24), (152, 187, 18, 24),
             (-128, -107, -1, 2.5), (-108, -107, -1, 2.5)]  # fmt: skip
PROGRAM_G91 = """G21 G90 G17
G0 X110 Y110 Z25
G1 X112 Y112 F300
G0 Z25
G91 G99 G81 X20 Y5 R-22 Z-10 L3 F100
G98 G83 X-10 Y30 R-1 Z-6 Q2 L2
G90 G80
G0 X-148 Y-107 Z4
G91 G99 G82 X20 R-1.5 Z-3.5 P0.2 L2
G90 G80
M2
"""


# Cycles in G18 and G19, as rs274ngc runs them: the G17 programs' moves with their axes renamed
# (rs274ngc's convert_cycle_zx and convert_cycle_yz: the first and second axis of the plane, and
# the drilling axis along its normal, take the places of X Y and Z): no polar words, no taps there
# (`G17 X Y Z` -> the plane's letters in that order)
PLANE_LETTERS = {18: "ZXY", 19: "YZX"}
# (first, second, normal) axis indices of each plane
PLANE_INDICES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}
AXES = "XYZ"
# (the G17 program's holes and lines but its taps, with the M4 before G74, and its polar words)
HOLES_IN_PLANE = HOLES[:9] + HOLES[11:14]
PROGRAM_IN_PLANE = "".join(
    line for line in PROGRAM.splitlines(keepends=True) if not line.startswith(("G84 ", "M4\n", "G74 ", "@"))
)


def in_plane(program: str, holes: list[tuple[float, ...]], plane: int) -> tuple[str, list[tuple[float, ...]]]:
    """A G17 program and its holes (X Y Z R) moved to `plane`: its axis letters renamed, each hole's
    bottom put on the plane's axes."""
    text = program.replace("G17", f"G{plane}").translate(str.maketrans("XYZ", PLANE_LETTERS[plane]))
    moved = []
    for aa, bb, cc, r in holes:
        point = [0.0, 0.0, 0.0]
        for axis, value in zip(PLANE_INDICES[plane], (aa, bb, cc)):
            point[axis] = value
        moved.append((*point, r))
    return text, moved


def reversing_in(plane: int) -> tuple[str, Machine]:
    """REVERSAL and `reversing` seen from `plane`: the roles of X, Y and Z taken by the plane's first
    and second axis and its normal (the drilling axis plays, the first axis runs ahead, the normal
    carries an error from the first's travel, the first one from the second's), so that each plane's
    holes meet the same machine as G17's."""
    first, second, normal = (AXES[k] for k in PLANE_INDICES[plane])
    toml = machine_file(f"reversals of {first} and {normal}", f"""
[errors.E{first}{first}]
kind = "table"
positions = [-1000.0, 1000.0]
values_um = [-10.0, 10.0]
values_um_minus = [-13.0, 7.0]
[errors.E{normal}{normal}]
kind = "table"
positions = [-1000.0, 1000.0]
values_um = [-20.0, 20.0]
values_um_minus = [-18.0, 22.0]
""" + linear_errors(**{f"E{normal}{first}": 0.02, f"E{first}{second}": -0.03}))  # fmt: skip
    order = list(PLANE_INDICES[plane])

    def machine(points: np.ndarray, directions: np.ndarray) -> np.ndarray:
        out = np.empty_like(points)
        out[:, order] = reversing(points[:, order], directions[order])
        return out

    return toml, machine


def drilled(path: Path, machine: Machine | None, plane: int = 17) -> list[tuple[np.ndarray, float]]:
    """Per hole of `path` as rs274 runs it (mapped through `machine`, or as commanded: None): where
    the tool is at its bottom, and its level along the plane's normal (Z in G17) where it arrives
    above the hole at R.  A hole: a run of moves ending at one commanded position in the plane with
    a feed down the normal; its R point the end of the move before its first feed, its bottom the
    lowest feed end."""
    first, second, normal = PLANE_INDICES[plane]
    across = [first, second]
    commanded = _moves(path)
    actual = [b for _, b, _ in commanded] if machine is None else [m[-1] for m in actual_moves(path, machine)]
    runs: list[list[int]] = []
    for k, (_, end, _) in enumerate(commanded):  # (moves written one by one: µm apart in the plane)
        if runs and np.allclose(commanded[runs[-1][0]][1][across], end[across], atol=0.01):
            runs[-1].append(k)
        else:
            runs.append([k])
    out = []
    for run in runs:
        plunges = [k for k in run if commanded[k][2] and _plunges(*commanded[k][:2], across, normal)]
        if plunges:
            lowest = min(plunges, key=lambda k: commanded[k][1][normal])
            out.append((actual[lowest], float(actual[plunges[0] - 1][normal])))
    return out


def _plunges(start: np.ndarray, end: np.ndarray, across: list[int], normal: int) -> bool:
    return bool(np.allclose(start[across], end[across], atol=0.01) and end[normal] < start[normal] - 0.01)


PROGRAMS = [
    (PROGRAM, HOLES, 17),
    (PROGRAM_G91, HOLES_G91, 17),
    *(
        (*in_plane(program, holes, plane), plane)
        for plane in (18, 19)
        for program, holes in ((PROGRAM_IN_PLANE, HOLES_IN_PLANE), (PROGRAM_G91, HOLES_G91))
    ),
]


@pytest.mark.parametrize("machine_toml, machine", [(MACHINE, square), ("reversals", None)],
                         ids=["scales and squareness", "reversals"])  # fmt: skip
@pytest.mark.parametrize(
    "program, holes, plane",
    PROGRAMS,
    ids=["G90", "G91 repeats", "G18 G90", "G18 G91 repeats", "G19 G90", "G19 G91 repeats"],
)
def test_each_hole_bottom_and_r_plane_land_where_programmed(
    tmp_path, machine_toml, machine, program, holes, plane
):
    if machine is None:  # (the reversals as G17 meets them: `reversing_in`)
        machine_toml, machine = (REVERSAL, reversing) if plane == 17 else reversing_in(plane)
    original = tmp_path / "holes.ngc"
    original.write_text(program)
    output = compensate_file(original, machine_toml, tmp_path)
    wanted = np.array(holes, dtype=float)
    assert np.allclose([tuple(b) + (r,) for b, r in drilled(original, None, plane)], wanted, atol=1e-6)
    before = drilled(original, machine, plane)
    after = drilled(output, machine, plane)
    assert len(after) == len(holes)
    assert_holes_land(before, after, wanted)


def _rs274_text(path: Path) -> str:
    proc = rs274.run(path, digits=7)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


def test_a_g92_after_a_compensated_hole_sets_the_programs_offset(tmp_path):
    """After a compensated hole the control stands at the corrected point, which ncpp knows: a G92
    there is written moved by it, so the control sets the offset the program means, and the moves
    after it land where the program puts them."""
    original = tmp_path / "g92.ngc"
    original.write_text("G21 G90 G54\nG0 X10 Y10 Z20\nG1 X50 F300\nG98 G81 X20 Y30 Z-2 R2 F100\nG80\n"
                        "G92 X0 Y0\nG1 X20 Y10\nX-5 Y40 Z3\nG92.1\nM2\n")  # fmt: skip
    output = compensate_file(original, MACHINE, tmp_path)
    offsets = [re.findall(r"SET_G92_OFFSET\(([^)]*)\)", _rs274_text(p)) for p in (original, output)]
    assert offsets[0] == offsets[1] and "20.0000000, 30.0000000" in offsets[0][1]
    shift = np.array([20.0, 30.0, 0.0])
    wanted = np.array([[20, 10, 20], [-5, 40, 3]], dtype=float) + shift
    got = np.array([args[:3] for name, args in rs274_calls(output) if name == "STRAIGHT_FEED"][-2:]) + shift
    assert np.abs(square(got, np.ones(3)) - wanted).max() * 1000 <= 0.5


def test_fanuc_repeats_in_k_land_where_programmed(tmp_path):
    """A Fanuc cycle's K is its repeats, as rs274ngc's L (`FanucInterpreter.repeat_letters`): each
    hole of the G91 rows lands on its programmed bottom and R, judged by rs274 running the written
    program and the original read with L for K."""
    original = tmp_path / "repeats.nc"
    program = PROGRAM_G91.replace("M2\n", "M30\n")
    original.write_text(program.replace(" L", " K"))
    output = compensate_file(original, MACHINE, tmp_path, dialect="fanuc")
    assert not re.search(r"\bK\d", output.read_text())  # (a block per hole, the first without its K)
    as_linuxcnc = tmp_path / "repeats.ngc"
    as_linuxcnc.write_text(program)
    wanted = np.array(HOLES_G91, dtype=float)
    before, after = drilled(as_linuxcnc, square), drilled(output, square)
    assert len(after) == len(wanted)
    assert_holes_land(before, after, wanted)
    assert _passes_pathcheck(as_linuxcnc, output)


def test_a_fanuc_p_that_no_dwell_reads_is_kept_and_the_holes_land(tmp_path):
    """A P in a Fanuc G81 or G83 block, whose formats have none (`FanucInterpreter.any_cycle_p`), stays as
    written and the holes are the cycles' own: each lands on its programmed bottom and R, judged by
    rs274 running the written program without its P (which rs274 refuses) against the original's holes."""
    original = tmp_path / "kept.nc"
    program = PROGRAM_G91.replace("M2\n", "M30\n").replace(" L", " K")
    original.write_text(program.replace("G81 X20", "G81 P300 X20").replace("G83 X-10", "G83 P300 X-10"))
    output = compensate_file(original, MACHINE, tmp_path, dialect="fanuc")
    written = output.read_text()
    assert re.search(r"^G91 G99 G81 P300 X", written, re.M) and re.search(r"^G98 G83 P300 X", written, re.M)
    as_linuxcnc, without_p = tmp_path / "kept.ngc", tmp_path / "written.ngc"
    as_linuxcnc.write_text(PROGRAM_G91)
    without_p.write_text(written.replace(" P300", ""))
    wanted = np.array(HOLES_G91, dtype=float)
    before, after = drilled(as_linuxcnc, square), drilled(without_p, square)
    assert len(after) == len(wanted)
    assert_holes_land(before, after, wanted)


@pytest.mark.parametrize(
    "dialect, words, where",
    [("fanuc", "Q2", "4:29: warning: back boring G87 with its shift in Q"),
     ("fanuc", "", "4:5: warning: Fanuc's back boring G87 without I or J"),
     ("fanuc", "I2 J1 G99", "4:5: warning: Fanuc's back boring G87 in G99"),
     ("haas", "I2 J1", "4:5: warning: G87 on Haas")],
)  # fmt: skip
def test_a_back_bore_whose_shift_is_not_told_passes_through(tmp_path, dialect, words, where):
    """Fanuc's G87 shifts the tool by Q (or without I and J) in a direction a parameter of the
    control's sets (Fanuc Series 15i-MA operator's manual, "Back boring cycle (G87)", "Shift
    specification by Q_"), and takes no G99: the program passes through from there, with a warning,
    where rs274ngc's reading refused it; so does a Haas program's G87."""
    retract, words = ("G99", words.removesuffix(" G99")) if words.endswith("G99") else ("G98", words)
    block = f"{retract} G87 X200 Y150 Z-30 R-45 {words} F100".replace("  ", " ")
    original = tmp_path / "back.nc"
    original.write_text(f"%\nG21 G90 G17\nG0 X40 Y30 Z25 S500 M3\n{block}\nG80\nG0 X10 Y10\nM30\n%\n")
    said = io.StringIO()
    output = compensate_file(original, MACHINE, tmp_path, warnings=Warnings(stream=said), dialect=dialect)
    assert output.read_text().endswith(f"{block}\nG80\nG0 X10 Y10\nM30\n%\n")
    assert f"back.nc:{where}" in said.getvalue()


# Fanuc's fine boring G76 (G90, G91 with K repeats, G98 and G99): (X, Y, Z bottom, R) of each hole
HOLES_FINE = [(100, 120, -16, 3), (30, 40, -16, 3), (150, -50, -20, 5),
              (170, -45, -2, 8), (190, -40, -2, 8), (210, -35, -2, 8)]  # fmt: skip
PROGRAM_FINE = """G21 G90 G17
G0 X40 Y30 Z25
M3 S500
G1 X45 Y35 F300
G99 G76 X100 Y120 R3 Z-16 Q0.2 P0 F100
X30 Y40
G98 G76 X150 Y-50 R5 Z-20 Q0.2 P0.5
G80
G0 Z30
G91 G99 G76 X20 Y5 R-22 Z-10 Q0.2 P0 K3
G90 G80
G1 X-100 Y80 Z3
M5
M30
"""


def _as_g86(path: Path) -> Path:
    """`path` with its fine boring as rs274ngc's G86 (feed to the bottom, dwell, spindle stop, rapid
    out: LinuxCNC G-code manual, G86), the moves Fanuc's G76 makes but the shift off the wall at the
    bottom and back above the hole (Fanuc Series 15i-MA operator's manual, "Fine boring cycle (G76)"),
    its K as L."""
    text = re.sub(r"\s*Q[\d.]+", "", path.read_text().replace("G76", "G86"))
    plain = path.with_name(path.stem + "-g86.ngc")
    plain.write_text(re.sub(r"\bK(\d)", r"L\1", text))
    return plain


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_fanuc_fine_boring_lands_where_programmed(tmp_path, dialect):
    """Fanuc's and Haas's G76 (fine boring: the spindle orients at the bottom and the tool shifts off
    the wall before it rapids out) is compensated hole by hole as the other cycles: each hole's bottom
    and R point, as rs274 runs the written program with its G76 as G86, mapped through the hand-written
    machine, within 0.5 µm of the programmed point.  (Haas counts repeats in L.)"""
    original = tmp_path / "fine.nc"
    original.write_text(PROGRAM_FINE if dialect == "fanuc" else PROGRAM_FINE.replace(" K3", " L3"))
    output = compensate_file(original, MACHINE, tmp_path, dialect=dialect)
    assert re.search(r"^G99 G76 X[\d.]+ Y[\d.]+ R[\d.]+ Z-[\d.]+ Q0.2 P0 F100$", output.read_text(), re.M)
    wanted = np.array(HOLES_FINE, dtype=float)
    assert np.allclose([tuple(b) + (r,) for b, r in drilled(_as_g86(original), None)], wanted, atol=1e-6)
    before, after = drilled(_as_g86(original), square), drilled(_as_g86(output), square)
    assert len(after) == len(wanted)
    assert_holes_land(before, after, wanted)
    assert _passes_pathcheck(_as_g86(original), _as_g86(output))


def test_a_fanuc_cycle_of_k0_passes_through(tmp_path):
    """K0 stores the cycle's data and drills no hole (the repeats' count 0); where the block gives a hole
    position too (what the control does with it is not in ncpp's references) the program passes through
    from there, with a warning, where rs274ngc's reading refused the K.  (Without one: test_fanuc_macro.py.)"""
    original = tmp_path / "k0.nc"
    original.write_text("%\nG21 G90 G17\nG0 X40 Y30 Z25\nG99 G81 X20 Y30 Z-3 R2 K0 F100\nX30\nG80\nM30\n%\n")
    said = io.StringIO()
    output = compensate_file(original, MACHINE, tmp_path, warnings=Warnings(stream=said), dialect="fanuc")
    assert output.read_text().endswith("G99 G81 X20 Y30 Z-3 R2 K0 F100\nX30\nG80\nM30\n%\n")
    assert "k0.nc:4:9: warning: canned cycle G81 of 0 repeats with a hole position" in said.getvalue()


# Taps in G18 and G19 (Fanuc: the drilling axis is the plane's normal for every cycle), G90 and G91
# with repeats, G98 and G99: the G17 program's holes (X Y Z bottom, R), moved to each plane by `in_plane`
HOLES_TAPPED = [(100, 120, -16, 3), (30, 40, -16, 3), (150, -50, -20, 5),
                (170, -45, -2, 8), (190, -40, -2, 8), (210, -35, -2, 8), (200, -5, 23, 29), (190, 25, 23, 29),
                (-128, -107, -1, 2.5), (-108, -107, -1, 2.5)]  # fmt: skip
PROGRAM_TAPPED = """G21 G90 G17
G0 X40 Y30 Z25
M3 S500
G99 G84 X100 Y120 R3 Z-16 F100
X30 Y40
G98 G84 X150 Y-50 R5 Z-20
G80
G0 Z30
G91 G99 G84 X20 Y5 R-22 Z-10 L3
G98 X-10 Y30 R-1 Z-6 L2
G90 G80
M4
G0 X-148 Y-107 Z4
G91 G98 G74 X20 R-1.5 Z-3.5
X20
G90 G80
M5
M2
"""


def _as_bored(path: Path) -> Path:
    """`path` with its taps as G89 P0, which rs274ngc moves as a tap along the plane's normal: feed
    to the bottom, feed back out (LinuxCNC G-code manual, G84 and G89), where rs274ngc's own
    G74/G84 in G18 and G19 feed other axes (`Interpreter.taps_in_any_plane`)."""
    bored = path.with_name(path.stem + "-bored" + path.suffix)
    bored.write_text(re.sub(r"G[78]4(?![.\d])", "G89 P0", path.read_text()))
    return bored


@pytest.mark.parametrize("plane", [18, 19])
@pytest.mark.parametrize("machine_name", ["scales and squareness", "reversals"])
def test_fanuc_taps_in_g18_and_g19_land_where_programmed(tmp_path, plane, machine_name):
    """Each tap's bottom and R point, as rs274 runs the written program (its taps as G89 P0), mapped
    through the hand-written machine: within 0.5 µm of the programmed point."""
    program, holes = in_plane(PROGRAM_TAPPED, HOLES_TAPPED, plane)
    machine_toml, machine = (
        (MACHINE, square) if machine_name == "scales and squareness" else reversing_in(plane)
    )
    original = tmp_path / "taps.nc"
    original.write_text(program)
    output = compensate_file(original, machine_toml, tmp_path, dialect="fanuc")
    assert re.search(r"^G91 G99 G84 ", output.read_text(), re.M)  # still a tap, not moves
    wanted = np.array(holes, dtype=float)
    as_programmed = drilled(_as_bored(original), None, plane)
    assert np.allclose([tuple(b) + (r,) for b, r in as_programmed], wanted, atol=1e-6)
    before = drilled(_as_bored(original), machine, plane)
    after = drilled(_as_bored(output), machine, plane)
    assert len(after) == len(holes)
    assert_holes_land(before, after, wanted)
    for pair in ((original, output), (_as_bored(original), _as_bored(output))):
        assert _passes_pathcheck(*pair)


def assert_holes_land(before: list, after: list, wanted: np.ndarray) -> None:
    """Every hole the written program drills (`drilled`: bottom and R level) within 0.5 µm of the
    programmed one (`wanted` rows: X Y Z R), where the original misses each by more than 1.5 µm (the
    machine is wrong enough to tell, at every hole)."""
    off_before = np.array([np.linalg.norm(b - h[:3]) for (b, _), h in zip(before, wanted)]) * 1000
    off_after = np.array([np.linalg.norm(b - h[:3]) for (b, _), h in zip(after, wanted)]) * 1000
    r_after = np.array([abs(r - h[3]) for (_, r), h in zip(after, wanted)]) * 1000
    assert off_before.min() > 1.5
    assert off_after.max() <= 0.5, off_after
    assert r_after.max() <= 0.5, r_after


def _passes_pathcheck(original: Path, output: Path) -> bool:
    """pathcheck's verdict on `output` written for `original` (rs274 with a home of its own)."""
    pathcheck = SHARED / "tools" / "pathcheck"
    if not pathcheck.exists():
        pytest.skip(f"pathcheck not found under {SHARED}")
    check = subprocess.run([sys.executable, str(pathcheck), str(original), str(output)], capture_output=True,
                           text=True, timeout=600, env=rs274_environment(original.parent))  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr
    return True
