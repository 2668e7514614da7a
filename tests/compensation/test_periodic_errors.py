"""A screw-lead error (the `cyclic` effect of docs/machine-file.md: δk = um·sin(2π·k/period_mm))
repeats every few mm, shorter than the stretches over which a smooth error map is sampled: lines
and arcs are cut short enough to follow it.  Judged by LinuxCNC's rs274 running the output, its
points mapped through the sine written out here."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.compensation import accuracy
from tests.compensation.test_machine_files import ncpp
from tests.conftest import RS274

AMPLITUDE_MM, PERIOD_MM = 2e-3, 5.0
MACHINE = f"""[machine]
chain = "XYFZ"
[limits]
X = [-200.0, 200.0]
Y = [-200.0, 200.0]
Z = [-200.0, 200.0]
[[effects]]
kind = "cyclic"
axis = "X"
um = {AMPLITUDE_MM * 1000}
period_mm = {PERIOD_MM}
"""
# diagonal lines (the error along X has a part across them), a short one, and arcs (G17)
PROGRAM = """G21 G90 G17 G94
G0 X0 Y0 Z1
G1 Z0 F300
G1 X13 Y13
G1 X50 Y50
G1 X50.7 Y50.1
G1 X100 Y100.3
G2 X130 Y100.3 I15 J0
G3 X121.2 Y91.5 R8.8
M2
"""


def screw(commands: np.ndarray, direction: np.ndarray) -> np.ndarray:
    x = commands[:, 0]
    return commands + np.column_stack([AMPLITUDE_MM * np.sin(2 * np.pi * x / PERIOD_MM), 0 * x, 0 * x])


@pytest.mark.skipif(not RS274.exists(), reason="rs274 oracle not available")
def test_a_screw_lead_error_is_followed_along_lines_and_arcs(tmp_path: Path):
    machine, program, out = tmp_path / "screw.toml", tmp_path / "p.ngc", tmp_path / "p.out.ngc"
    machine.write_text(MACHINE)
    program.write_text(PROGRAM)
    done = ncpp("compensate", "--machine", machine, "--tolerance", "0.0002", program, "-o", out)
    assert done.returncode == 0, done.stderr
    before = accuracy.worst_um(program, program, screw)
    after = accuracy.worst_um(program, out, screw)
    assert before > 1.0 and after <= 0.3, (before, after)
