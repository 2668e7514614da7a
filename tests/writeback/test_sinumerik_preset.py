"""Sinumerik `PRESETON(<axis>, <value>)` makes the value the machine axis's actual value where it
stands, shifting the machine coordinate system's zero, and the program's with it (SINUMERIK 828D Basic
Functions function manual 01/2023, "Axes, coordinate systems, frames", "Coordinate systems", on
PRESETONS).  ncpp ends interpretation there; as the control stands off the programmed point by the
last move's correction, whose actual value the block would take, a step back to the programmed point
is written before it, so that the shift it sets is the original program's.

The judge is closed form: the written numbers mapped through the machine whose errors are linear in
position (`machine`) land on every programmed point before the PRESETON within 0.5 µm, and the
command the control holds at the PRESETON is the programmed point itself."""

from __future__ import annotations

import numpy as np

from tests.compensation.test_dialect_cutter_comp import compensated
from tests.writeback.closed_form import landed
from tests.writeback.test_sinumerik_expand import points

BEFORE = "G17 G90 G54\nG0 X10 Y10 Z5\nG1 Z-1 F300\nX50 Y20\n"
AFTER = "G1 X60 Y30\nM30\n"
WANTED = [(10, 10, 5), (10, 10, -1), (50, 20, -1)]


def _program(preset: str) -> str:
    return f"{BEFORE}{preset}\n{AFTER}"


def test_a_preset_gets_a_step_back_to_the_programmed_point_and_ends_interpretation(tmp_path):
    written, messages = compensated(tmp_path, "preset.mpf", _program("PRESETON(X, 10)"))
    before, preset, after = written.partition("PRESETON(X, 10)")
    assert preset and after.strip() == AFTER.strip()  # (the rest as programmed)
    ends = points(before)
    assert landed(ends[:-1], WANTED).max() < 0.5e-3
    assert landed(points(BEFORE), WANTED).max() > 5e-3  # (the measure can fail)
    assert np.allclose(ends[-1], WANTED[-1], atol=1e-9)  # (the step: the command at the programmed point)
    assert "PRESETON (it sets a machine axis's actual value" in messages and "outside" in messages


def test_a_preset_value_read_from_the_control_gets_no_step(tmp_path):
    """`$AA_IM[X]+70` reads the actual position: ncpp does not compute it, and writes no step."""
    text = _program("PRESETON(X, $AA_IM[X]+70)")
    written, messages = compensated(tmp_path, "read.mpf", text)
    ends = points(written.partition("PRESETON")[0])
    assert landed(ends, WANTED).max() < 0.5e-3 and len(ends) == len(WANTED)
    assert "PRESETON (it sets" in messages


def test_a_preset_is_not_looked_for_as_a_subprogram_file(tmp_path):
    (tmp_path / "PRESETON.SPF").write_text("G1 X0 Y0\nM17\n")
    _, messages = compensated(
        tmp_path, "file.mpf", _program("PRESETON(X, 10)"), "--subroutine-path", str(tmp_path)
    )
    assert "PRESETON (it sets" in messages and "file" not in messages.partition("PRESETON")[2].split("\n")[0]
