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
