"""Klartext and Sinumerik interpreters follow X Y Z only: a block that turns A, B or C ends
interpretation there (the rest passes through as written, with a warning), so no compensation
is written as if the rotary axis stood (its whole turn on a reversal step)."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def machine(tmp_path: Path) -> Path:
    """HR5B, its programmed X Y Z said to be the linear axes' positions (rotary moves allowed)."""
    text = (ROOT / "samples/machines/hr5b.toml").read_text()
    path = tmp_path / "rotary.toml"
    path.write_text(
        text.replace("max_correction_mm", "rotary_xyz_are_axis_positions = true\nmax_correction_mm", 1)
    )
    return path


@pytest.mark.parametrize(
    "name, program, turning",
    [
        ("c.mpf", "G0 X0 Y0 Z0\nG1 X300 Y200 A90 F500\nG1 X10\nM30\n", 2),
        (
            "r.h",
            "0 BEGIN PGM R MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n2 L X+300 Y+200 A+90 F500\n3 L X+10\n4 END PGM R MM\n",
            3,
        ),
    ],
)
def test_a_rotary_word_ends_interpretation_where_it_stands(
    machine: Path, name: str, program: str, turning: int
):
    said = io.StringIO()
    out = io.BytesIO()
    process(io.BytesIO(program.encode()), out, file=name, source=ErrorSource.from_machine_file(str(machine)),
            warnings=Warnings(stream=said), offsets=WorkOffsets.at((400.0, 350.0, 300.0)))  # fmt: skip
    assert f"{name}:{turning}:" in said.getvalue() and "the rotary axis A" in said.getvalue()
    written = out.getvalue().decode().splitlines()
    rest = program.splitlines()[turning - 1 :]
    if name.endswith(".h"):  # (Klartext numbers its blocks again after the header)
        rest = [line.split(" ", 1)[1] for line in rest]
        written = [line.split(" ", 1)[1] for line in written]
    assert written[-len(rest) :] == rest
