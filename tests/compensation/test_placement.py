"""Where the control places the tool by itself, judged by LinuxCNC's rs274 on ncpp's output
and a machine whose error is known in closed form (`placement.ScaleMap`): G28/G30 returns,
G92 and G10 L20 set where the tool stands, travel ends, rotary axes."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from ncpp.errors import NcppError
from tests.compensation.placement import pathcheck, run_both, var_file

UM = 1e-3
HOME_28 = (10.0, 20.0, 650.0)  # machine mm: away from 0, where the scale error is 0
HOME_30 = (650.0, 100.0, 400.0)

FUSION = """%
O1001
G90 G94 G17 G21
G28 G91 Z0.
G90
T1 M6
S5000 M3
G54
G0 X10. Y10.
G43 Z15. H1
G0 Z5.
G1 Z-1. F300.
X50.
G0 Z15.
G28 G91 Z0.
G90
G28 G91 X0. Y0.
G90
M30
%
"""


def error_um(nominal, actual, k: int) -> float:
    return float(np.abs(actual[k][1][:3] - nominal[k][1][:3]).max() / UM)


def test_fusion_g28_retract_is_left_to_the_control(tmp_path):
    """`G28 G91 Z0.` stays as written (rs274 accepts it: no G0, no X Y added), the G90 after it
    holds, and the moves between the returns land within 0.2 µm; the homes are the control's."""
    var = var_file(tmp_path, g28=HOME_28)
    out, _, nominal, actual = run_both(tmp_path, FUSION, var)
    assert out.count("\nG28 G91 Z0.\n") == 2 and "\nG28 G91 X0. Y0.\n" in out
    assert len(actual) == len(nominal) == 12
    for k in range(2, 9):  # from the first move after the home to the second G28's intermediate point
        assert error_um(nominal, actual, k) < 0.2, (k, nominal[k], actual[k])
    commanded = [m for _, m in actual]
    home = np.array(HOME_28)
    assert abs(commanded[1][2] / (1 + 3e-5) - home[2]) < 1e-9  # the home move: the control's home, as it is
    assert np.allclose(nominal[9][1][2], home[2]) and np.allclose(nominal[11][1][:2], home[:2])
    pathcheck(tmp_path / "original.ngc", tmp_path / "rewritten.ngc", var, "--tol-mm", "0.05")


G90_RETURNS = """G21 G90 G54
G0 X100 Y50 Z20
G1 X150 F500
G28 Z30
G91 G1 X10 Y5 F500
G1 Z-600
G90 G1 X120 Y40 Z5
G30 G91 X0
G1 Y10
G90 G0 X20 Y30 Z10
M2
"""


def test_moves_after_a_return_are_corrected_from_the_home_position(tmp_path):
    """G28 with a G90 intermediate point and G30 in G91: G91 moves after the home move run
    from the home position (--var-file's 5161-5163, 5181-5183), and land within 0.2 µm."""
    var = var_file(tmp_path, g28=HOME_28, g30=HOME_30)
    out, _, nominal, actual = run_both(tmp_path, G90_RETURNS, var)
    assert "\nG28 Z30\n" in out and "\nG30 G91 X0\n" in out
    assert len(actual) == len(nominal) == 11
    for k in (0, 1, 4, 5, 6, 7, 9, 10):  # all but the G28's intermediate point and the two homes
        assert error_um(nominal, actual, k) < 0.2, (k, nominal[k], actual[k])
    pathcheck(tmp_path / "original.ngc", tmp_path / "rewritten.ngc", var, "--tol-mm", "0.05")


TRAVEL_END = """G21 G90 G54
G0 X10 Y10 Z20
G1 X80 F300
G53 G0 Y600
G0 X20
M2
"""


