"""Where the control places the tool by itself, judged by LinuxCNC's rs274 on ncpp's output
and a machine whose error is known in closed form (`placement.ScaleMap`): G28/G30 returns,
G92 and G10 L20 set where the tool stands, travel ends, rotary axes."""

from __future__ import annotations

import numpy as np
import pytest

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


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_move_to_a_travel_end_stays_at_the_end(tmp_path, jobs):
    """`G53 G0 Y600` where Y's travel ends at 600: the compensated command would pass the end
    (the Y scale is short), so Y stops at 600 with a warning at the Y word; X and Z are
    compensated there as elsewhere (also with the numeric work in a worker process)."""
    var = var_file(tmp_path)
    limits = {"X": (-5.0, 800.0), "Y": (-5.0, 600.0), "Z": (-5.0, 700.0)}
    _, said, nominal, actual = run_both(tmp_path, TRAVEL_END, var, jobs, limits)
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
    original, rewritten = (offsets_set(rs274(tmp_path / name, var)) for name in ("original.ngc", "rewritten.ngc"))
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
    ("G81 X20 Y20 Z-2 R2 F100\nG80\nG92 X0 Y0\n", "G92 or G10 L20 right after moves left as programmed in G90"),
    ("o100 repeat [2]\nG1 X[#<_x> + 1]\nG10 L20 P1 X0\no100 endrepeat\n", "G92 or G10 L20 in a loop or subroutine"),
])  # fmt: skip
def test_a_setting_where_ncpp_cannot_say_where_the_control_stands_passes_through(tmp_path, middle, why):
    """After a canned cycle in G90 (its G98 retract ends at the compensated level it started from),
    or run in a loop (each run from another point), a G92 or G10 L20 cannot be given one shift:
    from there on the program passes through as it is, with a warning naming the line."""
    from tests.compensation.placement import compensate

    program = f"G21 G90 G54\nG0 X10 Y10 Z20\nG1 X50 F300\n{middle}G1 X20 Y10\nM2\n"
    out, said = compensate(program.encode(), var_file(tmp_path))
    setting = program.index("G92") if "G92" in program else program.index("G10")
    line = program[:setting].count("\n") + 1
    assert f"t.ngc:{line}:" in said and why in said
    assert out.decode().endswith(program[setting if "G92" in program else program.index("o100"):])
