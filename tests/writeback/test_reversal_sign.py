"""Reversal tables of either sign: an axis that loses motion on reversal (its − table above
its + table) and one that runs ahead (below it).  Judged by rs274 on the output, mapped
through the machine written here by hand: X's error 0.01 µm/mm · x, plus `reversal` µm
travelling −; an axis never goes back while it moves one way (lost motion: it stands
until its command catches up; running ahead: it jumps the new way)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.compensation.accuracy import worst_um
from tests.writeback.conftest import compensate_file, machine_file

MACHINE = machine_file(
    "reversal of X",
    """
[errors.EXX]
kind = "table"
positions = [-1000.0, 1000.0]
values_um = [-10.0, 10.0]
values_um_minus = [{low}, {high}]
""",
)
# X reverses after lines along X (the corner is on the path either way) and after a line
# along Y into a slanted line (a jump there leaves the slanted line by its sine)
PROGRAM = """G21 G90 G17
G0 X0 Y0 Z0
G1 X100 F1000
G1 X50
G1 X80
G1 Y10
G1 X20
G1 X60 Y20
G1 X0
M2
"""


@pytest.mark.parametrize("reversal", [3.0, -3.0], ids=["lost motion", "runs ahead"])
def test_reversal_compensated_either_sign(tmp_path, reversal):
    def machine(points: np.ndarray, directions: np.ndarray) -> np.ndarray:
        error = 0.01 * points[:, 0] + (reversal if directions[0] < 0 else 0.0)
        return points + np.column_stack([error / 1000, 0 * error, 0 * error])

    original = tmp_path / "original.ngc"
    original.write_text(PROGRAM)
    output = compensate_file(original, MACHINE.format(low=-10 + reversal, high=10 + reversal), tmp_path)
    after = worst_um(original, output, machine)
    # running ahead, the jump at the slanted line's start is 3 µm · sin(14°) = 0.73 µm off it
    assert after <= 0.75, f"{after:.2f} µm off the path"
