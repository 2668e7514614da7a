"""An axis word written as an expression or a parameter (`Y[0]`, `Y#5`) positions its
axis as a number does: later blocks and the pieces of split lines write that axis's
correction.  Judged by rs274 on the output, mapped through a machine whose Y error along
X is written here by hand (a straightness 0.02 x + 2e-4 x² µm)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.compensation.accuracy import worst_um
from tests.writeback.conftest import SQUARE, compensate_file, machine_file

MACHINE = machine_file(
    "straightness of X in Y",
    """
[errors.EYX]
kind = "polynomial"
coefficients_um = [0.0, 0.02, 2e-4]
[compensation]
max_correction_mm = 0.5
""",
)


def straightness(points: np.ndarray, _directions: np.ndarray) -> np.ndarray:
    x = points[:, 0]
    return points + np.column_stack([0 * x, (0.02 * x + 2e-4 * x * x) / 1000, 0 * x])


PROGRAM = """G21 G90 G17
{set}G0 X-190 Y{y} Z3
G1 Z-1 F500
G1 X190 F800
G1 X-100
G0 Z3
M2
"""


@pytest.mark.parametrize(
    "y, set_", [("0", ""), ("[0]", ""), ("#5", "#5=0\n"), ("[#<_zero> * 2]", "#<_zero>=0\n")]
)
def test_expression_axis_keeps_its_correction(tmp_path, y, set_):
    original = tmp_path / "original.ngc"
    original.write_text(PROGRAM.format(y=y, set=set_))
    output = compensate_file(original, MACHINE, tmp_path)
    before = worst_um(original, original, straightness)
    after = worst_um(original, output, straightness)
    assert before > 10.0  # the machine is wrong enough to tell
    assert after <= 0.5, f"{after:.2f} µm (uncompensated {before:.2f} µm)"


def test_sinumerik_parameter_axis_keeps_its_correction(tmp_path):
    """`X=R1`: the machine's X is off by -50 µm/m · Y (a squareness), so at Y200 the command
    is X10.0100 (worked out by hand: no rs274 for Sinumerik)."""
    original = tmp_path / "original.mpf"
    original.write_text("R1=10\nG90 G71\nG0 X=R1 Y0 Z5\nG1 Y200 F500\nY0\nM30\n")
    output = compensate_file(original, SQUARE, tmp_path, dialect="sinumerik").read_text()
    far = next(line for line in output.splitlines() if "Y200" in line)
    assert "X10.0100" in far, output