def test_a_move_to_a_travel_end_stays_at_the_end(tmp_path):
    """`G53 G0 Y600` where Y's travel ends at 600: the compensated command would pass the end
    (the Y scale is short), so Y stops at 600 with a warning at the Y word; X and Z are
    compensated there as elsewhere (also with the numeric work in a worker process)."""
    var = var_file(tmp_path)
    limits = {"X": (-5.0, 800.0), "Y": (-5.0, 600.0), "Z": (-5.0, 700.0)}
    _, said, nominal, actual = run_both(tmp_path, TRAVEL_END, var, limits)
    assert "t.ngc:4:8: warning: Y goes to the end of its travel (600 mm on the machine)" in said
    assert "t.ngc:5:1: warning: Y goes to the end of its travel" in said
    commanded = [m / np.concatenate([1 + np.array([5e-5, -4e-5, 3e-5]), np.ones(3)]) for _, m in actual]
    assert len(actual) == len(nominal) == 4
    assert abs(commanded[2][1] - 600.0) < 1e-7 and abs(commanded[3][1] - 600.0) < 1e-7
    for k in range(4):
        error = np.abs(actual[k][1][:3] - nominal[k][1][:3]) / UM
        assert error[0] < 0.2 and error[2] < 0.2 and (k >= 2 or error[1] < 0.2), (k, error)
    pathcheck(tmp_path / "original.ngc", tmp_path / "rewritten.ngc", var, "--tol-mm", "0.05")


SETTINGS = """G21 G90 G54
G0 X10 Y10 Z20
G1 X50 Y30 F300
G92 X0 Y0
G1 X20 Y10
G52 X5
G1 X10
G52 X0
G92.1
G1 X30 Y40
G10 L20 P1 X0 Y0
G1 X15 Y5
G10 L20 P2 X0 Y0 Z[-2 * 3]
G55
G1 X3 Y4 Z-1
G92 Z5
G91
G1 X5 Y2
G92 X10 Y10
G1 X5 Y2
G92.2
G1 X-4
G92.3
G90 G1 X1 Y1 Z2
M2
"""


def offsets_set(calls) -> list[tuple[str, tuple[float, ...]]]:
    return [(name, numbers) for name, numbers in calls if name in ("SET_G92_OFFSET", "SET_G5X_OFFSET")]


def test_g92_and_g10_l20_set_the_offsets_the_program_means(tmp_path):
    """G92 and G10 L20 (P1, P2, an expression, in G91) at compensated points: written with their
    values moved by the correction where the tool stands, they set the offsets rs274 sets for
    the original program, to 7 decimals; G52, G92.1-G92.3 follow; every move lands within 0.2 µm."""
    from tests.compensation.placement import rs274

    var = var_file(tmp_path)
    out, said, nominal, actual = run_both(tmp_path, SETTINGS, var)
    assert "\nG92 X0 Y0\n" not in out and "\nG10 L20 P2 X" in out and "Z[" not in out
    original, rewritten = (
        offsets_set(rs274(tmp_path / name, var)) for name in ("original.ngc", "rewritten.ngc")
    )
    assert [name for name, _ in original] == [name for name, _ in rewritten]
    # exact where the tool stands at a G90 point; in G91 the control stands where the increments as
    # written add up to, which a map without reversal errors leaves off the grid: one last digit
    for k, ((name, want), (_, got)) in enumerate(zip(original, rewritten)):
        assert np.abs(np.array(want) - np.array(got)).max() < (2e-7 if k < 10 else 1.01e-4), (name, want, got)
    assert len(actual) == len(nominal)
    for k in range(len(nominal)):
        assert error_um(nominal, actual, k) < 0.2, (k, nominal[k], actual[k])
    pathcheck(tmp_path / "original.ngc", tmp_path / "rewritten.ngc", var, "--tol-mm", "0.05")


