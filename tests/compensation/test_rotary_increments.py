"""A move that turns a rotary axis in G91, written in pieces (a reversal step, a line split where
the error bows), on a machine whose X Y Z are the linear axes' positions: each piece's rotary word is
its own increment, as G91 reads every axis word (LinuxCNC G-code reference, "G90, G91 Distance
Mode": in G91 "axis numbers ... represent increments from the current coordinate").  Judged by
LinuxCNC's rs274 through pathcheck, which counts the rotary axes' degrees as mm."""

from __future__ import annotations

from pathlib import Path

from tests import rs274
from tests.compensation.test_machine_files import ncpp

# X loses 5 µm on reversing (a step before each reversal) and bows (its lines split)
MACHINE = """[machine]
chain = "XYFZ"
[limits]
X = [-200.0, 200.0]
Y = [-200.0, 200.0]
Z = [-200.0, 200.0]
[errors.EXX]
kind = "table"
positions = [-200.0, 0.0, 200.0]
values_um = [0.0, 12.0, 0.0]
values_um_minus = [5.0, 17.0, 5.0]
interpolation = "smooth"
[compensation]
rotary_xyz_are_axis_positions = true
"""
PROGRAM = """G21 G90 G17 G94
G0 X-20 Y-10 Z5 B10
G1 Z0 F300
G91
G1 X60 Y-5 B45
G1 X-35 B-15
G1 X-40 Y5 B30
G90
G0 Z20
M2
"""


def test_the_pieces_of_a_turning_move_in_g91_write_increments(tmp_path: Path):
    machine, program, out = tmp_path / "m.toml", tmp_path / "p.ngc", tmp_path / "p.out.ngc"
    machine.write_text(MACHINE)
    program.write_text(PROGRAM)
    done = ncpp("compensate", "--machine", machine, "--tolerance", "0.0002", program, "-o", out)
    assert done.returncode == 0, done.stderr
    assert out.read_text().count("B") > 6  # (written in pieces that turn)
    rs274.pathcheck(program, out, "--tol-mm", "0.03")
