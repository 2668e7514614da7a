"""A program that selects another work offset (G55-G59.3) than the one ncpp is
told, or moves in machine coordinates (G53), gets a warning naming the line,
once per G word; --strict refuses it."""

import io
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.pipeline import ErrorSource, process

MACHINE = Path(__file__).resolve().parents[2] / "samples/machines/hr5b.toml"
PROGRAM = b"G21 G90 G54\nG0 X10 Y10\nG55\nG1 X20 F100\nG56 G1 X5\nG55 X1\nG59.1 X2\nM2\n"


def _run(program: bytes, strict: bool = False, source: bool = True) -> str:
    said = io.StringIO()
    src = ErrorSource.from_machine_file(str(MACHINE)).shifted((400.0, 350.0, 300.0)) if source else None
    process(io.BytesIO(program), io.BytesIO(), file="t.ngc", source=src, warnings=Warnings(strict, said))
    return said.getvalue()


def test_each_other_work_offset_is_named_once_where_it_is_first_selected():
    lines = _run(PROGRAM).splitlines()
    assert [line.split(": warning: ")[0] for line in lines] == ["t.ngc:3:1", "t.ngc:5:1", "t.ngc:7:1"]
    assert [line.split(": warning: ")[1].split()[0] for line in lines] == ["G55", "G56", "G59.1"]


def test_strict_mode_refuses_another_work_offset():
    with pytest.raises(NcppError, match="G55 selects a work offset"):
        _run(PROGRAM, strict=True)


def test_a_move_in_machine_coordinates_is_named():
    lines = _run(b"G21 G90\nG0 X10 Y10 Z5\nG53 G0 Z0\nG53 G0 Z0\nM2\n").splitlines()
    assert len(lines) == 1 and lines[0].startswith("t.ngc:3:1: warning: G53 moves in machine coordinates")


def test_g54_alone_and_no_compensation_say_nothing():
    assert _run(PROGRAM.replace(b"G55", b"G54").replace(b"G56", b"G54").replace(b"G59.1", b"G54")) == ""
    assert _run(PROGRAM, source=False) == ""  # passthrough: nothing is compensated