@pytest.mark.parametrize("middle, why", [
    ("o100 repeat [2]\nG81 X20 Y20 Z-2 R2 F100\no100 endrepeat\nG80\nG92 X0 Y0\n", "G92, G10 L10/L11/L20 or PRESETON right after moves left as programmed in G90"),
    ("o100 repeat [2]\nG1 X[#<_x> + 1]\nG10 L20 P1 X0\no100 endrepeat\n", "G92 or G10 L10/L11/L20 in a loop or subroutine"),
])  # fmt: skip
def test_a_setting_where_ncpp_cannot_say_where_the_control_stands_passes_through(tmp_path, middle, why):
    """After a canned cycle left as programmed in G90 (its G98 retract ends at the compensated level it started from),
    or run in a loop (each run from another point), a G92 or G10 L20 cannot be given one shift:
    from there on the program passes through as it is, with a warning naming the line."""
    from tests.compensation.placement import compensate

    program = f"G21 G90 G54\nG0 X10 Y10 Z20\nG1 X50 F300\n{middle}G1 X20 Y10\nM2\n"
    out, said = compensate(program.encode(), var_file(tmp_path))
    setting = program.index("G92") if "G92" in program else program.index("G10")
    line = program[:setting].count("\n") + 1
    assert f"t.ngc:{line}:" in said and why in said
    assert out.decode().endswith(program[setting if "G92" in program else program.index("o100") :])


ROTARY = """G21 G90 G54 G94
G0 X0 Y-20 Z10 A0 C0
G1 Z0 F500
G93
G1 Y20 A30 C-45 F4
G1 X10 Y-20 A10 F2.5
G1 X20 F10
G94 G1 Y25 C90 F600
G1 X0 A0
M2
"""


def nominal_at(nominal, point: np.ndarray) -> tuple[float, np.ndarray]:
    """(distance in mm from `point`'s X Y Z to the nominal path of feed moves, the A..C the
    nominal moves have there, interpolated along the nearest one)."""
    best = (np.inf, None)
    for (_, a), (_name, b) in zip(nominal, nominal[1:]):
        d = b[:3] - a[:3]
        t = 0.0 if not d.any() else float(np.clip(np.dot(point[:3] - a[:3], d) / np.dot(d, d), 0.0, 1.0))
        distance = float(np.linalg.norm(a[:3] + t * d - point[:3]))
        if distance < best[0] - 1e-9:
            best = (distance, a[3:] + t * (b[3:] - a[3:]))
    return best


def test_moves_that_turn_rotary_axes_are_refused_unless_the_machine_file_says_xyz_are_axis_positions(
    tmp_path,
):
    from tests.compensation.placement import BowMap, compensate_with

    with pytest.raises(NcppError) as refused:
        compensate_with(ROTARY.encode(), BowMap(), var_file(tmp_path), False)
    assert str(refused.value).startswith("t.ngc:5:8: this move turns A and C")
    assert "rotary_xyz_are_axis_positions = true" in str(refused.value)


@pytest.mark.parametrize("tcp", ["G43.4 H1", "G43.5 H1"])
def test_tool_centre_point_control_is_refused(tmp_path, tcp):
    from tests.compensation.placement import BowMap, compensate_with

    program = ROTARY.replace("G93\n", f"{tcp}\nG93\n")
    with pytest.raises(NcppError) as refused:
        compensate_with(program.encode(), BowMap(), var_file(tmp_path), True)
    assert str(refused.value).startswith(f"t.ngc:4:1: {tcp.split()[0]} turns tool-centre-point control on")


