"""A screw-lead error (the `cyclic` effect of docs/machine-file.md: δk = um·sin(2π·k/period_mm))
repeats every few mm, shorter than the stretches over which a smooth error map is sampled: lines
and arcs are cut short enough to follow it.  Judged by LinuxCNC's rs274 running the output, its
points mapped through the sine written out here."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests import rs274
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


# cncjs/cncjs examples/gcode/helical-thread-milling.gcode (MIT) as it is: G42 in G91, helical R arcs of
# 2.4-3.1 mm, the file ending under compensation
UNDER_COMP = """G17
G20
G91
G01 Z-0.6533 F100.
G42 D08
G01 X0.0235 Y-0.0939 F10.
G03 X0.0939 Y0.0939 Z0.0179 R0.0939
G03 X-0.1179 Y0.1179 Z0.0179 R0.1179
G03 X-0.1185 Y-0.1185 Z0.0179 R0.1185
G03 X0.1191 Y-0.1191 Z0.0179 R0.1191 F16.
G03 X0.1196 Y0.1196 Z0.0179 R0.1196
G03 X-0.1202 Y0.1202 Z0.0179 R0.1202 F26.
G03 X-0.1207 Y-0.1207 Z0.0179 R0.1207
G03 X0.1213 Y-0.1213 Z0.0179 R0.1213
G03 X0.1218 Y0.1218 Z0.0179 R0.1218
G03 X-0.0975 Y0.0975 Z0.0179 R0.0975
"""


def test_arcs_under_cutter_compensation_are_not_cut_for_a_screw_lead_error(tmp_path: Path):
    """Each piece of an arc under G41/G42 is a move the control offsets by itself, as a line's
    would be (and lines there are not split): a screw-lead error leaves them whole.  This file ends
    under compensation without a program end, where rs274ngc never runs the move it still holds
    (the last arc): cut in pieces, its first pieces would run and the path would differ."""
    machine, program, out = tmp_path / "screw.toml", tmp_path / "h.ngc", tmp_path / "h.out.ngc"
    tools = tmp_path / "tools.tbl"
    machine.write_text(MACHINE)
    program.write_text(UNDER_COMP)
    tools.write_text("T8 P8 Z1.0 D0.035 ;mill\n")
    done = ncpp(
        "compensate", "--machine", machine, "--tool-table", tools, "--var-units", "inch", program, "-o", out
    )
    assert done.returncode == 0, done.stderr
    rs274.pathcheck(program, out, "--tool-table", str(tools), "--tol-mm", "0.02")
