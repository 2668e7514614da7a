"""After a change of units (G20 -> G21) the output's position is off the grid of the new
numbers: a block must not write an axis it does not move rounded to the new unit (a 0.016 µm
move that reverses the axis), whether it names the axis or not.  Judged by rs274 on the
output: Z never goes back up; and mapped through a machine written here by hand whose Z
runs ahead 5 µm on reversal, the tool stays on the programmed path."""

from __future__ import annotations

import numpy as np
import pytest

from tests.compensation.accuracy import rs274_calls, worst_um
from tests.writeback.conftest import compensate_file, machine_file

MACHINE = machine_file(
    "positioning of X, reversal of Z",
    """
[errors.EXX]
kind = "polynomial"
coefficients_um = [0.0, 0.05]
[errors.EZZ]
kind = "table"
positions = [-1000.0, 1000.0]
values_um = [0.0, 0.0]
values_um_minus = [-5.0, -5.0]
""",
)
PROGRAM = """G20 G90 G17
G0 X1 Y1 Z0.2
G1 Z-0.049737 F10
G1 X2
G21
G1 X60{z} F100
G1 Y40
G1 X30
G0 Z5
M2
"""


def machine(points: np.ndarray, directions: np.ndarray) -> np.ndarray:
    x = points[:, 0]
    z_error = -5.0 if directions[2] < 0 else 0.0
    return points + np.column_stack([0.05 * x, 0 * x, 0 * x + z_error]) / 1000


@pytest.mark.parametrize("z", ["", " Z-1.2633198"], ids=["Z not in the block", "Z in the block"])
def test_axis_not_moved_after_a_unit_switch_is_not_reversed(tmp_path, z):
    original = tmp_path / "original.ngc"
    original.write_text(PROGRAM.format(z=z))
    output = compensate_file(original, MACHINE, tmp_path)
    depth = np.array([args[2] for name, args in rs274_calls(output) if name == "STRAIGHT_FEED"])
    # Z goes down to its depth and never back up a little (to the grid of the mm numbers)
    assert np.all(np.diff(depth) <= 1e-9), depth
    after = worst_um(original, output, machine)
    assert after <= 0.3, f"{after:.2f} µm off the path"