def test_split_moves_turn_their_share_and_take_their_share_of_the_time(tmp_path):
    """With X Y Z axis positions: the lines along Y are split (the X error bows along Y); rs274
    accepts the output (an F on every G93 piece); every piece ends on the nominal path within
    1 µm, its A and C where the nominal move has them there (within 0.0002°); in G93 the
    pieces' times add up to the move's; pathcheck (1° counted as 1 mm) passes."""
    from tests.compensation.placement import BowMap, bowed, compensate_with, machine_moves, rs274

    var = var_file(tmp_path)
    out, _ = compensate_with(ROTARY.encode(), BowMap(), var, True)
    original, rewritten = tmp_path / "original.ngc", tmp_path / "rewritten.ngc"
    original.write_text(ROTARY)
    rewritten.write_bytes(out)
    nominal = machine_moves(rs274(original, var))
    calls = rs274(rewritten, var)
    actual = bowed(machine_moves(calls))
    assert len(actual) > len(nominal) + 4  # split
    for k, (_, point) in enumerate(actual[1:], 1):
        distance, rotary = nominal_at(nominal, point)
        assert distance < 1e-3 and np.abs(point[3:] - rotary).max() < 2e-4, (k, point, distance, rotary)
    # the G93 feeds: each piece's time (1/F) adds up to its move's (1/4 + 1/2.5 + 1/10 min)
    feeds, mode = [], 0
    for name, numbers in calls:
        if name == "SET_FEED_MODE":
            mode = int(numbers[-1])
        elif name == "SET_FEED_RATE" and mode == 1:
            feeds.append(numbers[0])
    text = out.decode()
    g93 = text[text.index("G93") : text.index("G94 G1")]
    times = [1 / float(f) for f in __import__("re").findall(r"F([\d.]+)", g93)]
    assert abs(sum(times) - (1 / 4 + 1 / 2.5 + 1 / 10)) < 1e-6 and len(times) > 3
    pathcheck(original, rewritten, var, "--tol-mm", "0.05", "--deg-per-mm", "1")


def test_the_impeller_compensates_on_a_machine_whose_xyz_are_axis_positions(tmp_path):
    """The corpus's 5-axis impeller (G93, A and C turning; its M428, a user M code rs274 does not
    know, left out) on HR5B told its X Y Z are axis positions: rs274 accepts the output (an F on
    every G93 piece) and pathcheck, 1° counted as 1 mm, finds it within 50 µm of the original."""
    from tests.conftest import CORPUS, ROOT

    source = CORPUS / "iso_gcode/linuxcnc/large/impeller-7bl-xyzac.ngc"
    if not source.exists():
        pytest.skip("corpus not available")
    lines = source.read_text().splitlines(keepends=True)
    program = tmp_path / "impeller.ngc"
    program.write_text("".join(line for line in lines[:600] if not line.startswith("M428")) + "M2\n")
    machine = tmp_path / "hr5b.toml"
    machine.write_text((ROOT / "samples/machines/hr5b.toml").read_text().replace(
        "max_correction_mm = 0.5", "max_correction_mm = 0.5\nrotary_xyz_are_axis_positions = true"))  # fmt: skip
    out = tmp_path / "out.ngc"
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(machine), "--work-offset", "400,350,300",
                           "--no-guard", str(program), "-o", str(out)], capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    from tests.compensation.placement import rs274

    var = var_file(tmp_path, g54=(0.0, 0.0, 0.0))
    assert len(rs274(out, var)) > len(rs274(program, var))  # reversal steps, each with its F
    pathcheck(program, out, var, "--tol-mm", "0.05", "--deg-per-mm", "1")


@pytest.mark.parametrize("file, program, name", [
    ("t.h", "BEGIN PGM T MM\nL X+10 Y+10 R0 F100\nM128\nL X+20 A+5\nEND PGM T MM\n", "M128"),
    ("t.h", "BEGIN PGM T MM\nL X+10 Y+10 R0 F100\nFUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS\nL X+20\nEND PGM T MM\n", "FUNCTION TCPM"),
    ("t.mpf", "G54\nG1 X10 Y10 F100\nTRAORI\nG1 X10 Y10 A5 F100\nM30\n", "TRAORI"),
])  # fmt: skip
def test_tool_centre_point_control_is_refused_in_klartext_and_sinumerik(tmp_path, file, program, name):
    from tests.compensation.placement import ScaleMap, compensate_with

    with pytest.raises(NcppError) as refused:
        compensate_with(program.encode(), ScaleMap(), var_file(tmp_path), True, file)
    assert str(refused.value).startswith(f"{file}:3:1: {name} turns tool-centre-point control on")
