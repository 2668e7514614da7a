"""Canned cycles in G91, with repeats and polar words (turning about XY zero) are compensated
hole by hole; one in a loop body, left as programmed, runs from where each run stands.  Judged by rs274 on the output, mapped through a machine written here by
hand (X and Y scale errors and a squareness)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.compensation.accuracy import holes_um
from tests.conftest import CORPUS
from tests.writeback.conftest import compensate_file, machine_file

MACHINE = machine_file(
    "scales and squareness",
    """
[errors.EXX]
kind = "polynomial"
coefficients_um = [0.0, 0.05]
[errors.EYY]
kind = "polynomial"
coefficients_um = [0.0, -0.04]
[squareness]
C0Y_urad = 30.0
""",
)


def machine(points: np.ndarray, _directions: np.ndarray) -> np.ndarray:
    x, y = points[:, 0], points[:, 1]
    return points + np.column_stack([0.05 * x - 0.03 * y, -0.04 * y, 0 * x]) / 1000


CARTESIAN = """G21 G90 G17
G0 X40 Y30 Z5
G1 Z1 F300
G0 Z5
G91 G81 X-25 Y10 R-2 Z-6 F100 L4
G90 G80
M2
"""
ALL_G91 = """G21 G91 G17
G0 X40 Y30 Z5
G1 Z-4 F300
G0 Z4
G81 X-25 Y10 R-2 Z-6 F100 L4
G80
M2
"""
# a cycle in a loop body after a compensated move: each run starts where the last left the
# tool (a step to the programmed start written in the body would run every time)
IN_A_LOOP = """G21 G90 G17
G0 X40 Y30 Z5
o100 repeat [3]
G83 X120 Y90 Z-6 R2 Q2 F100
G80
G0 X140
o100 endrepeat
M2
"""


def polar():
    path = CORPUS / "iso_gcode/linuxcnc/polar.ngc"
    if not path.exists():
        pytest.skip("corpus not available")
    return path.read_text()


PROGRAMS = {"G91 cycle": CARTESIAN, "all in G91": ALL_G91, "in a loop": IN_A_LOOP}


@pytest.mark.parametrize("name", ["polar.ngc", *PROGRAMS])
def test_cycle_holes_where_the_program_puts_them(tmp_path, name):
    original = tmp_path / "original.ngc"
    original.write_text(polar() if name == "polar.ngc" else PROGRAMS[name])
    output = compensate_file(original, MACHINE, tmp_path)
    before = holes_um(original, original, machine)
    after = holes_um(output, original, machine)
    assert before.max() > 4.0  # the machine is wrong enough to tell
    if name == "in a loop":  # (left as programmed: a compensated plunge before it counts as a hole too)
        assert np.all(after <= before + 0.01), np.column_stack([before, after])
    else:  # each hole compensated, a block per repeat, G91 words adding up on the output's grid
        assert after.max() <= 0.5, np.column_stack([before, after])
